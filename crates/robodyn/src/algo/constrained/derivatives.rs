//! Derivatives of constrained forward dynamics and of impulses with respect to q (tangent
//! space, right perturbations q ⊕ δ, as [`crate::algo::aba_derivatives`]), q̇ and τ.
//!
//! Reference: the implicit function theorem on the equations of motion (Featherstone,
//! *Rigid Body Dynamics Algorithms* (2008), §8.3); Carpentier and Mansard, "Analytical
//! derivatives of rigid body dynamics algorithms", RSS 2018, for the inverse-dynamics
//! derivatives they are built from. Forward dynamics solves
//! ```text
//!   ID(q, q̇, q̈) − J(q)ᵀ λ = τ,        J(q) q̈ + γ(q, q̇) = 0
//! ```
//! Holding them along a change dx of x ∈ {q, q̇, τ} gives the same saddle-point matrix as the
//! dynamics themselves:
//! ```text
//!   [ M  −Jᵀ ] [ dq̈ ]   [ ∂τ/∂x − ∂(ID − Jᵀλ)/∂x ]
//!   [ J   0  ] [ dλ ] = [ −∂(J q̈ + γ)/∂x          ]     (q̈ and λ held in the partials)
//! ```
//! ∂ID/∂x with λ as forces on the bodies is RNEA's derivative; what RNEA misses of ∂(Jᵀλ)/∂q
//! (forces that keep their direction while the bodies turn) and the rows' partials come from
//! `constraint::derivatives`. The solve factors M (CRBA, M = Lᵀ D L) and takes the Delassus
//! matrix from that factor: `dλ = (J M⁻¹ Jᵀ)⁻¹ (r₂ − J M⁻¹ r₁)`, `dq̈ = M⁻¹ (r₁ + Jᵀ dλ)`, column by column.
//! Impulses solve `M (q̇⁺ − q̇) − Jᵀ Λ = 0`, `J q̇⁺ + e J q̇ = 0`, differentiated the same way,
//! with `∂(M Δq̇)/∂q = ∂ID(q, 0, Δq̇)/∂q − ∂g/∂q`.
//! With damping (a redundant set, whose forces are the least-norm ones) the Delassus matrix is
//! singular: dλ is its pseudo-inverse's, the least-squares change of least norm. Along the
//! configurations where the dependent rows stay dependent (a planar loop moving in its plane), and
//! along q̇ and τ, dq̈ and Jᵀ dλ (what reaches the robot) are then exact; a change of q that makes
//! those rows independent (a planar loop leaving its plane) has no derivative, and gets the
//! least-squares one.
//! Baumgarte's terms are not differentiated: these are the derivatives of the exact equations.

use super::solve::PseudoInverse;
use super::{constrained_forward_dynamics, factor_with_rows, impulse_dynamics, product_scale};
use super::{solve_delassus, ConstrainedOptions, ConstraintData};
use crate::algo::derivatives::{rnea_derivatives, DerivativesInto};
use crate::algo::ltdl::solve_rows;
use crate::constraint::{
    add_body_forces, differentiate_rows, ConstraintSet, RowDerivatives, RowLevel, RowScratch,
};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::spatial::Force;
use crate::Data;
use nalgebra::{DMatrix, DVector};

/// The derivatives of [`constrained_forward_dynamics`] (or of [`impulse_dynamics`]) for one
/// [`ConstraintSet`] (m rows) on one model (nv coordinates), with their workspace. Made once by
/// [`ConstrainedDerivatives::new`].
#[derive(Debug, Clone)]
pub struct ConstrainedDerivatives {
    /// ∂q̈/∂q (nv × nv); for impulses ∂q̇⁺/∂q.
    pub dqdd_dq: DMatrix<f64>,
    /// ∂q̈/∂q̇ (nv × nv); for impulses ∂q̇⁺/∂q̇.
    pub dqdd_dv: DMatrix<f64>,
    /// ∂q̈/∂τ (nv × nv); not written for impulses.
    pub dqdd_dtau: DMatrix<f64>,
    /// ∂λ/∂q (m × nv); for impulses ∂Λ/∂q.
    pub dforces_dq: DMatrix<f64>,
    /// ∂λ/∂q̇ (m × nv); for impulses ∂Λ/∂q̇.
    pub dforces_dv: DMatrix<f64>,
    /// ∂λ/∂τ (m × nv); not written for impulses.
    pub dforces_dtau: DMatrix<f64>,
    /// The rows' derivatives and their scratch.
    rows: RowWork,
    /// λ as forces on the bodies, with the caller's.
    body_forces: Vec<Force>,
    /// q̇⁺ − q̇ or q̇⁺ + e q̇, and zeros (nv each).
    velocity: DVector<f64>,
    zeros: DVector<f64>,
    /// One column of dλ.
    column: Vec<f64>,
}

/// ∂(rows)/∂q and ∂(rows)/∂q̇ with q̈ (or q̇⁺) held, what RNEA misses of ∂(Jᵀλ)/∂q, and the
/// scratch they are made in.
#[derive(Debug, Clone)]
struct RowWork {
    by_q: DMatrix<f64>,
    by_v: DMatrix<f64>,
    forces_by_q: DMatrix<f64>,
    scratch: RowScratch,
}

impl RowWork {
    /// The rows' derivatives at `level` for the forces `forces`.
    fn differentiate(
        &mut self,
        model: &Model,
        data: &mut Data,
        set: &ConstraintSet,
        q: &[f64],
        level: RowLevel,
        forces: &[f64],
    ) {
        let out = RowDerivatives {
            by_q: &mut self.by_q,
            by_v: &mut self.by_v,
            forces_by_q: &mut self.forces_by_q,
        };
        differentiate_rows(model, data, set, q, level, forces, &mut self.scratch, out);
    }
}

impl ConstrainedDerivatives {
    /// The derivatives' workspace for `set` on `model`.
    pub fn new(model: &Model, set: &ConstraintSet) -> Self {
        let (m, nv) = (set.rows(), model.nv);
        ConstrainedDerivatives {
            dqdd_dq: DMatrix::zeros(nv, nv),
            dqdd_dv: DMatrix::zeros(nv, nv),
            dqdd_dtau: DMatrix::zeros(nv, nv),
            dforces_dq: DMatrix::zeros(m, nv),
            dforces_dv: DMatrix::zeros(m, nv),
            dforces_dtau: DMatrix::zeros(m, nv),
            rows: RowWork {
                by_q: DMatrix::zeros(m, nv),
                by_v: DMatrix::zeros(m, nv),
                forces_by_q: DMatrix::zeros(nv, nv),
                scratch: RowScratch::new(nv),
            },
            body_forces: vec![Force::ZERO; model.nbodies().saturating_sub(1)],
            velocity: DVector::zeros(nv),
            zeros: DVector::zeros(nv),
            column: vec![0.0; m],
        }
    }

    /// Whether this workspace was made for a set of `set`'s size on `model`.
    pub fn fits(&self, model: &Model, set: &ConstraintSet) -> bool {
        self.dforces_dq.nrows() == set.rows() && self.dforces_dq.ncols() == model.nv
    }
}

/// The derivatives of q̈ and λ of [`constrained_forward_dynamics`] (without Baumgarte's terms)
/// at (q, q̇, τ), into `derivatives`; q̈ and λ themselves into `constraints` as there.
#[allow(clippy::too_many_arguments)]
pub fn constrained_forward_dynamics_derivatives(
    model: &Model,
    data: &mut Data,
    constraints: &mut ConstraintData,
    derivatives: &mut ConstrainedDerivatives,
    set: &ConstraintSet,
    (q, v, tau): (&[f64], &[f64], &[f64]),
    f_ext: Option<&[Force]>,
    damping: f64,
) -> Result<()> {
    check_derivatives_fit(model, derivatives, set)?;
    let options = ConstrainedOptions {
        baumgarte: None,
        damping,
    };
    constrained_forward_dynamics(model, data, constraints, set, (q, v, tau), f_ext, &options)?;
    factor_with_rows(model, data, constraints, q)?;

    // ∂ID/∂q, ∂ID/∂q̇ at q̈ with λ (and f_ext) on the bodies: ID − Jᵀλ as RNEA has it
    let d = &mut *derivatives;
    match f_ext {
        Some(given) => d.body_forces.copy_from_slice(given),
        None => d.body_forces.fill(Force::ZERO),
    }
    let lambda = constraints.forces.as_slice();
    add_body_forces(model, &data.x_world, set, lambda, &mut d.body_forces);
    let qdd = constraints.qdd.as_slice();
    rnea_derivatives(
        model,
        data,
        q,
        v,
        qdd,
        Some(&d.body_forces),
        DerivativesInto::Data,
    )?;
    let level = RowLevel::Acceleration { v, qdd };
    d.rows.differentiate(model, data, set, q, level, lambda);

    // r₁ = ∂τ/∂x − ∂(ID − Jᵀλ)/∂x,  r₂ = −∂(J q̈ + γ)/∂x
    d.dqdd_dq.copy_from(&d.rows.forces_by_q);
    d.dqdd_dq -= &data.dtau_dq;
    d.dqdd_dv.copy_from(&data.dtau_dv);
    d.dqdd_dv.neg_mut();
    d.dqdd_dtau.fill_with_identity();
    d.dforces_dq.copy_from(&d.rows.by_q);
    d.dforces_dq.neg_mut();
    d.dforces_dv.copy_from(&d.rows.by_v);
    d.dforces_dv.neg_mut();
    d.dforces_dtau.fill(0.0);
    let pairs = [
        (&mut d.dqdd_dq, &mut d.dforces_dq),
        (&mut d.dqdd_dv, &mut d.dforces_dv),
        (&mut d.dqdd_dtau, &mut d.dforces_dtau),
    ];
    solve_saddle_points(
        model,
        data,
        (constraints, set),
        pairs,
        &mut d.column,
        damping,
    )
}

/// The derivatives of q̇⁺ and Λ of [`impulse_dynamics`] at (q, q̇), into `derivatives`
/// (`dqdd_dq`, `dqdd_dv`, `dforces_dq`, `dforces_dv`); q̇⁺ and Λ into `constraints` as there.
#[allow(clippy::too_many_arguments)]
pub fn impulse_dynamics_derivatives(
    model: &Model,
    data: &mut Data,
    constraints: &mut ConstraintData,
    derivatives: &mut ConstrainedDerivatives,
    set: &ConstraintSet,
    (q, v): (&[f64], &[f64]),
    restitution: f64,
    damping: f64,
) -> Result<()> {
    check_derivatives_fit(model, derivatives, set)?;
    impulse_dynamics(model, data, constraints, set, (q, v), restitution, damping)?;
    factor_with_rows(model, data, constraints, q)?;
    let d = &mut *derivatives;

    // ∂(M Δq̇ − JᵀΛ)/∂q = ∂ID(q, 0, Δq̇; Λ)/∂q − ∂g/∂q, Δq̇ = q̇⁺ − q̇
    d.body_forces.fill(Force::ZERO);
    add_body_forces(
        model,
        &data.x_world,
        set,
        constraints.forces.as_slice(),
        &mut d.body_forces,
    );
    for ((jump, after), before) in d.velocity.iter_mut().zip(constraints.qdd.iter()).zip(v) {
        *jump = after - before;
    }
    let (zeros, jump) = (d.zeros.as_slice(), d.velocity.as_slice());
    rnea_derivatives(
        model,
        data,
        q,
        zeros,
        jump,
        Some(&d.body_forces),
        DerivativesInto::Data,
    )?;
    d.dqdd_dq.copy_from(&data.dtau_dq);
    d.dqdd_dq.neg_mut();
    rnea_derivatives(model, data, q, zeros, zeros, None, DerivativesInto::Data)?;
    d.dqdd_dq += &data.dtau_dq;

    // the rows' velocity J (q̇⁺ + e q̇), and what RNEA misses of ∂(JᵀΛ)/∂q
    for ((w, after), before) in d.velocity.iter_mut().zip(constraints.qdd.iter()).zip(v) {
        *w = after + restitution * before;
    }
    let level = RowLevel::Velocity {
        w: d.velocity.as_slice(),
    };
    d.rows
        .differentiate(model, data, set, q, level, constraints.forces.as_slice());

    // r₁ = (∂(JᵀΛ)/∂q missed) − ∂(MΔq̇ − JᵀΛ)/∂q and M;  r₂ = −∂(J w)/∂q and −e J
    d.dqdd_dq += &d.rows.forces_by_q;
    d.dqdd_dv.copy_from(&data.mass_matrix);
    d.dforces_dq.copy_from(&d.rows.by_q);
    d.dforces_dq.neg_mut();
    d.dforces_dv.copy_from(&constraints.jacobian);
    d.dforces_dv *= -restitution;
    let pairs = [
        (&mut d.dqdd_dq, &mut d.dforces_dq),
        (&mut d.dqdd_dv, &mut d.dforces_dv),
    ];
    solve_saddle_points(
        model,
        data,
        (constraints, set),
        pairs,
        &mut d.column,
        damping,
    )
}

/// How the Delassus systems of the derivatives are solved: by Cholesky (independent rows), or by
/// its pseudo-inverse (with damping: rows that may depend on each other).
enum Solver {
    Cholesky,
    PseudoInverse(PseudoInverse),
}

impl Solver {
    fn new(constraints: &ConstraintData, damping: f64) -> Self {
        if damping > 0.0 {
            Solver::PseudoInverse(PseudoInverse::new(&constraints.delassus))
        } else {
            Solver::Cholesky
        }
    }
}

/// [`solve_saddle_point`] for each pair of right-hand sides, with one [`Solver`].
fn solve_saddle_points<'p>(
    model: &Model,
    data: &Data,
    (constraints, set): (&mut ConstraintData, &ConstraintSet),
    pairs: impl IntoIterator<Item = (&'p mut DMatrix<f64>, &'p mut DMatrix<f64>)>,
    column: &mut [f64],
    damping: f64,
) -> Result<()> {
    let solver = Solver::new(constraints, damping);
    for (x, y) in pairs {
        solve_saddle_point(model, data, constraints, set, (x, y), column, &solver)?;
    }
    Ok(())
}

/// Solves `[M −Jᵀ; J 0] [X; Y] = [R₁; R₂]` in place (R₁ in `x`, nv × k; R₂ in `y`, m × k) with
/// forward dynamics' factor of M, J, J M⁻¹ and Delassus matrix:
/// `X₀ = M⁻¹ R₁`, `Λ⁻¹ Y = R₂ − J X₀`, `X = X₀ + (J M⁻¹)ᵀ Y`.
fn solve_saddle_point(
    model: &Model,
    data: &Data,
    constraints: &mut ConstraintData,
    set: &ConstraintSet,
    (x, y): (&mut DMatrix<f64>, &mut DMatrix<f64>),
    column: &mut [f64],
    solver: &Solver,
) -> Result<()> {
    let m = set.rows();
    for c in 0..x.ncols() {
        // X₀ = M⁻¹ R₁, one column (contiguous, a right-hand side of width 1) at a time
        solve_rows(model, data, x.column_mut(c).as_mut_slice());
        let x0 = x.column(c);
        for r in 0..m {
            let row = constraints.jacobian.row(r);
            let product: f64 = row.iter().zip(x0.iter()).map(|(j, x)| j * x).sum();
            constraints.rhs[r] = y[(r, c)] - product;
        }
        match solver {
            Solver::Cholesky => {
                let scale = 1.0
                    + product_scale(&constraints.jacobian, x0.as_slice(), &mut constraints.step)
                    + super::solve::largest(&constraints.rhs[..m]);
                solve_delassus(model, set, constraints, 0.0, scale, column)?;
            }
            Solver::PseudoInverse(inverse) => inverse.solve(&constraints.rhs[..m], column),
        }
        y.column_mut(c).copy_from_slice(column);
    }
    x.gemm_tr(1.0, &constraints.jacobian_inverse_inertia, y, 1.0);
    Ok(())
}

/// Refuses a derivatives workspace made for another set or model.
fn check_derivatives_fit(
    model: &Model,
    derivatives: &ConstrainedDerivatives,
    set: &ConstraintSet,
) -> Result<()> {
    if derivatives.fits(model, set) {
        return Ok(());
    }
    Err(Error::Shape {
        argument: "derivatives".into(),
        expected: format!(
            "a ConstrainedDerivatives of {} rows and {} columns",
            set.rows(),
            model.nv
        ),
        received: format!(
            "{} rows and {} columns",
            derivatives.dforces_dq.nrows(),
            derivatives.dforces_dq.ncols()
        ),
    })
}
