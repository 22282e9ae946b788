//! Where results go: the caller's `out=` array (checked), new arrays, and the matrix layouts the
//! methods write.

use crate::args::{shape_text, Argument};
use nalgebra::DMatrix;
use numpy::ndarray::Axis;
use numpy::npyffi::NPY_ARRAY_WRITEABLE;
use numpy::{
    PyArray1, PyArray2, PyArray3, PyArray4, PyArrayDyn, PyArrayMethods, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyString;

/// Where a kernel's result goes.
pub(crate) enum Target<'a, 'py> {
    /// A new array of zeros: for a kernel that may leave values as they are.
    Zeros,
    /// The caller's `out` when given, else a new array not zeroed: for a kernel that writes
    /// every value (as it must for a caller's array).
    Out(Option<&'a Bound<'py, PyAny>>),
}

/// The caller's `out` array, checked: float64, the result's shape (with the batch's leading
/// N), C-contiguous, writeable, and sharing no memory with an input (the kernel would read what
/// it had just written).
pub(super) fn output_array<'py>(
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

/// Writes the first `rows` rows of a matrix (column-major in nalgebra) into a row-major output
/// (as many whole rows as `out` holds).
pub(crate) fn write_row_major(matrix: &nalgebra::DMatrix<f64>, rows: usize, out: &mut [f64]) {
    let (stored_rows, columns) = matrix.shape();
    let rows = rows.min(stored_rows).min(out.len() / columns.max(1));
    // row-major rows × columns is column-major columns × rows: the transpose, written in place
    let mut target =
        nalgebra::DMatrixViewMut::from_slice(&mut out[..rows * columns], columns, rows);
    matrix.rows(0, rows).transpose_to(&mut target);
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
