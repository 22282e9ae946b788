//! `simulate_scene` and `step_scene`: a scene stepped as MuJoCo steps it
//! (`robodyn::soft::simulate`), for `robodyn.simulate` and `robodyn.step` with
//! `integrator="mujoco"`. Native controls and controllers run with the GIL released (batches on
//! all cores); Python callables are called back with the GIL.

use super::arguments::{initial_states, read_controller, Control};
use super::callbacks::{call_back, keep_raised, PythonController, Raised};
use super::record::stack;
use crate::args::{Argument, SampleShape};
use crate::model::PyModel;
use crate::scene::contact_dicts;
use crate::to_py_err;
use numpy::{PyArray1, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use robodyn::integrate::{Controller, PassiveForces, Trajectory};
use robodyn::soft::simulate::{
    simulate_scene as run, Controls, FixedControls, SceneRun, SceneTrajectory,
};
use robodyn::soft::step::SceneStep;
use robodyn::{Error, Model};

/// Simulates `model`'s scene from `q0`, `v0` (one state, or N: shape (N, nq), (N, nv)), the
/// activations `act0` (None: zeros; na, or (N, na)) and the plastic springs' references
/// `plastic0` (None: the model's; nplastic, or (N, nplastic)) at time `start` over `steps` of its time
/// step, recording every `record_every`-th. `ctrl`: None (zeros), the controls (nu, or (N, nu))
/// or a callable `(t, q, v) -> ctrl`; `controller` as in `simulate`.
#[pyfunction]
#[pyo3(signature = (model, q0, v0, steps, record_every, start=0.0, ctrl=None, controller=None, progress=None, act0=None, plastic0=None))]
#[allow(clippy::too_many_arguments)]
pub fn simulate_scene<'py>(
    py: Python<'py>,
    model: &PyModel,
    q0: &Bound<'py, PyAny>,
    v0: &Bound<'py, PyAny>,
    steps: usize,
    record_every: usize,
    start: f64,
    ctrl: Option<&Bound<'py, PyAny>>,
    controller: Option<&Bound<'py, PyAny>>,
    progress: Option<&Bound<'py, PyAny>>,
    act0: Option<&Bound<'py, PyAny>>,
    plastic0: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = &model.model;
    let (q0, v0, batch) = initial_states(model, q0, v0)?;
    let count = batch.unwrap_or(1);
    let controls = read_controls(m, ctrl, count)?;
    let act0 = per_rollout("act0", act0, m.na(), count)?;
    let plastic0 = match plastic0 {
        Some(_) => per_rollout("plastic0", plastic0, m.nplastic(), count)?,
        None => vec![m.initial_plastic(); count],
    };
    let t_end = start + steps as f64 * m.options.timestep;
    let control = read_controller(m, controller, PassiveForces::default(), t_end)?;
    let (q0, v0) = (q0.values().into_owned(), v0.values().into_owned());
    let initial = |k: usize| {
        (
            &q0[k * m.nq..(k + 1) * m.nq],
            &v0[k * m.nv..(k + 1) * m.nv],
            act0[k].as_slice(),
            plastic0[k].as_slice(),
        )
    };
    let scene = SceneRun {
        steps,
        record_every,
        start,
    };
    let named = |k: usize, error: Error| match (batch, error) {
        (Some(_), Error::Simulation { time, message }) => Error::Simulation {
            time,
            message: format!("rollout {k}: {message}"),
        },
        (_, error) => error,
    };
    let runs: Vec<SceneTrajectory> = match (&controls, &control, progress) {
        (SceneControls::Fixed(fixed), Control::Native(native), None) => py
            .detach(|| {
                (0..count)
                    .into_par_iter()
                    .map(|k| {
                        let (mut native, mut fixed) = (native.as_ref().clone(), fixed[k].clone());
                        run(m, initial(k), scene, &mut native, &mut fixed, None)
                            .map_err(|e| named(k, e))
                    })
                    .collect::<robodyn::Result<_>>()
            })
            .map_err(to_py_err)?,
        _ => {
            let mut runs = Vec::with_capacity(count);
            for k in 0..count {
                let (mut native, mut python) = (None, None);
                let controller: &mut dyn Controller = match &control {
                    Control::Native(controller) => native.insert(controller.as_ref().clone()),
                    Control::Python(callable) => python.insert(PythonController {
                        callable: callable.clone(),
                        raised: None,
                    }),
                };
                let (mut fixed, mut python_controls) = (None, None);
                let inputs: &mut dyn Controls = match &controls {
                    SceneControls::Fixed(rows) => fixed.insert(rows[k].clone()),
                    SceneControls::Python(callable) => python_controls.insert(PythonControls {
                        callable: callable.clone(),
                        raised: None,
                    }),
                };
                let mut progress_raised: Raised = None;
                let mut report = |fraction: f64| -> robodyn::Result<()> {
                    let result = py.check_signals().and_then(|_| match progress {
                        Some(callback) => callback
                            .call1(((k as f64 + fraction) / count as f64,))
                            .map(|_| ()),
                        None => Ok(()),
                    });
                    keep_raised(&mut progress_raised, result, fraction)
                };
                let result = run(m, initial(k), scene, controller, inputs, Some(&mut report));
                let raised = python
                    .and_then(|p| p.raised)
                    .or(python_controls.and_then(|p| p.raised))
                    .or(progress_raised);
                if let Some(error) = raised {
                    return Err(error);
                }
                runs.push(result.map_err(|e| to_py_err(named(k, e)))?);
            }
            runs
        }
    };
    let trajectories: Vec<Trajectory> = runs.iter().map(|r| r.trajectory.clone()).collect();
    let out = stack(py, m, &trajectories, batch.is_some())?;
    let samples = trajectories[0].t.len();
    for (name, width, field) in [
        (
            "ctrl",
            m.nu(),
            (|r| &r.ctrl) as fn(&SceneTrajectory) -> &Vec<f64>,
        ),
        ("tau_constraint", m.nv, |r| &r.tau_constraint),
        ("act", m.na(), |r| &r.act),
        ("plastic", m.nplastic(), |r| &r.plastic),
    ] {
        let flat: Vec<f64> = runs.iter().flat_map(|r| field(r).iter().copied()).collect();
        let shape = match batch {
            Some(n) => vec![n, samples, width],
            None => vec![samples, width],
        };
        out.set_item(name, PyArray1::from_vec(py, flat).reshape(shape)?)?;
    }
    // per rollout, per sample: the contacts as `collide` lists them, each with its `force`
    let mut contacts = Vec::with_capacity(runs.len());
    for run in &runs {
        let mut samples = Vec::with_capacity(run.contacts.len());
        for sample in &run.contacts {
            let found: Vec<_> = sample.iter().map(|(contact, _)| *contact).collect();
            let items = contact_dicts(py, m, &found)?;
            for ((_, force), item) in sample.iter().zip(&items) {
                item.set_item("force", PyArray1::from_slice(py, force))?;
            }
            samples.push(items);
        }
        contacts.push(samples);
    }
    out.set_item("contacts", contacts)?;
    Ok(out)
}

/// One step of each state (q, v, act, plastic) under applied forces `tau` and controls `ctrl`:
/// per sample the flat [q₁, v₁, act₁, plastic₁] (act: the activations, na; plastic: the plastic
/// springs' references, nplastic).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub fn step_scene<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    tau: &Bound<'py, PyAny>,
    ctrl: &Bound<'py, PyAny>,
    act: &Bound<'py, PyAny>,
    plastic: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    let m = &model.model;
    let arguments = [
        model.q_arg("q", q)?,
        model.v_arg("v", v)?,
        model.v_arg("tau", tau)?,
        Argument::new("ctrl", ctrl, SampleShape::vector(m.nu()))?,
        Argument::new("act", act, SampleShape::vector(m.na()))?,
        Argument::new("plastic", plastic, SampleShape::vector(m.nplastic()))?,
    ];
    let batch = arguments[0].batch()?;
    for argument in &arguments[1..] {
        if argument.batch()?.is_some_and(|n| Some(n) != batch) {
            return Err(PyValueError::new_err(format!(
                "argument '{}': expected one row per state of 'q', got shape {:?}",
                argument.name,
                argument.array.shape()
            )));
        }
    }
    let count = batch.unwrap_or(1);
    let values: Vec<Vec<f64>> = arguments.iter().map(|a| a.values().into_owned()).collect();
    let sizes = [m.nq, m.nv, m.nv, m.nu(), m.na(), m.nplastic()];
    let row = |i: usize, k: usize| -> &[f64] {
        let n = sizes[i];
        match values[i].len() == n {
            true => &values[i],
            false => &values[i][k * n..(k + 1) * n],
        }
    };
    let states: Vec<Vec<f64>> = py
        .detach(|| {
            let step = |stepper: &mut SceneStep, k: usize| {
                stepper.forget_warm_start();
                let (mut q, mut v) = (row(0, k).to_vec(), row(1, k).to_vec());
                let (mut act, mut plastic) = (row(4, k).to_vec(), row(5, k).to_vec());
                let state = (&mut q[..], &mut v[..], &mut act[..], &mut plastic[..]);
                stepper.step(m, 0.0, state, row(2, k), row(3, k))?;
                q.extend_from_slice(&v);
                q.extend_from_slice(&act);
                q.extend_from_slice(&plastic);
                Ok(q)
            };
            // one state with the model's own step; a batch with a copy per task
            model.with_scene_step(|stepper| match count {
                1 => Ok(vec![step(stepper, 0)?]),
                _ => (0..count)
                    .into_par_iter()
                    .map_init(|| stepper.clone(), step)
                    .collect(),
            })
        })
        .map_err(to_py_err)?;
    let flat: Vec<f64> = states.concat();
    let array = PyArray1::from_vec(py, flat);
    Ok(match batch {
        Some(n) => array
            .reshape([n, m.nq + m.nv + m.na() + m.nplastic()])?
            .into_any(),
        None => array.into_any(),
    })
}

/// The controls of a scene simulation.
enum SceneControls<'py> {
    /// One row of controls per rollout.
    Fixed(Vec<FixedControls>),
    /// A callable `(t, q, v) -> ctrl`.
    Python(Bound<'py, PyAny>),
}

/// `ctrl`: None, an array (nu) or (count, nu), or a callable.
fn read_controls<'py>(
    m: &Model,
    ctrl: Option<&Bound<'py, PyAny>>,
    count: usize,
) -> PyResult<SceneControls<'py>> {
    if let Some(ctrl) = ctrl.filter(|c| c.is_callable()) {
        return Ok(SceneControls::Python(ctrl.clone()));
    }
    let rows = per_rollout("ctrl", ctrl, m.nu(), count)?;
    Ok(SceneControls::Fixed(
        rows.into_iter().map(FixedControls).collect(),
    ))
}

/// `value`: None (zeros), an array (width) for every rollout or (count, width), one row each.
fn per_rollout(
    name: &'static str,
    value: Option<&Bound<'_, PyAny>>,
    width: usize,
    count: usize,
) -> PyResult<Vec<Vec<f64>>> {
    let Some(value) = value else {
        return Ok(vec![vec![0.0; width]; count]);
    };
    let argument = Argument::new(name, value, SampleShape::vector(width))?;
    let values = argument.values();
    match argument.batch()? {
        None => Ok(vec![values.to_vec(); count]),
        Some(n) if n == count => Ok((0..n)
            .map(|k| values[k * width..(k + 1) * width].to_vec())
            .collect()),
        Some(_) => Err(PyValueError::new_err(format!(
            "argument '{name}': expected shape ({width},) or ({count}, {width}), one row per \
             rollout, got {:?}",
            argument.array.shape()
        ))),
    }
}

/// Controls written in Python: `ctrl(t, q, v) -> (nu,)`.
struct PythonControls<'py> {
    callable: Bound<'py, PyAny>,
    raised: Raised,
}

impl Controls for PythonControls<'_> {
    fn controls(
        &mut self,
        model: &Model,
        t: f64,
        q: &[f64],
        v: &[f64],
        ctrl: &mut [f64],
    ) -> robodyn::Result<()> {
        let shape = SampleShape::vector(model.nu());
        let result = call_back(&self.callable, t, q, v, "ctrl", shape, ctrl);
        keep_raised(&mut self.raised, result, t)
    }
}
