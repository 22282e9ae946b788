//! Whether a body's inertial parameters are physical: finite, a non-negative mass, a symmetric
//! inertia whose principal moments satisfy the triangle inequalities.

use super::{INERTIA_ABSOLUTE_TOLERANCE, INERTIA_EIGENVALUE_TOLERANCE};
use crate::spatial::{Inertia, Mat3};

/// Checks that (mass, rotational inertia about the COM) can be computed with: finite, mass ≥ 0,
/// symmetric. [`check_positive_semidefinite`] checks that the body is physical.
pub fn check_mass_and_inertia(mass: f64, inertia_com: &Mat3) -> std::result::Result<(), String> {
    if !mass.is_finite() || mass < 0.0 {
        return Err(format!("expected a finite mass >= 0, got {mass}"));
    }
    if inertia_com.iter().any(|x| !x.is_finite()) {
        return Err("expected a finite inertia tensor, got a non-finite entry".into());
    }
    let asymmetry = (inertia_com - inertia_com.transpose()).abs().max();
    let scale = inertia_com.abs().max().max(f64::MIN_POSITIVE);
    if asymmetry > INERTIA_EIGENVALUE_TOLERANCE * scale {
        return Err("expected a symmetric inertia tensor".into());
    }
    Ok(())
}

/// Checks that a rotational inertia is positive semi-definite (a point mass, zero, is valid).
pub fn check_positive_semidefinite(inertia_com: &Mat3) -> std::result::Result<(), String> {
    let scale = inertia_com.abs().max();
    let eigenvalues = inertia_com.symmetric_eigenvalues();
    let smallest = eigenvalues.min();
    if smallest < -(INERTIA_EIGENVALUE_TOLERANCE * scale).max(INERTIA_ABSOLUTE_TOLERANCE) {
        return Err(format!(
            "expected a positive semi-definite inertia tensor, got principal moments [{:.6e}, {:.6e}, {:.6e}]",
            eigenvalues[0], eigenvalues[1], eigenvalues[2]
        ));
    }
    Ok(())
}

/// Why ten inertial parameters are not those of a rigid body.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Unphysical {
    /// No algorithm can compute with them: a value not finite, a negative mass, a first moment
    /// without mass, or an inertia about the centre of mass that is not positive semi-definite.
    Invalid(String),
    /// Positive semi-definite, but the principal moments break a triangle inequality: no body of
    /// matter has them (its density would be negative somewhere), though every algorithm still
    /// computes with them, as Pinocchio's do; MuJoCo refuses such a body.
    TriangleInequality(String),
}

impl std::fmt::Display for Unphysical {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Unphysical::Invalid(message) | Unphysical::TriangleInequality(message) => {
                f.write_str(message)
            }
        }
    }
}

/// The one rule for physical inertias, applied by the loaders, the `inertial_parameters`
/// setter and Python's `robodyn.inertia.check_physical`: ten inertial parameters [m, h, Ī_O]
/// describe a rigid body when they are finite, m ≥ 0, and the rotational inertia about the
/// centre of mass I_C = Ī_O − (h·h 1 − h hᵀ)/m is positive semi-definite with principal moments
/// obeying the triangle inequalities λ_a + λ_b ≥ λ_c (a massless body has h = 0 and I_C = Ī_O),
/// all within [`INERTIA_EIGENVALUE_TOLERANCE`] of the tensor's largest entry.
pub fn check_physical_parameters(p: &[f64; 10]) -> std::result::Result<(), Unphysical> {
    if let Some(k) = p.iter().position(|x| !x.is_finite()) {
        return Err(Unphysical::Invalid(format!(
            "expected finite parameters, got {} at index {k}",
            p[k]
        )));
    }
    let inertia = Inertia::from_parameters(p);
    let (mass, h) = (inertia.mass, inertia.first_moment);
    if mass < 0.0 {
        return Err(Unphysical::Invalid(format!(
            "expected a mass >= 0, got {mass}"
        )));
    }
    let scale = inertia.rotational.abs().max();
    let tolerance = (INERTIA_EIGENVALUE_TOLERANCE * scale).max(INERTIA_ABSOLUTE_TOLERANCE);
    let inertia_com = if mass > 0.0 {
        inertia.rotational - (Mat3::identity() * h.norm_squared() - h * h.transpose()) / mass
    } else if h.norm() > INERTIA_ABSOLUTE_TOLERANCE {
        return Err(Unphysical::Invalid(format!(
            "a massless body has no first moment, got m c = [{}, {}, {}]",
            h.x, h.y, h.z
        )));
    } else {
        inertia.rotational
    };
    check_positive_semidefinite(&inertia_com).map_err(Unphysical::Invalid)?;
    // sorted, λ₁ ≤ λ₂ ≤ λ₃, only λ₁ + λ₂ ≥ λ₃ can fail
    let mut moments: [f64; 3] = inertia_com.symmetric_eigenvalues().into();
    moments.sort_by(f64::total_cmp);
    let [a, b, c] = moments;
    if a + b < c - tolerance {
        return Err(Unphysical::TriangleInequality(format!(
            "the principal moments about the centre of mass [{a:.6e}, {b:.6e}, {c:.6e}] break the triangle inequality ({a:.6e} + {b:.6e} < {c:.6e}): no rigid body has them"
        )));
    }
    Ok(())
}
