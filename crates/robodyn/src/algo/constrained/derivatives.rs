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
//! `constraint::derivatives`. M is factored (CRBA, M = Lᵀ D L), q̈ and λ themselves are solved
//! with that factor, and so is the saddle point, with the Delassus matrix inverted once: `dλ = (J M⁻¹ Jᵀ)⁻¹ (r₂ − J M⁻¹ r₁)`,
//! `dq̈ = M⁻¹ (r₁ + Jᵀ dλ)`, all columns of r₁ and r₂ at once.
//! Impulses solve `M (q̇⁺ − q̇) − Jᵀ Λ = 0`, `J q̇⁺ + e J q̇ = 0`, differentiated the same way,
//! with `∂(M Δq̇)/∂q = ∂ID(q, 0, Δq̇)/∂q − ∂g/∂q`.
//! With damping (a redundant set, whose forces are the least-norm ones) the Delassus matrix is
//! singular: dλ is its pseudo-inverse's, the least-squares change of least norm. Along the
//! configurations where the dependent rows stay dependent (a planar loop moving in its plane), and
//! along q̇ and τ, dq̈ and Jᵀ dλ (what reaches the robot) are then exact; a change of q that makes
//! those rows independent (a planar loop leaving its plane) has no derivative, and gets the
//! least-squares one.
//! Baumgarte's terms are not differentiated: these are the derivatives of the exact equations.

use super::forward::{solve_accelerated_forces, solve_impulses};
use super::solve::{cholesky_solve_rows, multiply_add, pseudo_inverse};
use super::{check_fits, constraint_rows, factor_delassus, factor_with_rows};
#[cfg(doc)]
use super::{constrained_forward_dynamics, impulse_dynamics};
use super::{ConstrainedOptions, ConstraintData};
use crate::algo::derivatives::{rnea_derivatives, DerivativesInto};
use crate::algo::ltdl::solve_rows;
use crate::algo::rnea::rnea;
use crate::constraint::{
    add_body_forces, differentiate_rows, ConstraintSet, RowDerivatives, RowLevel, RowScratch,
};
use crate::error::{check_vector, Error, Result};
use crate::model::Model;
use crate::spatial::Force;
use crate::Data;
use nalgebra::{DMatrix, DVector, DVectorViewMut};

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
    /// The saddle-point solves' scratch.
    saddle: SaddleScratch,
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
            saddle: SaddleScratch {
                inverse: DMatrix::zeros(m, m),
                transposed: DMatrix::zeros(nv, nv),
                forces: DMatrix::zeros(m, nv),
                response: DMatrix::zeros(nv, m),
            },
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
    factored_forward_dynamics(model, data, constraints, set, (q, v, tau), f_ext, &options)?;

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
    difference_into(&mut d.dqdd_dq, &d.rows.forces_by_q, &data.dtau_dq);
    negated_into(&mut d.dqdd_dv, &data.dtau_dv);
    negated_into(&mut d.dforces_dq, &d.rows.by_q);
    negated_into(&mut d.dforces_dv, &d.rows.by_v);
    let pairs = [
        (&mut d.dqdd_dq, &mut d.dforces_dq),
        (&mut d.dqdd_dv, &mut d.dforces_dv),
    ];
    let torques = Some((&mut d.dqdd_dtau, &mut d.dforces_dtau));
    solve_saddle_points(
        model,
        data,
        (constraints, set),
        (pairs, torques),
        &mut d.saddle,
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
    factored_impulse_dynamics(model, data, constraints, set, (q, v), restitution, damping)?;
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
    negated_into(&mut d.dqdd_dq, &data.dtau_dq);
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
    negated_into(&mut d.dforces_dq, &d.rows.by_q);
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
        (pairs, None),
        &mut d.saddle,
        damping,
    )
}

/// [`constrained_forward_dynamics`] from M's factor instead of ABA's terms: the derivatives need
/// M, its factor, J M⁻¹ and Λ⁻¹ (left in `data` and `constraints`), and with them q̈ and λ are a
/// few solves away. `a_f = M⁻¹ (τ − h)` (h: RNEA at q̈ = 0, with f_ext), λ as there, then
/// `q̈ = a_f + (J M⁻¹)ᵀ λ`; the free acceleration stays in `data.qdd`.
fn factored_forward_dynamics(
    model: &Model,
    data: &mut Data,
    constraints: &mut ConstraintData,
    set: &ConstraintSet,
    (q, v, tau): (&[f64], &[f64], &[f64]),
    f_ext: Option<&[Force]>,
    options: &ConstrainedOptions,
) -> Result<()> {
    check_fits(model, constraints, set)?;
    options.check()?;
    check_vector("tau", tau, model.nv)?;
    // J, γ, φ; M, its factor, Λ⁻¹ and J M⁻¹
    constraint_rows(model, data, constraints, set, q, v)?;
    factor_with_rows(model, data, constraints, q)?;

    // a_f = M⁻¹ (τ − h);  J a_f + γ
    let mut zeros = std::mem::take(&mut constraints.joint_forces);
    zeros.fill(0.0);
    let bias = rnea(model, data, q, v, zeros.as_slice(), f_ext).map(|_| ());
    constraints.joint_forces = zeros;
    bias?;
    let mut free = std::mem::take(&mut data.qdd);
    for ((a, t), h) in free.iter_mut().zip(tau).zip(data.tau.iter()) {
        *a = t - h;
    }
    solve_rows(model, data, free.as_mut_slice());
    data.qdd = free;
    let m = set.rows();
    let mut rows = DVectorViewMut::from_slice(&mut constraints.rhs[..m], m);
    rows.copy_from(&constraints.drift);
    rows.gemv(1.0, &constraints.jacobian, &data.qdd, 1.0);

    // Λ⁻¹ λ = −(J a_f + γ + K_d J q̇ + K_p φ);  q̈ = a_f + (J M⁻¹)ᵀ λ
    solve_accelerated_forces(model, set, constraints, (v, data.qdd.as_slice()), options)?;
    constraints.qdd.copy_from(&data.qdd);
    let response = &constraints.jacobian_inverse_inertia;
    constraints
        .qdd
        .gemv_tr(1.0, response, &constraints.forces, 1.0);
    Ok(())
}

/// [`impulse_dynamics`] from M's factor, as [`factored_forward_dynamics`]:
/// `q̇⁺ = q̇ + (J M⁻¹)ᵀ Λ`.
fn factored_impulse_dynamics(
    model: &Model,
    data: &mut Data,
    constraints: &mut ConstraintData,
    set: &ConstraintSet,
    (q, v): (&[f64], &[f64]),
    restitution: f64,
    damping: f64,
) -> Result<()> {
    check_fits(model, constraints, set)?;
    constraint_rows(model, data, constraints, set, q, v)?;
    factor_with_rows(model, data, constraints, q)?;
    solve_impulses(model, set, constraints, v, restitution, damping)?;
    constraints.qdd.copy_from_slice(v);
    let response = &constraints.jacobian_inverse_inertia;
    constraints
        .qdd
        .gemv_tr(1.0, response, &constraints.forces, 1.0);
    Ok(())
}

/// `Λ = (J M⁻¹ Jᵀ)⁻¹` into `inverse` (m × m), for the derivatives' many right-hand sides: by
/// Cholesky (independent rows; a dependent one is an error naming it), or with damping (rows
/// that may depend on each other) the pseudo-inverse.
fn invert_delassus(
    model: &Model,
    set: &ConstraintSet,
    constraints: &mut ConstraintData,
    damping: f64,
    inverse: &mut DMatrix<f64>,
) -> Result<()> {
    if damping > 0.0 {
        pseudo_inverse(&constraints.delassus, inverse);
        return Ok(());
    }
    factor_delassus(model, set, constraints)?;
    // Λ is symmetric: solving for the identity row by row gives it as well as column by column
    inverse.fill_with_identity();
    cholesky_solve_rows(
        set.rows(),
        constraints.factor.as_slice(),
        inverse.as_mut_slice(),
    );
    Ok(())
}

/// The scratch of [`solve_saddle_points`].
#[derive(Debug, Clone)]
struct SaddleScratch {
    /// Λ (m × m).
    inverse: DMatrix<f64>,
    /// A right-hand side R₁ transposed (k × nv, k = nv), for the solve with M.
    transposed: DMatrix<f64>,
    /// Λ (R₂ − J X₀) (m × k).
    forces: DMatrix<f64>,
    /// (J M⁻¹)ᵀ = M⁻¹ Jᵀ (nv × m): a product with it runs down contiguous columns.
    response: DMatrix<f64>,
}

/// A pair of [`solve_saddle_points`]: X (nv × k) and Y (m × k).
type SaddlePair<'p> = (&'p mut DMatrix<f64>, &'p mut DMatrix<f64>);

/// Solves `[M −Jᵀ; J 0] [X; Y] = [R₁; R₂]` in place for each pair (R₁ in the first, nv × k; R₂ in
/// the second, m × k) with forward dynamics' factor of M, J, J M⁻¹ and the Delassus matrix,
/// inverted once: `X₀ = M⁻¹ R₁`, `Y = Λ (R₂ − J X₀)`, `X = X₀ + (J M⁻¹)ᵀ Y`. With `torques`, also
/// the pair of R₁ = 1, R₂ = 0 (whatever the matrices held): X₀ = M⁻¹ and J X₀ = J M⁻¹, known.
fn solve_saddle_points<'p>(
    model: &Model,
    data: &Data,
    (constraints, set): (&mut ConstraintData, &ConstraintSet),
    (pairs, torques): (
        impl IntoIterator<Item = SaddlePair<'p>>,
        Option<SaddlePair<'p>>,
    ),
    scratch: &mut SaddleScratch,
    damping: f64,
) -> Result<()> {
    let SaddleScratch {
        inverse,
        transposed,
        forces,
        response,
    } = scratch;
    invert_delassus(model, set, constraints, damping, inverse)?;
    constraints.jacobian_inverse_inertia.transpose_to(response);
    for (x, y) in pairs {
        // X₀ = M⁻¹ R₁: R₁ᵀ (column-major) holds R₁ row by row, all its columns solved at once
        x.transpose_to(transposed);
        solve_rows(model, data, transposed.as_mut_slice());
        transposed.transpose_to(x);
        // Y = Λ (R₂ − J X₀), X = X₀ + (J M⁻¹)ᵀ Y
        multiply_add(y, -1.0, &constraints.jacobian, x, 1.0);
        multiply_add(forces, 1.0, inverse, y, 0.0);
        y.as_mut_slice().copy_from_slice(forces.as_slice());
        multiply_add(x, 1.0, response, y, 1.0);
    }
    if let Some((x, y)) = torques {
        // X₀ = M⁻¹: the identity solved row by row (M⁻¹ is symmetric, so no transposes)
        x.fill_with_identity();
        solve_rows(model, data, x.as_mut_slice());
        // Y = −Λ J M⁻¹, X = M⁻¹ + (J M⁻¹)ᵀ Y
        multiply_add(y, -1.0, inverse, &constraints.jacobian_inverse_inertia, 0.0);
        multiply_add(x, 1.0, response, y, 1.0);
    }
    Ok(())
}

/// `out = a − b` (matrices of one shape), element by element over their storage.
fn difference_into(out: &mut DMatrix<f64>, a: &DMatrix<f64>, b: &DMatrix<f64>) {
    for ((o, a), b) in out
        .as_mut_slice()
        .iter_mut()
        .zip(a.as_slice())
        .zip(b.as_slice())
    {
        *o = a - b;
    }
}

/// `out = −a` (matrices of one shape).
fn negated_into(out: &mut DMatrix<f64>, a: &DMatrix<f64>) {
    for (o, a) in out.as_mut_slice().iter_mut().zip(a.as_slice()) {
        *o = -a;
    }
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
