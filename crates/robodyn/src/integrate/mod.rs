//! Simulation: the equations of motion
//!
//! ```text
//! M(q) q̈ + C(q, q̇) q̇ + g(q) = τ_control(t, q, q̇) + τ_passive(q, q̇) + Σ J_iᵀ f_ext,i(t, q, q̇)
//! ```
//!
//! integrated in time from (q₀, v₀), as the UR5 dynamics notes end: "q̈ = −M⁻¹(C + G); simulate: integrate …
//! Euler's method, Runge–Kutta fixed order 4, odeint (adaptive)".
//!
//! - [`lie_group`]: the rate of the tangent coordinates ξ in q = q₀ ⊕ ξ, so that spherical and free
//!   joints are integrated on their group (quaternions stay unit by construction).
//! - [`forward_dynamics`]: the [`ForwardDynamics`] strategy q̈ = FD(q, v, τ, f_ext) that the
//!   simulator, the single step and the rollouts in lockstep integrate, and its free-space
//!   implementation [`Aba`].
//! - [`forces`]: passive joint forces (damping, smoothed Coulomb friction, springs, the optional
//!   joint-limit penalty).
//! - [`control`]: the [`Controller`] trait and the native controllers (constant torque, PD,
//!   gravity compensation, computed torque) with their reference motions.
//! - [`schemes`]: the Butcher tableaus and the Runge–Kutta–Munthe-Kaas step.
//! - [`step`]: one fixed step and its Jacobians A = ∂x₁/∂x₀, B = ∂x₁/∂τ (trajectory optimisation).
//! - [`simulator`]: the loop, fixed-step or adaptive with dense output, recording a [`Trajectory`].
//!
//! Forward dynamics is [`Aba`] ([`crate::algo::aba()`]; armature is part of the model's M there)
//! unless another [`ForwardDynamics`] is given to the `_with` forms.

pub mod control;
pub mod forces;
pub mod forward_dynamics;
pub mod lie_group;
pub mod schemes;
pub mod simulator;
pub mod step;

pub use control::{ControlLaw, Controller, DesiredMotion, ExternalWrenches, NativeController};
pub use forces::{LimitModel, PassiveForces};
pub use forward_dynamics::{Aba, AccelerationDerivatives, Constrained, ForwardDynamics};
pub use schemes::Integrator;
pub use simulator::{
    simulate, simulate_lockstep, simulate_lockstep_with, simulate_with, Accuracy, AccuracyIssue,
    AccuracyMeasure, SimulationOptions, Statistics, Trajectory,
};
pub use step::StepWorkspace;
