//! Boxes against spheres and capsules.
//!
//! Reference: MuJoCo's documentation, "Computation", §Collision detection; the contacts are the
//! ones MuJoCo 4.0's box colliders generate (`mjc_SphereBox`, `mjc_CapsuleBox`, `mjc_BoxBox`).
//! Everything is worked out in the frame of a box, centred on it, where the box is the set
//! `|x_k| ≤ h_k` of its half extents `h`.
//! - A sphere touches a box at the point of the box nearest its centre: the centre clamped into
//!   the box (Ericson, *Real-Time Collision Detection*, §5.1.3). A centre inside the box leaves
//!   through its nearest face.
//! - A capsule is its segment thickened by its radius. The point of the segment nearest the box
//!   (one of its ends against a face, or a point against one of the twelve edges: closest points
//!   of two segments, Ericson §5.1.9) makes a first sphere; when the segment lies along the box
//!   (along an edge, across a face), a second sphere sits where it stops lying on the box.
//!
//! Two boxes: [`super::box_box`]; the tests below check all three against MuJoCo.

use super::{Placed, Touch};
use crate::spatial::Vec3;
use crate::visual::Shape;

/// Below this a length or determinant counts as zero (MuJoCo's `mjMINVAL`).
pub(super) const TINY: f64 = 1e-15;

/// The half extents of a box.
pub(super) fn half_extents_of(shape: &Shape) -> Vec3 {
    match shape {
        Shape::Box { half_extents } => *half_extents,
        _ => unreachable!("a box collider called on a {}", shape.kind()),
    }
}

/// `+1` or `−1`.
pub(super) fn sign_of(positive: bool) -> f64 {
    if positive {
        1.0
    } else {
        -1.0
    }
}

/// The clamped value and whether clamping moved it.
fn clamp_into(value: f64, half: f64) -> (f64, bool) {
    if value < -half {
        (-half, true)
    } else if value > half {
        (half, true)
    } else {
        (value, false)
    }
}

/// A sphere (`centre` in world coordinates, `radius`) against the box `boxed`, when it comes
/// within `margin`. With `c` the centre in the box's frame and `q` its clamp into the box,
/// outside the box
/// ```text
///   n = (q − c)/|q − c|,   d = |q − c| − r,   p = (q + c + r n)/2
/// ```
/// and inside it, through the face nearest `c`, `depth` away, of outward normal `o`:
/// ```text
///   n = −o,   d = −depth − r,   p = c + n (r − depth)/2
/// ```
fn sphere_and_box(centre: &Vec3, radius: f64, boxed: &Placed, margin: f64) -> Option<Touch> {
    let half = half_extents_of(boxed.shape);
    let local = boxed.rotation.tr_mul(&(centre - boxed.position));
    let nearest = local.zip_map(&half, |x, h| clamp_into(x, h).0);
    let toward_box = nearest - local;
    let gap = toward_box.norm();
    if gap - radius > margin {
        return None;
    }
    let (distance, position, normal) = if gap <= TINY {
        // the centre is inside: leave through the nearest face, the first of equals
        let (mut axis, mut side, mut depth) = (0, -1.0, f64::INFINITY);
        for k in 0..3 {
            for sign in [-1.0, 1.0] {
                let to_face = (sign * half[k] - local[k]).abs();
                if to_face < depth {
                    (axis, side, depth) = (k, sign, to_face);
                }
            }
        }
        let mut inward = Vec3::zeros();
        inward[axis] = -side;
        let position = local + inward * ((radius - depth) / 2.0);
        (-depth - radius, position, inward)
    } else {
        let unit = toward_box * (1.0 / gap);
        let deepest = local + unit * radius;
        (gap - radius, nearest * 0.5 + deepest * 0.5, unit)
    };
    Some(Touch::new(
        distance,
        boxed.rotation * position + boxed.position,
        boxed.rotation * normal,
    ))
}

/// Sphere `first` against box `second`.
pub fn sphere_box(first: &Placed, second: &Placed, margin: f64, touches: &mut Vec<Touch>) {
    let radius = match first.shape {
        Shape::Sphere { radius } => *radius,
        shape => unreachable!("sphere_box called on a {}", shape.kind()),
    };
    touches.extend(sphere_and_box(&first.position, radius, second, margin));
}

/// A capsule's segment `c + t a`, `t ∈ [−1, 1]`, in a box's frame (`a` the half axis), and the
/// box's half extents `h`.
struct SegmentInBox {
    centre: Vec3,
    half_axis: Vec3,
    /// The unit direction of `a`.
    direction: Vec3,
    half_length: f64,
    half: Vec3,
}

/// The feature of the box nearest the segment.
#[derive(Debug, Clone, Copy)]
enum Nearest {
    /// An end of the segment, over the face normal to `face` (`None`: the end is inside).
    End { face: Option<usize> },
    /// The edge along `axis` through `corner` (bit k set: on the box's +k side, bit `axis` the
    /// end of the edge when `at_corner`), at `s ∈ [−1, 1]` along it (`s h_axis` from its middle).
    Edge {
        axis: usize,
        corner: usize,
        s: f64,
        at_corner: bool,
    },
}

/// Closest points of the box edge `m + s h_k e_k` (middle `m`, along axis `k`) and the segment,
/// `s` and `t` each clamped to `[−1, 1]`: the normal equations of `|m − c + s h_k e_k − t a|²`,
/// ```text
///   h_k² s − h_k a_k t = −h_k (m − c)_k,   −h_k a_k s + |a|² t = a·(m − c)
/// ```
/// re-solved for one parameter when the other is clamped. Returns `(s, t, end, squared
/// distance)`, `None` when the edge and segment are parallel; `end` is the end of the edge `s`
/// was last clamped to (as MuJoCo does, kept when a re-solve brings `s` back inside).
fn edge_and_segment(
    segment: &SegmentInBox,
    middle: &Vec3,
    k: usize,
) -> Option<(f64, f64, Option<f64>, f64)> {
    let (a, hk) = (&segment.half_axis, segment.half[k]);
    let offset = middle - segment.centre;
    let ss = hk * hk;
    let st = -hk * a[k];
    let tt = segment.half_length * segment.half_length;
    let rhs_s = -hk * offset[k];
    let rhs_t = a.dot(&offset);
    let det = ss * tt - st * st;
    if det.abs() < TINY {
        return None;
    }
    let inverse = 1.0 / det;
    let mut s = (tt * rhs_s - st * rhs_t) * inverse;
    let mut t = (ss * rhs_t - st * rhs_s) * inverse;
    let mut edge_end = None;
    if s.abs() > 1.0 {
        s = s.signum();
        edge_end = Some(s);
        t = (rhs_t - s * st) * (1.0 / tt);
    }
    if t.abs() > 1.0 {
        t = t.signum();
        s = (rhs_s - t * st) * (1.0 / ss);
        if s.abs() > 1.0 {
            s = s.signum();
            edge_end = Some(s);
        }
    }
    let mut gap = offset - a * t;
    gap[k] += hk * s;
    Some((s, t, edge_end, gap.dot(&gap)))
}

impl SegmentInBox {
    /// The box feature nearest the segment and the segment's `t` there: each end against the
    /// faces (an end beyond more than one face is nearer an edge), then the twelve edges, a
    /// later candidate replacing an earlier one only when nearer by more than [`TINY`] (squared).
    fn nearest(&self, radius: f64, margin: f64) -> Option<(f64, Nearest)> {
        let h = &self.half;
        // squared distances beyond (m + 2 (r + l + Σ h))² are no candidates (MuJoCo 4.0's bound)
        let bound = margin + 2.0 * (radius + self.half_length + h.x + h.y + h.z);
        let mut best = bound * bound;
        let mut nearest = None;
        for t in [-1.0, 1.0] {
            let end = self.centre + self.half_axis * t;
            let (mut clamped, mut face, mut faces) = (end, None, 0);
            for k in 0..3 {
                let moved;
                (clamped[k], moved) = clamp_into(end[k], h[k]);
                if moved {
                    (face, faces) = (Some(k), faces + 1);
                }
            }
            let squared = (clamped - end).norm_squared();
            if faces <= 1 && squared < best {
                best = squared;
                nearest = Some((t, Nearest::End { face }));
            }
        }
        for axis in 0..3 {
            for corner in (0..8).filter(|c| c & (1 << axis) == 0) {
                let mut middle = Vec3::from_fn(|k, _| sign_of(corner & (1 << k) != 0) * h[k]);
                middle[axis] = 0.0;
                let Some((s, t, end, squared)) = edge_and_segment(self, &middle, axis) else {
                    continue;
                };
                if squared < best - TINY {
                    best = squared;
                    let corner = corner | (usize::from(end == Some(1.0)) << axis);
                    let at_corner = end.is_some();
                    nearest = Some((
                        t,
                        Nearest::Edge {
                            axis,
                            corner,
                            s,
                            at_corner,
                        },
                    ));
                }
            }
        }
        nearest
    }

    /// `2 h_k / |a_k|`: how far in `t` the segment crosses the box's whole extent along `k`.
    fn crossing(&self, k: usize) -> f64 {
        2.0 * self.half[k] / self.half_axis[k].abs()
    }

    /// Where, as an offset in `t` from the nearest point `t`, the segment stops lying along the
    /// box: `None` when it points at or away from it. The axes "inward" are those along which
    /// `+a` enters the box from the corner or edge; moving by `sign a` from `t` leaves
    /// `1 − sign t` of the segment.
    fn second_point(&self, t: f64, nearest: &Nearest) -> Option<f64> {
        let a = &self.half_axis;
        let positive = (0..3)
            .filter(|&k| a[k] > 0.0)
            .fold(0, |bits, k| bits | (1 << k));
        let remaining = |t: f64, sign: f64| 1.0 - sign * t;
        match *nearest {
            // at a corner, of the two ways along the segment the one entering the box along a
            // single axis: down that edge when the segment is mostly along it (at most the
            // edge's length), else the other way, across the face normal to it
            Nearest::Edge {
                corner,
                at_corner: true,
                ..
            } => {
                let inward = positive ^ corner;
                let (sign, axis) = match inward.count_ones() {
                    1 => (1.0, inward.trailing_zeros() as usize),
                    2 => (-1.0, (7 - inward).trailing_zeros() as usize),
                    _ => return None,
                };
                if self.direction[axis] * self.direction[axis] > 0.5 {
                    Some(sign * remaining(t, sign).min(self.crossing(axis)))
                } else {
                    let across = self
                        .crossing((axis + 1) % 3)
                        .min(self.crossing((axis + 2) % 3));
                    Some(-sign * remaining(t, -sign).min(across))
                }
            }
            // within an edge, crossing it (entering the box along one other axis only): over
            // the face it is flatter against, as far as the segment, that face and the edge go
            Nearest::Edge {
                axis, corner, s, ..
            } => {
                let inward = (positive ^ corner) & (7 ^ (1 << axis));
                if inward.count_ones() != 1 {
                    return None;
                }
                let (next, last) = ((axis + 1) % 3, (axis + 2) % 3);
                let flat = if self.direction[next].abs() > self.direction[last].abs() {
                    last
                } else {
                    next
                };
                let steep = 3 - axis - flat;
                let sign = sign_of(inward & (1 << steep) != 0);
                let forward = (positive & (1 << axis) != 0) == (sign > 0.0);
                let along_edge = 1.0 - if forward { s } else { -s };
                let edge_left = self.half[axis] * along_edge / a[axis].abs();
                Some(sign * remaining(t, sign).min(self.crossing(steep)).min(edge_left))
            }
            Nearest::End { face: None } => None,
            // an end over a face: towards the other end, until it leaves the face's slab
            Nearest::End { face: Some(face) } => {
                let sign = -t;
                let mut offset: f64 = 2.0;
                for k in (0..3).filter(|&k| k != face) {
                    for bound in [self.half[k], -self.half[k]] {
                        let end = self.centre[k] + a[k] * t;
                        let reach = (bound - end) / a[k] * sign;
                        if reach > 0.0 && reach < offset {
                            offset = reach;
                        }
                    }
                }
                Some(offset * sign)
            }
        }
    }
}

/// Capsule `first` against box `second`: a sphere at the segment's point nearest the box, and
/// one where it stops lying along the box when it does.
pub fn capsule_box(first: &Placed, second: &Placed, margin: f64, touches: &mut Vec<Touch>) {
    let (radius, half_length) = match first.shape {
        Shape::Capsule {
            radius,
            half_length,
        } => (*radius, *half_length),
        shape => unreachable!("capsule_box called on a {}", shape.kind()),
    };
    let direction = second.rotation.tr_mul(&first.axis(2));
    let segment = SegmentInBox {
        centre: second.rotation.tr_mul(&(first.position - second.position)),
        half_axis: direction * half_length,
        direction,
        half_length,
        half: half_extents_of(second.shape),
    };
    let Some((t, nearest)) = segment.nearest(radius, margin) else {
        return;
    };
    let second_point = segment.second_point(t, &nearest);
    let sphere_at = |t: f64| {
        let centre = second.rotation * (segment.centre + segment.half_axis * t) + second.position;
        sphere_and_box(&centre, radius, second, margin)
    };
    touches.extend(sphere_at(t));
    if let Some(offset) = second_point {
        touches.extend(sphere_at(offset + t));
    }
}

#[cfg(test)]
#[path = "box_tests.rs"]
mod tests;
