//! Jacobians of `integrate` and `difference` on the joints' Lie groups, with configurations
//! perturbed on the right (q ⊕ δ = q exp(δ), δ in the tangent space, one entry per velocity
//! coordinate; Pinocchio's `dIntegrate`/`dDifference` use the same convention):
//!
//! - q₁ = q ⊕ v: ∂q₁/∂q = Ad(exp(v))⁻¹ = Ad(exp(−v)), ∂q₁/∂v = J_r(v);
//! - v = q₁ ⊖ q₀ = log(q₀⁻¹ q₁): ∂v/∂q₁ = J_r(v)⁻¹, ∂v/∂q₀ = −J_l(v)⁻¹ = −J_r(−v)⁻¹.
//!
//! and of the tangent rate ξ̇ = T(ξ, v) = v + ½ ad_ξ v + ¹⁄₁₂ ad_ξ² v − ¹⁄₇₂₀ ad_ξ⁴ v that a
//! Runge–Kutta–Munthe-Kaas stage evaluates (for derivatives of a simulation step).
//!
//! J_r(ξ) = J_l(−ξ) are the right and left Jacobians of the group (Barfoot, *State Estimation for
//! Robotics*, 2017, §7.1.5 and §7.1.6, eqs. 7.77 and 7.86 for SO(3) and SE(3)); on SE(3) twists are
//! [linear; angular] as in v, and Ad(R, p) = [R, p× R; 0, R].

use super::configuration::left_jacobian_so3;
use crate::spatial::{skew, Mat3, Mat6, Vec3};
use nalgebra::{SMatrix, SVector, UnitQuaternion};

/// Below this angle Q's coefficients, which divide by up to θ⁵, come from their Taylor series
/// (to θ⁴: truncation below 1e-15; the closed forms lose about ε/θ⁴ relative above it).
const SERIES_ANGLE: f64 = 0.05;

/// J_l(ρ, φ) on SE(3): [J_l(φ), Q(ρ, φ); 0, J_l(φ)] with (θ = |φ|, ρ×, φ× written r, f)
/// Q = ½ r + (θ − sin θ)/θ³ (f r + r f + f r f) + (θ² + 2 cos θ − 2)/(2θ⁴) (f² r + r f² − 3 f r f)
///   + (2θ − 3 sin θ + θ cos θ)/(2θ⁵) (f r f² + f² r f).
pub(super) fn left_jacobian_se3(linear: &Vec3, angular: &Vec3) -> Mat6 {
    let theta = angular.norm();
    let (r, f) = (skew(linear), skew(angular));
    let t2 = theta * theta;
    let (a, b, c) = if theta < SERIES_ANGLE {
        let t4 = t2 * t2;
        (
            1.0 / 6.0 - t2 / 120.0 + t4 / 5040.0,
            1.0 / 24.0 - t2 / 720.0 + t4 / 40320.0,
            1.0 / 120.0 - t2 / 2520.0 + t4 / 120960.0,
        )
    } else {
        let (s, co) = (theta.sin(), theta.cos());
        (
            (theta - s) / (t2 * theta),
            (t2 + 2.0 * co - 2.0) / (2.0 * t2 * t2),
            (2.0 * theta - 3.0 * s + theta * co) / (2.0 * t2 * t2 * theta),
        )
    };
    let q = r * 0.5
        + (f * r + r * f + f * r * f) * a
        + (f * f * r + r * f * f - f * r * f * 3.0) * b
        + (f * r * f * f + f * f * r * f) * c;
    let jl = left_jacobian_so3(angular);
    let mut out = Mat6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&jl);
    out.fixed_view_mut::<3, 3>(0, 3).copy_from(&q);
    out.fixed_view_mut::<3, 3>(3, 3).copy_from(&jl);
    out
}

/// Ad of the transform (R, p) acting on [linear; angular] twists: [R, p× R; 0, R].
pub(super) fn adjoint_se3(rotation: &UnitQuaternion<f64>, position: &Vec3) -> Mat6 {
    let r: Mat3 = *rotation.to_rotation_matrix().matrix();
    let mut out = Mat6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
    out.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&(skew(position) * r));
    out.fixed_view_mut::<3, 3>(3, 3).copy_from(&r);
    out
}

/// ∂T/∂ξ and ∂T/∂v of T(ξ, v) = v + ½ ad_ξ v + ¹⁄₁₂ ad_ξ² v − ¹⁄₇₂₀ ad_ξ⁴ v, with `ad(x)` the
/// matrix of ad_x. T is linear in v: ∂T/∂v = 1 + ½ A + ¹⁄₁₂ A² − ¹⁄₇₂₀ A⁴ (A = ad_ξ). Along ξ,
/// ad_δ x = −ad_x δ turns each term's derivative into a matrix; with w_k = A^k v:
/// ∂T/∂ξ = −½ ad_v − ¹⁄₁₂ (ad_w₁ + A ad_v) + ¹⁄₇₂₀ (ad_w₃ + A ad_w₂ + A² ad_w₁ + A³ ad_v).
pub(super) fn tangent_rate_jacobians<const N: usize>(
    xi: &SVector<f64, N>,
    v: &SVector<f64, N>,
    ad: impl Fn(&SVector<f64, N>) -> SMatrix<f64, N, N>,
) -> (SMatrix<f64, N, N>, SMatrix<f64, N, N>) {
    let a = ad(xi);
    let a2 = a * a;
    let (w1, w2, w3) = (a * v, a2 * v, a2 * a * v);
    let ad_v = ad(v);
    let d_xi = ad_v * -0.5 - (ad(&w1) + a * ad_v) / 12.0
        + (ad(&w3) + a * ad(&w2) + a2 * ad(&w1) + a2 * a * ad_v) / 720.0;
    let d_v = SMatrix::<f64, N, N>::identity() + a * 0.5 + a2 / 12.0 - a2 * a2 / 720.0;
    (d_xi, d_v)
}

/// ad_x on SE(3) twists x = [ρ; φ] (linear; angular): [φ×, ρ×; 0, φ×].
pub(super) fn ad_se3(x: &SVector<f64, 6>) -> Mat6 {
    let (r, f) = (
        skew(&x.fixed_rows::<3>(0).into()),
        skew(&x.fixed_rows::<3>(3).into()),
    );
    let mut out = Mat6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&f);
    out.fixed_view_mut::<3, 3>(0, 3).copy_from(&r);
    out.fixed_view_mut::<3, 3>(3, 3).copy_from(&f);
    out
}
