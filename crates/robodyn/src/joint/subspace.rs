//! A body's motion subspace `S_i` as the algorithms take it: the few products of Featherstone's
//! tables that involve `S` (Tables 5.1, 6.2 and 7.1), chosen once per body.
//!
//! Most joints have one coordinate along a coordinate axis (URDF and MJCF axes are mostly x, y or
//! z): `S = ±e_c`. Every product with `S` is then one component, `S q̇` adds to one component and
//! `D_i⁻¹` is one division. Leaving out products with `S`'s exact zeros and ones leaves every
//! value as the general products give it (x + 0·y = x, ±1·x = ±x), so both paths agree bit for
//! bit. Any other joint takes the general products, column by column, each column that is a
//! coordinate axis (every column of a spherical or free joint) read as one component.

use super::{inertia_column, Joint};
use crate::algo::crba::{MassColumns, SubtreeForces};
use crate::algo::SINGULARITY_TOLERANCE;
use crate::spatial::{signed, Force, Inertia, Motion, Real};
use nalgebra::Matrix6;
use std::ops::Range;

/// Body i's motion subspace (`Model::subspace`), from the joint and what the model derives from
/// it when it is built (`Model::unit_axis`, `Model::subspace_component`).
#[derive(Debug, Clone, Copy)]
pub(crate) enum MotionSubspace<'m> {
    /// One coordinate, `dof`, with `S = ±e_c` (c in [`Force::plucker`]'s order; `negative`: −).
    Axis {
        c: usize,
        negative: bool,
        dof: usize,
    },
    /// Any other joint: its `joint.nv()` coordinates from `first`, column k a coordinate axis
    /// where `components[k]` says so (asked of the joint where `components` is empty).
    Columns {
        joint: &'m Joint,
        first: usize,
        components: &'m [Option<(usize, bool)>],
    },
}

/// A joint's terms of the articulated-body algorithm (Table 7.1): `U_i = I^A_i S_i` (one force per
/// coordinate), `u_i = τ_i − S_iᵀ p^A_i` and `D_i⁻¹ = (S_iᵀ U_i)⁻¹` (its leading nv x nv block).
pub(crate) struct ArticulatedTerms<'b, S> {
    pub u: &'b mut [Force<S>; 6],
    pub u_tau: &'b mut [S; 6],
    pub d_inv: &'b mut Matrix6<S>,
}

impl MotionSubspace<'_> {
    /// The joint's velocity coordinates.
    #[inline(always)]
    fn dofs(&self) -> Range<usize> {
        match *self {
            MotionSubspace::Axis { dof, .. } => dof..dof + 1,
            MotionSubspace::Columns { joint, first, .. } => first..first + joint.nv(),
        }
    }

    /// Where column `k` of `S` is a coordinate axis: its component and sign.
    #[inline(always)]
    fn component(&self, k: usize) -> Option<(usize, bool)> {
        match *self {
            MotionSubspace::Axis { c, negative, .. } => Some((c, negative)),
            MotionSubspace::Columns {
                joint, components, ..
            } => match components.get(k) {
                Some(component) => *component,
                None => joint.subspace_component(k),
            },
        }
    }

    /// `m += S x_i`, for `x` a velocity-sized vector (q̈, say) and `x_i` the joint's slice.
    #[inline(always)]
    pub(crate) fn add_motion<S: Real>(&self, m: &mut Motion<S>, x: &[S]) {
        match *self {
            MotionSubspace::Axis { c, negative, dof } => {
                m.add_to_component(c, signed(x[dof], negative))
            }
            MotionSubspace::Columns { joint, .. } => *m += joint.motion(&x[self.dofs()]),
        }
    }

    /// `v += v_J` with `v_J = S q̇_i` (`rates` is q̇), returning `v × v_J`: the velocity product
    /// of the body's acceleration (`c_J = 0`).
    #[inline(always)]
    pub(crate) fn add_velocity<S: Real>(&self, v: &mut Motion<S>, rates: &[S]) -> Motion<S> {
        match *self {
            MotionSubspace::Axis { c, negative, dof } => {
                let rate = signed(rates[dof], negative);
                v.add_to_component(c, rate);
                v.cross_unit_motion(c, rate)
            }
            MotionSubspace::Columns { joint, .. } => {
                let v_j = joint.motion(&rates[self.dofs()]);
                *v += v_j;
                v.cross_motion(&v_j)
            }
        }
    }

    /// Inverse dynamics' joint forces into `tau`: `τ_i = S_iᵀ f_i + armature (q̈_i + K(q̇_i) q̇_i)`
    /// (`None` a zero q̈ or q̇; only a free joint has a rotor term `K`).
    #[inline(always)]
    pub(crate) fn joint_forces<S: Real>(
        &self,
        f: &Force<S>,
        accelerations: Option<&[S]>,
        rates: Option<&[S]>,
        armature: &[f64],
        tau: &mut [S],
    ) {
        match *self {
            MotionSubspace::Axis { c, negative, dof } => {
                let rate = accelerations.map_or(S::zero(), |a| a[dof]);
                tau[dof] = signed(f.component(c), negative) + S::splat(armature[dof]) * rate;
            }
            MotionSubspace::Columns { joint, .. } => {
                let dofs = self.dofs();
                for (k, dof) in dofs.clone().enumerate() {
                    let mut rate = accelerations.map_or(S::zero(), |a| a[dof]);
                    if let Some(v) = rates {
                        let v_i = &v[dofs.clone()];
                        for (c, v_c) in v_i.iter().enumerate() {
                            rate += joint.rotor_velocity_term(k, c, v_i) * *v_c;
                        }
                    }
                    let projected = joint.project_force(k, f);
                    tau[dof] = projected + S::splat(armature[dof]) * rate;
                }
            }
        }
    }

    /// ABA's `U_i = I^A_i S_i`, `u_i = τ_i − S_iᵀ p^A_i − armature K(q̇_i) q̇_i` and
    /// `D_i = S_iᵀ U_i + armature` inverted, into `terms`. Returns the lanes where `D_i` is
    /// singular: a pivot not positive relative to its largest diagonal entry
    /// ([`SINGULARITY_TOLERANCE`]).
    #[inline(always)]
    pub(crate) fn articulated_terms<S: Real>(
        &self,
        i_a: &Matrix6<S>,
        p_a: &Force<S>,
        (tau, rates): (&[S], &[S]),
        armature: &[f64],
        terms: &mut ArticulatedTerms<S>,
    ) -> S::SimdBool {
        match *self {
            MotionSubspace::Axis { c, negative, dof } => {
                // U_i = ±(column c of I^A_i);  u_i = τ_i ∓ p^A_i,c
                let column = inertia_column(i_a, c);
                terms.u[0] = if negative { -column } else { column };
                terms.u_tau[0] = tau[dof] - signed(p_a.component(c), negative);
                // D_i = I^A_i,cc + armature
                let pivot = i_a[(c, c)] + S::splat(armature[dof]);
                terms.d_inv[(0, 0)] = S::splat(1.0) / pivot;
                singular_pivot(pivot, pivot.simd_max(S::splat(0.0)))
            }
            MotionSubspace::Columns { joint, .. } => {
                let dofs = self.dofs();
                let (nv_i, v_i) = (dofs.len(), &rates[dofs.clone()]);
                for k in 0..nv_i {
                    terms.u[k] = joint.inertia_times_subspace(i_a, k);
                    let mut rotor = S::splat(0.0);
                    for (c, v_c) in v_i.iter().enumerate() {
                        rotor += joint.rotor_velocity_term(k, c, v_i) * *v_c;
                    }
                    terms.u_tau[k] = tau[dofs.start + k]
                        - joint.project_force(k, p_a)
                        - S::splat(armature[dofs.start + k]) * rotor;
                }
                let d = &mut *terms.d_inv;
                for r in 0..nv_i {
                    for c in 0..nv_i {
                        d[(r, c)] = joint.project_force(r, &terms.u[c]);
                    }
                    d[(r, r)] += S::splat(armature[dofs.start + r]);
                }
                invert_leading_block(d, nv_i)
            }
        }
    }

    /// ABA's articulated inertia and bias force passed on to the parent, before the transform:
    /// `I^a = I^A − U D⁻¹ Uᵀ` on and above the diagonal (the lower triangle is left as it was),
    /// `p^a = p^A + U D⁻¹ u`.
    #[inline(always)]
    pub(crate) fn subtract_articulated<S: Real>(
        &self,
        i_a: &mut Matrix6<S>,
        p_a: &mut Force<S>,
        terms: &ArticulatedTerms<S>,
    ) {
        let (u, d) = (&*terms.u, &*terms.d_inv);
        match self {
            // one coordinate: D⁻¹ is a number
            MotionSubspace::Axis { .. } => {
                let d_inv = d[(0, 0)];
                subtract_outer_upper(i_a, &u[0], &(u[0] * d_inv));
            }
            MotionSubspace::Columns { .. } => {
                let nv_i = self.dofs().len();
                for r in 0..nv_i {
                    // W_r = Σ_c D⁻¹_rc U_c, so that U D⁻¹ Uᵀ = Σ_r U_r W_rᵀ
                    let mut w_r = u[0] * d[(r, 0)];
                    for c in 1..nv_i {
                        w_r += u[c] * d[(r, c)];
                    }
                    subtract_outer_upper(i_a, &u[r], &w_r);
                }
            }
        }
        self.add_bias_response(p_a, terms.u, terms.d_inv, terms.u_tau);
    }

    /// `u −= S_iᵀ p` on the joint's coordinates (`u[k]` for coordinate k): ABA's
    /// `u_i = τ_i − S_iᵀ p_i` with τ_i in `u`.
    #[inline(always)]
    pub(crate) fn subtract_projection<S: Real>(&self, p: &Force<S>, u: &mut [S; 6]) {
        match *self {
            MotionSubspace::Axis { c, negative, .. } => u[0] -= signed(p.component(c), negative),
            MotionSubspace::Columns { joint, .. } => {
                for (k, u_k) in u.iter_mut().enumerate().take(joint.nv()) {
                    *u_k -= joint.project_force(k, p);
                }
            }
        }
    }

    /// ABA's inward pass through this joint of rows of J taken as generalised forces
    /// (`algo::constrained::articulated`): for each row r of `rows` and the force p it carries
    /// in (`carried`, one per row), `u = J_r,i − S_iᵀ p` into Y's entries of the joint's
    /// coordinates (J and Y column-major, m rows), then, with `onward` (the parent is not the
    /// world), `p += U_i D_i⁻¹ u`. `(u_forces, d_inv)`: U_i's columns and D_i⁻¹. One match on
    /// the joint for all the rows.
    #[inline(always)]
    pub(crate) fn transmit_rows<S: Real>(
        &self,
        carried: &mut [Force<S>],
        (j, y, m, rows): (&[S], &mut [S], usize, Range<usize>),
        (u_forces, d_inv): (&[Force<S>; 6], &Matrix6<S>),
        onward: bool,
    ) {
        match *self {
            MotionSubspace::Axis { c, negative, dof } => {
                for (p, r) in carried.iter_mut().zip(rows) {
                    // u = J_r,i ∓ p_c;  p += U_i u / D_i
                    let u = j[dof * m + r] - signed(p.component(c), negative);
                    y[dof * m + r] = u;
                    if onward {
                        *p += u_forces[0] * (d_inv[(0, 0)] * u);
                    }
                }
            }
            MotionSubspace::Columns { .. } => {
                for (p, r) in carried.iter_mut().zip(rows) {
                    let mut u = [S::zero(); 6];
                    for (u_k, dof) in u.iter_mut().zip(self.dofs()) {
                        *u_k = j[dof * m + r];
                    }
                    self.subtract_projection(p, &mut u);
                    for (u_k, dof) in u.iter().zip(self.dofs()) {
                        y[dof * m + r] = *u_k;
                    }
                    if onward {
                        self.add_bias_response(p, u_forces, d_inv, &u);
                    }
                }
            }
        }
    }

    /// `p += U D⁻¹ u` (`u_forces`: U's columns; `d_inv`: D⁻¹ in its leading block): ABA's bias
    /// force passed on to the parent, before the transform.
    #[inline(always)]
    pub(crate) fn add_bias_response<S: Real>(
        &self,
        p: &mut Force<S>,
        u_forces: &[Force<S>; 6],
        d_inv: &Matrix6<S>,
        u: &[S; 6],
    ) {
        let nv_i = self.dofs().len();
        for r in 0..nv_i {
            let mut d_inv_u = S::splat(0.0);
            for c in 0..nv_i {
                d_inv_u += d_inv[(r, c)] * u[c];
            }
            *p += u_forces[r] * d_inv_u;
        }
    }

    /// ABA's accelerations: `q̈_i = D_i⁻¹ (u_i − U_iᵀ a'_i)` into `qdd`, then `a_i = a'_i + S_i q̈_i`
    /// in place of `a`; `(u, u_tau, d_inv)`: U_i's columns, u_i and D_i⁻¹.
    #[inline(always)]
    pub(crate) fn accelerate<S: Real>(
        &self,
        a: &mut Motion<S>,
        (u, u_tau, d_inv): (&[Force<S>; 6], &[S; 6], &Matrix6<S>),
        qdd: &mut [S],
    ) {
        match *self {
            MotionSubspace::Axis { c, negative, dof } => {
                let qdd_i = d_inv[(0, 0)] * (u_tau[0] - a.dot(&u[0]));
                qdd[dof] = qdd_i;
                a.add_to_component(c, signed(qdd_i, negative));
            }
            MotionSubspace::Columns { joint, .. } => {
                let dofs = self.dofs();
                let nv_i = dofs.len();
                let mut rhs = [S::splat(0.0); 6];
                for (k, value) in rhs.iter_mut().enumerate().take(nv_i) {
                    *value = u_tau[k] - a.dot(&u[k]);
                }
                for (r, dof) in dofs.enumerate() {
                    let mut qdd_r = S::splat(0.0);
                    for (c, rhs_c) in rhs.iter().enumerate().take(nv_i) {
                        qdd_r += d_inv[(r, c)] * *rhs_c;
                    }
                    qdd[dof] = qdd_r;
                    *a += Motion::splat(&joint.subspace_column(r)) * qdd_r;
                }
            }
        }
    }

    /// CRBA's columns of M for this joint: `F_k = I^c_i S_k` for its coordinates k into `forces`,
    /// then `H_dk = S_kᵀ F_d` for the coordinates d ≥ k of its subtree (up to `subtree_end`,
    /// their forces in body i's coordinates) into `columns`.
    #[inline(always)]
    pub(crate) fn composite_columns<S: Real, F: SubtreeForces<S>>(
        &self,
        composite: &Inertia<S>,
        subtree_end: usize,
        forces: &mut F,
        columns: &mut MassColumns<S>,
    ) {
        match *self {
            // F = ±column c of I^c_i, and H_d = ±component c of F_d
            MotionSubspace::Axis { c, negative, dof } => {
                forces.set(dof, &composite.mul_unit_motion(c, negative));
                columns.store(dof, forces.unit_projections(c, negative, dof..subtree_end));
            }
            MotionSubspace::Columns { joint, .. } => {
                // all the joint's forces first: column k takes those of its later coordinates
                for (k, dof) in self.dofs().enumerate() {
                    let force = match self.component(k) {
                        Some((c, negative)) => composite.mul_unit_motion(c, negative),
                        None => composite.mul_motion(&Motion::splat(&joint.subspace_column(k))),
                    };
                    forces.set(dof, &force);
                }
                for (k, col) in self.dofs().enumerate() {
                    let rows = col..subtree_end;
                    match self.component(k) {
                        Some((c, negative)) => {
                            columns.store(col, forces.unit_projections(c, negative, rows))
                        }
                        None => {
                            let values = rows.map(|d| joint.project_force(k, &forces.force(d)));
                            columns.store(col, values)
                        }
                    }
                }
            }
        }
    }
}

/// The lanes where a pivot of `D_i` is not positive relative to `scale`, the largest diagonal
/// entry of `D_i` ([`SINGULARITY_TOLERANCE`]); NaN compares false, so a NaN pivot is singular.
#[inline(always)]
fn singular_pivot<S: Real>(pivot: S, scale: S) -> S::SimdBool {
    let threshold = S::splat(SINGULARITY_TOLERANCE) * scale;
    !(pivot.simd_gt(threshold) & pivot.simd_gt(S::splat(0.0)))
}

/// `I −= x yᵀ` on and above the diagonal, for two forces taken as `[angular; linear]`
/// 6-vectors (the sum of such terms, `U D⁻¹ Uᵀ`, is symmetric).
#[inline(always)]
fn subtract_outer_upper<S: Real>(inertia: &mut Matrix6<S>, x: &Force<S>, y: &Force<S>) {
    let (x, y) = (x.plucker(), y.plucker());
    for (col, y_col) in y.iter().enumerate() {
        for (row, x_row) in x.iter().enumerate().take(col + 1) {
            inertia[(row, col)] -= *x_row * *y_col;
        }
    }
}

/// Inverts the leading `n` x `n` block of `m` in place by Gauss–Jordan elimination without
/// pivoting (the block, `D_i`, is symmetric positive definite). Returns the lanes where a pivot is
/// not positive relative to the block's largest diagonal entry ([`SINGULARITY_TOLERANCE`]).
#[inline(always)]
fn invert_leading_block<S: Real>(m: &mut Matrix6<S>, n: usize) -> S::SimdBool {
    let zero = S::splat(0.0);
    let mut scale = zero;
    for k in 0..n {
        scale = scale.simd_max(m[(k, k)]);
    }
    // false in every lane, unless the scale is NaN
    let mut singular = scale.simd_ne(scale);
    for k in 0..n {
        let pivot = m[(k, k)];
        singular = singular | singular_pivot(pivot, scale);
        m[(k, k)] = S::splat(1.0);
        for j in 0..n {
            m[(k, j)] /= pivot;
        }
        for i in 0..n {
            if i != k {
                let factor = m[(i, k)];
                m[(i, k)] = zero;
                for j in 0..n {
                    let product = factor * m[(k, j)];
                    m[(i, j)] -= product;
                }
            }
        }
    }
    singular
}
