//! Two boxes.
//!
//! Reference: MuJoCo's documentation, "Computation", §Collision detection; the contacts are the
//! ones MuJoCo 4.0's box–box collider generates (`mjc_BoxBox`). Two boxes are separated or not
//! by the separating axis theorem (Gottschalk, Lin & Manocha, "OBBTree", 1996; Ericson,
//! *Real-Time Collision Detection*, §4.4.1) on fifteen axes: the three face normals of each box
//! and the nine cross products of an edge of one with an edge of the other. The axis of least
//! penetration decides the contact: for an edge pair, one point midway between the two edges;
//! for a face, the face of the other box most opposed to it clipped to it (Sutherland & Hodgman,
//! "Reentrant polygon clipping", 1974), a point at each vertex left within the margin. Near ties
//! go to the faces, whose several points hold a box at rest.

use super::boxes::{half_extents_of, sign_of, TINY};
use super::{Placed, Touch};
use crate::spatial::{Mat3, Vec3};
/// Rounding slack of the separation tests, per unit of the two boxes' summed half extents: a
/// pair overlapping by less than the rounding of its own supports still touches.
const SEPARATION_SLACK: f64 = 1e-13;
/// `sin²` of the angle below which two edges are parallel and give no axis of their own.
const PARALLEL_SIN2: f64 = 1e-16;
/// An axis component below which either edge of a box on that side supports it.
const SIGN_AMBIGUITY: f64 = 1e-9;
/// Squared distance, relative to the reference face's size, below which clipped vertices merge.
const DUPLICATE_RADIUS2: f64 = 1e-14;
/// Relative margin by which an edge axis must beat the best face axis.
const EDGE_BIAS: f64 = 1e-6;
/// `|cos|` above which a winning edge axis is nearly the best face axis (about 8°) ...
const FACE_ALIGNMENT: f64 = 0.99;
/// ... and gives way to it unless it separates by more than this fraction of the face's depth.
const FACE_PREFERENCE: f64 = 0.05;
/// Vertices a clipped face can hold (a quadrilateral clipped by four half-planes has at most
/// eight; the rest is room for rounding).
const POLYGON_CAPACITY: usize = 12;

/// A convex polygon in a fixed array.
#[derive(Clone, Copy)]
struct Polygon {
    vertices: [Vec3; POLYGON_CAPACITY],
    count: usize,
}

impl Polygon {
    fn new() -> Self {
        Polygon {
            vertices: [Vec3::zeros(); POLYGON_CAPACITY],
            count: 0,
        }
    }

    fn push(&mut self, vertex: Vec3) {
        if self.count < POLYGON_CAPACITY {
            self.vertices[self.count] = vertex;
            self.count += 1;
        }
    }

    fn vertices(&self) -> &[Vec3] {
        &self.vertices[..self.count]
    }

    /// The part with `sign v[coordinate] ≤ limit` (one Sutherland–Hodgman pass): each vertex
    /// inside, and where an edge strictly crosses the line `b = sign v[coordinate] − limit = 0`,
    /// ```text
    ///   p + (q − p) b_p / (b_p − b_q)
    /// ```
    fn clipped(&self, coordinate: usize, sign: f64, limit: f64) -> Polygon {
        let beyond = |v: &Vec3| sign * v[coordinate] - limit;
        let mut inside = Polygon::new();
        let vertices = self.vertices();
        for (k, p) in vertices.iter().enumerate() {
            let q = &vertices[(k + 1) % vertices.len()];
            let (bp, bq) = (beyond(p), beyond(q));
            if bp <= 0.0 {
                inside.push(*p);
            }
            if (bp < 0.0 && bq > 0.0) || (bp > 0.0 && bq < 0.0) {
                inside.push(p + (q - p) * (bp / (bp - bq)));
            }
        }
        inside
    }
}

/// A candidate separating axis.
#[derive(Debug, Clone, Copy)]
enum Axis {
    /// The normal of the faces across axis `k` of the first box or of the second.
    Face { of_first: bool, k: usize },
    /// `e_i × d_j` (unit, in the first box's frame): the first box's edges along its axis `i`
    /// across the second's along its axis `j` (`d_j` in the first's frame).
    Edges { i: usize, j: usize, unit: Vec3 },
}

/// Two boxes as the first sees them.
struct BoxPair<'a> {
    first: &'a Placed<'a>,
    second: &'a Placed<'a>,
    half1: Vec3,
    half2: Vec3,
    /// The second's axes in the first's frame (the columns): `R₁ᵀ R₂`.
    rotation: Mat3,
    /// The second's centre in the first's frame, and the first's in the second's.
    centre21: Vec3,
    centre12: Vec3,
}

impl BoxPair<'_> {
    /// How far apart the boxes are across the faces normal to axis `k` of the first box (or
    /// of the second): the distance of the centres along it less the two boxes' reaches, the
    /// other's `Σ h_c |u_c|` for the axis `u` in its frame.
    fn face_separation(&self, of_first: bool, k: usize) -> f64 {
        let (centre, own, other) = if of_first {
            (self.centre21, self.half1, self.half2)
        } else {
            (self.centre12, self.half2, self.half1)
        };
        let axis = if of_first {
            self.rotation.row(k).transpose()
        } else {
            self.rotation.column(k).into_owned()
        };
        centre[k].abs() - own[k] - axis.abs().dot(&other)
    }

    /// The unit axis across the first's edges along `i` and the second's along `j`, and how far
    /// apart the boxes are along it (as [`Self::face_separation`], each box's own edge's
    /// component, zero, left out); `None` when the edges are parallel:
    /// ```text
    ///   e_i × d_j = (…)_{i+1} = −d_{j,i+2},   (…)_{i+2} = d_{j,i+1},   (…)_i = 0
    /// ```
    fn edge_axis(&self, i: usize, j: usize) -> Option<(Vec3, f64)> {
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
        let mut cross = Vec3::zeros();
        cross[i1] = -self.rotation[(i2, j)];
        cross[i2] = self.rotation[(i1, j)];
        let sin2 = cross.norm_squared();
        if sin2 < PARALLEL_SIN2 {
            return None;
        }
        let unit = cross * (1.0 / sin2.sqrt());
        let reach1 = self.half1[i1] * unit[i1].abs() + self.half1[i2] * unit[i2].abs();
        let in_second =
            |k: usize| unit[i1] * self.rotation[(i1, k)] + unit[i2] * self.rotation[(i2, k)];
        let reach2 = self.half2[j1] * in_second(j1).abs() + self.half2[j2] * in_second(j2).abs();
        let apart = (unit[i1] * self.centre21[i1] + unit[i2] * self.centre21[i2]).abs();
        Some((unit, apart - reach1 - reach2))
    }

    /// The axis of greatest separation (the least penetration), `None` when some axis
    /// separates the boxes by more than `slack`. An edge axis must beat the
    /// best face by [`EDGE_BIAS`], and gives way to that face when nearly parallel to it.
    fn separating_axis(&self, slack: f64) -> Option<Axis> {
        let mut best = (
            Axis::Face {
                of_first: true,
                k: 0,
            },
            f64::NEG_INFINITY,
        );
        for of_first in [true, false] {
            for k in 0..3 {
                let separation = self.face_separation(of_first, k);
                if separation > slack {
                    return None;
                }
                if separation > best.1 {
                    best = (Axis::Face { of_first, k }, separation);
                }
            }
        }
        let face = best;
        for i in 0..3 {
            for j in 0..3 {
                let Some((unit, separation)) = self.edge_axis(i, j) else {
                    continue;
                };
                if separation > slack {
                    return None;
                }
                if separation - EDGE_BIAS * separation.abs() > best.1 && separation > face.1 {
                    best = (Axis::Edges { i, j, unit }, separation);
                }
            }
        }
        // an edge axis within ~8° of the face's, not clearly deeper, is that face
        if let Axis::Edges { unit, .. } = best.0 {
            let alignment = match face.0 {
                Axis::Face { of_first: true, k } => unit[k].abs(),
                Axis::Face { k, .. } => self.rotation.column(k).dot(&unit).abs(),
                Axis::Edges { .. } => unreachable!("the best face axis is a face's"),
            };
            let near_tie = face.1 + FACE_PREFERENCE * face.1.abs() + TINY;
            if alignment > FACE_ALIGNMENT && best.1 < near_tie {
                best = face;
            }
        }
        Some(best.0)
    }

    /// One contact midway between the two supporting edges (the closest points of two
    /// segments, Ericson §5.1.9), its distance along the axis oriented from the first box to the
    /// second. A component of the axis near zero leaves two candidate edges on that box; the
    /// pair of edges closest together wins.
    fn edge_contact(&self, i: usize, j: usize, unit: &Vec3, slack: f64) -> Option<Touch> {
        let axis = unit * sign_of(unit.dot(&self.centre21) >= 0.0);
        let axis2 = self.rotation.tr_mul(&axis);
        let ambiguous = |v: &Vec3, k: usize| {
            let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
            [k1, k2].into_iter().find(|&c| v[c].abs() < SIGN_AMBIGUITY)
        };
        let (ambiguous1, ambiguous2) = (ambiguous(&axis, i), ambiguous(&axis2, j));
        let flips = |ambiguous: Option<usize>| {
            [None, ambiguous]
                .into_iter()
                .take(1 + usize::from(ambiguous.is_some()))
        };
        let along2 = self.rotation.column(j).into_owned();
        let cosine = along2[i];
        let sin2 = 1.0 - cosine * cosine;
        let (l1, l2) = (self.half1[i], self.half2[j]);
        let mut closest: Option<(f64, Vec3, Vec3)> = None;
        for flip1 in flips(ambiguous1) {
            for flip2 in flips(ambiguous2) {
                // the middles of the first's edge furthest along the axis and the second's
                // furthest against it
                let mut middle1 = axis.zip_map(&self.half1, |u, h| if u >= 0.0 { h } else { -h });
                middle1[i] = 0.0;
                let mut corner2 = axis2.zip_map(&self.half2, |u, h| if u >= 0.0 { -h } else { h });
                corner2[j] = 0.0;
                if let Some(k) = flip1 {
                    middle1[k] = -middle1[k];
                }
                if let Some(k) = flip2 {
                    corner2[k] = -corner2[k];
                }
                let middle2 = self.rotation * corner2 + self.centre21;
                // closest points m₁ + s e_i and m₂ + t d_j, |s| ≤ l₁, |t| ≤ l₂, each clamp
                // re-solving the other: s = (e·e_i − c e·d_j)/(1 − c²), t = c s − e·d_j
                let between = middle2 - middle1;
                let (along1_gap, along2_gap) = (between[i], along2.dot(&between));
                let free = if sin2 < TINY {
                    0.0
                } else {
                    (along1_gap - cosine * along2_gap) / sin2
                };
                let s = free.clamp(-l1, l1);
                let t = (cosine * s - along2_gap).clamp(-l2, l2);
                let s = (along1_gap + cosine * t).clamp(-l1, l1);
                let mut point1 = middle1;
                point1[i] += s;
                let point2 = middle2 + along2 * t;
                let gap2 = (point2 - point1).norm_squared();
                if closest.is_none_or(|(best, ..)| gap2 < best) {
                    closest = Some((gap2, point1, point2));
                }
            }
        }
        let (_, point1, point2) = closest?;
        let distance = (point2 - point1).dot(&axis);
        if distance > slack {
            return None;
        }
        let middle = (point1 + point2) * 0.5;
        let (rotation, origin) = (&self.first.rotation, &self.first.position);
        Some(Touch::new(
            distance,
            rotation * middle + origin,
            rotation * axis,
        ))
    }

    /// The contacts of the face across axis `a` of the reference box (the first one or the
    /// second): the incident (other) box's face most opposed to it, in coordinates `(x, y, z)`
    /// = (the face's two in-plane axes, the height above it), clipped to the reference face;
    /// each vertex left within `margin` of it is a contact, at its `(x, y)`, midway between
    /// the face and the vertex.
    fn face_contacts(
        &self,
        first_is_reference: bool,
        a: usize,
        margin: f64,
        touches: &mut Vec<Touch>,
    ) {
        let (reference, half_ref, half_inc, centre) = if first_is_reference {
            (self.first, self.half1, self.half2, self.centre21)
        } else {
            (self.second, self.half2, self.half1, self.centre12)
        };
        // the incident box's axes in the reference box's frame (the columns)
        let incident_axes = if first_is_reference {
            self.rotation
        } else {
            self.rotation.transpose()
        };
        let side = sign_of(centre[a] >= 0.0);
        // the incident face: across the incident axis most aligned with the normal, facing it
        let mut b = 0;
        for k in 1..3 {
            if incident_axes[(a, k)].abs() > incident_axes[(a, b)].abs() {
                b = k;
            }
        }
        let facing = -sign_of(side * incident_axes[(a, b)] > 0.0);
        let (u, v) = ((b + 1) % 3, (b + 2) % 3);
        let (ax, ay) = ((a + 1) % 3, (a + 2) % 3);
        let coordinates = [ax, ay, a];
        let in_plane =
            |k: usize, scale: f64| Vec3::from_fn(|r, _| scale * incident_axes[(coordinates[r], k)]);
        let mut middle = Vec3::from_fn(|r, _| {
            let c = coordinates[r];
            centre[c] + facing * half_inc[b] * incident_axes[(c, b)]
        });
        let (mut half_u, mut half_v) = (in_plane(u, half_inc[u]), in_plane(v, half_inc[v]));
        middle.z = side * middle.z - half_ref[a];
        half_u.z *= side;
        half_v.z *= side;
        let mut polygon = Polygon::new();
        for (su, sv) in [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)] {
            polygon.push(middle + half_u * su + half_v * sv);
        }
        let polygon = polygon
            .clipped(0, 1.0, half_ref[ax])
            .clipped(0, -1.0, half_ref[ax])
            .clipped(1, 1.0, half_ref[ay])
            .clipped(1, -1.0, half_ref[ay]);
        // within the margin, vertices at one place (clipped at a corner) counted once
        let duplicate2 =
            DUPLICATE_RADIUS2 * (half_ref[ax] * half_ref[ax] + half_ref[ay] * half_ref[ay]);
        let mut kept = Polygon::new();
        for vertex in polygon.vertices() {
            let near = |w: &Vec3| {
                let (dx, dy) = (w.x - vertex.x, w.y - vertex.y);
                dx * dx + dy * dy < duplicate2
            };
            if vertex.z <= margin && !kept.vertices().iter().any(near) {
                kept.push(*vertex);
            }
        }
        let normal = reference.axis(a) * if first_is_reference { side } else { -side };
        for vertex in kept.vertices() {
            let mut local = Vec3::zeros();
            local[ax] = vertex.x;
            local[ay] = vertex.y;
            local[a] = side * (half_ref[a] + 0.5 * vertex.z);
            let position = reference.rotation * local + reference.position;
            touches.push(Touch::new(vertex.z, position, normal));
        }
    }
}

/// Box `first` against box `second`: the separating axis theorem over the fifteen axes, then
/// one contact between two edges or the clipped incident face's vertices.
pub fn box_box(first: &Placed, second: &Placed, margin: f64, touches: &mut Vec<Touch>) {
    let (half1, half2) = (half_extents_of(first.shape), half_extents_of(second.shape));
    let pair = BoxPair {
        first,
        second,
        half1,
        half2,
        rotation: first.rotation.tr_mul(&second.rotation),
        centre21: first.rotation.tr_mul(&(second.position - first.position)),
        centre12: second.rotation.tr_mul(&(first.position - second.position)),
    };
    let scale = half1.x + half1.y + half1.z + half2.x + half2.y + half2.z;
    let slack = margin + SEPARATION_SLACK * scale;
    match pair.separating_axis(slack) {
        None => {}
        Some(Axis::Edges { i, j, unit }) => touches.extend(pair.edge_contact(i, j, &unit, slack)),
        Some(Axis::Face { of_first, k }) => pair.face_contacts(of_first, k, margin, touches),
    }
}
