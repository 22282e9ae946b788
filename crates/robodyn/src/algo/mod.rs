//! One file per algorithm. Each is a free function `f(&Model, &mut Data, inputs) -> Result<..>`
//! that validates its inputs, writes its results into [`crate::Data`] and allocates nothing.

/// A pivot of M's factorisation (`ltdl`), or of an articulated inertia `D_i`, smaller than this
/// times the largest diagonal entry means the matrix is singular (a massless subtree without
/// armature): forward dynamics and M⁻¹ are then refused rather than returned as huge numbers.
pub const SINGULARITY_TOLERANCE: f64 = 1e-12;

pub mod aba;
pub mod centroidal;
pub mod constrained;
pub mod coriolis;
pub mod crba;
pub mod derivatives;
pub mod energy;
pub mod frame_derivatives;
pub mod frame_motion;
pub mod inverse_kinematics;
pub mod jacobian;
pub mod kinematics;
pub mod lanes;
pub mod ltdl;
pub mod manipulability;
pub mod minv;
pub mod regressor;
pub mod rnea;
pub mod textbook_forms;

pub use aba::aba;
pub use centroidal::centroidal_momentum_matrix;
pub use constrained::{
    close_constraints, constrained_forward_dynamics, constrained_forward_dynamics_derivatives,
    constrained_inverse_dynamics, constraint_jacobian, delassus, impulse_dynamics,
    impulse_dynamics_derivatives, ClosureOptions, ConstrainedDerivatives, ConstrainedOptions,
    ConstraintData,
};
pub use coriolis::{christoffel_symbols, coriolis_matrix};
pub use crba::{crba, crba_into};
pub use derivatives::{aba_derivatives, rnea_derivatives, DerivativesInto, DynamicsState};
pub use energy::{center_of_mass, center_of_mass_jacobian, kinetic_energy, potential_energy};
pub use frame_derivatives::{center_of_mass_velocity_derivatives, frame_motion_derivatives};
pub use frame_motion::{frame_acceleration, frame_velocity, jacobian_time_variation};
pub use inverse_kinematics::{inverse_kinematics, IkOptions, IkSolution};
pub use jacobian::{jacobian, jacobian_columns, Reference};
pub use kinematics::{forward_kinematics, frame_placement, frame_pose};
pub use lanes::{
    aba_batch, aba_derivatives_batch, batch, constrained_forward_dynamics_batch, crba_batch,
    frame_pose_batch, impulse_dynamics_batch, jacobian_batch, newton_euler_batch,
    rnea_derivatives_batch, write_jacobian_column, BatchAlgorithm, BatchResult, BatchWorkspace,
    ConstrainedBatchWorkspace, LaneWidth, States,
};
pub use manipulability::manipulability;
pub use minv::inverse_mass_matrix;
pub use regressor::torque_regressor;
pub use rnea::{bias_forces, generalized_gravity, rnea};
pub use textbook_forms::{
    generalized_gravity_by_jacobians, mass_matrix_by_jacobians, mass_matrix_by_rnea,
};
