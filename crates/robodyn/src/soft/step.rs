//! One step of a scene as MuJoCo's `mj_step` takes it: the soft model's forward dynamics
//! ([`super::dynamics`]) integrated by the `<option>`'s integrator over its `timestep` h.
//!
//! Reference: MuJoCo's documentation, "Computation", §Numerical integration. MuJoCo's velocity
//! ν differs from robodyn's v on free joints only, whose linear velocity it measures in world
//! axes: ν = T v, T = diag(R, 1) there, and its acceleration is ã = T (q̈ + w), w = (ω × v, 0).
//! With q̈ the soft model's accelerations and M the mass matrix:
//! ```text
//!   Euler          ν₁ = ν₀ + h ã,  ã explicit, or with joint damping D implicit in it:
//!                      (M + h D) ã = M ã_explicit
//!   implicitfast   (M − h K) ã = M ã_explicit,  K = ∂f/∂ν of the dampers and the actuators
//!                      (and, on a free body alone in its tree, of its gyroscopic forces)
//!   RK4            the classical tableau on (q, ν) on the joints' groups (Runge–Kutta–
//!                  Munthe-Kaas), the constraints found anew at each stage
//!   then           q₁ = q₀ ⊞ h ν₁ joint by joint: q + h q̇ on hinges and slides, quat ⊗
//!                  exp(h ω) on balls, p + h v_world and quat ⊗ exp(h ω) on free joints,
//!                  and the activations w₁ = w₀ ⊞ h ẇ (crate::model::Actuator::next_activation;
//!                  RK4: its stages take w₀ + h a_i ẇ_{i−1}, its step the weighted ẇ)
//!   last           the plastic springs yield at q₁ (crate::model::plastic; its stages keep
//!                  the references of the step's start), a tendon's at the length MuJoCo
//!                  takes there, L₁ = L₀ + J₀ (q₁ ⊖ q₀) (measured: not L(q₁))
//! ```
//! Written in robodyn's basis an implicit solve reads `(M − h Tᵀ K T) u = M (q̈ + w)` with
//! ν₁ = T₀ (v₀ + h u), and v₁ = T₁ᵀ ν₁ at the new orientation. A free body's gyroscopic
//! derivative, Tᵀ (∂f/∂ν) T = −(∂τ/∂v − M ∂w/∂v), comes from RNEA's derivatives
//! (`crate::algo::rnea_derivatives`).

use super::dynamics::{free_joint_velocity_product, ContactDynamics, ContactForward};
use super::tendons::TendonKinematics;
use super::TINY;
use crate::algo::rnea_derivatives;
use crate::algo::DerivativesInto;
use crate::error::{check_vector, Error, Result};
use crate::joint::{quaternion_of, rotation_of, Joint};
use crate::model::{Integrator, Model};
use crate::spatial::{skew, Mat3, Vec3};
use crate::Data;
use nalgebra::{DMatrix, DVector, Quaternion, UnitQuaternion};

/// RK4's tableau: a_{i,i−1} (the rest are 0) and the weights b.
const RK4_A: [f64; 3] = [0.5, 0.5, 1.0];
const RK4_B: [f64; 4] = [1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0];
/// A state coordinate beyond this has diverged (MuJoCo's `mjMAXVAL`).
pub const MAX_STATE: f64 = 1e10;

/// A scene's step: its soft-constraint dynamics and scratch space.
#[derive(Debug, Clone)]
pub struct SceneStep {
    dynamics: ContactDynamics,
    /// The forward dynamics at the start of the last step: its contacts, rows and forces,
    /// q̈ (robodyn's basis) and the actuators' forces.
    pub forward: ContactForward,
    /// For RK4's later stages.
    stage: ContactForward,
    data: Data,
    /// Forward dynamics evaluated so far.
    evaluations: usize,
    /// The free bodies alone in their trees ([`lone_free_bodies`]).
    lone_free_bodies: Vec<usize>,
    /// Euler's implicit matrix (then its factor) and its K, kept between steps.
    implicit: DMatrix<f64>,
    damping: DMatrix<f64>,
    /// For the plastic tendons: q₀, q₁ ⊖ q₀ and the lengths L₁.
    start: Vec<f64>,
    change: Vec<f64>,
    lengths: Vec<f64>,
}

impl SceneStep {
    /// The step of `model`'s scene; its integrator must be one robodyn steps as MuJoCo does.
    pub fn new(model: &Model) -> Result<Self> {
        let integrator = model.options.integrator;
        if matches!(integrator, Integrator::Implicit | Integrator::Discrete) {
            return Err(Error::InvalidValue {
                argument: "integrator".into(),
                message: format!(
                    "the model's <option integrator=\"{}\"> is not made yet: robodyn steps \
                     Euler, implicitfast and RK4 as MuJoCo does",
                    integrator.keyword()
                ),
            });
        }
        if model.options.noslip_iterations > 0 {
            return Err(Error::InvalidValue {
                argument: "noslip_iterations".into(),
                message: "MuJoCo's no-slip solver is not made yet: expected \
                          <option noslip_iterations=\"0\">"
                    .into(),
            });
        }
        Ok(SceneStep {
            dynamics: ContactDynamics::new(model)?,
            forward: ContactForward::default(),
            stage: ContactForward::default(),
            data: Data::new(model),
            evaluations: 0,
            lone_free_bodies: lone_free_bodies(model),
            implicit: DMatrix::zeros(0, 0),
            damping: DMatrix::zeros(0, 0),
            start: Vec::new(),
            change: Vec::new(),
            lengths: Vec::new(),
        })
    }

    /// The forward dynamics at (q, v), the activations `act` and the plastic state `plastic`
    /// into [`Self::forward`], without a step.
    pub fn forward_only(
        &mut self,
        model: &Model,
        state: (&[f64], &[f64], &[f64], &[f64]),
        tau: &[f64],
        ctrl: &[f64],
    ) -> Result<()> {
        self.evaluations += 1;
        self.dynamics
            .forward(model, state, tau, ctrl, &mut self.forward)
    }

    /// The next step starts its solver from q̈₀ (as a new `SceneStep` would) rather than from
    /// the last solution: its result no longer depends on the steps before.
    pub fn forget_warm_start(&mut self) {
        self.dynamics.forget_warm_start();
    }

    /// How many times the forward dynamics was evaluated (RK4: four per step).
    pub fn evaluations(&self) -> usize {
        self.evaluations
    }

    /// Advances (q, v), the activations `act` (na) and the plastic state `plastic` (nplastic)
    /// at time `time` (s; for its errors) by the scene's time step under the applied forces
    /// `tau` (nv) and the controls `ctrl` (nu), both held over the step. A state that is not
    /// finite or beyond [`MAX_STATE`] afterwards stops it (MuJoCo resets there).
    pub fn step(
        &mut self,
        model: &Model,
        time: f64,
        (q, v, act, plastic): (&mut [f64], &mut [f64], &mut [f64], &mut [f64]),
        tau: &[f64],
        ctrl: &[f64],
    ) -> Result<()> {
        model.check_configuration(q)?;
        check_vector("v", v, model.nv)?;
        check_vector("act", act, model.na())?;
        let h = model.options.timestep;
        self.forward_only(model, (q, v, act, plastic), tau, ctrl)?;
        self.start.clear();
        self.start.extend_from_slice(q);
        let acceleration = mujoco_acceleration(model, v, &self.forward.solution.acceleration);
        let u = match model.options.integrator {
            Integrator::Rk4 => None,
            Integrator::Euler => {
                // as MuJoCo 4.0 decides (measured): a positive linear or any higher term
                let damped = model.options.flag("eulerdamp")
                    && model.options.flag("damper")
                    && (model.damping.iter().any(|d| *d > 0.0)
                        || model.damping_poly.iter().any(|t| *t != [0.0; 2]));
                Some(match damped {
                    true => self.damped_euler(model, q, v, &acceleration),
                    false => Some(acceleration.clone()),
                })
            }
            Integrator::ImplicitFast => {
                let tendons = &self.forward.tendons;
                let k = velocity_derivative(model, (q, v, act), ctrl, tendons)?;
                let gyroscopic = self.free_body_gyroscopic(model, q, v)?;
                let mass = &self.forward.mass;
                let mut matrix = DMatrix::zeros(0, 0);
                implicit_matrix(model, q, mass, &k, gyroscopic, &mut matrix);
                Some(matrix.lu().solve(&(mass * &acceleration)))
            }
            Integrator::Implicit | Integrator::Discrete => unreachable!("refused by new"),
        };
        match u {
            None => {
                let state = (&mut *q, &mut *v, &mut *act, &*plastic);
                self.runge_kutta(model, state, &acceleration, tau, ctrl)?
            }
            Some(Some(u)) => {
                advance(model, q, v, &u, h);
                model.advance_activations(act, self.forward.activation_rate.as_slice(), h);
            }
            Some(None) => {
                return Err(Error::Simulation {
                    time,
                    message: "the implicit step's matrix M − h ∂f/∂v is singular".into(),
                })
            }
        }
        let bad = |x: &f64| !x.is_finite() || x.abs() > MAX_STATE;
        if q.iter().chain(v.iter()).any(bad) {
            return Err(Error::Simulation {
                time,
                message: format!("the state diverged (beyond {MAX_STATE:e} or not finite)"),
            });
        }
        self.yield_springs(model, q, plastic)
    }

    /// Euler's step with its joints' damping implicit: u with (M − h Tᵀ K T) u = M a, K the
    /// dampers' ∂f/∂ν (diagonal, ≤ 0: the matrix is M plus a positive semi-definite term,
    /// factored by Cholesky); `None` when singular.
    fn damped_euler(
        &mut self,
        model: &Model,
        q: &[f64],
        v: &[f64],
        acceleration: &DVector<f64>,
    ) -> Option<DVector<f64>> {
        let nv = model.nv;
        if self.damping.shape() != (nv, nv) {
            self.damping = DMatrix::zeros(nv, nv);
        }
        self.damping.set_diagonal(&damper_slopes(model, q, v));
        let mass = &self.forward.mass;
        let mut matrix = std::mem::take(&mut self.implicit);
        implicit_matrix(model, q, mass, &self.damping, None, &mut matrix);
        let mut u = mass * acceleration;
        match matrix.cholesky() {
            Some(factor) => {
                factor.solve_mut(&mut u);
                self.implicit = factor.unpack_dirty();
                Some(u)
            }
            // a damper's negative terms may leave it indefinite: the general solve
            None => {
                let mut matrix = DMatrix::zeros(0, 0);
                implicit_matrix(model, q, mass, &self.damping, None, &mut matrix);
                matrix.lu().solve(&u)
            }
        }
    }

    /// The plastic springs yield at the step's new configuration q, the tendons at
    /// L₁ = L₀ + J₀ (q ⊖ q₀) (from the step's start), while springs are enabled.
    fn yield_springs(&mut self, model: &Model, q: &[f64], plastic: &mut [f64]) -> Result<()> {
        if plastic.is_empty() || !model.options.flag("spring") {
            return Ok(());
        }
        self.lengths.clear();
        if model.has_plastic_tendons() {
            self.change.resize(model.nv, 0.0);
            mujoco_change(model, &self.start, q, &mut self.change);
            let tendons = &self.forward.tendons;
            let lengths = tendons.lengths.iter().enumerate();
            self.lengths
                .extend(lengths.map(|(t, length)| length + tendons.rate(t, &self.change)));
        }
        model.yield_springs(q, &self.lengths, plastic);
        Ok(())
    }

    /// RK4 on (q, ν) as a Runge–Kutta–Munthe-Kaas scheme (MuJoCo's): stage i at
    /// q₀ ⊞ θ_i, ν₀ + h a_i ã_{i−1}, with θ_i = h a_i K_{i−1} and K_j = dexp⁻¹_{θ_j}(ν_j) the rate
    /// of the tangent coordinates (ν itself but on the rotations); the step q₀ ⊞ h Σ b_j K_j,
    /// ν₀ + h Σ b_j ã_j; the activations likewise, w₀ + h a_i ẇ_{i−1} at the stages and
    /// w₀ ⊞ h Σ b_j ẇ_j.
    /// `start`: q̈ + w at (q, v), from the step's first evaluation.
    fn runge_kutta(
        &mut self,
        model: &Model,
        (q, v, act, plastic): (&mut [f64], &mut [f64], &mut [f64], &[f64]),
        start: &DVector<f64>,
        tau: &[f64],
        ctrl: &[f64],
    ) -> Result<()> {
        let h = model.options.timestep;
        let (q0, nu0, w0) = (
            q.to_vec(),
            to_mujoco(model, q, v),
            DVector::from_column_slice(act),
        );
        let mut rates = vec![nu0.clone()];
        let mut acceleration = vec![to_mujoco(model, q, start.as_slice())];
        let mut activation_rates = vec![self.forward.activation_rate.clone()];
        for a in RK4_A {
            let last = rates.len() - 1;
            let (rate, last_acceleration) = (&rates[last], &acceleration[last]);
            let theta = rate * (h * a);
            let mut stage_q = q0.clone();
            integrate_positions(model, &mut stage_q, &theta, 1.0);
            let stage_nu = &nu0 + last_acceleration * (h * a);
            let stage_v = from_mujoco(model, &stage_q, stage_nu.as_slice());
            let stage_w = &w0 + &activation_rates[last] * (h * a);
            self.evaluations += 1;
            self.dynamics.forward(
                model,
                (&stage_q, stage_v.as_slice(), stage_w.as_slice(), plastic),
                tau,
                ctrl,
                &mut self.stage,
            )?;
            let stage_acceleration =
                mujoco_acceleration(model, stage_v.as_slice(), &self.stage.solution.acceleration);
            acceleration.push(to_mujoco(model, &stage_q, stage_acceleration.as_slice()));
            rates.push(tangent_rate(model, &theta, stage_nu));
            activation_rates.push(self.stage.activation_rate.clone());
        }
        let weighted = |values: &[DVector<f64>]| -> DVector<f64> {
            values.iter().zip(RK4_B).map(|(x, b)| x * b).sum()
        };
        q.copy_from_slice(&q0);
        integrate_positions(model, q, &weighted(&rates), h);
        let nu1 = nu0 + weighted(&acceleration) * h;
        v.copy_from_slice(from_mujoco(model, q, nu1.as_slice()).as_slice());
        model.advance_activations(act, weighted(&activation_rates).as_slice(), h);
        Ok(())
    }

    /// Tᵀ (∂f/∂ν) T of the gyroscopic forces of each free body alone in its tree (MuJoCo's
    /// implicitfast adds them), −(∂τ/∂v − M ∂w/∂v) on its block; `None` when the model has no
    /// such body.
    fn free_body_gyroscopic(
        &mut self,
        model: &Model,
        q: &[f64],
        v: &[f64],
    ) -> Result<Option<DMatrix<f64>>> {
        if self.lone_free_bodies.is_empty() {
            return Ok(None);
        }
        let zero = vec![0.0; model.nv];
        rnea_derivatives(
            model,
            &mut self.data,
            q,
            v,
            &zero,
            None,
            DerivativesInto::Data,
        )?;
        let mut k = DMatrix::zeros(model.nv, model.nv);
        for &body in &self.lone_free_bodies {
            let s = model.idx_v[body];
            let (linear, angular) = (vec3(&v[s..s + 3]), vec3(&v[s + 3..s + 6]));
            // ∂w/∂v: w = ω × v_linear on the linear rows
            let mut dw = DMatrix::<f64>::zeros(6, 6);
            dw.fixed_view_mut::<3, 3>(0, 0).copy_from(&skew(&angular));
            dw.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-skew(&linear)));
            let block = self.data.dtau_dv.view((s, s), (6, 6))
                - self.data.mass_matrix.view((s, s), (6, 6)) * dw;
            k.view_mut((s, s), (6, 6)).copy_from(&(-block));
        }
        Ok(Some(k))
    }
}

/// q₁ ⊖ q₀ as MuJoCo's `mj_differentiatePos` measures it, in robodyn's basis at q₀: a free
/// joint's translation p₁ − p₀ in world axes turned into its body's at q₀, R₀ᵀ (p₁ − p₀), and its
/// rotation log(R₀ᵀ R₁); every other joint on its group.
fn mujoco_change(model: &Model, q0: &[f64], q1: &[f64], out: &mut [f64]) {
    for i in 1..model.nbodies() {
        let (configuration, dofs) = (model.q_range(i), model.v_range(i));
        let (a, b) = (&q0[configuration.clone()], &q1[configuration]);
        let out = &mut out[dofs];
        match model.joints[i] {
            Joint::Free => {
                let (r0, r1) = (quaternion_of(&a[3..7]), quaternion_of(&b[3..7]));
                let moved = vec3(&b[0..3]) - vec3(&a[0..3]);
                out[0..3].copy_from_slice(r0.inverse_transform_vector(&moved).as_slice());
                out[3..6].copy_from_slice((r0.inverse() * r1).scaled_axis().as_slice());
            }
            ref joint => joint.difference(a, b, out),
        }
    }
}

/// The bodies MuJoCo calls standalone free bodies: a free joint, no child bodies, and no mass
/// in the file's bodies welded to it but its own.
fn lone_free_bodies(model: &Model) -> Vec<usize> {
    (1..model.nbodies())
        .filter(|&b| matches!(model.joints[b], Joint::Free))
        .filter(|&b| !model.parent.contains(&b))
        .filter(|&b| {
            let welded = model.source_bodies.iter().filter(|s| s.body == b);
            let mut masses = welded.map(|s| s.mass).filter(|m| *m != 0.0);
            masses.next().is_some() && masses.next().is_none()
        })
        .collect()
}

/// K = ∂f/∂ν of the dampers (−D with its polynomial terms, and (∂f/∂L̇) JᵀJ of each
/// tendon's) and of the actuators whose force is not saturated
/// ([`crate::model::ActuatorForce::saturated`]): (b₂ + a₂ u) m mᵀ, m the moment arms (gear on a
/// joint, gear J on a tendon; the activation w, or with `actearly` the next one, in place of u
/// where the actuator has one), MuJoCo's `qDeriv` without the bias forces' terms, in MuJoCo's velocities ν (a joint actuator's hinge or slide has ν = v; a
/// tendon's J, on a free body's sites, is turned into ν's).
fn velocity_derivative(
    model: &Model,
    (q, v, act): (&[f64], &[f64], &[f64]),
    ctrl: &[f64],
    tendons: &TendonKinematics,
) -> Result<DMatrix<f64>> {
    let nv = model.nv;
    let mut k = DMatrix::zeros(nv, nv);
    if model.options.flag("damper") {
        k.set_diagonal(&damper_slopes(model, q, v));
        // (∂f/∂L̇) JᵀJ, ∂f/∂L̇ = −(b + 2 b₁ |L̇| + 3 b₂ L̇²), with J in MuJoCo's velocities:
        // J_ν = J T⁻¹, its transpose T Jᵀ
        for (t, tendon) in model.tendons.iter().enumerate() {
            let slope = tendon.damping_slope(tendons.rate(t, v));
            if slope == 0.0 {
                continue;
            }
            let row: Vec<f64> = tendons.jacobian.row(t).iter().copied().collect();
            let j = to_mujoco(model, q, &row);
            k.ger(slope, &j, &j, 1.0);
        }
    }
    check_vector("ctrl", ctrl, model.nu())?;
    if model.options.flag("actuation") {
        check_vector("act", act, model.na())?;
        let mut arms = vec![0.0; nv];
        for (actuator, out) in model.actuator_scalar_forces((q, v), (ctrl, act), tendons) {
            if !out.saturated {
                // (b₂ + a₂ u) m mᵀ with m in MuJoCo's velocities: T m
                let slope = actuator.bias[2] + actuator.gain[2] * out.input;
                arms.fill(0.0);
                for (c, arm) in model.actuator_arms(actuator, tendons) {
                    arms[c] += arm;
                }
                let arms = to_mujoco(model, q, &arms);
                k.ger(slope, &arms, &arms, 1.0);
            }
        }
    }
    keep_tree_pattern(model, &mut k);
    Ok(k)
}

/// ∂f/∂ν of each joint's damper on MuJoCo's velocities ν, −(b + 2 b₁ |ν| + 3 b₂ ν²)
/// ([`Model::damper_slope`]; −b without polynomial terms).
fn damper_slopes(model: &Model, q: &[f64], v: &[f64]) -> DVector<f64> {
    let nu = to_mujoco(model, q, v);
    DVector::from_fn(model.nv, |c, _| model.damper_slope(c, nu[c]))
}

/// K keeps only the entries MuJoCo's `qDeriv` holds, those of M's sparsity: two degrees of
/// freedom on one branch of the tree (one's body the other's or an ancestor of it). A tendon's
/// or actuator's coupling of two branches (two trees, two fingers) is left out there, and so
/// here.
fn keep_tree_pattern(model: &Model, k: &mut DMatrix<f64>) {
    for a in 0..model.nv {
        for b in 0..model.nv {
            if !model.dofs_on_one_branch(a, b) {
                k[(a, b)] = 0.0;
            }
        }
    }
}

/// M − h Tᵀ K T − h G into `matrix`: the implicit step's matrix in robodyn's basis (G: the
/// free bodies' gyroscopic Tᵀ(∂f/∂ν)T, already in that basis; h the scene's time step).
fn implicit_matrix(
    model: &Model,
    q: &[f64],
    mass: &DMatrix<f64>,
    k: &DMatrix<f64>,
    gyroscopic: Option<DMatrix<f64>>,
    matrix: &mut DMatrix<f64>,
) {
    // Tᵀ K T, T the identity but for each free joint's linear block R: Rᵀ on those rows, R on
    // those columns
    if matrix.shape() == k.shape() {
        matrix.copy_from(k);
    } else {
        *matrix = k.clone();
    }
    for (s, rotation) in free_rotations(model, q) {
        let turned = rotation.transpose() * matrix.fixed_rows::<3>(s);
        matrix.fixed_rows_mut::<3>(s).copy_from(&turned);
        let turned = matrix.fixed_columns::<3>(s) * rotation;
        matrix.fixed_columns_mut::<3>(s).copy_from(&turned);
    }
    if let Some(g) = gyroscopic {
        *matrix += g;
    }
    *matrix *= -model.options.timestep;
    *matrix += mass;
}

/// ν₁ = T₀ (v₀ + h u), q₁ = q₀ ⊞ h ν₁, v₁ = T₁ᵀ ν₁ (the module's header).
fn advance(model: &Model, q: &mut [f64], v: &mut [f64], u: &DVector<f64>, h: f64) {
    let moved: Vec<f64> = v.iter().zip(u.iter()).map(|(v, u)| v + h * u).collect();
    let nu = to_mujoco(model, q, &moved);
    integrate_positions(model, q, &nu, h);
    v.copy_from_slice(from_mujoco(model, q, nu.as_slice()).as_slice());
}

/// q̈ + w: the acceleration MuJoCo's basis sees, still in robodyn's axes (w = (ω × v, 0) on
/// free joints).
fn mujoco_acceleration(model: &Model, v: &[f64], qdd: &DVector<f64>) -> DVector<f64> {
    qdd + free_joint_velocity_product(model, v)
}

/// ν = T v.
fn to_mujoco(model: &Model, q: &[f64], v: &[f64]) -> DVector<f64> {
    let mut nu = DVector::from_column_slice(v);
    for (s, rotation) in free_rotations(model, q) {
        nu.fixed_rows_mut::<3>(s)
            .copy_from(&(rotation * vec3(&v[s..s + 3])));
    }
    nu
}

/// v = Tᵀ ν.
fn from_mujoco(model: &Model, q: &[f64], nu: &[f64]) -> DVector<f64> {
    let mut v = DVector::from_column_slice(nu);
    for (s, rotation) in free_rotations(model, q) {
        v.fixed_rows_mut::<3>(s)
            .copy_from(&(rotation.transpose() * vec3(&nu[s..s + 3])));
    }
    v
}

/// Each free joint's first velocity coordinate and its rotation R (child to world axes).
fn free_rotations<'a>(model: &'a Model, q: &'a [f64]) -> impl Iterator<Item = (usize, Mat3)> + 'a {
    (1..model.nbodies())
        .filter(move |&b| matches!(model.joints[b], Joint::Free))
        .map(move |b| {
            let quaternion = &q[model.idx_q[b] + 3..model.idx_q[b] + 7];
            (model.idx_v[b], rotation_of(quaternion))
        })
}

/// K = dexp⁻¹_θ(ν): the rate of the tangent coordinates θ in q = q₀ ⊞ θ that moves with
/// velocity ν; on each rotation (a ball's, a free joint's angular part: MuJoCo integrates a free
/// joint on R³ × SO(3)) the rotation group's ([`rotation_tangent_rate`]); ν itself elsewhere.
fn tangent_rate(model: &Model, theta: &DVector<f64>, mut nu: DVector<f64>) -> DVector<f64> {
    for b in 1..model.nbodies() {
        let angular = match model.joints[b] {
            Joint::Spherical => model.idx_v[b],
            Joint::Free => model.idx_v[b] + 3,
            _ => continue,
        };
        let (theta, omega) = (
            vec3(&theta.as_slice()[angular..angular + 3]),
            vec3(&nu.as_slice()[angular..angular + 3]),
        );
        let rate = rotation_tangent_rate(&theta, &omega);
        nu.rows_mut(angular, 3).copy_from(&rate);
    }
    nu
}

/// dexp⁻¹_θ(ω) on SO(3) for a body-axes ω, in closed form (MuJoCo's RK4 takes it exactly; a
/// series cut after θ⁴ is 4e-13 off at |ω| h = 0.17):
/// ```text
///   ω + ½ θ × ω + c θ × (θ × ω),   c = (1 − (t/2) cot(t/2)) / t²,  t = |θ|
/// ```
/// with c = 1/12 + t²/720 below t = 1e-3 (the next term, t⁴/30240, is below 1e-16 there).
fn rotation_tangent_rate(theta: &Vec3, omega: &Vec3) -> Vec3 {
    let t = theta.norm();
    let c = if t < 1e-3 {
        1.0 / 12.0 + t * t / 720.0
    } else {
        let half = 0.5 * t;
        (1.0 - half / half.tan()) / (t * t)
    };
    let across = theta.cross(omega);
    omega + across * 0.5 + theta.cross(&across) * c
}

/// q ⊞ h ν joint by joint as MuJoCo's `mj_integratePos`: hinges and slides q + h q̇, balls
/// quat ⊗ exp(h ω), free joints p + h v_world with their quaternion as a ball's.
fn integrate_positions(model: &Model, q: &mut [f64], nu: &DVector<f64>, h: f64) {
    for b in 1..model.nbodies() {
        let (iq, iv) = (model.idx_q[b], model.idx_v[b]);
        match model.joints[b] {
            Joint::Fixed => {}
            Joint::Revolute { .. } | Joint::Prismatic { .. } => q[iq] += h * nu[iv],
            Joint::Spherical => turn(&mut q[iq..iq + 4], &vec3(&nu.as_slice()[iv..iv + 3]), h),
            Joint::Free => {
                for k in 0..3 {
                    q[iq + k] += h * nu[iv + k];
                }
                turn(
                    &mut q[iq + 3..iq + 7],
                    &vec3(&nu.as_slice()[iv + 3..iv + 6]),
                    h,
                );
            }
        }
    }
}

/// quat ← quat/|quat| ⊗ exp(h ω) for a quaternion [x, y, z, w] and a body-axes ω (MuJoCo's
/// `mju_quatIntegrate`).
fn turn(quaternion: &mut [f64], omega: &Vec3, h: f64) {
    let start = UnitQuaternion::from_quaternion(Quaternion::new(
        quaternion[3],
        quaternion[0],
        quaternion[1],
        quaternion[2],
    ));
    let speed = omega.norm();
    let rotation = if speed < TINY {
        UnitQuaternion::identity()
    } else {
        UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_unchecked(omega / speed), h * speed)
    };
    let end = start.into_inner() * rotation.into_inner();
    quaternion.copy_from_slice(&[end.i, end.j, end.k, end.w]);
}

fn vec3(v: &[f64]) -> Vec3 {
    Vec3::new(v[0], v[1], v[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_turn_about_z_by_a_quarter_is_the_quaternion_of_a_quarter_turn() {
        let mut quaternion = [0.0, 0.0, 0.0, 1.0];
        turn(
            &mut quaternion,
            &Vec3::new(0.0, 0.0, std::f64::consts::PI),
            0.5,
        );
        let half = std::f64::consts::FRAC_PI_4;
        let expected = [0.0, 0.0, half.sin(), half.cos()];
        for (a, b) in quaternion.iter().zip(expected) {
            assert!((a - b).abs() < 1e-15, "{quaternion:?}");
        }
    }

    #[test]
    fn the_rotation_tangent_rate_is_the_rate_of_the_logarithm() {
        // d/dε log(exp(θ) exp(ε ω)) at ε = 0, by central differences, small and large θ
        let omega = Vec3::new(0.3, -1.2, 0.7);
        for theta in [
            Vec3::new(1e-4, -2e-4, 3e-4),
            Vec3::new(0.2, 0.1, -0.3),
            Vec3::new(1.5, -0.4, 0.9),
        ] {
            let at = |epsilon: f64| {
                let turned = UnitQuaternion::from_scaled_axis(theta)
                    * UnitQuaternion::from_scaled_axis(omega * epsilon);
                turned.scaled_axis()
            };
            let step = 1e-6;
            let expected = (at(step) - at(-step)) / (2.0 * step);
            let rate = rotation_tangent_rate(&theta, &omega);
            assert!(
                (rate - expected).norm() < 1e-8,
                "θ = {theta:?}: {rate:?} vs {expected:?}"
            );
        }
    }
}
