//! The NumPy arrays a call returns its result in.
//!
//! A small result (below 1 KiB) is NumPy's own: `PyArray_Empty` or `PyArray_Zeros`, whose memory
//! comes from NumPy's cache of small blocks. A larger one — a Talos Jacobian is 2.4 KiB, its mass
//! matrix 20 KiB — would come from the C library's `malloc`, whose blocks past 1 KiB live in
//! sorted bins (glibc), with NumPy looking its allocator up on the way in and out: 50 ns of a
//! 610 ns Talos Jacobian call. Such a result is instead a buffer of this extension's allocator
//! (mimalloc, see `lib.rs`) that the array does not own: a capsule holding it is the array's
//! base, freeing the buffer when NumPy lets the array go.

use crate::args::plain_float64;
use numpy::ndarray::IxDyn;
use numpy::npyffi::{npy_intp, PyArray_Descr, NPY_ARRAY_CARRAY, PY_ARRAY_API};
use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::ffi;
use pyo3::prelude::*;
use std::ffi::{c_int, c_void};
use std::mem::MaybeUninit;

/// The most dimensions a result has (a batch of matrices: 3); more take rust-numpy's way.
const MOST_DIMENSIONS: usize = 4;

/// NumPy keeps data blocks smaller than this in its cache (`NBUCKETS`, in bytes).
const NUMPY_CACHED_BYTES: usize = 1024;

/// A new C-ordered float64 array of `shape`, of zeros where `zeroed` (else its values are
/// whatever its memory held: for a caller that writes every one). NumPy's own below
/// [`NUMPY_CACHED_BYTES`], with the descriptor found once ([`plain_float64`]: rust-numpy's
/// `zeros` looks it up and copies the shape on every call, a tenth of a small call's fixed cost);
/// a buffer of this extension's from there on.
pub(crate) fn new_array<'py>(
    py: Python<'py>,
    shape: &[usize],
    zeroed: bool,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if shape.len() > MOST_DIMENSIONS {
        return Ok(PyArrayDyn::zeros(py, IxDyn(shape), false));
    }
    let mut dims: [npy_intp; MOST_DIMENSIONS] = [0; MOST_DIMENSIONS];
    for (dim, &n) in dims.iter_mut().zip(shape) {
        *dim = n as npy_intp;
    }
    let dims = &mut dims[..shape.len()];
    let size: usize = shape.iter().product();
    if size * size_of::<f64>() >= NUMPY_CACHED_BYTES {
        return array_on_buffer(py, dims, Buffer::new(size, zeroed));
    }
    let (_, float64) = plain_float64(py);
    let rank = dims.len() as c_int;
    // SAFETY: NumPy's API with the GIL held; PyArray_Zeros and PyArray_Empty take the reference
    // to the descriptor given them, and return a new array or null with the error set.
    unsafe {
        ffi::Py_IncRef(float64 as *mut ffi::PyObject);
        let descriptor = float64 as *mut PyArray_Descr;
        let array = if zeroed {
            PY_ARRAY_API.PyArray_Zeros(py, rank, dims.as_mut_ptr(), descriptor, 0)
        } else {
            PY_ARRAY_API.PyArray_Empty(py, rank, dims.as_mut_ptr(), descriptor, 0)
        };
        Bound::from_owned_ptr_or_err(py, array).map(|array| array.cast_into_unchecked())
    }
}

/// The float64 values of a result, allocated by this extension; uninitialised unless asked for
/// zeros (NumPy's `empty` is no different).
struct Buffer(Box<[MaybeUninit<f64>]>);

impl Buffer {
    fn new(size: usize, zeroed: bool) -> Self {
        Buffer(match zeroed {
            true => Box::new_zeroed_slice(size),
            false => Box::new_uninit_slice(size),
        })
    }
}

/// A C-ordered array of shape `dims` on `buffer` (of their product's length), the buffer kept
/// alive by a capsule that is the array's base and frees it with the array.
fn array_on_buffer<'py>(
    py: Python<'py>,
    dims: &mut [npy_intp],
    mut buffer: Buffer,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let data = buffer.0.as_mut_ptr().cast::<c_void>();
    // the capsule's pointer: the buffer itself, boxed (its values stay where they are)
    let owner = Box::into_raw(Box::new(buffer));
    // SAFETY: CPython's API with the GIL held. The capsule owns the boxed buffer from its
    // creation (its destructor frees it); where it could not be made, the box is freed here.
    // Where the array could not be made, dropping the capsule frees the buffer.
    let capsule = unsafe {
        let capsule =
            ffi::PyCapsule_New(owner.cast::<c_void>(), std::ptr::null(), Some(free_buffer));
        if capsule.is_null() {
            drop(Box::from_raw(owner));
            return Err(PyErr::fetch(py));
        }
        Bound::from_owned_ptr(py, capsule)
    };
    // SAFETY: `data` holds the product of `dims` values, kept alive by the capsule
    unsafe { array_on(py, dims, data, capsule) }
}

/// `values[start..]` of the C-ordered float64 `whole` as an array of shape `shape` (a C-ordered
/// view, `whole` its base), made directly (Python's indexing and `reshape` cost a microsecond
/// each); refused where `whole` is not C-contiguous or the part does not fit in it.
pub(crate) fn view_of<'py>(
    py: Python<'py>,
    whole: &Bound<'py, PyArray1<f64>>,
    start: usize,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let size: usize = shape.iter().product();
    if !whole.is_c_contiguous() || start + size > whole.len() || shape.len() > MOST_DIMENSIONS {
        return Err(PyValueError::new_err("a part outside its result's array"));
    }
    let mut dims: [npy_intp; MOST_DIMENSIONS] = [0; MOST_DIMENSIONS];
    for (dim, &n) in dims.iter_mut().zip(shape) {
        *dim = n as npy_intp;
    }
    // SAFETY: the part lies within `whole`'s contiguous values (checked), which `whole`, the
    // view's base, keeps alive
    unsafe {
        let data = whole.data().add(start).cast::<c_void>();
        let array = array_on(py, &mut dims[..shape.len()], data, whole.clone().into_any())?;
        Ok(array.into_any())
    }
}

/// A C-ordered float64 array of shape `dims` on `data`, which `base` keeps alive.
///
/// # Safety
/// `data` must hold the product of `dims` values, valid and writable while `base` lives.
unsafe fn array_on<'py>(
    py: Python<'py>,
    dims: &mut [npy_intp],
    data: *mut c_void,
    base: Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    // SAFETY: NumPy's API with the GIL held. NumPy's array refers to `data` without owning it,
    // and takes `base`'s reference as its base.
    unsafe {
        let (array_type, float64) = plain_float64(py);
        // NumPy takes this reference to its descriptor, even where it fails
        ffi::Py_IncRef(float64 as *mut ffi::PyObject);
        let array = PY_ARRAY_API.PyArray_NewFromDescr(
            py,
            array_type as *mut ffi::PyTypeObject,
            float64 as *mut PyArray_Descr,
            dims.len() as c_int,
            dims.as_mut_ptr(),
            std::ptr::null_mut(),
            data,
            NPY_ARRAY_CARRAY,
            std::ptr::null_mut(),
        );
        let array = Bound::from_owned_ptr_or_err(py, array)?;
        // takes the base's reference, even where it fails
        if PY_ARRAY_API.PyArray_SetBaseObject(py, array.as_ptr().cast(), base.into_ptr()) != 0 {
            return Err(PyErr::fetch(py));
        }
        Ok(array.cast_into_unchecked())
    }
}

/// The capsule's destructor: frees the buffer it holds.
unsafe extern "C" fn free_buffer(capsule: *mut ffi::PyObject) {
    // SAFETY: a capsule of `array_on_buffer`, unnamed, whose pointer is a boxed buffer let go of
    // by `Box::into_raw`; a capsule is destroyed once.
    unsafe {
        let owner = ffi::PyCapsule_GetPointer(capsule, std::ptr::null()).cast::<Buffer>();
        if !owner.is_null() {
            drop(Box::from_raw(owner));
        }
    }
}
