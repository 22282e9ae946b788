//! Resolving the constraint objects against a model: names to frame and joint indices, a
//! `ConstraintSet` for the core (kept for the next call given the same objects), and the
//! model's own constraints back as objects.

use super::{PyDistance, PyFrameAnchor, PyJointCoupling, PyPointAnchor};
use crate::args::describe;
use crate::model::PyModel;
use nalgebra::{Matrix3, Matrix4, Vector3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PySequence, PyString};
use robodyn::constraint::{
    Attachment, Constraint, ConstraintKind, ConstraintReference, ConstraintSet,
};
use robodyn::spatial::Transform;
use robodyn::Model;
use std::sync::Arc;

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
