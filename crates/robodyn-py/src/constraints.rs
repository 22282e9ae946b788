//! The constraint objects of the Python API (`robodyn.PointAnchor`, `FrameAnchor`,
//! `JointCoupling`, `Distance`): frames and joints by name, resolved against a model when a call
//! uses them (`constraint_set`).

use crate::args::{describe, named};
use nalgebra::{Matrix3, Matrix4};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyString, PyTuple};

mod resolve;

pub(crate) use resolve::{constraint_set, to_python, ResolvedConstraints};

/// How far from orthonormal a placement's rotation may be (|RᵀR − 1|∞).
const ROTATION_TOLERANCE: f64 = 1e-9;

/// A point of `frame` held to the world, or to a point of `frame2`: 3 rows, the velocity of the
/// first point minus that of the second. `offset`: the point in `frame`'s axes from its origin
/// (default: the origin). `offset2`: the point in `frame2`'s axes, or, without `frame2`, the
/// world point it is held to (default: where it is now, no position error). `reference`:
/// "world" (rows and forces in world axes, Pinocchio's LOCAL_WORLD_ALIGNED) or "local" (in
/// `frame`'s axes).
#[pyclass(name = "PointAnchor", module = "robodyn", frozen)]
pub(crate) struct PyPointAnchor {
    /// The frame whose point is held.
    #[pyo3(get)]
    frame: String,
    /// The frame it is held to, or None: the world.
    #[pyo3(get)]
    frame2: Option<String>,
    /// The point in `frame`'s axes, from its origin (m).
    #[pyo3(get)]
    offset: [f64; 3],
    /// The point it is held to, in `frame2`'s axes or the world's (m); None: where it is.
    #[pyo3(get)]
    offset2: Option<[f64; 3]>,
    /// The axes of the rows and forces: "world" or "local".
    #[pyo3(get)]
    reference: String,
}

#[pymethods]
impl PyPointAnchor {
    #[new]
    #[pyo3(
        signature = (frame, frame2=None, offset=None, offset2=None, reference=String::from("world")),
        text_signature = "(frame, frame2=None, offset=None, offset2=None, reference='world')"
    )]
    fn new(
        frame: &Bound<PyAny>,
        frame2: Option<&Bound<PyAny>>,
        offset: Option<&Bound<PyAny>>,
        offset2: Option<&Bound<PyAny>>,
        #[pyo3(from_py_with = reference_name)] reference: String,
    ) -> PyResult<Self> {
        Ok(PyPointAnchor {
            frame: name("frame", frame)?,
            frame2: frame2.map(|f| name("frame2", f)).transpose()?,
            offset: offset
                .map(|o| point("offset", o))
                .transpose()?
                .unwrap_or([0.0; 3]),
            offset2: offset2.map(|o| point("offset2", o)).transpose()?,
            reference,
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "PointAnchor({:?}, frame2={}, offset={:?}, offset2={}, reference={:?})",
            self.frame,
            optional_text(&self.frame2),
            self.offset,
            self.offset2.map_or("None".into(), |o| format!("{o:?}")),
            self.reference
        )
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let this = slf.get();
        let args = (
            this.frame.clone(),
            this.frame2.clone(),
            this.offset.to_vec(),
            this.offset2.map(|o| o.to_vec()),
            this.reference.clone(),
        );
        (slf.get_type(), args).into_pyobject(slf.py())
    }
}

/// A frame held to the world, or to a frame of `frame2`: 6 rows `[linear x, y, z; angular x,
/// y, z]` (the velocity of its origin and its angular velocity, minus the second's), or those
/// `mask` keeps (six booleans). `placement`: the held frame as a 4×4 pose in `frame` (default:
/// `frame` itself). `placement2`: its target as a 4×4 pose in `frame2`, or, without `frame2`, in
/// the world (default: where it is now). `reference` as for `PointAnchor`.
#[pyclass(name = "FrameAnchor", module = "robodyn", frozen)]
pub(crate) struct PyFrameAnchor {
    /// The frame held.
    #[pyo3(get)]
    frame: String,
    /// The frame it is held to, or None: the world.
    #[pyo3(get)]
    frame2: Option<String>,
    placement: Matrix4<f64>,
    placement2: Option<Matrix4<f64>>,
    /// The rows kept, `[linear x, y, z; angular x, y, z]`.
    #[pyo3(get)]
    mask: [bool; 6],
    /// The axes of the rows and forces: "world" or "local".
    #[pyo3(get)]
    reference: String,
}

#[pymethods]
impl PyFrameAnchor {
    #[new]
    #[pyo3(
        signature = (frame, frame2=None, placement=None, placement2=None, mask=None, reference=String::from("world")),
        text_signature = "(frame, frame2=None, placement=None, placement2=None, mask=None, reference='world')"
    )]
    fn new(
        frame: &Bound<PyAny>,
        frame2: Option<&Bound<PyAny>>,
        placement: Option<&Bound<PyAny>>,
        placement2: Option<&Bound<PyAny>>,
        mask: Option<&Bound<PyAny>>,
        #[pyo3(from_py_with = reference_name)] reference: String,
    ) -> PyResult<Self> {
        let mask = match mask {
            None => [true; 6],
            Some(m) => row_mask(m)?,
        };
        if !mask.iter().any(|&kept| kept) {
            return Err(PyValueError::new_err(
                "argument 'mask': expected six booleans keeping at least one row, got none kept",
            ));
        }
        Ok(PyFrameAnchor {
            frame: name("frame", frame)?,
            frame2: frame2.map(|f| name("frame2", f)).transpose()?,
            placement: placement
                .map(|p| pose("placement", p))
                .transpose()?
                .unwrap_or_else(Matrix4::identity),
            placement2: placement2.map(|p| pose("placement2", p)).transpose()?,
            mask,
            reference,
        })
    }

    /// The held frame in `frame`, 4×4 (a nested list).
    #[getter]
    fn placement(&self) -> Vec<Vec<f64>> {
        rows_of(&self.placement)
    }

    /// Its target (4×4, in `frame2` or the world), or None: where it is now.
    #[getter]
    fn placement2(&self) -> Option<Vec<Vec<f64>>> {
        self.placement2.as_ref().map(rows_of)
    }

    fn __repr__(&self) -> String {
        format!(
            "FrameAnchor({:?}, frame2={}, mask={:?}, reference={:?})",
            self.frame,
            optional_text(&self.frame2),
            self.mask,
            self.reference
        )
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let this = slf.get();
        let args = (
            this.frame.clone(),
            this.frame2.clone(),
            rows_of(&this.placement),
            this.placement2.as_ref().map(rows_of),
            this.mask.to_vec(),
            this.reference.clone(),
        );
        (slf.get_type(), args).into_pyobject(slf.py())
    }
}

/// Joint `joint`'s coordinate held to `ratio · q_leader + offset`, or, with `polycoef` (up to five
/// numbers c0 … c4), to `c0 + c1 q_leader + … + c4 q_leader⁴`; with `leader` None, held at
/// `offset` (or c0). Each joint revolute or prismatic
/// (a revolute leader may drive a prismatic joint, as a rack and pinion does). 1 row; its force
/// is the torque (or force) on `joint`.
#[pyclass(name = "JointCoupling", module = "robodyn", frozen)]
pub(crate) struct PyJointCoupling {
    /// The joint that follows.
    #[pyo3(get)]
    joint: String,
    /// The joint it follows, or None: it is held at `polycoef[0]`.
    #[pyo3(get)]
    leader: Option<String>,
    /// c0 … c4: q_joint = c0 + c1 q_leader + … + c4 q_leader⁴.
    #[pyo3(get)]
    polycoef: [f64; 5],
}

#[pymethods]
impl PyJointCoupling {
    #[new]
    #[pyo3(signature = (joint, leader, ratio=1.0, offset=0.0, polycoef=None))]
    fn new(
        joint: &Bound<PyAny>,
        leader: Option<&Bound<PyAny>>,
        #[pyo3(from_py_with = named::ratio)] ratio: f64,
        #[pyo3(from_py_with = named::offset)] offset: f64,
        polycoef: Option<&Bound<PyAny>>,
    ) -> PyResult<Self> {
        let polycoef = match polycoef {
            None => [offset, ratio, 0.0, 0.0, 0.0],
            Some(_) if ratio != 1.0 || offset != 0.0 => {
                return Err(PyValueError::new_err(
                    "arguments 'ratio', 'offset' and 'polycoef': expected either ratio and \
                     offset or polycoef, got both",
                ))
            }
            Some(c) => {
                let values = numbers("polycoef", c)?;
                if values.is_empty() || values.len() > 5 {
                    return Err(PyValueError::new_err(format!(
                        "argument 'polycoef': expected 1 to 5 coefficients, got {}",
                        values.len()
                    )));
                }
                std::array::from_fn(|k| values.get(k).copied().unwrap_or(0.0))
            }
        };
        if polycoef.iter().any(|c| !c.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "arguments 'ratio', 'offset', 'polycoef': expected finite values, got {polycoef:?}"
            )));
        }
        Ok(PyJointCoupling {
            joint: name("joint", joint)?,
            leader: leader.map(|l| name("leader", l)).transpose()?,
            polycoef,
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "JointCoupling({:?}, {}, polycoef={:?})",
            self.joint,
            optional_text(&self.leader),
            self.polycoef
        )
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let this = slf.get();
        let args = (
            this.joint.clone(),
            this.leader.clone(),
            1.0,
            0.0,
            this.polycoef.to_vec(),
        );
        (slf.get_type(), args).into_pyobject(slf.py())
    }
}

/// The origins of `frame1` and `frame2` held at distance `length` (m): 1 row, the rate of their
/// distance; its force pushes them apart when positive.
#[pyclass(name = "Distance", module = "robodyn", frozen)]
pub(crate) struct PyDistance {
    /// One frame, whose origin is held.
    #[pyo3(get)]
    frame1: String,
    /// The other.
    #[pyo3(get)]
    frame2: String,
    /// The distance held between their origins (m).
    #[pyo3(get)]
    length: f64,
}

#[pymethods]
impl PyDistance {
    #[new]
    fn new(
        frame1: &Bound<PyAny>,
        frame2: &Bound<PyAny>,
        #[pyo3(from_py_with = named::length)] length: f64,
    ) -> PyResult<Self> {
        if !(length.is_finite() && length > 0.0) {
            return Err(PyValueError::new_err(format!(
                "argument 'length': expected a positive finite distance (m), got {length}"
            )));
        }
        Ok(PyDistance {
            frame1: name("frame1", frame1)?,
            frame2: name("frame2", frame2)?,
            length,
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Distance({:?}, {:?}, length={})",
            self.frame1, self.frame2, self.length
        )
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let this = slf.get();
        let args = (this.frame1.clone(), this.frame2.clone(), this.length);
        (slf.get_type(), args).into_pyobject(slf.py())
    }
}

fn name(argument: &str, value: &Bound<PyAny>) -> PyResult<String> {
    match value.cast::<PyString>() {
        Ok(text) => Ok(text.to_str()?.to_string()),
        Err(_) => Err(PyValueError::new_err(format!(
            "argument '{argument}': expected a name (str), got {}",
            describe(value)
        ))),
    }
}

/// "world" or "local".
fn reference_name(value: &Bound<PyAny>) -> PyResult<String> {
    match value.cast::<PyString>().ok().map(|t| t.to_string()) {
        Some(r) if r == "world" || r == "local" => Ok(r),
        _ => Err(PyValueError::new_err(format!(
            "argument 'reference': expected 'world' or 'local', got {}",
            value.repr()?
        ))),
    }
}

fn numbers(argument: &str, value: &Bound<PyAny>) -> PyResult<Vec<f64>> {
    value.extract::<Vec<f64>>().map_err(|_| {
        PyValueError::new_err(format!(
            "argument '{argument}': expected a sequence of numbers, got {}",
            describe(value)
        ))
    })
}

fn point(argument: &str, value: &Bound<PyAny>) -> PyResult<[f64; 3]> {
    let values = numbers(argument, value)?;
    match <[f64; 3]>::try_from(values.as_slice()) {
        Ok(p) if p.iter().all(|x| x.is_finite()) => Ok(p),
        _ => Err(PyValueError::new_err(format!(
            "argument '{argument}': expected 3 finite numbers (m), got {values:?}"
        ))),
    }
}

fn row_mask(value: &Bound<PyAny>) -> PyResult<[bool; 6]> {
    let values: Vec<bool> = value.extract().map_err(|_| {
        PyValueError::new_err(format!(
            "argument 'mask': expected six booleans [linear x, y, z; angular x, y, z], got {}",
            describe(value)
        ))
    })?;
    <[bool; 6]>::try_from(values.as_slice()).map_err(|_| {
        PyValueError::new_err(format!(
            "argument 'mask': expected six booleans, got {}",
            values.len()
        ))
    })
}

/// A 4×4 rigid pose: a rotation (orthonormal, determinant 1), a translation, `[0 0 0 1]` below.
fn pose(argument: &str, value: &Bound<PyAny>) -> PyResult<Matrix4<f64>> {
    let rows: Vec<Vec<f64>> = value.extract().map_err(|_| {
        PyValueError::new_err(format!(
            "argument '{argument}': expected a 4×4 pose, got {}",
            describe(value)
        ))
    })?;
    if rows.len() != 4 || rows.iter().any(|r| r.len() != 4) {
        return Err(PyValueError::new_err(format!(
            "argument '{argument}': expected a 4×4 pose, got {} rows of lengths {:?}",
            rows.len(),
            rows.iter().map(Vec::len).collect::<Vec<_>>()
        )));
    }
    let pose = Matrix4::from_fn(|r, c| rows[r][c]);
    let rotation: Matrix3<f64> = pose.fixed_view::<3, 3>(0, 0).into_owned();
    let orthonormal = (rotation.transpose() * rotation - Matrix3::identity()).amax();
    let bottom = [pose[(3, 0)], pose[(3, 1)], pose[(3, 2)], pose[(3, 3)]];
    let finite = pose.iter().all(|x| x.is_finite());
    if !finite
        || orthonormal > ROTATION_TOLERANCE
        || rotation.determinant() < 0.0
        || bottom != [0.0, 0.0, 0.0, 1.0]
    {
        return Err(PyValueError::new_err(format!(
            "argument '{argument}': expected a rigid pose [R p; 0 0 0 1] with R a rotation, got \
             {rows:?}"
        )));
    }
    Ok(pose)
}

fn rows_of(pose: &Matrix4<f64>) -> Vec<Vec<f64>> {
    (0..4)
        .map(|r| (0..4).map(|c| pose[(r, c)]).collect())
        .collect()
}

fn optional_text(text: &Option<String>) -> String {
    text.as_ref().map_or("None".into(), |t| format!("{t:?}"))
}
