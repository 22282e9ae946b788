//! Manipulability measures of a frame's Jacobian (the ECE 470 notes, "Manipulability").
//!
//! Reference: Yoshikawa, "Manipulability of robotic mechanisms", IJRR 4(2), 1985:
//! `w = √det(J Jᵀ)`, the product of J's singular values, zero at a singularity (and whenever the
//! task has more rows than the robot has joints). The inverse condition number
//! `σ_min / σ_max` over the min(rows, nv) singular values measures how isotropic the motion is:
//! 1 for a perfectly conditioned Jacobian, 0 at a singularity.
//! The task selects rows of the world Jacobian `[linear; angular]` (e.g. 0..3 for position only);
//! both measures are invariant to the rotation of the axes. Writes what `jacobian` writes.

use crate::algo::jacobian::{jacobian, Reference};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::Data;
use nalgebra::DMatrix;

/// (Yoshikawa's manipulability, inverse condition number) of frame `frame` for the Jacobian
/// `rows` (indices into `[vx, vy, vz, ωx, ωy, ωz]`).
pub fn manipulability(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    frame: usize,
    rows: &[usize],
) -> Result<(f64, f64)> {
    if rows.is_empty()
        || rows.iter().any(|&r| r >= 6)
        || (1..rows.len()).any(|k| rows[..k].contains(&rows[k]))
    {
        return Err(Error::InvalidValue {
            argument: "task".into(),
            message: format!("expected distinct Jacobian rows in 0..6, got {rows:?}"),
        });
    }
    let j = jacobian(model, data, q, frame, Reference::World)?;
    // J Jᵀ of the selected rows, and its eigenvalues σ_i²
    let task = DMatrix::from_fn(rows.len(), model.nv, |r, c| j[(rows[r], c)]);
    let mut squared = (&task * task.transpose())
        .symmetric_eigenvalues()
        .iter()
        .map(|l| l.max(0.0))
        .collect::<Vec<_>>();
    squared.sort_by(|a, b| b.total_cmp(a));
    // w = √det(J Jᵀ) = Π σ_i
    let manipulability = squared.iter().map(|l| l.sqrt()).product::<f64>();
    let rank_bound = rows.len().min(model.nv);
    let inverse_condition = match (squared.first(), rank_bound) {
        (Some(&largest), k) if k > 0 && largest > 0.0 => (squared[k - 1] / largest).sqrt(),
        _ => 0.0,
    };
    Ok((manipulability, inverse_condition))
}
