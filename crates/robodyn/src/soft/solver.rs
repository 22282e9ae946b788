//! The constraint forces of MuJoCo's soft model: the accelerations that minimise
//! ```text
//!   ½ (q̈ − q̈₀)ᵀ M (q̈ − q̈₀) + s(J q̈ − a_ref)
//! ```
//! (q̈₀ the unconstrained accelerations), solved by Newton's method to convergence, and the
//! forces `f = −∂s/∂(J q̈ − a_ref)` there.
//!
//! Reference: MuJoCo's documentation, "Computation", §Constraint model (the primal problem),
//! §Soft constraints and §Solver (Newton); E. Todorov, "Convex and analytically-invertible
//! dynamics with contacts and constraints", ICRA 2014. Per group of rows, with `D = 1/R` and
//! `x = J q̈ − a_ref`:
//! ```text
//!   limits, frictionless and pyramidal rows   s = ½ D x²  where x < 0          f = −D x  (or 0)
//!   friction loss (largest force φ)           Huber: ½ D x² for |x| < R φ,     f = ∓φ beyond
//!                                                    φ|x| − ½ R φ² beyond
//!   elliptic contact (μ, friction f_k)        u₀ = μ x₀, u_k = f_k x_k, N = u₀, T = |u_1…|
//!     N ≥ μ T            (in the cone)        s = 0
//!     μ N + T ≤ 0        (opposite)           s = ½ Σ D_k x_k²
//!     otherwise          (on its surface)     s = ½ D_m (N − μ T)²,  D_m = D₀ / (μ² (1 + μ²))
//! ```
//! The cost is convex and once differentiable; Newton's step uses its Hessian `M + Jᵀ H_s J`
//! and an exact line search (the cost's slope along the step is monotone).

use super::rows::{Group, RowKind, Rows};
use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector};

/// Newton's iterations at most; the active set settles in a few, the cone in a few more.
const MAX_ITERATIONS: usize = 100;
/// A step this small against the accelerations ends the iterations.
const STEP_TOLERANCE: f64 = 1e-15;
/// The line search's iterations at most (bisection and secant on the slope).
const LINE_ITERATIONS: usize = 100;

/// The solution: accelerations, the rows' forces.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Solution {
    /// q̈ (nv).
    pub acceleration: DVector<f64>,
    /// One force per row.
    pub forces: Vec<f64>,
}

/// The forces `f` of every row at `x = J q̈ − a_ref` (`x` per row), into `forces`; the cost `s`
/// is returned. With `hessian`, each group's block of `∂²s/∂x²` is added to it (rows × rows).
fn forces_at(
    rows: &Rows,
    x: &[f64],
    forces: &mut [f64],
    mut hessian: Option<&mut DMatrix<f64>>,
) -> f64 {
    let mut cost = 0.0;
    for group in &rows.groups {
        let range = group.first..group.first + group.len;
        match group.kind {
            RowKind::FrictionDof => {
                let i = group.first;
                let (r, loss) = (rows.regulariser[i], rows.frictionloss[i]);
                if x[i] <= -r * loss {
                    forces[i] = loss;
                    cost += -0.5 * r * loss * loss - loss * x[i];
                } else if x[i] >= r * loss {
                    forces[i] = -loss;
                    cost += -0.5 * r * loss * loss + loss * x[i];
                } else {
                    forces[i] = -x[i] / r;
                    cost += 0.5 * x[i] * x[i] / r;
                    if let Some(h) = hessian.as_deref_mut() {
                        h[(i, i)] += 1.0 / r;
                    }
                }
            }
            RowKind::ContactElliptic => {
                cost += elliptic(rows, group, x, forces, hessian.as_deref_mut());
            }
            _ => {
                for i in range {
                    if x[i] < 0.0 {
                        let d = 1.0 / rows.regulariser[i];
                        forces[i] = -d * x[i];
                        cost += 0.5 * d * x[i] * x[i];
                        if let Some(h) = hessian.as_deref_mut() {
                            h[(i, i)] += d;
                        }
                    } else {
                        forces[i] = 0.0;
                    }
                }
            }
        }
    }
    cost
}

/// An elliptic contact's forces, cost and Hessian block (see the module's header).
fn elliptic(
    rows: &Rows,
    group: &Group,
    x: &[f64],
    forces: &mut [f64],
    hessian: Option<&mut DMatrix<f64>>,
) -> f64 {
    let (first, len, mu, f) = (group.first, group.len, group.mu, group.friction);
    let normal = mu * x[first];
    let mut u = [0.0; 6];
    for k in 1..len {
        u[k] = f[k - 1] * x[first + k];
    }
    let tangent = u[1..len].iter().map(|u| u * u).sum::<f64>().sqrt();
    // in the cone: no force
    if normal >= mu * tangent || (tangent == 0.0 && normal >= 0.0) {
        forces[first..first + len].fill(0.0);
        return 0.0;
    }
    // opposite the cone: every row a spring
    if mu * normal + tangent <= 0.0 || (tangent == 0.0 && normal < 0.0) {
        let mut cost = 0.0;
        let mut hessian = hessian;
        for i in first..first + len {
            let d = 1.0 / rows.regulariser[i];
            forces[i] = -d * x[i];
            cost += 0.5 * d * x[i] * x[i];
            if let Some(h) = hessian.as_deref_mut() {
                h[(i, i)] += d;
            }
        }
        return cost;
    }
    // on the cone's surface: s = ½ D_m h², h = N − μ T
    let dm = 1.0 / rows.regulariser[first] / (mu * mu * (1.0 + mu * mu));
    let h = normal - mu * tangent;
    forces[first] = -dm * h * mu;
    for k in 1..len {
        forces[first + k] = -forces[first] * u[k] * f[k - 1] / tangent;
    }
    if let Some(hessian) = hessian {
        // ∇h = (μ, −μ f_k u_k / T);  ∇²s = D_m (∇h ∇hᵀ − μ h diag(f) (I − û ûᵀ) diag(f) / T)
        let mut gradient = [0.0; 6];
        gradient[0] = mu;
        for k in 1..len {
            gradient[k] = -mu * f[k - 1] * u[k] / tangent;
        }
        for a in 0..len {
            for b in 0..len {
                let mut value = gradient[a] * gradient[b];
                if a > 0 && b > 0 {
                    let projector = f64::from(u8::from(a == b)) - u[a] * u[b] / (tangent * tangent);
                    value -= mu * h * f[a - 1] * f[b - 1] * projector / tangent;
                }
                hessian[(first + a, first + b)] += dm * value;
            }
        }
    }
    0.5 * dm * h * h
}

/// Minimises the problem of the module's header from `start`: `mass` M (nv × nv), `free` the
/// unconstrained accelerations q̈₀, `reference` each row's a_ref as the solver sees it.
pub fn solve(
    rows: &Rows,
    mass: &DMatrix<f64>,
    free: &DVector<f64>,
    reference: &[f64],
) -> Result<Solution> {
    let (nv, count) = (mass.nrows(), rows.len());
    let jacobian = DMatrix::from_row_slice(count, nv, &rows.jacobian);
    let mut acceleration = free.clone();
    let mut forces = vec![0.0; count];
    let mut x = vec![0.0; count];
    let residual = |a: &DVector<f64>, x: &mut [f64]| {
        let ja = &jacobian * a;
        for i in 0..count {
            x[i] = ja[i] - reference[i];
        }
    };
    for _ in 0..MAX_ITERATIONS {
        // gradient M (q̈ − q̈₀) − Jᵀ f and Hessian M + Jᵀ H_s J
        residual(&acceleration, &mut x);
        let mut row_hessian = DMatrix::zeros(count, count);
        forces_at(rows, &x, &mut forces, Some(&mut row_hessian));
        let f = DVector::from_column_slice(&forces);
        let gradient = mass * (&acceleration - free) - jacobian.transpose() * &f;
        let hessian = mass + jacobian.transpose() * &row_hessian * &jacobian;
        let step = -hessian
            .cholesky()
            .ok_or_else(|| Error::InvalidValue {
                argument: "model".into(),
                message: "the constraint problem's Hessian is not positive definite".into(),
            })?
            .solve(&gradient);
        let length = line_search(rows, mass, free, &jacobian, reference, &acceleration, &step);
        let change = &step * length;
        acceleration += &change;
        if change.amax() <= STEP_TOLERANCE * (1.0 + acceleration.amax()) {
            break;
        }
    }
    residual(&acceleration, &mut x);
    forces_at(rows, &x, &mut forces, None);
    Ok(Solution {
        acceleration,
        forces,
    })
}

/// The step length α minimising the cost along `step` from `start`: where its slope
/// `φ'(α) = δᵀ M (q̈ + α δ − q̈₀) − (J δ)ᵀ f(α)` (monotone) changes sign.
fn line_search(
    rows: &Rows,
    mass: &DMatrix<f64>,
    free: &DVector<f64>,
    jacobian: &DMatrix<f64>,
    reference: &[f64],
    start: &DVector<f64>,
    step: &DVector<f64>,
) -> f64 {
    let count = rows.len();
    let m_step = mass * step;
    let j_step = jacobian * step;
    let j_start = jacobian * start;
    let base = m_step.dot(&(start - free));
    let curvature = m_step.dot(step);
    let mut x = vec![0.0; count];
    let mut forces = vec![0.0; count];
    let mut slope = |alpha: f64| {
        for i in 0..count {
            x[i] = j_start[i] + alpha * j_step[i] - reference[i];
        }
        forces_at(rows, &x, &mut forces, None);
        base + alpha * curvature
            - forces
                .iter()
                .zip(j_step.iter())
                .map(|(f, j)| f * j)
                .sum::<f64>()
    };
    // bracket the root: φ'(0) < 0; Newton's full step first
    let (mut low, mut slope_low) = (0.0, slope(0.0));
    if slope_low >= 0.0 {
        return 0.0;
    }
    let (mut high, mut slope_high) = (1.0, slope(1.0));
    while slope_high < 0.0 {
        (low, slope_low) = (high, slope_high);
        high *= 2.0;
        slope_high = slope(high);
        if high > 1e6 {
            return high;
        }
    }
    if slope_high == 0.0 {
        return high;
    }
    // the slope is piecewise linear: secant steps, halving where they stall (Illinois)
    let mut side = 0;
    for _ in 0..LINE_ITERATIONS {
        let alpha = (low * slope_high - high * slope_low) / (slope_high - slope_low);
        let value = slope(alpha);
        if value == 0.0 || (high - low) <= f64::EPSILON * high {
            return alpha;
        }
        if value < 0.0 {
            (low, slope_low) = (alpha, value);
            if side == -1 {
                slope_high *= 0.5;
            }
            side = -1;
        } else {
            (high, slope_high) = (alpha, value);
            if side == 1 {
                slope_low *= 0.5;
            }
            side = 1;
        }
    }
    (low * slope_high - high * slope_low) / (slope_high - slope_low)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed forms by hand: exact up to round-off.
    const EXACT: f64 = 1e-12;

    fn one_row(kind: RowKind, regulariser: f64, frictionloss: f64) -> Rows {
        Rows {
            nv: 1,
            jacobian: vec![1.0],
            kind: vec![kind],
            id: vec![0],
            position: vec![0.0],
            margin: vec![0.0],
            frictionloss: vec![frictionloss],
            regulariser: vec![regulariser],
            reference: vec![0.0],
            groups: vec![Group {
                first: 0,
                len: 1,
                kind,
                mu: 0.0,
                friction: [0.0; 5],
            }],
            contact_rows: Vec::new(),
        }
    }

    #[test]
    fn a_limit_row_meets_the_free_motion_halfway_by_its_softness() {
        // m = 2 falling at q̈₀ = −9.81 onto a row asking a_ref = 1 with D = 1/R = 6:
        // q̈ = (m q̈₀ + D a_ref)/(m + D), f = −D (q̈ − a_ref)
        let (mass, free, reference, regulariser) = (2.0, -9.81, 1.0, 1.0 / 6.0);
        let rows = one_row(RowKind::LimitJoint, regulariser, 0.0);
        let solution = solve(
            &rows,
            &DMatrix::from_element(1, 1, mass),
            &DVector::from_element(1, free),
            &[reference],
        )
        .expect("solvable");
        let expected = (mass * free + 6.0 * reference) / (mass + 6.0);
        assert!((solution.acceleration[0] - expected).abs() < EXACT);
        assert!((solution.forces[0] + 6.0 * (expected - reference)).abs() < EXACT);
    }

    #[test]
    fn a_limit_row_leaves_motion_away_from_it_alone() {
        let rows = one_row(RowKind::LimitJoint, 0.1, 0.0);
        let one = DMatrix::from_element(1, 1, 1.0);
        let solution =
            solve(&rows, &one, &DVector::from_element(1, 3.0), &[1.0]).expect("solvable");
        assert_eq!((solution.acceleration[0], solution.forces[0]), (3.0, 0.0));
    }

    #[test]
    fn dry_friction_saturates_at_its_largest_force() {
        // m = 1 pushed at q̈₀ = 5 against friction 2 (R = 1e-3): sliding, f = −2, q̈ = 3
        let rows = one_row(RowKind::FrictionDof, 1e-3, 2.0);
        let one = DMatrix::from_element(1, 1, 1.0);
        let solution =
            solve(&rows, &one, &DVector::from_element(1, 5.0), &[0.0]).expect("solvable");
        assert!((solution.forces[0] + 2.0).abs() < EXACT);
        assert!((solution.acceleration[0] - 3.0).abs() < EXACT);
    }
}
