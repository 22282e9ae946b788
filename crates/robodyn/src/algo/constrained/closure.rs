//! Closing constraints at position level: a configuration near q at which every row holds.
//!
//! Reference: Nocedal and Wright, *Numerical Optimization* (2nd ed.), §10.3 (Gauss–Newton and
//! Levenberg–Marquardt); the same step as the assembly of a closed-loop mechanism (Haug,
//! *Computer Aided Kinematics and Dynamics of Mechanical Systems*, 1989, §3.5). Each iteration
//! takes the least-squares step on the rows' errors φ(q) with a damping μ relative to the
//! largest diagonal entry of J Jᵀ:
//! ```text
//!   δ = −Jᵀ (J Jᵀ + μ 1)⁻¹ φ,      q ← q ⊕ δ
//! ```
//! the least-norm correction of the linearised rows (so q moves as little as it must); rows
//! that repeat others (a loop stated twice, Cassie's out-of-plane rows) are taken care of by μ.
//! Writes what [`super::constraint_jacobian`] writes, `constraints.delassus` (J Jᵀ + μ 1),
//! `constraints.forces` (the step's multipliers) and `constraints.qdd` (the step δ). Allocates
//! one configuration.

use super::solve::{largest, solve_direct};
use super::{rows_at_rest, ConstraintData};
use crate::constraint::ConstraintSet;
use crate::error::{check_length, Error, Result};
use crate::model::Model;
use crate::Data;

/// Settings of [`close_constraints`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosureOptions {
    /// Closed when every row's error |φ_r| is at most this (m, rad, or the row's unit).
    pub tolerance: f64,
    /// Steps at most.
    pub max_iterations: usize,
    /// μ / max_r (J Jᵀ)_rr, > 0: the Levenberg–Marquardt damping, relative.
    pub damping: f64,
}

impl Default for ClosureOptions {
    fn default() -> Self {
        ClosureOptions {
            tolerance: 1e-12,
            max_iterations: 50,
            damping: 1e-8,
        }
    }
}

impl ClosureOptions {
    /// Refuses a tolerance or damping that is not finite and positive.
    pub fn check(&self) -> Result<()> {
        for (name, value) in [("tolerance", self.tolerance), ("damping", self.damping)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(Error::InvalidValue {
                    argument: name.into(),
                    message: format!("expected a finite value > 0, got {value}"),
                });
            }
        }
        Ok(())
    }
}

/// What [`close_constraints`] reached.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Closure {
    /// Whether every row's error is within the tolerance.
    pub success: bool,
    /// Steps taken.
    pub iterations: usize,
    /// The largest row error |φ_r| at the result.
    pub residual: f64,
}

/// A configuration near `q` (into `out`, nq) at which the rows of `set` hold, by damped
/// Gauss–Newton steps from `q`. A set that cannot hold ends with `success` false and the
/// configuration of the last step.
pub fn close_constraints(
    model: &Model,
    data: &mut Data,
    constraints: &mut ConstraintData,
    set: &ConstraintSet,
    q: &[f64],
    out: &mut [f64],
    options: &ClosureOptions,
) -> Result<Closure> {
    super::check_fits(model, constraints, set)?;
    options.check()?;
    check_length("out", out.len(), model.nq)?;
    model.check_configuration(q)?;
    out.copy_from_slice(q);
    let mut start = vec![0.0; model.nq];
    let m = set.rows();
    let mut iterations = 0;
    loop {
        // J and φ at the current configuration
        rows_at_rest(model, data, constraints, set, out)?;
        let residual = largest(constraints.error.as_slice());
        if residual <= options.tolerance || iterations == options.max_iterations {
            return Ok(Closure {
                success: residual <= options.tolerance,
                iterations,
                residual,
            });
        }
        let ConstraintData {
            jacobian,
            error,
            delassus,
            factor,
            rhs,
            forces,
            qdd: step,
            ..
        } = constraints;
        // G = J Jᵀ + μ 1
        delassus.fill(0.0);
        for column in jacobian.column_iter() {
            delassus.ger(1.0, &column, &column, 1.0);
        }
        let mu = options.damping * (0..m).fold(0.0f64, |g, r| g.max(delassus[(r, r)]));
        if mu == 0.0 {
            // J = 0: no step changes φ
            return Ok(Closure {
                success: false,
                iterations,
                residual,
            });
        }
        for r in 0..m {
            delassus[(r, r)] += mu;
        }
        // G x = −φ;  δ = Jᵀ x
        for (b, phi) in rhs.iter_mut().zip(error.iter()) {
            *b = -phi;
        }
        solve_direct(m, delassus.as_slice(), factor, rhs, forces.as_mut_slice())
            .map_err(|_| not_finite(iterations))?;
        step.gemv_tr(1.0, jacobian, forces, 0.0);
        // q ← q ⊕ δ
        start.copy_from_slice(out);
        model.integrate(&start, step.as_slice(), out)?;
        iterations += 1;
    }
}

/// The error of a step whose damped system could not be solved: only a row error or Jacobian
/// that is not finite leaves J Jᵀ + μ 1 without a Cholesky factor.
fn not_finite(iterations: usize) -> Error {
    Error::InvalidValue {
        argument: "q".into(),
        message: format!(
            "closing the constraints met a row error or Jacobian that is not finite after {iterations} step(s)"
        ),
    }
}
