//! Articulated-body algorithm: forward dynamics q̈ = M(q)⁻¹ (τ - C(q, q̇) q̇ - g(q) + Σ Jᵀ f_ext).
//!
//! Reference: Featherstone, *Rigid Body Dynamics Algorithms* (2008), Table 7.1, with joint armature
//! added to `D_i` so that ABA inverts exactly the M that CRBA builds.
//! Inputs: q (nq), v (nv), τ (nv), optional external forces per moving body (body frame).
//! Writes `data.x_up`, `data.v`, `data.c`, `data.i_a`, `data.p_a`, `data.u`, `data.d_inv`,
//! `data.u_tau`, `data.a`, `data.qdd`. Cost: O(n).

use crate::algo::kinematics::update_joint_transforms;
use crate::algo::rnea::check_external_forces;
use crate::algo::SINGULARITY_TOLERANCE;
use crate::error::{check_vector, Error, Result};
use crate::model::Model;
use crate::spatial::{mat6_mul_motion, Force, Mat6, Motion, Vec3};
use crate::Data;
use nalgebra::DVector;

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
    update_joint_transforms(model, data, q);

    // pass 1, outward: velocities, velocity-product accelerations, rigid-body inertias and biases
    data.v[0] = Motion::ZERO;
    for i in 1..model.nbodies() {
        let v_j = model.joints[i].motion(&v[model.v_range(i)]);
        // v_i = X_i v_λ(i) + v_J;  c_i = v_i × v_J
        let v_i = data.x_up[i].apply_motion(&data.v[model.parent[i]]) + v_j;
        data.c[i] = v_i.cross_motion(&v_j);
        let inertia = &model.inertias[i];
        data.i_a[i] = inertia.to_matrix();
        // p^A_i = v_i ×* I_i v_i - f_ext_i
        data.p_a[i] = v_i.cross_force(&inertia.mul_motion(&v_i));
        if let Some(forces) = f_ext {
            data.p_a[i] -= forces[i - 1];
        }
        data.v[i] = v_i;
    }

    // pass 2, inward: articulated inertias and bias forces
    for i in (1..model.nbodies()).rev() {
        let joint = &model.joints[i];
        let nv_i = joint.nv();
        let dofs = model.v_range(i);
        let v_i = &v[dofs.clone()];
        for k in 0..nv_i {
            // U_i = I^A_i S_i;  u_i = τ_i - S_iᵀ p^A_i - armature K(q̇_i) q̇_i
            data.u[i][k] = joint.inertia_times_subspace(&data.i_a[i], k);
            let rotor: f64 = (0..nv_i)
                .map(|c| joint.rotor_velocity_term(k, c, v_i) * v_i[c])
                .sum();
            data.u_tau[i][k] = tau[dofs.start + k]
                - joint.project_force(k, &data.p_a[i])
                - model.armature[dofs.start + k] * rotor;
        }
        // D_i = S_iᵀ U_i + armature
        let mut d = Mat6::identity();
        for r in 0..nv_i {
            for c in 0..nv_i {
                d[(r, c)] = joint.project_force(r, &data.u[i][c]);
            }
            d[(r, r)] += model.armature[dofs.start + r];
        }
        if !invert_leading_block(&mut d, nv_i) {
            return Err(Error::InvalidValue {
                argument: "q".into(),
                message: format!(
                    "the articulated inertia of joint '{}' is singular (a massless subtree without \
                     armature): forward dynamics is undefined",
                    model.joint_names[i]
                ),
            });
        }
        data.d_inv[i] = d;
        let parent = model.parent[i];
        if parent != 0 {
            // I^a = I^A - U D⁻¹ Uᵀ;  p^a = p^A + I^a c + U D⁻¹ u
            let mut i_a = data.i_a[i];
            let mut p_a = data.p_a[i];
            for r in 0..nv_i {
                let u_r = data.u[i][r].to_vector();
                let mut d_inv_u = 0.0;
                for c in 0..nv_i {
                    // rank-one update in place: I^a −= D⁻¹_rc U_r U_cᵀ
                    i_a.ger(-d[(r, c)], &u_r, &data.u[i][c].to_vector(), 1.0);
                    d_inv_u += d[(r, c)] * data.u_tau[i][c];
                }
                p_a += data.u[i][r] * d_inv_u;
            }
            p_a += mat6_mul_motion(&i_a, &data.c[i]);
            // I^A_λ(i) += X_iᵀ I^a X_i;  p^A_λ(i) += X_iᵀ p^a
            let carried = data.x_up[i].transpose_apply_matrix(&i_a);
            data.i_a[parent] += carried;
            let p_parent = data.x_up[i].transpose_apply_force(&p_a);
            data.p_a[parent] += p_parent;
        }
    }

    // pass 3, outward: accelerations
    data.a[0] = Motion::new(Vec3::zeros(), -model.gravity);
    for i in 1..model.nbodies() {
        let joint = &model.joints[i];
        let dofs = model.v_range(i);
        // a'_i = X_i a_λ(i) + c_i
        let a_i = data.x_up[i].apply_motion(&data.a[model.parent[i]]) + data.c[i];
        // q̈_i = D_i⁻¹ (u_i - U_iᵀ a'_i)
        let nv_i = joint.nv();
        let mut rhs = [0.0; 6];
        for (k, value) in rhs.iter_mut().enumerate().take(nv_i) {
            *value = data.u_tau[i][k] - a_i.dot(&data.u[i][k]);
        }
        let mut a_i = a_i;
        for (r, dof) in dofs.enumerate() {
            let qdd: f64 = (0..nv_i).map(|c| data.d_inv[i][(r, c)] * rhs[c]).sum();
            data.qdd[dof] = qdd;
            // a_i = a'_i + S_i q̈_i
            a_i += joint.subspace_column(r) * qdd;
        }
        data.a[i] = a_i;
    }
    Ok(&data.qdd)
}

/// Inverts the leading `n` x `n` block of `m` in place by Gauss–Jordan elimination without
/// pivoting (the block, `D_i`, is symmetric positive definite). Returns false if a pivot is not
/// positive relative to the block's largest diagonal entry ([`SINGULARITY_TOLERANCE`]).
fn invert_leading_block(m: &mut Mat6, n: usize) -> bool {
    let scale = (0..n).map(|k| m[(k, k)]).fold(0.0, f64::max);
    for k in 0..n {
        let pivot = m[(k, k)];
        if pivot.is_nan() || pivot <= SINGULARITY_TOLERANCE * scale || pivot <= 0.0 {
            return false;
        }
        m[(k, k)] = 1.0;
        for j in 0..n {
            m[(k, j)] /= pivot;
        }
        for i in 0..n {
            if i != k {
                let factor = m[(i, k)];
                m[(i, k)] = 0.0;
                for j in 0..n {
                    m[(i, j)] -= factor * m[(k, j)];
                }
            }
        }
    }
    true
}
