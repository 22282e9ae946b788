//! The model file's actuators (MJCF `<actuator>`): their names, control ranges and the
//! generalised forces a control vector produces.

use crate::args::*;
use crate::model::*;
use numpy::PyArray2;
use pyo3::prelude::*;
use robodyn::soft::tendons::TendonKinematics;

#[pymethods]
impl PyModel {
    /// nu: the number of actuators, the length of a control vector `ctrl`.
    #[getter]
    fn nu(&self) -> usize {
        self.model.nu()
    }

    /// na: the number of activations (MuJoCo's `act`), one per actuator with activation dynamics
    /// (`dyntype` integrator, filter, filterexact; a muscle's is held).
    #[getter]
    fn na(&self) -> usize {
        self.model.na()
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

    /// The generalised forces (nv,) the actuators exert under the controls `ctrl` (nu,) and the
    /// activations `act` (na,; None: zero) at (q, v): MuJoCo's `qfrc_actuator` — each control
    /// clamped to its range (unless the `clampctrl` flag is disabled; with `actuation` disabled
    /// every force is zero), its actuator's force `(a₀ + a₁ l + a₂ l̇) u + (b₀ + b₁ l + b₂ l̇)`
    /// (l = gear q_j, or gear L on a tendon; its activation w, or with `actearly` the next one,
    /// in place of u where it has one) clamped to its force range, times its moment arms: the
    /// gear on its joint, gear J on a tendon (J = ∂L̇/∂v, fixed or spatial), a joint's total
    /// clamped to its `actuatorfrcrange`. An `actuatorgravcomp` joint's gravity compensation,
    /// which MuJoCo adds there, is in `contact_forward_dynamics`' `tau_actuator`, not here. A
    /// batch gives (N, nv).
    #[pyo3(signature = (q, v, ctrl, act=None))]
    fn actuator_forces<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        ctrl: &Bound<'py, PyAny>,
        act: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let controls = Argument::new("ctrl", ctrl, SampleShape::vector(self.model.nu()))?;
        let mut arguments = vec![self.q_arg("q", q)?, self.v_arg("v", v)?, controls];
        if let Some(act) = act {
            let shape = SampleShape::vector(self.model.na());
            arguments.push(Argument::new("act", act, shape)?);
        }
        // without `act`: zero activations
        let zeros = vec![0.0; self.model.na()];
        self.evaluate(py, &arguments, &[self.model.nv], &|m, workspace, i, out| {
            let act = i.get(3).copied().unwrap_or(&zeros);
            let tendons = match m.tendons.is_empty() {
                true => TendonKinematics::default(),
                false => TendonKinematics::at(m, &mut workspace.data, i[0])?,
            };
            m.actuator_forces((i[0], i[1]), (i[2], act), &tendons, out)
        })
    }

    /// ẇ (na,): the rates of the actuators' activations under the controls `ctrl` (nu,) at the
    /// activations `act` (na,), MuJoCo's `act_dot`: u (clamped, unless the `clampctrl` flag is
    /// disabled) for an integrator, (u − w)/τ for a filter; all zero with the `actuation` flag
    /// disabled. A batch gives (N, na).
    fn activation_rates<'py>(
        &self,
        py: Python<'py>,
        ctrl: &Bound<'py, PyAny>,
        act: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let m = &self.model;
        self.evaluate(
            py,
            &[
                Argument::new("ctrl", ctrl, SampleShape::vector(m.nu()))?,
                Argument::new("act", act, SampleShape::vector(m.na()))?,
            ],
            &[m.na()],
            &|m, _, i, out| m.activation_rates(i[0], i[1], out),
        )
    }
}
