//! Forward kinematics: the placement of every body and frame for a configuration q.
//!
//! Reference: Featherstone, *Rigid Body Dynamics Algorithms* (2008), §4.4 (`jcalc`) and the
//! first lines of Table 5.1: `X_J = jcalc(q_i)`, `X_{i←λ(i)} = X_J X_T(i)`, and the world
//! transform `X_{i←0} = X_{i←λ(i)} X_{λ(i)←0}`; the ECE 470 notes ("forward kinematics": chained `T`).
//! Cost: one 3x3 rotation product per body; the joints' sines and cosines several at once.

use crate::error::{Error, Result};
use crate::model::Model;
use crate::spatial::{Motion, Real, Transform};
use crate::Data;

/// Writes `data.x_up` for configuration `q` (assumed already checked).
pub(crate) fn update_joint_transforms(model: &Model, data: &mut Data, q: &[f64]) {
    joint_transforms(model, q, &mut data.x_up);
}

/// How many bodies' joint sines [`joint_transforms`] evaluates together.
const TURNS_AT_ONCE: usize = 16;

/// `X_{i←λ(i)}` of every body for `q`, in `f64` or lanes (assumed already checked).
#[inline(always)]
pub(crate) fn joint_transforms<S: Real>(model: &Model, q: &[S], x_up: &mut [Transform<S>]) {
    let mut turns = [(S::zero(), S::one()); TURNS_AT_ONCE];
    for first in (1..model.nbodies()).step_by(TURNS_AT_ONCE) {
        let bodies = first..model.nbodies().min(first + TURNS_AT_ONCE);
        // consecutive bodies: their first coordinates are a slice of idx_q
        let coordinates = &model.idx_q[bodies.clone()];
        transforms_of_chunk(model, q, bodies, coordinates, &mut turns, x_up);
    }
}

/// `X_{i←λ(i)} = X_J(q_i) X_T(i)` of the bodies of `bodies`, whose first coordinates are
/// `coordinates` (a revolute joint's angle; the others' sines are not used): the sines and
/// cosines of all of them first ([`Real::sin_cos_at`]), then the transforms.
#[inline(always)]
fn transforms_of_chunk<S: Real>(
    model: &Model,
    q: &[S],
    bodies: impl Iterator<Item = usize>,
    coordinates: &[usize],
    turns: &mut [(S, S)],
    x_up: &mut [Transform<S>],
) {
    let turns = &mut turns[..coordinates.len()];
    S::sin_cos_at(q, coordinates, turns);
    for (i, &turn) in bodies.zip(turns.iter()) {
        let joint = &model.joints[i];
        let (x_tree, pattern) = (&model.x_tree[i], model.turn(i));
        x_up[i] = joint.transform_after_turn_of(&q[model.q_range(i)], turn, x_tree, pattern);
    }
}

/// Writes every body's velocity `data.v` and its acceleration with q̈ = 0 and no gravity
/// `data.a` (its velocity product), in its own coordinates, at the velocity `v` (checked), the
/// bodies placed (`data.x_up`): the outward pass of Featherstone's Table 5.1 without q̈.
pub(crate) fn update_velocity_products(model: &Model, data: &mut Data, v: &[f64]) {
    // v_i = X_i v_λ(i) + S q̇_i;  a_i = X_i a_λ(i) + v_i × S q̇_i
    data.v[0] = Motion::ZERO;
    data.a[0] = Motion::ZERO;
    for i in 1..model.nbodies() {
        let parent = model.parent[i];
        let v_j = model.joints[i].motion(&v[model.v_range(i)]);
        let v_i = data.x_up[i].apply_motion(&data.v[parent]) + v_j;
        data.a[i] = data.x_up[i].apply_motion(&data.a[parent]) + v_i.cross_motion(&v_j);
        data.v[i] = v_i;
    }
}

/// Writes `data.x_up` and `data.x_world` (the pose of every body) for `q` and returns the poses.
pub(crate) fn update_body_placements(model: &Model, data: &mut Data, q: &[f64]) {
    body_placements(model, q, &mut data.x_up, &mut data.x_world);
}

/// `X_{i←λ(i)}` and `X_{i←0}` of every body for `q`, in `f64` or lanes (`x_world[0]` is left as
/// it is: the identity).
#[inline(always)]
pub(crate) fn body_placements<S: Real>(
    model: &Model,
    q: &[S],
    x_up: &mut [Transform<S>],
    x_world: &mut [Transform<S>],
) {
    joint_transforms(model, q, x_up);
    for i in 1..model.nbodies() {
        // X_{i←0} = X_{i←λ(i)} X_{λ(i)←0}
        x_world[i] = x_up[i].compose_turned(model.turn(i), &x_world[model.parent[i]]);
    }
}

/// Forward kinematics: checks `q`, writes `data.x_up` and `data.x_world`.
pub fn forward_kinematics<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
) -> Result<&'d [Transform]> {
    model.check_configuration(q)?;
    update_body_placements(model, data, q);
    Ok(&data.x_world)
}

/// Writes `data.support` (the bodies from `body` to the world) and `data.x_up`, `data.x_world`
/// along it only: what a single frame needs.
pub(crate) fn update_support_placements(model: &Model, data: &mut Data, q: &[f64], body: usize) {
    support_of(model, body, &mut data.support);
    support_placements(model, q, &data.support, &mut data.x_up, &mut data.x_world);
}

/// The bodies from `body` to the world (the world left out), into `support`.
pub(crate) fn support_of(model: &Model, body: usize, support: &mut Vec<usize>) {
    support.clear();
    let mut j = body;
    while j != 0 {
        support.push(j);
        j = model.parent[j];
    }
}

/// `X_{i←λ(i)}` and `X_{i←0}` of the bodies of `support` (from a body to the world), in `f64` or
/// lanes.
#[inline(always)]
pub(crate) fn support_placements<S: Real>(
    model: &Model,
    q: &[S],
    support: &[usize],
    x_up: &mut [Transform<S>],
    x_world: &mut [Transform<S>],
) {
    // the joints first, independent of one another (their sines several at once), then the
    // chain that needs them
    let (mut indices, mut turns) = ([0; TURNS_AT_ONCE], [(S::zero(), S::one()); TURNS_AT_ONCE]);
    for bodies in support.chunks(TURNS_AT_ONCE) {
        for (index, &i) in indices.iter_mut().zip(bodies) {
            *index = model.idx_q[i];
        }
        let coordinates = &indices[..bodies.len()];
        transforms_of_chunk(
            model,
            q,
            bodies.iter().copied(),
            coordinates,
            &mut turns,
            x_up,
        );
    }
    // X_{i←0} = X_{i←λ(i)} X_{λ(i)←0} down the chain from the world, whose every body's parent
    // is the one before it: that one's placement is carried on, not read back from memory
    let mut placement = x_world[0];
    for &i in support.iter().rev() {
        placement = x_up[i].compose_turned(model.turn(i), &placement);
        x_world[i] = placement;
    }
}

/// The placement `X_{frame←0}` of one frame for configuration `q`, computing only the bodies
/// between it and the world. Writes `data.support`, and `data.x_up`, `data.x_world` on it.
pub fn frame_pose(model: &Model, data: &mut Data, q: &[f64], frame: usize) -> Result<Transform> {
    model.check_configuration(q)?;
    check_frame(model, frame)?;
    update_support_placements(model, data, q, model.frames[frame].body);
    Ok(frame_placement(model, data, frame))
}

/// Checks a frame index.
pub(crate) fn check_frame(model: &Model, frame: usize) -> Result<()> {
    if frame < model.frames.len() {
        return Ok(());
    }
    Err(Error::InvalidValue {
        argument: "frame".into(),
        message: format!(
            "expected a frame index below {}, got {frame}",
            model.frames.len()
        ),
    })
}

/// `X_{frame←0}` of frame `frame` from the body placements in `data.x_world` (call
/// [`forward_kinematics`] first). Its pose in the world is [`Transform::to_homogeneous`].
pub fn frame_placement(model: &Model, data: &Data, frame: usize) -> Transform {
    placement_of_frame(model, &data.x_world, frame)
}

/// `X_{frame←0} = X_{frame←body} X_{body←0}` from the body placements `x_world`, in `f64` or
/// lanes.
#[inline(always)]
pub(crate) fn placement_of_frame<S: Real>(
    model: &Model,
    x_world: &[Transform<S>],
    frame: usize,
) -> Transform<S> {
    let f = &model.frames[frame];
    Transform::splat(&f.placement) * x_world[f.body]
}
