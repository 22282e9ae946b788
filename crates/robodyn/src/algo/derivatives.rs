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
    add_composites, mass_matrix_of_composites, world_inertias_of, CompositeBuffers,
};
use crate::algo::ltdl::{
    factor_into, singular_mass_matrix, solve_rows_in, solve_rows_with, Sweeps,
};
use crate::algo::rnea::check_external_forces;
use crate::dispatch::multiversion;
use crate::error::{check_vector, Result};
use crate::model::Model;
use crate::spatial::{
    splat_vector, zero_vector, CoriolisFactor, Force, Inertia, Motion, Real, Transform,
};
use crate::Data;
use destinations::{Matrices, NegatedRows};
use std::mem::take;

mod destinations;

pub use destinations::DerivativesInto;
pub(crate) use destinations::{RowMajor, TorqueDerivatives};

/// ∂τ/∂q, ∂τ/∂q̇ and ∂τ/∂q̈ = M of τ = ID(q, q̇, q̈, f_ext), with τ itself: the two
/// derivatives written where `into` says, M into `data.mass_matrix` and τ into `data.tau`.
/// `f_ext` as in `rnea` (one force per moving body, in its frame; held fixed in the body as q
/// moves). Also writes `data.x_up`, `data.x_world`, `data.i_c`, `data.s_world`, `data.v_world`,
/// `data.a_world`, `data.i_world`, `data.f_velocity`, `data.f_world`, `data.coriolis_factors`,
/// `data.motion_terms`.
pub fn rnea_derivatives(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    f_ext: Option<&[Force]>,
    into: DerivativesInto,
) -> Result<()> {
    into.check(model, ["dtau_dq", "dtau_dv"])?;
    check_arguments(model, q, v, ("a", a), f_ext)?;
    let (state, nv) = ((q, v, a, f_ext), model.nv);
    match into {
        DerivativesInto::Data => {
            let (by_q, by_v) = (take(&mut data.dtau_dq), take(&mut data.dtau_dv));
            let mut matrices = Matrices(by_q, by_v);
            matrices.0.as_mut_slice().fill(0.0);
            matrices.1.as_mut_slice().fill(0.0);
            one_state_derivatives(
                model,
                &mut DerivativeBuffers::of(data),
                state,
                &mut matrices,
            );
            (data.dtau_dq, data.dtau_dv) = (matrices.0, matrices.1);
        }
        DerivativesInto::RowMajor { by_q, by_v } => {
            by_q.fill(0.0);
            by_v.fill(0.0);
            let mut rows = RowMajor { by_q, by_v, nv };
            one_state_derivatives(model, &mut DerivativeBuffers::of(data), state, &mut rows);
        }
        DerivativesInto::Stacked(out) => {
            out.fill(0.0);
            let (by_q, rest) = out.split_at_mut(nv * nv);
            let (by_v, by_a) = rest.split_at_mut(nv * nv);
            let mut rows = RowMajor { by_q, by_v, nv };
            one_state_derivatives(model, &mut DerivativeBuffers::of(data), state, &mut rows);
            // M is mirrored: its column-major storage is its row-major one
            by_a.copy_from_slice(data.mass_matrix.as_slice());
        }
    }
    Ok(())
}

/// (q, q̇, q̈ or τ, f_ext): the state and inputs of a dynamics algorithm (in `f64`, or lanes).
pub type DynamicsState<'a, S = f64> = (&'a [S], &'a [S], &'a [S], Option<&'a [Force<S>]>);

/// The derivative passes on checked inputs, in `f64` or lanes: τ, M and ∂τ/∂q, ∂τ/∂q̇ into `out`.
#[inline(always)]
pub(crate) fn derivative_passes<S: Real>(
    model: &Model,
    buffers: &mut DerivativeBuffers<S>,
    (q, v, a, f_ext): DynamicsState<S>,
    out: &mut impl TorqueDerivatives<S>,
) {
    velocity_terms(model, buffers, q, v, f_ext);
    acceleration_terms(model, buffers, Some(a));
    derivative_products::<_, true>(model, buffers, v, out);
    add_rotor_torques(model, buffers, v, Some(a));
}

/// What the derivative passes read and write (see `Data`'s fields of the same meaning): one
/// state's, borrowed from [`Data`], or several states' in lanes ([`crate::algo::lanes`]).
pub(crate) struct DerivativeBuffers<'b, S> {
    pub x_up: &'b mut [Transform<S>],
    pub x_world: &'b mut [Transform<S>],
    pub i_c: &'b mut [Inertia<S>],
    pub s_world: &'b mut [Motion<S>],
    pub v_world: &'b mut [Motion<S>],
    pub a_world: &'b mut [Motion<S>],
    pub motion_terms: &'b mut [[Motion<S>; 3]],
    pub i_world: &'b mut [Inertia<S>],
    pub f_velocity: &'b mut [Force<S>],
    pub f_world: &'b mut [Force<S>],
    pub coriolis_factors: &'b mut [CoriolisFactor<S>],
    pub tau: &'b mut [S],
    pub mass_matrix: &'b mut [S],
}

impl<'b> DerivativeBuffers<'b, f64> {
    /// `data`'s fields.
    fn of(data: &'b mut Data) -> Self {
        Self::with_solve(data).0
    }

    /// `data`'s fields, and those the solves of ABA's derivatives write.
    fn with_solve(data: &'b mut Data) -> (Self, SolveBuffers<'b, f64>) {
        let solve = SolveBuffers {
            factor: data.mass_matrix_factor.as_mut_slice(),
            qdd: data.qdd.as_mut_slice(),
            rows: &mut data.derivative_rows,
        };
        let buffers = DerivativeBuffers {
            x_up: &mut data.x_up,
            x_world: &mut data.x_world,
            i_c: &mut data.i_c,
            s_world: &mut data.s_world,
            v_world: &mut data.v_world,
            a_world: &mut data.a_world,
            motion_terms: &mut data.motion_terms,
            i_world: &mut data.i_world,
            f_velocity: &mut data.f_velocity,
            f_world: &mut data.f_world,
            coriolis_factors: &mut data.coriolis_factors,
            tau: data.tau.as_mut_slice(),
            mass_matrix: data.mass_matrix.as_mut_slice(),
        };
        (buffers, solve)
    }
}

/// ∂q̈/∂q, ∂q̈/∂q̇ and ∂q̈/∂τ = M⁻¹ of q̈ = FD(q, q̇, τ, f_ext), with q̈ itself: the derivatives
/// written where `into` says ([`DerivativesInto::Data`]: `data.dqdd_dq`, `data.dqdd_dv`,
/// `data.mass_matrix_inverse`), q̈ into `data.qdd`, and in every case row by row into
/// `data.derivative_rows` (row i is [∂q̈_i/∂q, ∂q̈_i/∂q̇, (M⁻¹)_i], nv rows of 3 nv). Also writes
/// what `rnea_derivatives` writes (at q̈) except its two derivatives, and
/// `data.mass_matrix_factor`.
pub fn aba_derivatives(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    f_ext: Option<&[Force]>,
    into: DerivativesInto,
) -> Result<()> {
    into.check(model, ["dqdd_dq", "dqdd_dv"])?;
    check_arguments(model, q, v, ("tau", tau), f_ext)?;
    let (mut b, mut solve) = DerivativeBuffers::with_solve(data);
    one_state_aba_right_sides(model, &mut b, &mut solve, (q, v, tau, f_ext))
        .map_err(|()| singular_mass_matrix())?;
    solve_rows_in(model, solve.factor, solve.rows, Sweeps::Both);
    into.copy_rows(data);
    Ok(())
}

/// What the ABA derivatives solve with, in `f64` or lanes: M's factors (column-major), q̈, and
/// the rows [∂q̈/∂q, ∂q̈/∂q̇, M⁻¹] (nv rows of 3 nv).
pub(crate) struct SolveBuffers<'b, S> {
    pub factor: &'b mut [S],
    pub qdd: &'b mut [S],
    pub rows: &'b mut [S],
}

multiversion! {
    /// [`derivative_passes`] of one state, built for AVX2 and FMA as well ([`crate::dispatch`]).
    #[inline(never)]
    fn one_state_derivatives(
        model: &Model,
        b: &mut DerivativeBuffers<f64>,
        state: DynamicsState,
        out: &mut impl TorqueDerivatives<f64>,
    ) {
        one_state_derivatives_avx2 for ["avx2", "fma"] => { derivative_passes(model, b, state, out) }
        baseline => { derivative_passes(model, b, state, out) }
    }
}

multiversion! {
    /// [`aba_derivative_right_sides`] of one state, built for AVX2 and FMA as well
    /// ([`crate::dispatch`]); the solve of the rows is dispatched on its own, since AVX-512 serves
    /// its long rows.
    #[inline(never)]
    fn one_state_aba_right_sides(
        model: &Model,
        b: &mut DerivativeBuffers<f64>,
        solve: &mut SolveBuffers<f64>,
        state: DynamicsState,
    ) -> std::result::Result<(), ()> {
        one_state_aba_right_sides_avx2 for ["avx2", "fma"] => {
            aba_derivative_right_sides(model, b, solve, state)
        }
        baseline => { aba_derivative_right_sides(model, b, solve, state) }
    }
}

/// The passes of [`aba_derivative_rows`] on checked inputs, in `f64` or lanes (the same
/// operations in every lane, so each lane equals the one-state call bit for bit); an error
/// where a lane's M is refused.
#[inline(always)]
pub(crate) fn aba_derivative_passes<S: Real>(
    model: &Model,
    b: &mut DerivativeBuffers<S>,
    mut solve: SolveBuffers<S>,
    state: DynamicsState<S>,
) -> std::result::Result<(), ()> {
    aba_derivative_right_sides(model, b, &mut solve, state)?;
    solve_rows_with(model, solve.factor, solve.rows, Sweeps::Both);
    Ok(())
}

/// q̈, M's factors and the right-hand sides [−∂τ/∂q, −∂τ/∂q̇, 1] at q̈ in `solve.rows`, which
/// M⁻¹ then turns into [∂q̈/∂q, ∂q̈/∂q̇, ∂q̈/∂τ]; an error where a lane's M is refused.
#[inline(always)]
fn aba_derivative_right_sides<S: Real>(
    model: &Model,
    b: &mut DerivativeBuffers<S>,
    solve: &mut SolveBuffers<S>,
    (q, v, tau, f_ext): DynamicsState<S>,
) -> std::result::Result<(), ()> {
    velocity_terms(model, b, q, v, f_ext);
    // q̈ = M⁻¹ (τ − b), b = ID(q, q̇, 0)
    acceleration_terms(model, b, None);
    joint_torques(model, b);
    add_rotor_torques(model, b, v, None);
    mass_matrix_of_composites(model, b.i_c, b.s_world, b.mass_matrix);
    factor_into(model, b.mass_matrix, solve.factor)?;
    for (qdd, (applied, bias)) in solve.qdd.iter_mut().zip(tau.iter().zip(b.tau.iter())) {
        *qdd = *applied - *bias;
    }
    solve_rows_with(model, solve.factor, solve.qdd, Sweeps::Both);
    // [∂q̈/∂q, ∂q̈/∂q̇, ∂q̈/∂τ] = M⁻¹ [−∂τ/∂q, −∂τ/∂q̇, 1] at q̈: the right-hand sides
    let nv = model.nv;
    solve.rows.fill(S::splat(0.0));
    let mut negated = NegatedRows {
        rows: &mut *solve.rows,
        nv,
    };
    acceleration_terms(model, b, Some(&*solve.qdd));
    derivative_products::<_, false>(model, b, v, &mut negated);
    add_rotor_torques(model, b, v, Some(&*solve.qdd));
    add_identity(solve.rows, nv);
    Ok(())
}

/// τ_k = S_kᵀ F_i for each coordinate k of each body i.
#[inline(always)]
fn joint_torques<S: Real>(model: &Model, b: &mut DerivativeBuffers<S>) {
    for i in 1..model.nbodies() {
        for k in model.v_range(i) {
            b.tau[k] = b.s_world[k].dot(&b.f_world[i]);
        }
    }
}

/// The identity's 1 in the last third of each of the nv rows of 3 nv.
#[inline(always)]
fn add_identity<S: Real>(rows: &mut [S], nv: usize) {
    for k in 0..nv {
        rows[k * 3 * nv + 2 * nv + k] = S::splat(1.0);
    }
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

/// What does not depend on q̈: poses, world inertias (each body's in `i_world`, the subtrees'
/// in `i_c`) and subspaces, velocities, the terms u and u + u', each body's velocity-product
/// force less its external force, and the subtrees' H^C.
#[inline(always)]
fn velocity_terms<S: Real>(
    model: &Model,
    b: &mut DerivativeBuffers<S>,
    q: &[S],
    v: &[S],
    f_ext: Option<&[Force<S>]>,
) {
    let composites = CompositeBuffers {
        x_up: b.x_up,
        x_world: b.x_world,
        composites: b.i_c,
        subspaces: b.s_world,
    };
    world_inertias_of(model, q, composites);
    b.v_world[0] = Motion::zeros();
    for i in 1..model.nbodies() {
        let v_parent = b.v_world[model.parent[i]];
        let mut v_joint = Motion::zeros();
        for dof in model.v_range(i) {
            v_joint += b.s_world[dof] * v[dof];
        }
        // v_i = v_λ + S q̇
        let v_i = v_parent + v_joint;
        for dof in model.v_range(i) {
            let s = b.s_world[dof];
            let u = s.cross_motion(&v_parent);
            b.motion_terms[dof][0] = u;
            b.motion_terms[dof][1] = u + s.cross_motion(&v_i);
        }
        // v_i ×* I_i v_i − f_ext_i
        let inertia = b.i_c[i];
        let coriolis = CoriolisFactor::new(&inertia, &v_i);
        let mut f_velocity = v_i.cross_force(&coriolis.momentum);
        if let Some(forces) = f_ext {
            f_velocity -= b.x_world[i].transpose_apply_force(&forces[i - 1]);
        }
        b.i_world[i] = inertia;
        b.f_velocity[i] = f_velocity;
        b.coriolis_factors[i] = coriolis;
        b.v_world[i] = v_i;
    }
    // composites, leaves to root
    add_composites(model, b.i_c);
    for i in (1..model.nbodies()).rev() {
        let parent = model.parent[i];
        if parent != 0 {
            let h = b.coriolis_factors[i];
            b.coriolis_factors[parent] += h;
        }
    }
}

/// What q̈ (zero for `None`) adds: accelerations, the terms z, each body's force
/// f_i = I_i a_i + v_i ×* I_i v_i − f_ext_i and the subtrees' sums F in `f_world`.
#[inline(always)]
fn acceleration_terms<S: Real>(model: &Model, b: &mut DerivativeBuffers<S>, a: Option<&[S]>) {
    b.a_world[0] = Motion::new(zero_vector(), -splat_vector::<S>(&model.gravity));
    for i in 1..model.nbodies() {
        let parent = model.parent[i];
        let (v_parent, a_parent, v_i) = (b.v_world[parent], b.a_world[parent], b.v_world[i]);
        let mut a_joint = Motion::zeros();
        if let Some(a) = a {
            for dof in model.v_range(i) {
                a_joint += b.s_world[dof] * a[dof];
            }
        }
        // a_i = a_λ + S q̈ + v_i × S q̇, with S q̇ = v_i − v_λ
        let a_i = a_parent + a_joint + v_i.cross_motion(&(v_i - v_parent));
        for dof in model.v_range(i) {
            let [u, ..] = b.motion_terms[dof];
            // z_k = S_k × a_λ − u_k × v_λ
            b.motion_terms[dof][2] =
                b.s_world[dof].cross_motion(&a_parent) - u.cross_motion(&v_parent);
        }
        b.a_world[i] = a_i;
        b.f_world[i] = b.i_world[i].mul_motion(&a_i) + b.f_velocity[i];
    }
    for i in (1..model.nbodies()).rev() {
        let parent = model.parent[i];
        if parent != 0 {
            let f = b.f_world[i];
            b.f_world[parent] += f;
        }
    }
}

/// τ, M (when `MASS_MATRIX`: the ABA derivatives have it already) and both derivatives from the
/// terms and composites above: one coordinate k of body i against the coordinates on its path to
/// the root; then the rotors' armature on M and their velocity term's Jacobian on ∂τ/∂q̇.
#[inline(always)]
fn derivative_products<S: Real, const MASS_MATRIX: bool>(
    model: &Model,
    b: &mut DerivativeBuffers<S>,
    v: &[S],
    out: &mut impl TorqueDerivatives<S>,
) {
    let nv = model.nv;
    let zero = S::splat(0.0);
    let mass_matrix = &mut *b.mass_matrix;
    if MASS_MATRIX {
        mass_matrix.fill(zero);
    }
    for i in 1..model.nbodies() {
        let (composite, h_composite, f_i) = (b.i_c[i], b.coriolis_factors[i], b.f_world[i]);
        for k in model.v_range(i) {
            let s_k = b.s_world[k];
            let [u_k, w_k, z_k] = b.motion_terms[k];
            b.tau[k] = s_k.dot(&f_i);
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
                    let s_c = b.s_world[c];
                    let [u_c, w_c, z_c] = b.motion_terms[c];
                    // row k: i lies in the subtree of c's body
                    out.add(
                        k,
                        c,
                        -(z_c.dot(&inertia_s) + u_c.dot(&h_transpose_s)),
                        s_c.dot(&h_transpose_s) - w_c.dot(&inertia_s),
                    );
                    // column-major storage: M[k, c] at k + c nv
                    if MASS_MATRIX {
                        let m = s_c.dot(&inertia_s);
                        mass_matrix[k + c * nv] = m;
                        mass_matrix[c + k * nv] = m;
                    }
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
            let armature = S::splat(model.armature[row]);
            if MASS_MATRIX {
                mass_matrix[row + row * nv] += armature;
            }
            for (c, column) in dofs.clone().enumerate() {
                let by_v = armature * joint.rotor_velocity_jacobian(r, c, v_i);
                out.add(row, column, zero, by_v);
            }
        }
    }
}

/// The rotors' torque armature · (q̈ + K(q̇) q̇) added to τ on each joint's own coordinates (q̈ = 0
/// for `None`).
#[inline(always)]
fn add_rotor_torques<S: Real>(
    model: &Model,
    b: &mut DerivativeBuffers<S>,
    v: &[S],
    a: Option<&[S]>,
) {
    for i in 1..model.nbodies() {
        let (joint, dofs) = (&model.joints[i], model.v_range(i));
        let v_i = &v[dofs.clone()];
        for (r, row) in dofs.clone().enumerate() {
            let mut rate = a.map_or(S::splat(0.0), |a| a[row]);
            for (c, v_c) in v_i.iter().enumerate() {
                rate += joint.rotor_velocity_term(r, c, v_i) * *v_c;
            }
            b.tau[row] += S::splat(model.armature[row]) * rate;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::bundled::floating_ur5_state;

    /// A single call's passes, built for AVX2 and FMA where the processor has them, equal the
    /// baseline build of the same passes bit for bit (the claim of the dispatched builds).
    #[test]
    fn the_dispatched_passes_equal_the_baseline_build_bit_for_bit() {
        let (model, q, v, a) = floating_ur5_state();
        let nv = model.nv;
        let state = (&q[..], &v[..], &a[..], None);
        let mut dispatched = Data::new(&model);
        let (mut by_q, mut by_v) = (vec![0.0; nv * nv], vec![0.0; nv * nv]);
        let into = DerivativesInto::RowMajor {
            by_q: &mut by_q,
            by_v: &mut by_v,
        };
        rnea_derivatives(&model, &mut dispatched, &q, &v, &a, None, into).unwrap();
        let mut baseline = vec![vec![0.0; nv * nv]; 2];
        let [baseline_q, baseline_v] = &mut baseline[..] else {
            unreachable!()
        };
        let mut rows = RowMajor {
            by_q: baseline_q,
            by_v: baseline_v,
            nv,
        };
        let mut other = Data::new(&model);
        derivative_passes(
            &model,
            &mut DerivativeBuffers::of(&mut other),
            state,
            &mut rows,
        );
        assert_eq!(vec![by_q, by_v], baseline);
        assert_eq!(dispatched.tau, other.tau);
        let into = DerivativesInto::Data;
        aba_derivatives(&model, &mut dispatched, &q, &v, &a, None, into).unwrap();
        let (mut b, solve) = DerivativeBuffers::with_solve(&mut other);
        aba_derivative_passes(&model, &mut b, solve, state).unwrap();
        assert_eq!(dispatched.derivative_rows, other.derivative_rows);
        assert_eq!(dispatched.qdd, other.qdd);
        assert_eq!(other.derivative_rows.len(), 3 * nv * nv);
    }
}
