//! The constraint Jacobian J kept by its nonzero columns: a friction row has one, a foot's
//! contact the columns of its leg and its base. Products with J and Jᵀ, and the Hessian's terms
//! Jᵀ H_s J row by row and block by block, touch those columns only, read from compact copies of
//! J's values made once per solve.
//!
//! The Hessian's terms go into its lower triangle only (row ≥ column): the Cholesky
//! factorisation reads no more.

use super::rows::{RowKind, Rows};
use nalgebra::DMatrix;

/// Where each row of J is not zero and its values there: row i's columns are
/// `columns[starts[i]..starts[i + 1]]`, its values `values[..]` alike. An elliptic contact's rows
/// together (`group_len[i]` of them, i the first): the columns where any of them is not zero,
/// `group_columns[group_starts[i]..]` up to its width `group_width[i]`, and its rows' values on
/// each of them (a column of J_g, zeros past its rows) alike in `group_values`.
#[derive(Debug, Clone, Default)]
pub(super) struct Pattern {
    starts: Vec<usize>,
    columns: Vec<usize>,
    values: Vec<f64>,
    group_starts: Vec<usize>,
    group_width: Vec<usize>,
    group_len: Vec<usize>,
    group_columns: Vec<usize>,
    group_values: Vec<[f64; 6]>,
}

impl Pattern {
    pub(super) fn find(&mut self, rows: &Rows) {
        self.starts.clear();
        self.columns.clear();
        self.values.clear();
        self.starts.push(0);
        for i in 0..rows.len() {
            let row = rows.row(i);
            for (c, &value) in row.iter().enumerate().filter(|(_, v)| **v != 0.0) {
                self.columns.push(c);
                self.values.push(value);
            }
            self.starts.push(self.columns.len());
        }
        self.group_starts.resize(rows.len(), 0);
        self.group_width.resize(rows.len(), 0);
        self.group_len.resize(rows.len(), 0);
        self.group_columns.clear();
        self.group_values.clear();
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
            self.group_width[first] = self.group_columns.len() - start;
            self.group_len[first] = len;
            let column = |c: usize| {
                std::array::from_fn(|a| match a < len {
                    true => rows.row(first + a)[c],
                    false => 0.0,
                })
            };
            let values = self.group_columns[start..].iter().map(|&c| column(c));
            self.group_values.extend(values);
        }
    }

    /// Row i's columns and its values there.
    fn row(&self, i: usize) -> (&[usize], &[f64]) {
        let range = self.starts[i]..self.starts[i + 1];
        (&self.columns[range.clone()], &self.values[range])
    }

    /// y = J a.
    pub(super) fn multiply(&self, a: &[f64], y: &mut [f64]) {
        for (i, y) in y.iter_mut().enumerate() {
            let (columns, values) = self.row(i);
            *y = columns.iter().zip(values).map(|(&c, v)| v * a[c]).sum();
        }
    }

    /// out −= Jᵀ f.
    pub(super) fn subtract_transposed(&self, f: &[f64], out: &mut [f64]) {
        for (i, f) in f.iter().enumerate().filter(|(_, f)| **f != 0.0) {
            let (columns, values) = self.row(i);
            for (&c, v) in columns.iter().zip(values) {
                out[c] -= v * f;
            }
        }
    }

    /// H += J_gᵀ B J_g (lower triangle) for an elliptic contact's rows `first..first + len` of J
    /// (J_g) and a block B over them (zeros past them), on the columns where any of those rows
    /// is not zero; `scratch` holds B J_g's columns.
    pub(super) fn add_block(
        &self,
        (first, block): (usize, &[[f64; 6]; 6]),
        scratch: &mut Vec<[f64; 6]>,
        h: &mut DMatrix<f64>,
    ) {
        // the products over the contact's rows only, their count known to the compiler
        match self.group_len[first] {
            3 => self.add_block_of::<3>(first, block, scratch, h),
            4 => self.add_block_of::<4>(first, block, scratch, h),
            _ => self.add_block_of::<6>(first, block, scratch, h),
        }
    }

    /// [`Self::add_block`] over the block's first `N` rows and columns.
    fn add_block_of<const N: usize>(
        &self,
        first: usize,
        block: &[[f64; 6]; 6],
        scratch: &mut Vec<[f64; 6]>,
        h: &mut DMatrix<f64>,
    ) {
        let start = self.group_starts[first];
        let width = self.group_width[first];
        let columns = &self.group_columns[start..start + width];
        let j = &self.group_values[start..start + width];
        // W = B J_g, column by column
        scratch.clear();
        scratch.extend(j.iter().map(|j| {
            std::array::from_fn(|a| match a < N {
                true => (0..N).map(|b| block[a][b] * j[b]).sum(),
                false => 0.0,
            })
        }));
        // H[k, l] += J_g[:, k] · W[:, l], k ≥ l
        let nv = h.nrows();
        let h = h.as_mut_slice();
        for (l, (&column, w)) in columns.iter().zip(scratch.iter()).enumerate() {
            let target = &mut h[column * nv..(column + 1) * nv];
            for (&k, j) in columns[l..].iter().zip(&j[l..]) {
                target[k] += (0..N).map(|a| j[a] * w[a]).sum::<f64>();
            }
        }
    }

    /// H += d · J_iᵀ J_i (row i of J; lower triangle).
    pub(super) fn add_row(&self, (i, d): (usize, f64), h: &mut DMatrix<f64>) {
        let (columns, values) = self.row(i);
        let nv = h.nrows();
        let h = h.as_mut_slice();
        for (li, (&l, &right)) in columns.iter().zip(values).enumerate() {
            let weight = d * right;
            let column = &mut h[l * nv..(l + 1) * nv];
            for (&k, value) in columns[li..].iter().zip(&values[li..]) {
                column[k] += value * weight;
            }
        }
    }
}
