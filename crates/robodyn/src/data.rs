//! The workspace every algorithm writes into, allocated once per model by [`Data::new`].
//! After that, the algorithms in [`crate::algo`] allocate nothing.

use crate::algo::crba::ForceRowsRoom;
use crate::model::Model;
use crate::spatial::{CoriolisFactor, Force, Inertia, Mat6, Motion, Transform};
use nalgebra::{DMatrix, DVector};

/// Results and intermediates of the algorithms, indexed like the model's bodies (0 = world).
/// Each field says its meaning, shape, frame and which algorithm writes it.
#[derive(Debug, Clone)]
pub struct Data {
    /// `X_{i←λ(i)}`: transform from the parent body's frame to body i's frame; nbodies.
    /// Written by every algorithm that takes q.
    pub x_up: Vec<Transform>,
    /// `X_{i←0}`: transform from the world to body i's frame (its pose in the world); nbodies.
    /// Written by `forward_kinematics`, `jacobian`, `potential_energy`, `center_of_mass`.
    pub x_world: Vec<Transform>,
    /// Spatial velocity of body i in its own frame; nbodies. Written by `rnea`, `aba`,
    /// `kinetic_energy`.
    pub v: Vec<Motion>,
    /// Spatial acceleration of body i in its own frame, gravity included as a fictitious upward
    /// base acceleration (Featherstone's `a_0 = -g`); nbodies. Written by `rnea`, `aba`.
    pub a: Vec<Motion>,
    /// Net spatial force transmitted across joint i, in body i's frame; nbodies. Written by `rnea`.
    pub f: Vec<Force>,
    /// Generalized forces; nv. Written by `rnea`.
    pub tau: DVector<f64>,
    /// Composite rigid-body inertia of the subtree rooted at body i, in world coordinates;
    /// nbodies. Written by `crba` on a model it computes in world coordinates (see `algo::crba`),
    /// `centroidal_momentum_matrix`, `coriolis_matrix` and the derivatives;
    /// `center_of_mass_jacobian` writes only its mass and first moment.
    pub i_c: Vec<Inertia>,
    /// Motion subspace column of each velocity coordinate in world coordinates (the spatial
    /// Jacobian's columns); nv. Written with `i_c`.
    pub s_world: Vec<Motion>,
    /// Composite rigid-body inertia of the subtree rooted at body i, in body i's own frame;
    /// nbodies. Written by `crba` on a model it computes in body coordinates.
    pub i_c_body: Vec<Inertia>,
    /// `F = I^c_i S_k` of each velocity coordinate k (of body i's joint), in the frame of the
    /// last body `crba` carried it to, in the layout `crba` keeps them in. Written with
    /// `i_c_body`.
    pub(crate) crba_forces: ForceRowsRoom,
    /// Spatial velocity of body i in world coordinates; nbodies. Written by `coriolis_matrix`.
    pub v_world: Vec<Motion>,
    /// Rate Ṡ = v_i × ⁰S of each world-frame subspace column; nv. Written by `coriolis_matrix`.
    pub s_dot_world: Vec<Motion>,
    /// Coriolis matrix C(q, q̇); nv x nv. Written by `coriolis_matrix`.
    pub coriolis: DMatrix<f64>,
    /// Generalized gravity g(q); nv. Written by `mass_matrix_by_rnea`.
    pub gravity: DVector<f64>,
    /// All zeros between uses; `christoffel_symbols` and `mass_matrix_by_rnea` set one
    /// entry at a time to 1; nv.
    pub unit_velocity: DVector<f64>,
    /// Centroidal momentum matrix A_G(q), rows [linear; angular about the centre of mass];
    /// 6 x nv. Written by `centroidal_momentum_matrix`.
    pub centroidal_matrix: DMatrix<f64>,
    /// Joint-space inertia matrix M(q), full and symmetric; nv x nv. Written by `crba`.
    pub mass_matrix: DMatrix<f64>,
    /// M(q)⁻¹; nv x nv. Written by `inverse_mass_matrix`.
    pub mass_matrix_inverse: DMatrix<f64>,
    /// M's tree-sparse factors M = Lᵀ D L: D on the diagonal, L strictly below (see
    /// `algo::ltdl`); nv x nv. Written by `inverse_mass_matrix` and `aba_derivatives`.
    pub mass_matrix_factor: DMatrix<f64>,
    /// Velocity-product acceleration `c_i = v_i × v_J` of body i, own frame; nbodies.
    /// Written by `aba`.
    pub c: Vec<Motion>,
    /// Articulated-body inertia `I^A_i` (6x6 on `[angular; linear]`), own frame; nbodies.
    /// Written by `aba`.
    pub i_a: Vec<Mat6>,
    /// Articulated-body bias force `p^A_i`, own frame; nbodies. Written by `aba`.
    pub p_a: Vec<Force>,
    /// `U_i = I^A_i S_i`, one force per velocity coordinate of joint i (first nv_i used); nbodies.
    /// Written by `aba`.
    pub u: Vec<[Force; 6]>,
    /// `D_i⁻¹ = (S_iᵀ U_i + armature)⁻¹` in the leading nv_i x nv_i block; nbodies.
    /// Written by `aba`.
    pub d_inv: Vec<Mat6>,
    /// `u_i = τ_i - S_iᵀ p^A_i` (first nv_i used); nbodies. Written by `aba`.
    pub u_tau: Vec<[f64; 6]>,
    /// Joint accelerations q̈; nv. Written by `aba`.
    pub qdd: DVector<f64>,
    /// Frame Jacobian, 6 x nv, rows `[linear; angular]`. Written by `jacobian`.
    pub jacobian: DMatrix<f64>,
    /// Time derivative J̇ of a frame Jacobian, 6 x nv, rows `[linear; angular]`. Written by
    /// `jacobian_time_variation`.
    pub jacobian_dot: DMatrix<f64>,
    /// Joint-torque regressor Y(q, q̇, q̈), τ = Y π; nv x 10 (nbodies − 1). Written by
    /// `torque_regressor`.
    pub regressor: DMatrix<f64>,
    /// Spatial acceleration of body i in world coordinates, gravity included as `a_0 = -g`;
    /// nbodies. Written by `rnea_derivatives`.
    pub a_world: Vec<Motion>,
    /// Net spatial force transmitted across joint i (the forces of its whole subtree), in world
    /// coordinates; nbodies. Written by `rnea_derivatives` (`center_of_mass_velocity_derivatives`
    /// writes the subtrees' momenta Σ I ν here).
    pub f_world: Vec<Force>,
    /// Per velocity coordinate k of body i (parent λ), world coordinates: `[u_k, u_k + u'_k, z_k]`
    /// with `u_k = S_k × v_λ`, `u'_k = S_k × v_i`, `z_k = S_k × a_λ − u_k × v_λ`, the terms by which v and a of i's subtree move when q_k or
    /// q̇_k does; nv. Written by `rnea_derivatives`.
    pub motion_terms: Vec<[Motion; 3]>,
    /// `H = 2B(I, v)` of the subtree rooted at body i, world coordinates, factored; nbodies.
    /// Written by `rnea_derivatives` and `coriolis_matrix`.
    pub coriolis_factors: Vec<CoriolisFactor>,
    /// Each body's own spatial inertia in world coordinates; nbodies. Written by
    /// `rnea_derivatives`.
    pub i_world: Vec<Inertia>,
    /// Each body's velocity-product force v ×* I v less its external force, world coordinates;
    /// nbodies. Written by `rnea_derivatives`.
    pub f_velocity: Vec<Force>,
    /// ∂τ/∂q (tangent space, right perturbations q ⊕ δ); nv x nv. Written by `rnea_derivatives`.
    pub dtau_dq: DMatrix<f64>,
    /// ∂τ/∂q̇; nv x nv. Written by `rnea_derivatives`.
    pub dtau_dv: DMatrix<f64>,
    /// ∂q̈/∂q (tangent space); nv x nv. Written by `aba_derivatives`.
    pub dqdd_dq: DMatrix<f64>,
    /// ∂q̈/∂q̇; nv x nv. Written by `aba_derivatives`.
    pub dqdd_dv: DMatrix<f64>,
    /// Row i of [−∂τ/∂q, −∂τ/∂q̇, 1], then of M⁻¹ times it, row-major (nv rows of 3 nv).
    /// Written by `aba_derivatives`.
    pub derivative_rows: Vec<f64>,
    /// ∂(frame velocity)/∂q (tangent space); 6 x nv. Written by `frame_motion_derivatives`.
    pub frame_velocity_dq: DMatrix<f64>,
    /// ∂(frame classical acceleration)/∂q; 6 x nv. Written by `frame_motion_derivatives`.
    pub frame_acceleration_dq: DMatrix<f64>,
    /// ∂(frame classical acceleration)/∂q̇; 6 x nv. Written by `frame_motion_derivatives`.
    pub frame_acceleration_dv: DMatrix<f64>,
    /// ∂ċ/∂q of the centre of mass's velocity (tangent space); 3 x nv. Written by
    /// `center_of_mass_velocity_derivatives`.
    pub com_velocity_dq: DMatrix<f64>,
    /// The bodies from a frame's body down to the world's child (its support), in that order.
    /// Written by `jacobian` and `frame_pose`.
    pub support: Vec<usize>,
}

impl Data {
    /// Allocates every buffer for `model`.
    pub fn new(model: &Model) -> Self {
        let nb = model.nbodies();
        let nv = model.nv;
        Data {
            x_up: vec![Transform::IDENTITY; nb],
            x_world: vec![Transform::IDENTITY; nb],
            v: vec![Motion::ZERO; nb],
            a: vec![Motion::ZERO; nb],
            f: vec![Force::ZERO; nb],
            tau: DVector::zeros(nv),
            i_c: vec![Inertia::ZERO; nb],
            s_world: vec![Motion::ZERO; nv],
            i_c_body: vec![Inertia::ZERO; nb],
            crba_forces: ForceRowsRoom::new(nv),
            v_world: vec![Motion::ZERO; nb],
            s_dot_world: vec![Motion::ZERO; nv],
            coriolis: DMatrix::zeros(nv, nv),
            gravity: DVector::zeros(nv),
            unit_velocity: DVector::zeros(nv),
            centroidal_matrix: DMatrix::zeros(6, nv),
            mass_matrix: DMatrix::zeros(nv, nv),
            mass_matrix_inverse: DMatrix::zeros(nv, nv),
            mass_matrix_factor: DMatrix::zeros(nv, nv),
            derivative_rows: vec![0.0; 3 * nv * nv],
            c: vec![Motion::ZERO; nb],
            i_a: vec![Mat6::zeros(); nb],
            p_a: vec![Force::ZERO; nb],
            u: vec![[Force::ZERO; 6]; nb],
            d_inv: vec![Mat6::zeros(); nb],
            u_tau: vec![[0.0; 6]; nb],
            qdd: DVector::zeros(nv),
            jacobian: DMatrix::zeros(6, nv),
            jacobian_dot: DMatrix::zeros(6, nv),
            regressor: DMatrix::zeros(nv, 10 * (nb - 1)),
            a_world: vec![Motion::ZERO; nb],
            f_world: vec![Force::ZERO; nb],
            motion_terms: vec![[Motion::ZERO; 3]; nv],
            coriolis_factors: vec![CoriolisFactor::ZERO; nb],
            i_world: vec![Inertia::ZERO; nb],
            f_velocity: vec![Force::ZERO; nb],
            dtau_dq: DMatrix::zeros(nv, nv),
            dtau_dv: DMatrix::zeros(nv, nv),
            dqdd_dq: DMatrix::zeros(nv, nv),
            dqdd_dv: DMatrix::zeros(nv, nv),
            frame_velocity_dq: DMatrix::zeros(6, nv),
            frame_acceleration_dq: DMatrix::zeros(6, nv),
            frame_acceleration_dv: DMatrix::zeros(6, nv),
            com_velocity_dq: DMatrix::zeros(3, nv),
            support: Vec::with_capacity(nb),
        }
    }
}
