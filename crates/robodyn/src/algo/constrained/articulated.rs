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
//! not zero; the other u_i are zero. ABA is linear in its u_i: its outward pass from
//! `u_i + Y_i λ` gives `M⁻¹ (τ − h + Jᵀ λ)` at once, so forward dynamics runs that pass once,
//! after λ, and before it only along the support, where `J a_f` needs a_f. Cost: ABA, then O(d)
//! per row (d: the bodies its support holds), O(m² d) for Λ⁻¹. The rows themselves take ABA's
//! placements, velocities and velocity products along their support. Every step is generic over
//! [`Real`]: one state in `f64`, or several in lanes ([`crate::algo::lanes`]).

use super::ConstraintData;
use crate::algo::aba::{
    acceleration_pass, articulated_inertia_passes, check_dynamics_inputs, singular_joint,
    AbaBuffers, OutwardTerms,
};
use crate::constraint::{evaluate, BodyMotion, ConstraintRows, ConstraintSet};
use crate::error::Result;
use crate::model::Model;
use crate::spatial::{Force, Motion, Real, Transform};
use crate::Data;
use nalgebra::{DMatrix, Matrix6, Vector6};
use std::ops::Range;

/// ABA's terms that the route reads (one state's from [`Data`], or lanes'), and the placements
/// `X_{i←0}` it writes along the rows' support.
pub(crate) struct AbaTerms<'b, S> {
    pub x_up: &'b [Transform<S>],
    pub v: &'b [Motion<S>],
    pub c: &'b [Motion<S>],
    pub u: &'b [[Force<S>; 6]],
    pub u_tau: &'b [[S; 6]],
    pub d_inv: &'b [Matrix6<S>],
    pub x_world: &'b mut [Transform<S>],
    /// a_f = M⁻¹ (τ − h), ABA's q̈, on the coordinates of the rows' support (zero on the others).
    pub free_acceleration: &'b [S],
}

impl<'b> AbaTerms<'b, f64> {
    /// `data`'s.
    pub(crate) fn of(data: &'b mut Data) -> Self {
        AbaTerms {
            x_up: &data.x_up,
            v: &data.v,
            c: &data.c,
            u: &data.u,
            u_tau: &data.u_tau,
            d_inv: &data.d_inv,
            x_world: &mut data.x_world,
            free_acceleration: data.qdd.as_slice(),
        }
    }
}

impl<S> AbaTerms<'_, S> {
    /// What ABA's outward pass reads.
    fn outward(&self) -> OutwardTerms<'_, S> {
        OutwardTerms {
            x_up: self.x_up,
            c: self.c,
            u: self.u,
            u_tau: self.u_tau,
            d_inv: self.d_inv,
        }
    }
}

/// The route's rows, workspace and results (one state's from [`ConstraintData`], or lanes').
pub(crate) struct RouteBuffers<'b, S> {
    /// J (m × nv), γ, φ and, after [`free_motion_rows`], `J a_f + γ` in `rhs`.
    pub jacobian: &'b mut DMatrix<S>,
    pub drift: &'b mut [S],
    pub error: &'b mut [S],
    pub rhs: &'b mut [S],
    /// Y = K Jᵀ as rows (m × nv), and Λ⁻¹ (m × m).
    pub transmitted_rows: &'b mut DMatrix<S>,
    pub delassus: &'b mut DMatrix<S>,
    /// The forces the inward passes carry (zero between uses), the bodies' accelerations, Yᵀ λ.
    pub body_forces: &'b mut [[Force<S>; 6]],
    pub body_accelerations: &'b mut [Motion<S>],
    pub joint_forces: &'b mut [S],
    /// One body's columns of Y, row by row, and D_i⁻¹ times them.
    pub body_rows: &'b mut [(Vector6<S>, Vector6<S>)],
    /// λ (m).
    pub forces: &'b mut [S],
    /// The result (nv): q̈, or q̇ after an impact.
    pub qdd: &'b mut [S],
}

impl<'b> RouteBuffers<'b, f64> {
    /// `constraints`'.
    pub(crate) fn of(constraints: &'b mut ConstraintData) -> Self {
        RouteBuffers {
            jacobian: &mut constraints.jacobian,
            drift: constraints.drift.as_mut_slice(),
            error: constraints.error.as_mut_slice(),
            rhs: &mut constraints.rhs,
            transmitted_rows: &mut constraints.transmitted_rows,
            delassus: &mut constraints.delassus,
            body_forces: &mut constraints.body_forces,
            body_accelerations: &mut constraints.body_accelerations,
            joint_forces: constraints.joint_forces.as_mut_slice(),
            body_rows: &mut constraints.body_rows,
            forces: constraints.forces.as_mut_slice(),
            qdd: constraints.qdd.as_mut_slice(),
        }
    }
}

/// ABA's passes 1 and 2 at (q, q̇, τ, f_ext) into `data` (checked as [`crate::algo::aba()`]
/// checks them), the free acceleration `a_f = M⁻¹ (τ − h)` along the rows' support
/// ([`support_acceleration_pass`]), then [`rows_under_free_motion`].
#[inline(always)]
pub(super) fn free_motion_rows(
    model: &Model,
    data: &mut Data,
    constraints: &mut ConstraintData,
    set: &ConstraintSet,
    (q, v, tau): (&[f64], &[f64], &[f64]),
    f_ext: Option<&[Force]>,
) -> Result<()> {
    check_dynamics_inputs(model, (q, v, tau), f_ext)?;
    let mut buffers = AbaBuffers::of(data);
    articulated_inertia_passes(model, (q, v, tau), f_ext, &mut buffers)
        .map_err(|joint| singular_joint(model, joint))?;
    support_acceleration_pass(model, set, &mut buffers);
    let mut route = RouteBuffers::of(constraints);
    rows_under_free_motion(model, set, &mut AbaTerms::of(data), &mut route, (q, v));
    Ok(())
}

/// ABA's outward pass along the rows' support only: a_f on its bodies' coordinates, zero on the
/// others' (J's columns there are zero).
#[inline(always)]
pub(crate) fn support_acceleration_pass<S: Real>(
    model: &Model,
    set: &ConstraintSet,
    buffers: &mut AbaBuffers<S>,
) {
    let (terms, (a, qdd)) = buffers.outward();
    qdd.fill(S::zero());
    acceleration_pass(model, set.support().iter().copied(), &terms, None, (a, qdd));
}

/// From ABA's terms: the placements `X_{i←0}` of the bodies the rows reach, then J, φ, the
/// drift γ = J̇ q̇ and, in `rhs`, the rows' acceleration `J a_f + γ` under a_f.
#[inline(always)]
pub(crate) fn rows_under_free_motion<S: Real>(
    model: &Model,
    set: &ConstraintSet,
    terms: &mut AbaTerms<S>,
    route: &mut RouteBuffers<S>,
    (q, v): (&[S], &[S]),
) {
    // along the bodies the rows reach: X_{i←0} = X_{i←λ(i)} X_{λ(i)←0}, and the accelerations
    // with q̈ = 0 (no gravity) from ABA's velocity products, a_i = X_i a_λ(i) + c_i
    let accelerations = &mut *route.body_accelerations;
    accelerations[0] = Motion::zeros();
    for &i in set.support() {
        let (parent, turn) = (model.parent[i], model.turn(i));
        terms.x_world[i] = terms.x_up[i].compose_turned(turn, &terms.x_world[parent]);
        accelerations[i] =
            terms.x_up[i].apply_motion_turned(turn, &accelerations[parent]) + terms.c[i];
    }

    // J, γ, φ;  then J a_f + γ
    let bodies = BodyMotion {
        x_world: terms.x_world,
        v: terms.v,
        a: accelerations,
    };
    let rows = ConstraintRows {
        jacobian: route.jacobian,
        drift: route.drift,
        error: route.error,
    };
    evaluate(model, set, &bodies, (q, v), rows);
    let m = set.rows();
    let rows_acceleration = &mut route.rhs[..m];
    rows_acceleration.copy_from_slice(route.drift);
    let j = route.jacobian.as_slice();
    for c in set.support().iter().flat_map(|&i| model.v_range(i)) {
        let a_c = terms.free_acceleration[c];
        for (entry, j_rc) in rows_acceleration.iter_mut().zip(&j[c * m..(c + 1) * m]) {
            *entry += *j_rc * a_c;
        }
    }
}

/// Y = K Jᵀ (`transmitted_rows`, m × nv: row r holds the u_i of J's row r) by each row's inward
/// pass over its constraint's support, then `Λ⁻¹ = Σ_i Y_iᵀ D_i⁻¹ Y_i` into `delassus`. Needs
/// ABA's terms and J ([`rows_under_free_motion`]).
#[inline(always)]
pub(crate) fn articulated_delassus<S: Real>(
    model: &Model,
    set: &ConstraintSet,
    terms: &AbaTerms<S>,
    route: &mut RouteBuffers<S>,
) {
    transmit_rows(model, set, terms, route);
    delassus_from_transmitted(model, set, terms, route);
}

/// Y = K Jᵀ into `transmitted_rows`: each row's inward pass over its constraint's support.
#[inline(always)]
fn transmit_rows<S: Real>(
    model: &Model,
    set: &ConstraintSet,
    terms: &AbaTerms<S>,
    route: &mut RouteBuffers<S>,
) {
    let m = set.rows();
    let p = &mut *route.body_forces;
    // column-major m × nv: entry (r, k) at k m + r
    let (j, y) = (
        route.jacobian.as_slice(),
        route.transmitted_rows.as_mut_slice(),
    );
    y.fill(S::zero());
    let zero = Force::splat(&Force::ZERO);
    for (k, constraint) in set.constraints().iter().enumerate() {
        // each body once, all the constraint's rows (at most 6) through it
        let rows = set.offset(k)..set.offset(k) + constraint.rows();
        for &i in set.support_of(k) {
            let parent = model.parent[i];
            let (toward_root, from_i) = p.split_at_mut(i);
            let carried = &mut from_i[0][..rows.len()];
            // u_i = J_ri − S_iᵀ p_i into Y;  p_i + U_i D_i⁻¹ u_i where there is a parent
            let rows = (j, &mut *y, m, rows.clone());
            let own = (&terms.u[i], &terms.d_inv[i]);
            model
                .subspace(i)
                .transmit_rows(carried, rows, own, parent != 0);
            // p_λ(i) += X_iᵀ (p_i + U_i D_i⁻¹ u_i), and p_i back to zero for the next rows
            if parent != 0 {
                terms.x_up[i].transpose_apply_forces_turned(model.turn(i), carried);
                for (sum, p_i) in toward_root[parent].iter_mut().zip(carried.iter_mut()) {
                    *sum += std::mem::replace(p_i, zero);
                }
            } else {
                carried.iter_mut().for_each(|p_i| *p_i = zero);
            }
        }
    }
}

/// `Λ⁻¹ = Σ_i Y_iᵀ D_i⁻¹ Y_i` into `delassus`, from [`transmit_rows`]' Y.
#[inline(always)]
fn delassus_from_transmitted<S: Real>(
    model: &Model,
    set: &ConstraintSet,
    terms: &AbaTerms<S>,
    route: &mut RouteBuffers<S>,
) {
    let m = set.rows();
    let (y, body_rows) = (route.transmitted_rows.as_slice(), &mut *route.body_rows);
    // Λ⁻¹ += Y_iᵀ D_i⁻¹ Y_i on the rows whose constraints reach body i, upper triangle; then the
    // lower one mirrored
    let lambda = route.delassus.as_mut_slice();
    lambda.fill(S::zero());
    for (&i, span) in set.support().iter().zip(set.row_spans()) {
        let dofs = model.v_range(i);
        let (d_inv, columns) = (&terms.d_inv[i], &y[dofs.start * m..dofs.end * m]);
        let body = (d_inv, columns, m, span.clone());
        // the joint's number of coordinates as a constant, so that its loops unroll
        match dofs.len() {
            1 => add_body_delassus::<S, 1>(lambda, body_rows, body),
            2 => add_body_delassus::<S, 2>(lambda, body_rows, body),
            3 => add_body_delassus::<S, 3>(lambda, body_rows, body),
            6 => add_body_delassus::<S, 6>(lambda, body_rows, body),
            _ => add_body_delassus_of(dofs.len(), lambda, body_rows, body),
        }
    }
    for c in 0..m {
        for r in c + 1..m {
            lambda[c * m + r] = lambda[r * m + c];
        }
    }
}

/// One body's term of [`delassus_from_transmitted`], for a joint of N coordinates:
/// `Λ⁻¹_rc += y_r · D_i⁻¹ y_c` for the rows r ≤ c of `span`, y_r the body's N entries of Y's row
/// r (Y's columns of the body in `columns`, m each).
#[inline(always)]
fn add_body_delassus<S: Real, const N: usize>(
    lambda: &mut [S],
    body_rows: &mut [(Vector6<S>, Vector6<S>)],
    body: (&Matrix6<S>, &[S], usize, Range<usize>),
) {
    add_body_delassus_of(N, lambda, body_rows, body);
}

/// [`add_body_delassus`] for `n` coordinates.
#[inline(always)]
fn add_body_delassus_of<S: Real>(
    n: usize,
    lambda: &mut [S],
    body_rows: &mut [(Vector6<S>, Vector6<S>)],
    (d_inv, columns, m, span): (&Matrix6<S>, &[S], usize, Range<usize>),
) {
    if n == 1 {
        // one coordinate: Λ⁻¹_rc += y_r y_c / D_i
        for c in span.clone() {
            let w_c = d_inv[(0, 0)] * columns[c];
            let column = &mut lambda[c * m + span.start..=c * m + c];
            for (entry, y_r) in column.iter_mut().zip(&columns[span.start..=c]) {
                *entry += *y_r * w_c;
            }
        }
        return;
    }
    // y_r and w_r = D_i⁻¹ y_r as 6-vectors (zero past the joint's coordinates)
    for r in span.clone() {
        let mut y_r = Vector6::zeros();
        for a in 0..n {
            y_r[a] = columns[a * m + r];
        }
        let mut w_r = Vector6::zeros();
        for a in 0..n {
            let mut sum = S::zero();
            for b in 0..n {
                sum += d_inv[(a, b)] * y_r[b];
            }
            w_r[a] = sum;
        }
        body_rows[r] = (y_r, w_r);
    }
    for c in span.clone() {
        let w_c = &body_rows[c].1;
        for r in span.start..=c {
            let y_r = &body_rows[r].0;
            let mut sum = S::zero();
            for a in 0..n {
                sum += y_r[a] * w_c[a];
            }
            lambda[c * m + r] += sum;
        }
    }
}

/// `q̈ = M⁻¹ (τ − h + Jᵀ λ)` (λ in `forces`) into `qdd`: ABA's outward pass from `u_i + Y_i λ`
/// ([`articulated_delassus`]'s Y), with ABA's terms. The bodies' accelerations are left in
/// `body_accelerations`.
#[inline(always)]
pub(crate) fn constrained_accelerations<S: Real>(
    model: &Model,
    set: &ConstraintSet,
    terms: &AbaTerms<S>,
    route: &mut RouteBuffers<S>,
) {
    transmit_forces(set, route);
    let (a, qdd) = (&mut *route.body_accelerations, &mut *route.qdd);
    let transmitted = Some(&*route.joint_forces);
    acceleration_pass(
        model,
        1..model.nbodies(),
        &terms.outward(),
        transmitted,
        (a, qdd),
    );
}

/// `base + M⁻¹ Jᵀ λ` (λ in `forces`; base: q̇ before an impact) into `qdd` by ABA's outward pass
/// from `u_i = Y_i λ` ([`articulated_delassus`]'s Y) alone (q̇ = 0, no gravity), with ABA's
/// terms.
#[inline(always)]
pub(crate) fn constraint_response<S: Real>(
    model: &Model,
    set: &ConstraintSet,
    terms: &AbaTerms<S>,
    route: &mut RouteBuffers<S>,
    base: &[S],
) {
    transmit_forces(set, route);
    let (u, a) = (&*route.joint_forces, &mut *route.body_accelerations);
    a[0] = Motion::zeros();
    for i in 1..model.nbodies() {
        // a'_i = X_i a_λ(i);  q̈_i = D_i⁻¹ (u_i − U_iᵀ a'_i);  a_i = a'_i + S_i q̈_i
        let mut a_i = terms.x_up[i].apply_motion_turned(model.turn(i), &a[model.parent[i]]);
        let mut u_i = [S::zero(); 6];
        for (u_k, dof) in u_i.iter_mut().zip(model.v_range(i)) {
            *u_k = u[dof];
        }
        let own = (&terms.u[i], &u_i, &terms.d_inv[i]);
        model.subspace(i).accelerate(&mut a_i, own, route.qdd);
        a[i] = a_i;
    }
    for (x, b) in route.qdd.iter_mut().zip(base) {
        *x += *b;
    }
}

/// The u_i that ABA's inward pass makes of the constraint forces, `Yᵀ λ` (λ in `forces`), into
/// `joint_forces`.
#[inline(always)]
fn transmit_forces<S: Real>(set: &ConstraintSet, route: &mut RouteBuffers<S>) {
    let m = set.rows();
    let y = route.transmitted_rows.as_slice();
    for (k, u_k) in route.joint_forces.iter_mut().enumerate() {
        let mut sum = S::zero();
        for (y_rk, lambda_r) in y[k * m..(k + 1) * m].iter().zip(&route.forces[..m]) {
            sum += *y_rk * *lambda_r;
        }
        *u_k = sum;
    }
}
