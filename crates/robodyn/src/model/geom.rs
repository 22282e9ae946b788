//! The shapes that touch (MJCF geoms as collision shapes), what each says of its contacts, and
//! the file's explicit contact pairs and exclusions (`<contact>`).
//!
//! Reference: MuJoCo's documentation, "XML Reference", §geom and §contact, and "Computation",
//! §Contact parameters (how two geoms' parameters combine). The defaults are MuJoCo's.

use super::options::SolverParameters;
use crate::spatial::{Transform, Vec3};
use crate::visual::Shape;

/// MuJoCo's default `friction` of a geom: sliding, torsional, rolling.
pub const DEFAULT_GEOM_FRICTION: [f64; 3] = [1.0, 0.005, 0.0001];
/// MuJoCo's default `friction` of a contact pair: sliding ×2, torsional, rolling ×2.
pub const DEFAULT_PAIR_FRICTION: [f64; 5] = [1.0, 1.0, 0.005, 0.0001, 0.0001];
/// The contact dimensions MuJoCo accepts: normal only, with sliding friction, with torsional
/// friction too, with rolling friction too.
pub const CONTACT_DIMENSIONS: [usize; 4] = [1, 3, 4, 6];

/// What a geom or pair says of the contacts it makes.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactParameters {
    /// `condim`: 1, 3, 4 or 6 (see [`CONTACT_DIMENSIONS`]).
    pub condim: usize,
    /// `solref` and `solimp` of the contact's normal (and, for a geom, its friction) rows.
    pub solver: SolverParameters,
    /// `margin`: the distance (m) at which a contact is found.
    pub margin: f64,
    /// `gap`: how much of the margin is not yet active (m).
    pub gap: f64,
}

/// A collision shape attached to a body (an MJCF geom).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Geom {
    /// The geom's `name` (`geom<offset>` when the file gives none).
    pub name: String,
    /// The model body it moves with.
    pub body: usize,
    /// The file's body that holds it: MuJoCo's body id (the world 0, then the bodies in the
    /// file's order). Several of them may move as one model body (a body without joints is merged
    /// into its parent); exclusions and MuJoCo's filters name these.
    pub source_body: usize,
    /// `X_{geom←body}`: its placement on the model body.
    pub placement: Transform,
    /// Its shape, sized as MuJoCo sizes it.
    pub shape: Shape,
    /// `contype`: the bits it offers; two geoms may touch when one's `contype` shares a bit with
    /// the other's `conaffinity`.
    pub contype: i32,
    /// `conaffinity`: the bits it accepts.
    pub conaffinity: i32,
    /// `priority`: of two geoms, the higher one's parameters are used as they are.
    pub priority: i32,
    /// `friction`: sliding, torsional, rolling.
    pub friction: [f64; 3],
    /// `solmix`: its weight when its solver parameters are mixed with another geom's.
    pub solmix: f64,
    /// `condim`, `solref`, `solimp`, `margin`, `gap`.
    pub contact: ContactParameters,
    /// Where the file declares it (file, element and line), for messages.
    pub element: String,
}

/// A pair of geoms the file asks to be checked for contact whatever their bits and bodies
/// (`<contact><pair>`), with the contact parameters used as they are.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactPair {
    /// The pair's `name` (empty when the file gives none).
    pub name: String,
    /// The two geoms (indices into [`crate::Model::geoms`]).
    pub geoms: (usize, usize),
    /// `friction`: sliding ×2, torsional, rolling ×2.
    pub friction: [f64; 5],
    /// `condim`, `solref`, `solimp`, `margin`, `gap`.
    pub contact: ContactParameters,
    /// `solreffriction`: the friction rows' `solref` ([0, 0]: the normal's).
    pub solreffriction: [f64; 2],
}

/// One of the file's bodies (MuJoCo's body), which a model body may merge with others.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SourceBody {
    /// Its `name` (`body<offset>` when the file gives none; the world's is "world").
    pub name: String,
    /// Its parent's MuJoCo body id (the world's own: 0).
    pub parent: usize,
    /// The model body it moves with (0: welded to the world).
    pub body: usize,
    /// Its own mass (kg), before any merging.
    pub mass: f64,
    /// Its own centre of mass (its frame's origin when massless) in the frame of `body`
    /// (MuJoCo's `xipos` there).
    pub com: Vec3,
    /// Whether MuJoCo calls it a simple body without rotations (`body_simple == 2`): only
    /// axis-aligned slides at its origin, its inertia frame its own, no child, and its parent the
    /// world or a jointless child of it. Its weights are then 1/m.
    #[serde(default)]
    pub simple: bool,
    /// The fraction of its weight held up by a force at its centre of mass (MJCF `gravcomp`,
    /// MuJoCo's gravity compensation; 0: none).
    #[serde(default)]
    pub gravcomp: f64,
}

/// Two of the file's bodies whose geoms never touch (`<contact><exclude>`), as
/// [`Geom::source_body`] ids.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct ContactExclude {
    /// One body.
    pub first: usize,
    /// The other.
    pub second: usize,
}

/// A joint's limit and dry friction in MuJoCo's soft constraint model (MJCF `solreflimit`,
/// `solimplimit`, `margin`, `solreffriction`, `solimpfriction`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct JointSoftness {
    /// The limit's solver parameters.
    pub limit: SolverParameters,
    /// The distance (rad or m) from a limit at which it becomes active.
    pub margin: f64,
    /// The dry friction's solver parameters.
    pub friction: SolverParameters,
    /// A limited ball joint's largest angle (rad): MuJoCo's `max(range)`.
    #[serde(default)]
    pub cone_limit: Option<f64>,
}

impl Default for JointSoftness {
    fn default() -> Self {
        JointSoftness {
            limit: SolverParameters::default(),
            margin: 0.0,
            friction: SolverParameters::default(),
            cone_limit: None,
        }
    }
}
