//! A spatial tendon's path around a sphere or a cylinder between two points (MJCF
//! `<spatial><geom geom sidesite>`, MuJoCo's geom wrapping).
//!
//! Reference: MuJoCo's documentation, XML reference §tendon/spatial/geom and "Modeling"
//! §Tendons; where the geometry leaves a choice (which way round, a side site inside the geom,
//! degenerate ends) MuJoCo 4.0's engine decides, so that lengths agree to round-off.
//!
//! In the geom's frame, with both ends p₀, p₁ outside it, the problem is planar: for a sphere,
//! the plane through its centre, p₀ and p₁ (axes p̂₀ and n × p̂₀, n ∥ p₀ × p₁); for a cylinder,
//! its cross-section (x, y), z handled after. In that plane, the two tangent points of a circle
//! of radius r seen from an end e (|e| > r) are
//! ```text
//!   t = (r² e ± r √(|e|² − r²) e⊥) / |e|²,          e⊥ = (e_y, −e_x)
//! ```
//! The path is e₀ → t₀, the arc t₀ → t₁ (length r θ), t₁ → e₁. It wraps where the segment e₀e₁
//! passes through the circle or, with a side site s, where s lies behind the circle as seen
//! from both ends (within the angle between −e₀ and −e₁: MuJoCo 4.0's rule, found by probing
//! it, where its 3.x source tested only that the segment's nearest point faces away from s).
//! Of the two ways round: with a side site the one whose mid-direction
//! (t₀ + t₁)/|t₀ + t₁| is nearest s, else the shorter chord |t₀ − t₁|; never one whose straight
//! pieces e₀t₀ and e₁t₁ cross. A cylinder's path climbs linearly in its unrolled length:
//! ```text
//!   z(t₀) = z₀ + (z₁ − z₀) ℓ₀ / ℓ,   z(t₁) = z₀ + (z₁ − z₀)(ℓ₀ + r θ) / ℓ,   ℓ = ℓ₀ + r θ + ℓ₁
//! ```
//! (ℓ₀, ℓ₁ the straight pieces' lengths in the cross-section), its arc the helix's
//! √((r θ)² + Δz²). A side site inside the geom presses the path against the surface from
//! within: one point t = r (cos φ, sin φ) rotated from an end, where the pieces meet at equal
//! angles, found by Newton's method on
//! ```text
//!   f(z) = asin(A z) + asin(B z) − 2 asin(z) + G = 0,   A = r/|e₀|, B = r/|e₁|, G = ∠e₀0e₁
//! ```
//! from z = 1 − 10⁻⁷ to round-off (|f| ≤ 10⁻¹⁴, at most 50 steps), then φ = asin z − asin(A z)
//! from e₀ (or asin z − asin(B z) from e₁); where f starts positive, a step lands past the root
//! by more than 10⁻⁶ or the slope is not negative, the ends' mean direction. MuJoCo stops at
//! |f| ≤ 10⁻⁶: its J of such a path differs from this root's by up to 6.2e-8 over 400 states
//! (test_soft_elements.py), its length by round-off (the length is stationary there).

use super::TINY;
use crate::spatial::{Mat3, Vec3};
use crate::visual::Shape;
use nalgebra::{SVector, Vector2};
use std::f64::consts::PI;

type Vec2 = Vector2<f64>;

/// The surfaces a tendon wraps around.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Surface {
    /// A sphere of this radius about the geom's origin.
    Sphere(f64),
    /// An infinite cylinder of this radius about the geom's z axis.
    Cylinder(f64),
}

impl Surface {
    /// The surface of a geom's shape a tendon wraps around: a sphere's or a cylinder's; `None`
    /// for the other shapes (MuJoCo wraps around no other).
    pub fn of(shape: &Shape) -> Option<Surface> {
        match *shape {
            Shape::Sphere { radius } => Some(Surface::Sphere(radius)),
            Shape::Cylinder { radius, .. } => Some(Surface::Cylinder(radius)),
            _ => None,
        }
    }
}

/// What a wrap puts between a path's two ends: its two points on the surface (world
/// coordinates) and the length of the path over the surface between them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wrap {
    /// Where the path meets the surface, then where it leaves it.
    pub points: [Vec3; 2],
    /// The length over the surface.
    pub arc: f64,
}

/// The wrap of the path from `x0` to `x1` around `surface`, its geom's axes `rotation` (columns,
/// in the world) and origin `origin`; `side` the side site's position. `None`: the straight
/// segment.
pub fn wrap(
    (x0, x1): (&Vec3, &Vec3),
    (rotation, origin): (&Mat3, &Vec3),
    surface: Surface,
    side: Option<&Vec3>,
) -> Option<Wrap> {
    let local = |x: &Vec3| rotation.transpose() * (x - origin);
    let (p0, p1) = (local(x0), local(x1));
    if p0.norm() < TINY || p1.norm() < TINY {
        return None;
    }
    // the plane of the wrap, and the ends and the side site in it
    let (axes, radius) = match surface {
        Surface::Sphere(radius) => (sphere_plane(&p0, &p1), radius),
        Surface::Cylinder(radius) => ([Vec3::x(), Vec3::y()], radius),
    };
    let flat = |p: &Vec3| Vec2::new(p.dot(&axes[0]), p.dot(&axes[1]));
    let ends = [flat(&p0), flat(&p1)];
    let side = side.map(local);
    let (tangents, mut arc) = match side {
        Some(s) if s.norm() < radius => inside(ends, radius)?,
        _ => around(ends, side.map(|s| radius * unit(flat(&s))), radius)?,
    };
    let mut points = tangents.map(|t| axes[0] * t.x + axes[1] * t.y);
    // a cylinder's path climbs in proportion to its unrolled length
    if let Surface::Cylinder(_) = surface {
        let planar = |p: &Vec3, t: &Vec3| (p.x - t.x).hypot(p.y - t.y);
        let (l0, l1) = (planar(&p0, &points[0]), planar(&p1, &points[1]));
        let total = l0 + arc + l1;
        points[0].z = p0.z + (p1.z - p0.z) * l0 / total;
        points[1].z = p0.z + (p1.z - p0.z) * (l0 + arc) / total;
        arc = arc.hypot(points[1].z - points[0].z);
    }
    Some(Wrap {
        points: points.map(|p| rotation * p + origin),
        arc,
    })
}

/// A sphere's wrap plane through p₀ and p₁: its axes p̂₀ and n × p̂₀ (n ∥ p₀ × p₁; where p₀ and
/// p₁ are parallel, n ⟂ p₀ and (1, 1, 1) with a zero at p̂₀'s largest entry).
fn sphere_plane(p0: &Vec3, p1: &Vec3) -> [Vec3; 2] {
    let first = unit(*p0);
    let mut normal = p0.cross(p1);
    if normal.norm() < TINY {
        let a = first.abs();
        let largest = if a.y > a.x && a.y > a.z {
            1
        } else if a.z > a.x && a.z > a.y {
            2
        } else {
            0
        };
        let mut other = Vec3::repeat(1.0);
        other[largest] = 0.0;
        normal = first.cross(&other);
    }
    [first, unit(unit(normal).cross(&first))]
}

/// The tangent points and arc of the wrap from `e0` to `e1` (the module's header) around a
/// circle of radius `radius`, `side` the side site on the circle; `None` where the path does
/// not wrap.
fn around([e0, e1]: [Vec2; 2], side: Option<Vec2>, radius: f64) -> Option<([Vec2; 2], f64)> {
    let (s0, s1, r2) = (e0.norm_squared(), e1.norm_squared(), radius * radius);
    if s0 < r2 || s1 < r2 || radius < TINY {
        return None;
    }
    let chord = e1 - e0;
    let length2 = chord.norm_squared();
    if length2 < TINY {
        return None;
    }
    // a segment that misses the circle wraps only towards a side site behind it from both ends
    let nearest = e0 + (-chord.dot(&e0) / length2).clamp(0.0, 1.0) * chord;
    if nearest.norm_squared() > r2 && side.is_none_or(|s| !behind(&s, &e0, &e1)) {
        return None;
    }
    // t = (r² e ± r √(|e|² − r²) e⊥) / |e|², opposite signs at the two ends
    let (root0, root1) = ((s0 - r2).sqrt(), (s1 - r2).sqrt());
    let way = |sign: f64| {
        [
            (e0 * r2 + sign * radius * root0 * Vec2::new(e0.y, -e0.x)) / s0,
            (e1 * r2 - sign * radius * root1 * Vec2::new(e1.y, -e1.x)) / s1,
        ]
    };
    let goodness = |[t0, t1]: [Vec2; 2]| {
        if crosses((e0, t0), (e1, t1)) {
            return -1e4;
        }
        match side {
            Some(s) => unit(t0 + t1).dot(&s),
            None => -(t0 - t1).norm_squared(),
        }
    };
    let (positive, negative) = (way(1.0), way(-1.0));
    let (tangents, sign) = if goodness(positive) > goodness(negative) {
        (positive, 1.0)
    } else {
        (negative, -1.0)
    };
    let [t0, t1] = tangents;
    if crosses((e0, t0), (e1, t1)) {
        return None;
    }
    // θ in [0, π] between t₀ and t₁, the long way round where the turn runs against the sign
    let mut angle = unit(t0).dot(&unit(t1)).clamp(-1.0, 1.0).acos();
    let turn = t0.y * t1.x - t0.x * t1.y;
    if (turn > 0.0 && sign < 0.0) || (turn < 0.0 && sign > 0.0) {
        angle = 2.0 * PI - angle;
    }
    Some((tangents, radius * angle))
}

/// The point where a path from `e0` to `e1` presses against a circle of radius `radius` from
/// within (the module's header), twice, and no arc; `None` where it does not touch.
fn inside([e0, e1]: [Vec2; 2], radius: f64) -> Option<([Vec2; 2], f64)> {
    const MAX_STEPS: usize = 50;
    const START: f64 = 1.0 - 1e-7;
    // |f| at round-off (MuJoCo's 1e-6 leaves the point up to 1e-8 from the root)
    const CONVERGED: f64 = 1e-14;
    // f past the root by more than this: the iteration has failed (MuJoCo's)
    const OVERSHOOT: f64 = 1e-6;
    let (l0, l1) = (e0.norm(), e1.norm());
    if l0 <= radius || l1 <= radius || radius < TINY || l0 < TINY || l1 < TINY {
        return None;
    }
    // the segment passes through the circle: no wrap
    let chord = e1 - e0;
    let length2 = chord.norm_squared();
    if length2 > TINY {
        let a = -chord.dot(&e0) / length2;
        if a > 0.0 && a < 1.0 && (e0 + a * chord).norm() <= radius {
            return None;
        }
    }
    // where Newton's method fails: the ends' mean direction
    let mean = radius * unit(0.5 * (e0 + e1));
    let fallback = Some(([mean; 2], 0.0));
    let (a, b) = (radius / l0, radius / l1);
    let cos_g = (l0 * l0 + l1 * l1 - length2) / (2.0 * l0 * l1);
    if cos_g < -1.0 + TINY {
        return None;
    }
    if cos_g > 1.0 - TINY {
        return fallback;
    }
    let g = cos_g.acos();
    // f(z) = asin(A z) + asin(B z) − 2 asin(z) + G, from z just below 1 downwards
    let f = |z: f64| (a * z).asin() + (b * z).asin() - 2.0 * z.asin() + g;
    let slope_term = |k: f64, z: f64| k / (1.0 - z * z * k * k).sqrt().max(TINY);
    let mut z = START;
    let mut value = f(z);
    if value > 0.0 {
        return fallback;
    }
    let mut steps = 0;
    while steps < MAX_STEPS && value.abs() > CONVERGED {
        let slope = slope_term(a, z) + slope_term(b, z) - 2.0 * slope_term(1.0, z);
        if slope > -TINY {
            return fallback;
        }
        z -= value / slope;
        value = f(z);
        if value > OVERSHOOT {
            return fallback;
        }
        steps += 1;
    }
    // rotate from the end the turn starts at
    let (from, angle) = if e0.x * e1.y - e0.y * e1.x > 0.0 {
        (e0, z.asin() - (a * z).asin())
    } else {
        (e1, z.asin() - (b * z).asin())
    };
    let u = unit(from);
    let (sin, cos) = angle.sin_cos();
    let point = radius * Vec2::new(cos * u.x - sin * u.y, sin * u.x + cos * u.y);
    Some(([point; 2], 0.0))
}

/// Whether the direction `s` lies strictly within the angle between −e₀ and −e₁: behind the
/// circle as seen from both ends.
fn behind(s: &Vec2, e0: &Vec2, e1: &Vec2) -> bool {
    let cross = |a: &Vec2, b: &Vec2| a.x * b.y - a.y * b.x;
    let (u, w) = (-e0, -e1);
    let turn = cross(&u, &w);
    cross(&u, s) * turn > 0.0 && cross(s, &w) * turn > 0.0
}

/// Whether the segments p₀p₁ and q₀q₁ meet (not where they are parallel).
fn crosses((p0, p1): (Vec2, Vec2), (q0, q1): (Vec2, Vec2)) -> bool {
    let (u, w, o) = (p1 - p0, q1 - q0, p0 - q0);
    let det = u.x * w.y - u.y * w.x;
    if det.abs() < TINY {
        return false;
    }
    let along_p = (w.x * o.y - w.y * o.x) / det;
    let along_q = (u.x * o.y - u.y * o.x) / det;
    (0.0..=1.0).contains(&along_p) && (0.0..=1.0).contains(&along_q)
}

/// v/|v|, the first axis where v vanishes (MuJoCo's rule).
fn unit<const D: usize>(v: SVector<f64, D>) -> SVector<f64, D> {
    let norm = v.norm();
    if norm < TINY {
        let mut first = SVector::zeros();
        first[0] = 1.0;
        first
    } else {
        v / norm
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const EXACT: f64 = 1e-12;

    #[test]
    fn tendons_wrap_around_spheres_and_cylinders_only() {
        let sphere = Shape::Sphere { radius: 0.5 };
        assert_eq!(Surface::of(&sphere), Some(Surface::Sphere(0.5)));
        let (radius, half_length) = (0.25, 1.0);
        let cylinder = Shape::Cylinder {
            radius,
            half_length,
        };
        assert_eq!(Surface::of(&cylinder), Some(Surface::Cylinder(0.25)));
        let capsule = Shape::Capsule {
            radius,
            half_length,
        };
        assert_eq!(Surface::of(&capsule), None);
    }

    /// A path from (−2, 0.5, 0) to (2, 0.5, 0) around the unit sphere passes over its top (the
    /// shorter way), as the closed form has it: seen from an end at distance d and angle β, the
    /// tangent touches at β ∓ acos(r/d); each straight piece is √(d² − r²).
    #[test]
    fn a_sphere_wraps_the_short_way_with_the_closed_form_length() {
        let (x0, x1) = (Vec3::new(-2.0, 0.5, 0.0), Vec3::new(2.0, 0.5, 0.0));
        let w = wrap(
            (&x0, &x1),
            (&Mat3::identity(), &Vec3::zeros()),
            Surface::Sphere(1.0),
            None,
        )
        .unwrap();
        let d = x0.norm();
        let piece = (d * d - 1.0_f64).sqrt();
        let to_tangent = (1.0 / d).acos();
        // the ends at angles β and π − β
        let end_angle = x0.y.atan2(x0.x);
        let arc = (end_angle - to_tangent) - (PI - end_angle + to_tangent);
        let total = (w.points[0] - x0).norm() + w.arc + (x1 - w.points[1]).norm();
        assert!((total - (2.0 * piece + arc.abs())).abs() < EXACT, "{total}");
        assert!(w
            .points
            .iter()
            .all(|p| (p.norm() - 1.0).abs() < EXACT && p.y > 0.0));
        // a segment that misses the sphere does not wrap
        let high = (Vec3::new(-2.0, 1.5, 0.0), Vec3::new(2.0, 1.5, 0.0));
        let frame = (&Mat3::identity(), &Vec3::zeros());
        assert!(wrap((&high.0, &high.1), frame, Surface::Sphere(1.0), None).is_none());
        // a side site below sends it under, the long way
        let below = Vec3::new(0.0, -3.0, 0.0);
        let under = wrap((&x0, &x1), frame, Surface::Sphere(1.0), Some(&below)).unwrap();
        assert!(under.points.iter().all(|p| p.y < 0.0) && under.arc > w.arc);
    }

    /// A cylinder's path is a helix between its tangent points: its length is the unrolled
    /// plane's straight line.
    #[test]
    fn a_cylinder_wrap_unrolls_to_a_straight_line() {
        let (x0, x1) = (Vec3::new(-2.0, 0.3, -0.4), Vec3::new(1.5, 0.2, 0.9));
        let frame = (&Mat3::identity(), &Vec3::zeros());
        let w = wrap((&x0, &x1), frame, Surface::Cylinder(0.5), None).unwrap();
        let planar = |a: &Vec3, b: &Vec3| (a.x - b.x).hypot(a.y - b.y);
        let flat_arc = (w.arc.powi(2) - (w.points[1].z - w.points[0].z).powi(2)).sqrt();
        let unrolled = planar(&x0, &w.points[0]) + flat_arc + planar(&w.points[1], &x1);
        let total = (w.points[0] - x0).norm() + w.arc + (x1 - w.points[1]).norm();
        assert!((total - unrolled.hypot(x1.z - x0.z)).abs() < EXACT);
    }
}
