//! MuJoCo's soft constraint model. So far: the parameters a contact between two geoms takes, and
//! ([`impedance`]) how soft a constraint row is.
//!
//! Reference: MuJoCo's documentation, "Modeling", §Contact parameters, and "Computation",
//! §Contact. A contact of an explicit pair takes the pair's parameters as they are. A contact
//! of two geoms found by MuJoCo's filters (a "dynamic" pair) mixes theirs: when one geom's
//! `priority` is higher, its `condim`, `friction`, `solref` and `solimp` are used as they are;
//! otherwise
//! ```text
//!   condim   = max(condim₁, condim₂)
//!   friction = max(friction₁, friction₂)  per term, (sliding, torsional, rolling) → (s, s, t, r, r)
//!   mix      = solmix₁ / (solmix₁ + solmix₂)      (½ when both are below 1e-15, 0 or 1 when one is)
//!   solref   = mix solref₁ + (1 − mix) solref₂    when both time constants are positive,
//!              min(solref₁, solref₂) per term     otherwise (direct stiffness and damping)
//!   solimp   = mix solimp₁ + (1 − mix) solimp₂
//! ```
//! and whatever the priorities the margins and the gaps add: `margin = margin₁ + margin₂`,
//! `gap = gap₁ + gap₂` (MuJoCo ≥ 3.5). With the `override` flag enabled, every contact's margin,
//! `solref` (its friction rows' too), `solimp` and friction are the `<option>`'s `o_margin`,
//! `o_solref`, `o_solimp` and `o_friction`. Every friction term is at least [`MIN_FRICTION`].

mod cost;
pub mod dynamics;

/// Below this a width, a mass, a regulariser, an impratio or a speed counts as zero (MuJoCo's
/// `mjMINVAL`).
pub(crate) const TINY: f64 = 1e-15;

pub mod equality;
pub mod impedance;
pub mod inertia;
mod pattern;
pub mod rows;
pub mod simulate;
pub mod solver;
pub mod step;
pub mod tendons;
pub mod weights;
pub mod wrap;

use crate::model::{ContactPair, Geom, Model, SolverParameters};

/// The smallest friction coefficient MuJoCo uses (its `mjMINMU`).
pub const MIN_FRICTION: f64 = 1e-5;
/// Below this a `solmix` weight counts as zero (MuJoCo's `mjMINVAL`).
const MIN_SOLMIX: f64 = 1e-15;

/// The parameters a contact takes (MuJoCo's `mjContact` fields of the same names).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactParameters {
    /// 1, 3, 4 or 6.
    pub condim: usize,
    /// Sliding ×2, torsional, rolling ×2.
    pub friction: [f64; 5],
    /// The normal's solver parameters.
    pub solver: SolverParameters,
    /// The friction rows' `solref` ([0, 0]: the normal's).
    pub solreffriction: [f64; 2],
    /// The distance (m) within which the contact is active (MuJoCo's `includemargin`).
    pub margin: f64,
    /// The part of the margin that is not (m).
    pub gap: f64,
}

/// The parameters of a contact between geoms `first` and `second`: their explicit pair's, if
/// they form one, else their mixture.
pub fn contact_parameters(model: &Model, first: usize, second: usize) -> ContactParameters {
    let explicit = model
        .contact_pairs
        .iter()
        .find(|p| p.geoms == (first, second) || p.geoms == (second, first));
    let parameters = match explicit {
        Some(pair) => pair_parameters(pair),
        None => mixed_parameters(&model.geoms[first], &model.geoms[second]),
    };
    overridden(model, parameters)
}

/// An explicit pair's parameters, as they are.
fn pair_parameters(pair: &ContactPair) -> ContactParameters {
    ContactParameters {
        condim: pair.contact.condim,
        friction: pair.friction,
        solver: pair.contact.solver,
        solreffriction: pair.solreffriction,
        margin: pair.contact.margin,
        gap: pair.contact.gap,
    }
}

/// Two geoms' parameters mixed as the module's header states.
fn mixed_parameters(one: &Geom, other: &Geom) -> ContactParameters {
    let (margin, gap) = (
        one.contact.margin + other.contact.margin,
        one.contact.gap + other.contact.gap,
    );
    let spread = |f: [f64; 3]| [f[0], f[0], f[1], f[2], f[2]];
    // the higher priority's parameters, as they are
    if one.priority != other.priority {
        let higher = if one.priority > other.priority {
            one
        } else {
            other
        };
        return ContactParameters {
            condim: higher.contact.condim,
            friction: spread(higher.friction),
            solver: higher.contact.solver,
            solreffriction: [0.0, 0.0],
            margin,
            gap,
        };
    }
    // mix = solmix₁ / (solmix₁ + solmix₂)
    let mix = match (one.solmix >= MIN_SOLMIX, other.solmix >= MIN_SOLMIX) {
        (true, true) => one.solmix / (one.solmix + other.solmix),
        (false, false) => 0.5,
        (false, true) => 0.0,
        (true, false) => 1.0,
    };
    let blend = |a: f64, b: f64| mix * a + (1.0 - mix) * b;
    let (sr1, sr2) = (one.contact.solver.solref, other.contact.solver.solref);
    let solref = if sr1[0] > 0.0 && sr2[0] > 0.0 {
        [blend(sr1[0], sr2[0]), blend(sr1[1], sr2[1])]
    } else {
        [sr1[0].min(sr2[0]), sr1[1].min(sr2[1])]
    };
    let (si1, si2) = (one.contact.solver.solimp, other.contact.solver.solimp);
    let friction = std::array::from_fn(|k| one.friction[k].max(other.friction[k]));
    ContactParameters {
        condim: one.contact.condim.max(other.contact.condim),
        friction: spread(friction),
        solver: SolverParameters {
            solref,
            solimp: std::array::from_fn(|k| blend(si1[k], si2[k])),
        },
        solreffriction: [0.0, 0.0],
        margin,
        gap,
    }
}

/// The `<option>` override where the `override` flag is on, and friction at least
/// [`MIN_FRICTION`].
fn overridden(model: &Model, mut parameters: ContactParameters) -> ContactParameters {
    let options = &model.options;
    if options.flag("override") {
        parameters.margin = options.override_margin;
        parameters.solver = options.override_solver;
        parameters.solreffriction = options.override_solver.solref;
        parameters.friction = options.override_friction;
    }
    for term in &mut parameters.friction {
        *term = term.max(MIN_FRICTION);
    }
    parameters
}
