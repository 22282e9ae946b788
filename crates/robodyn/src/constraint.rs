//! Constraints on a robot: what is held, its rows, and the frame its forces are expressed in.
//!
//! A constraint is a set of rows `φ(q) = 0` whose velocity form is `J(q) q̇ = 0` and whose
//! acceleration form is `J q̈ + γ = 0`, with the drift `γ = J̇ q̇`. Its forces λ are what it exerts
//! on the robot: `M q̈ + h = τ + Jᵀ λ` (Pinocchio's `lambda_c`). The kinds:
//!
//! - [`ConstraintKind::Point`]: a point of one frame held to the world or to a point of another
//!   frame, 3 rows: the velocity of the first point minus that of the second.
//! - [`ConstraintKind::Frame`]: a frame held to the world or to another frame, 6 rows `[linear;
//!   angular]` (the velocity of its origin and its angular velocity, minus the second's), or the
//!   rows its mask keeps.
//! - [`ConstraintKind::Coupling`]: one joint's coordinate a polynomial of another's (MuJoCo's joint
//!   equality, a URDF mimic), 1 row.
//! - [`ConstraintKind::Distance`]: two points at a fixed distance, 1 row.
//!
//! Rows of points and frames are in world axes ([`ConstraintReference::World`], Pinocchio's
//! LOCAL_WORLD_ALIGNED) or in the axes of the first frame ([`ConstraintReference::Local`]); their
//! forces are expressed in the same axes, applied at the first point. `rows.rs` evaluates them.

mod derivatives;
mod rows;

pub(crate) use derivatives::{
    add_body_forces, differentiate_rows, RowDerivatives, RowLevel, RowScratch,
};
pub(crate) use rows::{evaluate, polynomial_at, BodyMotion, ConstraintRows};

use crate::error::{Error, Result};
use crate::model::Model;
use crate::spatial::Transform;
use std::ops::Range;

/// The axes a point or frame constraint's rows (and forces) are expressed in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum ConstraintReference {
    /// World axes at the constrained point (Pinocchio's LOCAL_WORLD_ALIGNED).
    World,
    /// The axes of the first frame (with its placement), at the constrained point.
    Local,
}

/// Where a point or frame constraint attaches: a frame of the model (or the world) and the
/// constraint frame's placement in it.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Attachment {
    /// The model frame (`Model::frames` index), or `None` for the world.
    pub frame: Option<usize>,
    /// `X_{c←frame}`: the constraint frame in that frame (for a point, only its translation
    /// counts: the point's offset).
    pub placement: Transform,
}

impl Attachment {
    /// The origin of frame `frame`.
    pub fn at_frame(frame: usize) -> Self {
        Attachment {
            frame: Some(frame),
            placement: Transform::default(),
        }
    }
}

/// What a constraint holds.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum ConstraintKind {
    /// The point `first` held to the point `second`, or, with `second` `None`, to the world
    /// where it is (the position error is then zero). 3 rows.
    Point {
        /// The point held.
        first: Attachment,
        /// What it is held to.
        second: Option<Attachment>,
    },
    /// The frame `first` held to `second` (or to the world where it is). The rows `[linear x, y,
    /// z; angular x, y, z]` that `mask` keeps.
    Frame {
        /// The frame held.
        first: Attachment,
        /// What it is held to.
        second: Option<Attachment>,
        /// The rows kept, in the order `[linear; angular]`.
        mask: [bool; 6],
    },
    /// `q_f − q_f,ref = Σ_k c_k (q_l − q_l,ref)^k` between two one-coordinate joints (bodies
    /// `follower` and `leader`; a hinge may drive a slide, as a rack and pinion does, the
    /// coefficients then carrying the units), or, without a leader, `q_f − q_f,ref = c_0` (the
    /// joint held). 1 row.
    Coupling {
        /// The body whose joint follows.
        follower: usize,
        /// The body whose joint leads, or `None`: the follower is held at `q_f,ref + c_0`.
        leader: Option<usize>,
        /// `c_0 … c_4` (MuJoCo's `polycoef`; a ratio r and offset o are `[o, r, 0, 0, 0]`).
        polynomial: [f64; 5],
        /// The coordinates the polynomial is taken about: `(q_f,ref, q_l,ref)`.
        references: (f64, f64),
    },
    /// The points `first` and `second` at distance `length`. 1 row.
    Distance {
        /// One point.
        first: Attachment,
        /// The other.
        second: Attachment,
        /// The distance held (m).
        length: f64,
    },
}

/// One constraint: what it holds and the axes of its rows.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Constraint {
    /// What is held.
    pub kind: ConstraintKind,
    /// The axes of a point or frame constraint's rows (ignored by the others).
    pub reference: ConstraintReference,
}

impl Constraint {
    /// Its number of rows.
    pub fn rows(&self) -> usize {
        match &self.kind {
            ConstraintKind::Point { .. } => 3,
            ConstraintKind::Frame { mask, .. } => mask.iter().filter(|&&kept| kept).count(),
            ConstraintKind::Coupling { .. } | ConstraintKind::Distance { .. } => 1,
        }
    }

    /// The bodies it attaches to or whose joints it couples (the world as 0), up to two.
    pub fn bodies(&self, model: &Model) -> [Option<usize>; 2] {
        let body = |a: &Attachment| a.frame.map_or(0, |f| model.frames[f].body);
        match &self.kind {
            ConstraintKind::Point { first, second }
            | ConstraintKind::Frame { first, second, .. } => {
                [Some(body(first)), second.as_ref().map(body)]
            }
            ConstraintKind::Distance { first, second, .. } => {
                [Some(body(first)), Some(body(second))]
            }
            ConstraintKind::Coupling {
                follower, leader, ..
            } => [Some(*follower), *leader],
        }
    }

    /// Why it does not fit `model` (an unknown frame or joint, a coupled joint of several
    /// coordinates, ...), if it does not; [`ConstraintSet::new`] refuses it with this reason.
    pub fn check(&self, model: &Model) -> std::result::Result<(), String> {
        check_constraint(model, self)
    }

    /// A short description naming its kind and frames or joints, for messages.
    pub fn describe(&self, model: &Model) -> String {
        let frame = |a: &Attachment| match a.frame {
            Some(f) => format!("'{}'", model.frames[f].name),
            None => "the world".to_string(),
        };
        let held_to = |second: &Option<Attachment>| match second {
            Some(a) => frame(a),
            None => "the world".to_string(),
        };
        match &self.kind {
            ConstraintKind::Point { first, second } => {
                format!("PointAnchor({} to {})", frame(first), held_to(second))
            }
            ConstraintKind::Frame { first, second, .. } => {
                format!("FrameAnchor({} to {})", frame(first), held_to(second))
            }
            ConstraintKind::Coupling {
                follower, leader, ..
            } => match leader {
                Some(leader) => format!(
                    "JointCoupling('{}' on '{}')",
                    model.joint_names[*follower], model.joint_names[*leader]
                ),
                None => format!("JointCoupling('{}' held)", model.joint_names[*follower]),
            },
            ConstraintKind::Distance { first, second, .. } => {
                format!("Distance({} to {})", frame(first), frame(second))
            }
        }
    }

    /// The name of row `k` of this constraint: its axis (`x`, `angular z`, …) for messages.
    pub fn row_name(&self, k: usize) -> &'static str {
        const AXES: [&str; 6] = ["x", "y", "z", "angular x", "angular y", "angular z"];
        match &self.kind {
            ConstraintKind::Point { .. } => AXES[k],
            ConstraintKind::Frame { mask, .. } => {
                let axis = (0..6).filter(|&r| mask[r]).nth(k).unwrap_or(0);
                AXES[axis]
            }
            ConstraintKind::Coupling { .. } | ConstraintKind::Distance { .. } => "the row",
        }
    }
}

/// A constraint a model file declares (MJCF `<equality>`): the constraint, and what MuJoCo's
/// soft constraint model reads of it.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ModelConstraint {
    /// Its name in the file (empty when it has none).
    pub name: String,
    /// What it holds (anchors computed at the neutral configuration, MuJoCo's `qpos0`).
    pub constraint: Constraint,
    /// Whether it is enforced (`active`); an inactive one is kept but not held.
    pub active: bool,
    /// MuJoCo's `solref` (time constant, damping ratio) for its soft form.
    pub solref: [f64; 2],
    /// MuJoCo's `solimp` (d₀, d_width, width, midpoint, power) for its soft form.
    pub solimp: [f64; 5],
    /// A weld's `torquescale` (the weight of its rotation rows in the soft form; 1 otherwise).
    pub torquescale: f64,
    /// The file bodies ([`Model::source_bodies`] ids, the world 0) a connect or weld attaches,
    /// whose weights soften its rows in MuJoCo's model (unused by the other kinds).
    #[serde(default)]
    pub bodies: [usize; 2],
}

pub use crate::model::{DEFAULT_SOLIMP, DEFAULT_SOLREF};

impl ModelConstraint {
    /// An active constraint named `name` with MuJoCo's default `solref` and `solimp`.
    pub fn active(name: String, constraint: Constraint) -> Self {
        ModelConstraint {
            name,
            constraint,
            active: true,
            solref: DEFAULT_SOLREF,
            solimp: DEFAULT_SOLIMP,
            torquescale: 1.0,
            bodies: [0, 0],
        }
    }
}

/// Constraints checked against a model, with the first row of each.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintSet {
    constraints: Vec<Constraint>,
    offsets: Vec<usize>,
    rows: usize,
    /// Per constraint, the bodies whose joints its rows reach (the ancestors of its bodies, the
    /// world left out), the deepest first.
    supports: Vec<Vec<usize>>,
    /// The bodies some row reaches, in increasing order (each after its parent).
    support: Vec<usize>,
    /// For each body of `support`, the rows from the first to the last of the constraints that
    /// reach it.
    row_spans: Vec<Range<usize>>,
}

impl ConstraintSet {
    /// Checks each constraint against `model`: its frames and joints exist, a coupling joins two
    /// one-coordinate joints and not a joint to itself, a frame mask keeps a
    /// row, a distance is positive and finite, placements are finite.
    pub fn new(model: &Model, constraints: Vec<Constraint>) -> Result<Self> {
        for (k, constraint) in constraints.iter().enumerate() {
            check_constraint(model, constraint)
                .map_err(|message| invalid(format!("constraints[{k}]: {message}")))?;
        }
        let mut offsets = Vec::with_capacity(constraints.len());
        let mut rows = 0;
        for constraint in &constraints {
            offsets.push(rows);
            rows += constraint.rows();
        }
        let mut reached = vec![false; model.nbodies()];
        let mut supports = Vec::with_capacity(constraints.len());
        for constraint in &constraints {
            let mut own = vec![false; model.nbodies()];
            for mut body in constraint.bodies(model).into_iter().flatten() {
                while body != 0 && !own[body] {
                    own[body] = true;
                    body = model.parent[body];
                }
            }
            let deepest_first: Vec<usize> =
                (1..model.nbodies()).rev().filter(|&i| own[i]).collect();
            for &i in &deepest_first {
                reached[i] = true;
            }
            supports.push(deepest_first);
        }
        let support: Vec<usize> = (1..model.nbodies()).filter(|&i| reached[i]).collect();
        let mut spans = vec![rows..0; model.nbodies()];
        for ((constraint, own), &offset) in constraints.iter().zip(&supports).zip(&offsets) {
            for &i in own {
                spans[i].start = spans[i].start.min(offset);
                spans[i].end = spans[i].end.max(offset + constraint.rows());
            }
        }
        let row_spans = support.iter().map(|&i| spans[i].clone()).collect();
        Ok(ConstraintSet {
            constraints,
            offsets,
            rows,
            supports,
            support,
            row_spans,
        })
    }

    /// The bodies whose joints the rows of constraint `k` reach (the ancestors of its bodies),
    /// the deepest first: J's columns of any other joint are zero in its rows.
    pub fn support_of(&self, k: usize) -> &[usize] {
        &self.supports[k]
    }

    /// The bodies whose joints some row reaches, in increasing order (each after its parent).
    pub fn support(&self) -> &[usize] {
        &self.support
    }

    /// The rows, from the first to the last, of the constraints that reach each body of
    /// [`ConstraintSet::support`] (in its order): J's columns of that body's joint are zero in
    /// the other rows.
    pub fn row_spans(&self) -> &[Range<usize>] {
        &self.row_spans
    }

    /// The constraints.
    pub fn constraints(&self) -> &[Constraint] {
        &self.constraints
    }

    /// The number of rows of all of them.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The first row of constraint `k`.
    pub fn offset(&self, k: usize) -> usize {
        self.offsets[k]
    }

    /// The constraint that row `row` belongs to, and the row within it.
    pub fn row_owner(&self, row: usize) -> (usize, usize) {
        let k = self.offsets.partition_point(|&start| start <= row) - 1;
        (k, row - self.offsets[k])
    }

    /// Names row `row` for a message: `constraints[k] (PointAnchor('foot' to the world)), row y`.
    pub fn describe_row(&self, model: &Model, row: usize) -> String {
        let (k, within) = self.row_owner(row);
        let constraint = &self.constraints[k];
        format!(
            "constraints[{k}] ({}), row {}",
            constraint.describe(model),
            constraint.row_name(within)
        )
    }
}

/// The error for a constraint argument.
fn invalid(message: String) -> Error {
    Error::InvalidValue {
        argument: "constraints".into(),
        message,
    }
}

/// Why `constraint` does not fit `model`, if it does not.
fn check_constraint(model: &Model, constraint: &Constraint) -> std::result::Result<(), String> {
    let attachment = |a: &Attachment| -> std::result::Result<(), String> {
        if let Some(f) = a.frame {
            if f >= model.frames.len() {
                return Err(format!(
                    "expected a frame index below {}, got {f}",
                    model.frames.len()
                ));
            }
        }
        let finite = a.placement.rotation.iter().all(|x| x.is_finite())
            && a.placement.translation.iter().all(|x| x.is_finite());
        if !finite {
            return Err("a placement or offset holds a value that is not finite".into());
        }
        Ok(())
    };
    match &constraint.kind {
        ConstraintKind::Point { first, second } => {
            attachment(first)?;
            second.iter().try_for_each(attachment)
        }
        ConstraintKind::Frame {
            first,
            second,
            mask,
        } => {
            attachment(first)?;
            second.iter().try_for_each(attachment)?;
            if !mask.iter().any(|&kept| kept) {
                return Err("the mask keeps no row: expected at least one True of six".into());
            }
            Ok(())
        }
        ConstraintKind::Distance {
            first,
            second,
            length,
        } => {
            attachment(first)?;
            attachment(second)?;
            if !(length.is_finite() && *length > 0.0) {
                return Err(format!(
                    "expected a positive finite length (m), got {length}"
                ));
            }
            Ok(())
        }
        ConstraintKind::Coupling {
            follower,
            leader,
            polynomial,
            references,
        } => {
            let nbodies = model.nbodies();
            for body in std::iter::once(follower).chain(leader) {
                if *body == 0 || *body >= nbodies {
                    return Err(format!(
                        "expected a joint index from 1 to {}, got {body}",
                        nbodies - 1
                    ));
                }
            }
            let name = |b: &usize| &model.joint_names[*b];
            let f = &model.joints[*follower];
            let one_coordinate = |j: &crate::Joint| j.nv() == 1 && j.nq() == 1;
            if !one_coordinate(f) {
                return Err(format!(
                    "a coupling holds a revolute or prismatic joint, got '{}' ({})",
                    name(follower),
                    f.kind()
                ));
            }
            if let Some(leader) = leader {
                let l = &model.joints[*leader];
                if follower == leader {
                    return Err(format!("joint '{}' is coupled to itself", name(follower)));
                }
                if !one_coordinate(l) {
                    return Err(format!(
                        "a coupling is led by a revolute or prismatic joint, got '{}' ({})",
                        name(leader),
                        l.kind()
                    ));
                }
            }
            let finite = polynomial.iter().all(|c| c.is_finite())
                && references.0.is_finite()
                && references.1.is_finite();
            if !finite {
                return Err(
                    "the ratio, offset or polynomial holds a value that is not finite".into(),
                );
            }
            Ok(())
        }
    }
}
