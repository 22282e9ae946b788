//! One fixed step of the equations of motion M q̈ + C q̇ + g = τ + τ_passive(q, q̇) and, on request,
//! its Jacobians for trajectory optimisation (iLQR, DDP, MPC):
//!
//! ```text
//! x₁ = Φ(x₀, τ),   A = ∂x₁/∂x₀ (2nv × 2nv),   B = ∂x₁/∂τ (2nv × nv),   x = (q, q̇)
//! ```
//!
//! with q in the tangent space on both sides (right perturbations q ⊕ δ, as every derivative in
//! robodyn). The step is the one [`super::simulate`] takes: explicit Euler and RK4 as
//! Runge–Kutta–Munthe-Kaas schemes ([`super::schemes`]), semi-implicit Euler velocity first. τ is
//! held over the step (zero-order hold).
//!
//! The Jacobians are those of the discrete map itself (exact up to round-off, not of the ODE),
//! carried through the stages by the chain rule with three columns blocks [δq₀, δq̇₀, δτ]:
//! ```text
//!   dξ_s = h Σ a_sj dΞ_j        dv_s = [0 1 0] + h Σ a_sj dA_j
//!   dq_s = ∂(q₀ ⊕ ξ_s)/∂q₀ [1 0 0] + ∂(q₀ ⊕ ξ_s)/∂ξ dξ_s
//!   dA_s = ∂q̈/∂q dq_s + ∂q̈/∂q̇ dv_s + ∂q̈/∂τ [0 0 1]
//!   dΞ_s = ∂T/∂ξ dξ_s + ∂T/∂v dv_s            (Ξ_s = T(ξ_s, v_s) = dexp⁻¹_{-ξ_s} v_s)
//! ```
//! and the same weighted sums with b_s for the step. q̈ and ∂q̈ come from the forward dynamics
//! ([`super::ForwardDynamics`], free-space [`Aba`] unless chosen) and the passive forces' own
//! Jacobians (∂q̈/∂x += ∂q̈/∂τ ∂τ_passive/∂x); ⊕ and T from [`super::lie_group`]. Cost with
//! derivatives: per stage one evaluation of the derivatives (`aba_derivatives`) and O(n³)
//! products.

use crate::error::{check_vector, Error, Result};
use crate::integrate::forces::PassiveForces;
use crate::integrate::forward_dynamics::{Aba, AccelerationDerivatives, ForwardDynamics};
use crate::integrate::lie_group::{integrate_jacobians, tangent_rate, tangent_rate_jacobians};
use crate::integrate::schemes::{Integrator, Tableau};
use crate::integrate::simulator::positive;
use crate::model::Model;
use crate::Data;
use nalgebra::DMatrix;

/// Most stages of a fixed-step scheme (RK4).
const MAX_STAGES: usize = 4;

/// Everything one step needs, allocated once per model, with the forward dynamics the step
/// integrates; [`StepWorkspace::step`] allocates nothing.
pub struct StepWorkspace<F = Aba> {
    /// The forward dynamics the step integrates.
    pub forward_dynamics: F,
    data: Data,
    tau_passive: Vec<f64>,
    tau_total: Vec<f64>,
    /// ∂τ_passive/∂q, ∂τ_passive/∂q̇ (nv × nv).
    passive_jacobians: (DMatrix<f64>, DMatrix<f64>),
    /// q̈ and ∂q̈/∂q, ∂q̈/∂q̇, ∂q̈/∂τ at the current stage (nv × nv each).
    acceleration_derivatives: AccelerationDerivatives,
    /// ∂(q₀ ⊕ ξ)/∂q₀ and ∂(q₀ ⊕ ξ)/∂ξ, or ∂T/∂ξ and ∂T/∂v (nv × nv each).
    group_jacobians: (DMatrix<f64>, DMatrix<f64>),
    /// Per stage: A_s and Ξ_s (nv), dA_s and dΞ_s (nv × 3nv).
    accelerations: [Vec<f64>; MAX_STAGES],
    tangent_rates: [Vec<f64>; MAX_STAGES],
    d_accelerations: [DMatrix<f64>; MAX_STAGES],
    d_tangent_rates: [DMatrix<f64>; MAX_STAGES],
    /// The current stage: q_s (nq), ξ_s and v_s (nv), and their derivatives (nv × 3nv).
    stage_q: Vec<f64>,
    xi: Vec<f64>,
    stage_v: Vec<f64>,
    d_xi: DMatrix<f64>,
    d_v: DMatrix<f64>,
    d_q: DMatrix<f64>,
    /// The step's result q₁ (nq).
    pub q_end: Vec<f64>,
    /// The step's result q̇₁ (nv).
    pub v_end: Vec<f64>,
    /// A = ∂x₁/∂x₀ (2nv × 2nv), rows and columns [q (tangent); q̇]; written when the step is
    /// asked for derivatives.
    pub a: DMatrix<f64>,
    /// B = ∂x₁/∂τ (2nv × nv), rows [q (tangent); q̇]; written when the step is asked for
    /// derivatives.
    pub b: DMatrix<f64>,
}

impl StepWorkspace {
    /// The workspace of a step in free space ([`Aba`]).
    pub fn new(model: &Model) -> Self {
        StepWorkspace::with_forward_dynamics(model, Aba)
    }
}

impl<F: ForwardDynamics> StepWorkspace<F> {
    /// The workspace of a step that integrates `forward_dynamics`.
    pub fn with_forward_dynamics(model: &Model, forward_dynamics: F) -> Self {
        let (nq, nv) = (model.nq, model.nv);
        let square = || DMatrix::zeros(nv, nv);
        let wide = || DMatrix::zeros(nv, 3 * nv);
        StepWorkspace {
            forward_dynamics,
            data: Data::new(model),
            tau_passive: vec![0.0; nv],
            tau_total: vec![0.0; nv],
            passive_jacobians: (square(), square()),
            acceleration_derivatives: AccelerationDerivatives::new(model),
            group_jacobians: (square(), square()),
            accelerations: std::array::from_fn(|_| vec![0.0; nv]),
            tangent_rates: std::array::from_fn(|_| vec![0.0; nv]),
            d_accelerations: std::array::from_fn(|_| wide()),
            d_tangent_rates: std::array::from_fn(|_| wide()),
            stage_q: vec![0.0; nq],
            xi: vec![0.0; nv],
            stage_v: vec![0.0; nv],
            d_xi: wide(),
            d_v: wide(),
            d_q: wide(),
            q_end: vec![0.0; nq],
            v_end: vec![0.0; nv],
            a: DMatrix::zeros(2 * nv, 2 * nv),
            b: DMatrix::zeros(2 * nv, nv),
        }
    }

    /// One step of size `h` from (q, q̇) under the constant torque `tau` and the model's passive
    /// forces: writes `q_end`, `v_end` and, with `derivatives`, `a` and `b`. `integrator` is
    /// explicit Euler, semi-implicit Euler or RK4 (an adaptive scheme has no fixed step).
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &mut self,
        model: &Model,
        q: &[f64],
        v: &[f64],
        tau: &[f64],
        h: f64,
        integrator: Integrator,
        passive: &PassiveForces,
        derivatives: bool,
    ) -> Result<()> {
        model.check_configuration(q)?;
        check_vector("v", v, model.nv)?;
        check_vector("tau", tau, model.nv)?;
        passive.check()?;
        positive("dt", h, false)?;
        let tableau = match integrator {
            Integrator::Rk45 { .. } => {
                return Err(Error::InvalidValue {
                    argument: "integrator".into(),
                    message: "'rk45' chooses its own steps; a single step takes 'euler', \
                              'semi_implicit_euler' or 'rk4'"
                        .into(),
                })
            }
            Integrator::SemiImplicitEuler => None,
            other => other.tableau(),
        };
        let stages = tableau.map_or(1, |t| t.b.len());
        for s in 0..stages {
            self.stage(model, tableau, s, q, v, tau, h, passive, derivatives)?;
        }
        self.finish(model, tableau, q, v, h, derivatives)
    }

    /// Stage s: (ξ_s, v_s) from the earlier stages, then A_s = q̈(q₀ ⊕ ξ_s, v_s) and Ξ_s, with their
    /// derivatives.
    #[allow(clippy::too_many_arguments)]
    fn stage(
        &mut self,
        model: &Model,
        tableau: Option<&Tableau>,
        s: usize,
        q: &[f64],
        v: &[f64],
        tau: &[f64],
        h: f64,
        passive: &PassiveForces,
        derivatives: bool,
    ) -> Result<()> {
        let weights = tableau.map_or(&[][..], |t| t.a[s]);
        self.weighted_sums(weights, h, v, derivatives);
        model.integrate(q, &self.xi, &mut self.stage_q)?;
        self.dynamics(model, tau, passive, s, derivatives)?;
        tangent_rate(model, &self.xi, &self.stage_v, &mut self.tangent_rates[s]);
        if derivatives {
            let nv = model.nv;
            // dq_s = ∂(q₀ ⊕ ξ)/∂q₀ [1 0 0] + ∂(q₀ ⊕ ξ)/∂ξ dξ_s
            let (d_group, d_tangent) = &mut self.group_jacobians;
            integrate_jacobians(model, q, &self.xi, d_group, d_tangent)?;
            multiply(&mut self.d_q, d_tangent, &self.d_xi, 0.0);
            let mut by_start = self.d_q.columns_mut(0, nv);
            by_start += &*d_group;
            // dA_s = ∂q̈/∂q dq_s + ∂q̈/∂q̇ dv_s + ∂q̈/∂τ [0 0 1]
            let AccelerationDerivatives {
                by_q, by_v, by_tau, ..
            } = &self.acceleration_derivatives;
            let d_acceleration = &mut self.d_accelerations[s];
            multiply(d_acceleration, by_q, &self.d_q, 0.0);
            multiply(d_acceleration, by_v, &self.d_v, 1.0);
            let mut by_torque = d_acceleration.columns_mut(2 * nv, nv);
            by_torque += by_tau;
            // dΞ_s = ∂T/∂ξ dξ_s + ∂T/∂v dv_s
            let (by_xi, by_velocity) = &mut self.group_jacobians;
            tangent_rate_jacobians(model, &self.xi, &self.stage_v, by_xi, by_velocity)?;
            multiply(&mut self.d_tangent_rates[s], by_xi, &self.d_xi, 0.0);
            multiply(&mut self.d_tangent_rates[s], by_velocity, &self.d_v, 1.0);
        }
        Ok(())
    }

    /// q̈ = FD(q_s, v_s, τ + τ_passive) into A_s, and with `derivatives` its three Jacobians.
    fn dynamics(
        &mut self,
        model: &Model,
        tau: &[f64],
        passive: &PassiveForces,
        s: usize,
        derivatives: bool,
    ) -> Result<()> {
        let (q, v) = (&self.stage_q, &self.stage_v);
        passive.torque(model, q, v, &mut self.tau_passive);
        for (total, (applied, own)) in self
            .tau_total
            .iter_mut()
            .zip(tau.iter().zip(&self.tau_passive))
        {
            *total = applied + own;
        }
        let forward = &mut self.forward_dynamics;
        if !derivatives {
            let qdd = forward.acceleration(model, &mut self.data, q, v, &self.tau_total, None)?;
            self.accelerations[s].copy_from_slice(qdd);
            return Ok(());
        }
        let jacobians = &mut self.acceleration_derivatives;
        forward.acceleration_derivatives(
            model,
            &mut self.data,
            q,
            v,
            &self.tau_total,
            jacobians,
        )?;
        self.accelerations[s].copy_from_slice(&jacobians.qdd);
        // ∂q̈/∂x = ∂FD/∂x + ∂q̈/∂τ ∂τ_passive/∂x
        let (passive_q, passive_v) = &mut self.passive_jacobians;
        passive.jacobians(model, q, v, passive_q, passive_v);
        multiply(&mut jacobians.by_q, &jacobians.by_tau, passive_q, 1.0);
        multiply(&mut jacobians.by_v, &jacobians.by_tau, passive_v, 1.0);
        Ok(())
    }

    /// ξ = h Σ w_j Ξ_j and v = v₀ + h Σ w_j A_j (and their derivatives) over the stages so far.
    fn weighted_sums(&mut self, weights: &[f64], h: f64, v: &[f64], derivatives: bool) {
        let nv = v.len();
        self.xi.as_mut_slice().fill(0.0);
        self.stage_v.copy_from_slice(v);
        if derivatives {
            // dξ = 0, dv = [0 1 0] before the sums
            self.d_xi.as_mut_slice().fill(0.0);
            self.d_v.as_mut_slice().fill(0.0);
            self.d_v.columns_mut(nv, nv).fill_with_identity();
        }
        for (j, &weight) in weights.iter().enumerate().filter(|(_, w)| **w != 0.0) {
            for k in 0..nv {
                self.xi[k] += h * weight * self.tangent_rates[j][k];
                self.stage_v[k] += h * weight * self.accelerations[j][k];
            }
            if derivatives {
                let scale = h * weight;
                self.d_xi
                    .zip_apply(&self.d_tangent_rates[j], |x, d| *x += scale * d);
                self.d_v
                    .zip_apply(&self.d_accelerations[j], |x, d| *x += scale * d);
            }
        }
    }

    /// The step's result: ξ₁ and v₁ by the weights b (semi-implicit Euler: v₁ = v₀ + h A₁,
    /// ξ₁ = h v₁), q₁ = q₀ ⊕ ξ₁, and A, B.
    fn finish(
        &mut self,
        model: &Model,
        tableau: Option<&Tableau>,
        q: &[f64],
        v: &[f64],
        h: f64,
        derivatives: bool,
    ) -> Result<()> {
        let nv = model.nv;
        match tableau {
            Some(tableau) => self.weighted_sums(tableau.b, h, v, derivatives),
            None => {
                // v₁ = v₀ + h A₁ first, then ξ₁ = h v₁
                self.weighted_sums(&[1.0], h, v, derivatives);
                for k in 0..nv {
                    self.xi[k] = h * self.stage_v[k];
                }
                if derivatives {
                    self.d_xi.copy_from(&self.d_v);
                    self.d_xi *= h;
                }
            }
        }
        self.v_end.copy_from_slice(&self.stage_v);
        model.integrate(q, &self.xi, &mut self.q_end)?;
        if derivatives {
            // dq₁ = ∂(q₀ ⊕ ξ₁)/∂q₀ [1 0 0] + ∂(q₀ ⊕ ξ₁)/∂ξ dξ₁
            let (d_group, d_tangent) = &mut self.group_jacobians;
            integrate_jacobians(model, q, &self.xi, d_group, d_tangent)?;
            multiply(&mut self.d_q, d_tangent, &self.d_xi, 0.0);
            let mut by_start = self.d_q.columns_mut(0, nv);
            by_start += &*d_group;
            for (rows, derivative) in [(0, &self.d_q), (nv, &self.d_v)] {
                self.a
                    .view_mut((rows, 0), (nv, 2 * nv))
                    .copy_from(&derivative.columns(0, 2 * nv));
                self.b
                    .view_mut((rows, 0), (nv, nv))
                    .copy_from(&derivative.columns(2 * nv, nv));
            }
        }
        Ok(())
    }
}

/// out = a b + β out, column by column with nalgebra's `gemv` (its `gemm` packs large operands
/// into a freshly allocated buffer; this stays allocation-free).
fn multiply(out: &mut DMatrix<f64>, a: &DMatrix<f64>, b: &DMatrix<f64>, beta: f64) {
    for (mut column, b_column) in out.column_iter_mut().zip(b.column_iter()) {
        column.gemv(1.0, a, &b_column, beta);
    }
}
