//! The forward dynamics a simulation integrates, as a strategy: q̈ = FD(q, v, τ, f_ext), the
//! solution of the equations of motion
//!
//! ```text
//! M(q) q̈ + C(q, v) v + g(q) = τ + Σ J_iᵀ f_ext,i
//! ```
//!
//! [`super::simulate`], [`super::simulate_lockstep`] and [`super::StepWorkspace`] call it through
//! [`ForwardDynamics`] (a generic parameter: static dispatch, nothing allocated per step); their
//! plain forms use [`Aba`], Featherstone's articulated-body algorithm for a tree in free space;
//! [`Constrained`] holds rigid constraints (closed loops, anchors, couplings). Contacts implement
//! the same trait (the `_with` forms take them).

use crate::algo::lanes::{aba_batch, BatchResult, BatchWorkspace, States};
use crate::algo::{
    aba, aba_derivatives, constrained_forward_dynamics, constrained_forward_dynamics_derivatives,
    ConstrainedDerivatives, ConstrainedOptions, ConstraintData, DerivativesInto,
};
use crate::constraint::ConstraintSet;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::spatial::Force;
use crate::Data;
use nalgebra::DMatrix;

/// How a simulation turns a state and the forces acting on it into accelerations.
///
/// An implementation provides:
///
/// - [`Self::acceleration`] (required): q̈ (nv) at the configuration q (nq) and velocity v (nv)
///   under the generalised forces τ (nv: the controller's plus the joints' passive forces) and
///   the external wrenches `f_ext`, one per body 1..nbodies in that body's frame, as
///   [`crate::algo::aba()`] takes them (`None`: no wrenches). Every scheme needs it: explicit
///   Euler, RK4 and RK45 evaluate it at each stage, semi-implicit Euler once per step (its
///   velocity first, v₁ = v₀ + h q̈₀, then q₁ = q₀ ⊕ h v₁), and every recorded sample once more.
///   It works in `data` and in its own fields, allocates nothing, and is a function of its
///   inputs alone: the step-doubling checks evaluate it again at states already visited.
/// - [`Self::acceleration_derivatives`] (optional): q̈ with ∂q̈/∂q, ∂q̈/∂v and ∂q̈/∂τ. The
///   explicit and semi-implicit schemes need none; [`super::StepWorkspace::step`] asked for the
///   Jacobians A = ∂x₁/∂x₀ and B = ∂x₁/∂τ of one step chains them through its stages (the
///   passive forces enter as ∂q̈/∂τ · ∂τ_passive/∂x), and an implicit scheme would build its
///   Newton matrix I − h ∂f/∂x from them. Without it, such a request fails with a clear error.
/// - [`Self::accelerations_in_lanes`] (optional): q̈ of many independent states at once, for
///   rollouts in lockstep; without it each rollout evaluates its own [`Self::acceleration`].
pub trait ForwardDynamics {
    /// q̈ = FD(q, v, τ, f_ext), in `data` or in `self`.
    fn acceleration<'w>(
        &'w mut self,
        model: &Model,
        data: &'w mut Data,
        q: &[f64],
        v: &[f64],
        tau: &[f64],
        f_ext: Option<&[Force]>,
    ) -> Result<&'w [f64]>;

    /// q̈ = FD(q, v, τ) without external wrenches and its Jacobians, into `out`: ∂q̈/∂q with q
    /// perturbed in its tangent space (q ⊕ δ, as every derivative in robodyn), ∂q̈/∂v and
    /// ∂q̈/∂τ. The default has none and says so.
    fn acceleration_derivatives(
        &mut self,
        model: &Model,
        data: &mut Data,
        q: &[f64],
        v: &[f64],
        tau: &[f64],
        out: &mut AccelerationDerivatives,
    ) -> Result<()> {
        let _ = (model, data, q, v, tau, out);
        Err(Error::InvalidValue {
            argument: "derivatives".into(),
            message: "this forward dynamics has no derivatives; a step without them works".into(),
        })
    }

    /// q̈ of the states in the rows of `states.q`, `states.v` and `states.tau` into the rows of
    /// `qdd`, several per instruction, exactly as [`Self::acceleration`] computes each (rollouts
    /// in lockstep equal their own simulations bit for bit); an error names its row. Called
    /// through one rollout's strategy for all of them, so only a strategy whose result does not
    /// depend on its own state may provide it. The default, `None`, has no such form.
    fn accelerations_in_lanes(
        &self,
        model: &Model,
        lanes: &mut BatchWorkspace,
        states: States,
        qdd: &mut [f64],
    ) -> Option<BatchResult> {
        let _ = (model, lanes, states, qdd);
        None
    }
}

/// q̈ and its Jacobians (nv × nv each), as [`ForwardDynamics::acceleration_derivatives`]
/// writes them.
#[derive(Debug, Clone, PartialEq)]
pub struct AccelerationDerivatives {
    /// q̈ (nv).
    pub qdd: Vec<f64>,
    /// ∂q̈/∂q, with q perturbed in its tangent space (nv × nv).
    pub by_q: DMatrix<f64>,
    /// ∂q̈/∂v (nv × nv).
    pub by_v: DMatrix<f64>,
    /// ∂q̈/∂τ (nv × nv; for a tree in free space, M⁻¹).
    pub by_tau: DMatrix<f64>,
}

impl AccelerationDerivatives {
    /// Zeros sized for `model` (nv, and nv × nv for each Jacobian).
    pub fn new(model: &Model) -> Self {
        let nv = model.nv;
        AccelerationDerivatives {
            qdd: vec![0.0; nv],
            by_q: DMatrix::zeros(nv, nv),
            by_v: DMatrix::zeros(nv, nv),
            by_tau: DMatrix::zeros(nv, nv),
        }
    }
}

/// A tree in free space: the articulated-body algorithm ([`crate::algo::aba()`]), its analytical
/// derivatives ([`crate::algo::aba_derivatives`]) and its lanes ([`aba_batch`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Aba;

impl ForwardDynamics for Aba {
    fn acceleration<'w>(
        &'w mut self,
        model: &Model,
        data: &'w mut Data,
        q: &[f64],
        v: &[f64],
        tau: &[f64],
        f_ext: Option<&[Force]>,
    ) -> Result<&'w [f64]> {
        Ok(aba(model, data, q, v, tau, f_ext)?.as_slice())
    }

    fn acceleration_derivatives(
        &mut self,
        model: &Model,
        data: &mut Data,
        q: &[f64],
        v: &[f64],
        tau: &[f64],
        out: &mut AccelerationDerivatives,
    ) -> Result<()> {
        aba_derivatives(model, data, q, v, tau, None, DerivativesInto::Data)?;
        out.qdd.copy_from_slice(data.qdd.as_slice());
        out.by_q.copy_from(&data.dqdd_dq);
        out.by_v.copy_from(&data.dqdd_dv);
        // ∂q̈/∂τ = M⁻¹
        out.by_tau.copy_from(&data.mass_matrix_inverse);
        Ok(())
    }

    fn accelerations_in_lanes(
        &self,
        model: &Model,
        lanes: &mut BatchWorkspace,
        states: States,
        qdd: &mut [f64],
    ) -> Option<BatchResult> {
        Some(aba_batch(model, lanes, states, qdd))
    }
}

/// A tree under rigid constraints: [`crate::algo::constrained_forward_dynamics`] with the
/// constraints of a [`ConstraintSet`] and their options (Baumgarte's gains, proximal damping).
#[derive(Debug, Clone)]
pub struct Constrained {
    set: ConstraintSet,
    options: ConstrainedOptions,
    constraints: ConstraintData,
    /// The derivatives' workspace, made on the first step that asks for them.
    derivatives: Option<Box<ConstrainedDerivatives>>,
}

impl Constrained {
    /// The strategy for `set` on `model`.
    pub fn new(model: &Model, set: ConstraintSet, options: ConstrainedOptions) -> Self {
        let constraints = ConstraintData::new(model, &set);
        Constrained {
            set,
            options,
            constraints,
            derivatives: None,
        }
    }

    /// The forces λ of the last acceleration evaluated (one per constraint row).
    pub fn forces(&self) -> &[f64] {
        self.constraints.forces.as_slice()
    }

    /// Whether this strategy holds the same constraints with the same options as `other`.
    pub fn is_for(&self, other: &Constrained) -> bool {
        self.set == other.set && self.options == other.options
    }
}

impl ForwardDynamics for Constrained {
    fn acceleration<'w>(
        &'w mut self,
        model: &Model,
        data: &'w mut Data,
        q: &[f64],
        v: &[f64],
        tau: &[f64],
        f_ext: Option<&[Force]>,
    ) -> Result<&'w [f64]> {
        let c = &mut self.constraints;
        let state = (q, v, tau);
        constrained_forward_dynamics(model, data, c, &self.set, state, f_ext, &self.options)?;
        Ok(self.constraints.qdd.as_slice())
    }

    /// [`constrained_forward_dynamics_derivatives`]: the derivatives of the exact equations, so
    /// refused with Baumgarte's gains (whose terms they do not hold).
    fn acceleration_derivatives(
        &mut self,
        model: &Model,
        data: &mut Data,
        q: &[f64],
        v: &[f64],
        tau: &[f64],
        out: &mut AccelerationDerivatives,
    ) -> Result<()> {
        if self.options.baumgarte.is_some() {
            return Err(Error::InvalidValue {
                argument: "derivatives".into(),
                message: "constrained derivatives are those of the exact constraint equations; \
                          a step with derivatives takes baumgarte=None"
                    .into(),
            });
        }
        let set = &self.set;
        let d = self
            .derivatives
            .get_or_insert_with(|| Box::new(ConstrainedDerivatives::new(model, set)));
        let (c, damping) = (&mut self.constraints, self.options.damping);
        constrained_forward_dynamics_derivatives(
            model,
            data,
            c,
            d,
            set,
            (q, v, tau),
            None,
            damping,
        )?;
        out.qdd.copy_from_slice(c.qdd.as_slice());
        out.by_q.copy_from(&d.dqdd_dq);
        out.by_v.copy_from(&d.dqdd_dv);
        out.by_tau.copy_from(&d.dqdd_dtau);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{
        simulate, simulate_lockstep, simulate_lockstep_with, simulate_with, ControlLaw, Integrator,
        NativeController, SimulationOptions, StepWorkspace, Trajectory,
    };
    use crate::io::bundled_model;
    use nalgebra::DVector;

    /// A strategy written outside the simulator: ABA under τ plus a constant generalised force.
    #[derive(Clone)]
    struct Pushed {
        inner: Aba,
        push: Vec<f64>,
        tau: Vec<f64>,
    }

    impl Pushed {
        fn new(push: &[f64]) -> Self {
            Pushed {
                inner: Aba,
                push: push.to_vec(),
                tau: vec![0.0; push.len()],
            }
        }

        /// τ + the push, into `self.tau`.
        fn push(&mut self, tau: &[f64]) {
            for (total, (applied, push)) in self.tau.iter_mut().zip(tau.iter().zip(&self.push)) {
                *total = applied + push;
            }
        }
    }

    impl ForwardDynamics for Pushed {
        fn acceleration<'w>(
            &'w mut self,
            model: &Model,
            data: &'w mut Data,
            q: &[f64],
            v: &[f64],
            tau: &[f64],
            f_ext: Option<&[Force]>,
        ) -> Result<&'w [f64]> {
            self.push(tau);
            self.inner.acceleration(model, data, q, v, &self.tau, f_ext)
        }

        fn acceleration_derivatives(
            &mut self,
            model: &Model,
            data: &mut Data,
            q: &[f64],
            v: &[f64],
            tau: &[f64],
            out: &mut AccelerationDerivatives,
        ) -> Result<()> {
            self.push(tau);
            self.inner
                .acceleration_derivatives(model, data, q, v, &self.tau, out)
        }
    }

    /// A strategy with q̈ alone: ABA, without derivatives or lanes.
    struct AccelerationOnly(Aba);

    impl ForwardDynamics for AccelerationOnly {
        fn acceleration<'w>(
            &'w mut self,
            model: &Model,
            data: &'w mut Data,
            q: &[f64],
            v: &[f64],
            tau: &[f64],
            f_ext: Option<&[Force]>,
        ) -> Result<&'w [f64]> {
            self.0.acceleration(model, data, q, v, tau, f_ext)
        }
    }

    /// A constant-torque controller.
    fn constant(model: &Model, tau: &[f64], options: &SimulationOptions) -> NativeController {
        let law = ControlLaw::Constant(DVector::from_column_slice(tau));
        NativeController::new(model, law, options.passive, options.t_end).unwrap()
    }

    fn assert_same_motion(run: &Trajectory, reference: &Trajectory, what: &str) {
        assert_eq!(run.t, reference.t, "{what}");
        assert_eq!(run.q, reference.q, "{what}");
        assert_eq!(run.v, reference.v, "{what}");
        assert_eq!(run.a, reference.a, "{what}");
        assert_eq!(run.statistics, reference.statistics, "{what}");
    }

    /// What the simulator, the rollouts in lockstep and the single step integrate is the
    /// strategy they are given: ABA pushed by a constant force moves the robot exactly as ABA
    /// under a controller applying that force, and unlike ABA alone.
    #[test]
    fn the_simulator_integrates_the_strategy_it_is_given() {
        let mut model = bundled_model("ur5", false).unwrap();
        let (nq, nv) = (model.nq, model.nv);
        // forces in proportion to each joint's inertia (the wrist's is small): passive ones,
        // whose Jacobians reach the step's through ∂q̈/∂τ, and the push
        let mut data = Data::new(&model);
        let inertia = crate::algo::crba(&model, &mut data, model.neutral().as_slice())
            .unwrap()
            .diagonal();
        model.damping = inertia.scale(2.0);
        model.stiffness = inertia.scale(10.0);
        let push: Vec<f64> = (0..nv)
            .map(|j| inertia[j] * (2.0 - 0.7 * j as f64))
            .collect();
        let zero = vec![0.0; nv];
        let q0: Vec<f64> = (0..nq).map(|j| 0.3 - 0.1 * j as f64).collect();
        let v0: Vec<f64> = (0..nv).map(|j| 0.05 * j as f64).collect();
        for name in Integrator::NAMES {
            let integrator = Integrator::from_name(name, 1e-6, 1e-9).unwrap();
            let what = format!("{integrator:?}");
            let options = SimulationOptions::new(integrator, 1e-3, 0.05);
            let (mut idle, mut pushing) = (
                constant(&model, &zero, &options),
                constant(&model, &push, &options),
            );
            let forward = Pushed::new(&push);
            let run = simulate_with(&model, &q0, &v0, &options, forward, &mut idle, None, None);
            let run = run.unwrap();
            let pushed = simulate(&model, &q0, &v0, &options, &mut pushing, None, None).unwrap();
            assert_same_motion(&run, &pushed, &what);
            assert_eq!(run.tau, vec![0.0; run.tau.len()], "{what}");
            let mut idle = constant(&model, &zero, &options);
            let free = simulate(&model, &q0, &v0, &options, &mut idle, None, None).unwrap();
            assert_ne!(run.q, free.q, "{what}");
        }

        // in lockstep: a strategy without lanes, rollout by rollout, equals ABA's lanes
        let starts: Vec<(Vec<f64>, Vec<f64>)> = (0..3)
            .map(|k| {
                let q = q0.iter().map(|x| x + 0.1 * k as f64).collect();
                (q, v0.clone())
            })
            .collect();
        let starts: Vec<(&[f64], &[f64])> = starts.iter().map(|(q, v)| (&q[..], &v[..])).collect();
        let options = SimulationOptions::new(Integrator::Rk4, 1e-3, 0.05);
        let forward = Pushed::new(&push);
        let idle = constant(&model, &zero, &options);
        let runs = simulate_lockstep_with(&model, &starts, &options, &forward, &idle).unwrap();
        let pushing = constant(&model, &push, &options);
        let pushed = simulate_lockstep(&model, &starts, &options, &pushing).unwrap();
        for (run, reference) in runs.iter().zip(&pushed) {
            assert_same_motion(run, reference, "lockstep");
        }

        // one step and its Jacobians A, B
        let mut pushed_step = StepWorkspace::with_forward_dynamics(&model, Pushed::new(&push));
        let mut plain_step = StepWorkspace::new(&model);
        for integrator in [Integrator::SemiImplicitEuler, Integrator::Rk4] {
            let passive = options.passive;
            pushed_step
                .step(&model, &q0, &v0, &zero, 0.01, integrator, &passive, true)
                .unwrap();
            plain_step
                .step(&model, &q0, &v0, &push, 0.01, integrator, &passive, true)
                .unwrap();
            assert_eq!(pushed_step.q_end, plain_step.q_end, "{integrator:?}");
            assert_eq!(pushed_step.v_end, plain_step.v_end, "{integrator:?}");
            assert_eq!(pushed_step.a, plain_step.a, "{integrator:?}");
            assert_eq!(pushed_step.b, plain_step.b, "{integrator:?}");
        }
    }

    /// A strategy without derivatives steps without them, and a step asked for them says why
    /// it cannot.
    #[test]
    fn a_step_asks_for_derivatives_only_when_it_needs_them() {
        let model = bundled_model("ur5", false).unwrap();
        let (q, v, tau) = (model.neutral(), vec![0.1; model.nv], vec![0.0; model.nv]);
        let q = q.as_slice();
        let passive = SimulationOptions::new(Integrator::Rk4, 1e-3, 1.0).passive;
        let mut only = StepWorkspace::with_forward_dynamics(&model, AccelerationOnly(Aba));
        let mut plain = StepWorkspace::new(&model);
        let step = |workspace: &mut StepWorkspace<_>, derivatives| {
            workspace.step(
                &model,
                q,
                &v,
                &tau,
                0.01,
                Integrator::Rk4,
                &passive,
                derivatives,
            )
        };
        step(&mut only, false).unwrap();
        plain
            .step(&model, q, &v, &tau, 0.01, Integrator::Rk4, &passive, false)
            .unwrap();
        assert_eq!(only.q_end, plain.q_end);
        let error = step(&mut only, true).unwrap_err().to_string();
        assert!(error.contains("no derivatives"), "{error}");
    }
}
