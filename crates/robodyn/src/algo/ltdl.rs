//! The mass matrix's tree-sparse factorisation M = Lᵀ D L and the solves with it.
//!
//! Reference: Featherstone, "Efficient factorization of the joint-space inertia matrix for
//! branched kinematic trees", IJRR 24(6), 2005, and *Rigid Body Dynamics Algorithms* (2008) §6.5.
//! M_ij is zero unless one of i, j is an ancestor of the other (the parent of a velocity
//! coordinate, `Model::dof_parent`, being the one before it in its joint or the last of the
//! parent body's joint). Eliminating the coordinates from the leaves up keeps that pattern: L is
//! unit lower triangular with L_ki ≠ 0 only for i an ancestor of k, D diagonal. In place, k from
//! the last coordinate to the first:
//! ```text
//!   for each ancestor i of k:   a = M_ki / M_kk;   M_ij −= a M_kj for j = i and its ancestors;   M_ki = a
//! ```
//! after which D_k = M_kk and L_ki = M_ki. Solving M x = b is then two sweeps along the ancestor
//! chains (Lᵀ from the leaves, L from the root) and a division by D. Cost: O(Σ depth²) to factor,
//! O(Σ depth) per right-hand side, against O(n³) and O(n²) dense: on a floating humanoid, whose
//! chains are short against its 50 coordinates, a fraction.

use crate::algo::SINGULARITY_TOLERANCE;
use crate::dispatch::multiversion;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::spatial::Real;
use crate::Data;
use simba::simd::SimdBool;
use std::ops::Range;

/// Factors `data.mass_matrix` into `data.mass_matrix_factor` (D on the diagonal, L strictly
/// below it; nothing above is read). A pivot D_k not above [`SINGULARITY_TOLERANCE`] times M's
/// largest diagonal entry is refused: M is then singular (a massless subtree without armature).
pub fn factor_mass_matrix(model: &Model, data: &mut Data) -> Result<()> {
    let (mass_matrix, factor) = (data.mass_matrix.as_slice(), &mut data.mass_matrix_factor);
    factor_into(model, mass_matrix, factor.as_mut_slice()).map_err(|()| singular_mass_matrix())
}

/// The error for a mass matrix whose factor refused a pivot.
pub(crate) fn singular_mass_matrix() -> Error {
    Error::InvalidValue {
        argument: "q".into(),
        message: "the mass matrix is singular at this configuration (a massless subtree without \
                  armature)"
            .into(),
    }
}

/// [`factor_mass_matrix`] of the column-major `mass_matrix` into `factor`, in `f64` or lanes;
/// an error if a pivot of any lane is refused.
#[inline(always)]
pub(crate) fn factor_into<S: Real>(
    model: &Model,
    mass_matrix: &[S],
    factor: &mut [S],
) -> std::result::Result<(), ()> {
    let nv = model.nv;
    factor.copy_from_slice(mass_matrix);
    let scale = (0..nv).fold(S::splat(0.0), |largest, k| {
        largest.simd_max(factor[k + k * nv])
    });
    let threshold = S::splat(SINGULARITY_TOLERANCE) * scale;
    for k in (0..nv).rev() {
        // column-major storage: F[r, c] at r + c nv
        let pivot = factor[k + k * nv];
        // refused where not above the threshold and zero (NaN is not above either)
        let accepted = pivot.simd_gt(threshold) & pivot.simd_gt(S::splat(0.0));
        if !accepted.all() {
            return Err(());
        }
        let mut ancestor = model.dof_parent[k];
        while let Some(i) = ancestor {
            // eliminate coordinate k from row i and the rows of i's ancestors
            let a = factor[k + i * nv] / pivot;
            let mut above = Some(i);
            while let Some(j) = above {
                factor[i + j * nv] -= a * factor[k + j * nv];
                above = model.dof_parent[j];
            }
            factor[k + i * nv] = a;
            ancestor = model.dof_parent[i];
        }
    }
    Ok(())
}

/// Which sweeps of the solve with M = Lᵀ D L a call makes.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Sweeps {
    /// Both: X = M⁻¹ B.
    Both,
    /// The first alone, from the leaves: Y = L⁻ᵀ B.
    Transposed,
    /// The second alone, from the root: X = L⁻¹ D⁻¹ Y.
    Lower,
}

multiversion! {
    /// [`solve_rows`]' `sweeps` with the column-major `factor` of [`factor_into`]. Each
    /// elimination step is one row update over all columns at once, vectorised: with AVX-512 or
    /// AVX2 where the processor has it ([`crate::dispatch`]), else with the baseline's SSE2.
    pub(crate) fn solve_rows_in(model: &Model, factor: &[f64], rows: &mut [f64], sweeps: Sweeps) {
        solve_rows_avx512 for ["avx512f"] => { solve_rows_with(model, factor, rows, sweeps) }
        solve_rows_avx2 for ["avx2"] => { solve_rows_with(model, factor, rows, sweeps) }
        baseline => { solve_rows_with(model, factor, rows, sweeps) }
    }
}

/// Solves M X = B in place for B stored row by row in `rows` (row i at `i * width..(i + 1) *
/// width`, width = rows.len() / nv), with the factor of [`factor_mass_matrix`] in `data`.
pub fn solve_rows(model: &Model, data: &Data, rows: &mut [f64]) {
    solve_rows_in(
        model,
        data.mass_matrix_factor.as_slice(),
        rows,
        Sweeps::Both,
    );
}

/// The first half of [`solve_rows`]: Y = L⁻ᵀ B in place (rows as there). A column of B that is
/// zero outside a body's ancestors stays so: `Yᵀ D⁻¹ Y = Bᵀ M⁻¹ B` can be summed over them.
pub fn solve_transposed_rows(model: &Model, data: &Data, rows: &mut [f64]) {
    solve_rows_in(
        model,
        data.mass_matrix_factor.as_slice(),
        rows,
        Sweeps::Transposed,
    );
}

/// The second half of [`solve_rows`]: X = L⁻¹ D⁻¹ Y in place (rows as there), so that
/// [`solve_transposed_rows`] then this is M⁻¹.
pub fn solve_lower_rows(model: &Model, data: &Data, rows: &mut [f64]) {
    solve_rows_in(
        model,
        data.mass_matrix_factor.as_slice(),
        rows,
        Sweeps::Lower,
    );
}

/// [`solve_rows`]' `sweeps` with the column-major `factor` of [`factor_into`], in `f64` or
/// lanes. The columns are solved a block at a time (256 bytes of each row, the block of one row
/// held in registers while it is updated or used), so a block's rows stay in the L1 cache
/// through the sweeps; each column is solved by the same operations in the same order in any
/// block.
#[inline(always)]
pub(crate) fn solve_rows_with<S: Real>(
    model: &Model,
    factor: &[S],
    rows: &mut [S],
    sweeps: Sweeps,
) {
    let width = rows.len() / model.nv.max(1);
    let mut start = 0;
    if std::mem::size_of::<S>() == 8 {
        start = solve_blocks::<S, 32>(model, factor, rows, width, start, sweeps);
        start = solve_blocks::<S, 16>(model, factor, rows, width, start, sweeps);
    }
    if std::mem::size_of::<S>() <= 32 {
        start = solve_blocks::<S, 8>(model, factor, rows, width, start, sweeps);
    }
    start = solve_blocks::<S, 4>(model, factor, rows, width, start, sweeps);
    start = solve_blocks::<S, 2>(model, factor, rows, width, start, sweeps);
    solve_blocks::<S, 1>(model, factor, rows, width, start, sweeps);
}

/// Solves the blocks of `W` columns from column `start` on while whole ones fit in the rows'
/// `width`; returns the first column left.
#[inline(always)]
fn solve_blocks<S: Real, const W: usize>(
    model: &Model,
    factor: &[S],
    rows: &mut [S],
    width: usize,
    mut start: usize,
    sweeps: Sweeps,
) -> usize {
    while start + W <= width {
        let block = Block::<W> { width, start };
        if sweeps != Sweeps::Lower {
            solve_transposed::<S, W>(model, factor, rows, block);
        }
        if sweeps != Sweeps::Transposed {
            solve_lower::<S, W>(model, factor, rows, block);
        }
        start += W;
    }
    start
}

/// `W` columns from `start` of rows of `width` values.
#[derive(Clone, Copy)]
struct Block<const W: usize> {
    width: usize,
    start: usize,
}

impl<const W: usize> Block<W> {
    /// The block's part of `row`.
    #[inline(always)]
    fn of(self, row: usize) -> Range<usize> {
        let first = row * self.width + self.start;
        first..first + W
    }

    /// The block's part of `row`, as values.
    #[inline(always)]
    fn load<S: Real>(self, rows: &[S], row: usize) -> [S; W] {
        rows[self.of(row)].try_into().expect("a block of W columns")
    }

    /// z_k = y_k / D_k on the block, D in the diagonal of the column-major `factor`.
    #[inline(always)]
    fn scaled<S: Real>(self, rows: &[S], factor: &[S], nv: usize, k: usize) -> [S; W] {
        let inverse_pivot = S::splat(1.0) / factor[k + k * nv];
        self.load(rows, k).map(|y: S| y * inverse_pivot)
    }
}

/// Lᵀ y = b on a block: k from the leaves, y_k (final once k's descendants are done) then leaves
/// its share L_ki y_k in the row of each ancestor i. A coordinate and its parent just before it
/// (the inside of a chain) go together, so each ancestor row is read and written once for both.
#[inline(always)]
fn solve_transposed<S: Real, const W: usize>(
    model: &Model,
    factor: &[S],
    rows: &mut [S],
    block: Block<W>,
) {
    let nv = model.nv;
    let mut k = nv;
    while k > 0 {
        k -= 1;
        let y_k: [S; W] = block.load(rows, k);
        let paired = k > 0 && model.dof_parent[k] == Some(k - 1);
        if !paired {
            let mut ancestor = model.dof_parent[k];
            while let Some(i) = ancestor {
                let l_ki = factor[k + i * nv];
                for (target, y) in rows[block.of(i)].iter_mut().zip(y_k) {
                    *target -= l_ki * y;
                }
                ancestor = model.dof_parent[i];
            }
            continue;
        }
        // the parent p = k − 1 is final after k's share
        let p = k - 1;
        let l_kp = factor[k + p * nv];
        let mut y_p: [S; W] = block.load(rows, p);
        for (y, y_from_k) in y_p.iter_mut().zip(y_k) {
            *y -= l_kp * y_from_k;
        }
        rows[block.of(p)].copy_from_slice(&y_p);
        let mut ancestor = model.dof_parent[p];
        while let Some(i) = ancestor {
            let (l_ki, l_pi) = (factor[k + i * nv], factor[p + i * nv]);
            for ((target, y_from_k), y_from_p) in rows[block.of(i)].iter_mut().zip(y_k).zip(y_p) {
                *target = *target - l_ki * y_from_k - l_pi * y_from_p;
            }
            ancestor = model.dof_parent[i];
        }
        k = p;
    }
}

/// D z = y and L x = z on a block, from the root: x_k = z_k / D_k − Σ L_ki x_i over k's
/// ancestors i. A coordinate and its child just after it go together, each ancestor row read
/// once for both; the child then takes its parent's share last.
#[inline(always)]
fn solve_lower<S: Real, const W: usize>(
    model: &Model,
    factor: &[S],
    rows: &mut [S],
    block: Block<W>,
) {
    let nv = model.nv;
    let mut k = 0;
    while k < nv {
        let mut x_k = block.scaled(rows, factor, nv, k);
        let paired = k + 1 < nv && model.dof_parent[k + 1] == Some(k);
        if !paired {
            let mut ancestor = model.dof_parent[k];
            while let Some(i) = ancestor {
                let l_ki = factor[k + i * nv];
                for (x, x_i) in x_k.iter_mut().zip(&rows[block.of(i)]) {
                    *x -= l_ki * *x_i;
                }
                ancestor = model.dof_parent[i];
            }
            rows[block.of(k)].copy_from_slice(&x_k);
            k += 1;
            continue;
        }
        let c = k + 1;
        let mut x_c = block.scaled(rows, factor, nv, c);
        let mut ancestor = model.dof_parent[k];
        while let Some(i) = ancestor {
            let (l_ki, l_ci) = (factor[k + i * nv], factor[c + i * nv]);
            for ((x, y), x_i) in x_k.iter_mut().zip(&mut x_c).zip(&rows[block.of(i)]) {
                *x -= l_ki * *x_i;
                *y -= l_ci * *x_i;
            }
            ancestor = model.dof_parent[i];
        }
        let l_ck = factor[c + k * nv];
        for (y, x) in x_c.iter_mut().zip(x_k) {
            *y -= l_ck * x;
        }
        rows[block.of(k)].copy_from_slice(&x_k);
        rows[block.of(c)].copy_from_slice(&x_c);
        k += 2;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algo::crba::crba;
    use crate::io::bundled::floating_ur5_state;

    /// The AVX-512 and AVX2 builds of the solve and the baseline one give the same result bit for bit (the
    /// claim of `solve_rows`), for row widths that do and do not fill whole vectors.
    #[test]
    fn solve_paths_agree_bit_for_bit() {
        let (model, q, ..) = floating_ur5_state();
        let mut data = Data::new(&model);
        crba(&model, &mut data, &q).unwrap();
        factor_mass_matrix(&model, &mut data).unwrap();
        for width in [1, 3, 4, 7, 3 * model.nv + 1] {
            let rows: Vec<f64> = (0..model.nv * width)
                .map(|k| ((k * 7919) % 1000) as f64 / 997.0 - 0.5)
                .collect();
            let mut generic = rows.clone();
            solve_rows_with(
                &model,
                data.mass_matrix_factor.as_slice(),
                &mut generic,
                Sweeps::Both,
            );
            let mut dispatched = rows.clone();
            solve_rows(&model, &data, &mut dispatched);
            assert_eq!(generic, dispatched, "width {width}");
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                let mut avx2 = rows.clone();
                // SAFETY: the processor has AVX2, just checked.
                unsafe {
                    solve_rows_avx2(
                        &model,
                        data.mass_matrix_factor.as_slice(),
                        &mut avx2,
                        Sweeps::Both,
                    )
                };
                assert_eq!(generic, avx2, "width {width}");
            }
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx512f") {
                let mut avx512 = rows.clone();
                // SAFETY: the processor has AVX-512F, just checked.
                unsafe {
                    solve_rows_avx512(
                        &model,
                        data.mass_matrix_factor.as_slice(),
                        &mut avx512,
                        Sweeps::Both,
                    )
                };
                assert_eq!(generic, avx512, "width {width}");
            }
        }
    }
}
