//! Dynamics under constraints: the constraint Jacobian, the Delassus matrix, forward dynamics,
//! impulses and inverse dynamics with the constraints of `constraints.rs`.

use crate::args::*;
use crate::constraints::constraint_set;
use crate::model::*;
use crate::results::view_of;
use nalgebra::{DMatrix, DVector};
use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyEllipsis, PySequence, PySlice, PyString, PyTuple};
use robodyn::algo::{self, ConstrainedDerivatives, ConstrainedOptions, ConstraintData};
use robodyn::constraint::ConstraintSet;
use robodyn::spatial::Force;
use robodyn::Model;

/// The constrained algorithms' workspace in `slot` for `set`, made again when the set's size
/// changed.
fn constraint_data<'w>(
    slot: &'w mut Option<Box<ConstraintData>>,
    model: &Model,
    set: &ConstraintSet,
) -> &'w mut ConstraintData {
    made_for(
        slot,
        |c| c.fits(model, set),
        || ConstraintData::new(model, set),
    )
}

/// The workspace in `slot`, made by `make` when there is none or it does not `fit`.
pub(crate) fn made_for<T>(
    slot: &mut Option<Box<T>>,
    fits: impl Fn(&T) -> bool,
    make: impl FnOnce() -> T,
) -> &mut T {
    if !slot.as_deref().is_some_and(fits) {
        *slot = Some(Box::new(make()));
    }
    slot.as_mut().expect("made above")
}

/// A constrained algorithm on (q, v, τ or q̈) and optional external forces, returning its
/// vector of nv (q̈ or τ); the forces stay in the [`ConstraintData`].
type ConstrainedAlgorithm<'a> = dyn for<'c> Fn(
        &Model,
        &mut robodyn::Data,
        &'c mut ConstraintData,
        (&[f64], &[f64], &[f64]),
        Option<&[Force]>,
    ) -> robodyn::Result<&'c DVector<f64>>
    + Sync
    + 'a;

impl PyModel {
    /// `compute(model, data, constraint data, set, q, out)` at one configuration or a batch of
    /// them, with the set `constraints` resolves to; each result of the shape `shape(rows)`.
    fn at_configuration<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        constraints: &Bound<'py, PyAny>,
        shape: impl FnOnce(usize) -> Vec<usize>,
        compute: impl Fn(
                &Model,
                &mut robodyn::Data,
                &mut ConstraintData,
                &ConstraintSet,
                &[f64],
                &mut [f64],
            ) -> robodyn::Result<()>
            + Sync,
    ) -> PyResult<Bound<'py, PyAny>> {
        let set = constraint_set(self, constraints)?;
        let kernel: &Kernel = &|m, w, i, out| {
            let Workspace {
                data, constrained, ..
            } = w;
            let c = constraint_data(constrained, m, &set);
            compute(m, data, c, &set, i[0], out)
        };
        self.evaluate(py, &[self.q_arg("q", q)?], &shape(set.rows()), kernel)
    }

    /// `algorithm` on the arguments (q, v, x[, f_ext]) for one state or a batch: a dict of its
    /// vector and the constraint forces, named `names`. A batch without external forces runs
    /// `lanes` when given.
    #[allow(clippy::too_many_arguments)]
    fn constrained_call<'py>(
        &self,
        py: Python<'py>,
        (q, v, x): (
            &Bound<'py, PyAny>,
            &Bound<'py, PyAny>,
            (&'static str, &Bound<'py, PyAny>),
        ),
        f_ext: Option<&Bound<'py, PyAny>>,
        set: &ConstraintSet,
        names: [&str; 2],
        algorithm: &ConstrainedAlgorithm,
        lanes: Option<LaneRun>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let nv = self.model.nv;
        let kernel: &Kernel = &|m, w, i, out| {
            let Workspace {
                data,
                constrained,
                forces,
                ..
            } = w;
            let f_ext = i.get(3).map(|flat| {
                fill_forces(forces, flat);
                &forces[..]
            });
            let c = constraint_data(constrained, m, set);
            let result = algorithm(m, data, c, (i[0], i[1], i[2]), f_ext)?;
            out[..nv].copy_from_slice(result.as_slice());
            out[nv..].copy_from_slice(c.forces.as_slice());
            Ok(())
        };
        let lanes = lanes.filter(|_| f_ext.is_none());
        let whole = self.with_dynamics_arguments((q, v, x), f_ext, |arguments| {
            // the kernel writes every value: the result's array is not zeroed first
            let shape = [nv + set.rows()];
            self.evaluate_to(py, arguments, &shape, Target::Out(None), kernel, lanes)
        })?;
        let parts: [(&str, &[usize]); 2] = [(names[0], &[nv]), (names[1], &[set.rows()])];
        Self::split_parts(py, &whole, &parts)
    }

    /// `(..., n)` results split along their last axis into a dict, each part named and shaped as
    /// `parts` says (`(..., *shape)`), in order: views of the array.
    fn split_parts<'py>(
        py: Python<'py>,
        whole: &Bound<'py, PyAny>,
        parts: &[(&str, &[usize])],
    ) -> PyResult<Bound<'py, PyAny>> {
        let out = PyDict::new(py);
        if let Ok(flat) = whole.cast::<PyArray1<f64>>() {
            // one state: views made directly (Python's indexing costs a microsecond a part)
            let mut start = 0;
            for (name, part) in parts {
                let view = view_of(py, flat, start, part)?;
                out.set_item(PyString::new(py, name), view)?;
                start += part.iter().product::<usize>();
            }
            return Ok(out.into_any());
        }
        let ellipsis = PyEllipsis::get(py);
        let shape: Vec<usize> = whole.getattr("shape")?.extract()?;
        let batch = &shape[..shape.len() - 1];
        let mut start = 0;
        for (name, part) in parts {
            let stop = start + part.iter().product::<usize>();
            let index = PyTuple::new(
                py,
                [
                    ellipsis.as_any(),
                    PySlice::new(py, start as isize, stop as isize, 1).as_any(),
                ],
            )?;
            let shaped: Vec<usize> = batch.iter().chain(part.iter()).copied().collect();
            let view = whole.get_item(index)?.call_method1("reshape", (shaped,))?;
            out.set_item(PyString::new(py, name), view)?;
            start = stop;
        }
        Ok(out.into_any())
    }

    /// The flags of the actuated velocity coordinates: those of the named joints, or (None)
    /// every coordinate but those of free joints.
    fn actuated_coordinates(&self, actuated: Option<&Bound<PyAny>>) -> PyResult<Vec<bool>> {
        let model = &self.model;
        let mut flags = vec![false; model.nv];
        let mut set_joint = |body: usize| {
            for k in model.v_range(body) {
                flags[k] = true;
            }
        };
        match actuated {
            None => {
                for body in 1..model.nbodies() {
                    if model.joints()[body].kind() != "free" {
                        set_joint(body);
                    }
                }
            }
            Some(names) => {
                let sequence = names.cast::<PySequence>().map_err(|_| {
                    PyValueError::new_err(format!(
                        "argument 'actuated': expected a list of joint names, got {}",
                        describe(names)
                    ))
                })?;
                for item in sequence.try_iter()? {
                    let item = item?;
                    let name: String = item.extract().map_err(|_| {
                        PyValueError::new_err(format!(
                            "argument 'actuated': expected joint names, got {}",
                            describe(&item)
                        ))
                    })?;
                    match model.joint_names.iter().skip(1).position(|n| *n == name) {
                        Some(k) => set_joint(k + 1),
                        None => {
                            return Err(PyValueError::new_err(format!(
                                "argument 'actuated': unknown joint '{name}'; the model's \
                                 joints are {:?}",
                                &model.joint_names[1..]
                            )))
                        }
                    }
                }
            }
        }
        Ok(flags)
    }
}

/// Baumgarte's gains from None or a pair (K_p, K_d).
pub(crate) fn baumgarte_gains(value: Option<&Bound<PyAny>>) -> PyResult<Option<(f64, f64)>> {
    let Some(value) = value.filter(|v| !v.is_none()) else {
        return Ok(None);
    };
    value.extract::<(f64, f64)>().map(Some).map_err(|_| {
        PyValueError::new_err(format!(
            "argument 'baumgarte': expected None or a pair (kp, kd) of gains (1/s², 1/s), got {}",
            describe(value)
        ))
    })
}

#[pymethods]
impl PyModel {
    /// The constraint Jacobian J(q) of `constraints` (one or a list of `PointAnchor`,
    /// `FrameAnchor`, `JointCoupling`, `Distance`): (rows, nv), the constraints' rows in order;
    /// the rows' velocity is J v.
    fn constraint_jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        constraints: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let nv = self.model.nv;
        self.at_configuration(
            py,
            q,
            constraints,
            |rows| vec![rows, nv],
            |m, data, c, set, q, out| {
                write_row_major(
                    algo::constraint_jacobian(m, data, c, set, q)?,
                    set.rows(),
                    out,
                );
                Ok(())
            },
        )
    }

    /// The errors φ(q) of `constraints`' rows: (rows,), zero where each holds, in the rows'
    /// units and axes (m for points and positions, rad for rotations and hinges). A loop that
    /// has opened by 1 mm shows 1e-3 in its rows.
    fn constraint_error<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        constraints: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.at_configuration(
            py,
            q,
            constraints,
            |rows| vec![rows],
            |m, data, c, set, q, out| {
                algo::constraint_jacobian(m, data, c, set, q)?;
                out.copy_from_slice(c.error.as_slice());
                Ok(())
            },
        )
    }

    /// A configuration near `q` at which `constraints` hold (a closed loop assembled from an
    /// open one, a keyframe put back onto its loops): damped Gauss–Newton steps
    /// `δ = −Jᵀ (J Jᵀ + μ 1)⁻¹ φ` (least-norm corrections; μ = `damping` × the largest
    /// diagonal entry of J Jᵀ takes care of repeated rows) until every row's error is at most
    /// `tolerance`. Returns a dict: "q" (nq,), "success" (bool), "iterations" (int),
    /// "residual" (the largest row error), with a leading N for a batch of configurations.
    #[pyo3(signature = (q, constraints, tolerance=1e-12, max_iterations=50, damping=1e-8))]
    fn close_constraints<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        constraints: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = named::tolerance)] tolerance: f64,
        #[pyo3(from_py_with = named::max_iterations)] max_iterations: usize,
        #[pyo3(from_py_with = named::damping)] damping: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let options = algo::ClosureOptions {
            tolerance,
            max_iterations,
            damping,
        };
        let nq = self.model.nq;
        let packed = self.at_configuration(
            py,
            q,
            constraints,
            |_| vec![nq + 3],
            |m, data, c, set, q, out| {
                let (closed, found) = out.split_at_mut(nq);
                let closure = algo::close_constraints(m, data, c, set, q, closed, &options)?;
                found[0] = f64::from(u8::from(closure.success));
                found[1] = closure.iterations as f64;
                found[2] = closure.residual;
                Ok(())
            },
        )?;
        crate::kinematics::search_result(py, &packed, nq)
    }

    /// The Delassus matrix J M⁻¹ Jᵀ of `constraints` at q: (rows, rows), the inverse inertia
    /// the constraints see.
    fn delassus<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        constraints: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.at_configuration(
            py,
            q,
            constraints,
            |rows| vec![rows, rows],
            |m, data, c, set, q, out| {
                write_row_major(algo::delassus(m, data, c, set, q)?, set.rows(), out);
                Ok(())
            },
        )
    }

    /// Forward dynamics under `constraints`: dict of `qdd` (nv,) and `forces` (rows,) with
    /// M qdd + h = tau + Jᵀ forces and J qdd + J̇ v = 0 (or −K_d J v − K_p φ with `baumgarte`
    /// = (K_p, K_d)). Forces are what the constraints exert on the robot, in each constraint's
    /// axes. `damping` μ > 0 solves redundant constraints (a loop stated twice) by proximal
    /// iterations, giving their least-norm forces; with 0 a redundant row is a ValueError
    /// naming it. `f_ext` as in `inverse_dynamics`.
    #[pyo3(signature = (q, v, tau, constraints, f_ext=None, baumgarte=None, damping=0.0))]
    #[allow(clippy::too_many_arguments)]
    fn constrained_forward_dynamics<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        tau: &Bound<'py, PyAny>,
        constraints: &Bound<'py, PyAny>,
        f_ext: Option<&Bound<'py, PyAny>>,
        baumgarte: Option<&Bound<'py, PyAny>>,
        #[pyo3(from_py_with = named::damping)] damping: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let set = constraint_set(self, constraints)?;
        let options = ConstrainedOptions {
            baumgarte: baumgarte_gains(baumgarte)?,
            damping,
        };
        let algorithm: &ConstrainedAlgorithm = &|m, data, c, state, f_ext| {
            algo::constrained_forward_dynamics(m, data, c, &set, state, f_ext, &options)?;
            Ok(&c.qdd)
        };
        let arguments = (q, v, ("tau", tau));
        let names = ["qdd", "forces"];
        let lanes = Some(LaneRun::ConstrainedForward(&set, &options));
        self.constrained_call(py, arguments, f_ext, &set, names, algorithm, lanes)
    }

    /// The velocity after an impact that makes `constraints` hold: dict of `v` (nv,), the
    /// velocity after, and `impulses` (rows,), with M (v⁺ − v) = Jᵀ impulses and J v⁺ =
    /// −restitution J v (0: the constrained motion stops; 1: it reverses). `damping` as in
    /// `constrained_forward_dynamics`.
    #[pyo3(signature = (q, v, constraints, restitution=0.0, damping=0.0))]
    fn impulse_dynamics<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        constraints: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = named::restitution)] restitution: f64,
        #[pyo3(from_py_with = named::damping)] damping: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let set = constraint_set(self, constraints)?;
        let nv = self.model.nv;
        let kernel: &Kernel = &|m, w, i, out| {
            let Workspace {
                data, constrained, ..
            } = w;
            let c = constraint_data(constrained, m, &set);
            algo::impulse_dynamics(m, data, c, &set, (i[0], i[1]), restitution, damping)?;
            out[..nv].copy_from_slice(c.qdd.as_slice());
            out[nv..].copy_from_slice(c.forces.as_slice());
            Ok(())
        };
        let arguments = [self.q_arg("q", q)?, self.v_arg("v", v)?];
        let lanes = Some(LaneRun::Impulse(&set, (restitution, damping)));
        let shape = [nv + set.rows()];
        let whole = self.evaluate_to(py, &arguments, &shape, Target::Out(None), kernel, lanes)?;
        Self::split_parts(py, &whole, &[("v", &[nv]), ("impulses", &[set.rows()])])
    }

    /// Inverse dynamics under `constraints`: dict of `tau` (nv,; zero on coordinates not
    /// actuated) and `forces` (rows,) with M a + h = tau + Jᵀ forces. `actuated`: the joints
    /// with actuators (default: all but free joints, for a floating base). Where the forces are
    /// not unique they are the least-norm ones, or with `weights` (rows,; each > 0) those of
    /// least Σ weights·forces² (a heavier weight, less force on that row). An `a` that breaks
    /// the constraints (J a + J̇ v ≠ 0), or that the forces cannot produce, is a ValueError
    /// giving the residual.
    #[pyo3(signature = (q, v, a, constraints, actuated=None, f_ext=None, weights=None))]
    #[allow(clippy::too_many_arguments)]
    fn constrained_inverse_dynamics<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        a: &Bound<'py, PyAny>,
        constraints: &Bound<'py, PyAny>,
        actuated: Option<&Bound<'py, PyAny>>,
        f_ext: Option<&Bound<'py, PyAny>>,
        weights: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let set = constraint_set(self, constraints)?;
        let flags = self.actuated_coordinates(actuated)?;
        let weights = weights
            .filter(|w| !w.is_none())
            .map(|w| read_sample("weights", w, SampleShape::vector(set.rows())))
            .transpose()?;
        let algorithm: &ConstrainedAlgorithm = &|m, data, c, state, f_ext| {
            let weights = weights.as_deref();
            algo::constrained_inverse_dynamics(m, data, c, &set, state, f_ext, &flags, weights)?;
            Ok(&c.tau)
        };
        let arguments = (q, v, ("a", a));
        let names = ["tau", "forces"];
        self.constrained_call(py, arguments, f_ext, &set, names, algorithm, None)
    }

    /// Derivatives of `constrained_forward_dynamics` (of the exact equations: no Baumgarte
    /// terms): dict of `qdd` and `forces` as there, `dqdd_dq`, `dqdd_dv`, `dqdd_dtau` (nv, nv)
    /// and `dforces_dq`, `dforces_dv`, `dforces_dtau` (rows, nv). ∂/∂q as in
    /// `inverse_dynamics_derivatives` (tangent space, right perturbations). With `damping` and
    /// redundant rows, qdd's derivatives are exact and the forces' are the least-norm solution
    /// of the differentiated equations (Jᵀ dforces, what reaches the robot, is exact).
    #[pyo3(signature = (q, v, tau, constraints, f_ext=None, damping=0.0))]
    #[allow(clippy::too_many_arguments)]
    fn constrained_forward_dynamics_derivatives<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        tau: &Bound<'py, PyAny>,
        constraints: &Bound<'py, PyAny>,
        f_ext: Option<&Bound<'py, PyAny>>,
        #[pyo3(from_py_with = named::damping)] damping: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let set = constraint_set(self, constraints)?;
        let kernel: &Kernel = &|m, w, i, out| {
            let Workspace {
                data,
                constrained,
                constrained_derivatives,
                forces,
                ..
            } = w;
            let f_ext = i.get(3).map(|flat| {
                fill_forces(forces, flat);
                &forces[..]
            });
            let c = constraint_data(constrained, m, &set);
            let d = derivatives_workspace(constrained_derivatives, m, &set);
            let state = (i[0], i[1], i[2]);
            algo::constrained_forward_dynamics_derivatives(
                m, data, c, d, &set, state, f_ext, damping,
            )?;
            let matrices = [
                &d.dqdd_dq,
                &d.dqdd_dv,
                &d.dqdd_dtau,
                &d.dforces_dq,
                &d.dforces_dv,
                &d.dforces_dtau,
            ];
            write_derivatives(c, &matrices, out);
            Ok(())
        };
        let (nv, rows) = (self.model.nv, set.rows());
        let size = nv + rows + 3 * nv * nv + 3 * rows * nv;
        // `write_derivatives` writes every value: the result's array is not zeroed first
        let whole = self.with_dynamics_arguments((q, v, ("tau", tau)), f_ext, |arguments| {
            self.evaluate_to(py, arguments, &[size], Target::Out(None), kernel, None)
        })?;
        let (square, tall): (&[usize], &[usize]) = (&[nv, nv], &[rows, nv]);
        let parts = [
            ("qdd", &[nv][..]),
            ("forces", &[rows][..]),
            ("dqdd_dq", square),
            ("dqdd_dv", square),
            ("dqdd_dtau", square),
            ("dforces_dq", tall),
            ("dforces_dv", tall),
            ("dforces_dtau", tall),
        ];
        Self::split_parts(py, &whole, &parts)
    }

    /// Derivatives of `impulse_dynamics`: dict of `v` and `impulses` as there, `dv_dq`, `dv_dv`
    /// (nv, nv; of the velocity after) and `dimpulses_dq`, `dimpulses_dv` (rows, nv). ∂/∂q and
    /// `damping` as in `constrained_forward_dynamics_derivatives`.
    #[pyo3(signature = (q, v, constraints, restitution=0.0, damping=0.0))]
    fn impulse_dynamics_derivatives<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        constraints: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = named::restitution)] restitution: f64,
        #[pyo3(from_py_with = named::damping)] damping: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let set = constraint_set(self, constraints)?;
        let kernel: &Kernel = &|m, w, i, out| {
            let Workspace {
                data,
                constrained,
                constrained_derivatives,
                ..
            } = w;
            let c = constraint_data(constrained, m, &set);
            let d = derivatives_workspace(constrained_derivatives, m, &set);
            let state = (i[0], i[1]);
            algo::impulse_dynamics_derivatives(m, data, c, d, &set, state, restitution, damping)?;
            let matrices = [&d.dqdd_dq, &d.dqdd_dv, &d.dforces_dq, &d.dforces_dv];
            write_derivatives(c, &matrices, out);
            Ok(())
        };
        let (nv, rows) = (self.model.nv, set.rows());
        let size = nv + rows + 2 * nv * nv + 2 * rows * nv;
        let arguments = [self.q_arg("q", q)?, self.v_arg("v", v)?];
        let whole = self.evaluate_to(py, &arguments, &[size], Target::Out(None), kernel, None)?;
        let (square, tall): (&[usize], &[usize]) = (&[nv, nv], &[rows, nv]);
        let parts = [
            ("v", &[nv][..]),
            ("impulses", &[rows][..]),
            ("dv_dq", square),
            ("dv_dv", square),
            ("dimpulses_dq", tall),
            ("dimpulses_dv", tall),
        ];
        Self::split_parts(py, &whole, &parts)
    }
}

/// The derivatives' workspace in `slot` for `set`, made again when the set's size changed.
fn derivatives_workspace<'w>(
    slot: &'w mut Option<Box<ConstrainedDerivatives>>,
    model: &Model,
    set: &ConstraintSet,
) -> &'w mut ConstrainedDerivatives {
    made_for(
        slot,
        |d| d.fits(model, set),
        || ConstrainedDerivatives::new(model, set),
    )
}

/// q̈ (or q̇⁺) and the forces of `c`, then each of `matrices` row by row, one after the other.
fn write_derivatives(c: &ConstraintData, matrices: &[&DMatrix<f64>], out: &mut [f64]) {
    let (nv, rows) = (c.qdd.len(), c.forces.len());
    out[..nv].copy_from_slice(c.qdd.as_slice());
    out[nv..nv + rows].copy_from_slice(c.forces.as_slice());
    let mut rest = &mut out[nv + rows..];
    for matrix in matrices {
        let (part, after) = rest.split_at_mut(matrix.len());
        write_row_major(matrix, matrix.nrows(), part);
        rest = after;
    }
}
