//! Recursive Newton–Euler algorithm: inverse dynamics τ = M(q) q̈ + C(q, q̇) q̇ + g(q) - Σ Jᵀ f_ext.
//!
//! Reference: Featherstone, *Rigid Body Dynamics Algorithms* (2008), Table 5.1; the notes' iterative
//! Newton–Euler (the ECE 470 and TUM notes eqs. 6.45-6.53: outward velocities and accelerations, inward
//! forces and torques). Gravity enters as a fictitious base acceleration `a_0 = -g`.
//! Inputs: q (nq), v (nv), a (nv), optional external forces per moving body (in the body's frame,
//! at its origin). Writes `data.x_up`, `data.v`, `data.a`, `data.f`, `data.tau`. Cost: O(n).

use crate::algo::kinematics::joint_transforms;
use crate::error::{check_length, check_vector, Error, Result};
use crate::model::Model;
use crate::spatial::{splat_vector, zero_vector, Force, Inertia, Motion, Real, Transform};
use crate::Data;
use nalgebra::DVector;

/// τ = ID(q, q̇, q̈, f_ext). `f_ext`, when given, has one force per moving body (nbodies - 1, in
/// body order), expressed in that body's frame.
pub fn rnea<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    f_ext: Option<&[Force]>,
) -> Result<&'d DVector<f64>> {
    check_vector("v", v, model.nv)?;
    check_vector("a", a, model.nv)?;
    newton_euler(model, data, q, Some(v), Some(a), f_ext)
}

/// Bias forces `C(q, q̇) q̇ + g(q)`: RNEA with q̈ = 0.
pub fn bias_forces<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
) -> Result<&'d DVector<f64>> {
    check_vector("v", v, model.nv)?;
    newton_euler(model, data, q, Some(v), None, None)
}

/// Generalized gravity `g(q)`: RNEA with q̇ = q̈ = 0.
pub fn generalized_gravity<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
) -> Result<&'d DVector<f64>> {
    newton_euler(model, data, q, None, None, None)
}

/// The two passes of Table 5.1 for one checked state, into `data`; `None` stands for a zero
/// velocity or acceleration.
pub(crate) fn newton_euler<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: Option<&[f64]>,
    a: Option<&[f64]>,
    f_ext: Option<&[Force]>,
) -> Result<&'d DVector<f64>> {
    model.check_configuration(q)?;
    if let Some(forces) = f_ext {
        check_external_forces(model, forces)?;
    }
    let buffers = NewtonEulerBuffers {
        x_up: &mut data.x_up,
        v: &mut data.v,
        a: &mut data.a,
        f: &mut data.f,
        tau: data.tau.as_mut_slice(),
    };
    newton_euler_passes(model, q, v, a, f_ext, buffers);
    Ok(&data.tau)
}

/// What the Newton–Euler passes write, per body (x_up, v, a, f) and per velocity coordinate
/// (tau): one state's, borrowed from [`Data`], or several states' in lanes (see
/// [`crate::algo::lanes`]).
pub(crate) struct NewtonEulerBuffers<'b, S> {
    pub x_up: &'b mut [Transform<S>],
    pub v: &'b mut [Motion<S>],
    pub a: &'b mut [Motion<S>],
    pub f: &'b mut [Force<S>],
    pub tau: &'b mut [S],
}

/// The two passes of Table 5.1 on checked inputs, in `f64` or in lanes (the same operations in
/// every lane, so each lane's result is the one-state result bit for bit).
#[inline(always)]
pub(crate) fn newton_euler_passes<S: Real>(
    model: &Model,
    q: &[S],
    v: Option<&[S]>,
    a: Option<&[S]>,
    f_ext: Option<&[Force<S>]>,
    mut out: NewtonEulerBuffers<S>,
) {
    joint_transforms(model, q, out.x_up);

    // outward pass: velocities, accelerations and the force each body needs
    out.v[0].set_zero();
    out.a[0] = Motion::new(zero_vector(), -splat_vector::<S>(&model.gravity));
    for i in 1..model.nbodies() {
        outward_body(model, i, v, a, f_ext, &mut out);
    }

    // inward pass: project onto the joint axes, pass the rest to the parent
    for i in (1..model.nbodies()).rev() {
        // τ_i = S_iᵀ f_i + armature (q̈_i + K(q̇_i) q̇_i)
        let subspace = model.subspace(i);
        subspace.joint_forces(&out.f[i], a, v, model.armature.as_slice(), out.tau);
        let parent = model.parent[i];
        if parent != 0 {
            // f_λ(i) += X_iᵀ f_i
            let f_parent = out.x_up[i].transpose_apply_force_turned(model.turn(i), &out.f[i]);
            out.f[parent] += f_parent;
        }
    }
}

/// Body i of the outward pass.
#[inline(always)]
fn outward_body<S: Real>(
    model: &Model,
    i: usize,
    v: Option<&[S]>,
    a: Option<&[S]>,
    f_ext: Option<&[Force<S>]>,
    out: &mut NewtonEulerBuffers<S>,
) {
    let (parent, x_up, turn) = (model.parent[i], &out.x_up[i], model.turn(i));
    let subspace = model.subspace(i);
    // I_i read into each product where it is used (kept whole, it would be copied)
    let inertia = &model.inertias[i];
    // a_i = X_i a_λ(i) + S q̈_i + v_i × v_J   (c_J = 0)
    let mut a_i = match (v, a) {
        // at rest every a_i is gravity's, a linear motion [0; g_i]: g_i = E_i g_λ(i)
        (None, None) => Motion::new(
            zero_vector(),
            x_up.rotate_turned(turn, &out.a[parent].linear),
        ),
        _ => x_up.apply_motion_turned(turn, &out.a[parent]),
    };
    if let Some(a) = a {
        subspace.add_motion(&mut a_i, a);
    }
    // f_i = I_i a_i + v_i ×* I_i v_i - f_ext_i
    let mut f_i = match v {
        Some(v) => {
            // v_i = X_i v_λ(i) + v_J
            let mut v_i = x_up.apply_motion_turned(turn, &out.v[parent]);
            a_i += subspace.add_velocity(&mut v_i, v);
            out.v[i] = v_i;
            let momentum = Inertia::<S>::splat(inertia).mul_motion(&v_i);
            Inertia::<S>::splat(inertia).mul_motion(&a_i) + v_i.cross_force(&momentum)
        }
        None => {
            // at rest every velocity product vanishes
            out.v[i].set_zero();
            match a {
                Some(_) => Inertia::<S>::splat(inertia).mul_motion(&a_i),
                None => Inertia::<S>::splat(inertia).mul_linear_motion(&a_i.linear),
            }
        }
    };
    if let Some(forces) = f_ext {
        f_i -= forces[i - 1];
    }
    out.a[i] = a_i;
    out.f[i] = f_i;
}

/// Checks one finite force per moving body.
pub(crate) fn check_external_forces(model: &Model, forces: &[Force]) -> Result<()> {
    check_length("f_ext", forces.len(), model.nbodies() - 1)?;
    for (i, force) in forces.iter().enumerate() {
        if let Some(k) = force.to_array().iter().position(|x| !x.is_finite()) {
            return Err(Error::NotFinite {
                argument: "f_ext".into(),
                index: 6 * i + k,
                value: force.to_array()[k],
            });
        }
    }
    Ok(())
}
