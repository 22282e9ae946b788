//! Velocity and acceleration of a frame, and with them J̇ q̇.
//!
//! Reference: Featherstone, *Rigid Body Dynamics Algorithms* (2008), §2.10-2.11 and the outward
//! pass of Table 5.1 without gravity: `v_i = X_i v_λ(i) + S_i q̇_i`,
//! `a_i = X_i a_λ(i) + S_i q̈_i + v_i × S_i q̇_i`, here only along the frame's support. The classical
//! (textbook) acceleration of the frame's origin is the spatial one plus `ω × v` (the ECE 470 notes,
//! "Recap: Acceleration"): `p̈ = a_O + ω × ṗ`. With q̈ = 0 it is `J̇ q̇`, the bias acceleration.
//! The time derivative of the Jacobian follows from `S` being constant in its body: in world
//! coordinates each column `s = X⁻¹ S_k` changes as `ṡ = v_j × s` (Featherstone §2.9), `v_j` the
//! spatial velocity of the joint's body; the world and local references add the motion of the
//! frame's origin and axes.
//! Inputs: q (nq), v (nv), a (nv), a frame and a [`Reference`]. Writes `data.support`,
//! `data.x_up`, `data.x_world`, `data.v`, `data.a` along the support (and `data.jacobian_dot`).
//! Cost: O(depth).

use crate::algo::kinematics::{check_frame, frame_placement, update_support_placements};
use crate::algo::Reference;
use crate::error::{check_vector, Result};
use crate::model::Model;
use crate::spatial::{Motion, Vec3};
use crate::Data;
use nalgebra::DMatrix;

/// The frame's velocity `[linear; angular]`: with [`Reference::World`] the velocity of its origin
/// and its angular velocity in world axes, [`Reference::Local`] the same in its own axes,
/// [`Reference::Spatial`] the spatial velocity in world coordinates. Equals `J(q) q̇`.
pub fn frame_velocity(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    frame: usize,
    reference: Reference,
) -> Result<[f64; 6]> {
    let (velocity, _) = frame_motion(model, data, q, v, None, frame, reference)?;
    Ok(velocity)
}

/// The frame's acceleration `[linear; angular]`: with [`Reference::World`] the classical
/// acceleration of its origin (`p̈`) and its angular acceleration, in world axes;
/// [`Reference::Local`] the same two vectors in the frame's axes; [`Reference::Spatial`]
/// Featherstone's spatial acceleration in world coordinates. Equals `J(q) q̈ + J̇(q, q̇) q̇`; with
/// `a = 0` it is `J̇ q̇`.
pub fn frame_acceleration(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    frame: usize,
    reference: Reference,
) -> Result<[f64; 6]> {
    check_vector("a", a, model.nv)?;
    let (_, acceleration) = frame_motion(model, data, q, v, Some(a), frame, reference)?;
    Ok(acceleration)
}

/// Checks (q, q̇, frame) and places the bodies from the frame's body to the world
/// (`data.support`, `data.x_up`, `data.x_world` along it); returns the frame's body.
pub(crate) fn place_frame_support(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    frame: usize,
) -> Result<usize> {
    model.check_configuration(q)?;
    check_vector("v", v, model.nv)?;
    check_frame(model, frame)?;
    let body = model.frames[frame].body;
    update_support_placements(model, data, q, body);
    Ok(body)
}

/// Velocity and acceleration of a frame in the requested coordinates.
fn frame_motion(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    a: Option<&[f64]>,
    frame: usize,
    reference: Reference,
) -> Result<([f64; 6], [f64; 6])> {
    let body = place_frame_support(model, data, q, v, frame)?;

    // outward along the support: v_i = X_i v_λ(i) + v_J;  a_i = X_i a_λ(i) + S q̈ + v_i × v_J
    data.v[0] = Motion::ZERO;
    data.a[0] = Motion::ZERO;
    for k in (0..data.support.len()).rev() {
        let i = data.support[k];
        let joint = &model.joints[i];
        let parent = model.parent[i];
        let v_j = joint.motion(&v[model.v_range(i)]);
        let v_i = data.x_up[i].apply_motion(&data.v[parent]) + v_j;
        let mut a_i = data.x_up[i].apply_motion(&data.a[parent]) + v_i.cross_motion(&v_j);
        if let Some(a) = a {
            a_i += joint.motion(&a[model.v_range(i)]);
        }
        data.v[i] = v_i;
        data.a[i] = a_i;
    }

    // in the frame's coordinates: (ω, v_O) and (ω̇, a_O) of its origin
    let to_frame = model.frames[frame].placement;
    let velocity = to_frame.apply_motion(&data.v[body]);
    let acceleration = to_frame.apply_motion(&data.a[body]);
    let pose = frame_placement(model, data, frame);
    let world_axes = |m: &Motion| {
        Motion::new(
            pose.rotation.tr_mul(&m.angular),
            pose.rotation.tr_mul(&m.linear),
        )
    };
    Ok(match reference {
        Reference::Spatial => (
            data.x_world[body]
                .inverse_apply_motion(&data.v[body])
                .to_array(),
            data.x_world[body]
                .inverse_apply_motion(&data.a[body])
                .to_array(),
        ),
        Reference::Local | Reference::World => {
            // classical acceleration of the origin: p̈ = a_O + ω × v_O
            let classical = Motion::new(
                acceleration.angular,
                acceleration.linear + velocity.angular.cross(&velocity.linear),
            );
            if reference == Reference::Local {
                (velocity.to_array(), classical.to_array())
            } else {
                (
                    world_axes(&velocity).to_array(),
                    world_axes(&classical).to_array(),
                )
            }
        }
    })
}

/// J̇(q, q̇) of frame `frame` (6 x nv, rows `[linear; angular]`, the same [`Reference`] as
/// [`crate::algo::jacobian()`]), written into `data.jacobian_dot`. `J̇ q̇` equals
/// [`frame_acceleration`] with q̈ = 0.
pub fn jacobian_time_variation<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    frame: usize,
    reference: Reference,
) -> Result<&'d DMatrix<f64>> {
    // body velocities along the support (data.v), in body coordinates
    frame_motion(model, data, q, v, None, frame, reference)?;
    let body = model.frames[frame].body;
    let pose = frame_placement(model, data, frame);
    // the frame's origin p, its velocity ṗ and angular velocity ω_f, in world coordinates
    let origin = pose.translation;
    let frame_velocity = data.x_world[body].inverse_apply_motion(&data.v[body]);
    let origin_velocity = frame_velocity.linear + frame_velocity.angular.cross(&origin);
    let frame_rotation_rate = frame_velocity.angular;

    data.jacobian_dot.as_mut_slice().fill(0.0);
    for &j in &data.support {
        let joint = &model.joints[j];
        let body_velocity = data.x_world[j].inverse_apply_motion(&data.v[j]);
        for (k, column) in model.v_range(j).enumerate() {
            // s = X_{j←0}⁻¹ S_k;  ṡ = v_j × s
            let s = joint.subspace_column_from(k, &data.x_world[j]);
            let s_dot = body_velocity.cross_motion(&s);
            let (linear, angular): (Vec3, Vec3) = match reference {
                Reference::Spatial => (s_dot.linear, s_dot.angular),
                Reference::World | Reference::Local => {
                    // d/dt (v_O + ω × p) = v̇_O + ω̇ × p + ω × ṗ
                    let linear = s_dot.linear
                        + s_dot.angular.cross(&origin)
                        + s.angular.cross(&origin_velocity);
                    if reference == Reference::World {
                        (linear, s_dot.angular)
                    } else {
                        // d/dt (Rᵀ x) = Rᵀ (ẋ - ω_f × x)
                        let world_linear = s.linear + s.angular.cross(&origin);
                        (
                            pose.rotation * (linear - frame_rotation_rate.cross(&world_linear)),
                            pose.rotation * (s_dot.angular - frame_rotation_rate.cross(&s.angular)),
                        )
                    }
                }
            };
            data.jacobian_dot
                .fixed_view_mut::<3, 1>(0, column)
                .copy_from(&linear);
            data.jacobian_dot
                .fixed_view_mut::<3, 1>(3, column)
                .copy_from(&angular);
        }
    }
    Ok(&data.jacobian_dot)
}
