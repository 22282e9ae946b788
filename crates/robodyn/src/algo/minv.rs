//! The inverse of the joint-space inertia matrix, M(q)⁻¹.
//!
//! M from CRBA (Featherstone Table 6.2) is symmetric positive definite, so M⁻¹ comes from its
//! Cholesky factorisation `M = L Lᵀ` (Featherstone §6.5) solved against the identity.
//! Input: q (nq). Writes everything `crba` writes, `data.cholesky` and
//! `data.mass_matrix_inverse`. Cost: that of `crba` plus O(n³).

use crate::algo::crba::crba;
use crate::algo::SINGULARITY_TOLERANCE;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::Data;
use nalgebra::{Cholesky, DMatrix};

/// M(q)⁻¹, written into `data.mass_matrix_inverse`.
pub fn inverse_mass_matrix<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
) -> Result<&'d DMatrix<f64>> {
    crba(model, data, q)?;
    invert_mass_matrix(model, data)?;
    Ok(&data.mass_matrix_inverse)
}

/// `data.mass_matrix_inverse` = `data.mass_matrix`⁻¹, by the Cholesky factor in `data.cholesky`.
pub(crate) fn invert_mass_matrix(model: &Model, data: &mut Data) -> Result<()> {
    // factor a copy of M in the preallocated workspace: M = L Lᵀ
    let mut work = std::mem::replace(&mut data.cholesky, DMatrix::zeros(0, 0));
    work.copy_from(&data.mass_matrix);
    let nv = model.nv;
    let scale = (0..nv)
        .map(|k| data.mass_matrix[(k, k)])
        .fold(0.0, f64::max);
    let factor = match Cholesky::new(work) {
        // L_kk² is the k-th pivot
        Some(factor)
            if (0..nv)
                .all(|k| factor.l_dirty()[(k, k)].powi(2) > SINGULARITY_TOLERANCE * scale) =>
        {
            factor
        }
        other => {
            data.cholesky = other.map_or_else(|| DMatrix::zeros(nv, nv), |f| f.unpack_dirty());
            return Err(Error::InvalidValue {
                argument: "q".into(),
                message: "the mass matrix is singular at this configuration (a massless subtree \
                          without armature)"
                    .into(),
            });
        }
    };
    // solve L Lᵀ X = 1
    data.mass_matrix_inverse.fill_with_identity();
    factor.solve_mut(&mut data.mass_matrix_inverse);
    data.cholesky = factor.unpack_dirty();
    Ok(())
}

/// Solves `L Lᵀ X = B` in place (`rhs` holds B, then X), with L the lower triangle of `cholesky`
/// (what [`invert_mass_matrix`] leaves in `data.cholesky`); allocates nothing.
pub(crate) fn cholesky_solve_mut(cholesky: &DMatrix<f64>, rhs: &mut DMatrix<f64>) {
    cholesky.solve_lower_triangular_unchecked_mut(rhs);
    cholesky.tr_solve_lower_triangular_unchecked_mut(rhs);
}
