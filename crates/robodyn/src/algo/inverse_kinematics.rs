//! Inverse kinematics by damped least squares (Levenberg–Marquardt), with joint limits and random
//! restarts.
//!
//! Reference: Wampler, "Manipulator inverse kinematic solutions based on vector formulations and
//! damped least-squares methods", IEEE SMC 16(1), 1986; Buss, "Introduction to inverse kinematics
//! with Jacobian transpose, pseudoinverse and damped least squares methods" (2004). Each step:
//! the task error e (full pose: `[Rᵀ(p* - p); log(Rᵀ R*)]` in the frame's axes with the local
//! Jacobian; position only: `p* - p` in world axes with the world Jacobian's linear rows), then
//! `Δq = Jᵀ (J Jᵀ + (½|e|² + λ²) 1)⁻¹ e` (the error-dependent damping of Sugihara, "Solvability-
//! unconcerned inverse kinematics by the Levenberg–Marquardt method", IEEE T-RO 27(5), 2011),
//! `q ← clamp(q ⊕ Δq)` to the position limits.
//! Writes what `jacobian` writes. Allocates its small work matrices.

use crate::algo::jacobian::{jacobian, Reference};
use crate::algo::kinematics::{check_frame, frame_pose};
use crate::error::{check_finite, Error, Result};
use crate::model::Model;
use crate::spatial::{log_rotation, Mat3, Transform, Vec3};
use crate::Data;
use nalgebra::{DMatrix, DVector, UnitQuaternion};
use rand::Rng;

/// Settings of [`inverse_kinematics`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkOptions {
    /// Solve for the frame's position only (3 equations) instead of its pose (6).
    pub position_only: bool,
    /// Converged when the error norm (m and rad) is below this.
    pub tolerance: f64,
    /// Steps per attempt.
    pub max_iterations: usize,
    /// Attempts from random configurations after the first one fails.
    pub restarts: usize,
    /// λ of the damped least squares.
    pub damping: f64,
}

impl Default for IkOptions {
    fn default() -> Self {
        IkOptions {
            position_only: false,
            tolerance: 1e-10,
            max_iterations: 200,
            restarts: 20,
            damping: 1e-6,
        }
    }
}

/// What [`inverse_kinematics`] found: the best configuration, whether it meets the tolerance,
/// the steps taken over all attempts and the final error norm.
#[derive(Debug, Clone, PartialEq)]
pub struct IkSolution {
    /// The configuration with the smallest error found, length nq.
    pub q: DVector<f64>,
    /// Whether `residual` is below the tolerance.
    pub success: bool,
    /// Steps taken, summed over all attempts.
    pub iterations: usize,
    /// The error norm (m and rad) at `q`.
    pub residual: f64,
}

/// A configuration placing frame `frame` at `target` (the desired `X_{frame←0}`, i.e. its pose),
/// starting from `q0`, then from random configurations.
pub fn inverse_kinematics<R: Rng>(
    model: &Model,
    data: &mut Data,
    frame: usize,
    target: &Transform,
    q0: &[f64],
    options: &IkOptions,
    rng: &mut R,
) -> Result<IkSolution> {
    model.check_configuration(q0)?;
    check_frame(model, frame)?;
    check_finite("target", target.to_homogeneous().as_slice())?;
    if !(options.tolerance > 0.0 && options.damping >= 0.0 && options.damping.is_finite()) {
        return Err(Error::InvalidValue {
            argument: "options".into(),
            message: format!(
                "expected tolerance > 0 and a finite damping >= 0, got {} and {}",
                options.tolerance, options.damping
            ),
        });
    }
    let mut best = IkSolution {
        q: DVector::from_column_slice(q0),
        success: false,
        iterations: 0,
        residual: f64::INFINITY,
    };
    let mut iterations = 0;
    for attempt in 0..=options.restarts {
        let start = if attempt == 0 {
            DVector::from_column_slice(q0)
        } else {
            model.random_configuration(rng)
        };
        let (q, residual, steps) = solve_from(model, data, frame, target, start, options)?;
        iterations += steps;
        if residual < best.residual {
            best.q = q;
            best.residual = residual;
        }
        if best.residual < options.tolerance {
            break;
        }
    }
    best.success = best.residual < options.tolerance;
    best.iterations = iterations;
    Ok(best)
}

/// One damped-least-squares descent; returns the configuration, its error norm and the steps.
fn solve_from(
    model: &Model,
    data: &mut Data,
    frame: usize,
    target: &Transform,
    mut q: DVector<f64>,
    options: &IkOptions,
) -> Result<(DVector<f64>, f64, usize)> {
    let rows = if options.position_only { 3 } else { 6 };
    let mut step = DVector::zeros(model.nv);
    let mut next = DVector::zeros(model.nq);
    for iteration in 0..options.max_iterations {
        let error = task_error(model, data, &q, frame, target, options.position_only)?;
        if error.norm() < options.tolerance {
            return Ok((q, error.norm(), iteration));
        }
        let reference = if options.position_only {
            Reference::World
        } else {
            Reference::Local
        };
        let j = jacobian(model, data, q.as_slice(), frame, reference)?
            .rows(0, rows)
            .into_owned();
        // Δq = Jᵀ (J Jᵀ + (½|e|² + λ²) 1)⁻¹ e: damping that grows with the error keeps the
        // steps bounded near singularities and for unreachable targets (Sugihara 2011)
        let damping = 0.5 * error.norm_squared() + options.damping.powi(2);
        let system = &j * j.transpose() + DMatrix::identity(rows, rows) * damping;
        let Some(factor) = system.cholesky() else {
            // a singular J Jᵀ without damping: this attempt ends here
            let residual = error.norm();
            return Ok((q, residual, iteration));
        };
        step.copy_from(&(j.transpose() * factor.solve(&error)));
        model.integrate(q.as_slice(), step.as_slice(), next.as_mut_slice())?;
        // stay within the position limits
        for (k, value) in next.iter_mut().enumerate() {
            *value = value.clamp(model.lower_position_limit[k], model.upper_position_limit[k]);
        }
        q.copy_from(&next);
    }
    let residual = task_error(model, data, &q, frame, target, options.position_only)?.norm();
    Ok((q, residual, options.max_iterations))
}

/// The task error: `p* - p` (world axes) or `[Rᵀ(p* - p); log(Rᵀ R*)]` (frame axes).
fn task_error(
    model: &Model,
    data: &mut Data,
    q: &DVector<f64>,
    frame: usize,
    target: &Transform,
    position_only: bool,
) -> Result<DVector<f64>> {
    let current = frame_pose(model, data, q.as_slice(), frame)?;
    let position_error: Vec3 = target.translation - current.translation;
    if position_only {
        return Ok(DVector::from_column_slice(position_error.as_slice()));
    }
    // poses: R = Eᵀ; Rᵀ R* = E E*ᵀ
    let relative: Mat3 = current.rotation * target.rotation.transpose();
    let rotation_error = log_rotation(&UnitQuaternion::from_matrix(&relative));
    let local = current.rotation * position_error;
    Ok(DVector::from_iterator(
        6,
        local.iter().chain(rotation_error.iter()).copied(),
    ))
}
