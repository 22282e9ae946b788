//! The simulation loop: from (q₀, v₀) at t = 0 to `t_end`, recording the state every `dt`.
//!
//! Fixed-step schemes take steps of `dt` (the last one shorter when `dt` does not divide
//! `t_end`). RK45 chooses its own steps (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.4:
//! the initial step from the first two derivatives, then h ← h · min(5, max(0.2, 0.9 err^(−1/5))),
//! never growing right after a rejection) and writes the recording times by dense output.
//! Every recorded sample holds q̈, τ and τ_passive evaluated at that sample's state.
//! After [`simulate`] has allocated its buffers, a step allocates nothing.

use crate::error::{check_vector, Error, Result};
use crate::integrate::control::{Controller, ExternalWrenches};
use crate::integrate::forces::PassiveForces;
use crate::integrate::forward_dynamics::{Aba, ForwardDynamics};
use crate::integrate::schemes::{Integrator, State, Stepper};
use crate::model::Model;
use crate::spatial::Force;
use crate::Data;
use guard::{EnergyAccount, STEP_CHECK_INTERVAL};

mod accuracy;
mod guard;
mod lockstep;

pub use accuracy::{Accuracy, AccuracyIssue, AccuracyMeasure, DEFAULT_ACCURACY_RTOL};
pub use guard::{ENERGY_GROWTH_BOUND, SPEED_BOUND};
pub use lockstep::{simulate_lockstep, simulate_lockstep_with, RolloutError};

/// The most samples one simulation records, so that a tiny `dt` fails clearly instead of
/// exhausting memory.
pub const MAX_SAMPLES: usize = 100_000_000;
/// RK45 fails when its step falls below this times max(1, t): the equations are too stiff or
/// singular for an explicit scheme.
pub const MIN_RELATIVE_STEP: f64 = 1e-14;

/// How to simulate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimulationOptions {
    /// The scheme that integrates the equations of motion.
    pub integrator: Integrator,
    /// Step of the fixed-step schemes and recording interval of all (s), > 0.
    pub dt: f64,
    /// Final time (s), ≥ 0; the simulation starts at t = 0.
    pub t_end: f64,
    /// Largest step RK45 may take (s); infinity for no bound.
    pub max_step: f64,
    /// The passive joint forces: the friction smoothing and what happens at the limits.
    pub passive: PassiveForces,
    /// Tolerance of the fixed-step schemes' accuracy check (local error per step and energy
    /// drift, relative to the state), > 0; see [`Trajectory::accuracy`].
    pub accuracy_rtol: f64,
}

impl SimulationOptions {
    /// `integrator` from 0 to `t_end`, recording every `dt`; default passive forces and no step
    /// bound.
    pub fn new(integrator: Integrator, dt: f64, t_end: f64) -> Self {
        SimulationOptions {
            integrator,
            dt,
            t_end,
            max_step: f64::INFINITY,
            passive: PassiveForces::default(),
            accuracy_rtol: DEFAULT_ACCURACY_RTOL,
        }
    }

    /// Checks every number and returns the number of recorded samples.
    pub fn check(&self) -> Result<usize> {
        positive("dt", self.dt, false)?;
        if !self.t_end.is_finite() || self.t_end < 0.0 {
            return Err(invalid(
                "t_end",
                format!("expected a finite time >= 0, got {}", self.t_end),
            ));
        }
        positive("max_step", self.max_step, true)?;
        positive("rtol", self.accuracy_rtol, false)?;
        if let Integrator::Rk45 { rtol, atol } = self.integrator {
            positive("rtol", rtol, false)?;
            positive("atol", atol, false)?;
        }
        self.passive.check()?;
        let steps = (self.t_end / self.dt - 1e-9).ceil().max(0.0);
        if steps >= MAX_SAMPLES as f64 {
            return Err(invalid(
                "dt",
                format!(
                    "t_end / dt = {} samples, more than the {MAX_SAMPLES} one simulation records",
                    self.t_end / self.dt
                ),
            ));
        }
        Ok(steps as usize + 1)
    }

    /// The time of recorded sample `k` of `samples`: k·dt, and t_end for the last.
    fn sample_time(&self, k: usize, samples: usize) -> f64 {
        if k + 1 == samples {
            self.t_end
        } else {
            k as f64 * self.dt
        }
    }
}

/// How much work a simulation did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Statistics {
    /// Accepted steps.
    pub steps: usize,
    /// Steps RK45 rejected and retried smaller.
    pub rejected_steps: usize,
    /// Evaluations of the equations of motion (forward dynamics and controller calls).
    pub evaluations: usize,
}

/// A recorded simulation: T samples, each row of `q` (T × nq), `v`, `a`, `tau` and `tau_passive`
/// (T × nv) at time `t[k]`. `tau` is the controller's torque, `tau_passive` the joints' own
/// (springs, damping, friction, limits); both act on the robot.
#[derive(Debug, Clone, Default)]
pub struct Trajectory {
    /// Sample times (s): k·dt from 0, the last one `t_end`.
    pub t: Vec<f64>,
    /// Configurations, row by row (T × nq).
    pub q: Vec<f64>,
    /// Velocities, row by row (T × nv).
    pub v: Vec<f64>,
    /// Accelerations q̈ evaluated at each sample's state, row by row (T × nv).
    pub a: Vec<f64>,
    /// The controller's torque at each sample, row by row (T × nv; N·m or N).
    pub tau: Vec<f64>,
    /// The joints' passive torque at each sample, row by row (T × nv; N·m or N).
    pub tau_passive: Vec<f64>,
    /// How much work the run did.
    pub statistics: Statistics,
    /// The fixed-step schemes' error estimates and energy drift, and whether they met
    /// `SimulationOptions::accuracy_rtol`.
    pub accuracy: Accuracy,
}

impl Trajectory {
    fn with_capacity(samples: usize, model: &Model, options: &SimulationOptions) -> Result<Self> {
        let mut trajectory = Trajectory {
            accuracy: Accuracy::new(model, options, samples)?,
            ..Trajectory::default()
        };
        let buffers = [
            (&mut trajectory.t, 1),
            (&mut trajectory.q, model.nq),
            (&mut trajectory.v, model.nv),
            (&mut trajectory.a, model.nv),
            (&mut trajectory.tau, model.nv),
            (&mut trajectory.tau_passive, model.nv),
        ];
        for (buffer, width) in buffers {
            buffer
                .try_reserve_exact(samples * width)
                .map_err(|_| invalid("dt", format!("{samples} samples do not fit in memory")))?;
        }
        Ok(trajectory)
    }

    /// Number of recorded samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether no sample was recorded.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
}

/// The equations of motion q̈(t, q, v): the forward dynamics with the controller, passive forces
/// and wrenches.
struct Dynamics<'a, F> {
    model: &'a Model,
    forward: F,
    passive: PassiveForces,
    controller: &'a mut dyn Controller,
    wrenches: Option<&'a mut dyn ExternalWrenches>,
    data: Data,
    forces: Vec<Force>,
    tau: Vec<f64>,
    tau_passive: Vec<f64>,
    tau_total: Vec<f64>,
    evaluations: usize,
    /// The energy and the work put in so far (the divergence guard).
    energy: EnergyAccount,
}

impl<F: ForwardDynamics> Dynamics<'_, F> {
    /// q̈ = FD(q, v, τ_control + τ_passive, f_ext) into `a`; τ and τ_passive stay in `self`.
    fn acceleration(&mut self, t: f64, q: &[f64], v: &[f64], a: &mut [f64]) -> Result<()> {
        self.torques(t, q, v)?;
        self.forward_dynamics(t, q, v, a)
    }

    /// q̈ = FD(q, v, `tau_total`, `forces`) into `a`, once [`Self::torques`] has run at (t, q, v).
    fn forward_dynamics(&mut self, t: f64, q: &[f64], v: &[f64], a: &mut [f64]) -> Result<()> {
        let f_ext = self.wrenches.is_some().then_some(&self.forces[..]);
        let qdd = self
            .forward
            .acceleration(self.model, &mut self.data, q, v, &self.tau_total, f_ext)
            .map_err(|e| at_time(t, e))?;
        a.copy_from_slice(qdd);
        Ok(())
    }

    /// What acts at (t, q, v), the start of an evaluation of q̈: τ (the controller's) and
    /// τ_passive, their sum in `tau_total`, and the wrenches in `forces`.
    fn torques(&mut self, t: f64, q: &[f64], v: &[f64]) -> Result<()> {
        self.evaluations += 1;
        let model = self.model;
        self.controller.torque(model, t, q, v, &mut self.tau)?;
        check_vector("controller torque", &self.tau, model.nv).map_err(|e| at_time(t, e))?;
        self.passive.torque(model, q, v, &mut self.tau_passive);
        for (total, (control, passive)) in self
            .tau_total
            .iter_mut()
            .zip(self.tau.iter().zip(&self.tau_passive))
        {
            *total = control + passive;
        }
        if let Some(wrenches) = self.wrenches.as_mut() {
            wrenches.wrenches(t, q, v, &mut self.forces)?;
            for force in &self.forces {
                check_vector("external wrench", &force.to_array(), 6).map_err(|e| at_time(t, e))?;
            }
        }
        Ok(())
    }

    /// Evaluates q̈ at (t, q, v) and records the sample with its torques.
    fn record(
        &mut self,
        trajectory: &mut Trajectory,
        t: f64,
        q: &[f64],
        v: &[f64],
        a: &mut [f64],
    ) -> Result<()> {
        self.acceleration(t, q, v, a)?;
        self.keep(trajectory, t, q, v, a)
    }

    /// Checks the sample whose q̈ and torques were just evaluated and adds it to `trajectory`.
    fn keep(
        &mut self,
        trajectory: &mut Trajectory,
        t: f64,
        q: &[f64],
        v: &[f64],
        a: &[f64],
    ) -> Result<()> {
        self.check_sample(t, q, v, a, &mut trajectory.accuracy)?;
        trajectory.t.push(t);
        trajectory.q.extend_from_slice(q);
        trajectory.v.extend_from_slice(v);
        trajectory.a.extend_from_slice(a);
        trajectory.tau.extend_from_slice(&self.tau);
        trajectory.tau_passive.extend_from_slice(&self.tau_passive);
        Ok(())
    }
}

/// A progress callback: the fraction done, in [0, 1].
pub type Progress<'p> = &'p mut dyn FnMut(f64) -> Result<()>;

/// Simulates `model` in free space ([`Aba`]) from (q₀, v₀) at t = 0 under `controller` (and
/// `wrenches`, if any). `progress`, if given, is called with the fraction done about a hundred
/// times; an error it returns stops the simulation with that error.
pub fn simulate<'a>(
    model: &'a Model,
    q0: &[f64],
    v0: &[f64],
    options: &'a SimulationOptions,
    controller: &'a mut dyn Controller,
    wrenches: Option<&'a mut dyn ExternalWrenches>,
    progress: Option<Progress<'a>>,
) -> Result<Trajectory> {
    simulate_with(model, q0, v0, options, Aba, controller, wrenches, progress)
}

/// [`simulate`] with the forward dynamics `forward` (constraints, contacts, or a variant of
/// [`Aba`]) in place of the articulated-body algorithm.
#[allow(clippy::too_many_arguments)]
pub fn simulate_with<'a, F: ForwardDynamics>(
    model: &'a Model,
    q0: &[f64],
    v0: &[f64],
    options: &'a SimulationOptions,
    forward: F,
    controller: &'a mut dyn Controller,
    wrenches: Option<&'a mut dyn ExternalWrenches>,
    progress: Option<Progress<'a>>,
) -> Result<Trajectory> {
    let mut simulation =
        Simulation::start(model, (q0, v0), options, forward, controller, wrenches)?;
    simulation.progress = progress;
    simulation.report(0)?;
    simulation.run()?;
    Ok(simulation.finish())
}

/// Everything one simulation works with.
struct Simulation<'a, F> {
    model: &'a Model,
    options: &'a SimulationOptions,
    samples: usize,
    dynamics: Dynamics<'a, F>,
    stepper: Stepper,
    /// The half steps of the step-doubling check.
    check_stepper: Stepper,
    /// The state at the start of the next step, with its acceleration (the last good state).
    state: State,
    /// A recorded state: the next one of a fixed step, or one between steps (RK45's dense output).
    sample: State,
    /// The state halfway through a step-doubling check, and the Δq it measures.
    middle: State,
    delta: Vec<f64>,
    trajectory: Trajectory,
    progress: Option<Progress<'a>>,
    statistics: Statistics,
}

impl<'a, F: ForwardDynamics> Simulation<'a, F> {
    /// A simulation of `model` from (q₀, v₀) at t = 0, its first sample recorded.
    fn start(
        model: &'a Model,
        (q0, v0): (&[f64], &[f64]),
        options: &'a SimulationOptions,
        forward: F,
        controller: &'a mut dyn Controller,
        wrenches: Option<&'a mut dyn ExternalWrenches>,
    ) -> Result<Self> {
        let samples = options.check()?;
        model
            .check_configuration(q0)
            .map_err(|e| e.for_argument("q0"))?;
        check_vector("v0", v0, model.nv)?;
        let mut simulation = Simulation {
            model,
            options,
            samples,
            dynamics: Dynamics {
                model,
                forward,
                passive: options.passive,
                controller,
                wrenches,
                data: Data::new(model),
                forces: vec![Force::ZERO; model.nbodies() - 1],
                tau: vec![0.0; model.nv],
                tau_passive: vec![0.0; model.nv],
                tau_total: vec![0.0; model.nv],
                evaluations: 0,
                energy: EnergyAccount::new(model),
            },
            stepper: Stepper::new(model),
            check_stepper: Stepper::new(model),
            state: State::new(model),
            sample: State::new(model),
            middle: State::new(model),
            delta: vec![0.0; model.nv],
            trajectory: Trajectory::with_capacity(samples, model, options)?,
            progress: None,
            statistics: Statistics::default(),
        };
        simulation.state.q.copy_from_slice(q0);
        simulation.state.v.copy_from_slice(v0);
        let start = &mut simulation.state;
        simulation.dynamics.record(
            &mut simulation.trajectory,
            0.0,
            &start.q,
            &start.v,
            &mut start.a,
        )?;
        Ok(simulation)
    }

    /// Every step after the first sample, by the options' scheme; an RK45 divergence's message
    /// says what may keep the motion bounded.
    fn run(&mut self) -> Result<()> {
        let Integrator::Rk45 { rtol, atol } = self.options.integrator else {
            return self.fixed_step();
        };
        self.adaptive((rtol, atol)).map_err(|error| match error {
            Error::Diverged { time, message } => Error::Diverged {
                time,
                message: format!(
                    "{message}; if the motion should stay bounded, tighter rtol and atol or a \
                     smaller max_step may keep it so"
                ),
            },
            other => other,
        })
    }

    /// The recorded trajectory with its statistics.
    fn finish(mut self) -> Trajectory {
        self.statistics.evaluations = self.dynamics.evaluations;
        self.trajectory.statistics = self.statistics;
        self.trajectory
    }

    /// Calls the progress callback after sample `k` about a hundred times per run.
    fn report(&mut self, k: usize) -> Result<()> {
        let stride = (self.samples / 100).max(1);
        match self.progress.as_mut() {
            Some(callback) if k.is_multiple_of(stride) || k + 1 == self.samples => {
                callback(k as f64 / (self.samples - 1).max(1) as f64)
            }
            _ => Ok(()),
        }
    }

    /// Steps of dt from sample to sample: [`lockstep::fixed_steps`] of this simulation alone.
    fn fixed_step(&mut self) -> Result<()> {
        lockstep::fixed_steps(std::slice::from_mut(self)).map_err(|(_, error)| error)
    }

    /// Dormand–Prince steps of the size its error estimate allows; samples by dense output.
    fn adaptive(&mut self, tolerances: (f64, f64)) -> Result<()> {
        let model = self.model;
        let tableau = self
            .options
            .integrator
            .tableau()
            .expect("RK45 has a tableau");
        let last_stage = tableau.b.len() - 1;
        let t_end = self.options.t_end;
        let mut h = self.initial_step(tolerances)?;
        let mut rejected_before = false;
        let mut next_sample = 1;
        while next_sample < self.samples {
            let reaches_end = h >= t_end - self.state.t;
            h = h.min(t_end - self.state.t).min(self.options.max_step);
            let dynamics = &mut self.dynamics;
            self.stepper
                .runge_kutta(model, tableau, &self.state, h, &mut |t, q, v, a| {
                    dynamics.acceleration(t, q, v, a)
                })?;
            let error = self
                .stepper
                .error_norm(model, tableau, &self.state, h, tolerances)?;
            // h ← h · min(5, max(0.2, 0.9 err^(−1/5)))
            let factor = (0.9 * error.powf(-0.2)).clamp(0.2, 5.0);
            let accepted = error <= 1.0; // false for a NaN estimate too
            if !accepted {
                self.statistics.rejected_steps += 1;
                rejected_before = true;
                h *= if error.is_finite() { factor } else { 0.2 };
                if h < MIN_RELATIVE_STEP * self.state.t.abs().max(1.0) {
                    return Err(at_time(
                        self.state.t,
                        invalid(
                            "integrator",
                            format!("RK45's step fell to {h:e} s: the equations are too stiff for the tolerances"),
                        ),
                    ));
                }
                continue;
            }
            self.statistics.steps += 1;
            let t_step_end = if reaches_end { t_end } else { self.state.t + h };
            // the samples inside (t, t + h], by dense output
            while next_sample < self.samples
                && self.options.sample_time(next_sample, self.samples) <= t_step_end
            {
                let t_sample = self.options.sample_time(next_sample, self.samples);
                let theta = (t_sample - self.state.t) / h;
                let sample = &mut self.sample;
                self.stepper.dense_output(
                    model,
                    &self.state,
                    h,
                    theta,
                    &mut sample.q,
                    &mut sample.v,
                )?;
                self.dynamics.record(
                    &mut self.trajectory,
                    t_sample,
                    &sample.q,
                    &sample.v,
                    &mut sample.a,
                )?;
                self.report(next_sample)?;
                next_sample += 1;
            }
            // accept: the last stage is q̈ at the new state
            let state = &mut self.state;
            state.t = t_step_end;
            state.q.copy_from_slice(&self.stepper.q_end);
            state.v.copy_from_slice(&self.stepper.v_end);
            state
                .a
                .copy_from_slice(self.stepper.stage_acceleration(last_stage));
            h *= if rejected_before {
                factor.min(1.0)
            } else {
                factor
            };
            rejected_before = false;
        }
        Ok(())
    }

    /// Hairer's starting step: h₀ = 0.01 ‖y₀‖/‖f₀‖, refined by the second derivative estimated
    /// from one Euler step, so that h⁵ · max(‖f₀‖, ‖f′‖) ≈ 0.01 (norms scaled by the tolerances).
    fn initial_step(&mut self, tolerances: (f64, f64)) -> Result<f64> {
        let (rtol, atol) = tolerances;
        let model = self.model;
        let nv = model.nv;
        let state = &self.state;
        let scale = |x: f64| atol + rtol * x.abs();
        let rms = |values: &mut dyn Iterator<Item = f64>| {
            (values.map(|x| x * x).sum::<f64>() / (2 * nv).max(1) as f64).sqrt()
        };
        let size = rms(&mut (0..nv).map(|j| state.v[j] / scale(state.v[j])));
        let rate = rms(&mut (0..nv)
            .map(|j| state.a[j] / scale(state.v[j]))
            .chain((0..nv).map(|j| state.v[j] / atol)));
        let mut h0 = if size < 1e-5 || rate < 1e-5 {
            1e-6
        } else {
            0.01 * size / rate
        };
        h0 = h0
            .min(self.options.max_step)
            .min(self.options.t_end.max(f64::MIN_POSITIVE));
        // one explicit Euler step, y₁ = y₀ + h₀ f₀, for the second derivative
        let sample = &mut self.sample;
        for j in 0..nv {
            sample.v[j] = state.v[j] + h0 * state.a[j];
            self.stepper.xi_end[j] = h0 * state.v[j];
        }
        model.integrate(&state.q, &self.stepper.xi_end, &mut sample.q)?;
        self.dynamics
            .acceleration(h0, &sample.q, &sample.v, &mut sample.a)?;
        let curvature = rms(&mut (0..nv)
            .map(|j| (sample.a[j] - state.a[j]) / scale(state.v[j]))
            .chain((0..nv).map(|j| (sample.v[j] - state.v[j]) / atol)))
            / h0;
        let largest = rate.max(curvature);
        let h1 = if largest <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / largest).powf(0.2)
        };
        Ok((100.0 * h0).min(h1).min(self.options.max_step))
    }
}

pub(crate) fn positive(argument: &str, value: f64, infinity_allowed: bool) -> Result<()> {
    if value > 0.0 && (value.is_finite() || infinity_allowed) {
        return Ok(());
    }
    Err(invalid(
        argument,
        format!("expected a finite number > 0, got {value}"),
    ))
}

pub(crate) fn invalid(argument: &str, message: String) -> Error {
    Error::InvalidValue {
        argument: argument.into(),
        message,
    }
}

/// `error` as it happened during the simulation at time `t`.
fn at_time(t: f64, error: Error) -> Error {
    Error::Simulation {
        time: t,
        message: error.to_string(),
    }
}
