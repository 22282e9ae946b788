//! Articulated-body algorithm: forward dynamics q̈ = M(q)⁻¹ (τ - C(q, q̇) q̇ - g(q) + Σ Jᵀ f_ext).
//!
//! Reference: Featherstone, *Rigid Body Dynamics Algorithms* (2008), Table 7.1, with joint armature
//! added to `D_i` so that ABA inverts exactly the M that CRBA builds. The products with a joint's
//! motion subspace `S_i` are the joint's (`joint::subspace`).
//! Inputs: q (nq), v (nv), τ (nv), optional external forces per moving body (body frame).
//! Writes `data.x_up`, `data.v`, `data.c`, `data.i_a`, `data.p_a`, `data.u`, `data.d_inv`,
//! `data.u_tau`, `data.a`, `data.qdd`. Cost: O(n).

use crate::algo::derivatives::DynamicsState;
use crate::algo::kinematics::joint_transforms;
use crate::algo::rnea::check_external_forces;
use crate::dispatch::multiversion;
use crate::error::{check_vector, Error, Result};
use crate::joint::ArticulatedTerms;
use crate::model::Model;
use crate::spatial::{
    mat6_mul_motion, splat_vector, zero_vector, Force, Inertia, Motion, Real, Transform,
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
    check_dynamics_inputs(model, (q, v, tau), f_ext)?;
    one_state_passes(model, (q, v, tau, f_ext), AbaBuffers::of(data))
        .map_err(|joint| singular_joint(model, joint))?;
    Ok(&data.qdd)
}

/// Refuses a q, q̇, τ or f_ext of the wrong size, or a q that is not a configuration.
pub(crate) fn check_dynamics_inputs(
    model: &Model,
    (q, v, tau): (&[f64], &[f64], &[f64]),
    f_ext: Option<&[Force]>,
) -> Result<()> {
    model.check_configuration(q)?;
    check_vector("v", v, model.nv)?;
    check_vector("tau", tau, model.nv)?;
    match f_ext {
        Some(forces) => check_external_forces(model, forces),
        None => Ok(()),
    }
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
    pub(crate) fn of(data: &'b mut Data) -> Self {
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
    articulated_inertia_passes(model, (q, v, tau), f_ext, &mut out)?;
    let (terms, accelerations) = out.outward();
    acceleration_pass(model, 1..model.nbodies(), &terms, None, accelerations);
    Ok(())
}

/// Passes 1 and 2 of Table 7.1 on checked inputs: the transforms, velocities, articulated
/// inertias and bias forces, and each joint's `U_i`, `u_i`, `D_i⁻¹`. An error gives the first
/// body whose `D_i` is singular in some lane.
#[inline(always)]
pub(crate) fn articulated_inertia_passes<S: Real>(
    model: &Model,
    (q, v, tau): (&[S], &[S], &[S]),
    f_ext: Option<&[Force<S>]>,
    out: &mut AbaBuffers<S>,
) -> std::result::Result<(), usize> {
    joint_transforms(model, q, out.x_up);

    // pass 1, outward: velocities, velocity-product accelerations, rigid-body inertias and biases
    out.v[0] = Motion::zeros();
    for i in 1..model.nbodies() {
        // v_i = X_i v_λ(i) + v_J;  c_i = v_i × v_J
        let turn = model.turn(i);
        let mut v_i = out.x_up[i].apply_motion_turned(turn, &out.v[model.parent[i]]);
        out.c[i] = model.subspace(i).add_velocity(&mut v_i, v);
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
        let subspace = model.subspace(i);
        // U_i = I^A_i S_i;  u_i = τ_i - S_iᵀ p^A_i;  D_i = S_iᵀ U_i, inverted
        let mut terms = ArticulatedTerms {
            u: &mut out.u[i],
            u_tau: &mut out.u_tau[i],
            d_inv: &mut out.d_inv[i],
        };
        let (i_a, p_a) = (&out.i_a[i], &out.p_a[i]);
        let not_positive =
            subspace.articulated_terms(i_a, p_a, (tau, v), model.armature.as_slice(), &mut terms);
        if not_positive.any() && singular.is_none() {
            singular = Some(i);
        }
        let parent = model.parent[i];
        if parent != 0 {
            // I^a = I^A - U D⁻¹ Uᵀ;  p^a = p^A + I^a c + U D⁻¹ u
            let (mut i_a, mut p_a) = (out.i_a[i], out.p_a[i]);
            subspace.subtract_articulated(&mut i_a, &mut p_a, &terms);
            mirror_upper(&mut i_a);
            p_a += mat6_mul_motion(&i_a, &out.c[i]);
            // I^A_λ(i) += X_iᵀ I^a X_i;  p^A_λ(i) += X_iᵀ p^a
            let turn = model.turn(i);
            out.x_up[i].add_transpose_apply_matrix_turned(turn, &i_a, &mut out.i_a[parent]);
            let p_parent = out.x_up[i].transpose_apply_force_turned(turn, &p_a);
            out.p_a[parent] += p_parent;
        }
    }
    match singular {
        Some(joint) => Err(joint),
        None => Ok(()),
    }
}

/// What ABA's outward pass writes: the bodies' accelerations a_i and q̈.
pub(crate) type OutwardResults<'b, S> = (&'b mut [Motion<S>], &'b mut [S]);

/// What ABA's outward pass (pass 3 of Table 7.1) reads of passes 1 and 2.
pub(crate) struct OutwardTerms<'b, S> {
    pub x_up: &'b [Transform<S>],
    pub c: &'b [Motion<S>],
    pub u: &'b [[Force<S>; 6]],
    pub u_tau: &'b [[S; 6]],
    pub d_inv: &'b [Matrix6<S>],
}

impl<S> AbaBuffers<'_, S> {
    /// What the outward pass reads, and what it writes: the accelerations a_i and q̈.
    pub(crate) fn outward(&mut self) -> (OutwardTerms<'_, S>, OutwardResults<'_, S>) {
        let terms = OutwardTerms {
            x_up: self.x_up,
            c: self.c,
            u: self.u,
            u_tau: self.u_tau,
            d_inv: self.d_inv,
        };
        (terms, (&mut *self.a, &mut *self.qdd))
    }
}

/// Pass 3 of Table 7.1, outward from `a_0 = −g` over `bodies` (each after its parent; the
/// others' a_i and q̈_i are left as they were), into `(a, qdd)`. `transmitted`: per coordinate,
/// the u_i that ABA's inward pass makes of further generalised forces f (K f: for constraint
/// forces f = Jᵀ λ, `Yᵀ λ`), added to τ's; none: zero.
#[inline(always)]
pub(crate) fn acceleration_pass<S: Real>(
    model: &Model,
    bodies: impl IntoIterator<Item = usize>,
    terms: &OutwardTerms<S>,
    transmitted: Option<&[S]>,
    (a, qdd): OutwardResults<S>,
) {
    a[0] = Motion::new(zero_vector(), -splat_vector::<S>(&model.gravity));
    for i in bodies {
        // a'_i = X_i a_λ(i) + c_i
        let turn = model.turn(i);
        let mut a_i = terms.x_up[i].apply_motion_turned(turn, &a[model.parent[i]]) + terms.c[i];
        // q̈_i = D_i⁻¹ (u_i − U_iᵀ a'_i);  a_i = a'_i + S_i q̈_i
        let mut sum;
        let u_i = match transmitted {
            None => &terms.u_tau[i],
            Some(transmitted) => {
                sum = terms.u_tau[i];
                for (u_k, t_k) in sum.iter_mut().zip(&transmitted[model.v_range(i)]) {
                    *u_k += *t_k;
                }
                &sum
            }
        };
        model
            .subspace(i)
            .accelerate(&mut a_i, (&terms.u[i], u_i, &terms.d_inv[i]), qdd);
        a[i] = a_i;
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
