//! Accuracy you can see: a fixed-step run estimates the local error of its steps and, while
//! nothing puts energy in or takes it out, how far its energy drifts; past the tolerance `rtol`
//! its trajectory carries an [`AccuracyIssue`] saying from when, how large, and the step that
//! would meet the tolerance.
//!
//! - Local error by step doubling (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.4): a scheme
//!   of order p errs by C h^(p+1) per step, so one step and two half steps differ by
//!   Δ = C h^(p+1) (1 − 2^(−p)), and the step taken (the single one) errs by
//!   e = Δ 2^p / (2^p − 1). Relative to the state's size (the divergence guard's, max(1, ‖v₀‖∞)),
//!   e ≤ rtol holds for every step h′ ≤ h (rtol / e)^(1/(p+1)).
//! - Energy drift: with no damping, friction, limit penalty, controller torque or wrench, the
//!   energy E = T + V + V_springs is conserved, so |E − E₀| is the scheme's error. It is measured
//!   against the largest kinetic energy reached (the energy in motion; E₀ has an arbitrary zero)
//!   and, a global error, scales as h^p: h′ ≤ h (rtol / drift)^(1/p).
//!
//! RK45 keeps every step's error below its own tolerances by rejecting the steps that miss them,
//! so it records no estimate and raises no issue.

use super::{SimulationOptions, STEP_CHECK_INTERVAL};
use crate::error::Result;
use crate::integrate::forces::{LimitModel, PassiveForces};
use crate::integrate::schemes::Integrator;
use crate::model::Model;
use std::fmt;

/// The default tolerance of the accuracy check: local error per step, and energy drift, relative
/// to the state.
pub const DEFAULT_ACCURACY_RTOL: f64 = 1e-3;
/// The suggested step is this fraction of the one the asymptotic law h^(p+1) or h^p gives, as
/// step size controllers keep a margin (Hairer, Nørsett & Wanner, §II.4); a wider one than their
/// 0.9, for the law is only approximate at a step far too large (the UR5's swing at dt = 0.05 s
/// drifts 0.19 where h^4 from its 8.5e-4 at dt = 0.01 s predicts 0.53).
const STEP_SAFETY: f64 = 0.7;
/// The energy's own rounding: a drift below this fraction of |T| + |V| is no drift (a robot at
/// rest has no energy in motion to compare with).
const ENERGY_ROUNDING: f64 = 1e-12;

/// Which measure missed the tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AccuracyMeasure {
    /// A step's local error, estimated by step doubling, relative to the state's size.
    LocalError,
    /// |E − E₀| of a conservative system, relative to the largest kinetic energy.
    EnergyDrift,
}

/// A fixed-step run less accurate than its tolerance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AccuracyIssue {
    /// The measure that asks for the smallest step.
    pub measure: AccuracyMeasure,
    /// The first time (s) a measure exceeded the tolerance.
    pub time: f64,
    /// The measure's largest value (relative, to compare with `rtol`).
    pub error: f64,
    /// The tolerance the run missed.
    pub rtol: f64,
    /// The step the run took (s).
    pub dt: f64,
    /// The largest step that meets the tolerance, with a safety margin (s).
    pub largest_step: f64,
}

impl fmt::Display for AccuracyIssue {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let what = match self.measure {
            AccuracyMeasure::LocalError => "a step's estimated local error reached",
            AccuracyMeasure::EnergyDrift => {
                "with nothing putting energy in or taking it out, the energy drifted by"
            }
        };
        let of = match self.measure {
            AccuracyMeasure::LocalError => "the state's size",
            AccuracyMeasure::EnergyDrift => "the largest kinetic energy",
        };
        write!(
            f,
            "dt = {:.3e} s misses rtol = {:.1e} from t = {:.6} s: {what} {:.2e} of {of}; a step of \
             about {:.1e} s or less meets the tolerance",
            self.dt, self.rtol, self.time, self.error, self.largest_step
        )
    }
}

/// What a run measured of its own accuracy.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Accuracy {
    /// The tolerance the run was checked against.
    pub rtol: f64,
    /// The start of each step that step doubling checked (s); empty for RK45.
    pub check_times: Vec<f64>,
    /// Each checked step's estimated local error relative to the state's size; empty for RK45.
    pub local_errors: Vec<f64>,
    /// The largest |E − E₀| relative to the largest kinetic energy, over the energy checks made
    /// while the system was conservative; None if it never was (or for RK45).
    pub energy_drift: Option<f64>,
    /// Set when a measure exceeded `rtol`.
    pub issue: Option<AccuracyIssue>,
    /// The fixed step and the scheme's order; None for RK45, which is not checked.
    scheme: Option<(f64, i32)>,
    /// Whether the model's passive forces conserve energy (no damping, friction or penalty).
    passive_conservative: bool,
    largest_kinetic: f64,
}

impl Accuracy {
    /// An empty record for a run of `samples` samples under `options`, with room for every check.
    pub(super) fn new(model: &Model, options: &SimulationOptions, samples: usize) -> Result<Self> {
        let scheme = match options.integrator {
            Integrator::Rk45 { .. } => None,
            fixed => Some((options.dt, fixed.order())),
        };
        let mut accuracy = Accuracy {
            rtol: options.accuracy_rtol,
            scheme,
            passive_conservative: conserves_energy(model, &options.passive),
            ..Accuracy::default()
        };
        // the first step and every STEP_CHECK_INTERVAL-th
        let checks = samples / STEP_CHECK_INTERVAL + 1;
        for buffer in [&mut accuracy.check_times, &mut accuracy.local_errors] {
            buffer.try_reserve_exact(checks).map_err(|_| {
                super::invalid("dt", format!("{samples} samples do not fit in memory"))
            })?;
        }
        Ok(accuracy)
    }

    /// Records the step-doubling check of the step of `h` from `t`, whose single step and two
    /// half steps disagree by `disagreement` (relative to the state's size).
    pub(super) fn record_step(&mut self, t: f64, h: f64, disagreement: f64) {
        let Some((dt, order)) = self.scheme else {
            return;
        };
        // e = Δ 2^p / (2^p − 1)
        let doubling = 2f64.powi(order);
        let error = disagreement * doubling / (doubling - 1.0);
        self.check_times.push(t);
        self.local_errors.push(error);
        if error > self.rtol {
            // h′ = h (rtol / e)^(1/(p+1))
            let step = h * (self.rtol / error).powf(1.0 / f64::from(order + 1));
            self.note(AccuracyMeasure::LocalError, (t, dt), error, step);
        }
    }

    /// Records the energy at the energy check of sample `sample` at `t`: `kinetic` + `stored`
    /// (gravity and springs), against `initial` (E₀, sample 1's). `work` is the work the
    /// controller and wrenches have done so far.
    pub(super) fn record_energy(
        &mut self,
        (sample, t): (usize, f64),
        kinetic: f64,
        stored: f64,
        initial: f64,
        work: f64,
    ) {
        let Some((dt, order)) = self.scheme else {
            return;
        };
        // conservative so far: nothing has put energy in or taken it out
        if !self.passive_conservative || work != 0.0 {
            return;
        }
        self.largest_kinetic = self.largest_kinetic.max(kinetic);
        if sample == 1 {
            return;
        }
        let rounding = ENERGY_ROUNDING * (kinetic.abs() + stored.abs());
        let drift = (kinetic + stored - initial).abs();
        let relative = if drift <= rounding {
            0.0
        } else {
            drift / self.largest_kinetic.max(rounding)
        };
        self.energy_drift = Some(self.energy_drift.map_or(relative, |d| d.max(relative)));
        if relative > self.rtol {
            // h′ = h (rtol / drift)^(1/p)
            let step = dt * (self.rtol / relative).powf(1.0 / f64::from(order));
            self.note(AccuracyMeasure::EnergyDrift, (t, dt), relative, step);
        }
    }

    /// Keeps the first time `t` a measure missed the tolerance under the fixed step `dt`, and the
    /// measure asking for the smallest step, with a safety margin.
    fn note(&mut self, measure: AccuracyMeasure, (t, dt): (f64, f64), error: f64, step: f64) {
        let largest_step = STEP_SAFETY * step;
        match &mut self.issue {
            Some(issue) if issue.largest_step <= largest_step => {}
            Some(issue) => {
                issue.measure = measure;
                issue.error = error;
                issue.largest_step = largest_step;
            }
            None => {
                self.issue = Some(AccuracyIssue {
                    measure,
                    time: t,
                    error,
                    rtol: self.rtol,
                    dt,
                    largest_step,
                })
            }
        }
    }
}

/// Whether the passive forces keep the energy E = T + V + V_springs: no damping or friction on
/// any joint and no limit penalty (springs are part of E).
fn conserves_energy(model: &Model, passive: &PassiveForces) -> bool {
    !model.has_dampers()
        && model.friction.iter().all(|f| *f == 0.0)
        && passive.limits == LimitModel::Report
}
