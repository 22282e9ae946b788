//! PyO3 glue for robodyn: argument conversion, batching over all cores with the GIL released, and
//! errors turned into `ValueError` / `FileNotFoundError`. No physics lives here.

use nalgebra::{DMatrix, DVector};
use numpy::ndarray::IxDyn;
use numpy::{
    AllowTypeChange, PyArray1, PyArrayDyn, PyArrayLikeDyn, PyArrayMethods, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyFileNotFoundError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rand::{rngs::StdRng, SeedableRng};
use rayon::prelude::*;
use robodyn::algo::{self, Reference};
use robodyn::io::LoadOptions;
use robodyn::spatial::Force;
use robodyn::{Data, Error, Model};
use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::Mutex;

mod simulation;

/// A core error as the Python exception the API promises.
fn to_py_err(error: Error) -> PyErr {
    match error {
        Error::FileNotFound { .. } => PyFileNotFoundError::new_err(error.to_string()),
        _ => PyValueError::new_err(error.to_string()),
    }
}

/// What a kernel works in: the algorithm workspace and a buffer for external forces.
struct Workspace {
    data: Data,
    forces: Vec<Force>,
}

impl Workspace {
    fn new(model: &Model) -> Self {
        Workspace {
            data: Data::new(model),
            forces: vec![Force::ZERO; model.nbodies() - 1],
        }
    }
}

/// Copies a flat array of `[linear; angular]` rows, one per body, into `forces`.
fn fill_forces(forces: &mut [Force], flat: &[f64]) {
    for (force, row) in forces.iter_mut().zip(flat.chunks_exact(6)) {
        *force = Force::from_array(&[row[0], row[1], row[2], row[3], row[4], row[5]]);
    }
}

/// A core algorithm taking (q, v, a or τ, external forces) and returning a vector in `Data`.
type DynamicsAlgorithm = for<'d> fn(
    &Model,
    &'d mut Data,
    &[f64],
    &[f64],
    &[f64],
    Option<&[Force]>,
) -> robodyn::Result<&'d nalgebra::DVector<f64>>;

/// One computation on one sample: inputs (flattened, in argument order) to a flattened output.
type Kernel<'k> =
    dyn Fn(&Model, &mut Workspace, &[&[f64]], &mut [f64]) -> robodyn::Result<()> + Sync + 'k;

/// The most numeric arguments a method takes (q, v, a, f_ext).
const MAX_ARGUMENTS: usize = 4;

/// The shape of one sample of an argument: one or two dimensions, stored without allocating.
#[derive(Clone, Copy)]
struct SampleShape {
    dims: [usize; 2],
    ndim: usize,
}

impl SampleShape {
    fn vector(n: usize) -> Self {
        SampleShape {
            dims: [n, 0],
            ndim: 1,
        }
    }

    fn matrix(rows: usize, columns: usize) -> Self {
        SampleShape {
            dims: [rows, columns],
            ndim: 2,
        }
    }

    fn as_slice(&self) -> &[usize] {
        &self.dims[..self.ndim]
    }
}

/// Runs `kernel` and rejects a result that is not finite (finite inputs so large that the
/// arithmetic overflowed), so that no NaN or infinity reaches the caller.
fn run_kernel(
    kernel: &Kernel,
    model: &Model,
    workspace: &mut Workspace,
    inputs: &[&[f64]],
    out: &mut [f64],
) -> robodyn::Result<()> {
    kernel(model, workspace, inputs, out)?;
    match out.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(index) => Err(Error::Overflow {
            index,
            value: out[index],
        }),
    }
}

/// A numeric argument: its name, the array, and the shape of one sample.
struct Argument<'py> {
    name: &'static str,
    array: Bound<'py, PyArrayDyn<f64>>,
    sample_shape: SampleShape,
}

impl<'py> Argument<'py> {
    fn new(
        name: &'static str,
        value: &Bound<'py, PyAny>,
        sample_shape: SampleShape,
    ) -> PyResult<Self> {
        // a float64 ndarray is used as it is; anything else goes through numpy.asarray
        if let Ok(array) = value.cast::<PyArrayDyn<f64>>() {
            return Ok(Argument {
                name,
                array: array.clone(),
                sample_shape,
            });
        }
        let converted = value.extract::<PyArrayLikeDyn<'py, f64, AllowTypeChange>>().map_err(|_| {
            PyValueError::new_err(format!(
                "argument '{name}': expected an array of numbers of shape {} or (N, ...), got {}",
                shape_text(sample_shape.as_slice()),
                value.repr().map(|r| r.to_string()).unwrap_or_else(|_| "an unreadable object".into())
            ))
        })?;
        Ok(Argument {
            name,
            array: (**converted).clone(),
            sample_shape,
        })
    }

    /// The batch size, `None` for a single sample; errors if the shape fits neither.
    fn batch(&self) -> PyResult<Option<usize>> {
        let shape = self.array.shape();
        let sample = self.sample_shape.as_slice();
        if shape == sample {
            Ok(None)
        } else if shape.len() == sample.len() + 1 && shape[1..] == *sample {
            Ok(Some(shape[0]))
        } else {
            let batch_shape: Vec<String> = std::iter::once("N".to_string())
                .chain(sample.iter().map(|n| n.to_string()))
                .collect();
            Err(PyValueError::new_err(format!(
                "argument '{}': expected shape {} or ({}), got {}",
                self.name,
                shape_text(sample),
                batch_shape.join(", "),
                shape_text(shape)
            )))
        }
    }

    /// The values in C order, borrowed when the array is contiguous.
    fn values(&self) -> Cow<'_, [f64]> {
        if self.array.is_c_contiguous() {
            // SAFETY: no Rust code holds a mutable view of an input: the only array robodyn writes
            // is the output, which each call creates itself.
            if let Ok(slice) = unsafe { self.array.as_slice() } {
                return Cow::Borrowed(slice);
            }
        }
        Cow::Owned(self.array.to_owned_array().iter().copied().collect())
    }
}

fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// A robot model with its preallocated workspace. Every numeric method takes one state (q of
/// shape (nq,)) or a batch (shape (N, nq)), returning the result or a stack of N results; batches
/// release the GIL and run on all cores.
#[pyclass(name = "Model", module = "robodyn._core")]
struct PyModel {
    model: Model,
    workspace: Mutex<Workspace>,
    /// Frame name to index, for the calls that take a frame by name.
    frame_indices: HashMap<String, usize>,
}

impl PyModel {
    fn wrap(model: Model) -> Self {
        let workspace = Mutex::new(Workspace::new(&model));
        let mut frame_indices = HashMap::new();
        for (index, frame) in model.frames.iter().enumerate() {
            // the first frame of a name wins, as in Model::frame_index
            frame_indices.entry(frame.name.clone()).or_insert(index);
        }
        PyModel {
            model,
            workspace,
            frame_indices,
        }
    }

    /// Runs `kernel` on one sample or a batch of the `arguments`, producing `output_shape` per
    /// sample.
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        arguments: &[Argument<'py>],
        output_shape: &[usize],
        kernel: &Kernel,
    ) -> PyResult<Bound<'py, PyAny>> {
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
        let values: [Cow<[f64]>; MAX_ARGUMENTS] = std::array::from_fn(|k| {
            arguments
                .get(k)
                .map_or(Cow::Borrowed(&[][..]), |a| a.values())
        });
        let values = &values[..arguments.len()];
        let output_size: usize = output_shape.iter().product();
        let model = &self.model;
        match batch {
            None => {
                let mut inputs: [&[f64]; MAX_ARGUMENTS] = [&[]; MAX_ARGUMENTS];
                for (input, value) in inputs.iter_mut().zip(values) {
                    *input = value.as_ref();
                }
                let inputs = &inputs[..values.len()];
                let output = PyArrayDyn::<f64>::zeros(py, IxDyn(output_shape), false);
                // SAFETY: the array was created just above and nothing else refers to it yet.
                let out = unsafe { output.as_slice_mut() }
                    .map_err(|e| PyValueError::new_err(e.to_string()))?;
                match self.workspace.try_lock() {
                    Ok(mut workspace) => run_kernel(kernel, model, &mut workspace, inputs, out),
                    Err(_) => run_kernel(kernel, model, &mut Workspace::new(model), inputs, out),
                }
                .map_err(to_py_err)?;
                if output_shape.is_empty() {
                    return output.get_item(());
                }
                Ok(output.into_any())
            }
            Some(n) => {
                let sizes: Vec<usize> = arguments
                    .iter()
                    .map(|a| a.sample_shape.as_slice().iter().product())
                    .collect();
                let mut out = vec![0.0; n * output_size];
                let result = py.detach(|| {
                    out.par_chunks_mut(output_size.max(1))
                        .enumerate()
                        .try_for_each_init(
                            || (Workspace::new(model), Vec::with_capacity(values.len())),
                            |(workspace, inputs), (k, out)| {
                                inputs.clear();
                                inputs.extend(
                                    values
                                        .iter()
                                        .zip(&sizes)
                                        .map(|(v, s)| &v[k * s..(k + 1) * s]),
                                );
                                run_kernel(kernel, model, workspace, inputs, out)
                                    .map_err(|e| (k, e))
                            },
                        )
                });
                if let Err((k, error)) = result {
                    let message = format!("batch element {k}: {error}");
                    return Err(match error {
                        Error::FileNotFound { .. } => PyFileNotFoundError::new_err(message),
                        _ => PyValueError::new_err(message),
                    });
                }
                let shape: Vec<usize> = std::iter::once(n)
                    .chain(output_shape.iter().copied())
                    .collect();
                Ok(PyArray1::from_vec(py, out).reshape(shape)?.into_any())
            }
        }
    }

    fn q_arg<'py>(&self, name: &'static str, value: &Bound<'py, PyAny>) -> PyResult<Argument<'py>> {
        Argument::new(name, value, SampleShape::vector(self.model.nq))
    }

    fn v_arg<'py>(&self, name: &'static str, value: &Bound<'py, PyAny>) -> PyResult<Argument<'py>> {
        Argument::new(name, value, SampleShape::vector(self.model.nv))
    }

    /// One of the two measures of `algo::manipulability`, per state.
    fn manipulability_measure<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: &Bound<'py, PyAny>,
        task: Option<&Bound<'py, PyAny>>,
        measure: fn((f64, f64)) -> f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let frame = self.frame_index(frame)?;
        let rows = task.map_or_else(|| Ok((0..6).collect()), parse_task)?;
        self.evaluate(py, &[self.q_arg("q", q)?], &[], &|m, w, i, out| {
            out[0] = measure(algo::manipulability(m, &mut w.data, i[0], frame, &rows)?);
            Ok(())
        })
    }

    fn frame_index(&self, frame: &Bound<PyAny>) -> PyResult<usize> {
        if let Ok(name) = frame.extract::<&str>() {
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

    /// Dynamics with optional external forces: `algorithm(q, v, x, f_ext)`.
    fn with_external_forces<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        x: (&'static str, &Bound<'py, PyAny>),
        f_ext: Option<&Bound<'py, PyAny>>,
        algorithm: DynamicsAlgorithm,
    ) -> PyResult<Bound<'py, PyAny>> {
        let mut arguments = vec![
            self.q_arg("q", q)?,
            self.v_arg("v", v)?,
            self.v_arg(x.0, x.1)?,
        ];
        if let Some(f) = f_ext {
            arguments.push(Argument::new(
                "f_ext",
                f,
                SampleShape::matrix(self.model.nbodies() - 1, 6),
            )?);
        }
        self.evaluate(py, &arguments, &[self.model.nv], &|m, w, i, out| {
            let Workspace { data, forces } = w;
            let forces = i.get(3).map(|flat| {
                fill_forces(forces, flat);
                &forces[..]
            });
            out.copy_from_slice(algorithm(m, data, i[0], i[1], i[2], forces)?.as_slice());
            Ok(())
        })
    }
}

/// "argument 'method': expected ..., got '...'".
fn unknown_method(method: &str, expected: &str) -> PyErr {
    PyValueError::new_err(format!(
        "argument 'method': expected {expected}, got '{method}'"
    ))
}

/// The Christoffel symbols at q, row-major (i, j, k), in a new buffer.
fn christoffel_of(model: &Model, worker: &mut Workspace, q: &[f64]) -> robodyn::Result<Vec<f64>> {
    let mut gamma = vec![0.0; model.nv.pow(3)];
    algo::christoffel_symbols(model, &mut worker.data, q, &mut gamma)?;
    Ok(gamma)
}

/// Writes the first `rows` rows of a matrix (column-major in nalgebra) into a row-major output.
/// `out = matrix · vector` (out has the matrix's rows).
fn matrix_times(matrix: &DMatrix<f64>, vector: &[f64], out: &mut [f64]) {
    for (row, value) in out.iter_mut().enumerate() {
        *value = vector
            .iter()
            .enumerate()
            .map(|(column, x)| matrix[(row, column)] * x)
            .sum();
    }
}

fn write_row_major(matrix: &nalgebra::DMatrix<f64>, rows: usize, out: &mut [f64]) {
    let columns = matrix.ncols();
    for (c, column) in matrix
        .as_slice()
        .chunks_exact(matrix.nrows().max(1))
        .enumerate()
    {
        for (r, value) in column.iter().take(rows).enumerate() {
            out[r * columns + c] = *value;
        }
    }
}

fn vector_array<'py>(py: Python<'py>, values: &[f64]) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, values)
}

/// The Jacobian/velocity reference named by the user.
fn parse_reference(reference: &str) -> PyResult<Reference> {
    match reference {
        "world" => Ok(Reference::World),
        "local" => Ok(Reference::Local),
        "spatial" => Ok(Reference::Spatial),
        other => Err(PyValueError::new_err(format!(
            "argument 'reference': expected 'world', 'local' or 'spatial', got '{other}'"
        ))),
    }
}

/// The Jacobian rows of a task: "full", "position", "orientation" or a list of row indices.
fn parse_task(task: &Bound<PyAny>) -> PyResult<Vec<usize>> {
    match task.extract::<String>().as_deref() {
        Ok("full") => Ok((0..6).collect()),
        Ok("position") => Ok((0..3).collect()),
        Ok("orientation") => Ok((3..6).collect()),
        Ok(other) => Err(PyValueError::new_err(format!(
            "argument 'task': expected 'full', 'position', 'orientation' or a list of rows 0..5, got '{other}'"
        ))),
        Err(_) => task.extract::<Vec<usize>>().map_err(|_| {
            PyValueError::new_err(format!(
                "argument 'task': expected 'full', 'position', 'orientation' or a list of rows 0..5, got {}",
                task.repr().map(|r| r.to_string()).unwrap_or_default()
            ))
        }),
    }
}

/// The values of an argument that must be one sample, not a batch.
fn single_sample<'a>(argument: &'a Argument) -> PyResult<Cow<'a, [f64]>> {
    if argument.batch()?.is_some() {
        return Err(PyValueError::new_err(format!(
            "argument '{}': expected shape {}, got {}",
            argument.name,
            shape_text(argument.sample_shape.as_slice()),
            shape_text(argument.array.shape())
        )));
    }
    Ok(argument.values())
}

/// Reads one finite sample of `shape` (a settable property, a constant input).
fn read_sample(name: &'static str, value: &Bound<PyAny>, shape: SampleShape) -> PyResult<Vec<f64>> {
    let argument = Argument::new(name, value, shape)?;
    let values = single_sample(&argument)?.into_owned();
    robodyn::error::check_finite(name, &values).map_err(to_py_err)?;
    Ok(values)
}

/// Reads a settable per-coordinate property.
fn read_property(name: &'static str, value: &Bound<PyAny>, length: usize) -> PyResult<Vec<f64>> {
    read_sample(name, value, SampleShape::vector(length))
}

/// Reads a settable per-coordinate property whose entries must be >= 0.
fn read_non_negative(
    name: &'static str,
    value: &Bound<PyAny>,
    length: usize,
) -> PyResult<DVector<f64>> {
    let values = read_property(name, value, length)?;
    if let Some(k) = values.iter().position(|x| *x < 0.0) {
        return Err(PyValueError::new_err(format!(
            "argument '{name}': expected values >= 0, got {} at index {k}",
            values[k]
        )));
    }
    Ok(DVector::from_vec(values))
}

#[pymethods]
impl PyModel {
    /// The model's name (URDF `<robot name>`).
    #[getter]
    fn name(&self) -> &str {
        &self.model.name
    }

    /// Number of configuration coordinates.
    #[getter]
    fn nq(&self) -> usize {
        self.model.nq
    }

    /// Number of velocity coordinates (degrees of freedom).
    #[getter]
    fn nv(&self) -> usize {
        self.model.nv
    }

    /// Names of the moving joints, in q/v order (depth-first, file order).
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.model.joint_names[1..].to_vec()
    }

    /// Kind of each moving joint: "revolute", "prismatic", "spherical" or "free".
    #[getter]
    fn joint_types(&self) -> Vec<&'static str> {
        self.model.joints[1..].iter().map(|j| j.kind()).collect()
    }

    /// First index of each joint in q (aligned with joint_names).
    #[getter]
    fn joint_idx_q(&self) -> Vec<usize> {
        self.model.idx_q[1..].to_vec()
    }

    /// First index of each joint in v (aligned with joint_names).
    #[getter]
    fn joint_idx_v(&self) -> Vec<usize> {
        self.model.idx_v[1..].to_vec()
    }

    /// Names of the moving bodies (the child link of each joint, aligned with joint_names); the
    /// rows of `f_ext`.
    #[getter]
    fn body_names(&self) -> Vec<String> {
        self.model.body_names[1..].to_vec()
    }

    /// Names of every frame: one per URDF link, moving or merged through a fixed joint.
    #[getter]
    fn frame_names(&self) -> Vec<String> {
        self.model.frames.iter().map(|f| f.name.clone()).collect()
    }

    /// The parent of each moving body, aligned with body_names: -1 for the world, else an index
    /// into body_names.
    #[getter]
    fn body_parents(&self) -> Vec<isize> {
        self.model.parent[1..]
            .iter()
            .map(|&p| p as isize - 1)
            .collect()
    }

    /// The body each frame is attached to, aligned with frame_names: -1 for the world, else an
    /// index into body_names.
    #[getter]
    fn frame_bodies(&self) -> Vec<isize> {
        self.model
            .frames
            .iter()
            .map(|f| f.body as isize - 1)
            .collect()
    }

    /// Gravity vector in world axes (m/s²), settable.
    #[getter]
    fn get_gravity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.gravity.as_slice())
    }

    #[setter]
    fn set_gravity(&mut self, value: &Bound<PyAny>) -> PyResult<()> {
        let values = read_property("gravity", value, 3)?;
        self.model.gravity = nalgebra::Vector3::from_row_slice(&values);
        Ok(())
    }

    /// Rotor inertia per velocity coordinate (kg m² or kg), settable: it adds to M's diagonal and
    /// to inverse and forward dynamics.
    #[getter]
    fn get_armature<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.armature.as_slice())
    }

    #[setter]
    fn set_armature(&mut self, value: &Bound<PyAny>) -> PyResult<()> {
        self.model.armature = read_non_negative("armature", value, self.model.nv)?;
        Ok(())
    }

    /// Lower position limits, shape (nq,), -inf where none.
    #[getter]
    fn lower_position_limit<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.lower_position_limit.as_slice())
    }

    /// Upper position limits, shape (nq,), inf where none.
    #[getter]
    fn upper_position_limit<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.upper_position_limit.as_slice())
    }

    /// Velocity limits, shape (nv,), inf where none.
    #[getter]
    fn velocity_limit<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.velocity_limit.as_slice())
    }

    /// Effort limits, shape (nv,), inf where none.
    #[getter]
    fn effort_limit<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.effort_limit.as_slice())
    }

    /// Viscous damping per velocity coordinate (URDF `<dynamics damping>`, MJCF `damping`),
    /// settable. `simulate` applies it; the dynamics calls do not.
    #[getter]
    fn get_damping<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.damping.as_slice())
    }

    #[setter]
    fn set_damping(&mut self, value: &Bound<PyAny>) -> PyResult<()> {
        self.model.damping = read_non_negative("damping", value, self.model.nv)?;
        Ok(())
    }

    /// Coulomb friction per velocity coordinate (URDF `<dynamics friction>`, MJCF
    /// `frictionloss`), settable. `simulate` applies it smoothed; the dynamics calls do not.
    #[getter]
    fn get_friction<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.friction.as_slice())
    }

    #[setter]
    fn set_friction(&mut self, value: &Bound<PyAny>) -> PyResult<()> {
        self.model.friction = read_non_negative("friction", value, self.model.nv)?;
        Ok(())
    }

    /// Joint spring stiffness per velocity coordinate (MJCF `stiffness`), settable. `simulate`
    /// applies it; the dynamics calls do not.
    #[getter]
    fn get_stiffness<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.stiffness.as_slice())
    }

    #[setter]
    fn set_stiffness(&mut self, value: &Bound<PyAny>) -> PyResult<()> {
        self.model.stiffness = read_non_negative("stiffness", value, self.model.nv)?;
        Ok(())
    }

    /// The configuration at which the joint springs are relaxed, shape (nq,) (MJCF `springref`;
    /// neutral for spherical and free joints), settable to any valid configuration.
    #[getter]
    fn get_spring_reference<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.spring_reference.as_slice())
    }

    #[setter]
    fn set_spring_reference(&mut self, value: &Bound<PyAny>) -> PyResult<()> {
        let values = read_property("spring_reference", value, self.model.nq)?;
        self.model
            .check_configuration(&values)
            .map_err(|e| to_py_err(e.for_argument("spring_reference")))?;
        self.model.spring_reference = DVector::from_vec(values);
        Ok(())
    }

    /// URDF mimic relations as (joint, mimicked joint, multiplier, offset):
    /// q[joint] = multiplier * q[mimicked] + offset. Reported, not enforced.
    #[getter]
    fn mimic_joints(&self) -> Vec<(String, String, f64, f64)> {
        self.model
            .mimics
            .iter()
            .map(|m| {
                (
                    self.model.joint_names[m.joint].clone(),
                    self.model.joint_names[m.mimicked].clone(),
                    m.multiplier,
                    m.offset,
                )
            })
            .collect()
    }

    /// What the loader accepted but you should know: ignored mimic tags, unchecked inertias.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.model.warnings.clone()
    }

    /// Total mass (kg).
    #[getter]
    fn total_mass(&self) -> f64 {
        self.model.total_mass()
    }

    fn __repr__(&self) -> String {
        format!(
            "robodyn.Model('{}', nq={}, nv={}, joints={}, frames={})",
            self.model.name,
            self.model.nq,
            self.model.nv,
            self.model.nbodies() - 1,
            self.model.frames.len()
        )
    }

    /// The neutral configuration: zero angles, identity quaternions. Shape (nq,).
    fn neutral<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.neutral().as_slice())
    }

    /// A random configuration within the position limits (angles in [-π, π] and translations in
    /// [-1, 1] m where a joint has none; uniform rotations). `n` gives a batch (n, nq); `seed`
    /// makes it reproducible.
    #[pyo3(signature = (n=None, seed=None))]
    fn random_configuration<'py>(
        &self,
        py: Python<'py>,
        n: Option<usize>,
        seed: Option<u64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let mut rng = match seed {
            Some(seed) => StdRng::seed_from_u64(seed),
            None => StdRng::from_os_rng(),
        };
        match n {
            None => Ok(
                vector_array(py, self.model.random_configuration(&mut rng).as_slice()).into_any(),
            ),
            Some(n) => {
                let mut values = Vec::with_capacity(n * self.model.nq);
                for _ in 0..n {
                    values.extend_from_slice(self.model.random_configuration(&mut rng).as_slice());
                }
                Ok(PyArray1::from_vec(py, values)
                    .reshape([n, self.model.nq])?
                    .into_any())
            }
        }
    }

    /// Inverse dynamics by RNEA: τ = M(q) a + C(q, v) v + g(q) - Σ J_iᵀ f_ext_i.
    /// `f_ext`: optional (nbodies, 6) wrenches [force; torque] on each body (rows as body_names),
    /// in the body's frame, at its origin.
    #[pyo3(signature = (q, v, a, f_ext=None))]
    fn inverse_dynamics<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        a: &Bound<'py, PyAny>,
        f_ext: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.with_external_forces(py, q, v, ("a", a), f_ext, algo::rnea)
    }

    /// Forward dynamics by ABA: a = M(q)⁻¹ (τ - C(q, v) v - g(q) + Σ J_iᵀ f_ext_i).
    #[pyo3(signature = (q, v, tau, f_ext=None))]
    fn forward_dynamics<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        tau: &Bound<'py, PyAny>,
        f_ext: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.with_external_forces(py, q, v, ("tau", tau), f_ext, algo::aba)
    }

    /// Joint-space inertia matrix M(q), full and symmetric, armature included. (nv, nv).
    /// `method`: "crba" (Featherstone's composite-rigid-body algorithm, the fastest), "rnea"
    /// (column k = τ(q, 0, e_k) − g(q), n RNEA calls: the UR5 dynamics notes) or "jacobians"
    /// (Σ m J_vᵀ J_v + J_ωᵀ I J_ω over the bodies: the TU Berlin and UR5 dynamics notes).
    #[pyo3(signature = (q, method="crba"))]
    fn mass_matrix<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        method: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        type Method = for<'d> fn(&Model, &'d mut Data, &[f64]) -> robodyn::Result<&'d DMatrix<f64>>;
        let algorithm: Method = match method {
            "crba" => algo::crba,
            "rnea" => algo::mass_matrix_by_rnea,
            "jacobians" => algo::mass_matrix_by_jacobians,
            other => return Err(unknown_method(other, "crba, rnea or jacobians")),
        };
        let nv = self.model.nv;
        self.evaluate(py, &[self.q_arg("q", q)?], &[nv, nv], &|m, w, i, out| {
            write_row_major(algorithm(m, &mut w.data, i[0])?, m.nv, out);
            Ok(())
        })
    }

    /// M(q)⁻¹. (nv, nv).
    fn inverse_mass_matrix<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let nv = self.model.nv;
        self.evaluate(py, &[self.q_arg("q", q)?], &[nv, nv], &|m, w, i, out| {
            write_row_major(algo::inverse_mass_matrix(m, &mut w.data, i[0])?, m.nv, out);
            Ok(())
        })
    }

    /// Bias forces C(q, v) v + g(q) (RNEA with a = 0). (nv,).
    fn bias_forces<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(
            py,
            &[self.q_arg("q", q)?, self.v_arg("v", v)?],
            &[self.model.nv],
            &|m, w, i, out| {
                out.copy_from_slice(algo::bias_forces(m, &mut w.data, i[0], i[1])?.as_slice());
                Ok(())
            },
        )
    }

    /// Coriolis matrix C(q, v) (nv, nv), from the Christoffel symbols of the first kind:
    /// C(q, v) v = bias_forces(q, v) − generalized_gravity(q), and Ṁ − 2C is skew-symmetric
    /// (the TU Berlin notes). A recursive O(n²) algorithm (Echeandia & Wensing 2021), no RNEA calls.
    fn coriolis_matrix<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let nv = self.model.nv;
        self.evaluate(
            py,
            &[self.q_arg("q", q)?, self.v_arg("v", v)?],
            &[nv, nv],
            &|m, w, i, out| {
                write_row_major(
                    algo::coriolis_matrix(m, &mut w.data, i[0], i[1])?,
                    m.nv,
                    out,
                );
                Ok(())
            },
        )
    }

    /// Generalized gravity g(q). (nv,). `method`: "rnea" (RNEA with v = a = 0) or "jacobians"
    /// (−Σ J_cᵀ m g over the bodies' centres of mass: the TU Berlin notes "Gravity").
    #[pyo3(signature = (q, method="rnea"))]
    fn generalized_gravity<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        method: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        type Method = for<'d> fn(&Model, &'d mut Data, &[f64]) -> robodyn::Result<&'d DVector<f64>>;
        let algorithm: Method = match method {
            "rnea" => algo::generalized_gravity,
            "jacobians" => algo::generalized_gravity_by_jacobians,
            other => return Err(unknown_method(other, "rnea or jacobians")),
        };
        self.evaluate(
            py,
            &[self.q_arg("q", q)?],
            &[self.model.nv],
            &|m, w, i, out| {
                out.copy_from_slice(algorithm(m, &mut w.data, i[0])?.as_slice());
                Ok(())
            },
        )
    }

    /// Christoffel symbols of the first kind, (nv, nv, nv):
    /// Γ[i, j, k] = ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i), so that C(q, v)_ij = Σ_k Γ[i, j, k] v_k
    /// (the TU Berlin notes). Exact: Γ[:, :, k] = C(q, e_k) by the recursive Coriolis algorithm. With
    /// spherical or free joints (velocities that are not coordinate rates) the coordinate formula
    /// has no meaning; Γ[:, :, k] = C(q, e_k) still holds.
    fn christoffel<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let nv = self.model.nv;
        self.evaluate(
            py,
            &[self.q_arg("q", q)?],
            &[nv, nv, nv],
            &|m, w, i, out| {
                algo::christoffel_symbols(m, &mut w.data, i[0], out)?;
                Ok(())
            },
        )
    }

    /// Craig's centrifugal matrix C(q), (nv, nv) (the TU Berlin notes, "Centrifugal and Coriolis
    /// Computation"): the velocity terms are C(q) [q̇₁², …, q̇ₙ²] + B(q) [q̇₁q̇₂, q̇₁q̇₃, …];
    /// C(q)_ij = Γ_ijj.
    fn centrifugal_matrix<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let nv = self.model.nv;
        self.evaluate(py, &[self.q_arg("q", q)?], &[nv, nv], &|m, w, i, out| {
            let gamma = christoffel_of(m, w, i[0])?;
            for (row, j) in (0..nv).flat_map(|row| (0..nv).map(move |j| (row, j))) {
                out[row * nv + j] = gamma[(row * nv + j) * nv + j];
            }
            Ok(())
        })
    }

    /// Craig's Coriolis matrix B(q), (nv, nv(nv−1)/2) (the TU Berlin notes): multiplies the products
    /// [q̇₁q̇₂, q̇₁q̇₃, …, q̇₁q̇ₙ, q̇₂q̇₃, …] (pairs j < k in that order); B(q)_i,(jk) = 2 Γ_ijk.
    fn coriolis_pairs_matrix<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let nv = self.model.nv;
        let pairs = nv * nv.saturating_sub(1) / 2;
        self.evaluate(py, &[self.q_arg("q", q)?], &[nv, pairs], &|m, w, i, out| {
            let gamma = christoffel_of(m, w, i[0])?;
            for row in 0..nv {
                let mut column = 0;
                for j in 0..nv {
                    for k in j + 1..nv {
                        out[row * pairs + column] = 2.0 * gamma[(row * nv + j) * nv + k];
                        column += 1;
                    }
                }
            }
            Ok(())
        })
    }

    /// Pose of a frame (name or index) in the world: 4x4 homogeneous matrix.
    fn frame_pose<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let frame = self.frame_index(frame)?;
        self.evaluate(py, &[self.q_arg("q", q)?], &[4, 4], &|m, w, i, out| {
            let pose = algo::frame_pose(m, &mut w.data, i[0], frame)?.to_homogeneous();
            for (r, row) in out.chunks_exact_mut(4).enumerate() {
                for (c, value) in row.iter_mut().enumerate() {
                    *value = pose[(r, c)];
                }
            }
            Ok(())
        })
    }

    /// Jacobian of a frame, (6, nv), rows [linear; angular]. `reference`: "world" (velocity of the
    /// frame's origin and angular velocity in world axes: the geometric Jacobian), "local" (the
    /// same in the frame's axes) or "spatial" (spatial velocity in world coordinates).
    #[pyo3(signature = (q, frame, reference="world"))]
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: &Bound<'py, PyAny>,
        reference: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let frame = self.frame_index(frame)?;
        let reference = parse_reference(reference)?;
        self.evaluate(
            py,
            &[self.q_arg("q", q)?],
            &[6, self.model.nv],
            &|m, w, i, out| {
                write_row_major(
                    algo::jacobian(m, &mut w.data, i[0], frame, reference)?,
                    6,
                    out,
                );
                Ok(())
            },
        )
    }

    /// Time derivative J̇(q, v) of a frame's Jacobian, (6, nv), same references as `jacobian`;
    /// J̇ v equals `frame_acceleration(q, v, 0, frame, reference)`.
    #[pyo3(signature = (q, v, frame, reference="world"))]
    fn jacobian_time_variation<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        frame: &Bound<'py, PyAny>,
        reference: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (frame, reference) = (self.frame_index(frame)?, parse_reference(reference)?);
        self.evaluate(
            py,
            &[self.q_arg("q", q)?, self.v_arg("v", v)?],
            &[6, self.model.nv],
            &|m, w, i, out| {
                write_row_major(
                    algo::jacobian_time_variation(m, &mut w.data, i[0], i[1], frame, reference)?,
                    6,
                    out,
                );
                Ok(())
            },
        )
    }

    /// Velocity of a frame, (6,) [linear; angular] = J(q) v: "world" (its origin's velocity and
    /// angular velocity in world axes), "local" (the same in its axes) or "spatial".
    #[pyo3(signature = (q, v, frame, reference="world"))]
    fn frame_velocity<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        frame: &Bound<'py, PyAny>,
        reference: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (frame, reference) = (self.frame_index(frame)?, parse_reference(reference)?);
        self.evaluate(
            py,
            &[self.q_arg("q", q)?, self.v_arg("v", v)?],
            &[6],
            &|m, w, i, out| {
                out.copy_from_slice(&algo::frame_velocity(
                    m,
                    &mut w.data,
                    i[0],
                    i[1],
                    frame,
                    reference,
                )?);
                Ok(())
            },
        )
    }

    /// Acceleration of a frame, (6,) [linear; angular] = J(q) a + J̇(q, v) v: "world" (the
    /// classical acceleration of its origin and its angular acceleration, world axes), "local"
    /// (the same in its axes) or "spatial" (Featherstone's spatial acceleration, world
    /// coordinates). With a = 0 it is J̇ v.
    #[pyo3(signature = (q, v, a, frame, reference="world"))]
    fn frame_acceleration<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        a: &Bound<'py, PyAny>,
        frame: &Bound<'py, PyAny>,
        reference: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (frame, reference) = (self.frame_index(frame)?, parse_reference(reference)?);
        let arguments = [
            self.q_arg("q", q)?,
            self.v_arg("v", v)?,
            self.v_arg("a", a)?,
        ];
        self.evaluate(py, &arguments, &[6], &|m, w, i, out| {
            out.copy_from_slice(&algo::frame_acceleration(
                m,
                &mut w.data,
                i[0],
                i[1],
                i[2],
                frame,
                reference,
            )?);
            Ok(())
        })
    }

    /// Kinetic energy ½ vᵀ M(q) v (J), rotor energy included.
    fn kinetic_energy<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(
            py,
            &[self.q_arg("q", q)?, self.v_arg("v", v)?],
            &[],
            &|m, w, i, out| {
                out[0] = algo::kinetic_energy(m, &mut w.data, i[0], i[1])?;
                Ok(())
            },
        )
    }

    /// The Lagrangian L = T − V (J): kinetic minus potential energy.
    fn lagrangian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(
            py,
            &[self.q_arg("q", q)?, self.v_arg("v", v)?],
            &[],
            &|m, w, i, out| {
                let kinetic = algo::kinetic_energy(m, &mut w.data, i[0], i[1])?;
                out[0] = kinetic - algo::potential_energy(m, &mut w.data, i[0])?;
                Ok(())
            },
        )
    }

    /// Centroidal momentum matrix A_G(q), (6, nv): h_G = A_G v, rows [linear momentum; angular
    /// momentum about the centre of mass], world axes (Orin, Goswami & Lee 2013).
    fn centroidal_momentum_matrix<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(
            py,
            &[self.q_arg("q", q)?],
            &[6, self.model.nv],
            &|m, w, i, out| {
                write_row_major(
                    algo::centroidal_momentum_matrix(m, &mut w.data, i[0])?,
                    6,
                    out,
                );
                Ok(())
            },
        )
    }

    /// Centroidal momentum h_G = A_G(q) v, (6,): [linear momentum m ċ; angular momentum about the
    /// centre of mass], world axes.
    fn centroidal_momentum<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(
            py,
            &[self.q_arg("q", q)?, self.v_arg("v", v)?],
            &[6],
            &|m, w, i, out| {
                matrix_times(
                    algo::centroidal_momentum_matrix(m, &mut w.data, i[0])?,
                    i[1],
                    out,
                );
                Ok(())
            },
        )
    }

    /// Potential energy -Σ m_i gᵀ c_i (J), zero at the world origin.
    fn potential_energy<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(py, &[self.q_arg("q", q)?], &[], &|m, w, i, out| {
            out[0] = algo::potential_energy(m, &mut w.data, i[0])?;
            Ok(())
        })
    }

    /// Centre of mass of the robot in world coordinates. (3,).
    fn center_of_mass<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(py, &[self.q_arg("q", q)?], &[3], &|m, w, i, out| {
            out.copy_from_slice(algo::center_of_mass(m, &mut w.data, i[0])?.as_slice());
            Ok(())
        })
    }

    /// Yoshikawa's manipulability √det(J Jᵀ) of a frame for a task: "full" (6 rows), "position",
    /// "orientation" or a list of rows of [vx, vy, vz, ωx, ωy, ωz]. Zero at a singularity.
    #[pyo3(signature = (q, frame, task=None))]
    fn manipulability<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: &Bound<'py, PyAny>,
        task: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.manipulability_measure(py, q, frame, task, |(w, _)| w)
    }

    /// σ_min / σ_max of a frame's task Jacobian (see `manipulability`): 1 when isotropic, 0 at a
    /// singularity.
    #[pyo3(signature = (q, frame, task=None))]
    fn inverse_condition_number<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: &Bound<'py, PyAny>,
        task: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.manipulability_measure(py, q, frame, task, |(_, inverse_condition)| {
            inverse_condition
        })
    }

    /// Workspace sampling: the world positions (n, 3) of a frame's origin over n random
    /// configurations (see `random_configuration`), computed on all cores.
    #[pyo3(signature = (frame, n=10_000, seed=None))]
    fn workspace<'py>(
        &self,
        py: Python<'py>,
        frame: &Bound<'py, PyAny>,
        n: usize,
        seed: Option<u64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let states = self.random_configuration(py, Some(n), seed)?;
        let poses = self.frame_pose(py, &states, frame)?;
        // the translation column of each pose
        let slicing = (
            pyo3::types::PySlice::full(py),
            pyo3::types::PySlice::new(py, 0, 3, 1),
            3,
        );
        poses.get_item(slicing)?.call_method0("copy")
    }

    /// Inverse kinematics: a configuration placing `frame` at `target`, a 4x4 pose (or N poses,
    /// solved in parallel), by damped least squares from `q0` (default: neutral) and then from up
    /// to `restarts` random configurations. `position_only` matches only the target's position.
    /// Returns a dict: "q" (nq,), "success" (bool), "iterations" (int), "residual" (the error
    /// norm, m and rad), with a leading N for a batch. Results do not depend on batch position.
    #[pyo3(signature = (frame, target, q0=None, position_only=false, tolerance=1e-10, max_iterations=200, restarts=20, damping=1e-6, seed=0))]
    #[allow(clippy::too_many_arguments)]
    fn inverse_kinematics<'py>(
        &self,
        py: Python<'py>,
        frame: &Bound<'py, PyAny>,
        target: &Bound<'py, PyAny>,
        q0: Option<&Bound<'py, PyAny>>,
        position_only: bool,
        tolerance: f64,
        max_iterations: usize,
        restarts: usize,
        damping: f64,
        seed: u64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let frame = self.frame_index(frame)?;
        let options = algo::IkOptions {
            position_only,
            tolerance,
            max_iterations,
            restarts,
            damping,
        };
        let target = Argument::new("target", target, SampleShape::matrix(4, 4))?;
        let q0 = match q0 {
            Some(q0) => self.q_arg("q0", q0)?,
            None => {
                // the neutral configuration, once per target
                let neutral = self.model.neutral();
                let starts = match target.batch()? {
                    None => PyArray1::from_slice(py, neutral.as_slice()).into_any(),
                    Some(n) => {
                        let repeated: Vec<f64> =
                            (0..n).flat_map(|_| neutral.iter().copied()).collect();
                        PyArray1::from_vec(py, repeated)
                            .reshape([n, self.model.nq])?
                            .into_any()
                    }
                };
                self.q_arg("q0", &starts)?
            }
        };
        let nq = self.model.nq;
        let packed = self.evaluate(py, &[target, q0], &[nq + 3], &|m, w, i, out| {
            let pose = i[0];
            let rotation = nalgebra::Matrix3::new(
                pose[0], pose[1], pose[2], pose[4], pose[5], pose[6], pose[8], pose[9], pose[10],
            );
            let orthonormal =
                (rotation.transpose() * rotation - nalgebra::Matrix3::identity()).norm() < 1e-6
                    && rotation.determinant() > 0.0
                    && pose[12..16] == [0.0, 0.0, 0.0, 1.0];
            if !orthonormal {
                return Err(Error::InvalidValue {
                    argument: "target".into(),
                    message: "expected a 4x4 homogeneous pose [R p; 0 0 0 1] with R a rotation"
                        .into(),
                });
            }
            let position = nalgebra::Vector3::new(pose[3], pose[7], pose[11]);
            let target = robodyn::spatial::Transform::from_pose(&rotation, &position);
            // the restarts' random states depend on the sample, never on its place in a batch
            let mut hasher = std::collections::hash_map::DefaultHasher::new();
            std::hash::Hash::hash(&seed, &mut hasher);
            for value in pose.iter().chain(i[1]) {
                std::hash::Hash::hash(&value.to_bits(), &mut hasher);
            }
            let mut rng = StdRng::seed_from_u64(std::hash::Hasher::finish(&hasher));
            let solution =
                algo::inverse_kinematics(m, &mut w.data, frame, &target, i[1], &options, &mut rng)?;
            out[..m.nq].copy_from_slice(solution.q.as_slice());
            out[m.nq] = f64::from(u8::from(solution.success));
            out[m.nq + 1] = solution.iterations as f64;
            out[m.nq + 2] = solution.residual;
            Ok(())
        })?;
        // unpack [q, success, iterations, residual] along the last axis
        let result = PyDict::new(py);
        let ellipsis = py.Ellipsis().into_bound(py);
        let column = |k: usize| (ellipsis.clone(), k);
        result.set_item(
            "q",
            packed
                .get_item((
                    ellipsis.clone(),
                    pyo3::types::PySlice::new(py, 0, nq as isize, 1),
                ))?
                .call_method0("copy")?,
        )?;
        result.set_item(
            "success",
            packed
                .get_item(column(nq))?
                .call_method1("astype", ("bool",))?,
        )?;
        result.set_item(
            "iterations",
            packed
                .get_item(column(nq + 1))?
                .call_method1("astype", ("int64",))?,
        )?;
        result.set_item("residual", packed.get_item(column(nq + 2))?)?;
        Ok(result)
    }

    /// Jacobian of the centre of mass, (3, nv) in world axes: ċ = J_com v.
    fn center_of_mass_jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(
            py,
            &[self.q_arg("q", q)?],
            &[3, self.model.nv],
            &|m, w, i, out| {
                write_row_major(algo::center_of_mass_jacobian(m, &mut w.data, i[0])?, 3, out);
                Ok(())
            },
        )
    }

    /// Velocity of the centre of mass ċ = J_com(q) v, (3,), world axes.
    fn center_of_mass_velocity<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(
            py,
            &[self.q_arg("q", q)?, self.v_arg("v", v)?],
            &[3],
            &|m, w, i, out| {
                matrix_times(
                    algo::center_of_mass_jacobian(m, &mut w.data, i[0])?,
                    i[1],
                    out,
                );
                Ok(())
            },
        )
    }

    /// q ⊕ v dt: moves q with constant velocity v for dt seconds on each joint's Lie group.
    #[pyo3(signature = (q, v, dt=1.0))]
    fn integrate<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        dt: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        if !dt.is_finite() {
            return Err(PyValueError::new_err(format!(
                "argument 'dt': expected a finite number, got {dt}"
            )));
        }
        self.evaluate(
            py,
            &[self.q_arg("q", q)?, self.v_arg("v", v)?],
            &[self.model.nq],
            &|m, _, i, out| {
                robodyn::error::check_finite("v", i[1])?;
                let step: Vec<f64> = i[1].iter().map(|x| x * dt).collect();
                m.integrate(i[0], &step, out)
            },
        )
    }

    /// q1 ⊖ q0: the velocity that moves q0 to q1 in unit time. (nv,).
    fn difference<'py>(
        &self,
        py: Python<'py>,
        q0: &Bound<'py, PyAny>,
        q1: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(
            py,
            &[self.q_arg("q0", q0)?, self.q_arg("q1", q1)?],
            &[self.model.nv],
            &|m, _, i, out| m.difference(i[0], i[1], out),
        )
    }
}

/// Loads a URDF file. `floating_base` adds a free joint "root_joint" above the root link;
/// `check_inertia=False` turns a non-positive-semi-definite inertia from an error into a warning.
#[pyfunction]
#[pyo3(signature = (path, floating_base=false, check_inertia=true))]
fn load_urdf(
    path: std::path::PathBuf,
    floating_base: bool,
    check_inertia: bool,
) -> PyResult<PyModel> {
    let options = LoadOptions {
        floating_base,
        check_inertia,
    };
    robodyn::io::load_urdf_file(&path, options)
        .map(PyModel::wrap)
        .map_err(to_py_err)
}

/// Loads a URDF document from a string; `source` names it in error messages.
#[pyfunction]
#[pyo3(signature = (text, floating_base=false, check_inertia=true, source="<string>"))]
fn load_urdf_string(
    text: &str,
    floating_base: bool,
    check_inertia: bool,
    source: &str,
) -> PyResult<PyModel> {
    let options = LoadOptions {
        floating_base,
        check_inertia,
    };
    robodyn::io::load_urdf_str(text, source, options)
        .map(PyModel::wrap)
        .map_err(to_py_err)
}

/// Loads an MJCF (MuJoCo XML) file.
#[pyfunction]
fn load_mjcf(path: std::path::PathBuf) -> PyResult<PyModel> {
    robodyn::io::load_mjcf_file(&path)
        .map(PyModel::wrap)
        .map_err(to_py_err)
}

/// Loads an MJCF document from a string; `source` names it in error messages.
#[pyfunction]
#[pyo3(signature = (text, source="<string>"))]
fn load_mjcf_string(text: &str, source: &str) -> PyResult<PyModel> {
    robodyn::io::load_mjcf_str(text, source)
        .map(PyModel::wrap)
        .map_err(to_py_err)
}

/// Loads a DH table file (TOML).
#[pyfunction]
fn load_dh(path: std::path::PathBuf) -> PyResult<PyModel> {
    robodyn::io::load_dh_file(&path)
        .map(PyModel::wrap)
        .map_err(to_py_err)
}

/// Builds a model from a DH table given as a dict with the keys of the TOML format.
#[pyfunction]
#[pyo3(signature = (document, source="from_dh"))]
fn load_dh_dict(document: &Bound<PyDict>, source: &str) -> PyResult<PyModel> {
    let toml::Value::Table(table) = toml_value(document.as_any(), "table")? else {
        return Err(PyValueError::new_err(
            "argument 'document': expected a dict",
        ));
    };
    robodyn::io::load_dh_document(&table, source)
        .map(PyModel::wrap)
        .map_err(to_py_err)
}

/// A Python value (dict, list, str, bool, int, float, NumPy array) as a TOML value.
fn toml_value(value: &Bound<PyAny>, key: &str) -> PyResult<toml::Value> {
    if let Ok(dict) = value.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (k, v) in dict.iter() {
            let k: String = k
                .extract()
                .map_err(|_| PyValueError::new_err(format!("'{key}': expected string keys")))?;
            let item = toml_value(&v, &k)?;
            table.insert(k, item);
        }
        return Ok(toml::Value::Table(table));
    }
    if let Ok(text) = value.extract::<String>() {
        return Ok(toml::Value::String(text));
    }
    if let Ok(flag) = value.extract::<bool>() {
        return Ok(toml::Value::Boolean(flag));
    }
    if let Ok(number) = value.extract::<f64>() {
        return Ok(toml::Value::Float(number));
    }
    if let Ok(items) = value.try_iter() {
        return items
            .map(|item| toml_value(&item?, key))
            .collect::<PyResult<Vec<_>>>()
            .map(toml::Value::Array);
    }
    Err(PyValueError::new_err(format!(
        "'{key}': expected a number, a string, a list or a dict, got {}",
        value.repr()?
    )))
}

/// A model bundled with robodyn, by name.
#[pyfunction]
#[pyo3(signature = (name, floating_base=false))]
fn load_bundled(name: &str, floating_base: bool) -> PyResult<PyModel> {
    robodyn::io::bundled_model(name, floating_base)
        .map(PyModel::wrap)
        .map_err(to_py_err)
}

/// Names of the bundled models.
#[pyfunction]
fn bundled_names() -> Vec<&'static str> {
    robodyn::io::bundled_names()
}

#[pymodule]
fn _core(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add_class::<PyModel>()?;
    module.add_function(wrap_pyfunction!(load_urdf, module)?)?;
    module.add_function(wrap_pyfunction!(load_urdf_string, module)?)?;
    module.add_function(wrap_pyfunction!(load_bundled, module)?)?;
    module.add_function(wrap_pyfunction!(load_dh, module)?)?;
    module.add_function(wrap_pyfunction!(load_mjcf, module)?)?;
    module.add_function(wrap_pyfunction!(load_mjcf_string, module)?)?;
    module.add_function(wrap_pyfunction!(load_dh_dict, module)?)?;
    module.add_function(wrap_pyfunction!(bundled_names, module)?)?;
    module.add_function(wrap_pyfunction!(simulation::simulate, module)?)?;
    Ok(())
}
