//! Fixed steps in lockstep: fixed-step simulations of one model from several starts advance
//! together, stage by stage, so that each stage's forward dynamics runs for all of them at once,
//! several states per instruction ([`crate::algo::lanes::aba_batch`]); a single simulation's
//! steps are the case of one (its forward dynamics then one call, with its wrenches if any).
//! Everything else is each rollout's own, as in [`super::simulate`]: its controller and passive
//! forces, the divergence guard and its step-doubling checks, the recording. The lanes compute
//! exactly what the one-state ABA computes, so every rollout equals its own `simulate` bit for
//! bit.

use super::{at_time, Simulation, SimulationOptions, Trajectory, STEP_CHECK_INTERVAL};
use crate::algo::lanes::{BatchWorkspace, States};
use crate::error::Error;
use crate::integrate::control::Controller;
use crate::integrate::forward_dynamics::{Aba, ForwardDynamics};
use crate::integrate::schemes::Integrator;
use crate::model::Model;

/// A failed rollout: its index among the starts, and the error its own `simulate` reports.
pub type RolloutError = (usize, Error);

/// Simulates `model` in free space ([`Aba`]) from each start (q₀, v₀) at t = 0 under its own
/// copy of `controller`, as [`super::simulate`] does without wrenches or a progress callback,
/// the rollouts in lockstep. RK45, whose steps each rollout chooses for itself, runs the
/// rollouts one after the other.
pub fn simulate_lockstep<C: Controller + Clone>(
    model: &Model,
    starts: &[(&[f64], &[f64])],
    options: &SimulationOptions,
    controller: &C,
) -> Result<Vec<Trajectory>, RolloutError> {
    simulate_lockstep_with(model, starts, options, &Aba, controller)
}

/// [`simulate_lockstep`] with the forward dynamics `forward`, each rollout with its own copy:
/// in lanes where it has them ([`ForwardDynamics::accelerations_in_lanes`]), else one rollout
/// after another at each stage.
pub fn simulate_lockstep_with<F: ForwardDynamics + Clone, C: Controller + Clone>(
    model: &Model,
    starts: &[(&[f64], &[f64])],
    options: &SimulationOptions,
    forward: &F,
    controller: &C,
) -> Result<Vec<Trajectory>, RolloutError> {
    let mut controllers = vec![controller.clone(); starts.len()];
    let mut simulations = Vec::with_capacity(starts.len());
    for (k, (start, controller)) in starts.iter().zip(&mut controllers).enumerate() {
        let forward = forward.clone();
        let simulation = Simulation::start(model, *start, options, forward, controller, None);
        simulations.push(simulation.map_err(|e| (k, e))?);
    }
    if let Integrator::Rk45 { .. } = options.integrator {
        return simulations
            .into_iter()
            .enumerate()
            .map(|(k, mut simulation)| {
                simulation.run().map_err(|e| (k, e))?;
                Ok(simulation.finish())
            })
            .collect();
    }
    fixed_steps(&mut simulations)?;
    Ok(simulations.into_iter().map(Simulation::finish).collect())
}

/// The fixed steps of `simulations` (one model, one scheme, started together) from sample to
/// sample, in lockstep; every scheme starts from the acceleration recorded at the step's start.
/// The first step, and every `STEP_CHECK_INTERVAL`-th, is checked against two half steps; a
/// divergence reports the step that would keep the motion stable.
pub(super) fn fixed_steps<F: ForwardDynamics>(
    simulations: &mut [Simulation<F>],
) -> Result<(), RolloutError> {
    let Some(first) = simulations.first() else {
        return Ok(());
    };
    let (model, options, samples) = (first.model, first.options, first.samples);
    let mut group = Group::new(model, simulations.len());
    for k in 1..samples {
        let t_next = options.sample_time(k, samples);
        let h = t_next - simulations[0].state.t;
        group
            .step(simulations, k, t_next, h)
            .map_err(|(r, error)| (r, simulations[r].with_suggested_step(error, h)))?;
        for (r, simulation) in simulations.iter_mut().enumerate() {
            simulation.report(k).map_err(|e| (r, e))?;
        }
    }
    Ok(())
}

/// The rollouts' states and accelerations side by side, one row each, and the lanes' workspace.
struct Group {
    workspace: BatchWorkspace,
    q: Vec<f64>,
    v: Vec<f64>,
    tau: Vec<f64>,
    qdd: Vec<f64>,
}

impl Group {
    fn new(model: &Model, rollouts: usize) -> Self {
        Group {
            workspace: BatchWorkspace::new(model),
            q: vec![0.0; rollouts * model.nq],
            v: vec![0.0; rollouts * model.nv],
            tau: vec![0.0; rollouts * model.nv],
            qdd: vec![0.0; rollouts * model.nv],
        }
    }

    /// Every rollout's step to sample `k` at `t_next` (of size `h`), as `fixed_sample` takes
    /// one: the step, its check, then the new sample evaluated, checked and recorded.
    fn step<F: ForwardDynamics>(
        &mut self,
        simulations: &mut [Simulation<F>],
        k: usize,
        t_next: f64,
        h: f64,
    ) -> Result<(), RolloutError> {
        let model = simulations[0].model;
        let integrator = simulations[0].options.integrator;
        match integrator.tableau() {
            Some(tableau) => {
                for simulation in simulations.iter_mut() {
                    simulation.stepper.first_stage(&simulation.state);
                }
                for s in 1..tableau.a.len() {
                    for (r, simulation) in simulations.iter_mut().enumerate() {
                        let Simulation {
                            stepper,
                            state,
                            dynamics,
                            ..
                        } = simulation;
                        let t = stepper
                            .stage_state(model, tableau, state, h, s)
                            .map_err(|e| (r, e))?;
                        let (q, v, _) = stepper.stage_evaluation(s);
                        dynamics.torques(t, q, v).map_err(|e| (r, e))?;
                        self.gather(model, r, (q, v, &dynamics.tau_total));
                    }
                    let t = simulations[0].state.t + tableau.c[s] * h;
                    self.accelerations(simulations, t)?;
                    for (r, simulation) in simulations.iter_mut().enumerate() {
                        let (_, _, a) = simulation.stepper.stage_evaluation(s);
                        a.copy_from_slice(self.row_of_qdd(model, r));
                        simulation.stepper.stage_rate(model, s);
                    }
                }
                for (r, simulation) in simulations.iter_mut().enumerate() {
                    let Simulation { stepper, state, .. } = simulation;
                    stepper
                        .step_result(model, tableau, state, h)
                        .map_err(|e| (r, e))?;
                }
            }
            None => {
                for (r, simulation) in simulations.iter_mut().enumerate() {
                    let Simulation { stepper, state, .. } = simulation;
                    stepper
                        .semi_implicit_euler(model, state, h)
                        .map_err(|e| (r, e))?;
                }
            }
        }
        // the checks and the new samples, evaluated together
        for (r, simulation) in simulations.iter_mut().enumerate() {
            if k == 1 || k.is_multiple_of(STEP_CHECK_INTERVAL) {
                simulation.check_step(h).map_err(|e| (r, e))?;
            }
            simulation.statistics.steps += 1;
            let Simulation {
                stepper,
                sample,
                dynamics,
                ..
            } = simulation;
            sample.t = t_next;
            sample.q.copy_from_slice(&stepper.q_end);
            sample.v.copy_from_slice(&stepper.v_end);
            dynamics
                .torques(t_next, &sample.q, &sample.v)
                .map_err(|e| (r, e))?;
            self.gather(model, r, (&sample.q, &sample.v, &dynamics.tau_total));
        }
        self.accelerations(simulations, t_next)?;
        for (r, simulation) in simulations.iter_mut().enumerate() {
            let Simulation {
                sample,
                dynamics,
                trajectory,
                state,
                ..
            } = simulation;
            sample.a.copy_from_slice(self.row_of_qdd(model, r));
            dynamics
                .keep(trajectory, t_next, &sample.q, &sample.v, &sample.a)
                .map_err(|e| (r, e))?;
            std::mem::swap(state, sample);
        }
        Ok(())
    }

    /// Rollout `r`'s (q, v, τ) into row r.
    fn gather(&mut self, model: &Model, r: usize, (q, v, tau): (&[f64], &[f64], &[f64])) {
        let (nq, nv) = (model.nq, model.nv);
        self.q[r * nq..(r + 1) * nq].copy_from_slice(q);
        self.v[r * nv..(r + 1) * nv].copy_from_slice(v);
        self.tau[r * nv..(r + 1) * nv].copy_from_slice(tau);
    }

    /// q̈ = FD(q, v, τ) of every row, at time `t` (for the error of a failing rollout): in lanes
    /// where the forward dynamics has them, else (or where there is one rollout, or wrenches
    /// act) through each rollout's own.
    fn accelerations<F: ForwardDynamics>(
        &mut self,
        simulations: &mut [Simulation<F>],
        t: f64,
    ) -> Result<(), RolloutError> {
        let model = simulations[0].model;
        let (nq, nv) = (model.nq, model.nv);
        if simulations.len() > 1 && simulations.iter().all(|s| s.dynamics.wrenches.is_none()) {
            let states = States {
                q: &self.q,
                v: Some(&self.v),
                a: None,
                tau: Some(&self.tau),
            };
            let forward = &simulations[0].dynamics.forward;
            if let Some(result) =
                forward.accelerations_in_lanes(model, &mut self.workspace, states, &mut self.qdd)
            {
                return result.map_err(|(r, e)| (r, at_time(t, e)));
            }
        }
        for (r, simulation) in simulations.iter_mut().enumerate() {
            let (q, v) = (&self.q[r * nq..(r + 1) * nq], &self.v[r * nv..(r + 1) * nv]);
            let a = &mut self.qdd[r * nv..(r + 1) * nv];
            simulation
                .dynamics
                .forward_dynamics(t, q, v, a)
                .map_err(|e| (r, e))?;
        }
        Ok(())
    }

    /// Rollout `r`'s q̈.
    fn row_of_qdd(&self, model: &Model, r: usize) -> &[f64] {
        &self.qdd[r * model.nv..(r + 1) * model.nv]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::control::{ControlLaw, DesiredMotion, NativeController};
    use crate::integrate::simulate;
    use crate::io::bundled_model;

    /// Rollouts in lockstep equal their own simulations bit for bit, with each fixed-step scheme
    /// (the step-doubling checks included), and RK45 runs them one by one; a diverging rollout
    /// fails with its own index and `simulate`'s error.
    #[test]
    fn lockstep_rollouts_equal_their_own_simulations() {
        let model = bundled_model("ur5", false).unwrap();
        // gains in proportion to each joint's inertia (the wrist's is small)
        let mut data = crate::Data::new(&model);
        let inertia = crate::algo::crba(&model, &mut data, model.neutral().as_slice())
            .unwrap()
            .diagonal();
        let (kp, kd) = (inertia.scale(100.0), inertia.scale(20.0));
        let law = ControlLaw::Pd {
            kp,
            kd,
            reference: DesiredMotion::Setpoint(model.neutral()),
            gravity_compensation: true,
        };
        let starts: Vec<(Vec<f64>, Vec<f64>)> = (0..7)
            .map(|k| {
                let q = (0..model.nq).map(|j| 0.1 * (k + j) as f64 - 0.2).collect();
                let v = (0..model.nv).map(|j| 0.05 * (k * j) as f64).collect();
                (q, v)
            })
            .collect();
        let borrowed: Vec<(&[f64], &[f64])> =
            starts.iter().map(|(q, v)| (&q[..], &v[..])).collect();
        for name in Integrator::NAMES {
            let integrator = Integrator::from_name(name, 1e-6, 1e-9).unwrap();
            let options = SimulationOptions::new(integrator, 1e-3, 0.12);
            let controller =
                NativeController::new(&model, law.clone(), options.passive, 0.12).unwrap();
            let together = simulate_lockstep(&model, &borrowed, &options, &controller).unwrap();
            for ((q0, v0), run) in borrowed.iter().zip(&together) {
                let mut alone_controller = controller.clone();
                let alone =
                    simulate(&model, q0, v0, &options, &mut alone_controller, None, None).unwrap();
                assert_eq!(run.q, alone.q, "{integrator:?}");
                assert_eq!(run.v, alone.v, "{integrator:?}");
                assert_eq!(run.a, alone.a, "{integrator:?}");
                assert_eq!(run.tau, alone.tau, "{integrator:?}");
                assert_eq!(run.tau_passive, alone.tau_passive, "{integrator:?}");
                assert_eq!(run.statistics, alone.statistics, "{integrator:?}");
                assert_eq!(run.accuracy, alone.accuracy, "{integrator:?}");
            }
        }
        // far too large a step for a stiff PD: the rollout diverges, named as alone
        let stiff = ControlLaw::Pd {
            kp: nalgebra::DVector::from_element(model.nv, 1e7),
            kd: nalgebra::DVector::from_element(model.nv, 0.0),
            reference: DesiredMotion::Setpoint(model.neutral()),
            gravity_compensation: false,
        };
        let options = SimulationOptions::new(Integrator::Rk4, 0.05, 1.0);
        let controller = NativeController::new(&model, stiff, options.passive, 1.0).unwrap();
        let (index, error) =
            simulate_lockstep(&model, &borrowed[2..4], &options, &controller).unwrap_err();
        let mut alone_controller = controller.clone();
        let (q0, v0) = borrowed[2 + index];
        let alone = simulate(&model, q0, v0, &options, &mut alone_controller, None, None);
        assert_eq!(error.to_string(), alone.unwrap_err().to_string());
    }
}
