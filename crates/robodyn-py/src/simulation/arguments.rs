//! The arguments of `simulate` and `step`, read and checked in one place.

use super::callbacks::ConstantWrenches;
use super::rollouts::Rollouts;
use crate::args::{read_property, read_sample, Argument, SampleShape};
use crate::constrained::baumgarte_gains;
use crate::constraints::constraint_set;
use crate::model::{fill_forces, PyModel};
use crate::to_py_err;
use nalgebra::DVector;
use numpy::PyUntypedArrayMethods;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robodyn::algo::ConstrainedOptions;
use robodyn::integrate::{
    Constrained, ControlLaw, DesiredMotion, Integrator, LimitModel, NativeController,
    PassiveForces, SimulationOptions,
};
use robodyn::spatial::Force;
use robodyn::Model;

/// The arguments of `simulate` as Python gave them (see `robodyn.simulate`).
pub(super) struct SimulateArguments<'a, 'py> {
    pub(super) q0: &'a Bound<'py, PyAny>,
    pub(super) v0: &'a Bound<'py, PyAny>,
    pub(super) t_end: f64,
    pub(super) dt: f64,
    pub(super) integrator: &'a str,
    pub(super) rtol: f64,
    pub(super) atol: f64,
    pub(super) max_step: f64,
    pub(super) controller: Option<&'a Bound<'py, PyAny>>,
    pub(super) wrenches: Option<&'a Bound<'py, PyAny>>,
    pub(super) passive: PassiveArguments<'a>,
    pub(super) progress: Option<&'a Bound<'py, PyAny>>,
    pub(super) accuracy_rtol: f64,
    pub(super) constrained: ConstrainedArguments<'a, 'py>,
}

/// The constraint arguments of `simulate`: the constraints held (None: none) and how.
pub(super) struct ConstrainedArguments<'a, 'py> {
    pub(super) constraints: Option<&'a Bound<'py, PyAny>>,
    pub(super) baumgarte: Option<&'a Bound<'py, PyAny>>,
    pub(super) damping: f64,
}

impl ConstrainedArguments<'_, '_> {
    /// The constrained forward dynamics, or None without constraints.
    pub(super) fn read(&self, model: &PyModel) -> PyResult<Option<Constrained>> {
        let Some(constraints) = self.constraints.filter(|c| !c.is_none()) else {
            return Ok(None);
        };
        let set = constraint_set(model, constraints)?;
        let options = ConstrainedOptions {
            baumgarte: baumgarte_gains(self.baumgarte)?,
            damping: self.damping,
        };
        options.check().map_err(to_py_err)?;
        Ok(Some(Constrained::new(
            &model.model,
            std::sync::Arc::unwrap_or_clone(set),
            options,
        )))
    }
}

/// The passive-force arguments of `simulate` and `step`.
pub(super) struct PassiveArguments<'a> {
    pub(super) friction_velocity: f64,
    pub(super) limits: &'a str,
    pub(super) limit_stiffness: f64,
    pub(super) limit_damping: f64,
}

impl PassiveArguments<'_> {
    /// The passive-force model, checked.
    pub(super) fn read(&self) -> PyResult<PassiveForces> {
        let limits = match self.limits {
            "report" => LimitModel::Report,
            "penalty" => LimitModel::Penalty {
                stiffness: self.limit_stiffness,
                damping: self.limit_damping,
            },
            other => {
                return Err(PyValueError::new_err(format!(
                    "argument 'limits': expected 'report' or 'penalty', got '{other}'"
                )))
            }
        };
        let passive = PassiveForces {
            friction_velocity: self.friction_velocity,
            limits,
        };
        passive.check().map_err(to_py_err)?;
        Ok(passive)
    }
}
/// The controller of a simulation.
pub(super) enum Control<'py> {
    /// Built once (which checks it), cloned for each rollout (boxed: it is large).
    Native(Box<NativeController>),
    /// A callable `(t, q, v) -> tau`.
    Python(Bound<'py, PyAny>),
}

/// The external wrenches of a simulation.
pub(super) enum Wrenches<'py> {
    None,
    Constant(ConstantWrenches),
    /// A callable `(t, q, v) -> (nbodies - 1, 6)`.
    Python(Bound<'py, PyAny>),
}

/// A `simulate` call, its arguments read and checked once.
pub(super) struct Simulation<'a, 'py> {
    pub(super) rollouts: Rollouts<'a>,
    pub(super) controller: Control<'py>,
    pub(super) wrenches: Wrenches<'py>,
    pub(super) progress: Option<&'a Bound<'py, PyAny>>,
}

impl<'a, 'py> Simulation<'a, 'py> {
    /// Reads and checks every argument: a `ValueError` naming the first bad one.
    pub(super) fn read(
        model: &'a PyModel,
        arguments: &SimulateArguments<'a, 'py>,
    ) -> PyResult<Self> {
        let m = &model.model;
        let passive = arguments.passive.read()?;
        let integrator =
            Integrator::from_name(arguments.integrator, arguments.rtol, arguments.atol)
                .map_err(to_py_err)?;
        let mut options = SimulationOptions::new(integrator, arguments.dt, arguments.t_end);
        options.max_step = arguments.max_step;
        options.passive = passive;
        options.accuracy_rtol = arguments.accuracy_rtol;
        options.check().map_err(to_py_err)?;

        let (q0, v0, batch) = initial_states(model, arguments.q0, arguments.v0)?;
        let wrenches = match arguments.wrenches {
            None => Wrenches::None,
            Some(callable) if callable.is_callable() => Wrenches::Python(callable.clone()),
            Some(value) => {
                let shape = SampleShape::matrix(m.nbodies() - 1, 6);
                let values = read_sample("wrenches", value, shape)?;
                let mut forces = vec![Force::ZERO; m.nbodies() - 1];
                fill_forces(&mut forces, &values);
                Wrenches::Constant(ConstantWrenches(forces))
            }
        };
        let controller =
            read_controller(m, arguments.controller, options.passive, arguments.t_end)?;
        Ok(Simulation {
            rollouts: Rollouts {
                model: m,
                options,
                q0: q0.values().into_owned(),
                v0: v0.values().into_owned(),
                batch,
                constrained: arguments.constrained.read(model)?,
            },
            controller,
            wrenches,
            progress: arguments.progress,
        })
    }
}

/// The initial states `q0` (nq or N × nq) and `v0` (nv or N × nv) and N (`None` for one).
pub(super) fn initial_states<'a, 'py>(
    model: &PyModel,
    q0: &'a Bound<'py, PyAny>,
    v0: &'a Bound<'py, PyAny>,
) -> PyResult<(Argument<'py>, Argument<'py>, Option<usize>)> {
    let (q0, v0) = (model.q_arg("q0", q0)?, model.v_arg("v0", v0)?);
    let batch = q0.batch()?;
    if v0.batch()? != batch {
        return Err(PyValueError::new_err(format!(
            "argument 'v0': expected as many states as 'q0' ({}), got shape {:?}",
            batch.map_or("one".to_string(), |n| n.to_string()),
            v0.array.shape()
        )));
    }
    Ok((q0, v0, batch))
}

/// The controller `spec`: None (no torque), a native controller's description, or a callable
/// `(t, q, v) -> tau`.
pub(super) fn read_controller<'py>(
    m: &Model,
    spec: Option<&Bound<'py, PyAny>>,
    passive: PassiveForces,
    t_end: f64,
) -> PyResult<Control<'py>> {
    let law = match spec {
        None => ControlLaw::Constant(DVector::zeros(m.nv)),
        Some(spec) => match spec.cast::<PyDict>() {
            Ok(dict) => control_law(m, dict)?,
            Err(_) if spec.is_callable() => return Ok(Control::Python(spec.clone())),
            Err(_) => {
                return Err(PyValueError::new_err(format!(
                    "argument 'controller': expected None, a callable (t, q, v) -> tau or a robodyn controller, got {}",
                    spec.repr()?
                )))
            }
        },
    };
    let native = NativeController::new(m, law, passive, t_end).map_err(to_py_err)?;
    Ok(Control::Native(Box::new(native)))
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
