//! Inverse dynamics under rigid constraints: the torques of the actuated joints and the
//! constraint forces that together give a wanted acceleration (whole-body control's problem).
//!
//! Reference: Featherstone, *Rigid Body Dynamics Algorithms* (2008), §8.1 and §9.3 (floating
//! bases: the base's coordinates have no actuator); Mistry, Buchli and Schaal, "Inverse dynamics
//! control of floating base systems using orthogonal decomposition", ICRA 2010, for the split.
//! With S selecting the actuated coordinates and u the others:
//! ```text
//!   M q̈ + h = Sᵀ τ_a + Jᵀ λ       rows u:  J_uᵀ λ = (M q̈ + h)_u      rows a:  τ_a = (M q̈ + h − Jᵀ λ)_a
//! ```
//! λ is the least-norm solution of the u rows, or with weights W (diagonal, > 0) the one of least
//! λᵀ W λ: λ = W⁻¹ J_u y with (J_uᵀ W⁻¹ J_u) y = (M q̈ + h)_u, solved by proximal iterations (it
//! is singular when the forces are not unique). q̈ must satisfy the
//! constraints, `J q̈ + γ = 0`; a q̈ that does not, or that the forces cannot produce, is refused
//! with its residual. Writes `constraints.tau` (zero on coordinates not actuated),
//! `constraints.forces`, J, γ, φ, and RNEA's fields of `data`.

use super::solve::{largest, solve_symmetric, SolveFailure, SolveScratch};
use super::{constraint_rows, ConstraintData};
use crate::algo::rnea::newton_euler;
use crate::constraint::ConstraintSet;
use crate::error::{check_length, check_vector, Error, Result};
use crate::model::Model;
use crate::spatial::Force;
use crate::Data;

/// `|J q̈ + γ|∞` above this times `1 + |γ|∞ + |J|∞ |q̈|∞` means q̈ breaks the constraints; the
/// same test on `J_uᵀ λ = (M q̈ + h)_u` means the constraint forces cannot produce q̈.
pub const CONSTRAINT_ACCELERATION_TOLERANCE: f64 = 1e-9;

/// The damping of the proximal solve for the least-norm forces, relative to the largest
/// diagonal entry of `J_uᵀ J_u` (any μ > 0 gives the same limit; this one converges in a few
/// iterations).
const LEAST_NORM_DAMPING: f64 = 1e-8;

/// τ (on the `actuated` coordinates) and λ that produce `a` under the constraints of `set`, with
/// `f_ext` as in [`crate::algo::rnea()`]. `actuated` has one flag per velocity coordinate;
/// `weights` one per row (> 0; `None`: all 1): where the forces are not unique, those of least
/// `Σ w_r λ_r²` (a heavier weight, less force on that row).
#[allow(clippy::too_many_arguments)]
pub fn constrained_inverse_dynamics(
    model: &Model,
    data: &mut Data,
    constraints: &mut ConstraintData,
    set: &ConstraintSet,
    (q, v, a): (&[f64], &[f64], &[f64]),
    f_ext: Option<&[Force]>,
    actuated: &[bool],
    weights: Option<&[f64]>,
) -> Result<()> {
    super::check_fits(model, constraints, set)?;
    check_vector("v", v, model.nv)?;
    check_vector("a", a, model.nv)?;
    check_length("actuated", actuated.len(), model.nv)?;
    let m = set.rows();
    check_weights(weights, m)?;
    // W⁻¹ of row r
    let inverse_weight = |r: usize| weights.map_or(1.0, |w| 1.0 / w[r]);

    // J q̈ + γ = 0 must hold
    constraint_rows(model, data, constraints, set, q, v)?;
    let (jacobian, drift) = (&constraints.jacobian, &constraints.drift);
    let scale = 1.0 + largest(drift.as_slice()) + largest(jacobian.as_slice()) * largest(a);
    for r in 0..m {
        let value: f64 = jacobian
            .row(r)
            .iter()
            .zip(a)
            .map(|(j, x)| j * x)
            .sum::<f64>()
            + drift[r];
        if value.abs() > CONSTRAINT_ACCELERATION_TOLERANCE * scale {
            return Err(Error::InvalidValue {
                argument: "a".into(),
                message: format!(
                    "the acceleration breaks the constraints: J a + γ = {value:.3e} on {}",
                    set.describe_row(model, r)
                ),
            });
        }
    }

    // τ_full = M q̈ + h (RNEA, with f_ext)
    let tau_full = newton_euler(model, data, q, Some(v), Some(a), f_ext)?;
    let ConstraintData {
        jacobian,
        forces,
        tau,
        rhs,
        factor,
        gram,
        unknowns,
        residual,
        step,
        iterations,
        ..
    } = constraints;
    tau.copy_from(tau_full);

    // the rows u: (J_uᵀ W⁻¹ J_u) y = τ_full,u
    let unactuated = || (0..model.nv).filter(|&c| !actuated[c]);
    let n = unactuated().count();
    for (i, ci) in unactuated().enumerate() {
        rhs[i] = tau[ci];
        for (j, cj) in unactuated().enumerate() {
            gram[i + j * n] = (0..m)
                .map(|r| jacobian[(r, ci)] * inverse_weight(r) * jacobian[(r, cj)])
                .sum();
        }
    }
    let damping = LEAST_NORM_DAMPING * (0..n).fold(0.0f64, |d, i| d.max(gram[i + i * n]));
    forces.fill(0.0);
    *iterations = 0;
    if damping > 0.0 {
        let scratch = SolveScratch { residual, step };
        let scale = 1.0 + largest(&rhs[..n]);
        let solved = solve_symmetric(n, gram, factor, rhs, unknowns, damping, scale, scratch);
        *iterations = match solved {
            Ok(count) => count,
            Err(SolveFailure::Inconsistent { .. }) | Err(SolveFailure::DependentRow(_)) => 0,
        };
        // λ = W⁻¹ J_u y
        for (i, ci) in unactuated().enumerate() {
            forces.axpy(unknowns[i], &jacobian.column(ci), 1.0);
        }
        for (r, force) in forces.iter_mut().enumerate() {
            *force *= inverse_weight(r);
        }
    }

    // J_uᵀ λ = τ_full,u must hold; τ_a = (τ_full − Jᵀ λ)_a
    let scale = 1.0 + largest(&rhs[..n]);
    for c in 0..model.nv {
        let force = jacobian.column(c).dot(forces);
        if actuated[c] {
            tau[c] -= force;
            continue;
        }
        if (tau[c] - force).abs() > CONSTRAINT_ACCELERATION_TOLERANCE * scale {
            return Err(Error::InvalidValue {
                argument: "a".into(),
                message: format!(
                    "the constraint forces cannot produce this acceleration: coordinate {c} \
                     (not actuated) needs {:.6e} N or N m, the constraints give at most \
                     {force:.6e}",
                    tau[c]
                ),
            });
        }
        tau[c] = 0.0;
    }
    Ok(())
}

/// Refuses weights that are not one finite positive number per row.
fn check_weights(weights: Option<&[f64]>, rows: usize) -> Result<()> {
    let Some(weights) = weights else {
        return Ok(());
    };
    check_length("weights", weights.len(), rows)?;
    match weights.iter().position(|w| !(w.is_finite() && *w > 0.0)) {
        None => Ok(()),
        Some(r) => Err(Error::InvalidValue {
            argument: "weights".into(),
            message: format!(
                "expected one finite weight > 0 per constraint row, got {} for row {r}",
                weights[r]
            ),
        }),
    }
}
