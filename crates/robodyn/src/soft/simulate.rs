//! A scene simulated as MuJoCo simulates it: [`SceneStep`] repeated from (q₀, v₀) at t = 0,
//! the controls u(t, q, v) and the applied forces τ(t, q, v) asked at each step's start and held
//! over it (MuJoCo's `ctrl` and `qfrc_applied` set before each `mj_step`), every
//! `record_every`-th state recorded with what the forward dynamics found there.

use super::step::SceneStep;
use crate::collision::Contact;
use crate::error::{check_vector, Error, Result};
use crate::integrate::simulator::Progress;
use crate::integrate::{Controller, Trajectory};
use crate::model::Model;

/// Anything that gives the actuators' controls at (t, q, q̇).
pub trait Controls {
    /// Writes the controls (nu) at time `t` (s), `q` (nq) and `v` (nv) into `ctrl`.
    fn controls(
        &mut self,
        model: &Model,
        t: f64,
        q: &[f64],
        v: &[f64],
        ctrl: &mut [f64],
    ) -> Result<()>;
}

/// The same controls at every instant.
#[derive(Debug, Clone, PartialEq)]
pub struct FixedControls(pub Vec<f64>);

impl Controls for FixedControls {
    fn controls(
        &mut self,
        _: &Model,
        _: f64,
        _: &[f64],
        _: &[f64],
        ctrl: &mut [f64],
    ) -> Result<()> {
        ctrl.copy_from_slice(&self.0);
        Ok(())
    }
}

/// A recorded scene simulation: the [`Trajectory`] (`tau` the applied forces plus the actuators'
/// `qfrc_actuator`, `tau_passive` the springs' and dampers', `a` the soft model's q̈) and, per
/// sample, the controls (T × nu), the activations (T × na), the constraints' forces Jᵀ f (T × nv)
/// and the contacts with their forces.
#[derive(Debug, Clone, Default)]
pub struct SceneTrajectory {
    /// t, q, v, a, tau, tau_passive and the work done (steps, evaluations).
    pub trajectory: Trajectory,
    /// The controls, row by row (T × nu).
    pub ctrl: Vec<f64>,
    /// The actuators' activations (MuJoCo's `act`), row by row (T × na).
    pub act: Vec<f64>,
    /// The plastic springs' references (MuJoCo's `plastic`), row by row (T × nplastic).
    pub plastic: Vec<f64>,
    /// The constraints' generalised forces (MuJoCo's `qfrc_constraint`), row by row (T × nv).
    pub tau_constraint: Vec<f64>,
    /// Per sample, its contacts and each one's force in its frame
    /// ([`super::rows::Rows::contact_force`]).
    pub contacts: Vec<Vec<(Contact, [f64; 6])>>,
}

/// How long a scene simulation runs and what it keeps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneRun {
    /// Steps of the scene's time step.
    pub steps: usize,
    /// A sample every this many steps (and the last state).
    pub record_every: usize,
    /// The time of the first state (s): a keyframe's `time`, else 0.
    pub start: f64,
}

/// Simulates `model`'s scene from (q₀, v₀), the activations w₀ (na) and the plastic state p₀
/// (nplastic, [`crate::model::plastic`]) at `run.start` over `run.steps` steps under `controls`
/// and the applied forces of `controller`. `progress`, if given, is called with the fraction
/// done about a hundred times; an error it returns stops the simulation with that error.
pub fn simulate_scene(
    model: &Model,
    (q0, v0, act0, plastic0): (&[f64], &[f64], &[f64], &[f64]),
    run: SceneRun,
    controller: &mut dyn Controller,
    controls: &mut dyn Controls,
    mut progress: Option<Progress>,
) -> Result<SceneTrajectory> {
    model.check_configuration(q0)?;
    check_vector("v0", v0, model.nv)?;
    check_vector("act0", act0, model.na())?;
    model.check_plastic("plastic0", plastic0)?;
    if run.record_every == 0 {
        return Err(Error::InvalidValue {
            argument: "record_every".into(),
            message: "expected a positive number of steps".into(),
        });
    }
    let h = model.options.timestep;
    let mut stepper = SceneStep::new(model)?;
    let (mut q, mut v) = (q0.to_vec(), v0.to_vec());
    let (mut act, mut plastic) = (act0.to_vec(), plastic0.to_vec());
    let (mut tau, mut ctrl) = (vec![0.0; model.nv], vec![0.0; model.nu()]);
    let mut out = SceneTrajectory::default();
    let report_every = (run.steps / 100).max(1);
    for k in 0..=run.steps {
        let t = run.start + k as f64 * h;
        controls.controls(model, t, &q, &v, &mut ctrl)?;
        controller.torque(model, t, &q, &v, &mut tau)?;
        let recorded = k % run.record_every == 0 || k == run.steps;
        if recorded {
            out.trajectory.t.push(t);
            out.trajectory.q.extend_from_slice(&q);
            out.trajectory.v.extend_from_slice(&v);
            out.act.extend_from_slice(&act);
            out.plastic.extend_from_slice(&plastic);
        }
        if k == run.steps {
            stepper.forward_only(model, (&q, &v, &act, &plastic), &tau, &ctrl)?;
        } else {
            let state = (&mut q[..], &mut v[..], &mut act[..], &mut plastic[..]);
            stepper.step(model, t, state, &tau, &ctrl)?;
        }
        if recorded {
            record(&mut out, &stepper, &tau, &ctrl);
        }
        if let Some(report) = progress.as_mut() {
            if k % report_every == 0 {
                report(k as f64 / run.steps.max(1) as f64)?;
            }
        }
    }
    let statistics = &mut out.trajectory.statistics;
    statistics.steps = run.steps;
    statistics.evaluations = stepper.evaluations();
    Ok(out)
}

/// One sample's forces from the forward dynamics at its state.
fn record(out: &mut SceneTrajectory, stepper: &SceneStep, tau: &[f64], ctrl: &[f64]) {
    let forward = &stepper.forward;
    let trajectory = &mut out.trajectory;
    trajectory
        .a
        .extend_from_slice(forward.solution.acceleration.as_slice());
    trajectory
        .tau
        .extend(tau.iter().zip(forward.actuator.iter()).map(|(a, b)| a + b));
    trajectory
        .tau_passive
        .extend_from_slice(forward.passive.as_slice());
    out.ctrl.extend_from_slice(ctrl);
    out.tau_constraint
        .extend_from_slice(forward.constraint.as_slice());
    let forces = &forward.solution.forces;
    let contacts = forward.contacts.iter().enumerate();
    out.contacts.push(
        contacts
            .map(|(c, contact)| (*contact, forward.rows.contact_force(forces, c)))
            .collect(),
    );
}
