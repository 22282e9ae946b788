//! The constraint Jacobian J used through its nonzero columns: a friction row has one, a foot's
//! contact the columns of its leg and its base. Products with J and Jᵀ, and the Hessian's terms
//! Jᵀ H_s J row by row and block by block, touch those columns only.

use super::rows::{RowKind, Rows};
use nalgebra::DMatrix;

/// Where each row of J is not zero: row i's columns are `columns[starts[i]..starts[i + 1]]`;
/// those of an elliptic contact's rows together, `group_columns[group_starts[i]..]` up to its
/// length `group_len[i]`, i its first row.
#[derive(Debug, Clone, Default)]
pub(super) struct Pattern {
    starts: Vec<usize>,
    columns: Vec<usize>,
    group_starts: Vec<usize>,
    group_len: Vec<usize>,
    group_columns: Vec<usize>,
}

impl Pattern {
    pub(super) fn find(&mut self, rows: &Rows) {
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
    pub(super) fn group_columns(&self, first: usize) -> &[usize] {
        let start = self.group_starts[first];
        &self.group_columns[start..start + self.group_len[first]]
    }

    pub(super) fn columns(&self, i: usize) -> &[usize] {
        &self.columns[self.starts[i]..self.starts[i + 1]]
    }

    /// y = J a.
    pub(super) fn multiply(&self, rows: &Rows, a: &[f64], y: &mut [f64]) {
        for (i, y) in y.iter_mut().enumerate() {
            let row = rows.row(i);
            *y = self.columns(i).iter().map(|&c| row[c] * a[c]).sum();
        }
    }

    /// out −= Jᵀ f.
    pub(super) fn subtract_transposed(&self, rows: &Rows, f: &[f64], out: &mut [f64]) {
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
    pub(super) fn add_block(
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
    pub(super) fn add_row(&self, rows: &Rows, (i, d): (usize, f64), h: &mut DMatrix<f64>) {
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
