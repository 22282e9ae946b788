//! Forward dynamics and impulses under rigid constraints.
//!
//! Reference: Featherstone, *Rigid Body Dynamics Algorithms* (2008), §8.3 (the constraint forces
//! from the constraint-space inverse inertia) and §11.6 (impulses); Pinocchio's
//! `constraintDynamics` and `impulseDynamics` compute the same quantities. See the module's
//! header for the equations. Inputs: q, q̇, τ (or only q, q̇), the constraint set. Writes
//! `constraints.qdd`, `constraints.forces` and everything on the way (J, γ, φ, Y, Λ⁻¹), and
//! in `data`: RNEA's fields, the mass matrix and its factor, the body placements. Cost: RNEA,
//! CRBA and M's factor, one sweep of the factor per row and two for the forces, O(m² d) for Λ⁻¹
//! (d: the coordinates the rows reach) and O(m³) to solve it.

use super::solve::largest;
use super::{
    constraint_rows, delassus_matrix, factor_inertia, product_scale, solve_forces, ConstraintData,
};
use crate::algo::ltdl::{solve_lower_rows, solve_transposed_rows};
use crate::algo::rnea::newton_euler;
use crate::constraint::ConstraintSet;
use crate::error::{check_vector, Error, Result};
use crate::model::Model;
use crate::spatial::Force;
use crate::Data;
use nalgebra::{DVectorView, DVectorViewMut};

/// How the constraint equations are solved.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ConstrainedOptions {
    /// Baumgarte's gains `(K_p, K_d)` (1/s², 1/s): the rows' acceleration is held to
    /// `−K_d J q̇ − K_p φ` instead of zero, pulling a drifting loop back. `None`: zero.
    pub baumgarte: Option<(f64, f64)>,
    /// μ ≥ 0: with μ > 0 the forces are found by proximal iterations on `Λ⁻¹ + μ 1`, which
    /// accept redundant rows (least-norm forces); with 0 a redundant row is an error naming it.
    pub damping: f64,
}

impl ConstrainedOptions {
    /// Refuses negative or non-finite gains and damping.
    pub fn check(&self) -> Result<()> {
        let (kp, kd) = self.baumgarte.unwrap_or((0.0, 0.0));
        for (name, value) in [
            ("baumgarte", kp),
            ("baumgarte", kd),
            ("damping", self.damping),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(Error::InvalidValue {
                    argument: name.into(),
                    message: format!("expected a finite value ≥ 0, got {value}"),
                });
            }
        }
        Ok(())
    }
}

/// q̈ and λ under the constraints of `set`: `M q̈ + h = τ + Jᵀ λ`, `J q̈ + γ = −K_d J q̇ − K_p φ`.
/// `f_ext` as in [`crate::algo::rnea()`]. Results in `constraints.qdd` and `constraints.forces`.
#[allow(clippy::too_many_arguments)]
pub fn constrained_forward_dynamics(
    model: &Model,
    data: &mut Data,
    constraints: &mut ConstraintData,
    set: &ConstraintSet,
    (q, v, tau): (&[f64], &[f64], &[f64]),
    f_ext: Option<&[Force]>,
    options: &ConstrainedOptions,
) -> Result<()> {
    super::check_fits(model, constraints, set)?;
    check_vector("v", v, model.nv)?;
    check_vector("tau", tau, model.nv)?;
    options.check()?;

    // z = L⁻ᵀ (τ − h), h = C q̇ + g − Σ Jᵀ f_ext (RNEA with q̈ = 0), M = Lᵀ D L; a_f = L⁻¹ D⁻¹ z
    let h = newton_euler(model, data, q, Some(v), None, f_ext)?;
    for ((z, t), b) in constraints.swept_force.iter_mut().zip(tau).zip(h.iter()) {
        *z = t - b;
    }
    factor_inertia(model, data, q)?;
    solve_transposed_rows(model, data, constraints.swept_force.as_mut_slice());

    // J, γ, φ; then Y = L⁻ᵀ Jᵀ and Λ⁻¹ = Yᵀ D⁻¹ Y
    constraint_rows(model, data, constraints, set, q, v)?;
    delassus_matrix(model, data, constraints);

    // Λ⁻¹ λ = −(J a_f + γ + K_d J q̇ + K_p φ), J a_f = Yᵀ D⁻¹ z
    let m = set.rows();
    let ConstraintData {
        jacobian,
        factored_rows,
        drift,
        error,
        swept_force,
        scaled_force,
        rhs,
        step,
        ..
    } = constraints;
    for (k, (scaled, z)) in scaled_force.iter_mut().zip(swept_force.iter()).enumerate() {
        *scaled = z / data.mass_matrix_factor[(k, k)];
    }
    let mut right = DVectorViewMut::from_slice(&mut rhs[..m], m);
    right.gemv(-1.0, factored_rows, scaled_force, 0.0);
    right.axpy(-1.0, drift, 1.0);
    let (kp, kd) = options.baumgarte.unwrap_or((0.0, 0.0));
    let mut scale = 1.0
        + product_scale(factored_rows, scaled_force.as_slice(), step)
        + largest(drift.as_slice());
    if kd != 0.0 {
        right.gemv(-kd, jacobian, &DVectorView::from_slice(v, v.len()), 1.0);
        scale += kd * product_scale(jacobian, v, step);
    }
    if kp != 0.0 {
        right.axpy(-kp, error, 1.0);
        scale += kp * largest(error.as_slice());
    }
    solve_forces(model, set, constraints, options.damping, scale)?;

    // q̈ = a_f + M⁻¹ Jᵀ λ = L⁻¹ D⁻¹ (z + Y λ)
    let ConstraintData {
        factored_rows,
        forces,
        swept_force,
        qdd,
        ..
    } = constraints;
    qdd.copy_from(swept_force);
    qdd.gemv_tr(1.0, factored_rows, forces, 1.0);
    solve_lower_rows(model, data, qdd.as_mut_slice());
    Ok(())
}

/// q̇ after an impact that makes the constraints of `set` hold at velocity level:
/// `M (q̇⁺ − q̇) = Jᵀ Λ`, `J q̇⁺ = −e J q̇` (e: `restitution`, from 0, plastic, to 1, elastic).
/// Results: q̇⁺ in `constraints.qdd`, the impulses Λ in `constraints.forces`.
pub fn impulse_dynamics(
    model: &Model,
    data: &mut Data,
    constraints: &mut ConstraintData,
    set: &ConstraintSet,
    (q, v): (&[f64], &[f64]),
    restitution: f64,
    damping: f64,
) -> Result<()> {
    super::check_fits(model, constraints, set)?;
    check_vector("v", v, model.nv)?;
    if !(0.0..=1.0).contains(&restitution) {
        return Err(Error::InvalidValue {
            argument: "restitution".into(),
            message: format!("expected a value from 0 to 1, got {restitution}"),
        });
    }
    let options = ConstrainedOptions {
        baumgarte: None,
        damping,
    };
    options.check()?;
    factor_inertia(model, data, q)?;
    constraint_rows(model, data, constraints, set, q, v)?;
    delassus_matrix(model, data, constraints);

    // Λ⁻¹ Λ = −(1 + e) J q̇
    let m = set.rows();
    let ConstraintData {
        jacobian,
        rhs,
        step,
        ..
    } = constraints;
    let velocity = DVectorView::from_slice(v, v.len());
    DVectorViewMut::from_slice(&mut rhs[..m], m).gemv(
        -(1.0 + restitution),
        jacobian,
        &velocity,
        0.0,
    );
    let scale = 1.0 + (1.0 + restitution) * product_scale(jacobian, v, step);
    solve_forces(model, set, constraints, damping, scale)?;

    // q̇⁺ = q̇ + M⁻¹ Jᵀ Λ = q̇ + L⁻¹ D⁻¹ (Y Λ)
    let ConstraintData {
        factored_rows,
        forces,
        qdd,
        ..
    } = constraints;
    qdd.gemv_tr(1.0, factored_rows, forces, 0.0);
    solve_lower_rows(model, data, qdd.as_mut_slice());
    *qdd += velocity;
    Ok(())
}
