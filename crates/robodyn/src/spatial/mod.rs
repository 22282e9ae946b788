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
mod transform;
pub mod trig;

pub use force::Force;
pub use inertia::{mat6_mul_motion, CoriolisFactor, Inertia};
pub use motion::Motion;
pub use transform::Transform;

pub use nalgebra::{SimdRealField, SimdValue};

/// A number the spatial algebra computes in: `f64` for one state, or a lane type holding one
/// `f64` per state of a batch (`simba`'s `AutoSimd<[f64; N]>`), so that one kernel serves both
/// and the same operations run in every lane. Model constants enter by [`SimdValue::splat`].
pub trait Real: SimdRealField<Element = f64> + Copy {}
impl<T: SimdRealField<Element = f64> + Copy> Real for T {}

/// 3-vector of f64.
pub type Vec3 = nalgebra::Vector3<f64>;
/// 3x3 matrix of f64.
pub type Mat3 = nalgebra::Matrix3<f64>;
/// 6x6 matrix of f64 acting on `[angular; linear]` spatial vectors.
pub type Mat6 = nalgebra::Matrix6<f64>;

/// The skew-symmetric matrix `v×` with `(v×) w = v × w`.
#[inline(always)]
pub fn skew<S: Real>(v: &nalgebra::Vector3<S>) -> nalgebra::Matrix3<S> {
    let zero = S::zero();
    nalgebra::Matrix3::new(zero, -v.z, v.y, v.z, zero, -v.x, -v.y, v.x, zero)
}

/// A constant vector in every lane.
#[inline(always)]
pub fn splat_vector<S: Real>(v: &Vec3) -> nalgebra::Vector3<S> {
    nalgebra::Vector3::new(S::splat(v.x), S::splat(v.y), S::splat(v.z))
}

/// A constant matrix in every lane.
#[inline(always)]
pub fn splat_matrix<S: Real>(m: &Mat3) -> nalgebra::Matrix3<S> {
    let e = |r: usize, c: usize| S::splat(m[(r, c)]);
    nalgebra::Matrix3::new(
        e(0, 0),
        e(0, 1),
        e(0, 2),
        e(1, 0),
        e(1, 1),
        e(1, 2),
        e(2, 0),
        e(2, 1),
        e(2, 2),
    )
}

/// The zero vector, entry by entry (nalgebra's generic `zeros` compiles poorly for wide lanes).
#[inline(always)]
pub fn zero_vector<S: Real>() -> nalgebra::Vector3<S> {
    let zero = S::splat(0.0);
    nalgebra::Vector3::new(zero, zero, zero)
}

// The products below are written out, and always inlined, so that a batch kernel compiled for
// wider vector instructions (`algo::lanes`) runs them with those instructions too.

/// `E v`.
#[inline(always)]
pub fn rotate<S: Real>(e: &nalgebra::Matrix3<S>, v: &nalgebra::Vector3<S>) -> nalgebra::Vector3<S> {
    let row = |r: usize| e[(r, 0)] * v.x + e[(r, 1)] * v.y + e[(r, 2)] * v.z;
    nalgebra::Vector3::new(row(0), row(1), row(2))
}

/// `Eᵀ v`.
#[inline(always)]
pub fn rotate_back<S: Real>(
    e: &nalgebra::Matrix3<S>,
    v: &nalgebra::Vector3<S>,
) -> nalgebra::Vector3<S> {
    let column = |c: usize| e[(0, c)] * v.x + e[(1, c)] * v.y + e[(2, c)] * v.z;
    nalgebra::Vector3::new(column(0), column(1), column(2))
}

/// `A B`.
#[inline(always)]
pub fn compose<S: Real>(
    a: &nalgebra::Matrix3<S>,
    b: &nalgebra::Matrix3<S>,
) -> nalgebra::Matrix3<S> {
    let entry =
        |r: usize, c: usize| a[(r, 0)] * b[(0, c)] + a[(r, 1)] * b[(1, c)] + a[(r, 2)] * b[(2, c)];
    nalgebra::Matrix3::new(
        entry(0, 0),
        entry(0, 1),
        entry(0, 2),
        entry(1, 0),
        entry(1, 1),
        entry(1, 2),
        entry(2, 0),
        entry(2, 1),
        entry(2, 2),
    )
}

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
