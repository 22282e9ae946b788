//! The constraint objects of the Python API (`robodyn.PointAnchor`, `FrameAnchor`,
//! `JointCoupling`, `Distance`): frames and joints by name, resolved against a model when a call
//! uses them (`constraint_set`).

use crate::args::{describe, named};
use crate::model::PyModel;
use nalgebra::{Matrix3, Matrix4, Vector3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PySequence, PyString, PyTuple};
use robodyn::constraint::{
    Attachment, Constraint, ConstraintKind, ConstraintReference, ConstraintSet,
};
use robodyn::spatial::Transform;
use robodyn::Model;
use std::sync::Arc;

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
/// `offset` (or c0). Both joints revolute or both
/// prismatic. 1 row; its force is the torque (or force) on `joint`.
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

/// The constraints of argument `constraints` (one constraint or a sequence of them) resolved
/// against `model`, or the set of the last call where it passed the same objects.
pub(crate) fn constraint_set(
    model: &PyModel,
    value: &Bound<PyAny>,
) -> PyResult<Arc<ConstraintSet>> {
    let items = constraint_items(value)?;
    let last = || {
        model
            .last_constraints
            .lock()
            .unwrap_or_else(|e| e.into_inner())
    };
    if let Some(resolved) = last().as_ref().filter(|r| r.made_from(&items)) {
        return Ok(resolved.set.clone());
    }
    // resolved without the lock held: describing a bad item may run Python code, which may let
    // another thread take the GIL and then wait for the lock
    let constraints = items
        .iter()
        .enumerate()
        .map(|(k, item)| resolve(model, item, k))
        .collect::<PyResult<Vec<_>>>()?;
    let set = Arc::new(ConstraintSet::new(&model.model, constraints).map_err(crate::to_py_err)?);
    *last() = Some(ResolvedConstraints {
        objects: items.into_iter().map(Bound::unbind).collect(),
        set: set.clone(),
    });
    Ok(set)
}

/// The constraint objects of the argument `constraints`: one, or a sequence of them.
fn constraint_items<'py>(value: &Bound<'py, PyAny>) -> PyResult<Vec<Bound<'py, PyAny>>> {
    if is_constraint(value) {
        return Ok(vec![value.clone()]);
    }
    let sequence = value
        .cast::<PySequence>()
        .ok()
        .filter(|_| !value.is_instance_of::<PyString>());
    let sequence = sequence.ok_or_else(|| {
        PyValueError::new_err(format!(
            "argument 'constraints': expected a constraint (PointAnchor, FrameAnchor, \
             JointCoupling, Distance) or a list of them, got {}",
            describe(value)
        ))
    })?;
    sequence.try_iter()?.collect()
}

/// The set the last call resolved, with the objects it came from. The constraint classes are
/// frozen and final, so the same objects in the same order resolve to the same set: a loop
/// that passes one list again and again resolves it once. The objects are held, so their
/// identities stay theirs.
pub(crate) struct ResolvedConstraints {
    objects: Vec<Py<PyAny>>,
    set: Arc<ConstraintSet>,
}

impl ResolvedConstraints {
    /// Whether `items` are the very objects this set came from, in order.
    fn made_from(&self, items: &[Bound<PyAny>]) -> bool {
        self.objects.len() == items.len()
            && self
                .objects
                .iter()
                .zip(items)
                .all(|(o, i)| o.as_ptr() == i.as_ptr())
    }
}

fn is_constraint(value: &Bound<PyAny>) -> bool {
    value.is_instance_of::<PyPointAnchor>()
        || value.is_instance_of::<PyFrameAnchor>()
        || value.is_instance_of::<PyJointCoupling>()
        || value.is_instance_of::<PyDistance>()
}

/// Constraint `k` of the argument, its names resolved.
fn resolve(model: &PyModel, value: &Bound<PyAny>, k: usize) -> PyResult<Constraint> {
    let context = |error: PyErr| {
        PyValueError::new_err(format!(
            "argument 'constraints[{k}]' ({}): {}",
            value.repr().map_or_else(|_| "?".into(), |r| r.to_string()),
            error.value(value.py())
        ))
    };
    resolve_one(model, value).map_err(context)?.ok_or_else(|| {
        PyValueError::new_err(format!(
            "argument 'constraints[{k}]': expected a PointAnchor, FrameAnchor, \
                 JointCoupling or Distance, got {}",
            describe(value)
        ))
    })
}

fn resolve_one(model: &PyModel, value: &Bound<PyAny>) -> PyResult<Option<Constraint>> {
    let frame = |name: &str| frame_of(model, name);
    let attachment = |frame_name: &str, placement: Transform| -> PyResult<Attachment> {
        Ok(Attachment {
            frame: Some(frame(frame_name)?),
            placement,
        })
    };
    let second = |frame2: &Option<String>, placement: Option<Transform>| match (frame2, placement) {
        (Some(f), p) => attachment(f, p.unwrap_or_default()).map(Some),
        (None, Some(p)) => Ok(Some(Attachment {
            frame: None,
            placement: p,
        })),
        (None, None) => Ok(None),
    };
    if let Ok(point) = value.cast::<PyPointAnchor>() {
        let p = point.get();
        let offset = |o: &[f64; 3]| Transform::from_translation(&Vector3::from(*o));
        let kind = ConstraintKind::Point {
            first: attachment(&p.frame, offset(&p.offset))?,
            second: second(&p.frame2, p.offset2.as_ref().map(offset))?,
        };
        return Ok(Some(with_reference(kind, &p.reference)));
    }
    if let Ok(anchor) = value.cast::<PyFrameAnchor>() {
        let a = anchor.get();
        // X_{c←frame}: the placement is the pose of c in the frame
        let transform = |pose: &Matrix4<f64>| {
            let rotation: Matrix3<f64> = pose.fixed_view::<3, 3>(0, 0).into_owned();
            let position: Vector3<f64> = pose.fixed_view::<3, 1>(0, 3).into_owned();
            Transform::from_pose(&rotation, &position)
        };
        let kind = ConstraintKind::Frame {
            first: attachment(&a.frame, transform(&a.placement))?,
            second: second(&a.frame2, a.placement2.as_ref().map(transform))?,
            mask: a.mask,
        };
        return Ok(Some(with_reference(kind, &a.reference)));
    }
    if let Ok(coupling) = value.cast::<PyJointCoupling>() {
        let c = coupling.get();
        let kind = ConstraintKind::Coupling {
            follower: joint_of(model, &c.joint)?,
            leader: c
                .leader
                .as_deref()
                .map(|l| joint_of(model, l))
                .transpose()?,
            polynomial: c.polycoef,
            references: (0.0, 0.0),
        };
        return Ok(Some(with_reference(kind, "world")));
    }
    if let Ok(distance) = value.cast::<PyDistance>() {
        let d = distance.get();
        let kind = ConstraintKind::Distance {
            first: attachment(&d.frame1, Transform::default())?,
            second: attachment(&d.frame2, Transform::default())?,
            length: d.length,
        };
        return Ok(Some(with_reference(kind, "world")));
    }
    Ok(None)
}

/// A core constraint of `model` as the Python object that states it (frames and joints by name;
/// a coupling's polynomial about its reference coordinates expanded into one in q_leader).
pub(crate) fn to_python(py: Python, model: &Model, constraint: &Constraint) -> PyResult<Py<PyAny>> {
    let frame_name = |a: &Attachment| a.frame.map(|f| model.frames[f].name.clone());
    let reference = match constraint.reference {
        ConstraintReference::World => "world",
        ConstraintReference::Local => "local",
    }
    .to_string();
    let object = match &constraint.kind {
        ConstraintKind::Point { first, second } => {
            let offset = |a: &Attachment| <[f64; 3]>::from(a.placement.translation);
            Py::new(
                py,
                PyPointAnchor {
                    frame: frame_name(first).unwrap_or_default(),
                    frame2: second.as_ref().and_then(frame_name),
                    offset: offset(first),
                    offset2: second.as_ref().map(offset),
                    reference,
                },
            )?
            .into_any()
        }
        ConstraintKind::Frame {
            first,
            second,
            mask,
        } => Py::new(
            py,
            PyFrameAnchor {
                frame: frame_name(first).unwrap_or_default(),
                frame2: second.as_ref().and_then(frame_name),
                placement: first.placement.to_homogeneous(),
                placement2: second.as_ref().map(|a| a.placement.to_homogeneous()),
                mask: *mask,
                reference,
            },
        )?
        .into_any(),
        ConstraintKind::Coupling {
            follower,
            leader,
            polynomial,
            references,
        } => Py::new(
            py,
            PyJointCoupling {
                joint: model.joint_names[*follower].clone(),
                leader: leader.map(|l| model.joint_names[l].clone()),
                polycoef: expanded(polynomial, *references, leader.is_some()),
            },
        )?
        .into_any(),
        ConstraintKind::Distance {
            first,
            second,
            length,
        } => Py::new(
            py,
            PyDistance {
                frame1: frame_name(first).unwrap_or_default(),
                frame2: frame_name(second).unwrap_or_default(),
                length: *length,
            },
        )?
        .into_any(),
    };
    Ok(object)
}

/// `q_f = q_f,ref + Σ_k c_k (q_l − q_l,ref)^k` as `Σ_j d_j q_l^j`: by the binomial theorem,
/// `d_j = Σ_{k≥j} c_k C(k, j) (−q_l,ref)^(k−j)`, and `d_0` gains q_f,ref. Without a leader only
/// `c_0` counts.
fn expanded(c: &[f64; 5], (follower_ref, leader_ref): (f64, f64), has_leader: bool) -> [f64; 5] {
    let mut d = [0.0; 5];
    if !has_leader {
        d[0] = follower_ref + c[0];
        return d;
    }
    let binomial =
        |k: usize, j: usize| (0..j).fold(1.0, |b, i| b * (k - i) as f64 / (i + 1) as f64);
    for (j, dj) in d.iter_mut().enumerate() {
        *dj = (j..5)
            .map(|k| c[k] * binomial(k, j) * (-leader_ref).powi((k - j) as i32))
            .sum();
    }
    d[0] += follower_ref;
    d
}

fn with_reference(kind: ConstraintKind, reference: &str) -> Constraint {
    let reference = match reference {
        "local" => ConstraintReference::Local,
        _ => ConstraintReference::World,
    };
    Constraint { kind, reference }
}

fn frame_of(model: &PyModel, name: &str) -> PyResult<usize> {
    match model.frame_indices.get(name) {
        Some(&index) => Ok(index),
        None => model.model.frame_index(name).map_err(crate::to_py_err),
    }
}

/// The body whose joint is called `name`.
fn joint_of(model: &PyModel, name: &str) -> PyResult<usize> {
    let names = &model.model.joint_names;
    match names.iter().skip(1).position(|n| n == name) {
        Some(k) => Ok(k + 1),
        None => Err(PyValueError::new_err(format!(
            "unknown joint '{name}'; the model's joints are [{}]",
            names
                .iter()
                .skip(1)
                .map(|n| format!("'{n}'"))
                .collect::<Vec<_>>()
                .join(", ")
        ))),
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
