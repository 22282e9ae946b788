//! What a simulation calls back: controllers and wrenches written in Python, constant wrenches,
//! and how a Python exception raised in a callback is kept until the loop stops.

use crate::args::{single_sample, Argument, SampleShape};
use crate::model::fill_forces;
use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use robodyn::integrate::{Controller, ExternalWrenches};
use robodyn::spatial::Force;
use robodyn::{Error, Model};

/// What a Python callback raised, kept until the simulation has stopped.
pub(super) type Raised = Option<PyErr>;

/// A controller written in Python: `controller(t, q, v) -> tau`.
pub(super) struct PythonController<'py> {
    pub(super) callable: Bound<'py, PyAny>,
    pub(super) raised: Raised,
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
pub(super) struct PythonWrenches<'py> {
    pub(super) callable: Bound<'py, PyAny>,
    pub(super) buffer: Vec<f64>,
    pub(super) raised: Raised,
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
pub(super) struct ConstantWrenches(pub(super) Vec<Force>);

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
pub(super) fn call_back(
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
    let mut read = || -> PyResult<()> {
        let argument = Argument::new(name, &result, shape)?;
        out.copy_from_slice(&single_sample(&argument)?);
        Ok(())
    };
    read().map_err(|e| PyValueError::new_err(format!("{} (returned at t = {t})", e.value(py))))
}

/// Keeps a Python exception for re-raising and tells the loop to stop.
pub(super) fn keep_raised(
    raised: &mut Raised,
    result: PyResult<()>,
    t: f64,
) -> robodyn::Result<()> {
    result.map_err(|error| {
        *raised = Some(error);
        Error::Simulation {
            time: t,
            message: "a Python callback raised".into(),
        }
    })
}
