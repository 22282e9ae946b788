//! Frame Jacobians: the 6 x nv matrix J with `[v; ω] = J q̇`, rows `[linear; angular]`.
//!
//! Reference: the ECE 470 and TU Berlin notes' geometric Jacobian (column i of a revolute joint: `[z_i × (p - p_i); z_i]`,
//! prismatic: `[z_i; 0]`), computed generally as in Featherstone (2008) §8.1: column k of joint j
//! is the joint's subspace column `S_k` mapped to world coordinates, `X_{j←0}⁻¹ S_k = (ω, v_O)`;
//! the linear velocity of the frame's origin p is then `v_O + ω × p`, for a joint turning about ω
//! through r the notes' `ω × (p − r)`, which is how it is computed.
//! Input: q (nq), a frame index and a [`Reference`]. Writes `data.support`, and `data.x_up`,
//! `data.x_world` along it, and `data.jacobian`. Cost: O(depth) plus one column per ancestor
//! degree of freedom.

use crate::algo::kinematics::{check_frame, placement_of_frame, update_support_placements};
use crate::error::Result;
use crate::model::Model;
use crate::spatial::{rotate, Real, Transform, Vec3};
use crate::Data;
use nalgebra::{DMatrix, Vector3};

/// The coordinates a Jacobian's columns are expressed in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reference {
    /// Linear velocity of the frame's origin and angular velocity, both in world axes: the lecture
    /// notes' geometric Jacobian.
    World,
    /// The same two vectors in the frame's own axes.
    Local,
    /// Featherstone's spatial velocity in world coordinates: the linear velocity of the body point
    /// passing through the world origin, and the angular velocity (Pinocchio's WORLD).
    Spatial,
}

/// J(q) of frame `frame`, written into `data.jacobian` (6 x nv).
pub fn jacobian<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    frame: usize,
    reference: Reference,
) -> Result<&'d DMatrix<f64>> {
    let mut jacobian = std::mem::take(&mut data.jacobian);
    jacobian.as_mut_slice().fill(0.0);
    let result = jacobian_columns(
        model,
        data,
        q,
        frame,
        reference,
        |column, linear, angular| {
            jacobian.fixed_view_mut::<3, 1>(0, column).copy_from(linear);
            jacobian
                .fixed_view_mut::<3, 1>(3, column)
                .copy_from(angular);
        },
    );
    data.jacobian = jacobian;
    result.map(|()| &data.jacobian)
}

/// The columns of J(q) that are not zero (those of the joints between the frame and the world),
/// each handed to `column(index, linear, angular)`: for a caller that stores J its own way
/// (row-major, for NumPy). Writes `data.support`, and `data.x_up`, `data.x_world` along it.
pub fn jacobian_columns(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    frame: usize,
    reference: Reference,
    column: impl FnMut(usize, &Vec3, &Vec3),
) -> Result<()> {
    model.check_configuration(q)?;
    check_frame(model, frame)?;
    update_support_placements(model, data, q, model.frames[frame].body);
    let placements = (&data.support[..], &data.x_world[..]);
    columns_of(model, placements, frame, reference, column);
    Ok(())
}

/// [`jacobian_columns`] from the placements of the frame's support (`x_world` on `support`), in
/// `f64` or lanes.
#[inline(always)]
pub(crate) fn columns_of<S: Real>(
    model: &Model,
    (support, x_world): (&[usize], &[Transform<S>]),
    frame: usize,
    reference: Reference,
    mut column: impl FnMut(usize, &Vector3<S>, &Vector3<S>),
) {
    // X_{frame←0}; p: the frame's origin in world coordinates
    let pose = placement_of_frame(model, x_world, frame);
    let origin = pose.translation;
    for &j in support {
        let joint = &model.joints[j];
        for (k, index) in model.v_range(j).enumerate() {
            // (ω, v_O) = X_{j←0}⁻¹ S_k, or (ω, v_p) with v_p = v_O + ω × p
            let (linear, angular) = match reference {
                Reference::Spatial => {
                    let s = joint.subspace_column_from(k, &x_world[j]);
                    (s.linear, s.angular)
                }
                Reference::World => {
                    let s = joint.subspace_column_at(k, &x_world[j], &origin);
                    (s.linear, s.angular)
                }
                Reference::Local => {
                    let s = joint.subspace_column_at(k, &x_world[j], &origin);
                    (
                        rotate(&pose.rotation, &s.linear),
                        rotate(&pose.rotation, &s.angular),
                    )
                }
            };
            column(index, &linear, &angular);
        }
    }
}
