//! The Coriolis matrix C(q, q̇) of M(q) q̈ + C(q, q̇) q̇ + g(q) = τ, the one built from the
//! Christoffel symbols of the first kind, C_ij = Σ_k Γ_ijk q̇_k with
//! Γ_ijk = ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i) (the TU Berlin notes, "Coriolis and centrifugal terms"),
//! so that C q̇ is the velocity-product part of the bias forces and Ṁ − 2C is skew-symmetric.
//!
//! Reference: S. Echeandia and P. M. Wensing, "Numerical Methods to Compute the Coriolis Matrix
//! and Christoffel Symbols for Rigid-Body Systems", J. Comput. Nonlinear Dynam. 16(9), 2021:
//! with ⁰J_k the spatial Jacobian of body k (its columns are the world-frame subspace columns ⁰S
//! of the joints supporting k) and ⁰I_k its world-frame inertia,
//!   C = Σ_k J_kᵀ (I_k J̇_k + B_k J_k),   B_k = B(I_k, v_k) = ½[(v_k×*) I_k + (I_k v_k)×̄ − I_k (v_k×)]
//! and, grouping the bodies into composites (I^C_i, B^C_i: sums over the subtree of body i), for
//! a velocity coordinate a of body i and b of body j on the path from i to the root:
//!   C[b, a] = S_bᵀ (I^C_i Ṡ_a + B^C_i S_a)
//!   C[a, b] = Ṡ_bᵀ (I^C_i S_a) + S_bᵀ (B^C_iᵀ S_a)        (j ≠ i)
//! where Ṡ = v_i × S is the rate of a world-frame subspace column (Featherstone eq. 2.42).
//! Cost O(n·d), d the depth of the tree: O(n²) for a chain, no RNEA calls.
//! B is kept as H = 2B in the factored form of `CoriolisFactor` (no 6x6 products).
//! Input: q (nq), q̇ (nv). Writes `data.x_up`, `data.x_world`, `data.i_c`, `data.s_world`,
//! `data.v_world`, `data.s_dot_world`, `data.coriolis_factors`, `data.coriolis` (nv x nv).

use crate::algo::crba::{add_composite_inertias, world_inertias_and_subspaces};
use crate::error::{check_length, check_vector, Result};
use crate::model::Model;
use crate::spatial::CoriolisFactor;
use crate::Data;
use nalgebra::DMatrix;

/// C(q, q̇), written into `data.coriolis`.
pub fn coriolis_matrix<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
) -> Result<&'d DMatrix<f64>> {
    model.check_configuration(q)?;
    check_vector("v", v, model.nv)?;
    fill_coriolis_matrix(model, data, q, v);
    Ok(&data.coriolis)
}

/// `coriolis_matrix` on inputs already checked.
fn fill_coriolis_matrix(model: &Model, data: &mut Data, q: &[f64], v: &[f64]) {
    world_inertias_and_subspaces(model, data, q);

    // outward: v_i = v_λ(i) + S_i q̇_i, Ṡ_i = v_i × S_i, and each body's H = 2B(I_i, v_i)
    for i in 1..model.nbodies() {
        let mut velocity = data.v_world[model.parent[i]];
        for dof in model.v_range(i) {
            velocity += data.s_world[dof] * v[dof];
        }
        data.v_world[i] = velocity;
        for dof in model.v_range(i) {
            data.s_dot_world[dof] = velocity.cross_motion(&data.s_world[dof]);
        }
        data.coriolis_factors[i] = CoriolisFactor::new(&data.i_c[i], &velocity);
    }

    // composites, leaves to root: I^C_λ(i) += I^C_i, H^C_λ(i) += H^C_i
    add_composite_inertias(model, data);
    for i in (1..model.nbodies()).rev() {
        let parent = model.parent[i];
        if parent != 0 {
            let subtree = data.coriolis_factors[i];
            data.coriolis_factors[parent] += subtree;
        }
    }

    // the entries, one column of body i against every velocity coordinate on its path to the root
    let nv = model.nv;
    let coriolis = data.coriolis.as_mut_slice();
    coriolis.fill(0.0);
    for i in 1..model.nbodies() {
        let (composite, h_composite) = (&data.i_c[i], &data.coriolis_factors[i]);
        for a in model.v_range(i) {
            let (s_a, s_dot_a) = (data.s_world[a], data.s_dot_world[a]);
            // f1 = I^C_i Ṡ_a + B^C_i S_a, f2 = I^C_i S_a, f3 = B^C_iᵀ S_a, with B = H / 2
            let f1 = composite.mul_motion(&s_dot_a) + h_composite.mul_motion(&s_a) * 0.5;
            let f2 = composite.mul_motion(&s_a);
            let f3 = h_composite.tr_mul_motion(&s_a) * 0.5;
            let mut j = i;
            while j != 0 {
                for b in model.v_range(j) {
                    let (s_b, s_dot_b) = (data.s_world[b], data.s_dot_world[b]);
                    // column-major storage: C[b, a] at b + a nv
                    coriolis[b + a * nv] = s_b.dot(&f1);
                    if j != i {
                        coriolis[a + b * nv] = s_dot_b.dot(&f2) + s_b.dot(&f3);
                    }
                }
                j = model.parent[j];
            }
        }
    }

    // the rotors: armature K(q̇_i) on each joint's own block
    for i in 1..model.nbodies() {
        let dofs = model.v_range(i);
        let v_i = &v[dofs.clone()];
        for (r, row) in dofs.clone().enumerate() {
            for (c, column) in dofs.clone().enumerate() {
                coriolis[row + column * nv] +=
                    model.armature[row] * model.joints[i].rotor_velocity_term(r, c, v_i);
            }
        }
    }
}

/// The Christoffel symbols of the first kind, Γ_ijk = ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i),
/// written into `gamma` (nv³ entries, Γ_ijk at `(i nv + j) nv + k`, row-major i, j, k). C is
/// linear in q̇ with C_ij = Σ_k Γ_ijk q̇_k, so Γ_··k = C(q, e_k): n evaluations of the recursive
/// algorithm above, O(n³) for a chain, exact (no finite differences). With spherical or free
/// joints, whose velocities are not rates of coordinates, no coordinate formula exists; these
/// Γ_··k = C(q, e_k) still give C = Σ_k Γ_··k q̇_k.
/// Writes what `coriolis_matrix` writes, and `data.unit_velocity`.
pub fn christoffel_symbols(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    gamma: &mut [f64],
) -> Result<()> {
    let nv = model.nv;
    model.check_configuration(q)?;
    check_length("gamma", gamma.len(), nv * nv * nv)?;
    let mut unit = std::mem::take(&mut data.unit_velocity);
    for k in 0..nv {
        unit[k] = 1.0;
        fill_coriolis_matrix(model, data, q, unit.as_slice());
        unit[k] = 0.0;
        for i in 0..nv {
            for j in 0..nv {
                gamma[(i * nv + j) * nv + k] = data.coriolis[(i, j)];
            }
        }
    }
    data.unit_velocity = unit;
    Ok(())
}
