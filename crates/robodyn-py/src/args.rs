//! Argument handling: numeric arguments (one sample or a batch, any array-like) and the named
//! options of the calls, each error a `ValueError` naming the argument.

use crate::to_py_err;
use nalgebra::DVector;
use numpy::npyffi::{
    get_type_object, NpyTypes, PyArrayObject, NPY_ARRAY_ALIGNED, NPY_ARRAY_C_CONTIGUOUS,
};
use numpy::{
    dtype, AllowTypeChange, PyArrayDyn, PyArrayLikeDyn, PyArrayMethods, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::ffi;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyString};
use robodyn::algo::Reference;
use std::borrow::Cow;
use std::ffi::c_int;
use std::sync::OnceLock;

/// The shape of one sample of an argument: one or two dimensions, in two words (a vector's
/// second is [`SampleShape::NONE`]), so that it travels in registers, not through memory.
#[derive(Clone, Copy)]
pub(crate) struct SampleShape {
    dims: [usize; 2],
}

impl SampleShape {
    /// The second dimension of a vector's shape: none.
    const NONE: usize = usize::MAX;

    pub(crate) fn vector(n: usize) -> Self {
        SampleShape {
            dims: [n, Self::NONE],
        }
    }

    pub(crate) fn matrix(rows: usize, columns: usize) -> Self {
        SampleShape {
            dims: [rows, columns],
        }
    }

    pub(crate) fn as_slice(&self) -> &[usize] {
        let ndim = if self.dims[1] == Self::NONE { 1 } else { 2 };
        &self.dims[..ndim]
    }
}

/// A numeric argument: its name, the array, and the shape of one sample.
pub(crate) struct Argument<'py> {
    pub(crate) name: &'static str,
    pub(crate) array: Bound<'py, PyArrayDyn<f64>>,
    pub(crate) sample_shape: SampleShape,
}

/// The type object of `numpy.ndarray` and NumPy's float64 descriptor (native byte order), found
/// once per process: a plain float64 array is then told by two pointer compares. NumPy's
/// descriptors of its built-in types are its own static objects, so the pointer stays valid.
static PLAIN_FLOAT64: OnceLock<(usize, usize)> = OnceLock::new();

/// The pair of [`PLAIN_FLOAT64`].
#[inline]
pub(crate) fn plain_float64(py: Python) -> (usize, usize) {
    *PLAIN_FLOAT64.get_or_init(|| {
        // SAFETY: NumPy's API table, read with the GIL held
        let array_type = unsafe { get_type_object(py, NpyTypes::PyArray_Type) };
        (array_type as usize, dtype::<f64>(py).as_ptr() as usize)
    })
}

/// `value` as a float64 array when it is a plain `ndarray` (not a subclass) of NumPy's own
/// float64 descriptor; `None` for anything else, which then takes the full test.
#[inline]
fn plain_float64_array<'a, 'py>(
    value: &'a Bound<'py, PyAny>,
) -> Option<&'a Bound<'py, PyArrayDyn<f64>>> {
    let (array_type, float64) = plain_float64(value.py());
    let object = value.as_ptr();
    // SAFETY: reads the type of a live object, then the descriptor of what is an ndarray
    unsafe {
        let is_plain = ffi::Py_TYPE(object) as usize == array_type
            && (*object.cast::<PyArrayObject>()).fields.descr as usize == float64;
        // SAFETY: an ndarray of float64, whatever its number of dimensions
        is_plain.then(|| value.cast_unchecked::<PyArrayDyn<f64>>())
    }
}

impl<'py> Argument<'py> {
    #[inline(always)]
    pub(crate) fn new(
        name: &'static str,
        value: &Bound<'py, PyAny>,
        sample_shape: SampleShape,
    ) -> PyResult<Self> {
        // a float64 ndarray is used as it is; anything else goes through numpy.asarray
        let array = match plain_float64_array(value) {
            Some(array) => array.clone(),
            None => Self::converted(name, value, sample_shape)?,
        };
        Ok(Argument {
            name,
            array,
            sample_shape,
        })
    }

    /// [`Self::new`]'s array for a value that is not a plain float64 array.
    #[inline(never)]
    fn converted(
        name: &'static str,
        value: &Bound<'py, PyAny>,
        sample_shape: SampleShape,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        if let Ok(array) = value.cast::<PyArrayDyn<f64>>() {
            return Ok(array.clone());
        }
        let converted = value.extract::<PyArrayLikeDyn<'py, f64, AllowTypeChange>>().map_err(|_| {
            PyValueError::new_err(format!(
                "argument '{name}': expected an array of numbers of shape {} or (N, ...), got {}",
                shape_text(sample_shape.as_slice()),
                value.repr().map(|r| r.to_string()).unwrap_or_else(|_| "an unreadable object".into())
            ))
        })?;
        Ok((**converted).clone())
    }

    /// The batch size, `None` for a single sample; errors if the shape fits neither.
    #[inline]
    pub(crate) fn batch(&self) -> PyResult<Option<usize>> {
        let shape = self.array.shape();
        let sample = self.sample_shape.as_slice();
        // entry by entry: a slice comparison calls memcmp for these few numbers
        let ends_with_sample = |first: usize| {
            shape.len() == first + sample.len()
                && shape[first..].iter().zip(sample).all(|(n, m)| n == m)
        };
        if ends_with_sample(0) {
            Ok(None)
        } else if ends_with_sample(1) {
            Ok(Some(shape[0]))
        } else {
            Err(self.shape_error())
        }
    }

    /// The error of a shape that is neither one sample nor a batch.
    #[cold]
    #[inline(never)]
    fn shape_error(&self) -> PyErr {
        let shape = self.array.shape();
        let sample = self.sample_shape.as_slice();
        let batch_shape: Vec<String> = std::iter::once("N".to_string())
            .chain(sample.iter().map(|n| n.to_string()))
            .collect();
        PyValueError::new_err(format!(
            "argument '{}': expected shape {} or ({}), got {}",
            self.name,
            shape_text(sample),
            batch_shape.join(", "),
            shape_text(shape)
        ))
    }

    /// The values in C order, borrowed when the array is contiguous.
    pub(crate) fn values(&self) -> Cow<'_, [f64]> {
        match self.contiguous_values() {
            Some(values) => Cow::Borrowed(values),
            None => Cow::Owned(self.copied_values()),
        }
    }

    /// The values in place when the array is C-contiguous and aligned (read from the array's
    /// flags: rust-numpy's `as_slice` tests contiguity and alignment again on its own).
    #[inline]
    pub(crate) fn contiguous_values(&self) -> Option<&[f64]> {
        const IN_PLACE: c_int = NPY_ARRAY_C_CONTIGUOUS | NPY_ARRAY_ALIGNED;
        // SAFETY: the fields of a live ndarray, read with the GIL held
        let fields = unsafe { &(*self.array.as_array_ptr()).fields };
        if fields.flags & IN_PLACE != IN_PLACE {
            return None;
        }
        let length: usize = self.array.shape().iter().product();
        if length == 0 {
            return Some(&[]);
        }
        // SAFETY: `length` float64 values, C-contiguous and aligned. No Rust code holds a mutable
        // view of an input: the only array robodyn writes is the output, which a call creates
        // itself or checks to share no memory with an input.
        Some(unsafe { std::slice::from_raw_parts(fields.data.cast::<f64>(), length) })
    }

    /// A copy of the values in C order (of a strided array).
    #[cold]
    #[inline(never)]
    pub(crate) fn copied_values(&self) -> Vec<f64> {
        self.array.to_owned_array().iter().copied().collect()
    }
}

pub(crate) fn shape_text(shape: &[usize]) -> String {
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

/// The Jacobian/velocity reference named by the user: "world", "local" or "spatial" (read in
/// place, no string copied: it is an argument of every Jacobian call).
pub(crate) fn reference_of(name: &str, value: &Bound<PyAny>) -> PyResult<Reference> {
    let named = value
        .cast::<PyString>()
        .ok()
        .map(|text| text.to_str())
        .transpose()?;
    match named {
        Some("world") => Ok(Reference::World),
        Some("local") => Ok(Reference::Local),
        Some("spatial") => Ok(Reference::Spatial),
        Some(other) => Err(PyValueError::new_err(format!(
            "argument '{name}': expected 'world', 'local' or 'spatial', got '{other}'"
        ))),
        None => Err(expected(name, "'world', 'local' or 'spatial'", value)),
    }
}

/// The Jacobian rows of a task: "full", "position", "orientation" or a list of row indices.
pub(crate) fn parse_task(task: &Bound<PyAny>) -> PyResult<Vec<usize>> {
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

/// The name given as a `method` argument, read in place: no string is made on the usual path
/// (the default included), only for a name no function knows.
pub(crate) enum MethodName {
    Crba,
    Rnea,
    Jacobians,
    Other(String),
}

impl MethodName {
    pub(crate) fn as_str(&self) -> &str {
        match self {
            MethodName::Crba => "crba",
            MethodName::Rnea => "rnea",
            MethodName::Jacobians => "jacobians",
            MethodName::Other(name) => name,
        }
    }
}

/// A `method` argument: a string, its name one of [`MethodName`]'s or another.
pub(crate) fn method_name(name: &str, value: &Bound<PyAny>) -> PyResult<MethodName> {
    let text = value
        .cast::<PyString>()
        .map_err(|_| expected(name, "a string", value))?
        .to_str()?;
    Ok(match text {
        "crba" => MethodName::Crba,
        "rnea" => MethodName::Rnea,
        "jacobians" => MethodName::Jacobians,
        other => MethodName::Other(other.to_string()),
    })
}

/// "argument 'method': expected ..., got '...'".
pub(crate) fn unknown_method(method: &str, expected: &str) -> PyErr {
    PyValueError::new_err(format!(
        "argument 'method': expected {expected}, got '{method}'"
    ))
}

/// The values of an argument that must be one sample, not a batch.
pub(crate) fn single_sample<'a>(argument: &'a Argument) -> PyResult<Cow<'a, [f64]>> {
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
pub(crate) fn read_sample(
    name: &'static str,
    value: &Bound<PyAny>,
    shape: SampleShape,
) -> PyResult<Vec<f64>> {
    let argument = Argument::new(name, value, shape)?;
    let values = single_sample(&argument)?.into_owned();
    robodyn::error::check_finite(name, &values).map_err(to_py_err)?;
    Ok(values)
}

/// Reads a settable per-coordinate property.
pub(crate) fn read_property(
    name: &'static str,
    value: &Bound<PyAny>,
    length: usize,
) -> PyResult<Vec<f64>> {
    read_sample(name, value, SampleShape::vector(length))
}

/// Reads a settable per-coordinate property whose entries must be >= 0.
pub(crate) fn read_non_negative(
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

/// How a value shows in a message: its `repr`.
pub(crate) fn describe(value: &Bound<PyAny>) -> String {
    value
        .repr()
        .map(|r| r.to_string())
        .unwrap_or_else(|_| "an unreadable object".into())
}

fn expected(name: &str, what: &str, value: &Bound<PyAny>) -> PyErr {
    PyValueError::new_err(format!(
        "argument '{name}': expected {what}, got {}",
        describe(value)
    ))
}

/// A non-negative integer below 2⁶⁴ (a seed): a Python or NumPy integer, never a bool or a float.
pub(crate) fn non_negative_integer(name: &str, value: &Bound<PyAny>) -> PyResult<u64> {
    if value.is_instance_of::<PyBool>() {
        return Err(expected(name, "a non-negative integer", value));
    }
    value
        .extract::<u64>()
        .map_err(|_| expected(name, "a non-negative integer", value))
}

/// A count or a size: a non-negative integer that fits in memory.
pub(crate) fn count(name: &str, value: &Bound<PyAny>) -> PyResult<usize> {
    usize::try_from(non_negative_integer(name, value)?)
        .map_err(|_| expected(name, "a smaller integer", value))
}

/// A number (int or float) that is finite.
pub(crate) fn real(name: &str, value: &Bound<PyAny>) -> PyResult<f64> {
    match value.extract::<f64>() {
        Ok(x) if x.is_finite() && !value.is_instance_of::<PyBool>() => Ok(x),
        _ => Err(expected(name, "a finite number", value)),
    }
}

/// True or False (a Python or NumPy bool).
pub(crate) fn flag(name: &str, value: &Bound<PyAny>) -> PyResult<bool> {
    let is_numpy_bool = value
        .get_type()
        .name()
        .is_ok_and(|type_name| type_name == "bool" || type_name == "bool_");
    match value.extract::<bool>() {
        Ok(x) if is_numpy_bool => Ok(x),
        _ => Err(expected(name, "True or False", value)),
    }
}

/// A string.
pub(crate) fn text(name: &str, value: &Bound<PyAny>) -> PyResult<String> {
    value
        .extract::<String>()
        .map_err(|_| expected(name, "a string", value))
}

/// A path: a string or an `os.PathLike`.
pub(crate) fn path(name: &str, value: &Bound<PyAny>) -> PyResult<std::path::PathBuf> {
    value
        .extract::<std::path::PathBuf>()
        .map_err(|_| expected(name, "a path (str or os.PathLike)", value))
}

/// One converter per argument name, for `#[pyo3(from_py_with = named::…)]`: a value of the wrong
/// type is a `ValueError` naming the argument, not PyO3's `TypeError` or `OverflowError`.
pub(crate) mod named {

    use pyo3::prelude::*;

    macro_rules! converters {
        ($($argument:ident: $convert:ident -> $type:ty;)*) => {$(
            pub(crate) fn $argument(value: &Bound<PyAny>) -> PyResult<$type> {
                super::$convert(stringify!($argument), value)
            }
        )*};
    }

    /// The same for an argument whose default is None: None stays None.
    macro_rules! optional_converters {
        ($($function:ident($argument:ident): $convert:ident -> $type:ty;)*) => {$(
            pub(crate) fn $function(value: &Bound<PyAny>) -> PyResult<Option<$type>> {
                if value.is_none() {
                    return Ok(None);
                }
                super::$convert(stringify!($argument), value).map(Some)
            }
        )*};
    }

    converters! {
        n: count -> usize;
        seed: non_negative_integer -> u64;
        max_iterations: count -> usize;
        restarts: count -> usize;
        dt: real -> f64;
        tolerance: real -> f64;
        damping: real -> f64;
        ratio: real -> f64;
        offset: real -> f64;
        length: real -> f64;
        restitution: real -> f64;
        position_only: flag -> bool;
        floating_base: flag -> bool;
        check_inertia: flag -> bool;
        method: method_name -> super::MethodName;
        reference: reference_of -> robodyn::algo::Reference;
        source: text -> String;
        text: text -> String;
        path: path -> std::path::PathBuf;
    }

    optional_converters! {
        optional_n(n): count -> usize;
        optional_seed(seed): non_negative_integer -> u64;
    }
}
