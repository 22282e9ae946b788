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
//! The cost is convex and once differentiable. Each Newton iteration:
//! ```text
//!   g = M (q̈ − q̈₀) − Jᵀ f                 the gradient
//!   H = M + Jᵀ H_s J                       the Hessian (H_s = ∂²s/∂x², block diagonal)
//!   δ = −H⁻¹ g                             Newton's step
//!   α: φ'(α) = 0,  φ(α) the cost at q̈ + α δ (convex: its slope is monotone)
//! ```
//! from the last solution when it costs less than q̈₀ (MuJoCo's warm start). J is sparse (a
//! friction row has one column, a foot's contact the columns of its leg and base): its rows are
//! used through their nonzero columns only.

use super::rows::{Group, RowKind, Rows};
use crate::error::{Error, Result};
use nalgebra::{Cholesky, DMatrix, DVector};

/// Newton's iterations at most; the active set settles in a few, the cone in a few more.
const MAX_ITERATIONS: usize = 100;
/// A step this small against the accelerations ends the iterations: Newton's method converges
/// quadratically near the optimum, so the next step would be below round-off (smaller
/// tolerances only chase round-off: steps of 1e-14 relative, measured on a Go2 falling onto its
/// floor; warm and cold starts then end within 2e-13 of each other).
const STEP_TOLERANCE: f64 = 1e-10;
/// The line search's iterations at most (Newton's method on the slope, kept in a bracket).
const LINE_ITERATIONS: usize = 50;
/// The line search ends where the slope is this small against its value at the start: the
/// outer iterations converge from any such point, and where the active set no longer changes
/// the slope is linear and Newton's full step already exact.
const LINE_TOLERANCE: f64 = 1e-10;

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

/// ∂²s/∂x²: one value per active row whose cost is its own, a dense block per elliptic contact
/// on its cone's surface (0 elsewhere).
#[derive(Debug, Clone, Default)]
struct Curvature {
    /// (row, ∂²s/∂x_row²).
    diagonal: Vec<(usize, f64)>,
    /// (first row, rows, the block).
    blocks: Vec<(usize, usize, [[f64; 6]; 6])>,
}

impl Curvature {
    fn clear(&mut self) {
        self.diagonal.clear();
        self.blocks.clear();
    }

    /// yᵀ H_s y.
    fn along(&self, y: &[f64]) -> f64 {
        let diagonal: f64 = self.diagonal.iter().map(|&(i, d)| d * y[i] * y[i]).sum();
        let blocks: f64 = self
            .blocks
            .iter()
            .map(|(first, len, block)| {
                let y = &y[*first..first + len];
                (0..*len)
                    .map(|a| (0..*len).map(|b| y[a] * block[a][b] * y[b]).sum::<f64>())
                    .sum::<f64>()
            })
            .sum();
        diagonal + blocks
    }
}

/// The forces `f` of every row at `x = J q̈ − a_ref` (`x` per row), into `forces`; the cost `s`
/// is returned. With `curvature`, each group's ∂²s/∂x² goes into it.
fn forces_at(
    rows: &Rows,
    x: &[f64],
    forces: &mut [f64],
    mut curvature: Option<&mut Curvature>,
) -> f64 {
    if let Some(c) = curvature.as_deref_mut() {
        c.clear();
    }
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
                    if let Some(c) = curvature.as_deref_mut() {
                        c.diagonal.push((i, 1.0 / r));
                    }
                }
            }
            RowKind::ContactElliptic => {
                cost += elliptic(rows, group, x, forces, curvature.as_deref_mut());
            }
            _ => {
                for i in range {
                    if x[i] < 0.0 {
                        let d = 1.0 / rows.regulariser[i];
                        forces[i] = -d * x[i];
                        cost += 0.5 * d * x[i] * x[i];
                        if let Some(c) = curvature.as_deref_mut() {
                            c.diagonal.push((i, d));
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

/// An elliptic contact's forces, cost and curvature (see the module's header).
fn elliptic(
    rows: &Rows,
    group: &Group,
    x: &[f64],
    forces: &mut [f64],
    curvature: Option<&mut Curvature>,
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
        let mut curvature = curvature;
        for i in first..first + len {
            let d = 1.0 / rows.regulariser[i];
            forces[i] = -d * x[i];
            cost += 0.5 * d * x[i] * x[i];
            if let Some(c) = curvature.as_deref_mut() {
                c.diagonal.push((i, d));
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
    if let Some(curvature) = curvature {
        // ∇h = (μ, −μ f_k u_k / T);  ∇²s = D_m (∇h ∇hᵀ − μ h diag(f) (I − û ûᵀ) diag(f) / T)
        let mut gradient = [0.0; 6];
        gradient[0] = mu;
        for k in 1..len {
            gradient[k] = -mu * f[k - 1] * u[k] / tangent;
        }
        let mut block = [[0.0; 6]; 6];
        for a in 0..len {
            for b in 0..len {
                let mut value = gradient[a] * gradient[b];
                if a > 0 && b > 0 {
                    let projector = f64::from(u8::from(a == b)) - u[a] * u[b] / (tangent * tangent);
                    value -= mu * h * f[a - 1] * f[b - 1] * projector / tangent;
                }
                block[a][b] = dm * value;
            }
        }
        curvature.blocks.push((first, len, block));
    }
    0.5 * dm * h * h
}

/// Where each row of J is not zero: row i's columns are `columns[starts[i]..starts[i + 1]]`;
/// those of an elliptic contact's rows together, `group_columns[group_starts[i]..]` up to its
/// length `group_len[i]`, i its first row.
#[derive(Debug, Clone, Default)]
struct Pattern {
    starts: Vec<usize>,
    columns: Vec<usize>,
    group_starts: Vec<usize>,
    group_len: Vec<usize>,
    group_columns: Vec<usize>,
}

impl Pattern {
    fn find(&mut self, rows: &Rows) {
        self.starts.clear();
        self.columns.clear();
        self.starts.push(0);
        for i in 0..rows.len() {
            let row = rows.row(i);
            self.columns.extend((0..rows.nv).filter(|&c| row[c] != 0.0));
            self.starts.push(self.columns.len());
        }
        self.group_starts.resize(rows.len(), 0);
        self.group_len.resize(rows.len(), 0);
        self.group_columns.clear();
        for group in rows
            .groups
            .iter()
            .filter(|g| g.kind == RowKind::ContactElliptic)
        {
            let (first, len) = (group.first, group.len);
            let start = self.group_columns.len();
            let used = |c: usize| (first..first + len).any(|i| rows.row(i)[c] != 0.0);
            self.group_columns.extend((0..rows.nv).filter(|&c| used(c)));
            self.group_starts[first] = start;
            self.group_len[first] = self.group_columns.len() - start;
        }
    }

    /// The columns of the elliptic contact whose first row is `first`.
    fn group_columns(&self, first: usize) -> &[usize] {
        let start = self.group_starts[first];
        &self.group_columns[start..start + self.group_len[first]]
    }

    fn columns(&self, i: usize) -> &[usize] {
        &self.columns[self.starts[i]..self.starts[i + 1]]
    }

    /// y = J a.
    fn multiply(&self, rows: &Rows, a: &[f64], y: &mut [f64]) {
        for (i, y) in y.iter_mut().enumerate() {
            let row = rows.row(i);
            *y = self.columns(i).iter().map(|&c| row[c] * a[c]).sum();
        }
    }

    /// out −= Jᵀ f.
    fn subtract_transposed(&self, rows: &Rows, f: &[f64], out: &mut [f64]) {
        for (i, f) in f.iter().enumerate().filter(|(_, f)| **f != 0.0) {
            let row = rows.row(i);
            for &c in self.columns(i) {
                out[c] -= row[c] * f;
            }
        }
    }

    /// H += J_gᵀ B J_g for an elliptic contact's rows `first..first + len` of J (J_g) and a
    /// block B over them (`len` ≤ 6), on the columns where any of those rows is not zero;
    /// `product` (B J_g on them) is scratch space.
    fn add_block(
        &self,
        rows: &Rows,
        (first, len, block): (usize, usize, &[[f64; 6]; 6]),
        product: &mut Vec<f64>,
        h: &mut DMatrix<f64>,
    ) {
        let columns = self.group_columns(first);
        let width = columns.len();
        // W = B J_g on those columns
        product.clear();
        product.resize(len * width, 0.0);
        for (a, weights) in block.iter().enumerate().take(len) {
            for (b, &weight) in weights.iter().enumerate().take(len) {
                let row = rows.row(first + b);
                if weight != 0.0 {
                    for (w, &c) in product[a * width..(a + 1) * width].iter_mut().zip(columns) {
                        *w += weight * row[c];
                    }
                }
            }
        }
        // H += J_gᵀ W
        let nv = rows.nv;
        let h = h.as_mut_slice();
        for a in 0..len {
            let (row, w) = (rows.row(first + a), &product[a * width..(a + 1) * width]);
            for &k in columns.iter() {
                let left = row[k];
                if left != 0.0 {
                    for (&l, w) in columns.iter().zip(w) {
                        h[k + l * nv] += left * w;
                    }
                }
            }
        }
    }

    /// H += d · J_iᵀ J_i (row i of J).
    fn add_row(&self, rows: &Rows, (i, d): (usize, f64), h: &mut DMatrix<f64>) {
        let (row, nv) = (rows.row(i), rows.nv);
        let h = h.as_mut_slice();
        for &k in self.columns(i) {
            let left = d * row[k];
            for &l in self.columns(i) {
                h[k + l * nv] += left * row[l];
            }
        }
    }
}

/// The soft model's solver and its scratch space, kept between solves: sized once, nothing is
/// allocated after.
#[derive(Debug, Clone, Default)]
pub struct Solver {
    /// The last solution's q̈, where the next solve may start.
    warm_start: DVector<f64>,
    /// Whether `warm_start` holds a solution (false: the next solve starts from q̈₀).
    warm: bool,
    pattern: Pattern,
    curvature: Curvature,
    /// x = J q̈ − a_ref and the rows' forces there.
    x: Vec<f64>,
    forces: Vec<f64>,
    /// J q̈ and J δ.
    j_acceleration: Vec<f64>,
    j_step: Vec<f64>,
    /// The Hessian (its factor while solving).
    hessian: DMatrix<f64>,
    /// A block's B J_g on its columns ([`Pattern::add_block`]).
    block_product: Vec<f64>,
    /// q̈ − q̈₀, then M (q̈ − q̈₀).
    difference: DVector<f64>,
    m_difference: DVector<f64>,
    /// g, then δ; M δ.
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
        // from the last solution when it costs less than q̈₀
        if out.acceleration.len() == nv {
            out.acceleration.copy_from(free);
        } else {
            out.acceleration = free.clone();
        }
        let warm_start = std::mem::take(&mut self.warm_start);
        if self.warm
            && warm_start.len() == nv
            && self.cost(rows, mass, free, reference, &warm_start)
                < self.cost(rows, mass, free, reference, free)
        {
            out.acceleration.copy_from(&warm_start);
        }
        self.warm_start = warm_start;
        out.iterations = 0;
        while out.iterations < MAX_ITERATIONS {
            // g = M (q̈ − q̈₀) − Jᵀ f and H = M + Jᵀ H_s J (f and H_s: the line search's last)
            if out.iterations == 0 {
                self.residual(rows, reference, &out.acceleration);
                forces_at(rows, &self.x, &mut self.forces, Some(&mut self.curvature));
            }
            out.iterations += 1;
            self.difference.copy_from(&out.acceleration);
            self.difference -= free;
            self.m_difference.gemv(1.0, mass, &self.difference, 0.0);
            self.step.copy_from(&self.m_difference);
            self.pattern
                .subtract_transposed(rows, &self.forces, self.step.as_mut_slice());
            self.assemble_hessian(rows, mass);
            // δ = −H⁻¹ g
            let factor = Cholesky::new(std::mem::take(&mut self.hessian)).ok_or_else(|| {
                Error::InvalidValue {
                    argument: "model".into(),
                    message: "the constraint problem's Hessian is not positive definite".into(),
                }
            })?;
            factor.solve_mut(&mut self.step);
            self.step.neg_mut();
            self.hessian = factor.unpack_dirty();
            // q̈ += α δ
            let length = self.line_search(rows, mass, reference, &out.acceleration);
            out.acceleration.axpy(length, &self.step, 1.0);
            if length * self.step.amax() <= STEP_TOLERANCE * (1.0 + out.acceleration.amax()) {
                break;
            }
        }
        self.residual(rows, reference, &out.acceleration);
        out.forces.resize(count, 0.0);
        forces_at(rows, &self.x, &mut out.forces, None);
        if self.warm_start.len() == nv {
            self.warm_start.copy_from(&out.acceleration);
        } else {
            self.warm_start = out.acceleration.clone();
        }
        self.warm = true;
        Ok(())
    }

    /// The next solve starts from q̈₀: its result no longer depends on the solves before.
    pub fn forget_warm_start(&mut self) {
        self.warm = false;
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
            self.hessian = DMatrix::zeros(nv, nv);
            for v in [
                &mut self.difference,
                &mut self.m_difference,
                &mut self.step,
                &mut self.m_step,
            ] {
                *v = DVector::zeros(nv);
            }
        }
    }

    /// x = J q̈ − a_ref (J q̈ kept).
    fn residual(&mut self, rows: &Rows, reference: &[f64], acceleration: &DVector<f64>) {
        self.pattern
            .multiply(rows, acceleration.as_slice(), &mut self.j_acceleration);
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
        self.residual(rows, reference, acceleration);
        self.difference.copy_from(acceleration);
        self.difference -= free;
        self.m_difference.gemv(1.0, mass, &self.difference, 0.0);
        0.5 * self.difference.dot(&self.m_difference)
            + forces_at(rows, &self.x, &mut self.forces, None)
    }

    /// H = M + Jᵀ H_s J from the curvature of the last [`forces_at`], row by row on J's
    /// nonzero columns.
    fn assemble_hessian(&mut self, rows: &Rows, mass: &DMatrix<f64>) {
        self.hessian.copy_from(mass);
        for &(i, d) in &self.curvature.diagonal {
            self.pattern.add_row(rows, (i, d), &mut self.hessian);
        }
        for &(first, len, ref block) in &self.curvature.blocks {
            self.pattern.add_block(
                rows,
                (first, len, block),
                &mut self.block_product,
                &mut self.hessian,
            );
        }
    }

    /// The step length α minimising the cost along δ from `start`: where its slope
    /// `φ'(α) = δᵀ M (q̈ + α δ − q̈₀) − (J δ)ᵀ f(α)` (monotone) is zero, by Newton's method on
    /// it (`φ''(α) = δᵀ M δ + (J δ)ᵀ H_s(α) (J δ)`) kept inside the bracket found so far.
    /// Expects `m_difference` = M (q̈ − q̈₀), `forces` f and `curvature` H_s at `start`; leaves f
    /// and H_s at the step's end.
    fn line_search(
        &mut self,
        rows: &Rows,
        mass: &DMatrix<f64>,
        reference: &[f64],
        start: &DVector<f64>,
    ) -> f64 {
        self.m_step.gemv(1.0, mass, &self.step, 0.0);
        self.pattern
            .multiply(rows, self.step.as_slice(), &mut self.j_step);
        self.pattern
            .multiply(rows, start.as_slice(), &mut self.j_acceleration);
        let base = self.step.dot(&self.m_difference);
        let step_mass = self.step.dot(&self.m_step);
        // φ'(0) from the forces at the start, still in `forces`
        let start_slope = base - dot(&self.forces, &self.j_step);
        let mut derivatives = |alpha: f64| {
            let moved = self.j_acceleration.iter().zip(&self.j_step);
            for ((x, (ja, js)), r) in self.x.iter_mut().zip(moved).zip(reference) {
                *x = ja + alpha * js - r;
            }
            forces_at(rows, &self.x, &mut self.forces, Some(&mut self.curvature));
            (
                base + alpha * step_mass - dot(&self.forces, &self.j_step),
                step_mass + self.curvature.along(&self.j_step),
            )
        };
        if start_slope >= 0.0 {
            return 0.0;
        }
        // Newton's full step first
        let (mut low, mut high, mut alpha) = (0.0, f64::INFINITY, 1.0);
        for _ in 0..LINE_ITERATIONS {
            let (slope, curvature) = derivatives(alpha);
            if slope.abs() <= LINE_TOLERANCE * start_slope.abs() {
                return alpha;
            }
            if slope < 0.0 {
                low = alpha;
            } else {
                high = alpha;
            }
            if high - low <= f64::EPSILON * high {
                return alpha;
            }
            let newton = alpha - slope / curvature;
            alpha = match (newton > low && newton < high, high.is_finite()) {
                (true, _) => newton,
                (false, true) => 0.5 * (low + high),
                (false, false) => 2.0 * alpha,
            };
        }
        derivatives(alpha);
        alpha
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

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

    /// Four degrees of freedom under a friction-loss row, a limit and an elliptic contact of
    /// three rows (μ = 0.5), J with zeros in it as a robot's has.
    fn mixed_rows() -> Rows {
        let jacobian = vec![
            0.0, 1.0, 0.0, 0.0, // friction loss
            0.3, 0.0, -1.2, 0.0, // limit
            1.0, 0.5, 0.0, 0.2, // contact normal
            0.0, 0.7, 0.4, -0.3, // first tangent
            0.6, 0.0, 0.9, 0.0, // second tangent
        ];
        let group = |first, len, kind, mu| Group {
            first,
            len,
            kind,
            mu,
            friction: [1.0, 0.8, 0.0, 0.0, 0.0],
        };
        use RowKind::*;
        Rows {
            nv: 4,
            jacobian,
            kind: vec![
                FrictionDof,
                LimitJoint,
                ContactElliptic,
                ContactElliptic,
                ContactElliptic,
            ],
            id: vec![0; 5],
            position: vec![0.0; 5],
            margin: vec![0.0; 5],
            frictionloss: vec![0.5, 0.0, 0.0, 0.0, 0.0],
            regulariser: vec![1e-2, 1e-1, 2e-2, 4e-2, 5e-2],
            reference: vec![0.1, 2.0, 3.0, -1.0, 0.5],
            groups: vec![
                group(0, 1, FrictionDof, 0.0),
                group(1, 1, LimitJoint, 0.0),
                group(2, 3, ContactElliptic, 0.5),
            ],
            contact_rows: vec![Some(2)],
        }
    }

    fn mixed_mass() -> DMatrix<f64> {
        let a = DMatrix::from_fn(4, 4, |i, j| ((i * 4 + j) as f64 * 0.7).sin());
        &a * a.transpose() + DMatrix::identity(4, 4)
    }

    #[test]
    fn the_curvature_is_minus_the_forces_derivative() {
        // x on the elliptic cone's surface and the friction row inside its Huber zone
        let rows = mixed_rows();
        let x = [1e-3, -0.2, -0.3, 0.4, -0.1];
        let mut curvature = Curvature::default();
        let mut forces = [0.0; 5];
        forces_at(&rows, &x, &mut forces, Some(&mut curvature));
        assert_eq!(curvature.blocks.len(), 1, "on the cone's surface");
        let mut dense = DMatrix::zeros(5, 5);
        for &(i, d) in &curvature.diagonal {
            dense[(i, i)] = d;
        }
        for (first, len, block) in &curvature.blocks {
            for a in 0..*len {
                for b in 0..*len {
                    dense[(first + a, first + b)] += block[a][b];
                }
            }
        }
        // H_s = −∂f/∂x, by central differences
        let step = 1e-6;
        for k in 0..5 {
            let (mut up, mut down) = (x, x);
            up[k] += step;
            down[k] -= step;
            let (mut f_up, mut f_down) = ([0.0; 5], [0.0; 5]);
            forces_at(&rows, &up, &mut f_up, None);
            forces_at(&rows, &down, &mut f_down, None);
            for i in 0..5 {
                let derivative = -(f_up[i] - f_down[i]) / (2.0 * step);
                let scale = 1.0 + dense[(i, k)].abs();
                assert!(
                    (derivative - dense[(i, k)]).abs() < 1e-6 * scale,
                    "({i}, {k})"
                );
            }
        }
    }

    #[test]
    fn the_sparse_hessian_is_m_plus_jt_hs_j() {
        let rows = mixed_rows();
        let mass = mixed_mass();
        let mut solver = Solver::default();
        solver.size(4, rows.len());
        solver.pattern.find(&rows);
        let x = [1e-3, -0.2, -0.3, 0.4, -0.1];
        let mut forces = [0.0; 5];
        forces_at(&rows, &x, &mut forces, Some(&mut solver.curvature));
        solver.assemble_hessian(&rows, &mass);
        let mut hs = DMatrix::zeros(5, 5);
        for &(i, d) in &solver.curvature.diagonal {
            hs[(i, i)] = d;
        }
        for (first, len, block) in &solver.curvature.blocks {
            for a in 0..*len {
                for b in 0..*len {
                    hs[(first + a, first + b)] += block[a][b];
                }
            }
        }
        let j = DMatrix::from_row_slice(5, 4, &rows.jacobian);
        let expected = &mass + j.transpose() * hs * &j;
        assert!(
            (&solver.hessian - &expected).amax() < EXACT,
            "{}",
            solver.hessian
        );
    }

    #[test]
    fn a_warm_start_ends_where_a_cold_start_does() {
        let rows = mixed_rows();
        let mass = mixed_mass();
        let mut warm = Solver::default();
        let mut solution = Solution::default();
        for shift in [0.0, 0.3, -2.0] {
            let free = DVector::from_fn(4, |i, _| (i as f64 - 1.5) * 4.0 + shift);
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
