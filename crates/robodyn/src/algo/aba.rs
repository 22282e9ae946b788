//! Articulated-body algorithm: forward dynamics q̈ = M(q)⁻¹ (τ - C(q, q̇) q̇ - g(q) + Σ Jᵀ f_ext).
//!
//! Reference: Featherstone, *Rigid Body Dynamics Algorithms* (2008), Table 7.1, with joint armature
//! added to `D_i` so that ABA inverts exactly the M that CRBA builds. A joint of one coordinate
//! along a coordinate axis (`Model::unit_axis`, S = ±e_c) takes each product with S as one
//! component and `D_i⁻¹` as one division; the values are those of the general products.
//! Inputs: q (nq), v (nv), τ (nv), optional external forces per moving body (body frame).
//! Writes `data.x_up`, `data.v`, `data.c`, `data.i_a`, `data.p_a`, `data.u`, `data.d_inv`,
//! `data.u_tau`, `data.a`, `data.qdd`. Cost: O(n).

use crate::algo::derivatives::DynamicsState;
use crate::algo::kinematics::joint_transforms;
use crate::algo::rnea::check_external_forces;
use crate::algo::SINGULARITY_TOLERANCE;
use crate::dispatch::multiversion;
use crate::error::{check_vector, Error, Result};
use crate::model::Model;
use crate::spatial::{
    mat6_mul_motion, signed, splat_vector, zero_vector, Force, Inertia, Motion, Real, Transform,
};
use crate::Data;
use nalgebra::{DVector, Matrix6, SimdBool};

/// q̈ = FD(q, q̇, τ, f_ext), written into `data.qdd`.
pub fn aba<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    f_ext: Option<&[Force]>,
) -> Result<&'d DVector<f64>> {
    model.check_configuration(q)?;
    check_vector("v", v, model.nv)?;
    check_vector("tau", tau, model.nv)?;
    if let Some(forces) = f_ext {
        check_external_forces(model, forces)?;
    }
    one_state_passes(model, (q, v, tau, f_ext), AbaBuffers::of(data))
        .map_err(|joint| singular_joint(model, joint))?;
    Ok(&data.qdd)
}

multiversion! {
    /// [`articulated_body_passes`] of one state, built for AVX2 and FMA as well
    /// ([`crate::dispatch`]).
    #[inline(never)]
    fn one_state_passes(
        model: &Model,
        state: DynamicsState,
        out: AbaBuffers<f64>,
    ) -> std::result::Result<(), usize> {
        one_state_passes_avx2 for ["avx2", "fma"] => { passes_of(model, state, out) }
        baseline => { passes_of(model, state, out) }
    }
}

/// [`articulated_body_passes`] of one state, its arguments in one.
#[inline(always)]
fn passes_of(
    model: &Model,
    (q, v, tau, f_ext): DynamicsState,
    out: AbaBuffers<f64>,
) -> std::result::Result<(), usize> {
    articulated_body_passes(model, q, v, tau, f_ext, out)
}

/// The error for a joint whose articulated inertia `D_i` is singular.
pub(crate) fn singular_joint(model: &Model, joint: usize) -> Error {
    Error::InvalidValue {
        argument: "q".into(),
        message: format!(
            "the articulated inertia of joint '{}' is singular (a massless subtree without \
             armature): forward dynamics is undefined",
            model.joint_names[joint]
        ),
    }
}

/// What the ABA passes write, per body and per velocity coordinate (qdd): one state's,
/// borrowed from [`Data`] (see its fields), or several states' in lanes ([`crate::algo::lanes`]).
pub(crate) struct AbaBuffers<'b, S> {
    pub x_up: &'b mut [Transform<S>],
    pub v: &'b mut [Motion<S>],
    pub c: &'b mut [Motion<S>],
    pub a: &'b mut [Motion<S>],
    pub i_a: &'b mut [Matrix6<S>],
    pub p_a: &'b mut [Force<S>],
    pub u: &'b mut [[Force<S>; 6]],
    pub u_tau: &'b mut [[S; 6]],
    pub d_inv: &'b mut [Matrix6<S>],
    pub qdd: &'b mut [S],
}

impl<'b> AbaBuffers<'b, f64> {
    /// `data`'s fields.
    fn of(data: &'b mut Data) -> Self {
        AbaBuffers {
            x_up: &mut data.x_up,
            v: &mut data.v,
            c: &mut data.c,
            a: &mut data.a,
            i_a: &mut data.i_a,
            p_a: &mut data.p_a,
            u: &mut data.u,
            u_tau: &mut data.u_tau,
            d_inv: &mut data.d_inv,
            qdd: data.qdd.as_mut_slice(),
        }
    }
}

/// The three passes of Table 7.1 on checked inputs, in `f64` or in lanes (the same operations
/// in every lane). An error gives the first body whose `D_i` is singular in some lane.
#[inline(always)]
pub(crate) fn articulated_body_passes<S: Real>(
    model: &Model,
    q: &[S],
    v: &[S],
    tau: &[S],
    f_ext: Option<&[Force<S>]>,
    mut out: AbaBuffers<S>,
) -> std::result::Result<(), usize> {
    joint_transforms(model, q, out.x_up);

    // pass 1, outward: velocities, velocity-product accelerations, rigid-body inertias and biases
    out.v[0] = Motion::zeros();
    for i in 1..model.nbodies() {
        // v_i = X_i v_λ(i) + v_J;  c_i = v_i × v_J
        let turn = model.turn(i);
        let mut v_i = out.x_up[i].apply_motion_turned(turn, &out.v[model.parent[i]]);
        match model.unit_axis(i) {
            // S = ±e_c: v_J is one component
            Some((c, negative)) => {
                let rate = signed(v[model.idx_v[i]], negative);
                v_i.add_to_component(c, rate);
                out.c[i] = v_i.cross_unit_motion(c, rate);
            }
            None => {
                let v_j = model.joints[i].motion(&v[model.v_range(i)]);
                v_i += v_j;
                out.c[i] = v_i.cross_motion(&v_j);
            }
        }
        let inertia = Inertia::<S>::splat(&model.inertias[i]);
        model.inertias[i].splat_matrix_into(&mut out.i_a[i]);
        // p^A_i = v_i ×* I_i v_i - f_ext_i
        out.p_a[i] = v_i.cross_force(&inertia.mul_motion(&v_i));
        if let Some(forces) = f_ext {
            out.p_a[i] -= forces[i - 1];
        }
        out.v[i] = v_i;
    }

    // pass 2, inward: articulated inertias and bias forces
    let mut singular = None;
    for i in (1..model.nbodies()).rev() {
        let joint = &model.joints[i];
        let nv_i = joint.nv();
        let dofs = model.v_range(i);
        let unit_axis = model.unit_axis(i);
        let not_positive = match unit_axis {
            Some((c, negative)) => {
                // S = ±e_c: U_i = ±(column c of I^A_i);  u_i = τ_i ∓ p^A_i,c (no rotor term)
                let dof = dofs.start;
                out.u[i][0] = joint.inertia_times_subspace(&out.i_a[i], 0);
                out.u_tau[i][0] = tau[dof] - signed(out.p_a[i].component(c), negative);
                // D_i = I^A_i,cc + armature, inverted
                let pivot = out.i_a[i][(c, c)] + S::splat(model.armature[dof]);
                out.d_inv[i][(0, 0)] = S::splat(1.0) / pivot;
                singular_pivot(pivot, pivot.simd_max(S::splat(0.0)))
            }
            None => general_joint_projection(model, i, v, tau, &mut out),
        };
        if not_positive.any() && singular.is_none() {
            singular = Some(i);
        }
        let parent = model.parent[i];
        if parent != 0 {
            // I^a = I^A - U D⁻¹ Uᵀ;  p^a = p^A + I^a c + U D⁻¹ u
            let mut i_a = out.i_a[i];
            let mut p_a = out.p_a[i];
            let (u, d) = (&out.u[i], &out.d_inv[i]);
            match unit_axis {
                // one coordinate: D⁻¹ is a number
                Some(_) => {
                    let d_inv = d[(0, 0)];
                    subtract_outer_upper(&mut i_a, &u[0], &(u[0] * d_inv));
                    p_a += u[0] * (d_inv * out.u_tau[i][0]);
                }
                None => {
                    for r in 0..nv_i {
                        // W_r = Σ_c D⁻¹_rc U_c, so that U D⁻¹ Uᵀ = Σ_r U_r W_rᵀ
                        let mut w_r = u[0] * d[(r, 0)];
                        let mut d_inv_u = S::splat(0.0);
                        for c in 0..nv_i {
                            if c > 0 {
                                w_r += u[c] * d[(r, c)];
                            }
                            d_inv_u += d[(r, c)] * out.u_tau[i][c];
                        }
                        subtract_outer_upper(&mut i_a, &u[r], &w_r);
                        p_a += u[r] * d_inv_u;
                    }
                }
            }
            mirror_upper(&mut i_a);
            p_a += mat6_mul_motion(&i_a, &out.c[i]);
            // I^A_λ(i) += X_iᵀ I^a X_i;  p^A_λ(i) += X_iᵀ p^a
            let turn = model.turn(i);
            out.x_up[i].add_transpose_apply_matrix_turned(turn, &i_a, &mut out.i_a[parent]);
            let p_parent = out.x_up[i].transpose_apply_force_turned(turn, &p_a);
            out.p_a[parent] += p_parent;
        }
    }
    if let Some(joint) = singular {
        return Err(joint);
    }

    // pass 3, outward: accelerations
    out.a[0] = Motion::new(zero_vector(), -splat_vector::<S>(&model.gravity));
    for i in 1..model.nbodies() {
        let joint = &model.joints[i];
        let dofs = model.v_range(i);
        // a'_i = X_i a_λ(i) + c_i
        let turn = model.turn(i);
        let mut a_i = out.x_up[i].apply_motion_turned(turn, &out.a[model.parent[i]]) + out.c[i];
        if let Some((c, negative)) = model.unit_axis(i) {
            // q̈_i = (u_i - U_iᵀ a'_i) / D_i;  a_i = a'_i ± q̈_i e_c
            let qdd = out.d_inv[i][(0, 0)] * (out.u_tau[i][0] - a_i.dot(&out.u[i][0]));
            out.qdd[dofs.start] = qdd;
            a_i.add_to_component(c, signed(qdd, negative));
            out.a[i] = a_i;
            continue;
        }
        // q̈_i = D_i⁻¹ (u_i - U_iᵀ a'_i)
        let nv_i = joint.nv();
        let mut rhs = [S::splat(0.0); 6];
        for (k, value) in rhs.iter_mut().enumerate().take(nv_i) {
            *value = out.u_tau[i][k] - a_i.dot(&out.u[i][k]);
        }
        for (r, dof) in dofs.enumerate() {
            let mut qdd = S::splat(0.0);
            for (c, rhs_c) in rhs.iter().enumerate().take(nv_i) {
                qdd += out.d_inv[i][(r, c)] * *rhs_c;
            }
            out.qdd[dof] = qdd;
            // a_i = a'_i + S_i q̈_i
            a_i += Motion::splat(&joint.subspace_column(r)) * qdd;
        }
        out.a[i] = a_i;
    }
    Ok(())
}

/// U_i, u_i and D_i⁻¹ of a joint whose motion subspace is not one coordinate axis (several
/// coordinates, or an axis that is not a coordinate axis). Returns the lanes where `D_i` is
/// singular.
#[inline(always)]
fn general_joint_projection<S: Real>(
    model: &Model,
    i: usize,
    v: &[S],
    tau: &[S],
    out: &mut AbaBuffers<S>,
) -> S::SimdBool {
    let joint = &model.joints[i];
    let nv_i = joint.nv();
    let dofs = model.v_range(i);
    let v_i = &v[dofs.clone()];
    for k in 0..nv_i {
        // U_i = I^A_i S_i;  u_i = τ_i - S_iᵀ p^A_i - armature K(q̇_i) q̇_i
        out.u[i][k] = joint.inertia_times_subspace(&out.i_a[i], k);
        let mut rotor = S::splat(0.0);
        for (c, v_c) in v_i.iter().enumerate() {
            rotor += joint.rotor_velocity_term(k, c, v_i) * *v_c;
        }
        out.u_tau[i][k] = tau[dofs.start + k]
            - joint.project_force(k, &out.p_a[i])
            - S::splat(model.armature[dofs.start + k]) * rotor;
    }
    // D_i = S_iᵀ U_i + armature, inverted in place
    let d = &mut out.d_inv[i];
    for r in 0..nv_i {
        for c in 0..nv_i {
            d[(r, c)] = joint.project_force(r, &out.u[i][c]);
        }
        d[(r, r)] += S::splat(model.armature[dofs.start + r]);
    }
    invert_leading_block(d, nv_i)
}

/// The lanes where a pivot of `D_i` is not positive relative to `scale`, the largest diagonal
/// entry of `D_i` ([`SINGULARITY_TOLERANCE`]); NaN compares false, so a NaN pivot is singular.
#[inline(always)]
fn singular_pivot<S: Real>(pivot: S, scale: S) -> S::SimdBool {
    let threshold = S::splat(SINGULARITY_TOLERANCE) * scale;
    !(pivot.simd_gt(threshold) & pivot.simd_gt(S::splat(0.0)))
}

/// `I −= x yᵀ` on and above the diagonal, for two forces taken as `[angular; linear]`
/// 6-vectors (the sum of such terms, `U D⁻¹ Uᵀ`, is symmetric: see [`mirror_upper`]).
#[inline(always)]
fn subtract_outer_upper<S: Real>(inertia: &mut Matrix6<S>, x: &Force<S>, y: &Force<S>) {
    let (x, y) = (x.plucker(), y.plucker());
    for (col, y_col) in y.iter().enumerate() {
        for (row, x_row) in x.iter().enumerate().take(col + 1) {
            inertia[(row, col)] -= *x_row * *y_col;
        }
    }
}

/// The lower triangle of `m` set from the upper one.
#[inline(always)]
fn mirror_upper<S: Real>(m: &mut Matrix6<S>) {
    for col in 0..6 {
        for row in col + 1..6 {
            m[(row, col)] = m[(col, row)];
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::bundled::floating_ur5_state;

    /// A single call, built for AVX2 and FMA where the processor has them, equals the baseline
    /// build of the same passes bit for bit (the claim of `one_state_passes`).
    #[test]
    fn the_dispatched_passes_equal_the_baseline_build_bit_for_bit() {
        let (model, q, v, tau) = floating_ur5_state();
        let mut dispatched = Data::new(&model);
        aba(&model, &mut dispatched, &q, &v, &tau, None).unwrap();
        let mut data = Data::new(&model);
        articulated_body_passes(&model, &q, &v, &tau, None, AbaBuffers::of(&mut data)).unwrap();
        assert_eq!(dispatched.qdd, data.qdd);
    }

    /// The articulated inertias stay exactly symmetric: the rank-one updates are made on the
    /// upper triangle and mirrored, the transform to the parent mirrors its result.
    #[test]
    fn articulated_inertias_are_exactly_symmetric() {
        let (model, q, v, tau) = floating_ur5_state();
        let mut data = Data::new(&model);
        aba(&model, &mut data, &q, &v, &tau, None).unwrap();
        for (i, inertia) in data.i_a.iter().enumerate().skip(1) {
            assert_eq!(*inertia, inertia.transpose(), "body {i}");
        }
    }
}
