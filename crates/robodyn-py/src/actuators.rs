//! The model file's actuators (MJCF `<actuator>`): their names, control ranges and the
//! generalised forces a control vector produces.

use crate::args::*;
use crate::model::*;
use numpy::PyArray2;
use pyo3::prelude::*;

#[pymethods]
impl PyModel {
    /// nu: the number of actuators, the length of a control vector `ctrl`.
    #[getter]
    fn nu(&self) -> usize {
        self.model.nu()
    }

    /// The actuators' names, in the controls' order (MJCF's `name`, `actuator<k>` where the
    /// file gives none).
    #[getter]
    fn actuator_names(&self) -> Vec<String> {
        self.model
            .actuators
            .iter()
            .map(|a| a.name.clone())
            .collect()
    }

    /// The controls' ranges, shape (nu, 2): [lower, upper], (−inf, inf) where a control is not
    /// limited (MJCF `ctrlrange` with `ctrllimited`). Controls outside are clamped.
    #[getter]
    fn ctrl_range<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let rows: Vec<Vec<f64>> = self
            .model
            .actuators
            .iter()
            .map(|a| {
                let (lower, upper) = a.ctrl_range.unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
                vec![lower, upper]
            })
            .collect();
        if rows.is_empty() {
            return Ok(PyArray2::zeros(py, [0, 2], false));
        }
        Ok(PyArray2::from_vec2(py, &rows)?)
    }

    /// The generalised forces (nv,) the actuators exert under the controls `ctrl` (nu,) at
    /// (q, v): MuJoCo's `qfrc_actuator` — each control clamped to its range, its actuator's
    /// force `(a₀ + a₁ l + a₂ l̇) u + (b₀ + b₁ l + b₂ l̇)` (l = gear q_j, or gear L on a fixed
    /// tendon) clamped to its force range, times the gear on its joint (gear coef on each of
    /// its tendon's joints). A batch gives (N, nv).
    fn actuator_forces<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        ctrl: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let controls = Argument::new("ctrl", ctrl, SampleShape::vector(self.model.nu()))?;
        self.evaluate(
            py,
            &[self.q_arg("q", q)?, self.v_arg("v", v)?, controls],
            &[self.model.nv],
            &|m, _, i, out| m.actuator_forces(i[0], i[1], i[2], out),
        )
    }
}
