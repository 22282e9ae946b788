//! The `<compiler>` options that rewrite masses and inertias, applied as MuJoCo's compiler applies
//! them (MJCF reference, "compiler"; MuJoCo's body compilation):
//! - per body except the world, on its mass m and principal moments (A, B, C) about its centre:
//!   `boundmass`: m ← max(m, boundmass); `boundinertia`: each moment ← max(moment, boundinertia);
//!   then, when A + B < C for some ordering (not a rigid body), `balanceinertia` sets all three
//!   to their mean, and without it the model is refused;
//! - over the model: `settotalmass` > 0 scales every body's mass and inertia by
//!   settotalmass / Σ m (the bodies welded to the world counted).

use crate::spatial::{Inertia, Mat3};

/// Relative slack in the triangle inequality A + B ≥ C, for the round-off of the principal moments.
const TRIANGLE_TOLERANCE: f64 = 1e-12;

/// The compiler's mass options; the defaults change nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MassRules {
    pub bound_mass: f64,
    pub bound_inertia: f64,
    pub balance_inertia: bool,
    /// `settotalmass`; ≤ 0 leaves the masses as they are.
    pub total_mass: f64,
}

impl Default for MassRules {
    fn default() -> Self {
        MassRules {
            bound_mass: 0.0,
            bound_inertia: 0.0,
            balance_inertia: false,
            total_mass: -1.0,
        }
    }
}

impl MassRules {
    /// One body's inertia (in its frame) after the bounds and the balancing; an inertia that is
    /// not a rigid body's, with `balanceinertia` off, is refused as MuJoCo refuses it.
    pub(crate) fn apply_to_body(&self, inertia: Inertia) -> Result<Inertia, String> {
        let com = inertia.com();
        let mass = inertia.mass;
        // I_C = Ī_O − m (c·c 1 − c cᵀ)
        let inertia_com = inertia.rotational
            - (Mat3::identity() * com.norm_squared() - com * com.transpose()) * mass;
        let eigen = inertia_com.symmetric_eigen();
        let mut moments = eigen.eigenvalues;
        let bounded_mass = mass.max(self.bound_mass);
        let mut changed = bounded_mass != mass;
        for moment in moments.iter_mut() {
            if *moment < self.bound_inertia {
                *moment = self.bound_inertia;
                changed = true;
            }
        }
        let [a, b, c] = [moments[0], moments[1], moments[2]];
        // round-off of the eigen-decomposition is not a violation
        let slack = TRIANGLE_TOLERANCE * (a + b + c);
        if a + b + slack < c || a + c + slack < b || b + c + slack < a {
            if !self.balance_inertia {
                return Err(format!(
                    "the principal moments of inertia [{a:.6e}, {b:.6e}, {c:.6e}] must satisfy \
                     A + B >= C (use <compiler balanceinertia=\"true\"> to fix, as in MuJoCo)"
                ));
            }
            moments.fill((a + b + c) / 3.0);
            changed = true;
        }
        if !changed {
            return Ok(inertia);
        }
        // I_C = R diag(A, B, C) Rᵀ in the body's axes
        let axes = eigen.eigenvectors;
        let balanced = axes * Mat3::from_diagonal(&moments) * axes.transpose();
        Ok(Inertia::from_com(bounded_mass, &com, &balanced))
    }

    /// The factor `settotalmass` scales every inertia by, given the model's total mass.
    pub(crate) fn total_mass_scale(&self, total_mass: f64) -> Option<f64> {
        (self.total_mass > 0.0 && total_mass > 0.0).then(|| self.total_mass / total_mass)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::Vec3;

    fn body(mass: f64, moments: [f64; 3]) -> Inertia {
        Inertia::from_com(
            mass,
            &Vec3::new(0.1, 0.0, 0.2),
            &Mat3::from_diagonal(&Vec3::from(moments)),
        )
    }

    #[test]
    fn the_defaults_change_nothing() {
        let inertia = body(2.0, [0.1, 0.2, 0.25]);
        assert_eq!(MassRules::default().apply_to_body(inertia), Ok(inertia));
    }

    #[test]
    fn bounds_raise_mass_and_moments() {
        let rules = MassRules {
            bound_mass: 0.5,
            bound_inertia: 0.01,
            ..MassRules::default()
        };
        let bounded = rules.apply_to_body(body(0.1, [0.001, 0.02, 0.02])).unwrap();
        assert_eq!(bounded.mass, 0.5);
        let expected = body(0.5, [0.01, 0.02, 0.02]);
        assert!((bounded.rotational - expected.rotational).abs().max() < 1e-15);
    }

    #[test]
    fn balancing_sets_the_mean_and_its_absence_refuses() {
        let thin = body(0.1, [0.001, 0.001, 0.02]);
        assert!(MassRules::default()
            .apply_to_body(thin)
            .unwrap_err()
            .contains("A + B >= C"));
        let rules = MassRules {
            balance_inertia: true,
            ..MassRules::default()
        };
        let balanced = rules.apply_to_body(thin).unwrap();
        let expected = body(0.1, [0.022 / 3.0; 3]);
        assert!((balanced.rotational - expected.rotational).abs().max() < 1e-15);
    }
}
