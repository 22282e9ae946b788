//! First-order derivatives of inverse and forward dynamics: ∂τ/∂q, ∂τ/∂q̇, ∂τ/∂q̈ = M of RNEA and
//! ∂q̈/∂q, ∂q̈/∂q̇, ∂q̈/∂τ = M⁻¹ of ABA, external forces included.
//!
//! Convention: a derivative with respect to q is taken in the tangent space of the configuration
//! Lie group, along right perturbations `q ⊕ δ` (δ in the child body's axes, as the joint's
//! velocity): ∂τ/∂q · δ = lim τ(q ⊕ εδ) − τ(q) / ε. On revolute and prismatic joints it is the
//! ordinary partial derivative; it is Pinocchio's convention for `computeRNEADerivatives`.
//!
//! Derivation (world coordinates, in the spirit of Carpentier & Mansard, "Analytical derivatives of
//! rigid body dynamics algorithms", RSS 2018; the formulas below are this file's own). Moving
//! coordinate j of body b (parent λ) by δ turns b's whole subtree by the world twist S_j δ, so a
//! quantity attached to it changes by S_j × (·) (S_j ×* for forces) — a rigid change that every
//! pairing S_kᵀ F within the subtree ignores — except where the subtree's motion comes from above b:
//! ```text
//!   ∂v_i/∂δ_j = S_j × v_i − u_j,               u_j = S_j × v_λ
//!   ∂a_i/∂δ_j = S_j × a_i − z_j − u_j × v_i,   z_j = S_j × a_λ − u_j × v_λ
//!   ∂v_i/∂q̇_j = S_j,  ∂a_i/∂q̇_j = S_j × v_i − u_j − u'_j,   u'_j = S_j × v_b
//! ```
//! for i in the subtree of b. With f_i = I_i a_i + v_i ×* I_i v_i and H(I, v) s = I (s × v) +
//! v ×* I s + s ×* I v = 2 B(I, v) s (B the Coriolis factor of `coriolis_matrix`), summing over a
//! subtree gives its composites I^C, H^C = 2 B^C (in the factored form of `CoriolisFactor`: no
//! 6×6 products) and F (all world coordinates):
//! ```text
//!   k in the subtree of b:   ∂τ_k/∂δ_j = −S_kᵀ (I^C_k z_j + H^C_k u_j)
//!                            ∂τ_k/∂q̇_j = S_kᵀ (H^C_k S_j − I^C_k (u_j + u'_j))
//!   k above b:               ∂τ_k/∂δ_j = S_kᵀ (S_j ×* F_b − I^C_b z_j − H^C_b u_j)
//!                            ∂τ_k/∂q̇_j = S_kᵀ (H^C_b S_j − I^C_b (u_j + u'_j))
//! ```
//! (I^C_k: the composite of k's body). ABA's derivatives follow from τ(q, q̇, FD(q, q̇, τ)) = τ:
//! ∂q̈/∂x = −M⁻¹ ∂τ/∂x at q̈ = FD(q, q̇, τ), and ∂q̈/∂τ = M⁻¹, solved with the Cholesky factor of
//! the M that the RNEA derivatives build anyway (no second recursion to maintain). Measured against
//! Pinocchio's dedicated recursion (benchmarks/README, "Derivatives") this O(n³) route is slower on
//! large trees: a direct recursion is the next step.
//! Cost: O(n · depth) for RNEA's, plus O(n³) for ABA's products with M⁻¹.

use crate::algo::aba::aba;
use crate::algo::crba::{add_composite_inertias, world_inertias_and_subspaces};
use crate::algo::minv::{cholesky_solve_mut, invert_mass_matrix};
use crate::algo::rnea::check_external_forces;
use crate::error::{check_vector, Result};
use crate::model::Model;
use crate::spatial::{CoriolisFactor, Force, Motion, Vec3};
use crate::Data;

/// ∂τ/∂q, ∂τ/∂q̇ and ∂τ/∂q̈ = M of τ = ID(q, q̇, q̈, f_ext), with τ itself: written into
/// `data.dtau_dq`, `data.dtau_dv`, `data.mass_matrix` and `data.tau`. `f_ext` as in `rnea` (one
/// force per moving body, in its frame; held fixed in the body as q moves). Also writes
/// `data.x_up`, `data.x_world`, `data.i_c`, `data.s_world`, `data.v_world`, `data.a_world`,
/// `data.f_world`, `data.coriolis_factors`, `data.motion_terms`.
pub fn rnea_derivatives(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    f_ext: Option<&[Force]>,
) -> Result<()> {
    model.check_configuration(q)?;
    check_vector("v", v, model.nv)?;
    check_vector("a", a, model.nv)?;
    if let Some(forces) = f_ext {
        check_external_forces(model, forces)?;
    }
    world_inertias_and_subspaces(model, data, q);

    // outward: world velocities and accelerations, the terms u, u', z, each body's force and B
    data.v_world[0] = Motion::ZERO;
    data.a_world[0] = Motion::new(Vec3::zeros(), -model.gravity);
    for i in 1..model.nbodies() {
        let parent = model.parent[i];
        let (v_parent, a_parent) = (data.v_world[parent], data.a_world[parent]);
        let (mut v_joint, mut a_joint) = (Motion::ZERO, Motion::ZERO);
        for dof in model.v_range(i) {
            v_joint += data.s_world[dof] * v[dof];
            a_joint += data.s_world[dof] * a[dof];
        }
        // v_i = v_λ + S q̇;  a_i = a_λ + S q̈ + v_i × S q̇
        let v_i = v_parent + v_joint;
        let a_i = a_parent + a_joint + v_i.cross_motion(&v_joint);
        for dof in model.v_range(i) {
            let s = data.s_world[dof];
            let u = s.cross_motion(&v_parent);
            data.motion_terms[dof] = [
                u,
                u + s.cross_motion(&v_i),
                s.cross_motion(&a_parent) - u.cross_motion(&v_parent),
            ];
        }
        // f_i = I_i a_i + v_i ×* I_i v_i − f_ext_i
        let inertia = data.i_c[i];
        let coriolis = CoriolisFactor::new(&inertia, &v_i);
        let mut f_i = inertia.mul_motion(&a_i) + v_i.cross_force(&coriolis.momentum);
        if let Some(forces) = f_ext {
            f_i -= data.x_world[i].transpose_apply_force(&forces[i - 1]);
        }
        data.coriolis_factors[i] = coriolis;
        (data.v_world[i], data.a_world[i], data.f_world[i]) = (v_i, a_i, f_i);
    }

    // composites, leaves to root: I^C, H^C and F of each subtree
    add_composite_inertias(model, data);
    for i in (1..model.nbodies()).rev() {
        let parent = model.parent[i];
        if parent != 0 {
            let (h, f) = (data.coriolis_factors[i], data.f_world[i]);
            data.coriolis_factors[parent] += h;
            data.f_world[parent] += f;
        }
    }

    // τ, M and both derivatives, one coordinate k of body i against the coordinates on its path
    data.dtau_dq.fill(0.0);
    data.dtau_dv.fill(0.0);
    data.mass_matrix.fill(0.0);
    for i in 1..model.nbodies() {
        let (composite, h_composite, f_i) =
            (data.i_c[i], data.coriolis_factors[i], data.f_world[i]);
        for k in model.v_range(i) {
            let s_k = data.s_world[k];
            let [u_k, w_k, z_k] = data.motion_terms[k];
            data.tau[k] = s_k.dot(&f_i);
            // I^C_i S_k and H^C_iᵀ S_k, for the rows of k
            let inertia_s = composite.mul_motion(&s_k);
            let h_transpose_s = h_composite.tr_mul_motion(&s_k);
            // S_k ×* F_i − I^C_i z_k − H^C_i u_k and H^C_i S_k − I^C_i (u_k + u'_k), for k's column
            let position_force = s_k.cross_force(&f_i)
                - composite.mul_motion(&z_k)
                - h_composite.mul_motion(&u_k);
            let velocity_force = h_composite.mul_motion(&s_k) - composite.mul_motion(&w_k);
            let mut j = i;
            while j != 0 {
                for c in model.v_range(j) {
                    let s_c = data.s_world[c];
                    let [u_c, w_c, z_c] = data.motion_terms[c];
                    // row k: i lies in the subtree of c's body
                    data.dtau_dq[(k, c)] = -(z_c.dot(&inertia_s) + u_c.dot(&h_transpose_s));
                    data.dtau_dv[(k, c)] = s_c.dot(&h_transpose_s) - w_c.dot(&inertia_s);
                    let m = s_c.dot(&inertia_s);
                    data.mass_matrix[(k, c)] = m;
                    data.mass_matrix[(c, k)] = m;
                    // column k: c's body lies strictly above i
                    if j != i {
                        data.dtau_dq[(c, k)] = s_c.dot(&position_force);
                        data.dtau_dv[(c, k)] = s_c.dot(&velocity_force);
                    }
                }
                j = model.parent[j];
            }
        }
    }

    // the rotors: armature · (q̈ + K(q̇) q̇) on each joint's own block
    for i in 1..model.nbodies() {
        let (joint, dofs) = (&model.joints[i], model.v_range(i));
        let v_i = &v[dofs.clone()];
        for (r, row) in dofs.clone().enumerate() {
            let armature = model.armature[row];
            let rotor_rate: f64 = (0..v_i.len())
                .map(|c| joint.rotor_velocity_term(r, c, v_i) * v_i[c])
                .sum();
            data.tau[row] += armature * (a[row] + rotor_rate);
            data.mass_matrix[(row, row)] += armature;
            for (c, column) in dofs.clone().enumerate() {
                data.dtau_dv[(row, column)] += armature * joint.rotor_velocity_jacobian(r, c, v_i);
            }
        }
    }
    Ok(())
}

/// ∂q̈/∂q, ∂q̈/∂q̇ and ∂q̈/∂τ = M⁻¹ of q̈ = FD(q, q̇, τ, f_ext), with q̈ itself: written into
/// `data.dqdd_dq`, `data.dqdd_dv`, `data.mass_matrix_inverse` and `data.qdd`. Also writes what
/// `aba` and `rnea_derivatives` write, and `data.cholesky`.
pub fn aba_derivatives(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    f_ext: Option<&[Force]>,
) -> Result<()> {
    aba(model, data, q, v, tau, f_ext)?;
    let qdd = std::mem::take(&mut data.qdd);
    let linearised = rnea_derivatives(model, data, q, v, qdd.as_slice(), f_ext);
    data.qdd = qdd;
    linearised?;
    invert_mass_matrix(model, data)?;
    // ∂q̈/∂x = −M⁻¹ ∂τ/∂x, solved with M's Cholesky factor
    for (derivative, tau_derivative) in [
        (&mut data.dqdd_dq, &data.dtau_dq),
        (&mut data.dqdd_dv, &data.dtau_dv),
    ] {
        derivative.copy_from(tau_derivative);
        derivative.neg_mut();
        cholesky_solve_mut(&data.cholesky, derivative);
    }
    Ok(())
}
