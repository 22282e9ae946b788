//! Which of a model's geoms may touch.
//!
//! Reference: MuJoCo's documentation, "Computation", §Collision detection. The geom pairs checked
//! for contact are the file's explicit pairs (`<contact><pair>`), always, and every other pair of
//! geoms that passes these filters (MuJoCo's "dynamic" pairs):
//! 1. they move with different bodies (a body without joints moves with its parent: MuJoCo's
//!    weld bodies, robodyn's model bodies), so two geoms fixed to the world never touch;
//! 2. neither moving body is the other's parent, unless the `filterparent` flag is disabled;
//! 3. the file does not exclude their two bodies (`<contact><exclude>`, by the file's bodies);
//! 4. the `contype` of one shares a bit with the `conaffinity` of the other;
//! 5. they are not an explicit pair already (the other geoms of the same two bodies still are).

use crate::model::Model;
use std::collections::{HashMap, HashSet};

/// The pairs of geoms (indices into [`Model::geoms`], the lower first, in increasing order) that
/// MuJoCo would check for contact besides the explicit pairs ([`Model::contact_pairs`]).
pub fn candidate_pairs(model: &Model) -> Vec<(usize, usize)> {
    let bodies = &model.source_bodies;
    // the parent of each moving model body: that of the file body that moves it first
    let mut parent_body: HashMap<usize, usize> = HashMap::new();
    for body in bodies {
        let parent = bodies[body.parent].body;
        if parent != body.body {
            parent_body.entry(body.body).or_insert(parent);
        }
    }
    let unordered = |a: usize, b: usize| (a.min(b), a.max(b));
    let excluded: HashSet<(usize, usize)> = model
        .contact_excludes
        .iter()
        .map(|e| unordered(e.first, e.second))
        .collect();
    let explicit: HashSet<(usize, usize)> = model
        .contact_pairs
        .iter()
        .map(|p| unordered(p.geoms.0, p.geoms.1))
        .collect();
    let filter_parent = model.options.flag("filterparent");
    let mut pairs = Vec::new();
    for (i, one) in model.geoms.iter().enumerate() {
        for (j, other) in model.geoms.iter().enumerate().skip(i + 1) {
            // 1: different moving bodies
            if one.body == other.body {
                continue;
            }
            // 2: not parent and child, the world aside
            let is_parent = |a: usize, b: usize| parent_body.get(&a) == Some(&b);
            let moving = one.body != 0 && other.body != 0;
            if filter_parent
                && moving
                && (is_parent(one.body, other.body) || is_parent(other.body, one.body))
            {
                continue;
            }
            // 3 and 5: neither excluded nor already an explicit pair
            let source = unordered(one.source_body, other.source_body);
            if excluded.contains(&source) || explicit.contains(&(i, j)) {
                continue;
            }
            // 4: a bit offered by one is accepted by the other
            if one.contype & other.conaffinity == 0 && other.contype & one.conaffinity == 0 {
                continue;
            }
            pairs.push((i, j));
        }
    }
    pairs
}
