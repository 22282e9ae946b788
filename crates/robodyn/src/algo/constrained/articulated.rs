//! The constraint-space inverse inertia and the constraint forces' effect from the articulated-body
//! algorithm's own terms: constrained forward dynamics and impulses without forming M.
//!
//! Reference: Featherstone, *Rigid Body Dynamics Algorithms* (2008), Table 7.1 and §8.3 (the
//! constraint forces through the inverse inertia). With q̇ = 0 and no gravity, ABA's inward pass
//! on a generalised force τ alone gives, for each body from the leaves,
//! ```text
//!   u_i = τ_i − S_iᵀ p_i,      p_λ(i) += X_iᵀ (p_i + U_i D_i⁻¹ u_i)
//! ```
//! (p: the force the subtree passes on), and its outward pass gives M⁻¹ τ from those u_i:
//! `q̈_i = D_i⁻¹ (u_i − U_iᵀ X_i a_λ(i))`, `a_i = X_i a_λ(i) + S_i q̈_i`. The u_i are K τ for a
//! matrix K with `τᵀ M⁻¹ τ = Σ_i u_iᵀ D_i⁻¹ u_i` (q̈ read against τ, body by body), so
//! `M⁻¹ = Kᵀ D⁻¹ K`. With Y = K Jᵀ (each row of J taken as a generalised force):
//! ```text
//!   Λ⁻¹ = J M⁻¹ Jᵀ = Σ_i Y_iᵀ D_i⁻¹ Y_i,      M⁻¹ Jᵀ λ = outward pass from u_i = Y_i λ
//! ```
//! A row's inward pass runs only over the ancestors of its bodies (its support), where its J is
//! not zero; the other u_i are zero. Cost: ABA, then O(d) per row (d: the bodies its support
//! holds), O(m² d) for Λ⁻¹ and one outward pass. The rows themselves take ABA's placements,
//! velocities and velocity products along their support.

use super::ConstraintData;
use crate::algo::aba::aba;
use crate::constraint::{evaluate, BodyMotion, ConstraintRows, ConstraintSet};
use crate::error::Result;
use crate::joint::ArticulatedTerms;
use crate::model::Model;
use crate::spatial::{Force, Motion};
use crate::Data;
use nalgebra::{DVectorViewMut, Vector6};

/// The free acceleration `a_f = M⁻¹ (τ − h)` by ABA into `data.qdd` (its articulated terms kept
/// in `data`), the placements `data.x_world` of the bodies the rows reach, then J, φ, the drift
/// γ = J̇ q̇ and, in `constraints.rhs`, the rows' acceleration `J a_f + γ` under a_f.
pub(super) fn free_motion_rows(
    model: &Model,
    data: &mut Data,
    constraints: &mut ConstraintData,
    set: &ConstraintSet,
    (q, v, tau): (&[f64], &[f64], &[f64]),
    f_ext: Option<&[Force]>,
) -> Result<()> {
    aba(model, data, q, v, tau, f_ext)?;

    // along the bodies the rows reach: X_{i←0} = X_{i←λ(i)} X_{λ(i)←0}, and the accelerations
    // with q̈ = 0 (no gravity) from ABA's velocity products, a_i = X_i a_λ(i) + c_i
    let accelerations = &mut constraints.body_accelerations;
    accelerations[0] = Motion::ZERO;
    for &i in set.support() {
        let (parent, turn) = (model.parent[i], model.turn(i));
        data.x_world[i] = data.x_up[i].compose_turned(turn, &data.x_world[parent]);
        accelerations[i] =
            data.x_up[i].apply_motion_turned(turn, &accelerations[parent]) + data.c[i];
    }

    // J, γ, φ;  then J a_f + γ
    let bodies = BodyMotion {
        x_world: &data.x_world,
        v: &data.v,
        a: accelerations,
    };
    let rows = ConstraintRows {
        jacobian: &mut constraints.jacobian,
        drift: constraints.drift.as_mut_slice(),
        error: constraints.error.as_mut_slice(),
    };
    evaluate(model, set, &bodies, (q, v), rows);
    let m = set.rows();
    let mut rows_acceleration = DVectorViewMut::from_slice(&mut constraints.rhs[..m], m);
    rows_acceleration.copy_from(&constraints.drift);
    rows_acceleration.gemv(1.0, &constraints.jacobian, &data.qdd, 1.0);
    Ok(())
}

/// Y = K Jᵀ (`constraints.transmitted_rows`, m × nv: row r holds the u_i of J's row r) by each
/// row's inward pass over its constraint's support, then `Λ⁻¹ = Σ_i Y_iᵀ D_i⁻¹ Y_i` into
/// `constraints.delassus`. Needs ABA's terms in `data` and J ([`free_motion_rows`]).
pub(super) fn articulated_delassus(
    model: &Model,
    data: &Data,
    constraints: &mut ConstraintData,
    set: &ConstraintSet,
) {
    transmit_rows(model, data, constraints, set);
    delassus_from_transmitted(model, data, constraints, set);
}

/// Y = K Jᵀ into `constraints.transmitted_rows`: each row's inward pass over its constraint's
/// support.
fn transmit_rows(
    model: &Model,
    data: &Data,
    constraints: &mut ConstraintData,
    set: &ConstraintSet,
) {
    let m = set.rows();
    let ConstraintData {
        jacobian,
        transmitted_rows,
        body_forces: p,
        ..
    } = constraints;
    // column-major m × nv: entry (r, k) at k m + r
    let (j, y) = (jacobian.as_slice(), transmitted_rows.as_mut_slice());
    y.fill(0.0);
    for (k, constraint) in set.constraints().iter().enumerate() {
        // each body once, all the constraint's rows (at most 6) through it
        let rows = set.offset(k)..set.offset(k) + constraint.rows();
        for &i in set.support_of(k) {
            let (dofs, subspace, parent) = (model.v_range(i), model.subspace(i), model.parent[i]);
            for (t, r) in rows.clone().enumerate() {
                // u_i = J_ri − S_iᵀ p_i
                let mut u = [0.0; 6];
                for (u_k, dof) in u.iter_mut().zip(dofs.clone()) {
                    *u_k = j[dof * m + r];
                }
                let mut p_i = std::mem::replace(&mut p[i][t], Force::ZERO);
                subspace.subtract_projection(&p_i, &mut u);
                for (u_k, dof) in u.iter().zip(dofs.clone()) {
                    y[dof * m + r] = *u_k;
                }
                // p_λ(i) += X_iᵀ (p_i + U_i D_i⁻¹ u_i)
                if parent != 0 {
                    subspace.add_bias_response(&mut p_i, &data.u[i], &data.d_inv[i], &u);
                    p[parent][t] += data.x_up[i].transpose_apply_force_turned(model.turn(i), &p_i);
                }
            }
        }
    }
}

/// `Λ⁻¹ = Σ_i Y_iᵀ D_i⁻¹ Y_i` into `constraints.delassus`, from [`transmit_rows`]' Y.
fn delassus_from_transmitted(
    model: &Model,
    data: &Data,
    constraints: &mut ConstraintData,
    set: &ConstraintSet,
) {
    let m = set.rows();
    let ConstraintData {
        transmitted_rows,
        delassus,
        body_rows,
        ..
    } = constraints;
    let y = transmitted_rows.as_slice();
    // Λ⁻¹ += Y_iᵀ D_i⁻¹ Y_i on the rows whose constraints reach body i, upper triangle; then the
    // lower one mirrored
    let lambda = delassus.as_mut_slice();
    lambda.fill(0.0);
    for (&i, span) in set.support().iter().zip(set.row_spans()) {
        let dofs = model.v_range(i);
        let (d_inv, columns) = (&data.d_inv[i], &y[dofs.start * m..dofs.end * m]);
        if dofs.len() == 1 {
            // one coordinate: Λ⁻¹_rc += y_r y_c / D_i
            let y_i = &columns[..m];
            for c in span.clone() {
                let w_c = d_inv[(0, 0)] * y_i[c];
                let column = &mut lambda[c * m + span.start..=c * m + c];
                for (entry, y_r) in column.iter_mut().zip(&y_i[span.start..=c]) {
                    *entry += y_r * w_c;
                }
            }
            continue;
        }
        // several: each row's y_r (body i's columns of row r) and w_r = D_i⁻¹ y_r as 6-vectors
        // (zero past the joint's coordinates), then Λ⁻¹_rc += y_r · w_c
        for r in span.clone() {
            let mut y_r = Vector6::zeros();
            for (a, y_ra) in y_r.iter_mut().take(dofs.len()).enumerate() {
                *y_ra = columns[a * m + r];
            }
            let w_r = if dofs.len() == 6 {
                d_inv * y_r
            } else {
                let mut w_r = Vector6::zeros();
                for (a, w_ra) in w_r.iter_mut().take(dofs.len()).enumerate() {
                    *w_ra = (0..dofs.len()).map(|b| d_inv[(a, b)] * y_r[b]).sum();
                }
                w_r
            };
            body_rows[r] = (y_r, w_r);
        }
        for c in span.clone() {
            let w_c = &body_rows[c].1;
            for r in span.start..=c {
                lambda[c * m + r] += body_rows[r].0.dot(w_c);
            }
        }
    }
    for c in 0..m {
        for r in c + 1..m {
            lambda[c * m + r] = lambda[r * m + c];
        }
    }
}

/// `M⁻¹ Jᵀ λ` (λ in `constraints.forces`) into `out` (nv) by ABA's outward pass from
/// `u_i = Y_i λ` ([`articulated_delassus`]'s Y), with ABA's terms in `data`.
pub(super) fn constraint_response(
    model: &Model,
    data: &mut Data,
    constraints: &mut ConstraintData,
    out: &mut [f64],
) {
    let ConstraintData {
        transmitted_rows: y,
        forces,
        joint_forces: u,
        body_accelerations: a,
        ..
    } = constraints;
    // u = Yᵀ λ
    u.gemv_tr(1.0, y, forces, 0.0);
    a[0] = Motion::ZERO;
    for i in 1..model.nbodies() {
        // a'_i = X_i a_λ(i);  q̈_i = D_i⁻¹ (u_i − U_iᵀ a'_i);  a_i = a'_i + S_i q̈_i
        let mut a_i = data.x_up[i].apply_motion_turned(model.turn(i), &a[model.parent[i]]);
        let mut u_i = [0.0; 6];
        for (u_k, dof) in u_i.iter_mut().zip(model.v_range(i)) {
            *u_k = u[dof];
        }
        let terms = ArticulatedTerms {
            u: &mut data.u[i],
            u_tau: &mut u_i,
            d_inv: &mut data.d_inv[i],
        };
        model.subspace(i).accelerate(&mut a_i, &terms, out);
        a[i] = a_i;
    }
}
