//! The Python `Model`: a core model with its preallocated workspace, and the one evaluation path
//! every numeric method takes (one sample in the caller's thread, a batch on all cores with the GIL
//! released).

use crate::args::*;
use crate::results::new_array;
use crate::to_py_err;
use nalgebra::DMatrix;
use numpy::ndarray::Axis;
use numpy::npyffi::NPY_ARRAY_WRITEABLE;
use numpy::{
    PyArray1, PyArray2, PyArray3, PyArray4, PyArrayDyn, PyArrayMethods, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyFileNotFoundError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyString;
use rayon::prelude::*;
use robodyn::algo::{self, BatchResult, BatchWorkspace, States};
use robodyn::integrate::StepWorkspace;
use robodyn::spatial::Force;
use robodyn::{Data, Error, Model};
use rustc_hash::FxHashMap;
use std::sync::Mutex;

/// What a kernel works in: the algorithm workspace and a buffer for external forces.
pub(crate) struct Workspace {
    pub(crate) data: Data,
    pub(crate) forces: Vec<Force>,
    /// Two nv × nv results of a pair of Jacobians (`integrate_jacobians`, ...).
    pub(crate) jacobians: (DMatrix<f64>, DMatrix<f64>),
    /// The stages of a simulation step, made on the first `step` call.
    pub(crate) step: Option<Box<StepWorkspace>>,
    /// The lane buffers of the batch kernels, made on the first batch that uses them.
    pub(crate) lanes: Option<Box<BatchWorkspace>>,
}

impl Workspace {
    pub(crate) fn new(model: &Model) -> Self {
        Workspace {
            data: Data::new(model),
            forces: vec![Force::ZERO; model.nbodies() - 1],
            jacobians: (
                DMatrix::zeros(model.nv, model.nv),
                DMatrix::zeros(model.nv, model.nv),
            ),
            step: None,
            lanes: None,
        }
    }

    /// The lane buffers of the batch kernels, made on first use.
    fn lanes(&mut self, model: &Model) -> &mut BatchWorkspace {
        self.lanes
            .get_or_insert_with(|| Box::new(BatchWorkspace::new(model)))
    }
}

/// Copies a flat array of `[linear; angular]` rows, one per body, into `forces`.
pub(crate) fn fill_forces(forces: &mut [Force], flat: &[f64]) {
    for (force, row) in forces.iter_mut().zip(flat.chunks_exact(6)) {
        *force = Force::from_array(&[row[0], row[1], row[2], row[3], row[4], row[5]]);
    }
}

/// A core algorithm taking (q, v, a or τ, external forces) and returning a vector in `Data`.
pub(crate) type DynamicsAlgorithm = for<'d> fn(
    &Model,
    &'d mut Data,
    &[f64],
    &[f64],
    &[f64],
    Option<&[Force]>,
) -> robodyn::Result<&'d nalgebra::DVector<f64>>;

/// One computation on one sample: inputs (flattened, in argument order) to a flattened output.
pub(crate) type Kernel<'k> =
    dyn Fn(&Model, &mut Workspace, &[&[f64]], &mut [f64]) -> robodyn::Result<()> + Sync + 'k;

/// The batch kernels in lanes (`robodyn::algo::lanes`) a method can run on each thread's run of
/// consecutive samples instead of one sample at a time.
#[derive(Debug, Clone, Copy)]
pub(crate) enum LaneKernel {
    /// Inputs q[, v[, a]] (zero where absent): inverse dynamics, bias forces, gravity.
    NewtonEuler,
    /// Inputs q, v, τ: forward dynamics.
    ArticulatedBody,
    /// Input q: the mass matrix.
    CompositeRigidBody,
    /// Inputs q, v, a: ∂τ/∂q, ∂τ/∂v and M stacked.
    RneaDerivatives,
    /// Inputs q, v, τ: ∂q̈/∂q, ∂q̈/∂v and M⁻¹ stacked.
    AbaDerivatives,
    /// Input q: the pose of a frame (its index), 4 × 4.
    FramePose(usize),
    /// Input q: the Jacobian of a frame (its index) in a reference's coordinates, 6 × nv.
    Jacobian(usize, algo::Reference),
}

impl LaneKernel {
    /// Runs on a run of samples: `inputs` hold the run's rows, `out` its results; an error names
    /// the sample by its place in the run.
    fn run(
        self,
        model: &Model,
        workspace: &mut Workspace,
        inputs: &[&[f64]],
        out: &mut [f64],
    ) -> BatchResult {
        let lanes = workspace.lanes(model);
        let (q, input) = (inputs[0], |k: usize| inputs.get(k).copied());
        let dynamics = States {
            q,
            v: input(1),
            a: input(2),
            tau: None,
        };
        match self {
            LaneKernel::NewtonEuler => algo::newton_euler_batch(model, lanes, dynamics, out),
            LaneKernel::RneaDerivatives => {
                algo::rnea_derivatives_batch(model, lanes, dynamics, out)
            }
            LaneKernel::CompositeRigidBody => algo::crba_batch(model, lanes, q, out),
            LaneKernel::FramePose(frame) => algo::frame_pose_batch(model, lanes, q, frame, out),
            LaneKernel::Jacobian(frame, reference) => {
                algo::jacobian_batch(model, lanes, q, (frame, reference), out)
            }
            LaneKernel::ArticulatedBody | LaneKernel::AbaDerivatives => {
                let forward = States {
                    a: None,
                    tau: input(2),
                    ..dynamics
                };
                match self {
                    LaneKernel::ArticulatedBody => algo::aba_batch(model, lanes, forward, out),
                    _ => algo::aba_derivatives_batch(model, lanes, forward, out),
                }
            }
        }
    }
}

/// The most numeric arguments a method takes (q, v, a, f_ext).
pub(crate) const MAX_ARGUMENTS: usize = 4;

/// Runs `kernel` and rejects a result that is not finite (finite inputs so large that the
/// arithmetic overflowed), so that no NaN or infinity reaches the caller.
pub(crate) fn run_kernel(
    kernel: &Kernel,
    model: &Model,
    workspace: &mut Workspace,
    inputs: &[&[f64]],
    out: &mut [f64],
) -> robodyn::Result<()> {
    kernel(model, workspace, inputs, out)?;
    match first_overflow(out) {
        Some(index) => Err(Error::Overflow {
            index,
            value: out[index],
        }),
        None => Ok(()),
    }
}

/// The first entry of `out` that is not finite, if any: one vectorised pass, then the search.
fn first_overflow(out: &[f64]) -> Option<usize> {
    if robodyn::error::all_finite(out) {
        return None;
    }
    out.iter().position(|x| !x.is_finite())
}

/// How many states a batch in lanes evaluates before checking their results for overflow: as
/// many as fill about a core's L2 cache (so the check reads them from cache, not from memory),
/// in whole groups of the widest lanes.
fn states_per_piece(output_size: usize) -> usize {
    const CACHED_BYTES: usize = 256 * 1024;
    const WIDEST_LANES: usize = 8;
    (CACHED_BYTES / (8 * output_size))
        .next_multiple_of(WIDEST_LANES)
        .max(WIDEST_LANES)
}

/// Asks the kernel to back a large buffer not yet touched with huge pages (Linux's transparent
/// huge pages, "madvise" mode): a batch's result is written once, and faulting it in 4 KiB pages
/// costs more than computing it (a 10 000-state Talos derivative batch writes 600 MB). Advice
/// only: where it is not taken, nothing changes.
fn advise_huge_pages(buffer: &mut [f64]) {
    const LARGE: usize = 1 << 21;
    const PAGE: usize = 4096;
    #[cfg(target_os = "linux")]
    if std::mem::size_of_val(buffer) >= LARGE {
        // madvise takes a page-aligned start: from the buffer's first whole page
        let start = buffer.as_mut_ptr() as usize;
        let offset = start.next_multiple_of(PAGE) - start;
        // SAFETY: the range lies within the buffer's own memory; MADV_HUGEPAGE changes how it is
        // backed, never its contents.
        unsafe {
            libc::madvise(
                (start + offset) as *mut libc::c_void,
                std::mem::size_of_val(buffer) - offset,
                libc::MADV_HUGEPAGE,
            );
        }
    }
}

/// A robot model with its preallocated workspace. Every numeric method takes one state (q of
/// shape (nq,)) or a batch (shape (N, nq)), returning the result or a stack of N results; batches
/// release the GIL and run on all cores.
#[pyclass(name = "Model", module = "robodyn._core")]
pub(crate) struct PyModel {
    pub(crate) model: Model,
    pub(crate) workspace: Mutex<Workspace>,
    /// Workspaces for the threads of a batch, kept between calls (making one allocates).
    pub(crate) batch_workspaces: Mutex<Vec<Workspace>>,
    /// Frame name to index, for the calls that take a frame by name (a fast hash: the names are
    /// the model's own, and SipHash had cost a tenth of a Talos Jacobian call's fixed cost).
    pub(crate) frame_indices: FxHashMap<String, usize>,
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
            batch_workspaces: Mutex::new(Vec::new()),
            frame_indices,
        }
    }

    /// Runs `kernel` on one sample or a batch of the `arguments`, producing `output_shape` per
    /// sample.
    pub(crate) fn evaluate<'py>(
        &self,
        py: Python<'py>,
        arguments: &[Argument<'py>],
        output_shape: &[usize],
        kernel: &Kernel,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate_to(py, arguments, output_shape, Target::Zeros, kernel, None)
    }

    /// [`Self::evaluate`] for a kernel that writes every value of its result: into the caller's
    /// array `out` when one is given (checked by [`output_array`]), returned, so that a loop can
    /// reuse its result array; else into a new array not zeroed first. A batch runs the kernel in
    /// `lanes` (when given) on each thread's run of samples instead of `kernel` on one sample at
    /// a time.
    pub(crate) fn evaluate_into<'py>(
        &self,
        py: Python<'py>,
        arguments: &[Argument<'py>],
        output_shape: &[usize],
        out: Option<&Bound<'py, PyAny>>,
        kernel: &Kernel,
        lanes: Option<LaneKernel>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate_to(py, arguments, output_shape, Target::Out(out), kernel, lanes)
    }

    /// [`Self::evaluate_into`] with the result's array chosen by `target`.
    pub(crate) fn evaluate_to<'py>(
        &self,
        py: Python<'py>,
        arguments: &[Argument<'py>],
        output_shape: &[usize],
        target: Target<'_, 'py>,
        kernel: &Kernel,
        lanes: Option<LaneKernel>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (out, zeroed) = match target {
            Target::Zeros => (None, true),
            Target::Out(out) => (out, false),
        };
        let batch = common_batch(arguments)?;
        // the inputs in place, or copies of the strided ones, each argument looked at once (plain
        // loops: through an array of `Cow`s made by `array::from_fn`, each came back through
        // memory and was copied again)
        let mut in_place: [Option<&[f64]>; MAX_ARGUMENTS] = [None; MAX_ARGUMENTS];
        let mut copies: [Vec<f64>; MAX_ARGUMENTS] = Default::default();
        for ((place, copy), argument) in in_place.iter_mut().zip(&mut copies).zip(arguments) {
            *place = argument.contiguous_values();
            if place.is_none() {
                *copy = argument.copied_values();
            }
        }
        let mut values: [&[f64]; MAX_ARGUMENTS] = [&[]; MAX_ARGUMENTS];
        for ((value, place), copy) in values.iter_mut().zip(in_place).zip(&copies) {
            *value = place.unwrap_or(copy);
        }
        let values = &values[..arguments.len()];
        let target = match out {
            Some(out) => Some(output_array(out, batch, output_shape, arguments, values)?),
            None => None,
        };
        let output_size: usize = output_shape.iter().product();
        let model = &self.model;
        match batch {
            None => {
                let given = target.is_some();
                let output = match target {
                    Some(target) => target,
                    None => new_array(py, output_shape, zeroed)?,
                };
                // SAFETY: a new array nothing else refers to yet, or the caller's, checked to
                // share no memory with an input
                let out = unsafe { output.as_slice_mut() }
                    .map_err(|e| PyValueError::new_err(e.to_string()))?;
                match self.workspace.try_lock() {
                    Ok(mut workspace) => run_kernel(kernel, model, &mut workspace, values, out),
                    Err(_) => run_kernel(kernel, model, &mut Workspace::new(model), values, out),
                }
                .map_err(to_py_err)?;
                if output_shape.is_empty() && !given {
                    return output.get_item(());
                }
                Ok(output.into_any())
            }
            Some(n) => {
                let sizes: [usize; MAX_ARGUMENTS] = std::array::from_fn(|k| {
                    arguments
                        .get(k)
                        .map_or(0, |a| a.sample_shape.as_slice().iter().product())
                });
                let batch = BatchInputs {
                    values,
                    sizes: &sizes[..values.len()],
                    output_size,
                };
                if let Some(output) = target {
                    // SAFETY: as for one sample
                    let out = unsafe { output.as_slice_mut() }
                        .map_err(|e| PyValueError::new_err(e.to_string()))?;
                    self.run_batch(py, &batch, out, kernel, lanes)?;
                    return Ok(output.into_any());
                }
                let mut out = vec![0.0; n * output_size];
                advise_huge_pages(&mut out);
                self.run_batch(py, &batch, &mut out, kernel, lanes)?;
                let shape: Vec<usize> = std::iter::once(n)
                    .chain(output_shape.iter().copied())
                    .collect();
                Ok(PyArray1::from_vec(py, out).reshape(shape)?.into_any())
            }
        }
    }

    /// Runs `kernel` on every sample of a batch into `out` (or `lanes` on runs of samples), with
    /// the GIL released, on all cores: a few runs of consecutive samples per thread (for
    /// balance), each in a workspace taken from the pool and given back.
    fn run_batch(
        &self,
        py: Python,
        batch: &BatchInputs,
        out: &mut [f64],
        kernel: &Kernel,
        lanes: Option<LaneKernel>,
    ) -> PyResult<()> {
        let (model, pool) = (&self.model, &self.batch_workspaces);
        let output_size = batch.output_size.max(1);
        let n = out.len() / output_size;
        let run = n.div_ceil(4 * rayon::current_num_threads()).max(1);
        let result = py.detach(|| {
            out.par_chunks_mut(run * output_size)
                .enumerate()
                .try_for_each(|(r, outputs)| {
                    let taken = pool.lock().ok().and_then(|mut p| p.pop());
                    let mut workspace = taken.unwrap_or_else(|| Workspace::new(model));
                    let first = r * run;
                    let mut inputs: [&[f64]; MAX_ARGUMENTS] = [&[]; MAX_ARGUMENTS];
                    let mut select = |first: usize, count: usize| {
                        for ((input, value), size) in
                            inputs.iter_mut().zip(batch.values).zip(batch.sizes)
                        {
                            *input = &value[first * size..(first + count) * size];
                        }
                        inputs
                    };
                    let arguments = batch.values.len();
                    match lanes {
                        Some(lanes) => {
                            // in pieces whose results are still in cache when checked
                            let piece = states_per_piece(output_size);
                            for (p, outputs) in outputs.chunks_mut(piece * output_size).enumerate()
                            {
                                let first = first + p * piece;
                                let count = outputs.len() / output_size;
                                let inputs = select(first, count);
                                lanes
                                    .run(model, &mut workspace, &inputs[..arguments], outputs)
                                    .map_err(|(k, e)| (first + k, e))?;
                                if let Some(index) = first_overflow(outputs) {
                                    let value = outputs[index];
                                    let (k, index) = (index / output_size, index % output_size);
                                    return Err((first + k, Error::Overflow { index, value }));
                                }
                            }
                        }
                        None => {
                            for (k, out) in (first..).zip(outputs.chunks_mut(output_size)) {
                                let inputs = select(k, 1);
                                run_kernel(
                                    kernel,
                                    model,
                                    &mut workspace,
                                    &inputs[..arguments],
                                    out,
                                )
                                .map_err(|e| (k, e))?;
                            }
                        }
                    }
                    if let Ok(mut p) = pool.lock() {
                        p.push(workspace);
                    }
                    Ok(())
                })
        });
        result.map_err(|(k, error)| {
            let message = format!("batch element {k}: {error}");
            match error {
                Error::FileNotFound { .. } => PyFileNotFoundError::new_err(message),
                _ => PyValueError::new_err(message),
            }
        })
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
}

/// Where a kernel's result goes.
pub(crate) enum Target<'a, 'py> {
    /// A new array of zeros: for a kernel that may leave values as they are.
    Zeros,
    /// The caller's `out` when given, else a new array not zeroed: for a kernel that writes
    /// every value (as it must for a caller's array).
    Out(Option<&'a Bound<'py, PyAny>>),
}

/// The inputs of a batch: each argument's values, flattened, and its size per sample.
struct BatchInputs<'v> {
    values: &'v [&'v [f64]],
    sizes: &'v [usize],
    output_size: usize,
}

/// The batch size the arguments share (`None`: one sample each), or an error naming the first
/// argument that differs.
fn common_batch(arguments: &[Argument]) -> PyResult<Option<usize>> {
    let batch = arguments[0].batch()?;
    for argument in &arguments[1..] {
        if argument.batch()? != batch {
            return Err(PyValueError::new_err(format!(
                "argument '{}': expected {} like argument '{}', got shape {}",
                argument.name,
                match batch {
                    None => "a single sample".to_string(),
                    Some(n) => format!("a batch of {n}"),
                },
                arguments[0].name,
                shape_text(argument.array.shape())
            )));
        }
    }
    Ok(batch)
}

/// The caller's `out` array, checked: float64, the result's shape (with the batch's leading
/// N), C-contiguous, writeable, and sharing no memory with an input (the kernel would read what
/// it had just written).
fn output_array<'py>(
    out: &Bound<'py, PyAny>,
    batch: Option<usize>,
    output_shape: &[usize],
    arguments: &[Argument],
    values: &[&[f64]],
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let expected: Vec<usize> = batch
        .into_iter()
        .chain(output_shape.iter().copied())
        .collect();
    let error = |what: String| PyValueError::new_err(format!("argument 'out': {what}"));
    let Ok(array) = out.cast::<PyArrayDyn<f64>>() else {
        let got = match out.cast::<PyUntypedArray>() {
            Ok(array) => format!(
                "an array of dtype {} and shape {}",
                array.dtype(),
                shape_text(array.shape())
            ),
            Err(_) => format!("{}", out.get_type().name()?),
        };
        return Err(error(format!(
            "expected a float64 NumPy array of shape {}, got {got}",
            shape_text(&expected)
        )));
    };
    if array.shape() != expected.as_slice() {
        return Err(error(format!(
            "expected shape {}, got {}",
            shape_text(&expected),
            shape_text(array.shape())
        )));
    }
    if !array.is_c_contiguous() {
        return Err(error(
            "expected a C-contiguous array, got a strided view".into(),
        ));
    }
    // SAFETY: reads the flags of a live array object
    let flags = unsafe { (*array.as_array_ptr()).fields.flags };
    if flags & NPY_ARRAY_WRITEABLE == 0 {
        return Err(error(
            "expected a writeable array, got a read-only one".into(),
        ));
    }
    let start = array.data() as usize;
    let end = start + std::mem::size_of::<f64>() * array.len();
    for (argument, value) in arguments.iter().zip(values) {
        let (input_start, input_end) = (value.as_ptr() as usize, value.as_ptr_range().end as usize);
        // (a copy of a strided input is the call's own and never overlaps)
        if input_start < end && start < input_end {
            return Err(error(format!(
                "shares memory with argument '{}'; pass a separate array",
                argument.name
            )));
        }
    }
    Ok(array.clone())
}

/// A core algorithm giving a matrix of the configuration (M, M⁻¹, A_G, J_com) in `Data`.
pub(crate) type MatrixOfQ =
    for<'d> fn(&Model, &'d mut Data, &[f64]) -> robodyn::Result<&'d DMatrix<f64>>;

impl PyModel {
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

/// Writes the first `rows` rows of a matrix (column-major in nalgebra) into a row-major output.
pub(crate) fn write_row_major(matrix: &nalgebra::DMatrix<f64>, rows: usize, out: &mut [f64]) {
    let (stored_rows, columns) = matrix.shape();
    // output row by row, reading along the matrix's row (a stride of its column length)
    for (r, out_row) in out.chunks_exact_mut(columns.max(1)).take(rows).enumerate() {
        let row = matrix.as_slice()[r..].iter().step_by(stored_rows);
        for (target, value) in out_row.iter_mut().zip(row) {
            *target = *value;
        }
    }
}

pub(crate) fn vector_array<'py>(py: Python<'py>, values: &[f64]) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, values)
}

/// `out = matrix · vector` (out has the matrix's rows).
pub(crate) fn matrix_times(matrix: &DMatrix<f64>, vector: &[f64], out: &mut [f64]) {
    for (row, value) in out.iter_mut().enumerate() {
        *value = vector
            .iter()
            .enumerate()
            .map(|(column, x)| matrix[(row, column)] * x)
            .sum();
    }
}

/// Dict keys as Python strings made once per process (with their hash), not on every call.
macro_rules! keys {
    ($py:expr, $($name:literal),+ $(,)?) => {
        [$(pyo3::intern!($py, $name)),+]
    };
}
pub(crate) use keys;

/// {names[k]: stack[..., k, :, :]}: a stack of results along axis −3 as a dict of views into it
/// (made without a Python call: contiguous for one sample, strided over a batch).
pub(crate) fn split_stack<'py>(
    py: Python<'py>,
    stack: &Bound<'py, PyAny>,
    names: &[&Bound<'py, PyString>],
) -> PyResult<Bound<'py, PyAny>> {
    let out = pyo3::types::PyDict::new(py);
    // SAFETY (both arms): the array was just made by `evaluate` and nothing else refers to it
    // yet; each view keeps it alive as its base.
    if let Ok(single) = stack.cast::<PyArray3<f64>>() {
        let whole = unsafe { single.as_array() };
        for (k, name) in names.iter().enumerate() {
            let part = whole.index_axis(Axis(0), k);
            out.set_item(*name, unsafe {
                PyArray2::borrow_from_array(&part, stack.clone())
            })?;
        }
    } else {
        let batch = stack.cast::<PyArray4<f64>>()?;
        let whole = unsafe { batch.as_array() };
        for (k, name) in names.iter().enumerate() {
            let part = whole.index_axis(Axis(1), k);
            out.set_item(*name, unsafe {
                PyArray3::borrow_from_array(&part, stack.clone())
            })?;
        }
    }
    Ok(out.into_any())
}

/// Matrices of `rows` rows each, one after the other, row-major, into `out`.
pub(crate) fn write_stack(matrices: &[&DMatrix<f64>], rows: usize, out: &mut [f64]) {
    let size = out.len() / matrices.len();
    for (matrix, block) in matrices.iter().zip(out.chunks_exact_mut(size)) {
        write_row_major(matrix, rows, block);
    }
}
