//! Passive joint forces: what the model's joints do by themselves.
//!
//! ```text
//! τ_passive = −K (q ⊖ q_ref) − D q̇ − F_c tanh(q̇ / v_s) + τ_limit
//! ```
//!
//! - Springs: stiffness K per velocity coordinate, relaxed at `spring_reference` (MJCF `stiffness`
//!   and `springref`; the UR5 dynamics notes' spring potential ½ k (q − q_ref)²). On spherical and free joints
//!   q ⊖ q_ref is the rotation (and displacement) on the group. MJCF's polynomial terms make K
//!   depend on the stretch ([`Model::spring_forces`]).
//! - Viscous damping D (URDF `<dynamics damping>`, MJCF `damping`; with MJCF's polynomial terms
//!   D depends on the speed, [`Model::damper_force`]).
//! - Coulomb friction F_c (URDF `friction`, MJCF `frictionloss`), smoothed: the ideal
//!   −F_c sign(q̇) is discontinuous at rest, which no explicit integrator can follow; tanh(q̇/v_s)
//!   reaches 76 % of F_c at q̇ = v_s and 99.9 % at 4 v_s. A joint held by friction creeps
//!   at a speed of order v_s instead of sticking.
//! - Joint limits ([`LimitModel::Penalty`]): past a limit, a one-sided spring–damper
//!   τ_limit = −k_l δ − b_l q̇ (δ the penetration, signed), clipped so that it only ever pushes
//!   back towards the allowed range. It applies to revolute and prismatic joints with finite
//!   limits; it is a penalty, so a joint driven hard into its limit goes past it by about τ/k_l.

use crate::error::Result;
use crate::integrate::simulator::{invalid, positive};
use crate::model::Model;
use crate::spatial::Mat6;
use nalgebra::DMatrix;

/// Default smoothing speed v_s of Coulomb friction (rad/s or m/s).
pub const DEFAULT_FRICTION_VELOCITY: f64 = 1e-2;
/// Default stiffness of the joint-limit penalty (N·m/rad or N/m).
pub const DEFAULT_LIMIT_STIFFNESS: f64 = 1e4;
/// Default damping of the joint-limit penalty (N·m·s/rad or N·s/m).
pub const DEFAULT_LIMIT_DAMPING: f64 = 1e2;

/// What the simulation does at a joint's position limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LimitModel {
    /// Nothing: limits are only reported (the trajectory shows where q left its range).
    Report,
    /// A one-sided spring–damper past the limit: stiffness (N·m/rad, N/m) and damping.
    Penalty {
        /// Stiffness k_l of the penalty (N·m/rad or N/m), ≥ 0.
        stiffness: f64,
        /// Damping b_l of the penalty (N·m·s/rad or N·s/m), ≥ 0.
        damping: f64,
    },
}

/// The passive-force model: the model's springs, damping and friction, and the limit model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PassiveForces {
    /// Smoothing speed v_s of Coulomb friction, > 0.
    pub friction_velocity: f64,
    /// What the simulation does at the joints' position limits.
    pub limits: LimitModel,
}

impl Default for PassiveForces {
    fn default() -> Self {
        PassiveForces {
            friction_velocity: DEFAULT_FRICTION_VELOCITY,
            limits: LimitModel::Report,
        }
    }
}

impl PassiveForces {
    /// Checks the numbers: a friction velocity > 0, limit stiffness and damping >= 0.
    pub fn check(&self) -> Result<()> {
        positive("friction_velocity", self.friction_velocity, false)?;
        if let LimitModel::Penalty { stiffness, damping } = self.limits {
            for (name, value) in [("limit_stiffness", stiffness), ("limit_damping", damping)] {
                if !value.is_finite() || value < 0.0 {
                    return Err(invalid(
                        name,
                        format!("expected a finite value >= 0, got {value}"),
                    ));
                }
            }
        }
        Ok(())
    }

    /// τ_passive(q, q̇) into `tau` (nv). `q` must be a valid configuration.
    pub fn torque(&self, model: &Model, q: &[f64], v: &[f64], tau: &mut [f64]) {
        // springs: −(k + k₁ s + k₂ s²)(q ⊖ q_ref), with q ⊖ q_ref written into tau first (none
        // without springs: the Lie-group differences are the costly part)
        if model.has_springs() {
            spring_displacement(model, model.spring_reference.as_slice(), q, tau);
            model.spring_forces(tau);
        } else {
            tau.fill(0.0);
        }
        for (k, value) in tau.iter_mut().enumerate() {
            // −(b + b₁ |q̇| + b₂ q̇²) q̇ − f_c tanh(q̇ / v_s), the tanh only where there is friction
            let f_c = model.friction[k];
            let friction = if f_c == 0.0 {
                0.0
            } else {
                f_c * (v[k] / self.friction_velocity).tanh()
            };
            *value += model.damper_force(k, v[k]) - friction;
        }
        if let LimitModel::Penalty { stiffness, damping } = self.limits {
            for (dof, push) in limit_penalties(model, (stiffness, damping), q, v) {
                tau[dof] += push;
            }
        }
    }

    /// ∂τ_passive/∂q (tangent space, right perturbations) and ∂τ_passive/∂q̇ into `d_q` and `d_v`
    /// (nv × nv; block-diagonal by joint). Springs: ∂f/∂d ∂(q ⊖ q_ref)/∂q
    /// ([`Model::joint_spring_slope`], −K without polynomial terms); dampers their slopes
    /// ([`Model::damper_slope`], −D); friction −F_c sech²(q̇/v_s)/v_s; the limit penalty −k_l and −b_l where it pushes (zero where clipped).
    pub fn jacobians(
        &self,
        model: &Model,
        q: &[f64],
        v: &[f64],
        d_q: &mut DMatrix<f64>,
        d_v: &mut DMatrix<f64>,
    ) {
        d_q.as_mut_slice().fill(0.0);
        d_v.as_mut_slice().fill(0.0);
        for i in 1..model.nbodies() {
            let (configuration, dofs) = (model.q_range(i), model.v_range(i));
            // ∂f/∂q = ∂f/∂d ∂(q ⊖ q_ref)/∂q, the joint's block, d = q ⊖ q_ref
            let (mut d_reference, mut d_displacement) = (Mat6::zeros(), Mat6::zeros());
            let reference = &model.spring_reference.as_slice()[configuration.clone()];
            model.joints[i].difference_jacobians(
                reference,
                &q[configuration.clone()],
                &mut d_reference,
                &mut d_displacement,
            );
            let mut displacement = [0.0; 6];
            let nv = dofs.len();
            model.joints[i].difference(reference, &q[configuration], &mut displacement[..nv]);
            let mut slope = Mat6::zeros();
            model.joint_spring_slope(i, &displacement[..nv], &mut slope);
            let spring = slope * d_displacement;
            for (r, row) in dofs.clone().enumerate() {
                for (c, column) in dofs.clone().enumerate() {
                    d_q[(row, column)] = spring[(r, c)];
                }
                // d/dq̇ [−(b + b₁ |q̇| + b₂ q̇²) q̇ − f_c tanh(q̇ / v_s)]
                let slope = (v[row] / self.friction_velocity).tanh();
                d_v[(row, row)] = model.damper_slope(row, v[row])
                    - model.friction[row] * (1.0 - slope * slope) / self.friction_velocity;
            }
        }
        if let LimitModel::Penalty { stiffness, damping } = self.limits {
            // where −k δ − b q̇ pushes back (not clipped to zero), its slopes −k and −b
            for (dof, _) in limit_penalties(model, (stiffness, damping), q, v) {
                d_q[(dof, dof)] -= stiffness;
                d_v[(dof, dof)] -= damping;
            }
        }
    }
}

/// The limit penalty τ_limit = −k δ − b q̇ of each revolute or prismatic joint past a finite
/// limit, as (velocity index, τ_limit) where it pushes back towards the range (elsewhere it is
/// clipped to zero and left out).
fn limit_penalties<'a>(
    model: &'a Model,
    (stiffness, damping): (f64, f64),
    q: &'a [f64],
    v: &'a [f64],
) -> impl Iterator<Item = (usize, f64)> + 'a {
    (1..model.nbodies())
        .filter(|&i| model.joints[i].nq() == 1 && model.joints[i].nv() == 1)
        .filter_map(move |i| {
            let (index_q, index_v) = (model.idx_q[i], model.idx_v[i]);
            let position = q[index_q];
            let (lower, upper) = (
                model.lower_position_limit[index_q],
                model.upper_position_limit[index_q],
            );
            let push = |delta: f64| -stiffness * delta - damping * v[index_v];
            match position {
                p if p > upper => Some(push(p - upper)).filter(|&t| t < 0.0),
                p if p < lower => Some(push(p - lower)).filter(|&t| t > 0.0),
                _ => None,
            }
            .map(|t| (index_v, t))
        })
}

/// The energy stored in the joint springs, Σ (k s²/2 + k₁ s³/3 + k₂ s⁴/4) over their stretches
/// s ([`Model::spring_energy_at`]); `scratch` (nv) holds q ⊖ q_ref.
pub fn spring_energy(model: &Model, q: &[f64], scratch: &mut [f64]) -> f64 {
    spring_displacement(model, model.spring_reference.as_slice(), q, scratch);
    model.spring_energy_at(scratch)
}

/// q ⊖ q_ref, joint by joint on its group, into `out` (nv): `reference` is q_ref (nq).
pub(crate) fn spring_displacement(model: &Model, reference: &[f64], q: &[f64], out: &mut [f64]) {
    for i in 1..model.nbodies() {
        let (configuration, dofs) = (model.q_range(i), model.v_range(i));
        model.joints[i].difference(
            &reference[configuration.clone()],
            &q[configuration],
            &mut out[dofs],
        );
    }
}
