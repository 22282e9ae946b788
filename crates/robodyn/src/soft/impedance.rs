//! How soft one constraint row is: its impedance, its spring and damper, its reference
//! acceleration and its regulariser.
//!
//! Reference: MuJoCo's documentation, "Computation", §Soft constraints (the impedance function of
//! `solimp`, the reference acceleration of `solref`). A row of violation `r` (its position past
//! the margin, `r = pos − margin`) and velocity `v = J q̇` asks for the acceleration
//! ```text
//!   a_ref = −b v − k d(r) r
//! ```
//! and is regularised by `R = (1 − d)/d · Â`, `Â` its approximate inverse inertia; the impedance
//! `d ∈ (0, 1)` rises from `d₀` at no violation to `d_max` at `|r| ≥ width` along two power
//! curves that meet at `midpoint`:
//! ```text
//!   x = |r| / width,   y(x) = x^p / m^(p−1)                 x ≤ m
//!                             1 − (1 − x)^p / (1 − m)^(p−1)   x > m
//!   d(r) = d₀ + y(x) (d_max − d₀)
//! ```
//! With `solref = (τ, ζ)` both positive (a time constant and a damping ratio) the row behaves
//! as a damped spring of that time constant: `k = 1/(d_max² τ² ζ²)`, `b = 2/(d_max τ)`; with both
//! negative they are the stiffness and damping themselves: `k = −solref₀/d_max²`,
//! `b = −solref₁/d_max`.

use crate::model::SolverParameters;

/// The impedance never leaves [`MIN_IMPEDANCE`, `MAX_IMPEDANCE`] (MuJoCo's `mjMINIMP`,
/// `mjMAXIMP`).
pub const MIN_IMPEDANCE: f64 = 1e-4;
/// See [`MIN_IMPEDANCE`].
pub const MAX_IMPEDANCE: f64 = 0.9999;
use super::TINY;

/// The impedance `d(r)` of a row violated by `r = pos − margin`, and its derivative `∂d/∂r`.
/// `solimp` is clamped as MuJoCo clamps it: d₀, d_max and the midpoint into
/// [[`MIN_IMPEDANCE`], [`MAX_IMPEDANCE`]], the width at least 0, the power at least 1.
pub fn impedance(solimp: &[f64; 5], violation: f64) -> (f64, f64) {
    let clamp = |value: f64| value.clamp(MIN_IMPEDANCE, MAX_IMPEDANCE);
    let (d0, dmax, width) = (clamp(solimp[0]), clamp(solimp[1]), solimp[2].max(0.0));
    let (midpoint, power) = (clamp(solimp[3]), solimp[4].max(1.0));
    // a constant impedance: no width, or nothing to rise to
    if d0 == dmax || width <= TINY {
        return ((d0 + dmax) / 2.0, 0.0);
    }
    let x = violation.abs() / width;
    if x >= 1.0 {
        return (dmax, 0.0);
    }
    if x == 0.0 {
        return (d0, 0.0);
    }
    // y(x) and y'(x): two power curves meeting at the midpoint
    let (y, slope) = if power == 1.0 {
        (x, 1.0)
    } else if x <= midpoint {
        let scale = midpoint.powf(power - 1.0);
        (x.powf(power) / scale, power * x.powf(power - 1.0) / scale)
    } else {
        let scale = (1.0 - midpoint).powf(power - 1.0);
        let rest = 1.0 - x;
        (
            1.0 - rest.powf(power) / scale,
            power * rest.powf(power - 1.0) / scale,
        )
    };
    // ∂d/∂r = y'(x) sign(r) (d_max − d₀) / width
    let derivative = slope * violation.signum() * (dmax - d0) / width;
    (d0 + y * (dmax - d0), derivative)
}

/// The spring's stiffness `k` and the damper's `b` of a row (see the module's header), with
/// `d_max` from `solver.solimp`. `safe_after`: MuJoCo's `refsafe`, the smallest time constant
/// allowed (twice the time step; `None` when the flag is off).
pub fn spring_and_damper(
    solref: &[f64; 2],
    solimp: &[f64; 5],
    safe_after: Option<f64>,
) -> (f64, f64) {
    let dmax = solimp[1].clamp(MIN_IMPEDANCE, MAX_IMPEDANCE);
    let [mut time_constant, damping] = *solref;
    if let Some(shortest) = safe_after {
        if time_constant > 0.0 {
            time_constant = time_constant.max(shortest);
        }
    }
    let stiffness = if time_constant > 0.0 {
        // k = 1/(d_max² τ² ζ²)
        1.0 / (dmax * dmax * time_constant * time_constant * damping * damping).max(TINY)
    } else {
        -time_constant / (dmax * dmax).max(TINY)
    };
    let damper = if damping > 0.0 {
        // b = 2/(d_max τ)
        2.0 / (dmax * time_constant).max(TINY)
    } else {
        -damping / dmax.max(TINY)
    };
    (stiffness, damper)
}

/// A row's reference acceleration `a_ref = −b v − k d r` and regulariser `R = (1 − d)/d · Â`
/// (at least 1e-15), from its violation `r`, velocity `v` and approximate inverse inertia
/// `Â`.
pub fn reference_and_regulariser(
    solver: &SolverParameters,
    safe_after: Option<f64>,
    violation: f64,
    velocity: f64,
    inverse_inertia: f64,
) -> (f64, f64) {
    let (d, _) = impedance(&solver.solimp, violation);
    let (k, b) = spring_and_damper(&solver.solref, &solver.solimp, safe_after);
    let reference = -b * velocity - k * d * violation;
    let regulariser = ((1.0 - d) / d * inverse_inertia).max(TINY);
    (reference, regulariser)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{DEFAULT_SOLIMP, DEFAULT_SOLREF};

    /// Closed forms by hand: exact up to round-off.
    const EXACT: f64 = 1e-12;

    #[test]
    fn the_impedance_rises_from_d0_to_dmax_across_the_width() {
        // MuJoCo's default: 0.9 → 0.95 over 1 mm, midpoint ½, power 2
        let solimp = DEFAULT_SOLIMP;
        assert_eq!(impedance(&solimp, 0.0), (0.9, 0.0));
        assert_eq!(impedance(&solimp, -0.002), (0.95, 0.0));
        // x = ¼: y = x²/½ = 1/8; d = 0.9 + 0.05/8; d' = 2x/½ · sign(r) · 0.05/0.001
        let (d, slope) = impedance(&solimp, -0.00025);
        assert!((d - (0.9 + 0.05 / 8.0)).abs() < EXACT);
        assert!((slope + 50.0).abs() < 1e-9);
        // x = ¾: y = 1 − (¼)²/½ = 7/8, symmetric in the sign of r
        let (d, _) = impedance(&solimp, 0.00075);
        assert!((d - (0.9 + 0.05 * 7.0 / 8.0)).abs() < EXACT);
        // the curves meet at the midpoint with the same slope
        let (below, slope_below) = impedance(&solimp, 0.0005 - 1e-12);
        let (above, slope_above) = impedance(&solimp, 0.0005 + 1e-12);
        assert!((below - above).abs() < 1e-9 && (slope_below - slope_above).abs() < 1e-6);
    }

    #[test]
    fn out_of_range_impedances_are_clamped_as_mujoco_clamps_them() {
        let (d, _) = impedance(&[0.0, 1.0, 0.0, 0.5, 2.0], 0.1);
        assert!((d - (MIN_IMPEDANCE + MAX_IMPEDANCE) / 2.0).abs() < EXACT);
        let (d, _) = impedance(&[0.5, 2.0, 0.01, 0.5, 0.5], 0.02);
        assert_eq!(d, MAX_IMPEDANCE);
    }

    #[test]
    fn a_time_constant_and_damping_ratio_make_a_damped_spring() {
        // τ = 0.02, ζ = 1, d_max = 0.95: k = 1/(0.95² 0.02²), b = 2/(0.95 · 0.02)
        let (k, b) = spring_and_damper(&DEFAULT_SOLREF, &DEFAULT_SOLIMP, None);
        assert!((k - 1.0 / (0.95f64.powi(2) * 0.0004)).abs() < 1e-8);
        assert!((b - 2.0 / (0.95 * 0.02)).abs() < 1e-10);
        // refsafe: τ at least twice the time step
        let (_, safe_b) = spring_and_damper(&[0.004, 1.0], &DEFAULT_SOLIMP, Some(0.01));
        assert!((safe_b - 2.0 / (0.95 * 0.01)).abs() < 1e-10);
        // direct: k = 9000/d_max², b = 70/d_max
        let (k, b) = spring_and_damper(&[-9000.0, -70.0], &DEFAULT_SOLIMP, Some(0.01));
        assert!((k - 9000.0 / 0.9025).abs() < 1e-8 && (b - 70.0 / 0.95).abs() < 1e-12);
    }

    #[test]
    fn a_resting_contact_asks_to_push_out_and_is_softened_by_its_impedance() {
        let solver = SolverParameters::default();
        // 1 mm deep, still: a_ref = −k d_max r > 0, R = (1 − 0.95)/0.95 · Â
        let (reference, regulariser) = reference_and_regulariser(&solver, None, -0.001, 0.0, 2.0);
        let k = 1.0 / (0.95f64.powi(2) * 0.0004);
        assert!((reference - k * 0.95 * 0.001).abs() < 1e-9);
        assert!((regulariser - 0.05 / 0.95 * 2.0).abs() < EXACT);
    }
}
