//! The small dense solves of constrained dynamics: `A x = b` for a symmetric positive
//! semi-definite A (the Delassus matrix J M⁻¹ Jᵀ, or a Gram matrix), exactly by Cholesky, or by
//! proximal iterations where A is singular.
//!
//! Reference: Golub and Van Loan, *Matrix Computations* (4th ed.), §4.2 (Cholesky); the proximal
//! point method for a singular system as used for rigid constraints by Carpentier, Budhiraja and
//! Mansard, "Proximal and sparse resolution of constrained dynamic equations", RSS 2021:
//! ```text
//!   x_{k+1} = x_k + (A + μ 1)⁻¹ (b − A x_k)
//! ```
//! which from x_0 = 0 converges, for any μ > 0 and b in the range of A, to the solution of
//! least norm, each eigen-direction's error shrinking by μ / (σ + μ) per iteration.
//! Matrices are n × n, column-major, in slices.

use crate::dispatch::multiversion;
use crate::spatial::Real;
use nalgebra::{DMatrix, SimdBool};

/// A Cholesky pivot below this times its row's diagonal entry means the row is a combination of
/// the rows before it: `L_kk² / A_kk = sin²` of the angle between that row and their span (in
/// the metric of M⁻¹), so rows closer than 1e-5 rad to dependent are called dependent.
pub const DEPENDENT_ROW_TOLERANCE: f64 = 1e-10;

/// The proximal iterations stop once `|b − A x|∞ ≤ PROXIMAL_ACCURACY · scale`, the scale being
/// the size of the terms b was computed from (its rounding floor is about 1e-16 of it).
pub const PROXIMAL_ACCURACY: f64 = 1e-12;

/// Iterations whose residual no longer falls (by a hundredth over ten of them) have reached what
/// is left along the directions A cannot reach, or reaches only through eigenvalues far below the
/// damping: the residual is accepted if it is below this times the scale, else the system is
/// refused as inconsistent. Rows that depend on each other only nearly leave such a residual: the
/// out-of-plane rows of a planar loop that integration has opened by 1e-11 m (Cassie's legs
/// swinging at 2 rad/s leave 1e-8 to 1e-7 m/s², about 1e-8 of the scale). A set that cannot hold
/// (one point held at two places) leaves one of the order of the scale itself.
pub const STALLED_ACCURACY: f64 = 1e-6;

/// How many iterations a stall is judged over.
const STALL_WINDOW: usize = 10;

/// At most this many proximal iterations; a system still unsolved is refused as inconsistent.
pub const PROXIMAL_MAX_ITERATIONS: usize = 500;

/// Why a solve failed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum SolveFailure {
    /// Row `k` is a combination of the rows before it (or zero): A is singular.
    DependentRow(usize),
    /// The proximal iterations did not reach [`PROXIMAL_ACCURACY`]: `b` is not in A's range.
    Inconsistent {
        /// `|b − A x|∞` at the last iteration.
        residual: f64,
        /// The size of the terms b was computed from.
        scale: f64,
    },
}

/// Scratch vectors of length n for the proximal iterations.
pub(crate) struct SolveScratch<'a> {
    /// b − A x.
    pub residual: &'a mut [f64],
    /// (A + μ 1)⁻¹ (b − A x).
    pub step: &'a mut [f64],
}

/// Solves `a x = b` (a: n × n, symmetric positive semi-definite): with `damping` 0 by Cholesky
/// ([`solve_direct`]), refusing a dependent row; with `damping` μ > 0 by proximal iterations on
/// `a + μ 1`, to [`PROXIMAL_ACCURACY`] times `scale` (at least 1: the size of the terms b comes
/// from). `factor` (n × n) receives the factor. Returns the number of proximal iterations (0
/// when direct).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(crate) fn solve_symmetric(
    n: usize,
    a: &[f64],
    factor: &mut [f64],
    b: &[f64],
    x: &mut [f64],
    damping: f64,
    scale: f64,
    scratch: SolveScratch,
) -> Result<usize, SolveFailure> {
    if damping == 0.0 {
        solve_direct(n, a, factor, b, x)?;
        return Ok(0);
    }
    factor[..n * n].copy_from_slice(&a[..n * n]);
    for k in 0..n {
        factor[k + k * n] += damping;
    }
    cholesky(n, factor)?;
    let SolveScratch { residual, step } = scratch;
    x[..n].fill(0.0);
    residual[..n].copy_from_slice(&b[..n]);
    let scale = scale.max(1.0).max(largest(&b[..n]));
    let mut recent = [f64::INFINITY; STALL_WINDOW];
    for iteration in 1..=PROXIMAL_MAX_ITERATIONS {
        // x ← x + (A + μ 1)⁻¹ (b − A x)
        step[..n].copy_from_slice(&residual[..n]);
        cholesky_solve(n, factor, step);
        for (xi, si) in x[..n].iter_mut().zip(&step[..n]) {
            *xi += si;
        }
        // b − A x
        residual[..n].copy_from_slice(&b[..n]);
        for (column, &xj) in x[..n].iter().enumerate() {
            for (r, aij) in residual[..n]
                .iter_mut()
                .zip(&a[column * n..(column + 1) * n])
            {
                *r -= aij * xj;
            }
        }
        let size = largest(&residual[..n]);
        if size <= PROXIMAL_ACCURACY * scale {
            return Ok(iteration);
        }
        // the residual STALL_WINDOW iterations ago, replaced by this one
        let before = std::mem::replace(&mut recent[iteration % STALL_WINDOW], size);
        if size > 0.99 * before {
            if size <= STALLED_ACCURACY * scale {
                return Ok(iteration);
            }
            return Err(SolveFailure::Inconsistent {
                residual: size,
                scale,
            });
        }
    }
    Err(SolveFailure::Inconsistent {
        residual: largest(&residual[..n]),
        scale,
    })
}

/// The Cholesky factor of `a` (n × n, symmetric positive definite) into `factor`, for
/// [`cholesky_solve`]; a dependent row is refused as by [`solve_symmetric`].
#[inline(always)]
pub(crate) fn factor_symmetric<S: Real>(
    n: usize,
    a: &[S],
    factor: &mut [S],
) -> Result<(), SolveFailure> {
    factor[..n * n].copy_from_slice(&a[..n * n]);
    cholesky(n, factor)
}

/// Solves `a x = b` (a: n × n, symmetric positive definite) by Cholesky, its factor into
/// `factor`; a dependent row (in any lane) is refused as by [`solve_symmetric`].
#[inline(always)]
pub(crate) fn solve_direct<S: Real>(
    n: usize,
    a: &[S],
    factor: &mut [S],
    b: &[S],
    x: &mut [S],
) -> Result<(), SolveFailure> {
    factor_symmetric(n, a, factor)?;
    x[..n].copy_from_slice(&b[..n]);
    cholesky_solve(n, factor, x);
    Ok(())
}

/// The largest magnitude of `values` (0 when empty).
pub(crate) fn largest(values: &[f64]) -> f64 {
    values.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// In place, `a = L Lᵀ` with L lower triangular (below and on the diagonal; above is left as it
/// was). A pivot not above [`DEPENDENT_ROW_TOLERANCE`] times its diagonal entry is refused.
#[inline(always)]
fn cholesky<S: Real>(n: usize, a: &mut [S]) -> Result<(), SolveFailure> {
    let largest_diagonal = (0..n).fold(S::zero(), |m, k| m.simd_max(a[k + k * n]));
    for k in 0..n {
        // L_kk² = A_kk − Σ_{j<k} L_kj²
        let diagonal = a[k + k * n];
        let mut pivot = diagonal;
        for j in 0..k {
            pivot -= a[k + j * n] * a[k + j * n];
        }
        // refused in any lane: a zero row, a pivot too small, or one not finite
        let zero_row = diagonal.simd_le(S::splat(f64::EPSILON) * largest_diagonal);
        let dependent = pivot.simd_le(S::splat(DEPENDENT_ROW_TOLERANCE) * diagonal);
        let finite = pivot.simd_abs().simd_lt(S::splat(f64::INFINITY));
        if (zero_row | dependent | !finite).any() {
            return Err(SolveFailure::DependentRow(k));
        }
        let l_kk = pivot.simd_sqrt();
        a[k + k * n] = l_kk;
        // L_ik = (A_ik − Σ_{j<k} L_ij L_kj) / L_kk, by one division
        let inverse = S::one() / l_kk;
        for i in k + 1..n {
            let mut sum = a[i + k * n];
            for j in 0..k {
                sum -= a[i + j * n] * a[k + j * n];
            }
            a[i + k * n] = sum * inverse;
        }
    }
    Ok(())
}

/// Solves `L Lᵀ x = b` in place (b in `x[..n]`) with the factor of [`cholesky`].
#[inline(always)]
pub(crate) fn cholesky_solve<S: Real>(n: usize, l: &[S], x: &mut [S]) {
    // the operations of `cholesky_solve_rows` on one column, without its row slicing
    // L y = b: y_k = (b_k − Σ_{j<k} L_kj y_j) / L_kk
    for k in 0..n {
        let mut y_k = x[k];
        for (j, y_j) in x[..k].iter().enumerate() {
            y_k -= l[k + j * n] * *y_j;
        }
        x[k] = y_k * (S::one() / l[k + k * n]);
    }
    // Lᵀ x = y: x_k = (y_k − Σ_{j>k} L_jk x_j) / L_kk
    for k in (0..n).rev() {
        let column = &l[k * n..(k + 1) * n];
        let mut x_k = x[k];
        for (l_jk, x_j) in column[k + 1..].iter().zip(&x[k + 1..n]) {
            x_k -= *l_jk * *x_j;
        }
        x[k] = x_k * (S::one() / column[k]);
    }
}

/// Solves `L Lᵀ X = B` in place for B stored row by row in `rows` (row i at `i * w..(i + 1) *
/// w`, w = rows.len() / n): each step updates a whole row, all columns at once.
pub(crate) fn cholesky_solve_rows(n: usize, l: &[f64], rows: &mut [f64]) {
    if n == 0 {
        return;
    }
    let w = rows.len() / n;
    // L Y = B: y_k = (b_k − Σ_{j<k} L_kj y_j) / L_kk
    for k in 0..n {
        let (done, rest) = rows.split_at_mut(k * w);
        let row = &mut rest[..w];
        for (j, y_j) in done.chunks_exact(w).enumerate() {
            let l_kj = l[k + j * n];
            for (x, y) in row.iter_mut().zip(y_j) {
                *x -= l_kj * y;
            }
        }
        let inverse = 1.0 / l[k + k * n];
        row.iter_mut().for_each(|x| *x *= inverse);
    }
    // Lᵀ X = Y: x_k = (y_k − Σ_{j>k} L_jk x_j) / L_kk
    for k in (0..n).rev() {
        let (before, done) = rows.split_at_mut((k + 1) * w);
        let row = &mut before[k * w..];
        for (j, x_j) in done.chunks_exact(w).enumerate() {
            let l_jk = l[(k + 1 + j) + k * n];
            for (x, y) in row.iter_mut().zip(x_j) {
                *x -= l_jk * y;
            }
        }
        let inverse = 1.0 / l[k + k * n];
        row.iter_mut().for_each(|x| *x *= inverse);
    }
}

multiversion! {
    /// `out = β out + α A B` for column-major A (r × k), B (k × c), out (r × c): each column of
    /// out gathers A's columns, scaled by that column of B, vectorised down the columns where
    /// the processor can ([`crate::dispatch`]). For the small matrices of constrained dynamics:
    /// unlike a blocked product it needs no packing buffer, so it allocates nothing.
    pub(crate) fn multiply_add(
        out: &mut DMatrix<f64>,
        alpha: f64,
        a: &DMatrix<f64>,
        b: &DMatrix<f64>,
        beta: f64,
    ) {
        multiply_add_avx512 for ["avx512f"] => { multiply_add_with(out, alpha, a, b, beta) }
        multiply_add_avx2 for ["avx2"] => { multiply_add_with(out, alpha, a, b, beta) }
        baseline => { multiply_add_with(out, alpha, a, b, beta) }
    }
}

/// [`multiply_add`]: out four columns at a time (the last few one at a time), its rows a block
/// at a time, each tile's sums held in registers while A's columns are gathered into them; a
/// loaded block of A serves the tile's four columns. Every entry sums over k in order, whatever
/// tile it falls in.
#[inline(always)]
fn multiply_add_with(
    out: &mut DMatrix<f64>,
    alpha: f64,
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    beta: f64,
) {
    debug_assert!(out.nrows() == a.nrows() && a.ncols() == b.nrows() && b.ncols() == out.ncols());
    let (r, k) = (a.nrows(), a.ncols());
    if r == 0 || k == 0 {
        out.as_mut_slice().iter_mut().for_each(|x| *x *= beta);
        return;
    }
    let tiled = out.ncols() / 4 * 4;
    let (a, b, out) = (a.as_slice(), b.as_slice(), out.as_mut_slice());
    let (out, rest) = out.split_at_mut(tiled * r);
    let (b, b_rest) = b.split_at(tiled * k);
    for (tile, b_tile) in out.chunks_exact_mut(4 * r).zip(b.chunks_exact(4 * k)) {
        let mut start = gather_tile::<8, 4>(tile, alpha, (a, b_tile), beta, 0);
        start = gather_tile::<4, 4>(tile, alpha, (a, b_tile), beta, start);
        gather_tile::<1, 4>(tile, alpha, (a, b_tile), beta, start);
    }
    for (column, b_j) in rest.chunks_exact_mut(r).zip(b_rest.chunks_exact(k)) {
        let mut start = gather_tile::<16, 1>(column, alpha, (a, b_j), beta, 0);
        start = gather_tile::<8, 1>(column, alpha, (a, b_j), beta, start);
        start = gather_tile::<4, 1>(column, alpha, (a, b_j), beta, start);
        gather_tile::<1, 1>(column, alpha, (a, b_j), beta, start);
    }
}

/// Rows `start..` of `C` columns of [`multiply_add_with`] (`columns`: C × r, `b_tile`: their C
/// columns of B), `W` rows at a time while whole blocks fit: `out_ij = β out_ij + α Σ_k b_kj
/// A_ik`, α applied to the sum (exact for α = ±1, which is all the derivatives use). Returns the
/// first row left.
#[inline(always)]
fn gather_tile<const W: usize, const C: usize>(
    columns: &mut [f64],
    alpha: f64,
    (a, b_tile): (&[f64], &[f64]),
    beta: f64,
    mut start: usize,
) -> usize {
    let (r, k) = (columns.len() / C, b_tile.len() / C);
    // B's C columns, k entries each: indexed below within k, so without checks
    let b_columns: [&[f64]; C] = std::array::from_fn(|c| &b_tile[c * k..(c + 1) * k]);
    while start + W <= r {
        let mut sums = [[0.0; W]; C];
        for (index, a_k) in a.chunks_exact(r).take(k).enumerate() {
            let block: &[f64; W] = a_k[start..start + W].try_into().expect("W rows");
            for (sum, b_column) in sums.iter_mut().zip(&b_columns) {
                let factor = b_column[index];
                for (s, a_ik) in sum.iter_mut().zip(block) {
                    *s += factor * a_ik;
                }
            }
        }
        for (c, sum) in sums.iter().enumerate() {
            let block = &mut columns[c * r + start..c * r + start + W];
            for (x, s) in block.iter_mut().zip(sum) {
                *x = if beta == 0.0 {
                    alpha * s
                } else {
                    beta * *x + alpha * s
                };
            }
        }
        start += W;
    }
    start
}

/// The pseudo-inverse `A⁺ = Σ u_i u_iᵀ / σ_i` of a symmetric positive semi-definite A into `out`
/// (both m × m), over the eigen-directions A reaches: those with σ_i above
/// [`DEPENDENT_ROW_TOLERANCE`] times the largest (the others are rows depending on the rest).
/// `A⁺ b` is the least-squares solution of least norm of `A x = b`. Allocates the
/// eigen-decomposition. Golub and Van Loan, §5.5 (the pseudo-inverse); §8.3 (the symmetric
/// eigen-decomposition).
pub(crate) fn pseudo_inverse(a: &DMatrix<f64>, out: &mut DMatrix<f64>) {
    let eigen = a.clone().symmetric_eigen();
    let cutoff = DEPENDENT_ROW_TOLERANCE * eigen.eigenvalues.amax();
    out.fill(0.0);
    for (i, &sigma) in eigen.eigenvalues.iter().enumerate() {
        if sigma > cutoff {
            let u = eigen.eigenvectors.column(i);
            out.ger(1.0 / sigma, &u, &u, 1.0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A = B Bᵀ for B with a repeated row: rank 2 of 3.
    fn singular() -> (Vec<f64>, Vec<f64>) {
        let rows = [[1.0, 2.0, 0.5], [0.0, 1.0, -1.0], [1.0, 2.0, 0.5]];
        let mut a = vec![0.0; 9];
        for i in 0..3 {
            for j in 0..3 {
                a[i + 3 * j] = (0..3).map(|k| rows[i][k] * rows[j][k]).sum();
            }
        }
        // b = A [1, 2, 3]: in A's range
        let b = (0..3)
            .map(|i| (0..3).map(|j| a[i + 3 * j] * (j + 1) as f64).sum())
            .collect();
        (a, b)
    }

    fn run(a: &[f64], b: &[f64], damping: f64) -> (Result<usize, SolveFailure>, Vec<f64>) {
        let (mut factor, mut x, mut r, mut s) = (vec![0.0; 9], vec![0.0; 3], [0.0; 3], [0.0; 3]);
        let scratch = SolveScratch {
            residual: &mut r,
            step: &mut s,
        };
        let result = solve_symmetric(3, a, &mut factor, b, &mut x, damping, 1.0, scratch);
        (result, x)
    }

    #[test]
    fn a_dependent_row_is_named_and_the_proximal_solve_finds_the_least_norm_solution() {
        let (a, b) = singular();
        assert_eq!(run(&a, &b, 0.0).0, Err(SolveFailure::DependentRow(2)));
        let (result, x) = run(&a, &b, 1e-3);
        assert!(result.is_ok(), "{result:?}");
        // least norm: the two equal rows share their part equally
        assert!((x[0] - x[2]).abs() < 1e-9, "{x:?}");
        for i in 0..3 {
            let ax: f64 = (0..3).map(|j| a[i + 3 * j] * x[j]).sum();
            assert!((ax - b[i]).abs() < 1e-9);
        }
    }

    #[test]
    fn many_right_hand_sides_solve_as_each_alone() {
        // A = B Bᵀ + 1, positive definite; X = A⁻¹ (rows of B as right-hand sides)
        let (a, _) = singular();
        let a: Vec<f64> = (0..9)
            .map(|k| a[k] + if k % 4 == 0 { 1.0 } else { 0.0 })
            .collect();
        let mut factor = vec![0.0; 9];
        factor_symmetric(3, &a, &mut factor).unwrap();
        let mut rows = vec![1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        cholesky_solve_rows(3, &factor, &mut rows);
        for c in 0..3 {
            let mut x = [0.0; 3];
            x[c] = 1.0;
            cholesky_solve(3, &factor, &mut x);
            for r in 0..3 {
                assert!((rows[r * 3 + c] - x[r]).abs() < 1e-15);
                // A x = e_c
                let ax: f64 = (0..3).map(|j| a[r + 3 * j] * x[j]).sum();
                assert!((ax - if r == c { 1.0 } else { 0.0 }).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn multiply_add_is_the_matrix_product() {
        // row counts that take each block size (16, 8, 4, 1) and a mix of them; column counts
        // in tiles of four, alone, and both
        for (rows, columns) in [1, 4, 8, 13, 16, 29]
            .into_iter()
            .flat_map(|r| [1, 4, 5, 11].map(|c| (r, c)))
        {
            for beta in [0.0, 0.5, 1.0] {
                let a = DMatrix::from_fn(rows, 7, |i, j| (i * 3 + j) as f64 - 4.0);
                let b = DMatrix::from_fn(7, columns, |i, j| (i + 2 * j) as f64 * 0.5);
                let mut out = DMatrix::from_fn(rows, columns, |i, j| (i + j) as f64);
                let expected = &out * beta + &a * &b * -2.0;
                multiply_add(&mut out, -2.0, &a, &b, beta);
                assert!(
                    (out - expected).amax() < 1e-12,
                    "{rows} × {columns}, β = {beta}"
                );
            }
        }
    }

    #[test]
    fn an_inconsistent_system_is_refused() {
        let (a, _) = singular();
        let b = [1.0, 0.0, -1.0];
        assert!(matches!(
            run(&a, &b, 1e-3).0,
            Err(SolveFailure::Inconsistent { .. })
        ));
    }
}
