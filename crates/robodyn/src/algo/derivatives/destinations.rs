//! Where the derivatives go: for a caller, `Data`'s matrices or its own row-major buffers
//! ([`DerivativesInto`]); inside, where the passes put ∂τ/∂q and ∂τ/∂q̇ ([`TorqueDerivatives`]):
//! two column-major matrices (`Data`'s), two row-major buffers (NumPy's, and the lanes'), or the
//! negated rows the ABA derivatives solve.

use crate::error::{check_length, Result};
use crate::model::Model;
use crate::spatial::Real;
use crate::Data;
use nalgebra::DMatrix;

/// Where a derivative function ([`super::rnea_derivatives`], [`super::aba_derivatives`])
/// writes the derivatives with respect to q and q̇, and the third matrix (M for inverse
/// dynamics, M⁻¹ for forward dynamics).
#[derive(Debug)]
pub enum DerivativesInto<'o> {
    /// `Data`'s matrices: `dtau_dq` and `dtau_dv` (M in `mass_matrix`), or `dqdd_dq`,
    /// `dqdd_dv` and `mass_matrix_inverse`.
    Data,
    /// Two row-major nv × nv buffers, the derivatives with respect to q and to q̇ (for a caller
    /// that hands them on row by row, as NumPy stores them, without a transpose).
    RowMajor {
        /// ∂/∂q, nv × nv.
        by_q: &'o mut [f64],
        /// ∂/∂q̇, nv × nv.
        by_v: &'o mut [f64],
    },
    /// One buffer of 3 nv × nv row-major matrices one after the other: ∂/∂q, ∂/∂q̇ and M (or M⁻¹).
    Stacked(&'o mut [f64]),
}

impl DerivativesInto<'_> {
    /// Checks the buffers' lengths; `names` are the two derivatives' for the error.
    pub(super) fn check(&self, model: &Model, names: [&str; 2]) -> Result<()> {
        let square = model.nv * model.nv;
        match self {
            DerivativesInto::Data => Ok(()),
            DerivativesInto::RowMajor { by_q, by_v } => {
                check_length(names[0], by_q.len(), square)?;
                check_length(names[1], by_v.len(), square)
            }
            DerivativesInto::Stacked(out) => check_length("out", out.len(), 3 * square),
        }
    }

    /// Hands `data.derivative_rows` (row i = [∂q̈_i/∂q, ∂q̈_i/∂q̇, (M⁻¹)_i]) on as `self` says.
    pub(super) fn copy_rows(self, data: &mut Data) {
        let nv = data.qdd.len();
        if nv == 0 {
            return;
        }
        match self {
            DerivativesInto::Data => {
                // into the matrices column by column, as they are stored
                let width = 3 * nv;
                let matrices = [
                    &mut data.dqdd_dq,
                    &mut data.dqdd_dv,
                    &mut data.mass_matrix_inverse,
                ];
                for (block, matrix) in matrices.into_iter().enumerate() {
                    for (j, column) in matrix.as_mut_slice().chunks_exact_mut(nv).enumerate() {
                        for (i, x) in column.iter_mut().enumerate() {
                            *x = data.derivative_rows[i * width + block * nv + j];
                        }
                    }
                }
            }
            DerivativesInto::RowMajor { by_q, by_v } => {
                for (i, row) in data.derivative_rows.chunks_exact(3 * nv).enumerate() {
                    by_q[i * nv..][..nv].copy_from_slice(&row[..nv]);
                    by_v[i * nv..][..nv].copy_from_slice(&row[nv..2 * nv]);
                }
            }
            DerivativesInto::Stacked(out) => {
                // each third of row i to row i of its block
                for (i, row) in data.derivative_rows.chunks_exact(3 * nv).enumerate() {
                    for (block, part) in row.chunks_exact(nv).enumerate() {
                        out[(block * nv + i) * nv..][..nv].copy_from_slice(part);
                    }
                }
            }
        }
    }
}

/// Where the entries of ∂τ/∂q and ∂τ/∂q̇ go, added to a zeroed buffer (a joint's own block gets
/// the recursion's term and its rotor's).
pub(crate) trait TorqueDerivatives<S> {
    fn add(&mut self, row: usize, column: usize, by_q: S, by_v: S);
}

/// Into two nv × nv matrices: `data.dtau_dq`, `data.dtau_dv`.
pub(super) struct Matrices(pub(super) DMatrix<f64>, pub(super) DMatrix<f64>);

impl TorqueDerivatives<f64> for Matrices {
    #[inline(always)]
    fn add(&mut self, row: usize, column: usize, by_q: f64, by_v: f64) {
        // column-major storage
        let index = row + column * self.0.nrows();
        self.0.as_mut_slice()[index] += by_q;
        self.1.as_mut_slice()[index] += by_v;
    }
}

/// Into two nv × nv row-major buffers, in `f64` or lanes.
pub(crate) struct RowMajor<'a, S> {
    pub by_q: &'a mut [S],
    pub by_v: &'a mut [S],
    pub nv: usize,
}

impl<S: Real> TorqueDerivatives<S> for RowMajor<'_, S> {
    #[inline(always)]
    fn add(&mut self, row: usize, column: usize, by_q: S, by_v: S) {
        let index = row * self.nv + column;
        self.by_q[index] += by_q;
        self.by_v[index] += by_v;
    }
}

/// Negated into the rows [−∂τ/∂q, −∂τ/∂q̇, ·] (nv rows of 3 nv) that the ABA derivatives solve,
/// in `f64` or lanes.
pub(super) struct NegatedRows<'a, S> {
    pub(super) rows: &'a mut [S],
    pub(super) nv: usize,
}

impl<S: Real> TorqueDerivatives<S> for NegatedRows<'_, S> {
    #[inline(always)]
    fn add(&mut self, row: usize, column: usize, by_q: S, by_v: S) {
        let start = row * 3 * self.nv + column;
        self.rows[start] -= by_q;
        self.rows[start + self.nv] -= by_v;
    }
}
