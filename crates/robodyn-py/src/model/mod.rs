//! The Python `Model`: a core model with its preallocated workspace, and the one evaluation path
//! every numeric method takes (one sample in the caller's thread, a batch on all cores with the GIL
//! released).
//!
//! Its parts: `workspace` (a kernel's workspace and the batch's pool of them), `evaluate` (the
//! evaluation path), `schedule` (how a batch is spread over the cores and checked, by one sample at a time or by
//! the core's batch algorithms in lanes), `pages` (huge-page advice), `output` (`out=` checks and result
//! layouts); the error mapping is the crate's `errors`.

mod evaluate;
mod output;
mod pages;
mod schedule;
mod workspace;

pub(crate) use output::*;
pub(crate) use schedule::{Kernel, LaneRun};
pub(crate) use workspace::{fill_forces, Workspace, WorkspacePool};

use crate::args::*;
use crate::constraints::ResolvedConstraints;
use crate::to_py_err;
use nalgebra::DMatrix;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyString;
use robodyn::soft::step::SceneStep;
use robodyn::{Data, Model};
use rustc_hash::FxHashMap;
use std::sync::Mutex;

/// A core algorithm taking (q, v, a or τ, external forces) and returning a vector in `Data`.
pub(crate) type DynamicsAlgorithm = for<'d> fn(
    &Model,
    &'d mut Data,
    &[f64],
    &[f64],
    &[f64],
    Option<&[robodyn::spatial::Force]>,
) -> robodyn::Result<&'d nalgebra::DVector<f64>>;

/// A core algorithm giving a matrix of the configuration (M, M⁻¹, A_G, J_com) in `Data`.
pub(crate) type MatrixOfQ =
    for<'d> fn(&Model, &'d mut Data, &[f64]) -> robodyn::Result<&'d DMatrix<f64>>;

/// A robot model with its preallocated workspace. Every numeric method takes one state (q of
/// shape (nq,)) or a batch (shape (N, nq)), returning the result or a stack of N results; batches
/// release the GIL and run on all cores.
#[pyclass(name = "Model", module = "robodyn._core")]
pub(crate) struct PyModel {
    pub(crate) model: Model,
    pub(crate) workspace: Mutex<Workspace>,
    /// Workspaces for the threads of a batch, kept between calls (making one allocates).
    pub(crate) batch_workspaces: WorkspacePool,
    /// Frame name to index, for the calls that take a frame by name (a fast hash: the names are
    /// the model's own, and SipHash had cost a tenth of a Talos Jacobian call's fixed cost).
    pub(crate) frame_indices: FxHashMap<String, usize>,
    /// The constraint set the last constrained call resolved (see `ResolvedConstraints`).
    pub(crate) last_constraints: Mutex<Option<ResolvedConstraints>>,
    /// The scene's step as made for this model (its weights, geom pairs and scratch space), used
    /// by each `step_scene` call; forgotten when a property changes.
    pub(crate) scene_step: Mutex<Option<SceneStep>>,
}

impl PyModel {
    pub(crate) fn wrap(model: Model) -> Self {
        let workspace = Mutex::new(Workspace::new(&model));
        let mut frame_indices = FxHashMap::default();
        for (index, frame) in model.frames.iter().enumerate() {
            // the first frame of a name wins, as in Model::frame_index
            frame_indices.entry(frame.name.clone()).or_insert(index);
        }
        PyModel {
            model,
            workspace,
            batch_workspaces: WorkspacePool::default(),
            frame_indices,
            last_constraints: Mutex::new(None),
            scene_step: Mutex::new(None),
        }
    }

    /// `work` with the model's scene step (made the first time, kept between calls), its solver
    /// starting from q̈₀ as a new one would.
    pub(crate) fn with_scene_step<T>(
        &self,
        work: impl FnOnce(&mut SceneStep) -> robodyn::Result<T>,
    ) -> robodyn::Result<T> {
        let mut cached = self.scene_step.lock().unwrap_or_else(|e| e.into_inner());
        if cached.is_none() {
            *cached = Some(SceneStep::new(&self.model)?);
        }
        let stepper = cached.as_mut().expect("made above");
        stepper.forget_warm_start();
        work(stepper)
    }

    /// Forgets the scene step: the model's properties changed.
    pub(crate) fn forget_scene_step(&mut self) {
        *self.scene_step.get_mut().unwrap_or_else(|e| e.into_inner()) = None;
    }

    #[inline(always)]
    pub(crate) fn q_arg<'py>(
        &self,
        name: &'static str,
        value: &Bound<'py, PyAny>,
    ) -> PyResult<Argument<'py>> {
        Argument::new(name, value, SampleShape::vector(self.model.nq))
    }

    #[inline(always)]
    pub(crate) fn v_arg<'py>(
        &self,
        name: &'static str,
        value: &Bound<'py, PyAny>,
    ) -> PyResult<Argument<'py>> {
        Argument::new(name, value, SampleShape::vector(self.model.nv))
    }

    pub(crate) fn frame_index(&self, frame: &Bound<PyAny>) -> PyResult<usize> {
        // a type test first: a failed extraction builds a Python exception, dearer than the call
        if let Ok(name) = frame.cast::<PyString>() {
            let name = name.to_str()?;
            return match self.frame_indices.get(name) {
                Some(&index) => Ok(index),
                None => self.model.frame_index(name).map_err(to_py_err),
            };
        }
        match frame.extract::<usize>() {
            Ok(index) if index < self.model.frames.len() => Ok(index),
            _ => Err(PyValueError::new_err(format!(
                "argument 'frame': expected a frame name or an index below {}, got {}",
                self.model.frames.len(),
                frame.repr()?
            ))),
        }
    }

    /// The first `rows` rows of `algorithm`'s matrix (rows × nv), per state.
    pub(crate) fn matrix_of_q<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        rows: usize,
        algorithm: MatrixOfQ,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.matrix_of_q_into(py, q, rows, None, algorithm)
    }

    /// [`Self::matrix_of_q`] into the caller's `out` when given.
    pub(crate) fn matrix_of_q_into<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        rows: usize,
        out: Option<&Bound<'py, PyAny>>,
        algorithm: MatrixOfQ,
    ) -> PyResult<Bound<'py, PyAny>> {
        let shape = [rows, self.model.nv];
        let kernel: &Kernel = &|m, w, i, out| {
            write_row_major(algorithm(m, &mut w.data, i[0])?, rows, out);
            Ok(())
        };
        self.evaluate_into(py, &[self.q_arg("q", q)?], &shape, out, kernel, None)
    }

    /// `algorithm`'s matrix times v (rows,), per state: a momentum or a velocity.
    pub(crate) fn matrix_of_q_times_v<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        rows: usize,
        algorithm: MatrixOfQ,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(
            py,
            &[self.q_arg("q", q)?, self.v_arg("v", v)?],
            &[rows],
            &|m, w, i, out| {
                matrix_times(algorithm(m, &mut w.data, i[0])?, i[1], out);
                Ok(())
            },
        )
    }
}
