//! Running a simulation's rollouts: native ones with the GIL released (in lockstep or in
//! parallel), those with Python callbacks one after another.

use super::arguments::{Control, Simulation, Wrenches};
use super::callbacks::{keep_raised, ConstantWrenches, PythonController, PythonWrenches, Raised};
use crate::to_py_err;
use pyo3::prelude::*;
use rayon::prelude::*;
use robodyn::integrate::simulator::Progress;
use robodyn::integrate::{
    simulate as run, simulate_lockstep, simulate_with, Constrained, Controller, ExternalWrenches,
    NativeController, SimulationOptions, Trajectory,
};
use robodyn::{Error, Model};

/// The rollouts of a `simulate` call: what every thread needs (nothing of Python in it).
pub(super) struct Rollouts<'a> {
    pub(super) model: &'a Model,
    pub(super) options: SimulationOptions,
    /// The initial states, one row of q0 and of v0 per rollout.
    pub(super) q0: Vec<f64>,
    pub(super) v0: Vec<f64>,
    /// The batch size, `None` for a single state.
    pub(super) batch: Option<usize>,
    /// The constrained forward dynamics, or `None` for a tree in free space (ABA).
    pub(super) constrained: Option<Constrained>,
}

impl Rollouts<'_> {
    fn count(&self) -> usize {
        self.batch.unwrap_or(1)
    }

    /// The initial state of rollout `k`.
    fn start(&self, k: usize) -> (&[f64], &[f64]) {
        let (nq, nv) = (self.model.nq, self.model.nv);
        (
            &self.q0[k * nq..(k + 1) * nq],
            &self.v0[k * nv..(k + 1) * nv],
        )
    }

    /// Rollout `k` with its forward dynamics: ABA, or the constraints'.
    fn simulate_one<'a>(
        &'a self,
        k: usize,
        controller: &'a mut dyn Controller,
        wrenches: Option<&'a mut dyn ExternalWrenches>,
        progress: Option<Progress<'a>>,
    ) -> robodyn::Result<Trajectory> {
        let (model, options) = (self.model, &self.options);
        let (q, v) = self.start(k);
        let result = match &self.constrained {
            None => run(model, q, v, options, controller, wrenches, progress),
            Some(constrained) => {
                let forward = constrained.clone();
                simulate_with(
                    model, q, v, options, forward, controller, wrenches, progress,
                )
            }
        };
        result.map_err(|e| self.error(k, e))
    }

    /// Names the rollout of a batch that failed.
    fn error(&self, k: usize, error: Error) -> Error {
        match (self.batch, error) {
            (Some(_), Error::Simulation { time, message }) => Error::Simulation {
                time,
                message: format!("rollout {k}: {message}"),
            },
            (Some(_), Error::Diverged { time, message }) => Error::Diverged {
                time,
                message: format!("rollout {k}: {message}"),
            },
            (_, error) => error,
        }
    }

    /// All native, no wrenches: a group of rollouts per thread in lockstep (their forward
    /// dynamics in lanes).
    fn run_lockstep(&self, native: &NativeController) -> robodyn::Result<Vec<Trajectory>> {
        let count = self.count();
        let group = count.div_ceil(rayon::current_num_threads()).max(1);
        let firsts: Vec<usize> = (0..count).step_by(group).collect();
        let groups: Vec<Vec<Trajectory>> = firsts
            .into_par_iter()
            .map(|first| {
                let starts: Vec<_> = (first..count.min(first + group))
                    .map(|k| self.start(k))
                    .collect();
                simulate_lockstep(self.model, &starts, &self.options, native)
                    .map_err(|(r, e)| self.error(first + r, e))
            })
            .collect::<robodyn::Result<_>>()?;
        Ok(groups.into_iter().flatten().collect())
    }

    /// All native: the rollouts in parallel.
    fn run_native(
        &self,
        native: &NativeController,
        constant: Option<&ConstantWrenches>,
    ) -> robodyn::Result<Vec<Trajectory>> {
        (0..self.count())
            .into_par_iter()
            .map(|k| {
                let mut controller = native.clone();
                let mut wrenches = constant.cloned();
                let wrenches = wrenches.as_mut().map(|w| w as &mut dyn ExternalWrenches);
                self.simulate_one(k, &mut controller, wrenches, None)
            })
            .collect()
    }
}

impl<'py> Simulation<'_, 'py> {
    /// Runs every rollout: native ones with the GIL released, in parallel, those with Python
    /// callbacks one after another with the GIL.
    pub(super) fn run(&self, py: Python<'py>) -> PyResult<Vec<Trajectory>> {
        let rollouts = &self.rollouts;
        let native = match (&self.controller, &self.wrenches, self.progress) {
            (Control::Native(native), Wrenches::None | Wrenches::Constant(_), None) => native,
            _ => return self.run_with_callbacks(py),
        };
        let result = match &self.wrenches {
            Wrenches::Constant(constant) => {
                py.detach(|| rollouts.run_native(native, Some(constant)))
            }
            _ if rollouts.count() > 1 && rollouts.constrained.is_none() => {
                py.detach(|| rollouts.run_lockstep(native))
            }
            _ => py.detach(|| rollouts.run_native(native, None)),
        };
        result.map_err(to_py_err)
    }

    /// Runs the rollouts one after another with the GIL, calling back into Python; a Python
    /// exception raised in a callback is re-raised as it was.
    fn run_with_callbacks(&self, py: Python<'py>) -> PyResult<Vec<Trajectory>> {
        let rollouts = &self.rollouts;
        let m = rollouts.model;
        let count = rollouts.count();
        let mut runs = Vec::with_capacity(count);
        for k in 0..count {
            let (mut native, mut python) = (None, None);
            let controller: &mut dyn Controller = match &self.controller {
                Control::Native(controller) => native.insert(NativeController::clone(controller)),
                Control::Python(callable) => python.insert(PythonController {
                    callable: callable.clone(),
                    raised: None,
                }),
            };
            let (mut fixed_wrenches, mut callable_wrenches) = (None, None);
            let wrenches: Option<&mut dyn ExternalWrenches> = match &self.wrenches {
                Wrenches::None => None,
                Wrenches::Constant(wrenches) => Some(fixed_wrenches.insert(wrenches.clone())),
                Wrenches::Python(callable) => Some(callable_wrenches.insert(PythonWrenches {
                    callable: callable.clone(),
                    buffer: vec![0.0; (m.nbodies() - 1) * 6],
                    raised: None,
                })),
            };
            let mut progress_raised: Raised = None;
            let mut report = |fraction: f64| -> robodyn::Result<()> {
                let result = py.check_signals().and_then(|_| match self.progress {
                    Some(callback) => callback
                        .call1(((k as f64 + fraction) / count as f64,))
                        .map(|_| ()),
                    None => Ok(()),
                });
                keep_raised(&mut progress_raised, result, fraction)
            };
            let result = rollouts.simulate_one(k, controller, wrenches, Some(&mut report));
            let raised = python
                .and_then(|p| p.raised)
                .or(callable_wrenches.and_then(|w| w.raised))
                .or(progress_raised);
            if let Some(error) = raised {
                return Err(error);
            }
            runs.push(result.map_err(to_py_err)?);
        }
        Ok(runs)
    }
}
