//! `simulate`: the binding of `robodyn::integrate`. Native controllers and constant wrenches run
//! with the GIL released (batches on all cores); Python callables are called back with the GIL.

use crate::args::{read_property, read_sample, single_sample, Argument, SampleShape};
use crate::model::{fill_forces, write_row_major, PyModel};
use crate::to_py_err;
use nalgebra::DVector;
use numpy::{PyArray1, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use robodyn::integrate::simulator::DEFAULT_ACCURACY_RTOL;
use robodyn::integrate::{
    simulate as run, simulate_lockstep, AccuracyIssue, AccuracyMeasure, ControlLaw, Controller,
    DesiredMotion, ExternalWrenches, Integrator, LimitModel, NativeController, PassiveForces,
    SimulationOptions, StepWorkspace, Trajectory,
};
use robodyn::spatial::Force;
use robodyn::{Error, Model};

/// What a Python callback raised, kept until the simulation has stopped.
type Raised = Option<PyErr>;

/// A controller written in Python: `controller(t, q, v) -> tau`.
struct PythonController<'py> {
    callable: Bound<'py, PyAny>,
    raised: Raised,
}

impl Controller for PythonController<'_> {
    fn torque(
        &mut self,
        model: &Model,
        t: f64,
        q: &[f64],
        v: &[f64],
        tau: &mut [f64],
    ) -> robodyn::Result<()> {
        let result = call_back(
            &self.callable,
            t,
            q,
            v,
            "controller",
            SampleShape::vector(model.nv),
            tau,
        );
        keep_raised(&mut self.raised, result, t)
    }
}

/// External wrenches written in Python: `wrenches(t, q, v) -> (nbodies - 1, 6)`.
struct PythonWrenches<'py> {
    callable: Bound<'py, PyAny>,
    buffer: Vec<f64>,
    raised: Raised,
}

impl ExternalWrenches for PythonWrenches<'_> {
    fn wrenches(
        &mut self,
        t: f64,
        q: &[f64],
        v: &[f64],
        forces: &mut [Force],
    ) -> robodyn::Result<()> {
        let shape = SampleShape::matrix(forces.len(), 6);
        let result = call_back(&self.callable, t, q, v, "wrenches", shape, &mut self.buffer);
        keep_raised(&mut self.raised, result, t)?;
        fill_forces(forces, &self.buffer);
        Ok(())
    }
}

/// The same wrenches at every instant.
#[derive(Clone)]
struct ConstantWrenches(Vec<Force>);

impl ExternalWrenches for ConstantWrenches {
    fn wrenches(
        &mut self,
        _: f64,
        _: &[f64],
        _: &[f64],
        forces: &mut [Force],
    ) -> robodyn::Result<()> {
        forces.copy_from_slice(&self.0);
        Ok(())
    }
}

/// Calls `callable(t, q, v)` and copies its result, of one sample of `shape`, into `out`.
fn call_back(
    callable: &Bound<PyAny>,
    t: f64,
    q: &[f64],
    v: &[f64],
    name: &'static str,
    shape: SampleShape,
    out: &mut [f64],
) -> PyResult<()> {
    let py = callable.py();
    let result = callable.call1((t, PyArray1::from_slice(py, q), PyArray1::from_slice(py, v)))?;
    let argument = Argument::new(name, &result, shape)
        .map_err(|e| PyValueError::new_err(format!("{} (returned at t = {t})", e.value(py))))?;
    out.copy_from_slice(&single_sample(&argument)?);
    Ok(())
}

/// Keeps a Python exception for re-raising and tells the loop to stop.
fn keep_raised(raised: &mut Raised, result: PyResult<()>, t: f64) -> robodyn::Result<()> {
    result.map_err(|error| {
        *raised = Some(error);
        Error::Simulation {
            time: t,
            message: "a Python callback raised".into(),
        }
    })
}

/// Reads the native controller description `{"kind": ..., ...}` that `robodyn.simulate` builds.
fn control_law(model: &Model, spec: &Bound<PyDict>) -> PyResult<ControlLaw> {
    let item = |key: &str| -> PyResult<Bound<PyAny>> {
        spec.get_item(key)?.ok_or_else(|| {
            PyValueError::new_err(format!("argument 'controller': missing key '{key}'"))
        })
    };
    let vector = |key: &'static str, length: usize| -> PyResult<DVector<f64>> {
        Ok(DVector::from_vec(read_property(key, &item(key)?, length)?))
    };
    let kind: String = item("kind")?.extract()?;
    let reference = || -> PyResult<DesiredMotion> {
        if spec.contains("times")? {
            let times: Vec<f64> = item("times")?.extract().map_err(|_| {
                PyValueError::new_err("argument 'reference times': expected a 1-D array of times")
            })?;
            let knots = times.len();
            let matrix = |key: &'static str, width: usize| -> PyResult<Vec<f64>> {
                let argument = Argument::new(key, &item(key)?, SampleShape::vector(width))?;
                match argument.batch()? {
                    Some(n) if n == knots => Ok(argument.values().into_owned()),
                    _ => Err(PyValueError::new_err(format!(
                        "argument 'reference {key}': expected shape ({knots}, {width}), one row per time, got {:?}",
                        argument.array.shape()
                    ))),
                }
            };
            Ok(DesiredMotion::Samples {
                times,
                q: matrix("q", model.nq)?,
                v: matrix("v", model.nv)?,
            })
        } else {
            Ok(DesiredMotion::Setpoint(vector("q_ref", model.nq)?))
        }
    };
    match kind.as_str() {
        "constant" => Ok(ControlLaw::Constant(vector("tau", model.nv)?)),
        "gravity_compensation" => Ok(ControlLaw::GravityCompensation),
        "pd" => Ok(ControlLaw::Pd {
            kp: vector("kp", model.nv)?,
            kd: vector("kd", model.nv)?,
            reference: reference()?,
            gravity_compensation: item("gravity_compensation")?.extract()?,
        }),
        "computed_torque" => Ok(ControlLaw::ComputedTorque {
            kp: vector("kp", model.nv)?,
            kd: vector("kd", model.nv)?,
            reference: reference()?,
        }),
        other => Err(PyValueError::new_err(format!(
            "argument 'controller': expected kind 'constant', 'gravity_compensation', 'pd' or \
             'computed_torque', got '{other}'"
        ))),
    }
}

/// One recorded series of a trajectory.
type Series = fn(&Trajectory) -> &Vec<f64>;

/// One trajectory's arrays into `out`: t, q, v, a, tau, tau_passive, stacked over rollouts.
fn stack<'py>(
    py: Python<'py>,
    model: &Model,
    runs: &[Trajectory],
    batch: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let samples = runs[0].len();
    let fields: [(&str, Series, usize); 6] = [
        ("t", |r| &r.t, 0),
        ("q", |r| &r.q, model.nq),
        ("v", |r| &r.v, model.nv),
        ("a", |r| &r.a, model.nv),
        ("tau", |r| &r.tau, model.nv),
        ("tau_passive", |r| &r.tau_passive, model.nv),
    ];
    for (name, field, width) in fields {
        let flat: Vec<f64> = if name == "t" {
            runs[0].t.clone()
        } else {
            runs.iter().flat_map(|r| field(r).iter().copied()).collect()
        };
        let mut shape = Vec::new();
        if batch && name != "t" {
            shape.push(runs.len());
        }
        shape.push(samples);
        if width > 0 {
            shape.push(width);
        }
        out.set_item(name, PyArray1::from_vec(py, flat).reshape(shape)?)?;
    }
    // statistics per rollout
    let each = |f: fn(&Trajectory) -> usize| runs.iter().map(f).collect::<Vec<usize>>();
    out.set_item("steps", each(|r| r.statistics.steps))?;
    out.set_item("rejected_steps", each(|r| r.statistics.rejected_steps))?;
    out.set_item("evaluations", each(|r| r.statistics.evaluations))?;
    // the accuracy record per rollout
    let accuracy = |f: fn(&Trajectory) -> &Vec<f64>| -> Vec<Bound<'py, PyArray1<f64>>> {
        runs.iter()
            .map(|r| PyArray1::from_slice(py, f(r)))
            .collect()
    };
    out.set_item("error_times", accuracy(|r| &r.accuracy.check_times))?;
    out.set_item("error_estimate", accuracy(|r| &r.accuracy.local_errors))?;
    let drifts: Vec<Option<f64>> = runs.iter().map(|r| r.accuracy.energy_drift).collect();
    out.set_item("energy_drift", drifts)?;
    let issues = runs
        .iter()
        .map(|r| {
            r.accuracy
                .issue
                .map(|issue| accuracy_issue(py, &issue))
                .transpose()
        })
        .collect::<PyResult<Vec<_>>>()?;
    out.set_item("accuracy_issue", issues)?;
    Ok(out)
}

/// An accuracy issue as `{"message", "measure", "time", "error", "largest_step"}`.
fn accuracy_issue<'py>(py: Python<'py>, issue: &AccuracyIssue) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("message", issue.to_string())?;
    let measure = match issue.measure {
        AccuracyMeasure::LocalError => "local_error",
        AccuracyMeasure::EnergyDrift => "energy_drift",
    };
    out.set_item("measure", measure)?;
    out.set_item("time", issue.time)?;
    out.set_item("error", issue.error)?;
    out.set_item("largest_step", issue.largest_step)?;
    Ok(out)
}

/// Simulates `model` from `q0`, `v0` (one state, or N of them: shape (N, nq), (N, nv)) over
/// [0, t_end], recording every `dt`. See `robodyn.simulate` for the arguments; `controller` is
/// None, a dict describing a native controller, or a callable `(t, q, v) -> tau`.
#[pyfunction]
#[pyo3(signature = (model, q0, v0, t_end, dt, integrator="rk4", rtol=1e-6, atol=1e-9, max_step=f64::INFINITY,
                    controller=None, wrenches=None, friction_velocity=1e-2, limits="report",
                    limit_stiffness=1e4, limit_damping=1e2, progress=None, accuracy_rtol=DEFAULT_ACCURACY_RTOL))]
#[allow(clippy::too_many_arguments)]
pub fn simulate<'py>(
    py: Python<'py>,
    model: &PyModel,
    q0: &Bound<'py, PyAny>,
    v0: &Bound<'py, PyAny>,
    t_end: f64,
    dt: f64,
    integrator: &str,
    rtol: f64,
    atol: f64,
    max_step: f64,
    controller: Option<&Bound<'py, PyAny>>,
    wrenches: Option<&Bound<'py, PyAny>>,
    friction_velocity: f64,
    limits: &str,
    limit_stiffness: f64,
    limit_damping: f64,
    progress: Option<&Bound<'py, PyAny>>,
    accuracy_rtol: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let m = &model.model;
    let passive = passive_forces(friction_velocity, limits, limit_stiffness, limit_damping)?;
    let mut options = SimulationOptions::new(
        Integrator::from_name(integrator, rtol, atol).map_err(to_py_err)?,
        dt,
        t_end,
    );
    options.max_step = max_step;
    options.passive = passive;
    options.accuracy_rtol = accuracy_rtol;
    options.check().map_err(to_py_err)?;

    let q0 = model.q_arg("q0", q0)?;
    let v0 = model.v_arg("v0", v0)?;
    let batch = q0.batch()?;
    if v0.batch()? != batch {
        return Err(PyValueError::new_err(format!(
            "argument 'v0': expected as many states as 'q0' ({}), got shape {:?}",
            batch.map_or("one".to_string(), |n| n.to_string()),
            v0.array.shape()
        )));
    }
    let (q_values, v_values) = (q0.values(), v0.values());
    let rollouts = batch.unwrap_or(1);

    // native parts
    let law = match controller {
        None => Some(ControlLaw::Constant(DVector::zeros(m.nv))),
        Some(spec) => match spec.cast::<PyDict>() {
            Ok(dict) => Some(control_law(m, dict)?),
            Err(_) if spec.is_callable() => None,
            Err(_) => {
                return Err(PyValueError::new_err(format!(
                    "argument 'controller': expected None, a callable (t, q, v) -> tau or a robodyn controller, got {}",
                    spec.repr()?
                )))
            }
        },
    };
    let constant_wrenches = match wrenches {
        Some(value) if !value.is_callable() => {
            let shape = SampleShape::matrix(m.nbodies() - 1, 6);
            let values = read_sample("wrenches", value, shape)?;
            let mut forces = vec![Force::ZERO; m.nbodies() - 1];
            fill_forces(&mut forces, &values);
            Some(ConstantWrenches(forces))
        }
        _ => None,
    };
    let python_wrenches = wrenches.filter(|w| w.is_callable());
    // built once (which checks it), cloned for each rollout
    let native = law
        .map(|law| NativeController::new(m, law, options.passive, t_end))
        .transpose()
        .map_err(to_py_err)?;

    let state = |k: usize| {
        (
            &q_values[k * m.nq..(k + 1) * m.nq],
            &v_values[k * m.nv..(k + 1) * m.nv],
        )
    };
    let runs: Vec<Trajectory> = match (&native, python_wrenches) {
        (Some(native), None)
            if progress.is_none() && constant_wrenches.is_none() && rollouts > 1 =>
        {
            // all native and no wrenches: release the GIL, a group of rollouts per thread in
            // lockstep (their forward dynamics in lanes)
            let group = rollouts.div_ceil(rayon::current_num_threads()).max(1);
            let firsts: Vec<usize> = (0..rollouts).step_by(group).collect();
            let result: robodyn::Result<Vec<Vec<Trajectory>>> = py.detach(|| {
                firsts
                    .into_par_iter()
                    .map(|first| {
                        let starts: Vec<_> =
                            (first..rollouts.min(first + group)).map(state).collect();
                        simulate_lockstep(m, &starts, &options, native)
                            .map_err(|(r, e)| batch_error(batch, first + r, e))
                    })
                    .collect()
            });
            result.map_err(to_py_err)?.into_iter().flatten().collect()
        }
        (Some(native), None) if progress.is_none() => {
            // all native: release the GIL, rollouts in parallel
            let result: robodyn::Result<Vec<Trajectory>> = py.detach(|| {
                (0..rollouts)
                    .into_par_iter()
                    .map(|k| {
                        let mut controller = native.clone();
                        let mut wrenches = constant_wrenches.clone();
                        let (q, v) = state(k);
                        run(
                            m,
                            q,
                            v,
                            &options,
                            &mut controller,
                            wrenches.as_mut().map(|w| w as &mut dyn ExternalWrenches),
                            None,
                        )
                        .map_err(|e| batch_error(batch, k, e))
                    })
                    .collect()
            });
            result.map_err(to_py_err)?
        }
        _ => {
            // Python callbacks: one rollout after another, with the GIL
            let mut runs = Vec::with_capacity(rollouts);
            for k in 0..rollouts {
                let mut native = native.clone();
                let mut python = match (&native, controller) {
                    (None, Some(callable)) => Some(PythonController {
                        callable: callable.clone(),
                        raised: None,
                    }),
                    _ => None,
                };
                let controller: &mut dyn Controller = match (native.as_mut(), python.as_mut()) {
                    (Some(native), _) => native,
                    (None, Some(python)) => python,
                    (None, None) => unreachable!("a controller is native or a callable"),
                };
                let mut callable_wrenches = python_wrenches.map(|callable| PythonWrenches {
                    callable: callable.clone(),
                    buffer: vec![0.0; (m.nbodies() - 1) * 6],
                    raised: None,
                });
                let mut fixed_wrenches = constant_wrenches.clone();
                let wrenches: Option<&mut dyn ExternalWrenches> =
                    match (callable_wrenches.as_mut(), fixed_wrenches.as_mut()) {
                        (Some(w), _) => Some(w),
                        (None, Some(w)) => Some(w),
                        (None, None) => None,
                    };
                let mut progress_raised: Raised = None;
                let mut report = |fraction: f64| -> robodyn::Result<()> {
                    let result = py.check_signals().and_then(|_| match progress {
                        Some(callback) => callback
                            .call1(((k as f64 + fraction) / rollouts as f64,))
                            .map(|_| ()),
                        None => Ok(()),
                    });
                    keep_raised(&mut progress_raised, result, fraction)
                };
                let (q, v) = state(k);
                let result = run(m, q, v, &options, controller, wrenches, Some(&mut report));
                // a Python exception raised in a callback is re-raised as it was
                let raised = python
                    .and_then(|p| p.raised)
                    .or(callable_wrenches.and_then(|w| w.raised))
                    .or(progress_raised);
                if let Some(error) = raised {
                    return Err(error);
                }
                runs.push(result.map_err(|e| to_py_err(batch_error(batch, k, e)))?);
            }
            runs
        }
    };
    stack(py, m, &runs, batch.is_some())
}

/// Names the rollout of a batch that failed.
fn batch_error(batch: Option<usize>, k: usize, error: Error) -> Error {
    match (batch, error) {
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

/// The passive-force model from the Python arguments.
fn passive_forces(
    friction_velocity: f64,
    limits: &str,
    limit_stiffness: f64,
    limit_damping: f64,
) -> PyResult<PassiveForces> {
    let limits = match limits {
        "report" => LimitModel::Report,
        "penalty" => LimitModel::Penalty {
            stiffness: limit_stiffness,
            damping: limit_damping,
        },
        other => {
            return Err(PyValueError::new_err(format!(
                "argument 'limits': expected 'report' or 'penalty', got '{other}'"
            )))
        }
    };
    let passive = PassiveForces {
        friction_velocity,
        limits,
    };
    passive.check().map_err(to_py_err)?;
    Ok(passive)
}

/// One step of each state: per sample the flat [q₁, v₁] and, with `derivatives`, A (2nv × 2nv)
/// and B (2nv × nv) row-major after it. The Python `robodyn.step` splits them.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub fn step<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    tau: &Bound<'py, PyAny>,
    dt: f64,
    integrator: &str,
    derivatives: bool,
    friction_velocity: f64,
    limits: &str,
    limit_stiffness: f64,
    limit_damping: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let m = &model.model;
    let passive = passive_forces(friction_velocity, limits, limit_stiffness, limit_damping)?;
    let integrator = Integrator::from_name(integrator, 0.0, 0.0).map_err(to_py_err)?;
    let arguments = [
        model.q_arg("q", q)?,
        model.v_arg("v", v)?,
        model.v_arg("tau", tau)?,
    ];
    let (nq, nv) = (m.nq, m.nv);
    let size = nq + nv + if derivatives { 6 * nv * nv } else { 0 };
    model.evaluate(py, &arguments, &[size], &|m, w, i, out| {
        let stepper = w
            .step
            .get_or_insert_with(|| Box::new(StepWorkspace::new(m)));
        stepper.step(m, i[0], i[1], i[2], dt, integrator, &passive, derivatives)?;
        let (state, jacobians) = out.split_at_mut(nq + nv);
        state[..nq].copy_from_slice(&stepper.q_end);
        state[nq..].copy_from_slice(&stepper.v_end);
        if derivatives {
            let (a, b) = jacobians.split_at_mut(4 * nv * nv);
            write_row_major(&stepper.a, 2 * nv, a);
            write_row_major(&stepper.b, 2 * nv, b);
        }
        Ok(())
    })
}
