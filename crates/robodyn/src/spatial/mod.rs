//! Spatial (Plücker) vector algebra, after Featherstone, *Rigid Body Dynamics Algorithms* (2008),
//! chapter 2.
//!
//! Spatial vectors have named `angular` and `linear` parts, so their order exists only at the
//! boundary, where robodyn flattens them as `[linear; angular]` (see [`Motion::to_array`]).
//! A [`Transform`] is Featherstone's `X` from frame A to frame B: it maps motion vectors expressed
//! in A to B coordinates.

mod force;
mod inertia;
mod motion;
mod products;
mod transform;
pub mod trig;
pub(crate) mod turn;

pub use force::{Force, ForceProduct, ForceStore};
pub use inertia::{CoriolisFactor, Inertia};
pub use motion::Motion;
pub use products::*;
pub use transform::Transform;
pub use turn::Turn;

pub use nalgebra::{SimdRealField, SimdValue};

/// 3-vector of f64.
pub type Vec3 = nalgebra::Vector3<f64>;
/// 3x3 matrix of f64.
pub type Mat3 = nalgebra::Matrix3<f64>;
/// 6x6 matrix of f64 acting on `[angular; linear]` spatial vectors.
pub type Mat6 = nalgebra::Matrix6<f64>;

/// Rotation matrix of URDF's roll-pitch-yaw angles: `R = Rz(yaw) Ry(pitch) Rx(roll)`.
pub fn rotation_from_rpy(roll: f64, pitch: f64, yaw: f64) -> Mat3 {
    *nalgebra::Rotation3::from_euler_angles(roll, pitch, yaw).matrix()
}

/// `log` on SO(3): the rotation vector θ·axis of a unit quaternion, accurate for tiny angles
/// (where acos of the scalar part loses half the digits) and up to θ = π.
pub fn log_rotation(rotation: &nalgebra::UnitQuaternion<f64>) -> Vec3 {
    // q and -q are the same rotation: take w ≥ 0, so θ = 2 atan2(|v|, w) ∈ [0, π]
    let sign = if rotation.w < 0.0 { -1.0 } else { 1.0 };
    let (w, v) = (rotation.w * sign, rotation.vector() * sign);
    let sine = v.norm();
    if sine < 1e-12 {
        // θ → 0: θ axis = 2 v / w
        return v * (2.0 / w);
    }
    v * (2.0 * sine.atan2(w) / sine)
}
