//! Tendons: a length L(q) that MuJoCo hangs forces and constraints on. A fixed tendon
//! (MJCF `<tendon><fixed>`) is a fixed linear combination of hinge and slide coordinates,
//! ```text
//!   L = Σ_k c_k q_k,   L̇ = J q̇,   J = Σ_k c_k e_k
//! ```
//! a spatial one (`<tendon><spatial>` through sites, pulleys, and around spheres and cylinders)
//! the length of its path through the sites, which moves with the bodies
//! ([`crate::soft::tendons`] computes both at a state: MuJoCo's `ten_length`, `ten_J`). What MuJoCo hangs on it: a spring and a damper on L (its
//! `stiffness` outside the dead band `springlength` and `damping`), dry friction and limits as
//! constraint rows, equalities coupling two lengths, actuators pulling on it, and an inertia
//! moving with it (`armature`).

use super::springs::{polynomial_coefficient, polynomial_slope};
use super::{Model, SolverParameters};
use crate::spatial::Vec3;

/// One stop of a spatial tendon's path.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum PathPoint {
    /// A site.
    Site {
        /// The body it moves with.
        body: usize,
        /// Its position in that body's frame.
        point: Vec3,
    },
    /// A sphere or cylinder the path wraps around between the sites on either side of it
    /// (the shortest path over its surface where the straight one would pass through it).
    Geom {
        /// The geom ([`Model::geoms`]): a sphere or a cylinder.
        geom: usize,
        /// A side site (`sidesite`: its body, its position in that body's frame): of the two
        /// ways around, the one on its side; inside the geom, the path is pressed against the
        /// surface from within.
        side: Option<(usize, Vec3)>,
    },
    /// A pulley: the branch after it counts its length divided by `divisor`.
    Pulley {
        /// The branch's divisor (MJCF `divisor`).
        divisor: f64,
    },
}

/// A site of a spatial tendon's path as its walkers read it: where it is, its branch's divisor,
/// whether it starts a branch (the path's first site, or the first after a pulley), and the geom
/// wrapped between it and the site before (`PathPoint::Geom`'s geom and side site).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathSite {
    /// The body it moves with.
    pub body: usize,
    /// Its position in that body's frame.
    pub point: Vec3,
    /// The divisor of its branch (1 before any pulley).
    pub divisor: f64,
    /// Whether no segment ends at it.
    pub starts_branch: bool,
    /// The geom the segment ending at it wraps around, and that geom's side site.
    pub wrapped: Option<(usize, Option<(usize, Vec3)>)>,
}

/// One tendon.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Tendon {
    /// Its name in the file (`tendon<k>` when it has none).
    pub name: String,
    /// A fixed tendon's joints: (the body whose hinge or slide it is, the coefficient c_k).
    pub joints: Vec<(usize, f64)>,
    /// A spatial tendon's path, in order (empty for a fixed tendon).
    #[serde(default)]
    pub path: Vec<PathPoint>,
    /// L at the neutral configuration (MuJoCo's `tendon_length0`).
    pub length0: f64,
    /// The range of L where it is limited (`limited`, `range`).
    pub range: Option<(f64, f64)>,
    /// How far inside the range a limit's row starts (`margin`).
    pub margin: f64,
    /// The limit rows' softness (`solreflimit`, `solimplimit`).
    pub limit: SolverParameters,
    /// Dry friction's largest force on L (`frictionloss`).
    pub frictionloss: f64,
    /// The friction row's softness (`solreffriction`, `solimpfriction`).
    pub friction: SolverParameters,
    /// The spring's stiffness (`stiffness`), pulling L into `spring_length`.
    pub stiffness: f64,
    /// The dead band [low, high] of the spring (`springlength`; when not given, the length at
    /// the joints' `springref`, not at qpos0).
    pub spring_length: [f64; 2],
    /// The damper on L̇ (`damping`).
    pub damping: f64,
    /// The spring's higher terms [k₁, k₂] (`stiffness="k k₁ k₂"`, MuJoCo's
    /// `tendon_stiffnesspoly`): its force −x (k + k₁ x + k₂ x²), x the stretch out of the band.
    #[serde(default)]
    pub stiffness_poly: [f64; 2],
    /// The damper's higher terms [b₁, b₂] (`damping="b b₁ b₂"`, with its actuators' g² terms;
    /// MuJoCo's `tendon_dampingpoly`): its force −L̇ (b + b₁ |L̇| + b₂ L̇²).
    #[serde(default)]
    pub damping_poly: [f64; 2],
    /// The range [f₋, f₊] the forces of the tendon's actuators are scaled into together, where
    /// limited (`actuatorfrclimited`, `actuatorfrcrange`; f₋ ≤ 0 ≤ f₊).
    #[serde(default)]
    pub actuator_force_range: Option<(f64, f64)>,
    /// The inertia a of a mass moving with L (`armature`, and its actuators' g² `armature`):
    /// MuJoCo's soft dynamics add a JᵀJ to M and a J (J̇ q̇) to the bias forces
    /// ([`crate::soft::inertia`]).
    #[serde(default)]
    pub armature: f64,
    /// The spring's yield (`springyield`; 0: elastic): past it the dead band moves
    /// ([`Model::yield_springs`]).
    #[serde(default)]
    pub spring_yield: f64,
}

impl Tendon {
    /// Whether it is a spatial tendon (a path through sites) rather than a fixed one.
    pub fn is_spatial(&self) -> bool {
        !self.path.is_empty()
    }

    /// A spatial tendon's sites in order, each with its branch and the geom wrapped before it.
    pub fn path_sites(&self) -> impl Iterator<Item = PathSite> + '_ {
        let (mut divisor, mut starts_branch, mut wrapped) = (1.0, true, None);
        self.path.iter().filter_map(move |stop| match stop {
            PathPoint::Pulley { divisor: d } => {
                (divisor, starts_branch) = (*d, true);
                None
            }
            PathPoint::Geom { geom, side } => {
                wrapped = Some((*geom, *side));
                None
            }
            PathPoint::Site { body, point } => {
                let site = PathSite {
                    body: *body,
                    point: *point,
                    divisor,
                    starts_branch,
                    wrapped: wrapped.take(),
                };
                starts_branch = false;
                Some(site)
            }
        })
    }

    /// A fixed tendon's nonzero Jacobian entries, with each joint's coordinate in q: (velocity coordinate,
    /// configuration coordinate, c_k).
    pub fn entries<'a>(
        &'a self,
        model: &'a Model,
    ) -> impl Iterator<Item = (usize, usize, f64)> + 'a {
        self.joints
            .iter()
            .map(|&(body, c)| (model.idx_v[body], model.idx_q[body], c))
    }

    /// The spring's and the damper's force along the tendon at (L, L̇) with the dead band
    /// `[low, high]` (its `spring_length`, or where it yielded to): with x = L − high above
    /// the dead band, L − low below it, 0 within, `−x (k + k₁ x + k₂ x²)` and
    /// `− L̇ (b + b₁ |L̇| + b₂ L̇²)` (MuJoCo's `mju_polyForce`).
    pub fn passive_force(
        &self,
        [low, high]: [f64; 2],
        length: f64,
        rate: f64,
        spring: bool,
        damper: bool,
    ) -> f64 {
        let x = if length < low {
            length - low
        } else if length > high {
            length - high
        } else {
            0.0
        };
        let spring_force = if spring {
            -x * polynomial_coefficient(self.stiffness, &self.stiffness_poly, x)
        } else {
            0.0
        };
        let damper_force = if damper {
            -rate * polynomial_coefficient(self.damping, &self.damping_poly, rate.abs())
        } else {
            0.0
        };
        spring_force + damper_force
    }

    /// ∂f/∂L̇ of the damper at L̇: `−(b + 2 b₁ |L̇| + 3 b₂ L̇²)` (MuJoCo's `mjd_xPolyForce`).
    pub fn damping_slope(&self, rate: f64) -> f64 {
        -polynomial_slope(self.damping, &self.damping_poly, rate.abs())
    }
}

/// A tendon equality (MJCF `<equality><tendon>`): one tendon's length a polynomial of another's
/// about their neutral lengths, `L₁ − L₁,₀ = Σ_k c_k (L₂ − L₂,₀)^k`, or, without a second,
/// `L₁ − L₁,₀ = c₀`. Held by MuJoCo's soft model only (`soft`).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TendonEquality {
    /// Its name in the file (empty when it has none).
    pub name: String,
    /// The tendon that follows and the one it follows ([`Model::tendons`] indices).
    pub tendons: (usize, Option<usize>),
    /// `c₀ … c₄` (MuJoCo's `polycoef`).
    pub polynomial: [f64; 5],
    /// Whether it is enforced (`active`).
    pub active: bool,
    /// Its `solref` and `solimp`.
    pub solver: SolverParameters,
    /// Its place among the file's equalities: the number of [`Model::constraints`] read before
    /// it (MuJoCo numbers them all in the file's order).
    pub before: usize,
}

/// The file's elements robodyn does not read, by where they sit: for each, how many elements of
/// its kind that robodyn reads come before it in the file.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct UnreadElements {
    /// Tendons among [`Model::tendons`] (none since robodyn reads every spatial path; kept for
    /// snapshots written before).
    pub tendons: Vec<usize>,
    /// Equalities (flex ones, those of unread tendons) among the file's read equalities
    /// ([`Model::constraints`] and [`Model::tendon_equalities`] together, in the file's order).
    pub equalities: Vec<usize>,
}

impl UnreadElements {
    /// MuJoCo's id of the `read`-th element robodyn reads of a kind, `unread` that kind's list:
    /// its place counting the unread elements before it too.
    pub fn mujoco_id(unread: &[usize], read: usize) -> usize {
        read + unread.iter().filter(|&&before| before <= read).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_spring_pulls_back_into_its_dead_band_and_the_damper_resists() {
        let tendon = Tendon {
            name: "t".into(),
            joints: vec![],
            path: vec![],
            length0: 0.0,
            range: None,
            margin: 0.0,
            limit: SolverParameters::default(),
            frictionloss: 0.0,
            friction: SolverParameters::default(),
            stiffness: 10.0,
            spring_length: [0.2, 0.4],
            damping: 2.0,
            actuator_force_range: None,
            armature: 0.0,
            spring_yield: 0.0,
            stiffness_poly: [0.0; 2],
            damping_poly: [0.0; 2],
        };
        assert_eq!(
            tendon.passive_force(tendon.spring_length, 0.1, 0.0, true, true),
            10.0 * 0.1
        );
        assert_eq!(
            tendon.passive_force(tendon.spring_length, 0.3, 0.0, true, true),
            0.0
        );
        assert_eq!(
            tendon.passive_force(tendon.spring_length, 0.5, 0.0, true, true),
            -10.0 * (0.5 - 0.4)
        );
        assert_eq!(
            tendon.passive_force(tendon.spring_length, 0.3, 1.5, true, true),
            -3.0
        );
        assert_eq!(
            tendon.passive_force(tendon.spring_length, 0.5, 1.5, false, false),
            0.0
        );
        // the polynomial terms: −x (k + k₁ x + k₂ x²), −L̇ (b + b₁ |L̇| + b₂ L̇²)
        let tendon = Tendon {
            stiffness_poly: [2.0, 0.5],
            damping_poly: [-0.5, 0.3],
            ..tendon
        };
        let spring = -0.1 * (10.0 + 2.0 * 0.1 + 0.5 * 0.01);
        assert!(
            (tendon.passive_force(tendon.spring_length, 0.5, 0.0, true, true) - spring).abs()
                < 1e-15
        );
        let damper = 1.5 * (2.0 - 0.5 * 1.5 + 0.3 * 2.25);
        assert!(
            (tendon.passive_force(tendon.spring_length, 0.3, -1.5, true, true) - damper).abs()
                < 1e-15
        );
        // the damper's slope: its force's derivative in L̇
        for rate in [-1.5, 0.7] {
            let force = |r: f64| tendon.passive_force(tendon.spring_length, 0.3, r, false, true);
            let slope = (force(rate + 1e-6) - force(rate - 1e-6)) / 2e-6;
            assert!((tendon.damping_slope(rate) - slope).abs() < 1e-8, "{rate}");
        }
    }
}
