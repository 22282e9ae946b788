//! The model file's keyframes (MJCF `<keyframe>`) as `robodyn.Keyframe` objects.

use crate::args::{describe, real, text};
use crate::model::PyModel;
use crate::to_py_err;
use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyTuple};
use robodyn::Keyframe;

/// A state the model file names (MuJoCo's `<key>`), in robodyn's coordinates: `q` (nq,),
/// quaternions scalar last; `v` (nv,), a free joint's linear velocity in its body's axes (MuJoCo's
/// `qvel` has world axes); `ctrl`, one control per actuator of the file, in its order; `act`, one
/// activation per actuator with activation dynamics (MuJoCo's `act`); `plastic`, the plastic
/// springs' references (MuJoCo's `plastic`, nplastic, a ball's quaternion scalar last); `time`
/// (s).
/// Start a simulation from it with `robodyn.simulate(m, key.q, v0=key.v, ...)`.
#[pyclass(name = "Keyframe", module = "robodyn", frozen)]
pub(crate) struct PyKeyframe {
    /// The key's name ("" when the file gives none).
    #[pyo3(get)]
    name: String,
    /// The simulation time the key holds (s).
    #[pyo3(get)]
    time: f64,
    q: Vec<f64>,
    v: Vec<f64>,
    ctrl: Vec<f64>,
    act: Vec<f64>,
    plastic: Vec<f64>,
}

impl From<&Keyframe> for PyKeyframe {
    fn from(key: &Keyframe) -> Self {
        PyKeyframe {
            name: key.name.clone(),
            time: key.time,
            q: key.q.as_slice().to_vec(),
            v: key.v.as_slice().to_vec(),
            ctrl: key.ctrl.as_slice().to_vec(),
            act: key.act.as_slice().to_vec(),
            plastic: key.plastic.as_slice().to_vec(),
        }
    }
}

#[pymethods]
impl PyKeyframe {
    #[new]
    #[pyo3(signature = (name, time, q, v, ctrl, act=None, plastic=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        name: &Bound<PyAny>,
        time: &Bound<PyAny>,
        q: &Bound<PyAny>,
        v: &Bound<PyAny>,
        ctrl: &Bound<PyAny>,
        act: Option<&Bound<PyAny>>,
        plastic: Option<&Bound<PyAny>>,
    ) -> PyResult<Self> {
        Ok(PyKeyframe {
            name: text("name", name)?,
            time: real("time", time)?,
            q: finite_numbers("q", q)?,
            v: finite_numbers("v", v)?,
            ctrl: finite_numbers("ctrl", ctrl)?,
            act: act.map_or(Ok(Vec::new()), |act| finite_numbers("act", act))?,
            plastic: plastic.map_or(Ok(Vec::new()), |p| finite_numbers("plastic", p))?,
        })
    }

    /// The configuration, (nq,): a new array each time.
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.q)
    }

    /// The velocity, (nv,): a new array each time.
    #[getter]
    fn v<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.v)
    }

    /// The actuators' controls, one per actuator of the file: a new array each time.
    #[getter]
    fn ctrl<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.ctrl)
    }

    /// The actuators' activations, one per actuator with activation dynamics (na,): a new array
    /// each time.
    #[getter]
    fn act<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.act)
    }

    /// The plastic springs' references (nplastic,): a new array each time.
    #[getter]
    fn plastic<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.plastic)
    }

    fn __repr__(&self) -> String {
        format!(
            "Keyframe({:?}, time={}, q={:?}, v={:?}, ctrl={:?}, act={:?}, plastic={:?})",
            self.name, self.time, self.q, self.v, self.ctrl, self.act, self.plastic
        )
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let this = slf.get();
        let args = (
            this.name.clone(),
            this.time,
            this.q.clone(),
            this.v.clone(),
            this.ctrl.clone(),
            this.act.clone(),
            this.plastic.clone(),
        );
        (slf.get_type(), args).into_pyobject(slf.py())
    }
}

/// A sequence of finite numbers.
fn finite_numbers(argument: &str, value: &Bound<PyAny>) -> PyResult<Vec<f64>> {
    match value.extract::<Vec<f64>>() {
        Ok(values) if values.iter().all(|x| x.is_finite()) => Ok(values),
        _ => Err(PyValueError::new_err(format!(
            "argument '{argument}': expected a sequence of finite numbers, got {}",
            describe(value)
        ))),
    }
}

#[pymethods]
impl PyModel {
    /// The states the model file names (MJCF `<keyframe>`), in its order, as `Keyframe`s.
    #[getter]
    fn keyframes(&self) -> Vec<PyKeyframe> {
        self.model.keyframes.iter().map(PyKeyframe::from).collect()
    }

    /// The keyframe named `key` (a str), or the `key`-th (an int, as MuJoCo numbers them); a
    /// `ValueError` names the model's keyframes when there is no such one.
    fn keyframe(&self, key: &Bound<PyAny>) -> PyResult<PyKeyframe> {
        let keyframes = &self.model.keyframes;
        if let Ok(name) = key.extract::<String>() {
            return self
                .model
                .keyframe(&name)
                .map(PyKeyframe::from)
                .map_err(to_py_err);
        }
        let index = key
            .extract::<usize>()
            .ok()
            .filter(|_| !key.is_instance_of::<PyBool>());
        match index {
            Some(k) if k < keyframes.len() => Ok(PyKeyframe::from(&keyframes[k])),
            _ => Err(PyValueError::new_err(format!(
                "argument 'key': expected a keyframe's name or an index below {}, got {}",
                keyframes.len(),
                describe(key)
            ))),
        }
    }
}
