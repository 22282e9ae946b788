//! Convex shapes by their support functions: an ellipsoid against a plane, and the pairs MuJoCo
//! hands to its general convex collider (an ellipsoid against anything, a capsule against a
//! cylinder, cylinders against cylinders and boxes).
//!
//! References: MuJoCo's documentation, "Computation", §Collision detection (Convex collisions;
//! Multiple contacts), whose native pipeline and single-shot multi-contact these contacts
//! reproduce (read to understand, written anew here); the distance and penetration queries of
//! [`super::gjk`]; I. E. Sutherland, G. W. Hodgman, "Reentrant polygon clipping", CACM 17(1),
//! 1974; G. T. Toussaint, "Solving geometric problems with the rotating calipers", 1983.
//!
//! A shape is its support function `S(d)`, the point farthest along d (exact for cylinders and
//! boxes); a margin m grows each shape of the pair by m/2 along d. The pipeline:
//! - spheres, capsules and margins first: GJK measures the distance between the cores (a
//!   sphere's centre, a capsule's segment, a shape without its margin), which, less the radii
//!   and margins, is the contact's distance when positive;
//! - otherwise GJK finds the shapes overlapping and EPA the penetration depth and its witness
//!   points `x₁ ∈ A`, `x₂ ∈ B`;
//! - a cylinder, a box or a capsule may touch along a face or an edge: when the features the
//!   witness points lie on (read off the support points' tags) are two nearly parallel faces,
//!   or an edge nearly in a face, one is clipped against the other and the clipped polygon's
//!   vertices become the contacts (a cylinder's cap is a 16-gon; at most 4 contacts, the
//!   polygon's largest quadrilateral; 2 with a capsule);
//! - a contact is at `(x₁ + x₂)/2`, normal `(x₁ − x₂)/|x₁ − x₂|`, distance the signed gap.
//!
//! Two polytopes without margins (boxes, meshes, a height field's prisms:
//! [`height_field_convex`]) are searched as MuJoCo's "discrete" geoms: GJK and EPA to exact
//! convergence, EPA stopping at a support point whose corners it has met before.

use super::gjk::{self, Convex, Query};
use super::hull::ConvexHull;
use super::{Placed, Touch};
use crate::spatial::{Mat3, Vec3};
use crate::visual::Shape;
use manifold::manifold;
pub use prisms::height_field_convex;

mod manifold;
mod prisms;
#[cfg(test)]
mod tests;

/// MuJoCo's `ccd_tolerance`.
const TOLERANCE: f64 = 1e-6;
/// MuJoCo's `ccd_iterations`.
const ITERATIONS: usize = 35;
/// `u·v`, summed left to right.
#[inline]
fn dot(u: &Vec3, v: &Vec3) -> f64 {
    u.x * v.x + u.y * v.y + u.z * v.z
}

/// `v/|v|`, or x when `|v|` is below [`gjk::TINY`].
fn unit_or_x(v: &Vec3) -> Vec3 {
    let length = dot(v, v).sqrt();
    if length < gjk::TINY {
        Vec3::x()
    } else {
        v * (1.0 / length)
    }
}

/// The support functions: the shapes, and the cores GJK measures first; a height field's prism
/// by its corners (0–2 on its base, 3–5 on the surface above them).
#[derive(Debug, Clone, Copy)]
enum Kind<'a> {
    Point,
    Segment { half_length: f64 },
    Sphere { radius: f64 },
    Capsule { radius: f64, half_length: f64 },
    Ellipsoid { radii: Vec3 },
    Cylinder { radius: f64, half_length: f64 },
    Cuboid { half_extents: Vec3 },
    Mesh { hull: &'a ConvexHull },
    Prism { corners: &'a [Vec3; 6] },
}

/// A placed convex shape, grown by `inflation` along every support direction.
#[derive(Debug, Clone, Copy)]
struct Body<'a> {
    kind: Kind<'a>,
    rotation: Mat3,
    position: Vec3,
    inflation: f64,
}

impl<'a> Body<'a> {
    /// The shape as a support function (`None`: a plane, or a mesh without its hull).
    fn new(placed: &Placed<'a>) -> Option<Self> {
        let kind = match *placed.shape {
            Shape::Sphere { radius } => Kind::Sphere { radius },
            Shape::Capsule {
                radius,
                half_length,
            } => Kind::Capsule {
                radius,
                half_length,
            },
            Shape::Ellipsoid { radii } => Kind::Ellipsoid { radii },
            Shape::Cylinder {
                radius,
                half_length,
            } => Kind::Cylinder {
                radius,
                half_length,
            },
            Shape::Box { half_extents } => Kind::Cuboid { half_extents },
            Shape::Mesh {
                hull: Some(ref hull),
                ..
            } => Kind::Mesh { hull },
            Shape::Plane { .. } | Shape::Mesh { hull: None, .. } | Shape::HeightField { .. } => {
                return None
            }
        };
        Some(Body {
            kind,
            rotation: placed.rotation,
            position: placed.position,
            inflation: 0.0,
        })
    }

    /// `Rᵀ d`: a world direction in the shape's frame.
    fn local_of(&self, d: &Vec3) -> Vec3 {
        let r = &self.rotation;
        Vec3::new(
            r[(0, 0)] * d.x + r[(1, 0)] * d.y + r[(2, 0)] * d.z,
            r[(0, 1)] * d.x + r[(1, 1)] * d.y + r[(2, 1)] * d.z,
            r[(0, 2)] * d.x + r[(1, 2)] * d.y + r[(2, 2)] * d.z,
        )
    }

    /// `R l`: a vector of the shape's frame in the world.
    fn turn(&self, l: &Vec3) -> Vec3 {
        let r = &self.rotation;
        Vec3::new(
            r[(0, 0)] * l.x + r[(0, 1)] * l.y + r[(0, 2)] * l.z,
            r[(1, 0)] * l.x + r[(1, 1)] * l.y + r[(1, 2)] * l.z,
            r[(2, 0)] * l.x + r[(2, 1)] * l.y + r[(2, 2)] * l.z,
        )
    }

    /// `R l + c`: a point of the shape's frame in the world.
    fn world_of(&self, l: &Vec3) -> Vec3 {
        self.turn(l) + self.position
    }

    /// Its axis `k` in the world.
    fn axis(&self, k: usize) -> Vec3 {
        self.rotation.column(k).into_owned()
    }
}

impl Convex for Body<'_> {
    /// The support point along `d`; the tag is a box's corner (bit k: +x_k), a cylinder's cap
    /// (0 top, 1 bottom) or a mesh's corner (its index in the hull).
    fn support(&self, d: &Vec3) -> (Vec3, i32) {
        let (point, tag) = match self.kind {
            Kind::Point => (self.position, -1),
            Kind::Segment { half_length } => {
                let axis = self.axis(2);
                let end = if dot(&axis, d) >= 0.0 {
                    half_length
                } else {
                    -half_length
                };
                (axis * end + self.position, -1)
            }
            Kind::Sphere { radius } => (d * radius + self.position, -1),
            Kind::Capsule {
                radius,
                half_length,
            } => {
                // the sphere's support, moved to the end of the segment along d
                let l = self.local_of(d);
                let mut s = l * radius;
                s.z += if l.z >= 0.0 {
                    half_length
                } else {
                    -half_length
                };
                (self.world_of(&s), -1)
            }
            Kind::Ellipsoid { radii } => {
                // s = D u / |u| with u = D l, D = diag(radii)
                let u = self.local_of(d).component_mul(&radii);
                let square = dot(&u, &u);
                if square < gjk::TINY * gjk::TINY {
                    return (self.axis(0) * radii.x + self.position, -1);
                }
                let inverse = 1.0 / square.sqrt();
                let s = Vec3::new(
                    u.x * (inverse * radii.x),
                    u.y * (inverse * radii.y),
                    u.z * (inverse * radii.z),
                );
                (self.world_of(&s), -1)
            }
            Kind::Cylinder {
                radius,
                half_length,
            } => {
                // the rim point of the cap facing d
                let l = self.local_of(d);
                let across = l.x * l.x + l.y * l.y;
                let scale = if across >= gjk::TINY * gjk::TINY {
                    radius / across.sqrt()
                } else {
                    0.0
                };
                let top = l.z >= 0.0;
                let z = if top { half_length } else { -half_length };
                let s = Vec3::new(scale * l.x, scale * l.y, z);
                (self.world_of(&s), if top { 0 } else { 1 })
            }
            Kind::Cuboid { half_extents } => {
                let l = self.local_of(d);
                let mut s = half_extents;
                let mut corner = 0;
                for k in 0..3 {
                    if l[k] < 0.0 || l[k].is_nan() {
                        s[k] = -s[k];
                    }
                    if s[k] > 0.0 {
                        corner |= 1 << k;
                    }
                }
                (self.world_of(&s), corner)
            }
            Kind::Mesh { hull } => {
                let (s, corner) = hull.support(&self.local_of(d));
                (self.world_of(&s), corner as i32)
            }
            Kind::Prism { corners } => {
                // of the base corners when d points down, else of the surface's: the first
                // farthest along d
                let l = self.local_of(d);
                let face = if l.z < 0.0 {
                    &corners[..3]
                } else {
                    &corners[3..]
                };
                let mut best = 0;
                for k in 1..3 {
                    if dot(&face[k], &l) > dot(&face[best], &l) {
                        best = k;
                    }
                }
                (self.world_of(&face[best]), -1)
            }
        };
        if self.inflation > 0.0 {
            (point + d * self.inflation, tag)
        } else {
            (point, tag)
        }
    }

    /// The origin; a prism's corners' mean.
    fn centre(&self) -> Vec3 {
        match self.kind {
            Kind::Prism { corners } => {
                let sum = corners.iter().fold(Vec3::zeros(), |sum, c| sum + c);
                self.world_of(&(sum * (1.0 / 6.0)))
            }
            _ => self.position,
        }
    }
}

/// A contact of the pipeline: signed distance and the witness points on A and B.
#[derive(Debug, Clone, Copy, Default)]
struct Witness {
    distance: f64,
    points: [Vec3; 2],
}

/// Up to four contacts of one pair.
#[derive(Debug, Clone, Copy, Default)]
struct Manifold {
    witnesses: [Witness; 4],
    len: usize,
}

impl Manifold {
    fn push(&mut self, witness: Witness) {
        self.witnesses[self.len] = witness;
        self.len += 1;
    }

    fn as_slice(&self) -> &[Witness] {
        &self.witnesses[..self.len]
    }
}

/// Moves witness points out along `n` by the amounts their shapes were shrunk:
/// `x₁ += r₁ n`, `x₂ −= r₂ n`, `d −= r₁ + r₂`.
fn inflate(witnesses: &mut [Witness], grow: [f64; 2], n: &Vec3) {
    if grow == [0.0, 0.0] {
        return;
    }
    for witness in witnesses {
        witness.points[0] += n * grow[0];
        witness.points[1] += n * -grow[1];
        witness.distance -= grow[0] + grow[1];
    }
}

/// How many contacts a pair may have: four between cylinders, boxes and meshes, two for a
/// capsule against one of them, one otherwise.
fn contact_budget(a: &Body, b: &Body) -> usize {
    let flat = |body: &Body| {
        matches!(
            body.kind,
            Kind::Cylinder { .. } | Kind::Cuboid { .. } | Kind::Mesh { .. }
        )
    };
    let capsule = |body: &Body| matches!(body.kind, Kind::Capsule { .. });
    if flat(a) && flat(b) {
        4
    } else if (capsule(a) && flat(b)) || (flat(a) && capsule(b)) {
        2
    } else {
        1
    }
}

/// The contacts of `a` and `b` grown by `margin`/2 each (MuJoCo's `mjc_ccd`), distances of the
/// grown shapes.
fn penetration<'a>(a: &Body<'a>, b: &Body<'a>, margin: f64) -> Manifold {
    let polytope = |body: &Body| {
        matches!(
            body.kind,
            Kind::Cuboid { .. } | Kind::Mesh { .. } | Kind::Prism { .. }
        )
    };
    let query = Query {
        tolerance: TOLERANCE,
        iterations: ITERATIONS,
        cutoff: 0.0,
        discrete: margin == 0.0 && polytope(a) && polytope(b),
    };
    let budget = contact_budget(a, b);
    let mut found = Manifold::default();
    let start = [a.centre(), b.centre()];
    let rounded = |body: &Body| matches!(body.kind, Kind::Sphere { .. } | Kind::Capsule { .. });
    if rounded(a) || rounded(b) || margin > 0.0 {
        // the cores' distance: spheres as points, capsules as segments, margins left out
        let core = |body: &Body<'a>| {
            let mut core = *body;
            let mut grow = 0.5 * margin;
            match body.kind {
                Kind::Sphere { radius } => {
                    core.kind = Kind::Point;
                    grow += radius;
                }
                Kind::Capsule {
                    radius,
                    half_length,
                } => {
                    core.kind = Kind::Segment { half_length };
                    grow += radius;
                }
                _ => {}
            }
            (core, grow)
        };
        let (core_a, grow_a) = core(a);
        let (core_b, grow_b) = core(b);
        let shallow = Query {
            cutoff: grow_a + grow_b,
            ..query
        };
        let proximity = gjk::gjk(&core_a, &core_b, start, &shallow);
        if proximity.distance > TOLERANCE {
            // apart or shallow: grow the cores back along the line of their nearest points
            let mut witness = Witness {
                distance: proximity.distance,
                points: proximity.witness,
            };
            let n = unit_or_x(&(witness.points[1] - witness.points[0]));
            inflate(std::slice::from_mut(&mut witness), [grow_a, grow_b], &n);
            if witness.distance <= 0.0 {
                found.push(witness);
                if witness.distance < 0.0 && budget > 1 && proximity.len > 0 {
                    let simplex = &proximity.simplex[..proximity.len];
                    manifold(a, b, margin, simplex, &witness.points, budget, &mut found);
                }
            }
            return found;
        }
    }
    // overlapping: GJK to a simplex around the origin, EPA for the depth
    let (mut a, mut b) = (*a, *b);
    a.inflation = 0.5 * margin;
    b.inflation = 0.5 * margin;
    let proximity = gjk::gjk(&a, &b, start, &query);
    if proximity.distance > TOLERANCE || proximity.len < 2 || proximity.separated {
        return found;
    }
    if let Some(deepest) = gjk::epa(&a, &b, &proximity, &query) {
        let witness = Witness {
            distance: deepest.distance,
            points: deepest.witness,
        };
        found.push(witness);
        if budget > 1 {
            manifold(
                &a,
                &b,
                margin,
                &deepest.face,
                &witness.points,
                budget,
                &mut found,
            );
        }
    }
    found
}

/// Plane `first` against an ellipsoid `second`: the ellipsoid's support point along −n. Meshes
/// are not handled here yet (they give no touches).
pub fn plane_convex(first: &Placed, second: &Placed, margin: f64, touches: &mut Vec<Touch>) {
    let Some(body) = Body::new(second) else {
        return;
    };
    let normal = first.axis(2);
    let (deepest, _) = body.support(&(normal * -1.0));
    let distance = dot(&normal, &(deepest - first.position));
    if distance > margin {
        return;
    }
    touches.push(Touch::new(
        distance,
        normal * (distance * -0.5) + deepest,
        normal,
    ));
}

/// Plane `first` against a mesh `second`: the hull's corner deepest below the plane, then the
/// other corners within the margin of the face at that corner most opposed to the plane's
/// normal n. Of more than four, the deepest and the three spread the most: the farthest from
/// it, then the farthest from the line of those two, then the farthest from the lines joining
/// the third to the other two. Each contact is at its corner v moved halfway to the plane:
/// `d = n·(v − o)`, `p = v − (d/2) n`.
pub fn plane_mesh(first: &Placed, second: &Placed, margin: f64, touches: &mut Vec<Touch>) {
    let Some(body) = Body::new(second) else {
        return;
    };
    let Kind::Mesh { hull } = body.kind else {
        return;
    };
    let normal = first.axis(2);
    let local_normal = body.local_of(&normal);
    let (lowest, deepest) = hull.support(&(local_normal * -1.0));
    let touch = |v: Vec3| {
        let distance = dot(&normal, &(v - first.position));
        Touch::new(distance, normal * (distance * -0.5) + v, normal)
    };
    let corner = body.world_of(&lowest);
    let first_touch = touch(corner);
    if first_touch.distance > margin {
        return;
    }
    touches.push(first_touch);
    // the face at the deepest corner turned most against the normal (the first of equals)
    let Some(face) = hull
        .faces_at(deepest)
        .iter()
        .copied()
        .fold(None, |best, f| {
            let facing = dot(&hull.normals[f], &local_normal);
            match best {
                Some((top, _)) if facing >= top => best,
                _ => Some((facing, f)),
            }
        })
    else {
        return;
    };
    let candidates = || {
        hull.face(face.1)
            .iter()
            .filter(move |&&c| c != deepest)
            .map(|&c| body.world_of(&hull.vertices[c]))
            .filter(|v| dot(&normal, &(v - first.position)) <= margin)
    };
    if candidates().count() <= 3 {
        touches.extend(candidates().map(touch));
        return;
    }
    // the first candidate of largest positive `measure`, not one already `taken`
    let farthest = |measure: &dyn Fn(&Vec3) -> f64, taken: &[Vec3]| {
        candidates()
            .filter(|v| !taken.contains(v))
            .fold(None, |best: Option<(f64, Vec3)>, v| {
                let m = measure(&v);
                match best {
                    Some((top, _)) if m <= top => best,
                    _ if m > 0.0 => Some((m, v)),
                    _ => best,
                }
            })
            .map(|(_, v)| v)
    };
    let from_line = |a: Vec3, b: Vec3| move |v: &Vec3| (v - a).cross(&(b - a)).norm();
    let Some(second) = farthest(&|v| (v - corner).norm(), &[]) else {
        return;
    };
    touches.push(touch(second));
    let Some(third) = farthest(&from_line(corner, second), &[second]) else {
        return;
    };
    touches.push(touch(third));
    let (to_first, to_second) = (from_line(third, corner), from_line(third, second));
    let spread = |v: &Vec3| to_first(v).max(to_second(v));
    if let Some(fourth) = farthest(&spread, &[second, third]) {
        touches.push(touch(fourth));
    }
}

/// Two convex shapes (see the module's header): primitives, and meshes by their hulls.
pub fn convex_convex(first: &Placed, second: &Placed, margin: f64, touches: &mut Vec<Touch>) {
    let (Some(a), Some(b)) = (Body::new(first), Body::new(second)) else {
        return;
    };
    push_touches(&a, &b, margin, touches);
}

/// The contacts of `a` and `b` within `margin`, into `touches`.
fn push_touches(a: &Body, b: &Body, margin: f64, touches: &mut Vec<Touch>) {
    let found = penetration(a, b, margin);
    let witnesses = found.as_slice();
    // the contacts exist when the deepest of them overlaps (distances of the grown shapes)
    if !witnesses.iter().any(|w| w.distance < 0.0) {
        return;
    }
    for witness in witnesses {
        let [x1, x2] = witness.points;
        touches.push(Touch::new(
            margin + witness.distance,
            (x1 + x2) * 0.5,
            unit_or_x(&(x1 - x2)),
        ));
    }
}
