//! Controllers: the joint torque τ(t, q, q̇) applied at every stage of a step, and the external
//! wrenches on bodies.
//!
//! Native control laws ([`ControlLaw`], run by [`NativeController`]):
//! - constant torque τ;
//! - gravity compensation τ = g(q);
//! - PD τ = K_p (q_d ⊖ q) + K_d (v_d − q̇), optionally + g(q);
//! - computed torque (Spong, Hutchinson & Vidyasagar, *Robot Modeling and Control*, §8.3):
//!   τ = M(q) (a_d + K_d (v_d − q̇) + K_p (q_d ⊖ q)) + C(q, q̇) q̇ + g(q) − τ_passive(q, q̇),
//!   one RNEA call. With the model exact, the error e = q_d ⊖ q obeys ë + K_d ė + K_p e = 0.
//!
//! The reference (q_d, v_d, a_d) is a set-point or a sampled motion ([`DesiredMotion`]).

use crate::algo::{generalized_gravity, rnea};
use crate::error::{check_length, check_vector, Error, Result};
use crate::integrate::forces::PassiveForces;
use crate::model::Model;
use crate::spatial::Force;
use crate::Data;
use nalgebra::DVector;

/// Anything that gives the joint torque τ(t, q, q̇) (nv) to apply.
pub trait Controller {
    /// τ(t, q, q̇) into `tau` (nv; N·m or N), at time `t` (s), `q` (nq) and `v` (nv).
    fn torque(
        &mut self,
        model: &Model,
        t: f64,
        q: &[f64],
        v: &[f64],
        tau: &mut [f64],
    ) -> Result<()>;
}

/// Anything that gives external wrenches on the moving bodies at (t, q, q̇): one per body
/// 1..nbodies, in that body's frame, as [`crate::algo::aba()`] takes them.
pub trait ExternalWrenches {
    /// Writes the wrench on each body 1..nbodies into `forces` (nbodies − 1) at (t, q, v).
    fn wrenches(&mut self, t: f64, q: &[f64], v: &[f64], forces: &mut [Force]) -> Result<()>;
}

/// A desired motion q_d(t), v_d(t), a_d(t).
#[derive(Debug, Clone, PartialEq)]
pub enum DesiredMotion {
    /// A fixed configuration (nq); v_d = a_d = 0.
    Setpoint(DVector<f64>),
    /// Knots (t_k, q_k, v_k) joined by cubic Hermite segments in the tangent space at q_k:
    /// q_d = q_k ⊕ ξ(s), ξ(s) = h h₁₀(s) v_k + h₀₁(s) (q_{k+1} ⊖ q_k) + h h₁₁(s) v_{k+1} with
    /// s = (t − t_k)/h, h = t_{k+1} − t_k; v_d and a_d are its first and second time derivatives,
    /// so the three are consistent (exactly so on revolute and prismatic joints). `q` holds the
    /// knots row by row (K × nq), `v` likewise (K × nv).
    Samples {
        /// Knot times t_k (s), at least 2, strictly increasing.
        times: Vec<f64>,
        /// Knot configurations q_k, row by row (K × nq).
        q: Vec<f64>,
        /// Knot velocities v_k, row by row (K × nv).
        v: Vec<f64>,
    },
}

impl DesiredMotion {
    /// Checks sizes, finiteness, valid configurations, increasing times, and that a sampled
    /// reference covers [0, t_end].
    pub fn check(&self, model: &Model, t_end: f64) -> Result<()> {
        match self {
            DesiredMotion::Setpoint(q) => model
                .check_configuration(q.as_slice())
                .map_err(|e| e.for_argument("reference")),
            DesiredMotion::Samples { times, q, v } => {
                check_vector("reference times", times, times.len())?;
                check_length("reference q", q.len(), times.len() * model.nq)?;
                check_vector("reference v", v, times.len() * model.nv)?;
                if times.len() < 2 || times.windows(2).any(|w| w[1] <= w[0]) {
                    return Err(invalid(
                        "reference times",
                        format!("expected at least 2 strictly increasing times, got {times:?}"),
                    ));
                }
                if times[0] > 0.0 || times[times.len() - 1] < t_end {
                    return Err(invalid(
                        "reference times",
                        format!(
                            "expected to cover the simulated interval [0, {t_end}], got [{}, {}]",
                            times[0],
                            times[times.len() - 1]
                        ),
                    ));
                }
                for row in q.chunks_exact(model.nq) {
                    model
                        .check_configuration(row)
                        .map_err(|e| e.for_argument("reference q"))?;
                }
                Ok(())
            }
        }
    }

    /// q_d(t), v_d(t), a_d(t) into the three buffers (nq, nv, nv); `delta` (nv) is scratch.
    fn evaluate(
        &self,
        model: &Model,
        t: f64,
        q_d: &mut [f64],
        v_d: &mut [f64],
        a_d: &mut [f64],
        delta: &mut [f64],
    ) -> Result<()> {
        match self {
            DesiredMotion::Setpoint(q) => {
                q_d.copy_from_slice(q.as_slice());
                v_d.fill(0.0);
                a_d.fill(0.0);
                Ok(())
            }
            DesiredMotion::Samples { times, q, v } => {
                let (nq, nv) = (model.nq, model.nv);
                // the segment [t_k, t_k+1] holding t
                let k = times
                    .partition_point(|&time| time <= t)
                    .clamp(1, times.len() - 1)
                    - 1;
                let h = times[k + 1] - times[k];
                let s = (t - times[k]) / h;
                let (q_k, q_next) = (&q[k * nq..(k + 1) * nq], &q[(k + 1) * nq..(k + 2) * nq]);
                let (v_k, v_next) = (&v[k * nv..(k + 1) * nv], &v[(k + 1) * nv..(k + 2) * nv]);
                model.difference(q_k, q_next, delta)?;
                // Hermite basis h₁₀, h₀₁, h₁₁ and their first and second derivatives in s
                let basis = [
                    s * s * s - 2.0 * s * s + s,
                    -2.0 * s * s * s + 3.0 * s * s,
                    s * s * s - s * s,
                ];
                let rate = [
                    3.0 * s * s - 4.0 * s + 1.0,
                    -6.0 * s * s + 6.0 * s,
                    3.0 * s * s - 2.0 * s,
                ];
                let curvature = [6.0 * s - 4.0, -12.0 * s + 6.0, 6.0 * s - 2.0];
                for j in 0..nv {
                    let terms = [h * v_k[j], delta[j], h * v_next[j]];
                    let combine =
                        |w: &[f64; 3]| w.iter().zip(&terms).map(|(w, x)| w * x).sum::<f64>();
                    v_d[j] = combine(&rate) / h;
                    a_d[j] = combine(&curvature) / (h * h);
                    delta[j] = combine(&basis);
                }
                model.integrate(q_k, delta, q_d)
            }
        }
    }
}

/// A native control law (see the module header for the formulas). Gains are per velocity
/// coordinate (nv).
#[derive(Debug, Clone, PartialEq)]
pub enum ControlLaw {
    /// A constant joint torque (nv); zeros for a passive robot.
    Constant(DVector<f64>),
    /// τ = g(q).
    GravityCompensation,
    /// τ = K_p (q_d ⊖ q) + K_d (v_d − q̇) [+ g(q)].
    Pd {
        /// Proportional gains K_p, one per velocity coordinate (N·m/rad or N/m).
        kp: DVector<f64>,
        /// Derivative gains K_d, one per velocity coordinate (N·m·s/rad or N·s/m).
        kd: DVector<f64>,
        /// The motion (q_d, v_d) to track.
        reference: DesiredMotion,
        /// Whether g(q) is added to the PD torque.
        gravity_compensation: bool,
    },
    /// τ = RNEA(q, q̇, a_d + K_d (v_d − q̇) + K_p (q_d ⊖ q)) − τ_passive(q, q̇).
    ComputedTorque {
        /// Proportional gains K_p, one per velocity coordinate (1/s²: acceleration per error).
        kp: DVector<f64>,
        /// Derivative gains K_d, one per velocity coordinate (1/s).
        kd: DVector<f64>,
        /// The motion (q_d, v_d, a_d) to track.
        reference: DesiredMotion,
    },
}

/// A [`ControlLaw`] with the workspace it needs; allocates only in [`NativeController::new`]
/// (and when cloned, one copy per rollout).
#[derive(Debug, Clone)]
pub struct NativeController {
    law: ControlLaw,
    passive: PassiveForces,
    data: Data,
    tracking: Tracking,
}

/// The reference at the current instant and the error from it.
#[derive(Debug, Clone)]
struct Tracking {
    q_d: Vec<f64>,
    v_d: Vec<f64>,
    a_d: Vec<f64>,
    /// e = q_d ⊖ q (nv); scratch between uses.
    error: Vec<f64>,
}

impl Tracking {
    /// The reference at t into q_d, v_d, a_d, and the tracking error e = q_d ⊖ q.
    fn update(
        &mut self,
        model: &Model,
        reference: &DesiredMotion,
        t: f64,
        q: &[f64],
    ) -> Result<()> {
        reference.evaluate(
            model,
            t,
            &mut self.q_d,
            &mut self.v_d,
            &mut self.a_d,
            &mut self.error,
        )?;
        model.difference(q, &self.q_d, &mut self.error)
    }
}

impl NativeController {
    /// Checks the law against the model (sizes, finite gains, the reference over [0, t_end]).
    /// `passive` is the plant's passive-force model, which computed torque cancels.
    pub fn new(model: &Model, law: ControlLaw, passive: PassiveForces, t_end: f64) -> Result<Self> {
        match &law {
            ControlLaw::Constant(tau) => check_vector("tau", tau.as_slice(), model.nv)?,
            ControlLaw::GravityCompensation => {}
            ControlLaw::Pd {
                kp, kd, reference, ..
            }
            | ControlLaw::ComputedTorque { kp, kd, reference } => {
                check_vector("kp", kp.as_slice(), model.nv)?;
                check_vector("kd", kd.as_slice(), model.nv)?;
                reference.check(model, t_end)?;
            }
        }
        Ok(NativeController {
            law,
            passive,
            data: Data::new(model),
            tracking: Tracking {
                q_d: vec![0.0; model.nq],
                v_d: vec![0.0; model.nv],
                a_d: vec![0.0; model.nv],
                error: vec![0.0; model.nv],
            },
        })
    }
}

impl Controller for NativeController {
    fn torque(
        &mut self,
        model: &Model,
        t: f64,
        q: &[f64],
        v: &[f64],
        tau: &mut [f64],
    ) -> Result<()> {
        match &self.law {
            ControlLaw::Constant(constant) => tau.copy_from_slice(constant.as_slice()),
            ControlLaw::GravityCompensation => {
                tau.copy_from_slice(generalized_gravity(model, &mut self.data, q)?.as_slice())
            }
            ControlLaw::Pd {
                kp,
                kd,
                reference,
                gravity_compensation,
            } => {
                self.tracking.update(model, reference, t, q)?;
                if *gravity_compensation {
                    tau.copy_from_slice(generalized_gravity(model, &mut self.data, q)?.as_slice());
                } else {
                    tau.fill(0.0);
                }
                // τ += K_p e + K_d (v_d − q̇)
                for j in 0..model.nv {
                    tau[j] +=
                        kp[j] * self.tracking.error[j] + kd[j] * (self.tracking.v_d[j] - v[j]);
                }
            }
            ControlLaw::ComputedTorque { kp, kd, reference } => {
                self.tracking.update(model, reference, t, q)?;
                // a* = a_d + K_d (v_d − q̇) + K_p e, kept in a_d
                for j in 0..model.nv {
                    self.tracking.a_d[j] +=
                        kd[j] * (self.tracking.v_d[j] - v[j]) + kp[j] * self.tracking.error[j];
                }
                // τ = RNEA(q, q̇, a*) − τ_passive
                self.passive.torque(model, q, v, &mut self.tracking.error);
                let inverse_dynamics = rnea(model, &mut self.data, q, v, &self.tracking.a_d, None)?;
                for j in 0..model.nv {
                    tau[j] = inverse_dynamics[j] - self.tracking.error[j];
                }
            }
        }
        Ok(())
    }
}

fn invalid(argument: &str, message: String) -> Error {
    Error::InvalidValue {
        argument: argument.into(),
        message,
    }
}
