//! Dynamics under rigid constraints: forward dynamics, impulses and inverse dynamics with the
//! constraints of a [`ConstraintSet`], the constraint Jacobian and Delassus matrix, and a
//! configuration at which the constraints hold (`closure`).
//!
//! Reference: Featherstone, *Rigid Body Dynamics Algorithms* (2008), §8.1-8.3 (the constrained
//! equations of motion, solved through the constraint-space inverse inertia), Table 7.1 (the
//! articulated-body algorithm) and §6.5 (the tree-sparse factorisation M = Lᵀ D L); Carpentier,
//! Budhiraja and Mansard, RSS 2021 (the proximal solve). The equations, with J the constraint rows and γ = J̇ q̇ their drift:
//! ```text
//!   M q̈ + h = τ + Jᵀ λ,      J q̈ + γ = −K_d J q̇ − K_p φ   (Baumgarte's terms optional)
//! ```
//! With the free acceleration `a_f = M⁻¹ (τ − h)` and the Delassus matrix `Λ⁻¹ = J M⁻¹ Jᵀ`:
//! ```text
//!   Λ⁻¹ λ = −(J a_f + γ + K_d J q̇ + K_p φ),      q̈ = a_f + M⁻¹ Jᵀ λ
//! ```
//! Forward dynamics and impulses never form M: the articulated-body algorithm gives a_f, and its
//! inward pass run on each row of J gives Λ⁻¹ and M⁻¹ Jᵀ λ (`articulated`: O(n + m d + m² d +
//! m³), d the bodies the rows reach). The Delassus matrix on its own and the derivatives take
//! M's tree-sparse factor M = Lᵀ D L and Y = L⁻ᵀ Jᵀ (the factor's first sweep, which keeps each
//! row's zeros outside its bodies' ancestors): `Λ⁻¹ = Yᵀ D⁻¹ Y` (Featherstone §6.5 and §8.3).
//! Λ⁻¹ is solved by Cholesky, or, with damping μ > 0, by proximal iterations that give the
//! least-norm forces of a redundant set (a loop closure stated twice).
//! The results live in a [`ConstraintData`] made for the set.

mod articulated;
mod closure;
mod derivatives;
mod forward;
mod inverse;
mod solve;

pub(crate) use articulated::{
    articulated_delassus, constrained_accelerations, constraint_response, rows_under_free_motion,
    support_acceleration_pass, AbaTerms, RouteBuffers,
};
pub use closure::{close_constraints, Closure, ClosureOptions};
pub use derivatives::{
    constrained_forward_dynamics_derivatives, impulse_dynamics_derivatives, ConstrainedDerivatives,
};
pub(crate) use forward::{accelerated_right_side, check_impact, impact_right_side};
pub use forward::{constrained_forward_dynamics, impulse_dynamics, ConstrainedOptions};
pub use inverse::{constrained_inverse_dynamics, CONSTRAINT_ACCELERATION_TOLERANCE};
pub(crate) use solve::solve_direct;
pub use solve::{
    DEPENDENT_ROW_TOLERANCE, PROXIMAL_ACCURACY, PROXIMAL_MAX_ITERATIONS, STALLED_ACCURACY,
};

use crate::algo::crba::crba;
use crate::algo::kinematics::{update_body_placements, update_velocity_products};
use crate::algo::ltdl::{factor_mass_matrix, solve_lower_rows, solve_transposed_rows};
use crate::constraint::{evaluate, BodyMotion, ConstraintRows, ConstraintSet};
use crate::error::{check_vector, Error, Result};
use crate::model::Model;
use crate::spatial::{Force, Motion};
use crate::Data;
use nalgebra::{DMatrix, DVector, Vector6};
use solve::{factor_symmetric, solve_symmetric, SolveFailure, SolveScratch};

/// The workspace and results of the constrained algorithms for one [`ConstraintSet`] (m rows)
/// on one model (nv coordinates). Made once by [`ConstraintData::new`].
#[derive(Debug, Clone)]
pub struct ConstraintData {
    /// J (m × nv): the rows' velocity is `J q̇`. Written by every algorithm here.
    pub jacobian: DMatrix<f64>,
    /// γ = J̇ q̇ (m): the rows' acceleration is `J q̈ + γ`.
    pub drift: DVector<f64>,
    /// φ (m): how far each row is from holding (zero for a point held where it is).
    pub error: DVector<f64>,
    /// Yᵀ = (L⁻ᵀ Jᵀ)ᵀ (m × nv), J half solved by M's factor: `Λ⁻¹ = Yᵀ D⁻¹ Y`. Written by
    /// [`delassus`] and the derivatives (forward dynamics and impulses do not factor M).
    pub factored_rows: DMatrix<f64>,
    /// J M⁻¹ (m × nv). Written by the derivatives (from [`ConstraintData::factored_rows`]).
    pub jacobian_inverse_inertia: DMatrix<f64>,
    /// The Delassus matrix J M⁻¹ Jᵀ (m × m).
    pub delassus: DMatrix<f64>,
    /// λ (m): the constraint forces (or impulses) on the robot, `M q̈ + h = τ + Jᵀ λ`.
    pub forces: DVector<f64>,
    /// q̈ of [`constrained_forward_dynamics`], or q̇ after [`impulse_dynamics`] (nv).
    pub qdd: DVector<f64>,
    /// τ of [`constrained_inverse_dynamics`] (nv, zero on coordinates not actuated).
    pub tau: DVector<f64>,
    /// The proximal iterations the last solve took (0: solved directly).
    pub iterations: usize,
    /// Y = K Jᵀ as rows (m × nv): each row of J taken as a generalised force through ABA's
    /// inward pass, its u_i (see `articulated`): `Λ⁻¹ = Σ_i Y_iᵀ D_i⁻¹ Y_i`. Written by forward
    /// dynamics and impulses.
    transmitted_rows: DMatrix<f64>,
    /// The forces the inward passes of a constraint's rows (at most 6) carry to each body
    /// (nbodies; zero between uses).
    body_forces: Vec<[Force; 6]>,
    /// The bodies' accelerations: under the free acceleration, then those the forces add
    /// (nbodies).
    body_accelerations: Vec<Motion>,
    /// Yᵀ λ (nv), or zero where an algorithm needs a zero velocity or torque.
    joint_forces: DVector<f64>,
    /// One body's columns of Y, row by row, and D_i⁻¹ times them (m pairs of 6-vectors).
    body_rows: Vec<(Vector6<f64>, Vector6<f64>)>,
    /// The right-hand side of the last solve.
    rhs: Vec<f64>,
    /// Cholesky factor and scratch of the last solve (room for max(m, nv)).
    factor: Vec<f64>,
    gram: Vec<f64>,
    unknowns: Vec<f64>,
    residual: Vec<f64>,
    step: Vec<f64>,
}

impl ConstraintData {
    /// The workspace for `set` on `model`.
    pub fn new(model: &Model, set: &ConstraintSet) -> Self {
        let (m, nv) = (set.rows(), model.nv);
        let n = m.max(nv);
        ConstraintData {
            jacobian: DMatrix::zeros(m, nv),
            drift: DVector::zeros(m),
            error: DVector::zeros(m),
            factored_rows: DMatrix::zeros(m, nv),
            jacobian_inverse_inertia: DMatrix::zeros(m, nv),
            delassus: DMatrix::zeros(m, m),
            forces: DVector::zeros(m),
            qdd: DVector::zeros(nv),
            tau: DVector::zeros(nv),
            iterations: 0,
            transmitted_rows: DMatrix::zeros(m, nv),
            body_forces: vec![[Force::ZERO; 6]; model.nbodies()],
            body_accelerations: vec![Motion::ZERO; model.nbodies()],
            joint_forces: DVector::zeros(nv),
            body_rows: vec![(Vector6::zeros(), Vector6::zeros()); m],
            rhs: vec![0.0; n],
            factor: vec![0.0; n * n],
            gram: vec![0.0; n * n],
            unknowns: vec![0.0; n],
            residual: vec![0.0; n],
            step: vec![0.0; n],
        }
    }

    /// Whether this workspace was made for a set of `set`'s size on `model`.
    pub fn fits(&self, model: &Model, set: &ConstraintSet) -> bool {
        self.jacobian.nrows() == set.rows()
            && self.jacobian.ncols() == model.nv
            && self.body_forces.len() == model.nbodies()
    }
}

/// The constraint Jacobian J(q) of `set` (rows × nv), in `constraints.jacobian`.
pub fn constraint_jacobian<'c>(
    model: &Model,
    data: &mut Data,
    constraints: &'c mut ConstraintData,
    set: &ConstraintSet,
    q: &[f64],
) -> Result<&'c DMatrix<f64>> {
    check_fits(model, constraints, set)?;
    rows_at_rest(model, data, constraints, set, q)?;
    Ok(&constraints.jacobian)
}

/// The Delassus matrix J M⁻¹ Jᵀ of `set` at q (rows × rows), in `constraints.delassus`.
pub fn delassus<'c>(
    model: &Model,
    data: &mut Data,
    constraints: &'c mut ConstraintData,
    set: &ConstraintSet,
    q: &[f64],
) -> Result<&'c DMatrix<f64>> {
    check_fits(model, constraints, set)?;
    factor_inertia(model, data, q)?;
    rows_at_rest(model, data, constraints, set, q)?;
    delassus_matrix(model, data, constraints);
    Ok(&constraints.delassus)
}

/// [`constraint_rows`] at q̇ = 0 (J and φ; γ is then zero).
fn rows_at_rest(
    model: &Model,
    data: &mut Data,
    constraints: &mut ConstraintData,
    set: &ConstraintSet,
    q: &[f64],
) -> Result<()> {
    let mut rest = std::mem::take(&mut constraints.joint_forces);
    rest.fill(0.0);
    let result = constraint_rows(model, data, constraints, set, q, rest.as_slice());
    constraints.joint_forces = rest;
    result
}

/// Refuses a workspace made for another set or model.
fn check_fits(model: &Model, constraints: &ConstraintData, set: &ConstraintSet) -> Result<()> {
    if constraints.fits(model, set) {
        return Ok(());
    }
    Err(Error::Shape {
        argument: "constraints".into(),
        expected: format!(
            "a ConstraintData of {} rows and {} columns",
            set.rows(),
            model.nv
        ),
        received: format!(
            "{} rows and {} columns",
            constraints.jacobian.nrows(),
            constraints.jacobian.ncols()
        ),
    })
}

/// M(q) by CRBA and its factor M = Lᵀ D L (`data.mass_matrix`, `data.mass_matrix_factor`).
fn factor_inertia(model: &Model, data: &mut Data, q: &[f64]) -> Result<()> {
    crba(model, data, q)?;
    factor_mass_matrix(model, data)
}

/// J, γ and φ at (q, q̇) into `constraints` (see [`evaluate_rows`]).
fn constraint_rows(
    model: &Model,
    data: &mut Data,
    constraints: &mut ConstraintData,
    set: &ConstraintSet,
    q: &[f64],
    v: &[f64],
) -> Result<()> {
    let rows = ConstraintRows {
        jacobian: &mut constraints.jacobian,
        drift: constraints.drift.as_mut_slice(),
        error: constraints.error.as_mut_slice(),
    };
    evaluate_rows(model, data, set, (q, v), rows)
}

/// J, γ and φ of `set` at (q, q̇): the bodies' placements, velocities and accelerations with
/// q̈ = 0 (no gravity) by the outward pass of Table 5.1, then each constraint's rows. Writes
/// `data.x_up`, `data.x_world`, `data.v`, `data.a`.
pub(crate) fn evaluate_rows(
    model: &Model,
    data: &mut Data,
    set: &ConstraintSet,
    (q, v): (&[f64], &[f64]),
    rows: ConstraintRows,
) -> Result<()> {
    model.check_configuration(q)?;
    check_vector("v", v, model.nv)?;
    update_body_placements(model, data, q);
    update_velocity_products(model, data, v);
    let bodies = BodyMotion {
        x_world: &data.x_world,
        v: &data.v,
        a: &data.a,
    };
    evaluate(model, set, &bodies, (q, v), rows);
    Ok(())
}

/// The size of the terms of `Σ_c A_rc x_c` over the rows of the column-major `a`:
/// `max_r Σ_c |A_rc x_c|`, the scale of that product's rounding (`sums`: room for a's rows).
fn product_scale(a: &DMatrix<f64>, x: &[f64], sums: &mut [f64]) -> f64 {
    let sums = &mut sums[..a.nrows()];
    sums.fill(0.0);
    for (column, x_c) in a.column_iter().zip(x) {
        for (sum, a_rc) in sums.iter_mut().zip(column.iter()) {
            *sum += (a_rc * x_c).abs();
        }
    }
    solve::largest(sums)
}

/// Y = L⁻ᵀ Jᵀ by the factor's first sweep (one column per row), then
/// `Λ⁻¹ = J M⁻¹ Jᵀ = Yᵀ D⁻¹ Y = Σ_k y_k y_kᵀ / D_k` over the coordinates k some row reaches
/// (y_k: row k of Y; zero outside the rows' bodies' ancestors).
fn delassus_matrix(model: &Model, data: &Data, constraints: &mut ConstraintData) {
    let ConstraintData {
        jacobian,
        factored_rows,
        delassus,
        ..
    } = constraints;
    // column-major J (m × nv) is Jᵀ row by row: the sweep leaves Yᵀ
    factored_rows.copy_from(jacobian);
    solve_transposed_rows(model, data, factored_rows.as_mut_slice());
    delassus.fill(0.0);
    for (k, y_k) in factored_rows.column_iter().enumerate() {
        if y_k.iter().any(|y| *y != 0.0) {
            delassus.ger(1.0 / data.mass_matrix_factor[(k, k)], &y_k, &y_k, 1.0);
        }
    }
}

/// M by CRBA and its factor, `Λ⁻¹` by [`delassus_matrix`] and
/// `J M⁻¹ = (L⁻¹ D⁻¹ Y)ᵀ` in `constraints.jacobian_inverse_inertia` (the factor's second sweep),
/// with J already in `constraints`: what the derivatives' saddle-point solves take.
fn factor_with_rows(
    model: &Model,
    data: &mut Data,
    constraints: &mut ConstraintData,
    q: &[f64],
) -> Result<()> {
    factor_inertia(model, data, q)?;
    delassus_matrix(model, data, constraints);
    let ConstraintData {
        factored_rows,
        jacobian_inverse_inertia,
        ..
    } = constraints;
    jacobian_inverse_inertia.copy_from(factored_rows);
    solve_lower_rows(model, data, jacobian_inverse_inertia.as_mut_slice());
    Ok(())
}

/// Solves `Λ⁻¹ λ = rhs` (the right-hand side in `constraints.rhs`, computed from terms of size
/// `scale`) into `constraints.forces`; a dependent row without damping, or an inconsistent set,
/// is an error naming its rows.
#[inline(always)]
fn solve_forces(
    model: &Model,
    set: &ConstraintSet,
    constraints: &mut ConstraintData,
    damping: f64,
    scale: f64,
) -> Result<()> {
    let ConstraintData {
        delassus,
        rhs,
        factor,
        residual,
        step,
        forces,
        iterations,
        ..
    } = constraints;
    let scratch = SolveScratch { residual, step };
    let solved = solve_symmetric(
        set.rows(),
        delassus.as_slice(),
        factor,
        rhs,
        forces.as_mut_slice(),
        damping,
        scale,
        scratch,
    );
    *iterations = solved.map_err(|failure| refused(model, set, failure))?;
    Ok(())
}

/// The Cholesky factor of the Delassus matrix in `constraints.factor` (for the derivatives'
/// many right-hand sides); a dependent row is an error naming it, as for [`solve_forces`].
fn factor_delassus(
    model: &Model,
    set: &ConstraintSet,
    constraints: &mut ConstraintData,
) -> Result<()> {
    let ConstraintData {
        delassus, factor, ..
    } = constraints;
    factor_symmetric(set.rows(), delassus.as_slice(), factor)
        .map_err(|failure| refused(model, set, failure))
}

/// The error of a Delassus solve that failed, naming the row or the residual.
fn refused(model: &Model, set: &ConstraintSet, failure: SolveFailure) -> Error {
    match failure {
        SolveFailure::DependentRow(row) => Error::InvalidValue {
            argument: "constraints".into(),
            message: format!(
                "the constraints are redundant or singular at this configuration: {} is zero or \
                 a combination of the rows before it; pass damping > 0 for their least-norm \
                 forces",
                set.describe_row(model, row)
            ),
        },
        SolveFailure::Inconsistent { residual, scale } => Error::InvalidValue {
            argument: "constraints".into(),
            message: format!(
                "the constraints cannot all hold: the proximal iterations leave an acceleration \
                 (or velocity) residual of {residual:.3e}, {:.1e} of the terms' size {scale:.3e}",
                residual / scale
            ),
        },
    }
}
