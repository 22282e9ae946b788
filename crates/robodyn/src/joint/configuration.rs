//! A joint's configurations on its Lie group: the neutral and random configurations, `q ⊕ v`
//! and `q₁ ⊖ q₀` (revolute and prismatic joints on the line, spherical joints on SO(3) with
//! unit quaternions, free joints on SE(3), body-frame velocities), their Jacobians, and the rate
//! of tangent coordinates that a Runge–Kutta–Munthe-Kaas stage needs. The exponential and
//! logarithm: Barfoot, *State Estimation for Robotics* (2017), §7.1.

use super::jacobians;
use super::{quaternion_of, Joint, SMALL_ANGLE};
use crate::spatial::{log_rotation, skew, Mat3, Mat6, Motion, Vec3};
use nalgebra::{UnitQuaternion, Vector6};
use rand::Rng;

impl Joint {
    /// The neutral configuration (zero angles, identity quaternions).
    pub fn neutral(&self, q: &mut [f64]) {
        q.fill(0.0);
        if let Some(offset) = self.quaternion_offset() {
            q[offset + 3] = 1.0;
        }
    }

    /// A random configuration: uniform within finite `lower`/`upper` limits, otherwise within
    /// [-π, π] for angles and [-1, 1] m for translations; uniformly distributed rotations.
    pub fn random<R: Rng>(&self, rng: &mut R, lower: &[f64], upper: &[f64], q: &mut [f64]) {
        for i in 0..self.nq() {
            let default = match self {
                Joint::Revolute { .. } => std::f64::consts::PI,
                _ => 1.0,
            };
            let (lo, hi) = if lower[i].is_finite() && upper[i].is_finite() && lower[i] <= upper[i] {
                (lower[i], upper[i])
            } else {
                (-default, default)
            };
            q[i] = lo + (hi - lo) * rng.random::<f64>();
        }
        if let Some(offset) = self.quaternion_offset() {
            // Shoemake's uniform random rotation
            let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
            let tau = std::f64::consts::TAU;
            let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
            q[offset..offset + 4].copy_from_slice(&[
                a * (tau * u2).sin(),
                a * (tau * u2).cos(),
                b * (tau * u3).sin(),
                b * (tau * u3).cos(),
            ]);
        }
    }

    /// `q ⊕ v`: the configuration reached from `q` by moving with constant velocity `v` for unit
    /// time, on the joint's Lie group (body-frame velocities, right multiplication).
    pub fn integrate(&self, q: &[f64], v: &[f64], out: &mut [f64]) {
        match self {
            Joint::Fixed => {}
            Joint::Revolute { .. } | Joint::Prismatic { .. } => out[0] = q[0] + v[0],
            Joint::Spherical => {
                let rotation = quaternion_of(&q[0..4]) * exp_so3(&Vec3::new(v[0], v[1], v[2]));
                write_quaternion(&rotation, &mut out[0..4]);
            }
            Joint::Free => {
                let rotation = quaternion_of(&q[3..7]);
                let (rotation_step, translation_step) =
                    exp_se3(&Vec3::new(v[0], v[1], v[2]), &Vec3::new(v[3], v[4], v[5]));
                let position = Vec3::new(q[0], q[1], q[2]) + rotation * translation_step;
                out[0..3].copy_from_slice(position.as_slice());
                write_quaternion(&(rotation * rotation_step), &mut out[3..7]);
            }
        }
    }

    /// `q1 ⊖ q0`: the velocity `v` with `integrate(q0, v) = q1`.
    pub fn difference(&self, q0: &[f64], q1: &[f64], v: &mut [f64]) {
        match self {
            Joint::Fixed => {}
            Joint::Revolute { .. } | Joint::Prismatic { .. } => v[0] = q1[0] - q0[0],
            Joint::Spherical => {
                let relative = quaternion_of(&q0[0..4]).inverse() * quaternion_of(&q1[0..4]);
                v.copy_from_slice(log_rotation(&relative).as_slice());
            }
            Joint::Free => {
                let r0 = quaternion_of(&q0[3..7]);
                let relative_rotation = r0.inverse() * quaternion_of(&q1[3..7]);
                let relative_position = r0.inverse()
                    * (Vec3::new(q1[0], q1[1], q1[2]) - Vec3::new(q0[0], q0[1], q0[2]));
                let (linear, angular) = log_se3(&relative_rotation, &relative_position);
                v[0..3].copy_from_slice(linear.as_slice());
                v[3..6].copy_from_slice(angular.as_slice());
            }
        }
    }
    /// ∂(q ⊕ v)/∂q = Ad(exp(v))⁻¹ and ∂(q ⊕ v)/∂v = J_r(v), tangent to tangent (configurations
    /// perturbed on the right, as in the joint's Lie-group Jacobians), written into the leading
    /// nv × nv blocks of `d_q` and `d_v`.
    pub fn integrate_jacobians(&self, v: &[f64], d_q: &mut Mat6, d_v: &mut Mat6) {
        match self {
            Joint::Fixed => {}
            Joint::Revolute { .. } | Joint::Prismatic { .. } => {
                d_q[(0, 0)] = 1.0;
                d_v[(0, 0)] = 1.0;
            }
            Joint::Spherical => {
                let w = Vec3::new(v[0], v[1], v[2]);
                let back = exp_so3(&-w).to_rotation_matrix();
                d_q.fixed_view_mut::<3, 3>(0, 0).copy_from(back.matrix());
                // J_r(w) = J_l(−w)
                d_v.fixed_view_mut::<3, 3>(0, 0)
                    .copy_from(&left_jacobian_so3(&-w));
            }
            Joint::Free => {
                let (linear, angular) = (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]));
                let (rotation, position) = exp_se3(&-linear, &-angular);
                *d_q = jacobians::adjoint_se3(&rotation, &position);
                *d_v = jacobians::left_jacobian_se3(&-linear, &-angular);
            }
        }
    }

    /// ∂(q₁ ⊖ q₀)/∂q₀ = −J_l(v)⁻¹ and ∂(q₁ ⊖ q₀)/∂q₁ = J_r(v)⁻¹ with v = q₁ ⊖ q₀, written into the
    /// leading nv × nv blocks of `d_q0` and `d_q1`.
    pub fn difference_jacobians(&self, q0: &[f64], q1: &[f64], d_q0: &mut Mat6, d_q1: &mut Mat6) {
        let mut v = [0.0; 6];
        let nv = self.nv();
        self.difference(q0, q1, &mut v[..nv]);
        match self {
            Joint::Fixed => {}
            Joint::Revolute { .. } | Joint::Prismatic { .. } => {
                d_q0[(0, 0)] = -1.0;
                d_q1[(0, 0)] = 1.0;
            }
            Joint::Spherical => {
                let w = Vec3::new(v[0], v[1], v[2]);
                let inverse = |j: Mat3| j.try_inverse().unwrap_or_else(Mat3::zeros);
                d_q0.fixed_view_mut::<3, 3>(0, 0)
                    .copy_from(&-inverse(left_jacobian_so3(&w)));
                d_q1.fixed_view_mut::<3, 3>(0, 0)
                    .copy_from(&inverse(left_jacobian_so3(&-w)));
            }
            Joint::Free => {
                let (linear, angular) = (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]));
                let inverse = |j: Mat6| j.try_inverse().unwrap_or_else(Mat6::zeros);
                *d_q0 = -inverse(jacobians::left_jacobian_se3(&linear, &angular));
                *d_q1 = inverse(jacobians::left_jacobian_se3(&-linear, &-angular));
            }
        }
    }

    /// The rate `ξ̇` of the tangent coordinates `ξ` in `q(t) = q₀ ⊕ ξ(t)` when the joint moves
    /// with body velocity `v`: `ξ̇ = dexp⁻¹_{-ξ}(v) = v + ½ ad_ξ v + ¹⁄₁₂ ad_ξ² v − ¹⁄₇₂₀ ad_ξ⁴ v`
    /// (the Bernoulli series, truncated after the term that a fifth-order Runge–Kutta–Munthe-Kaas
    /// step needs; Iserles et al., *Lie-group methods*, Acta Numerica 2000, §2.3). `ad` is the cross
    /// product on so(3) and the motion cross product on se(3); on a vector space it is zero and
    /// `ξ̇ = v`.
    pub fn tangent_rate(&self, xi: &[f64], v: &[f64], out: &mut [f64]) {
        match self {
            Joint::Fixed => {}
            Joint::Revolute { .. } | Joint::Prismatic { .. } => out[0] = v[0],
            Joint::Spherical => {
                let (xi, v) = (Vec3::new(xi[0], xi[1], xi[2]), Vec3::new(v[0], v[1], v[2]));
                let rate = bernoulli_series(v, |m| xi.cross(&m));
                out.copy_from_slice(rate.as_slice());
            }
            Joint::Free => {
                // twists are [linear; angular] in q's layout, (angular, linear) as a Motion
                let xi = Motion::new(
                    Vec3::new(xi[3], xi[4], xi[5]),
                    Vec3::new(xi[0], xi[1], xi[2]),
                );
                let v = Motion::new(Vec3::new(v[3], v[4], v[5]), Vec3::new(v[0], v[1], v[2]));
                let rate = bernoulli_series(v, |m| xi.cross_motion(&m));
                out[0..3].copy_from_slice(rate.linear.as_slice());
                out[3..6].copy_from_slice(rate.angular.as_slice());
            }
        }
    }

    /// ∂ξ̇/∂ξ and ∂ξ̇/∂v of [`Joint::tangent_rate`] (perturbed on the right), written into the
    /// leading nv × nv blocks of `d_xi` and `d_v`; identity and zero on revolute and prismatic
    /// joints.
    pub fn tangent_rate_jacobians(&self, xi: &[f64], v: &[f64], d_xi: &mut Mat6, d_v: &mut Mat6) {
        match self {
            Joint::Fixed => {}
            Joint::Revolute { .. } | Joint::Prismatic { .. } => {
                d_xi[(0, 0)] = 0.0;
                d_v[(0, 0)] = 1.0;
            }
            Joint::Spherical => {
                let (xi, v) = (Vec3::new(xi[0], xi[1], xi[2]), Vec3::new(v[0], v[1], v[2]));
                let (a, b) = jacobians::tangent_rate_jacobians(&xi, &v, skew);
                d_xi.fixed_view_mut::<3, 3>(0, 0).copy_from(&a);
                d_v.fixed_view_mut::<3, 3>(0, 0).copy_from(&b);
            }
            Joint::Free => {
                let (xi, v) = (
                    Vector6::from_column_slice(xi),
                    Vector6::from_column_slice(v),
                );
                (*d_xi, *d_v) = jacobians::tangent_rate_jacobians(&xi, &v, jacobians::ad_se3);
            }
        }
    }
}

/// `v + ½ ad v + ¹⁄₁₂ ad² v − ¹⁄₇₂₀ ad⁴ v` for the linear map `ad`.
fn bernoulli_series<T>(v: T, ad: impl Fn(T) -> T) -> T
where
    T: Copy + std::ops::Add<Output = T> + std::ops::Mul<f64, Output = T>,
{
    let ad1 = ad(v);
    let ad2 = ad(ad1);
    let ad4 = ad(ad(ad2));
    v + ad1 * 0.5 + ad2 * (1.0 / 12.0) + ad4 * (-1.0 / 720.0)
}

/// Writes `[qx, qy, qz, qw]`, with qw ≥ 0 for a canonical sign.
fn write_quaternion(rotation: &UnitQuaternion<f64>, out: &mut [f64]) {
    let sign = if rotation.w < 0.0 { -1.0 } else { 1.0 };
    out.copy_from_slice(&[
        sign * rotation.i,
        sign * rotation.j,
        sign * rotation.k,
        sign * rotation.w,
    ]);
}

/// `exp(ω×)` on SO(3).
fn exp_so3(omega: &Vec3) -> UnitQuaternion<f64> {
    UnitQuaternion::from_scaled_axis(*omega)
}

/// The left Jacobian of SO(3), `V(ω) = 1 + (1 - cos θ)/θ² ω× + (θ - sin θ)/θ³ ω×²`, which maps a
/// body twist's linear part to the translation of `exp` on SE(3).
pub(super) fn left_jacobian_so3(omega: &Vec3) -> Mat3 {
    let theta = omega.norm();
    let w = skew(omega);
    let (a, b) = if theta < SMALL_ANGLE {
        (
            0.5 - theta * theta / 24.0,
            1.0 / 6.0 - theta * theta / 120.0,
        )
    } else {
        let t2 = theta * theta;
        (
            (1.0 - theta.cos()) / t2,
            (theta - theta.sin()) / (t2 * theta),
        )
    };
    Mat3::identity() + w * a + w * w * b
}

/// `exp` on SE(3) of the body twist (v, ω): rotation `exp(ω×)`, translation `V(ω) v`.
fn exp_se3(linear: &Vec3, angular: &Vec3) -> (UnitQuaternion<f64>, Vec3) {
    (exp_so3(angular), left_jacobian_so3(angular) * linear)
}

/// `log` on SE(3): the body twist (v, ω) with `exp_se3(v, ω) = (rotation, translation)`.
fn log_se3(rotation: &UnitQuaternion<f64>, translation: &Vec3) -> (Vec3, Vec3) {
    let angular = log_rotation(rotation);
    let v = left_jacobian_so3(&angular);
    let linear = v
        .try_inverse()
        .map_or(*translation, |inv| inv * translation);
    (linear, angular)
}
