//! The divergence guard: a simulation that leaves sensible bounds stops with an error that says
//! when, which quantity and joint, and (for fixed steps) the step that would keep it stable,
//! rather than returning a trajectory of garbage. The bounds, in SI units:
//! - q, v and q̈ finite at every recorded sample;
//! - every speed |v_k| ≤ `SPEED_BOUND` (rad/s or m/s);
//! - the energy E = T + V + V_springs (checked every `ENERGY_CHECK_INTERVAL` samples) at most
//!   `ENERGY_GROWTH_BOUND` × (|E₀| + W + 1 J) above E₀, W = ∫ |P_in| dt the work the controller
//!   and the wrenches could have put in (P_in = τ·q̇ + Σ fᵢ·vᵢ); damping, friction and the limit
//!   penalty only take energy out, so a motion that obeys its equations never comes near;
//! - fixed-step schemes, every `STEP_CHECK_INTERVAL` steps: the step compared with two half
//!   steps (step doubling, Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.4): when they disagree
//!   by more than the state's own size, the step is far too large.
//!
//! The same step-doubling checks and energy checks feed the accuracy record
//! ([`super::accuracy`]), which holds a run to a much tighter tolerance but only reports.

use super::{Accuracy, Dynamics, Simulation};
use crate::algo::{kinetic_energy, potential_energy};
use crate::error::{Error, Result};
use crate::integrate::forces::spring_energy;
use crate::integrate::forward_dynamics::ForwardDynamics;
use crate::integrate::schemes::{Integrator, State, Stepper};
use crate::model::Model;

/// The largest speed a simulation may reach, rad/s or m/s.
pub const SPEED_BOUND: f64 = 1e6;
/// How far the energy may rise above its start, in units of (|E₀| + W + 1 J).
pub const ENERGY_GROWTH_BOUND: f64 = 1e6;
/// Samples between two energy checks.
pub const ENERGY_CHECK_INTERVAL: usize = 16;
/// Fixed steps between two step-doubling checks (the first step is always checked).
pub const STEP_CHECK_INTERVAL: usize = 50;
/// A step and two half steps may disagree by at most this fraction of the state's size …
const STEP_DISAGREEMENT_BOUND: f64 = 1.0;
/// … where a state's size is at least this (rad, m, rad/s, m/s).
const STATE_SIZE_FLOOR: f64 = 1.0;
/// The step suggested after a divergence is the largest dt/2ᵏ whose disagreement is below this.
const SUGGESTION_DISAGREEMENT: f64 = 1e-3;
/// At most this many halvings are tried for the suggestion.
const MAX_HALVINGS: usize = 30;

/// What the guard keeps between samples.
#[derive(Debug, Clone)]
pub(super) struct EnergyAccount {
    samples: usize,
    initial_energy: f64,
    /// ∫ |P_in| dt so far, and the last sample's (t, |P_in|).
    work: f64,
    last_power: Option<(f64, f64)>,
    /// Scratch for the springs' displacements (nv).
    displacement: Vec<f64>,
}

impl EnergyAccount {
    pub(super) fn new(model: &Model) -> Self {
        EnergyAccount {
            samples: 0,
            initial_energy: 0.0,
            work: 0.0,
            last_power: None,
            displacement: vec![0.0; model.nv],
        }
    }
}

/// "joint 'name'" of velocity coordinate `k`.
fn joint_of_coordinate<F>(dynamics: &Dynamics<F>, k: usize) -> String {
    let model = dynamics.model;
    let body = (1..model.nbodies())
        .find(|&i| model.v_range(i).contains(&k))
        .unwrap_or(0);
    format!("joint '{}'", model.joint_names[body])
}

fn diverged(t: f64, message: String) -> Error {
    Error::Diverged { time: t, message }
}

impl<F: ForwardDynamics> Dynamics<'_, F> {
    /// The bounds at a recorded sample whose q̈ (and torques, and the body velocities in
    /// `data.v`) were just evaluated; the energy checks go into `accuracy` too.
    pub(super) fn check_sample(
        &mut self,
        t: f64,
        q: &[f64],
        v: &[f64],
        a: &[f64],
        accuracy: &mut Accuracy,
    ) -> Result<()> {
        for (name, values) in [("q", q), ("v", v), ("q̈", a)] {
            if let Some(k) = values.iter().position(|x| !x.is_finite()) {
                let joint = if name == "q" {
                    format!("coordinate {k}")
                } else {
                    joint_of_coordinate(self, k)
                };
                return Err(diverged(
                    t,
                    format!("{name}[{k}] ({joint}) is {}", values[k]),
                ));
            }
        }
        if let Some(k) = v.iter().position(|x| x.abs() > SPEED_BOUND) {
            return Err(diverged(
                t,
                format!(
                    "the speed of {} is {:.3e} (rad/s or m/s), above the bound {SPEED_BOUND:e}",
                    joint_of_coordinate(self, k),
                    v[k]
                ),
            ));
        }
        // P_in = τ·q̇ + Σ fᵢ·vᵢ (body velocities from the forward dynamics just run)
        let mut power: f64 = self.tau.iter().zip(v).map(|(f, x)| f * x).sum();
        if self.wrenches.is_some() {
            power += self
                .forces
                .iter()
                .zip(&self.data.v[1..])
                .map(|(f, body)| f.linear.dot(&body.linear) + f.angular.dot(&body.angular))
                .sum::<f64>();
        }
        let account = &mut self.energy;
        if let Some((t_last, p_last)) = account.last_power {
            account.work += 0.5 * (p_last + power.abs()) * (t - t_last);
        }
        account.last_power = Some((t, power.abs()));
        account.samples += 1;
        if account.samples != 1 && !account.samples.is_multiple_of(ENERGY_CHECK_INTERVAL) {
            return Ok(());
        }
        let kinetic = kinetic_energy(self.model, &mut self.data, q, v)?;
        let stored = potential_energy(self.model, &mut self.data, q)?
            + spring_energy(self.model, q, &mut self.energy.displacement);
        let energy = kinetic + stored;
        let account = &mut self.energy;
        if account.samples == 1 {
            account.initial_energy = energy;
        }
        accuracy.record_energy(
            (account.samples, t),
            kinetic,
            stored,
            account.initial_energy,
            account.work,
        );
        if account.samples == 1 {
            return Ok(());
        }
        let allowed = ENERGY_GROWTH_BOUND * (account.initial_energy.abs() + account.work + 1.0);
        // a NaN energy fails too
        let within = energy - account.initial_energy <= allowed;
        if !within {
            return Err(diverged(
                t,
                format!(
                    "the energy rose from {:.6e} J to {energy:.3e} J, more than {ENERGY_GROWTH_BOUND:e} \
                     times what the start and the work put in ({:.3e} J) explain",
                    account.initial_energy,
                    account.initial_energy.abs() + account.work
                ),
            ));
        }
        Ok(())
    }
}

/// One fixed step of `h` from `start` by `integrator`'s scheme, into `stepper`.
pub(super) fn fixed_step<F: ForwardDynamics>(
    model: &Model,
    integrator: Integrator,
    dynamics: &mut Dynamics<F>,
    stepper: &mut Stepper,
    start: &State,
    h: f64,
) -> Result<()> {
    match integrator.tableau() {
        Some(tableau) => stepper.runge_kutta(model, tableau, start, h, &mut |t, q, v, a| {
            dynamics.acceleration(t, q, v, a)
        }),
        None => stepper.semi_implicit_euler(model, start, h),
    }
}

impl<F: ForwardDynamics> Simulation<'_, F> {
    /// How much the step of `h` just taken (in `self.stepper`) and two half steps from
    /// `self.state` disagree, relative to the size of the state it starts from: max |Δq|, |Δv|
    /// over max(1, |v₀|).
    pub(super) fn step_disagreement(&mut self, h: f64) -> Result<f64> {
        let Simulation {
            model,
            options,
            dynamics,
            stepper,
            check_stepper,
            state,
            middle,
            delta,
            ..
        } = self;
        fixed_step(
            model,
            options.integrator,
            dynamics,
            check_stepper,
            state,
            h / 2.0,
        )?;
        middle.t = state.t + h / 2.0;
        middle.q.copy_from_slice(&check_stepper.q_end);
        middle.v.copy_from_slice(&check_stepper.v_end);
        dynamics.acceleration(middle.t, &middle.q, &middle.v, &mut middle.a)?;
        fixed_step(
            model,
            options.integrator,
            dynamics,
            check_stepper,
            middle,
            h / 2.0,
        )?;
        // Δq = q₁(two halves) ⊖ q₁(one step);  Δv likewise
        model.difference(&stepper.q_end, &check_stepper.q_end, delta)?;
        // the size of the state the step starts from
        let size = state.v.iter().fold(STATE_SIZE_FLOOR, |m, x| m.max(x.abs()));
        let mut difference = delta.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
        for (one, two) in stepper.v_end.iter().zip(&check_stepper.v_end) {
            difference = difference.max((one - two).abs());
        }
        // a NaN disagreement is as bad as an infinite one
        Ok(if difference.is_nan() {
            f64::INFINITY
        } else {
            difference / size
        })
    }

    /// Refuses a fixed step far too large for the dynamics, and records the step's estimated
    /// local error.
    pub(super) fn check_step(&mut self, h: f64) -> Result<()> {
        let disagreement = self.step_disagreement(h)?;
        if disagreement > STEP_DISAGREEMENT_BOUND {
            return Err(diverged(
                self.state.t,
                format!(
                    "dt = {h:e} s is far too large here: one step and two half steps differ by \
                     {disagreement:.1e} times the state's size"
                ),
            ));
        }
        self.trajectory
            .accuracy
            .record_step(self.state.t, h, disagreement);
        Ok(())
    }

    /// `error` with, when the simulation diverged under a fixed step `h`, the largest dt/2ᵏ from
    /// the last good state whose step and half steps agree (step doubling).
    pub(super) fn with_suggested_step(&mut self, error: Error, h: f64) -> Error {
        let Error::Diverged { time, message } = error else {
            return error;
        };
        let mut trial = h;
        for _ in 0..MAX_HALVINGS {
            trial /= 2.0;
            let Simulation {
                model,
                options,
                dynamics,
                stepper,
                state,
                ..
            } = self;
            let agrees = fixed_step(model, options.integrator, dynamics, stepper, state, trial)
                .and_then(|_| self.step_disagreement(trial))
                .is_ok_and(|d| d < SUGGESTION_DISAGREEMENT);
            if agrees {
                return Error::Diverged {
                    time,
                    message: format!(
                        "{message}; a step of about {trial:.1e} s (dt) or less keeps it stable \
                         from the last good state at t = {:.6} s",
                        self.state.t
                    ),
                };
            }
        }
        Error::Diverged {
            time,
            message: format!(
                "{message}; no step down to {trial:.1e} s keeps it stable: the controller or the \
                 model is unstable"
            ),
        }
    }
}
