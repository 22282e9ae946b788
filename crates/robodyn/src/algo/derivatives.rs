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
//! ∂q̈/∂x = −M⁻¹ ∂τ/∂x at q̈ = FD(q, q̇, τ), and ∂q̈/∂τ = M⁻¹. The same passes give q̈ itself: the
//! velocity terms do not depend on q̈, the composites give M, the acceleration terms at q̈ = 0
//! give the bias b, and q̈ = M⁻¹ (τ − b) with M's tree-sparse factors (`ltdl`), which then solve
//! for all 3n columns of [−∂τ/∂q, −∂τ/∂q̇, 1] at once, a row update at a time.
//! Cost: O(n · depth) for RNEA's; ABA's add O(n Σ depth) for the solves.

use crate::algo::crba::{
    add_composite_inertias, composite_mass_matrix, world_inertias_and_subspaces,
};
use crate::algo::ltdl::{factor_mass_matrix, solve_rows};
use crate::algo::rnea::check_external_forces;
use crate::error::{check_length, check_vector, Result};
use crate::model::Model;
use crate::spatial::{CoriolisFactor, Force, Motion, Vec3};
use crate::Data;
use nalgebra::DMatrix;

/// ∂τ/∂q, ∂τ/∂q̇ and ∂τ/∂q̈ = M of τ = ID(q, q̇, q̈, f_ext), with τ itself: written into
/// `data.dtau_dq`, `data.dtau_dv`, `data.mass_matrix` and `data.tau`. `f_ext` as in `rnea` (one
/// force per moving body, in its frame; held fixed in the body as q moves). Also writes
/// `data.x_up`, `data.x_world`, `data.i_c`, `data.s_world`, `data.v_world`, `data.a_world`,
/// `data.i_world`, `data.f_velocity`, `data.f_world`, `data.coriolis_factors`,
/// `data.motion_terms`.
pub fn rnea_derivatives(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    f_ext: Option<&[Force]>,
) -> Result<()> {
    let mut matrices = Matrices(
        std::mem::take(&mut data.dtau_dq),
        std::mem::take(&mut data.dtau_dv),
    );
    matrices.0.as_mut_slice().fill(0.0);
    matrices.1.as_mut_slice().fill(0.0);
    let result = rnea_derivative_passes(model, data, (q, v, a, f_ext), &mut matrices);
    (data.dtau_dq, data.dtau_dv) = (matrices.0, matrices.1);
    result
}

/// (q, q̇, q̈ or τ, f_ext): the state and inputs of a dynamics algorithm.
pub type DynamicsState<'a> = (&'a [f64], &'a [f64], &'a [f64], Option<&'a [Force]>);

/// [`rnea_derivatives`] with ∂τ/∂q and ∂τ/∂q̇ written row-major (nv × nv each) into `dtau_dq` and
/// `dtau_dv` instead of `data.dtau_dq` and `data.dtau_dv`: for a caller that hands the results on
/// row by row (NumPy), without a transpose.
pub fn rnea_derivatives_row_major(
    model: &Model,
    data: &mut Data,
    (q, v, a, f_ext): DynamicsState,
    dtau_dq: &mut [f64],
    dtau_dv: &mut [f64],
) -> Result<()> {
    let nv = model.nv;
    check_length("dtau_dq", dtau_dq.len(), nv * nv)?;
    check_length("dtau_dv", dtau_dv.len(), nv * nv)?;
    dtau_dq.fill(0.0);
    dtau_dv.fill(0.0);
    let mut rows = RowMajor {
        by_q: dtau_dq,
        by_v: dtau_dv,
        nv,
    };
    rnea_derivative_passes(model, data, (q, v, a, f_ext), &mut rows)
}

/// The passes of [`rnea_derivatives`], the two derivatives added into `out` (zeroed).
fn rnea_derivative_passes(
    model: &Model,
    data: &mut Data,
    (q, v, a, f_ext): DynamicsState,
    out: &mut impl TorqueDerivatives,
) -> Result<()> {
    check_arguments(model, q, v, ("a", a), f_ext)?;
    velocity_terms(model, data, q, v, f_ext);
    acceleration_terms(model, data, Some(a));
    derivative_products(model, data, v, out);
    add_rotor_torques(model, data, v, Some(a));
    Ok(())
}

/// ∂q̈/∂q, ∂q̈/∂q̇ and ∂q̈/∂τ = M⁻¹ of q̈ = FD(q, q̇, τ, f_ext), with q̈ itself: written into
/// `data.dqdd_dq`, `data.dqdd_dv`, `data.mass_matrix_inverse` and `data.qdd`, and row by row
/// into `data.derivative_rows` (see [`aba_derivative_rows`]). Also writes what
/// `rnea_derivatives` writes (at q̈) except `data.dtau_dq` and `data.dtau_dv`, and
/// `data.mass_matrix_factor`.
pub fn aba_derivatives(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    f_ext: Option<&[Force]>,
) -> Result<()> {
    aba_derivative_rows(model, data, (q, v, tau, f_ext))?;
    // into the matrices, column by column as they are stored
    let (rows, nv) = (&data.derivative_rows, model.nv);
    let width = 3 * nv;
    for j in 0..nv {
        let (mut by_q, mut by_v) = (data.dqdd_dq.column_mut(j), data.dqdd_dv.column_mut(j));
        for i in 0..nv {
            by_q[i] = rows[i * width + j];
            by_v[i] = rows[i * width + nv + j];
        }
        let mut inverse = data.mass_matrix_inverse.column_mut(j);
        for i in 0..nv {
            inverse[i] = rows[i * width + 2 * nv + j];
        }
    }
    Ok(())
}

/// [`aba_derivatives`] with the results only in `data.derivative_rows`: row i is
/// [∂q̈_i/∂q, ∂q̈_i/∂q̇, (M⁻¹)_i] (nv rows of 3 nv), for a caller that hands them on row by row
/// (NumPy), without filling the three matrices.
pub fn aba_derivative_rows(
    model: &Model,
    data: &mut Data,
    (q, v, tau, f_ext): DynamicsState,
) -> Result<()> {
    check_arguments(model, q, v, ("tau", tau), f_ext)?;
    velocity_terms(model, data, q, v, f_ext);

    // q̈ = M⁻¹ (τ − b), b = ID(q, q̇, 0)
    acceleration_terms(model, data, None);
    for i in 1..model.nbodies() {
        for k in model.v_range(i) {
            data.tau[k] = data.s_world[k].dot(&data.f_world[i]);
        }
    }
    add_rotor_torques(model, data, v, None);
    let mut mass_matrix = std::mem::take(&mut data.mass_matrix);
    composite_mass_matrix(model, data, mass_matrix.as_mut_slice());
    data.mass_matrix = mass_matrix;
    factor_mass_matrix(model, data)?;
    for (qdd, (applied, bias)) in data.qdd.iter_mut().zip(tau.iter().zip(data.tau.iter())) {
        *qdd = applied - bias;
    }
    let mut qdd = std::mem::take(&mut data.qdd);
    solve_rows(model, data, qdd.as_mut_slice());

    // [∂q̈/∂q, ∂q̈/∂q̇, ∂q̈/∂τ] = M⁻¹ [−∂τ/∂q, −∂τ/∂q̇, 1] at q̈, solved row by row
    acceleration_terms(model, data, Some(qdd.as_slice()));
    let nv = model.nv;
    let mut rows = NegatedRows {
        rows: std::mem::take(&mut data.derivative_rows),
        nv,
    };
    rows.rows.fill(0.0);
    derivative_products(model, data, v, &mut rows);
    add_rotor_torques(model, data, v, Some(qdd.as_slice()));
    data.qdd = qdd;
    let (mut rows, width) = (rows.rows, 3 * nv);
    for k in 0..nv {
        rows[k * width + 2 * nv + k] = 1.0;
    }
    solve_rows(model, data, &mut rows);
    data.derivative_rows = rows;
    Ok(())
}

/// Shapes and finiteness of (q, v, a or τ, f_ext).
fn check_arguments(
    model: &Model,
    q: &[f64],
    v: &[f64],
    (name, x): (&str, &[f64]),
    f_ext: Option<&[Force]>,
) -> Result<()> {
    model.check_configuration(q)?;
    check_vector("v", v, model.nv)?;
    check_vector(name, x, model.nv)?;
    if let Some(forces) = f_ext {
        check_external_forces(model, forces)?;
    }
    Ok(())
}

/// What does not depend on q̈: poses, world inertias (each body's in `data.i_world`, the
/// subtrees' in `data.i_c`) and subspaces, velocities, the terms u and u + u', each body's
/// velocity-product force less its external force, and the subtrees' H^C.
fn velocity_terms(model: &Model, data: &mut Data, q: &[f64], v: &[f64], f_ext: Option<&[Force]>) {
    world_inertias_and_subspaces(model, data, q);
    data.v_world[0] = Motion::ZERO;
    for i in 1..model.nbodies() {
        let v_parent = data.v_world[model.parent[i]];
        let mut v_joint = Motion::ZERO;
        for dof in model.v_range(i) {
            v_joint += data.s_world[dof] * v[dof];
        }
        // v_i = v_λ + S q̇
        let v_i = v_parent + v_joint;
        for dof in model.v_range(i) {
            let s = data.s_world[dof];
            let u = s.cross_motion(&v_parent);
            data.motion_terms[dof][0] = u;
            data.motion_terms[dof][1] = u + s.cross_motion(&v_i);
        }
        // v_i ×* I_i v_i − f_ext_i
        let inertia = data.i_c[i];
        let coriolis = CoriolisFactor::new(&inertia, &v_i);
        let mut f_velocity = v_i.cross_force(&coriolis.momentum);
        if let Some(forces) = f_ext {
            f_velocity -= data.x_world[i].transpose_apply_force(&forces[i - 1]);
        }
        data.i_world[i] = inertia;
        data.f_velocity[i] = f_velocity;
        data.coriolis_factors[i] = coriolis;
        data.v_world[i] = v_i;
    }
    // composites, leaves to root
    add_composite_inertias(model, data);
    for i in (1..model.nbodies()).rev() {
        let parent = model.parent[i];
        if parent != 0 {
            let h = data.coriolis_factors[i];
            data.coriolis_factors[parent] += h;
        }
    }
}

/// What q̈ (zero for `None`) adds: accelerations, the terms z, each body's force
/// f_i = I_i a_i + v_i ×* I_i v_i − f_ext_i and the subtrees' sums F in `data.f_world`.
fn acceleration_terms(model: &Model, data: &mut Data, a: Option<&[f64]>) {
    data.a_world[0] = Motion::new(Vec3::zeros(), -model.gravity);
    for i in 1..model.nbodies() {
        let parent = model.parent[i];
        let (v_parent, a_parent, v_i) =
            (data.v_world[parent], data.a_world[parent], data.v_world[i]);
        let mut a_joint = Motion::ZERO;
        if let Some(a) = a {
            for dof in model.v_range(i) {
                a_joint += data.s_world[dof] * a[dof];
            }
        }
        // a_i = a_λ + S q̈ + v_i × S q̇, with S q̇ = v_i − v_λ
        let a_i = a_parent + a_joint + v_i.cross_motion(&(v_i - v_parent));
        for dof in model.v_range(i) {
            let [u, ..] = data.motion_terms[dof];
            // z_k = S_k × a_λ − u_k × v_λ
            data.motion_terms[dof][2] =
                data.s_world[dof].cross_motion(&a_parent) - u.cross_motion(&v_parent);
        }
        data.a_world[i] = a_i;
        data.f_world[i] = data.i_world[i].mul_motion(&a_i) + data.f_velocity[i];
    }
    for i in (1..model.nbodies()).rev() {
        let parent = model.parent[i];
        if parent != 0 {
            let f = data.f_world[i];
            data.f_world[parent] += f;
        }
    }
}

/// Where the entries of ∂τ/∂q and ∂τ/∂q̇ go, added to a zeroed buffer (a joint's own block gets
/// the recursion's term and its rotor's).
trait TorqueDerivatives {
    fn add(&mut self, row: usize, column: usize, by_q: f64, by_v: f64);
}

/// Into two nv × nv matrices: `data.dtau_dq`, `data.dtau_dv`.
struct Matrices(DMatrix<f64>, DMatrix<f64>);

impl TorqueDerivatives for Matrices {
    #[inline(always)]
    fn add(&mut self, row: usize, column: usize, by_q: f64, by_v: f64) {
        // column-major storage
        let index = row + column * self.0.nrows();
        self.0.as_mut_slice()[index] += by_q;
        self.1.as_mut_slice()[index] += by_v;
    }
}

/// Into two nv × nv row-major buffers.
struct RowMajor<'a> {
    by_q: &'a mut [f64],
    by_v: &'a mut [f64],
    nv: usize,
}

impl TorqueDerivatives for RowMajor<'_> {
    #[inline(always)]
    fn add(&mut self, row: usize, column: usize, by_q: f64, by_v: f64) {
        let index = row * self.nv + column;
        self.by_q[index] += by_q;
        self.by_v[index] += by_v;
    }
}

/// Negated into the rows [−∂τ/∂q, −∂τ/∂q̇, ·] (nv rows of 3 nv) that the ABA derivatives solve.
struct NegatedRows {
    rows: Vec<f64>,
    nv: usize,
}

impl TorqueDerivatives for NegatedRows {
    #[inline(always)]
    fn add(&mut self, row: usize, column: usize, by_q: f64, by_v: f64) {
        let start = row * 3 * self.nv + column;
        self.rows[start] -= by_q;
        self.rows[start + self.nv] -= by_v;
    }
}

/// τ, M and both derivatives from the terms and composites above: one coordinate k of body i
/// against the coordinates on its path to the root; then the rotors' armature on M and their
/// velocity term's Jacobian on ∂τ/∂q̇.
fn derivative_products(
    model: &Model,
    data: &mut Data,
    v: &[f64],
    out: &mut impl TorqueDerivatives,
) {
    let nv = model.nv;
    let mass_matrix = data.mass_matrix.as_mut_slice();
    mass_matrix.fill(0.0);
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
            let position_force =
                s_k.cross_force(&f_i) - composite.mul_motion(&z_k) - h_composite.mul_motion(&u_k);
            let velocity_force = h_composite.mul_motion(&s_k) - composite.mul_motion(&w_k);
            let mut j = i;
            while j != 0 {
                for c in model.v_range(j) {
                    let s_c = data.s_world[c];
                    let [u_c, w_c, z_c] = data.motion_terms[c];
                    // row k: i lies in the subtree of c's body
                    out.add(
                        k,
                        c,
                        -(z_c.dot(&inertia_s) + u_c.dot(&h_transpose_s)),
                        s_c.dot(&h_transpose_s) - w_c.dot(&inertia_s),
                    );
                    // column-major storage: M[k, c] at k + c nv
                    let m = s_c.dot(&inertia_s);
                    mass_matrix[k + c * nv] = m;
                    mass_matrix[c + k * nv] = m;
                    // column k: c's body lies strictly above i
                    if j != i {
                        out.add(c, k, s_c.dot(&position_force), s_c.dot(&velocity_force));
                    }
                }
                j = model.parent[j];
            }
        }
    }
    for i in 1..model.nbodies() {
        let (joint, dofs) = (&model.joints[i], model.v_range(i));
        let v_i = &v[dofs.clone()];
        for (r, row) in dofs.clone().enumerate() {
            let armature = model.armature[row];
            mass_matrix[row + row * nv] += armature;
            for (c, column) in dofs.clone().enumerate() {
                let by_v = armature * joint.rotor_velocity_jacobian(r, c, v_i);
                out.add(row, column, 0.0, by_v);
            }
        }
    }
}

/// The rotors' torque armature · (q̈ + K(q̇) q̇) added to τ on each joint's own coordinates (q̈ = 0
/// for `None`).
fn add_rotor_torques(model: &Model, data: &mut Data, v: &[f64], a: Option<&[f64]>) {
    for i in 1..model.nbodies() {
        let (joint, dofs) = (&model.joints[i], model.v_range(i));
        let v_i = &v[dofs.clone()];
        for (r, row) in dofs.clone().enumerate() {
            let rotor_rate: f64 = (0..v_i.len())
                .map(|c| joint.rotor_velocity_term(r, c, v_i) * v_i[c])
                .sum();
            data.tau[row] += model.armature[row] * (a.map_or(0.0, |a| a[row]) + rotor_rate);
        }
    }
}
