//! The constraint forces of MuJoCo's soft model: the accelerations that minimise
//! ```text
//!   ½ (q̈ − q̈₀)ᵀ M (q̈ − q̈₀) + s(J q̈ − a_ref)
//! ```
//! (q̈₀ the unconstrained accelerations, s the rows' cost of `cost.rs`), solved by Newton's
//! method to convergence, and the forces `f = −∂s/∂(J q̈ − a_ref)` there.
//!
//! Reference: MuJoCo's documentation, "Computation", §Constraint model (the primal problem) and
//! §Solver (Newton). The cost is convex and once differentiable. Each Newton iteration:
//! ```text
//!   g = M (q̈ − q̈₀) − Jᵀ f                 the gradient
//!   H = M + Jᵀ H_s J                       the Hessian (H_s = ∂²s/∂x², block diagonal)
//!   δ = −H⁻¹ g                             Newton's step
//!   α: φ'(α) = 0,  φ(α) the cost at q̈ + α δ (convex: its slope is monotone)
//! ```
//! from the last solution when it costs less than q̈₀ (MuJoCo's warm start), until a step is
//! below tolerance. Where no row has changed zone since the last factorisation, H differs from
//! that factor's only by the cones' curvature: its step −H⁻¹ g, below tolerance, ends the solve
//! (and is taken) without another Hessian, the last of Newton's iterations; small enough that
//! its error will be, it is taken in place of a new factorisation. A warm start's first step is
//! the last solve's factor's (the Hessian at the last optimum). J is sparse (a
//! friction row has one column, a foot's contact the columns of its leg and base): its rows are
//! used through their nonzero columns only.

use super::cost::{forces_at, Along, Curvature};
use super::pattern::Pattern;
use super::rows::Rows;
use crate::error::{Error, Result};
use nalgebra::{Cholesky, DMatrix, DVector};

/// Newton's iterations at most; the active set settles in a few, the cone in a few more.
const MAX_ITERATIONS: usize = 100;
/// A step this small against the accelerations ends the iterations: Newton's method converges
/// quadratically near the optimum, so the next step would be below round-off (smaller
/// tolerances only chase round-off: steps of 1e-14 relative, measured on a Go2 falling onto its
/// floor; warm and cold starts then end within 2e-13 of each other).
const STEP_TOLERANCE: f64 = 1e-10;
/// Near the optimum H moves with q̈ only through the cones' curvature, by about the size of the
/// last step: a step r by a factor taken with a step s leaves an error of about |r| |s|
/// (relative to the accelerations). Where that is below this the step is taken without a new
/// factorisation, once. Measured on the Go2 standing, 1000 Euler steps from `home`: 6.75
/// factorisations a solve without it or the warm start's kept factor, 6.19 with it, 5.81 with
/// the kept factor, 5.24 with both; the states within 1.3e-14 of each other at the end.
const CHORD_REACH: f64 = STEP_TOLERANCE;
/// The line search's iterations at most (Newton's method on the slope, kept in a bracket).
const LINE_ITERATIONS: usize = 50;
/// The line search ends where the slope is this small against its value at the start: the
/// outer iterations converge from any such point, and where the active set no longer changes
/// the slope is linear and Newton's full step already exact.
const LINE_TOLERANCE: f64 = 1e-10;
/// A slope is known to this much of the sum of its terms' magnitudes (round-off): the line
/// search ends where it is no larger (near the optimum the slope at the start may be no more).
const ROUND_OFF: f64 = 64.0 * f64::EPSILON;

/// The solution: accelerations, the rows' forces.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Solution {
    /// q̈ (nv).
    pub acceleration: DVector<f64>,
    /// One force per row.
    pub forces: Vec<f64>,
    /// Newton's iterations taken.
    pub iterations: usize,
}

/// The soft model's solver and its scratch space, kept between solves: sized once, nothing is
/// allocated after.
#[derive(Debug, Clone, Default)]
pub struct Solver {
    /// The last solution's q̈, where the next solve may start.
    warm_start: DVector<f64>,
    /// Whether `warm_start` holds a solution (false: the next solve starts from q̈₀).
    warm: bool,
    /// Whether `hessian` holds a factor (of the last solve's last Hessian, between solves).
    factored: bool,
    /// The last factor's step, taken, against the accelerations.
    factored_step: f64,
    pattern: Pattern,
    curvature: Curvature,
    /// x = J q̈ − a_ref and the rows' forces there.
    x: Vec<f64>,
    forces: Vec<f64>,
    /// J q̈ and J δ.
    j_acceleration: Vec<f64>,
    j_step: Vec<f64>,
    /// The Hessian, then its Cholesky factor L (lower triangle), kept for the next iteration.
    hessian: DMatrix<f64>,
    /// The zones of the rows (`Curvature::zones`) where the factored Hessian was taken.
    factored_zones: Vec<(usize, bool)>,
    /// A block's B J_g on its columns ([`Pattern::add_block`]).
    block_product: Vec<[f64; 6]>,
    /// q̈ − q̈₀, then M (q̈ − q̈₀).
    difference: DVector<f64>,
    m_difference: DVector<f64>,
    /// g; δ, M δ.
    gradient: DVector<f64>,
    step: DVector<f64>,
    m_step: DVector<f64>,
}

impl Solver {
    /// Minimises the problem of the module's header: `mass` M (nv × nv), `free` the
    /// unconstrained accelerations q̈₀, `reference` each row's a_ref as the solver sees it; the
    /// solution into `out`.
    pub fn solve(
        &mut self,
        rows: &Rows,
        mass: &DMatrix<f64>,
        free: &DVector<f64>,
        reference: &[f64],
        out: &mut Solution,
    ) -> Result<()> {
        let (nv, count) = (mass.nrows(), rows.len());
        self.size(nv, count);
        self.pattern.find(rows);
        let warmed = self.start(rows, mass, free, reference, &mut out.acceleration);
        out.iterations = 0;
        self.residual(reference, &out.acceleration);
        self.curvature.clear();
        forces_at(rows, &self.x, &mut self.forces, &mut self.curvature);
        // from a warm start, first the last solve's step: its factor is the Hessian at the
        // last optimum, Newton's own where no row has changed zone since
        if warmed && self.factored {
            self.gradient(mass, free, &out.acceleration);
            self.solve_factored();
            self.descend(rows, mass, reference, &mut out.acceleration);
        }
        let mut chord_taken = false;
        while out.iterations < MAX_ITERATIONS {
            // g (f and H_s: the line search's last)
            self.gradient(mass, free, &out.acceleration);
            // the last factor's step, where no row has changed zone since: below tolerance it
            // ends the solve; taken once where it will (see CHORD_REACH)
            if out.iterations > 0
                && self
                    .curvature
                    .zones()
                    .eq(self.factored_zones.iter().copied())
            {
                self.solve_factored();
                if self.converged(1.0, &out.acceleration) {
                    out.acceleration -= &self.step;
                    break;
                }
                let reach = self.relative_step(1.0, &out.acceleration) * self.factored_step;
                if !chord_taken && reach <= CHORD_REACH {
                    chord_taken = true;
                    self.descend(rows, mass, reference, &mut out.acceleration);
                    continue;
                }
            }
            out.iterations += 1;
            chord_taken = false;
            // δ = −H⁻¹ g,  H = M + Jᵀ H_s J
            self.assemble_hessian(mass);
            self.factor()?;
            self.solve_factored();
            // q̈ += α δ
            let length = self.descend(rows, mass, reference, &mut out.acceleration);
            self.factored_step = self.relative_step(length, &out.acceleration);
            if self.factored_step <= STEP_TOLERANCE {
                break;
            }
        }
        self.residual(reference, &out.acceleration);
        out.forces.resize(count, 0.0);
        forces_at(rows, &self.x, &mut out.forces, &mut ());
        if self.warm_start.len() == nv {
            self.warm_start.copy_from(&out.acceleration);
        } else {
            self.warm_start = out.acceleration.clone();
        }
        self.warm = true;
        Ok(())
    }

    /// Sets `acceleration` to where the solve starts: the last solution when it costs less
    /// than q̈₀ (MuJoCo's warm start; returns true), else q̈₀.
    fn start(
        &mut self,
        rows: &Rows,
        mass: &DMatrix<f64>,
        free: &DVector<f64>,
        reference: &[f64],
        acceleration: &mut DVector<f64>,
    ) -> bool {
        let nv = mass.nrows();
        if acceleration.len() == nv {
            acceleration.copy_from(free);
        } else {
            *acceleration = free.clone();
        }
        let warm_start = std::mem::take(&mut self.warm_start);
        let warmed = self.warm
            && warm_start.len() == nv
            && self.cost(rows, mass, free, reference, &warm_start)
                < self.cost(rows, mass, free, reference, free);
        if warmed {
            acceleration.copy_from(&warm_start);
        }
        self.warm_start = warm_start;
        warmed
    }

    /// The next solve starts from q̈₀: its result no longer depends on the solves before.
    pub fn forget_warm_start(&mut self) {
        self.warm = false;
        self.factored = false;
    }

    fn size(&mut self, nv: usize, count: usize) {
        for v in [
            &mut self.x,
            &mut self.forces,
            &mut self.j_acceleration,
            &mut self.j_step,
        ] {
            v.resize(count, 0.0);
        }
        if self.hessian.nrows() != nv {
            self.factored = false;
            self.hessian = DMatrix::zeros(nv, nv);
            for v in [
                &mut self.difference,
                &mut self.m_difference,
                &mut self.gradient,
                &mut self.step,
                &mut self.m_step,
            ] {
                *v = DVector::zeros(nv);
            }
        }
    }

    /// x = J q̈ − a_ref (J q̈ kept).
    fn residual(&mut self, reference: &[f64], acceleration: &DVector<f64>) {
        self.pattern
            .multiply(acceleration.as_slice(), &mut self.j_acceleration);
        for ((x, ja), r) in self.x.iter_mut().zip(&self.j_acceleration).zip(reference) {
            *x = ja - r;
        }
    }

    /// ½ (q̈ − q̈₀)ᵀ M (q̈ − q̈₀) + s(J q̈ − a_ref).
    fn cost(
        &mut self,
        rows: &Rows,
        mass: &DMatrix<f64>,
        free: &DVector<f64>,
        reference: &[f64],
        acceleration: &DVector<f64>,
    ) -> f64 {
        self.residual(reference, acceleration);
        self.difference.copy_from(acceleration);
        self.difference -= free;
        self.m_difference.gemv(1.0, mass, &self.difference, 0.0);
        0.5 * self.difference.dot(&self.m_difference)
            + forces_at(rows, &self.x, &mut self.forces, &mut ())
    }

    /// H = M + Jᵀ H_s J from the curvature of the last [`forces_at`], row by row on J's
    /// nonzero columns: its lower triangle, all the Cholesky factorisation reads.
    fn assemble_hessian(&mut self, mass: &DMatrix<f64>) {
        self.hessian.copy_from(mass);
        for &(i, d) in &self.curvature.diagonal {
            self.pattern.add_row((i, d), &mut self.hessian);
        }
        for &(first, ref block) in &self.curvature.blocks {
            self.pattern
                .add_block((first, block), &mut self.block_product, &mut self.hessian);
        }
        self.factored_zones.clear();
        self.factored_zones.extend(self.curvature.zones());
    }

    /// H = L Lᵀ in place (Cholesky).
    fn factor(&mut self) -> Result<()> {
        self.factored = false;
        let factor = Cholesky::new(std::mem::take(&mut self.hessian)).ok_or_else(|| {
            Error::InvalidValue {
                argument: "model".into(),
                message: "the constraint problem's Hessian is not positive definite".into(),
            }
        })?;
        self.hessian = factor.unpack_dirty();
        self.factored = true;
        Ok(())
    }

    /// `step` ← H⁻¹ g by the kept factor: L⁻ᵀ L⁻¹ g.
    fn solve_factored(&mut self) {
        self.step.copy_from(&self.gradient);
        self.hessian
            .solve_lower_triangular_unchecked_mut(&mut self.step);
        self.hessian
            .tr_solve_lower_triangular_unchecked_mut(&mut self.step);
    }

    /// g = M (q̈ − q̈₀) − Jᵀ f, with f at q̈ (the last [`forces_at`]'s); M (q̈ − q̈₀) kept.
    fn gradient(&mut self, mass: &DMatrix<f64>, free: &DVector<f64>, acceleration: &DVector<f64>) {
        self.difference.copy_from(acceleration);
        self.difference -= free;
        self.m_difference.gemv(1.0, mass, &self.difference, 0.0);
        self.gradient.copy_from(&self.m_difference);
        self.pattern
            .subtract_transposed(&self.forces, self.gradient.as_mut_slice());
    }

    /// q̈ += α δ along δ = −`step` (`step` a positive definite matrix's inverse times g, a
    /// direction of descent) by the line search; returns α.
    fn descend(
        &mut self,
        rows: &Rows,
        mass: &DMatrix<f64>,
        reference: &[f64],
        acceleration: &mut DVector<f64>,
    ) -> f64 {
        self.step.neg_mut();
        let length = self.line_search(rows, mass, reference);
        acceleration.axpy(length, &self.step, 1.0);
        length
    }

    /// A step of `length` × `step` against the accelerations.
    fn relative_step(&self, length: f64, acceleration: &DVector<f64>) -> f64 {
        length * self.step.amax() / (1.0 + acceleration.amax())
    }

    /// Whether a step of `length` × `step` is below tolerance against the accelerations.
    fn converged(&self, length: f64, acceleration: &DVector<f64>) -> bool {
        self.relative_step(length, acceleration) <= STEP_TOLERANCE
    }

    /// The step length α minimising the cost along δ from q̈: where its slope
    /// `φ'(α) = δᵀ M (q̈ + α δ − q̈₀) − (J δ)ᵀ f(α)` (monotone) is zero, by Newton's method on
    /// it (`φ''(α) = δᵀ M δ + (J δ)ᵀ H_s(α) (J δ)`) kept inside the bracket found so far.
    /// Expects `m_difference` = M (q̈ − q̈₀), `j_acceleration` J q̈ and `forces` f at the start;
    /// leaves J q̈, f and H_s at the step's end.
    fn line_search(&mut self, rows: &Rows, mass: &DMatrix<f64>, reference: &[f64]) -> f64 {
        self.m_step.gemv(1.0, mass, &self.step, 0.0);
        self.pattern
            .multiply(self.step.as_slice(), &mut self.j_step);
        let base = self.step.dot(&self.m_difference);
        let step_mass = self.step.dot(&self.m_step);
        // φ'(0) from the forces at the start, still in `forces`
        let start_slope = base - dot(&self.forces, &self.j_step);
        // δ no descent (round-off at the optimum): f, H_s and J q̈ stay the start's
        if start_slope >= 0.0 {
            return 0.0;
        }
        let alpha = self.slope_root(rows, reference, (base, step_mass), start_slope);
        // f and H_s at the step's end, for the next iteration; J q̈ += α J δ
        self.move_residual(reference, alpha);
        self.curvature.clear();
        forces_at(rows, &self.x, &mut self.forces, &mut self.curvature);
        for (ja, js) in self.j_acceleration.iter_mut().zip(&self.j_step) {
            *ja += alpha * js;
        }
        alpha
    }

    /// The root of φ'(α) = `base` + α `step_mass` − (J δ)ᵀ f(α), Newton's full step first,
    /// from φ'(0) = `start_slope` < 0 (see [`Self::line_search`]).
    fn slope_root(
        &mut self,
        rows: &Rows,
        reference: &[f64],
        (base, step_mass): (f64, f64),
        start_slope: f64,
    ) -> f64 {
        // φ'(α) and φ''(α), with H_s taken along J δ only
        let mut derivatives = |alpha: f64| {
            self.move_residual(reference, alpha);
            let mut along = Along::new(&self.j_step);
            forces_at(rows, &self.x, &mut self.forces, &mut along);
            let work = dot(&self.forces, &self.j_step);
            let terms =
                base.abs() + (alpha * step_mass).abs() + abs_dot(&self.forces, &self.j_step);
            (
                base + alpha * step_mass - work,
                step_mass + along.value,
                ROUND_OFF * terms,
            )
        };
        // the bracket's ends (α, φ'(α)): φ' < 0 at the low one, ≥ 0 at the high one; its
        // widths one and two evaluations before
        let (mut low, mut high) = ((0.0, start_slope), (f64::INFINITY, 0.0));
        let mut widths = [f64::INFINITY; 2];
        let mut alpha = 1.0;
        for evaluations in 1.. {
            let (slope, curvature, noise) = derivatives(alpha);
            let flat = slope.abs() <= (LINE_TOLERANCE * start_slope.abs()).max(noise);
            if flat || evaluations == LINE_ITERATIONS {
                break;
            }
            if slope < 0.0 {
                low = (alpha, slope);
            } else {
                high = (alpha, slope);
            }
            let width = high.0 - low.0;
            if width <= f64::EPSILON * high.0 {
                break;
            }
            // Newton's step, else the secant through the bracket's ends, inside the bracket;
            // its middle where two evaluations have not halved it (across a kink Newton's steps
            // bounce between its sides, a secant may keep one end)
            let stalled = 2.0 * width > widths[1];
            widths = [width, widths[0]];
            let newton = alpha - slope / curvature;
            let secant = low.0 + width * low.1 / (low.1 - high.1);
            let inside = |a: f64| a > low.0 && a < high.0 && !stalled;
            alpha = if inside(newton) {
                newton
            } else if !high.0.is_finite() {
                2.0 * alpha
            } else if inside(secant) {
                secant
            } else {
                0.5 * (low.0 + high.0)
            };
        }
        alpha
    }

    /// x = J q̈ + α J δ − a_ref from the kept J q̈ and J δ.
    fn move_residual(&mut self, reference: &[f64], alpha: f64) {
        let moved = self.j_acceleration.iter().zip(&self.j_step);
        for ((x, (ja, js)), r) in self.x.iter_mut().zip(moved).zip(reference) {
            *x = ja + alpha * js - r;
        }
    }
}

/// Σ |a_i b_i| of two slices.
fn abs_dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| (a * b).abs()).sum()
}

/// aᵀ b of two slices.
pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::soft::cost::tests::mixed_rows;
    use crate::soft::rows::{Group, RowKind};

    /// Closed forms by hand: exact up to round-off.
    const EXACT: f64 = 1e-12;

    /// One cold solve.
    fn solve(rows: &Rows, mass: &DMatrix<f64>, free: &DVector<f64>, reference: &[f64]) -> Solution {
        let mut solution = Solution::default();
        Solver::default()
            .solve(rows, mass, free, reference, &mut solution)
            .expect("solvable");
        solution
    }

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
        );
        let expected = (mass * free + 6.0 * reference) / (mass + 6.0);
        assert!((solution.acceleration[0] - expected).abs() < EXACT);
        assert!((solution.forces[0] + 6.0 * (expected - reference)).abs() < EXACT);
    }

    #[test]
    fn a_limit_row_leaves_motion_away_from_it_alone() {
        let rows = one_row(RowKind::LimitJoint, 0.1, 0.0);
        let one = DMatrix::from_element(1, 1, 1.0);
        let solution = solve(&rows, &one, &DVector::from_element(1, 3.0), &[1.0]);
        assert_eq!((solution.acceleration[0], solution.forces[0]), (3.0, 0.0));
    }

    #[test]
    fn dry_friction_saturates_at_its_largest_force() {
        // m = 1 pushed at q̈₀ = 5 against friction 2 (R = 1e-3): sliding, f = −2, q̈ = 3
        let rows = one_row(RowKind::FrictionDof, 1e-3, 2.0);
        let one = DMatrix::from_element(1, 1, 1.0);
        let solution = solve(&rows, &one, &DVector::from_element(1, 5.0), &[0.0]);
        assert!((solution.forces[0] + 2.0).abs() < EXACT);
        assert!((solution.acceleration[0] - 3.0).abs() < EXACT);
    }

    fn mixed_mass() -> DMatrix<f64> {
        let a = DMatrix::from_fn(4, 4, |i, j| ((i * 4 + j) as f64 * 0.7).sin());
        &a * a.transpose() + DMatrix::identity(4, 4)
    }

    #[test]
    fn the_sparse_hessians_lower_triangle_is_m_plus_jt_hs_js() {
        let rows = mixed_rows();
        let mass = mixed_mass();
        let mut solver = Solver::default();
        solver.size(4, rows.len());
        solver.pattern.find(&rows);
        let x = [0.3, 1e-3, -0.2, -0.3, 0.4, -0.1];
        let mut forces = [0.0; 6];
        forces_at(&rows, &x, &mut forces, &mut solver.curvature);
        solver.assemble_hessian(&mass);
        let hs = solver.curvature.dense(6);
        let j = DMatrix::from_row_slice(6, 4, &rows.jacobian);
        let expected = &mass + j.transpose() * hs * &j;
        let difference = solver.hessian.lower_triangle() - expected.lower_triangle();
        assert!(difference.amax() < EXACT, "{}", solver.hessian);
    }

    #[test]
    fn a_quadratic_cost_ends_after_one_newton_step_on_its_factor() {
        // equality rows only: the cost is quadratic, Newton's first step lands on the optimum,
        // and the kept factor (same zones) shows the next step below tolerance
        let mut rows = one_row(RowKind::Equality, 0.25, 0.0);
        rows.reference = vec![2.0];
        let solution = solve(
            &rows,
            &DMatrix::from_element(1, 1, 1.0),
            &DVector::from_element(1, -1.0),
            &rows.reference,
        );
        // q̈ = (m q̈₀ + D a_ref)/(m + D) with D = 4
        assert!((solution.acceleration[0] - 7.0 / 5.0).abs() < EXACT);
        assert_eq!(solution.iterations, 1);
    }

    #[test]
    fn a_warm_start_ends_where_a_cold_start_does() {
        let rows = mixed_rows();
        let mass = mixed_mass();
        let mut warm = Solver::default();
        let mut solution = Solution::default();
        // M changes between the solves too: the first step of each is by the last one's factor
        for (shift, scale) in [(0.0, 1.0), (0.3, 1.1), (-2.0, 0.8), (-2.1, 0.8)] {
            let free = DVector::from_fn(4, |i, _| (i as f64 - 1.5) * 4.0 + shift);
            let mass = &mass * scale;
            warm.solve(&rows, &mass, &free, &rows.reference, &mut solution)
                .expect("solvable");
            let cold = solve(&rows, &mass, &free, &rows.reference);
            let difference = (&solution.acceleration - &cold.acceleration).amax();
            assert!(
                difference < EXACT * (1.0 + cold.acceleration.amax()),
                "{difference:e}"
            );
        }
    }
}
