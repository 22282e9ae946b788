//! The inverse of the joint-space inertia matrix, M(q)⁻¹.
//!
//! M from CRBA (Featherstone Table 6.2) is factored along the tree, M = Lᵀ D L (`ltdl`), and
//! solved against the identity. Input: q (nq). Writes everything `crba` writes,
//! `data.mass_matrix_factor` and `data.mass_matrix_inverse`. Cost: that of `crba` plus
//! O(n Σ depth).

use crate::algo::crba::crba;
use crate::algo::ltdl::{factor_mass_matrix, solve_rows};
use crate::error::Result;
use crate::model::Model;
use crate::Data;
use nalgebra::DMatrix;

/// M(q)⁻¹, written into `data.mass_matrix_inverse`.
pub fn inverse_mass_matrix<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
) -> Result<&'d DMatrix<f64>> {
    crba(model, data, q)?;
    factor_mass_matrix(model, data)?;
    // M X = 1; X symmetric, so its rows are its columns
    let mut inverse = std::mem::take(&mut data.mass_matrix_inverse);
    inverse.as_mut_slice().fill(0.0);
    inverse.fill_diagonal(1.0);
    solve_rows(model, data, inverse.as_mut_slice());
    data.mass_matrix_inverse = inverse;
    Ok(&data.mass_matrix_inverse)
}
