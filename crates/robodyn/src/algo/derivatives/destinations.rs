//! Where the derivative passes put ∂τ/∂q and ∂τ/∂q̇: two column-major matrices (`Data`'s), two
//! row-major buffers (NumPy's, and the lanes'), or the negated rows the ABA derivatives solve.

use crate::spatial::Real;
use nalgebra::DMatrix;

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
