//! The mass matrix and the gravity vector the way the lecture notes build them, next to the
//! recursive algorithms (CRBA, RNEA) that compute the same quantities faster.
//!
//! - M from n RNEA calls (the UR5 dynamics notes, "Compute M numerically"): column k of M is the torque that
//!   produces the unit acceleration e_k at rest without gravity, τ(q, 0, e_k) − g(q).
//!   Cost n RNEA passes, O(n²).
//! - M from the bodies' Jacobians (the TU Berlin notes "Mass Matrix", the UR5 dynamics notes "TMT method"):
//!   M = Σ_i m_i J_vᵢᵀ J_vᵢ + J_ωᵢᵀ ⁰I_i J_ωᵢ, with J_vᵢ the Jacobian of body i's centre of mass and
//!   J_ωᵢ of its angular velocity, both in world axes, and ⁰I_i its inertia about its centre of mass
//!   in world axes. Rotor inertia (armature) is added on the diagonal, as M has it. Cost O(N d²).
//! - g from the same Jacobians (the TU Berlin notes "Gravity"): g(q) = −Σ_i J_vᵢᵀ m_i g₀, g₀ the gravity
//!   vector. Cost O(N d).
//!
//! Column of J for velocity coordinate b supporting body i: from the world-frame subspace column
//! ⁰S_b = (ω_b, v_b) (the velocity of the point at the world origin), J_ω = ω_b and the velocity of
//! the centre of mass c_i, J_v = v_b + ω_b × c_i.
//!
//! Writes `data.x_up`, `data.x_world`, `data.i_c` (each body's own inertia, world coordinates),
//! `data.s_world`; then `data.mass_matrix` or `data.tau` (M by RNEA also writes RNEA's fields and
//! `data.gravity`).

use crate::algo::crba::world_inertias_and_subspaces;
use crate::algo::rnea::newton_euler;
use crate::error::Result;
use crate::model::Model;
use crate::spatial::{Mat3, Motion, Vec3};
use crate::Data;
use nalgebra::{DMatrix, DVector};

/// M(q) column by column from RNEA: M e_k = τ(q, 0, e_k) − g(q).
pub fn mass_matrix_by_rnea<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
) -> Result<&'d DMatrix<f64>> {
    newton_euler(model, data, q, None, None, None)?;
    data.gravity.copy_from(&data.tau);
    let mut unit = std::mem::take(&mut data.unit_velocity);
    let mut outcome = Ok(());
    for k in 0..model.nv {
        unit[k] = 1.0;
        outcome = newton_euler(model, data, q, None, Some(unit.as_slice()), None).map(|_| ());
        unit[k] = 0.0;
        if outcome.is_err() {
            break;
        }
        // M e_k = τ(q, 0, e_k) − g(q)
        for row in 0..model.nv {
            data.mass_matrix[(row, k)] = data.tau[row] - data.gravity[row];
        }
    }
    data.unit_velocity = unit;
    outcome.map(|_| &data.mass_matrix)
}

/// The Jacobian columns of body i's centre-of-mass velocity and angular velocity for the subspace
/// column `s` (world coordinates): (J_v, J_ω) = (v + ω × c, ω).
fn point_columns(s: &Motion, com: &Vec3) -> (Vec3, Vec3) {
    (s.linear + s.angular.cross(com), s.angular)
}

/// M(q) = Σ_i m_i J_vᵢᵀ J_vᵢ + J_ωᵢᵀ ⁰I_i J_ωᵢ (+ armature on the diagonal).
pub fn mass_matrix_by_jacobians<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
) -> Result<&'d DMatrix<f64>> {
    model.check_configuration(q)?;
    world_inertias_and_subspaces(model, data, q);
    data.mass_matrix.as_mut_slice().fill(0.0);
    for i in 1..model.nbodies() {
        let body = &data.i_c[i];
        let com = body.com();
        // ⁰I_i about the centre of mass: Ī_O − m (c·c 1 − c cᵀ)
        let inertia_com = body.rotational
            - (Mat3::identity() * com.dot(&com) - com * com.transpose()) * body.mass;
        // every pair (a, b) of velocity coordinates supporting body i
        let mut j = i;
        while j != 0 {
            for a in model.v_range(j) {
                let (jv_a, jw_a) = point_columns(&data.s_world[a], &com);
                let mut k = i;
                while k != 0 {
                    for b in model.v_range(k) {
                        let (jv_b, jw_b) = point_columns(&data.s_world[b], &com);
                        // m J_vaᵀ J_vb + J_ωaᵀ I J_ωb
                        data.mass_matrix[(a, b)] +=
                            body.mass * jv_a.dot(&jv_b) + jw_a.dot(&(inertia_com * jw_b));
                    }
                    k = model.parent[k];
                }
            }
            j = model.parent[j];
        }
    }
    for dof in 0..model.nv {
        data.mass_matrix[(dof, dof)] += model.armature[dof];
    }
    Ok(&data.mass_matrix)
}

/// g(q) = −Σ_i J_vᵢᵀ m_i g₀, written into `data.tau`.
pub fn generalized_gravity_by_jacobians<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
) -> Result<&'d DVector<f64>> {
    model.check_configuration(q)?;
    world_inertias_and_subspaces(model, data, q);
    data.tau.fill(0.0);
    for i in 1..model.nbodies() {
        let (mass, com) = (data.i_c[i].mass, data.i_c[i].com());
        let mut j = i;
        while j != 0 {
            for b in model.v_range(j) {
                // −J_vbᵀ m_i g₀
                let (jv_b, _) = point_columns(&data.s_world[b], &com);
                data.tau[b] -= mass * jv_b.dot(&model.gravity);
            }
            j = model.parent[j];
        }
    }
    Ok(&data.tau)
}
