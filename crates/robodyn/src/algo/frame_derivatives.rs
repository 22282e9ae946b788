//! Derivatives of a frame's velocity and classical acceleration, and of the centre of mass's
//! velocity, with respect to q (tangent space,
//! right perturbations q ⊕ δ), q̇ and q̈; those of its placement are the frame Jacobian itself
//! (log(T(q)⁻¹ T(q ⊕ δ)) = J_local δ to first order).
//!
//! In world coordinates the body's spatial velocity ν and acceleration α (no gravity) move, when
//! coordinate j of a support body b (parent λ) does, as in `derivatives` (u_j = S_j × ν_λ,
//! u'_j = S_j × ν_b):
//! ```text
//!   ∂ν/∂δ_j = S_j × (ν − ν_λ)     ∂α/∂δ_j = S_j × (α − α_λ) − u_j × (ν − ν_λ)
//!   ∂ν/∂q̇_j = S_j                 ∂α/∂q̇_j = S_j × ν − u_j − u'_j           ∂α/∂q̈_j = S_j
//! ```
//! and the frame's origin p moves with the point velocity of S_j: ∂p/∂δ_j = v_j + ω_j × p. The
//! classical quantities of the origin, ṗ = ν_lin + ω × p and p̈ = α_lin + ω̇ × p + ω × ṗ (the
//! ECE 470 notes' "Recap: Acceleration"), follow by the product rule; in the frame's own axes
//! (Rᵀ x) a change of q also turns the axes: ∂(Rᵀ x)/∂δ_j = Rᵀ (∂x − ω_j × x).
//! Inputs: q, q̇, q̈, a frame and a [`Reference`]. Writes `data.support`, `data.x_up` and
//! `data.x_world` along it, `data.s_world`, `data.v_world`, `data.a_world` of the support, and
//! `data.jacobian` (= ∂velocity/∂q̇ = ∂acceleration/∂q̈), `data.frame_velocity_dq`,
//! `data.frame_acceleration_dq`, `data.frame_acceleration_dv` (6 × nv, rows `[linear; angular]`).
//! Cost: O(depth).

use crate::algo::crba::{add_composite_inertias, world_inertias_and_subspaces};
use crate::algo::frame_motion::place_frame_support;
use crate::algo::Reference;
use crate::error::{check_vector, Result};
use crate::model::Model;
use crate::spatial::{Motion, Transform, Vec3};
use crate::Data;

/// Linear and angular parts of one column, before they are written.
type Column = (Vec3, Vec3);

/// The frame's velocity and classical acceleration derivatives (see the module documentation).
pub fn frame_motion_derivatives(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    frame: usize,
    reference: Reference,
) -> Result<()> {
    let body = place_frame_support(model, data, q, v, frame)?;
    check_vector("a", a, model.nv)?;
    let placement = model.frames[frame].placement;
    attached_motion_derivatives(model, data, (v, a), body, &placement, reference);
    Ok(())
}

/// [`frame_motion_derivatives`] of the frame `placement` = `X_{c←body}` fixed in `body`, once
/// `data.support`, `data.x_up` and `data.x_world` hold the placements from `body` to the world.
pub(crate) fn attached_motion_derivatives(
    model: &Model,
    data: &mut Data,
    (v, a): (&[f64], &[f64]),
    body: usize,
    placement: &Transform,
    reference: Reference,
) {
    // outward along the support, world coordinates: ν_i = ν_λ + S q̇, α_i = α_λ + S q̈ + ν_i × S q̇
    data.v_world[0] = Motion::ZERO;
    data.a_world[0] = Motion::ZERO;
    for k in (0..data.support.len()).rev() {
        let i = data.support[k];
        let (mut v_joint, mut a_joint) = (Motion::ZERO, Motion::ZERO);
        for (c, dof) in model.v_range(i).enumerate() {
            let s = model.joints[i].subspace_column_from(c, &data.x_world[i]);
            data.s_world[dof] = s;
            v_joint += s * v[dof];
            a_joint += s * a[dof];
        }
        let parent = model.parent[i];
        let velocity = data.v_world[parent] + v_joint;
        data.a_world[i] = data.a_world[parent] + a_joint + velocity.cross_motion(&v_joint);
        data.v_world[i] = velocity;
    }

    // the frame: origin p, axes R (`pose.rotation` = Rᵀ), ω, ṗ, ω̇, p̈ in world axes
    let pose = *placement * data.x_world[body];
    let origin = pose.translation;
    let (nu, alpha) = (data.v_world[body], data.a_world[body]);
    let velocity = (nu.linear + nu.angular.cross(&origin), nu.angular);
    let acceleration = (
        alpha.linear + alpha.angular.cross(&origin) + nu.angular.cross(&velocity.0),
        alpha.angular,
    );
    let express = |change: &Change, turn: Option<(Vec3, Column)>| -> Column {
        match (reference, turn) {
            (Reference::Spatial, _) => (change.spatial.linear, change.spatial.angular),
            (Reference::World, _) => change.classical,
            (Reference::Local, None) => (
                pose.rotation * change.classical.0,
                pose.rotation * change.classical.1,
            ),
            // ∂(Rᵀ x) = Rᵀ (∂x − ω_s × x) when q turns the axes
            (Reference::Local, Some((w, (linear, angular)))) => (
                pose.rotation * (change.classical.0 - w.cross(&linear)),
                pose.rotation * (change.classical.1 - w.cross(&angular)),
            ),
        }
    };

    // one column per coordinate on the support
    for matrix in [
        &mut data.jacobian,
        &mut data.frame_velocity_dq,
        &mut data.frame_acceleration_dq,
        &mut data.frame_acceleration_dv,
    ] {
        matrix.as_mut_slice().fill(0.0);
    }
    for &j in &data.support {
        let parent = model.parent[j];
        let (nu_parent, alpha_parent) = (data.v_world[parent], data.a_world[parent]);
        for dof in model.v_range(j) {
            let s = data.s_world[dof];
            let u = s.cross_motion(&nu_parent);
            // along δ: ∂ν = S × (ν − ν_λ), ∂α = S × (α − α_λ) − u × (ν − ν_λ), ∂p = v_s + ω_s × p
            let d_nu = s.cross_motion(&(nu - nu_parent));
            let d_alpha =
                s.cross_motion(&(alpha - alpha_parent)) - u.cross_motion(&(nu - nu_parent));
            let d_origin = s.linear + s.angular.cross(&origin);
            let (velocity_dq, acceleration_dq) =
                Change::of_motion(&d_nu, &d_alpha, d_origin, (&nu, &alpha), velocity.0, origin);
            // along q̇: ∂ν = S, ∂α = S × ν − u − u'
            let d_alpha_dv = s.cross_motion(&nu) - u - s.cross_motion(&data.v_world[j]);
            let (velocity_dv, acceleration_dv) = Change::of_motion(
                &s,
                &d_alpha_dv,
                Vec3::zeros(),
                (&nu, &alpha),
                velocity.0,
                origin,
            );
            for (matrix, column) in [
                (&mut data.jacobian, express(&velocity_dv, None)),
                (
                    &mut data.frame_velocity_dq,
                    express(&velocity_dq, Some((s.angular, velocity))),
                ),
                (
                    &mut data.frame_acceleration_dq,
                    express(&acceleration_dq, Some((s.angular, acceleration))),
                ),
                (
                    &mut data.frame_acceleration_dv,
                    express(&acceleration_dv, None),
                ),
            ] {
                matrix.fixed_view_mut::<3, 1>(0, dof).copy_from(&column.0);
                matrix.fixed_view_mut::<3, 1>(3, dof).copy_from(&column.1);
            }
        }
    }
}

/// The change of a frame quantity, as a spatial vector in world coordinates and as the classical
/// [linear; angular] of the frame's origin in world axes.
struct Change {
    spatial: Motion,
    classical: Column,
}

impl Change {
    /// The changes of the velocity and the acceleration from dν, dα and the origin's dp:
    /// dṗ = dν_lin + dω × p + ω × dp,  dp̈ = dα_lin + dω̇ × p + ω̇ × dp + dω × ṗ + ω × dṗ.
    fn of_motion(
        d_nu: &Motion,
        d_alpha: &Motion,
        d_origin: Vec3,
        (nu, alpha): (&Motion, &Motion),
        origin_velocity: Vec3,
        origin: Vec3,
    ) -> (Change, Change) {
        let (omega, omega_dot) = (nu.angular, alpha.angular);
        let d_origin_velocity = d_nu.linear + d_nu.angular.cross(&origin) + omega.cross(&d_origin);
        let d_origin_acceleration = d_alpha.linear
            + d_alpha.angular.cross(&origin)
            + omega_dot.cross(&d_origin)
            + d_nu.angular.cross(&origin_velocity)
            + omega.cross(&d_origin_velocity);
        (
            Change {
                spatial: *d_nu,
                classical: (d_origin_velocity, d_nu.angular),
            },
            Change {
                spatial: *d_alpha,
                classical: (d_origin_acceleration, d_alpha.angular),
            },
        )
    }
}

/// ∂ċ/∂q of the centre of mass's velocity ċ = J_com q̇ (3 x nv, world axes, tangent space), written
/// into `data.com_velocity_dq`, with ∂ċ/∂q̇ = J_com in the first three rows of `data.jacobian`.
/// ċ = h_lin / m with h = Σ I_i ν_i the momentum (world coordinates); moving coordinate j of body
/// b turns b's subtree (momentum H_b, composite I^C_b) and slows it by u_j = S_j × ν_λ:
/// ∂h/∂δ_j = S_j ×* H_b − I^C_b u_j. Also writes `data.x_up`, `data.x_world`, `data.s_world`,
/// `data.i_c`, `data.v_world` and the momenta in `data.f_world`. Cost: O(n).
pub fn center_of_mass_velocity_derivatives(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
) -> Result<()> {
    model.check_configuration(q)?;
    check_vector("v", v, model.nv)?;
    world_inertias_and_subspaces(model, data, q);
    // velocities and momenta, then the subtrees' sums
    data.v_world[0] = Motion::ZERO;
    for i in 1..model.nbodies() {
        let mut velocity = data.v_world[model.parent[i]];
        for dof in model.v_range(i) {
            velocity += data.s_world[dof] * v[dof];
        }
        data.v_world[i] = velocity;
        data.f_world[i] = data.i_c[i].mul_motion(&velocity);
    }
    add_composite_inertias(model, data);
    for i in (1..model.nbodies()).rev() {
        let parent = model.parent[i];
        if parent != 0 {
            let momentum = data.f_world[i];
            data.f_world[parent] += momentum;
        }
    }
    data.jacobian.as_mut_slice().fill(0.0);
    data.com_velocity_dq.as_mut_slice().fill(0.0);
    let total = model.total_mass();
    if total <= 0.0 {
        return Ok(());
    }
    for i in 1..model.nbodies() {
        let (composite, momentum) = (data.i_c[i], data.f_world[i]);
        let v_parent = data.v_world[model.parent[i]];
        for dof in model.v_range(i) {
            let s = data.s_world[dof];
            // ∂h/∂δ = S ×* H − I^C (S × ν_λ);  ∂h/∂q̇ = I^C S
            let d_momentum =
                s.cross_force(&momentum) - composite.mul_motion(&s.cross_motion(&v_parent));
            let column = composite.mul_motion(&s);
            data.com_velocity_dq
                .fixed_view_mut::<3, 1>(0, dof)
                .copy_from(&(d_momentum.linear / total));
            data.jacobian
                .fixed_view_mut::<3, 1>(0, dof)
                .copy_from(&(column.linear / total));
        }
    }
    Ok(())
}
