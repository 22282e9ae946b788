//! Planes, spheres, capsules and cylinders against one another, in closed form.
//!
//! Reference: MuJoCo's documentation, "Computation", §Collision detection; the contacts are the
//! ones MuJoCo's primitive collision functions generate. Every case reduces to a sphere touching
//! a plane or another sphere:
//! - a capsule is a segment thickened by its radius: against a plane, a sphere at each end of the
//!   segment (the contacts' first tangent along its axis); against a sphere or a capsule, a
//!   sphere at the segment's point nearest the other;
//! - a cylinder against a plane touches at its rim: the lowest point of the lower disk, the same
//!   point of the other disk, and, when the lower disk's far half is within the margin too, two
//!   more points of that disk 120° on either side;
//! - a sphere against a cylinder touches its side, a cap or the rim, whichever is nearest;
//! - a box against a plane touches at its corners within the margin, at most four.
//!
//! A plane is the plane z = 0 of its frame (normal +z), unbounded.

use super::{Placed, Touch};
use crate::spatial::Vec3;
use crate::visual::Shape;

/// Below this a length counts as zero (MuJoCo's `mjMINVAL`).
const TINY: f64 = 1e-15;
/// Two capsules' axes are parallel when sin² of their angle is below this (MuJoCo 4.0's rule,
/// measured from its output: 1.00e-4 rad apart they are, 1.01e-4 rad apart they are not, for
/// any length).
const PARALLEL: f64 = 1e-8;

/// The radius of a sphere.
fn radius_of(shape: &Shape) -> f64 {
    match shape {
        Shape::Sphere { radius } => *radius,
        _ => unreachable!("a sphere collider called on a {}", shape.kind()),
    }
}

/// The radius and half-length of a capsule or cylinder.
fn round_of(shape: &Shape) -> (f64, f64) {
    match shape {
        Shape::Capsule {
            radius,
            half_length,
        }
        | Shape::Cylinder {
            radius,
            half_length,
        } => (*radius, *half_length),
        _ => unreachable!(
            "a capsule or cylinder collider called on a {}",
            shape.kind()
        ),
    }
}

/// `v / |v|`, or `fallback` when `|v|` is below [`TINY`].
fn unit_or(v: Vec3, fallback: Vec3) -> Vec3 {
    let length = v.norm();
    if length < TINY {
        fallback
    } else {
        v / length
    }
}

/// A sphere (`centre`, `radius`) against the plane through `point` of unit `normal`, when its
/// centre is within `margin + radius` of it:
/// ```text
///   d = (c − o)·n − r,   p = c − n (r + d/2)
/// ```
fn plane_and_sphere(
    point: &Vec3,
    normal: &Vec3,
    centre: &Vec3,
    radius: f64,
    margin: f64,
) -> Option<Touch> {
    let height = (centre - point).dot(normal);
    if height > margin + radius {
        return None;
    }
    let distance = height - radius;
    let position = centre - normal * (radius + distance / 2.0);
    Some(Touch::new(distance, position, *normal))
}

/// Two spheres, when their centres are within `margin + r₁ + r₂`:
/// ```text
///   d = |c₂ − c₁| − r₁ − r₂,   n = (c₂ − c₁)/|c₂ − c₁|,   p = c₁ + n (r₁ + d/2)
/// ```
/// Concentric spheres take the normal `z₁ × z₂` of the z axes of the shapes they stand for
/// (x when those are parallel).
fn two_spheres(
    (centre1, radius1, z1): (&Vec3, f64, Vec3),
    (centre2, radius2, z2): (&Vec3, f64, Vec3),
    margin: f64,
) -> Option<Touch> {
    let between = centre2 - centre1;
    let reach = margin + radius1 + radius2;
    if between.norm_squared() > reach * reach {
        return None;
    }
    let length = between.norm();
    let distance = length - radius1 - radius2;
    let normal = if length < TINY {
        unit_or(z1.cross(&z2), Vec3::x())
    } else {
        between / length
    };
    let position = centre1 + normal * (radius1 + distance / 2.0);
    Some(Touch::new(distance, position, normal))
}

/// Plane `first` against sphere `second`.
pub fn plane_sphere(first: &Placed, second: &Placed, margin: f64, touches: &mut Vec<Touch>) {
    let radius = radius_of(second.shape);
    touches.extend(plane_and_sphere(
        &first.position,
        &first.axis(2),
        &second.position,
        radius,
        margin,
    ));
}

/// Plane `first` against capsule `second`: a sphere at each end of its segment, `c ± h z`.
pub fn plane_capsule(first: &Placed, second: &Placed, margin: f64, touches: &mut Vec<Touch>) {
    let (radius, half_length) = round_of(second.shape);
    let axis = second.axis(2);
    for side in [1.0, -1.0] {
        let end = second.position + axis * (side * half_length);
        if let Some(touch) = plane_and_sphere(&first.position, &first.axis(2), &end, radius, margin)
        {
            touches.push(Touch {
                tangent: axis,
                ..touch
            });
        }
    }
}

/// Plane `first` against cylinder `second`, at its rim (see the module's header).
pub fn plane_cylinder(first: &Placed, second: &Placed, margin: f64, touches: &mut Vec<Touch>) {
    let (radius, half_length) = round_of(second.shape);
    let normal = first.axis(2);
    // the axis a, turned to point into the plane: a·n ≤ 0
    let mut axis = second.axis(2);
    let mut lean = normal.dot(&axis);
    if lean > 0.0 {
        axis = -axis;
        lean = -lean;
    }
    let centre_height = (second.position - first.position).dot(&normal);
    // the radius r towards the plane: r (a (a·n) − n)/|a (a·n) − n|, the cylinder's x when its
    // disks are parallel to the plane
    let towards = axis * lean - normal;
    let rim = if towards.norm_squared() >= TINY * TINY {
        towards * (radius / towards.norm())
    } else {
        second.axis(0) * radius
    };
    let rim_height = rim.dot(&normal);
    let (axis, lean) = (axis * half_length, lean * half_length);
    let touch = |distance: f64, offset: Vec3| {
        Touch::new(
            distance,
            second.position + offset - normal * (distance / 2.0),
            normal,
        )
    };
    // the lowest point of the lower disk, then the same point of the other disk
    let lowest = centre_height + lean + rim_height;
    if lowest > margin {
        return;
    }
    touches.push(touch(lowest, rim + axis));
    let opposite = centre_height - lean + rim_height;
    if opposite <= margin {
        touches.push(touch(opposite, rim - axis));
    }
    // two more points of the lower disk at ±120°: −r/2 ± (√3/2) r (r̂ × a)
    let side_height = centre_height + lean - rim_height / 2.0;
    if side_height <= margin {
        let sideways = rim.cross(&axis).normalize() * (radius * 3f64.sqrt() / 2.0);
        touches.push(touch(side_height, sideways + axis - rim * 0.5));
        touches.push(touch(side_height, -sideways + axis - rim * 0.5));
    }
}

/// Plane `first` against box `second`: its corners within the margin whose offset from the
/// centre points into the plane, in the order of the corners' sign bits, at most four.
pub fn plane_box(first: &Placed, second: &Placed, margin: f64, touches: &mut Vec<Touch>) {
    let Shape::Box { half_extents } = second.shape else {
        unreachable!("plane_box called on a {}", second.shape.kind());
    };
    let normal = first.axis(2);
    let centre_height = (second.position - first.position).dot(&normal);
    let mut found = 0;
    for corner in 0..8 {
        let sign = |bit: usize| if corner & (1 << bit) != 0 { 1.0 } else { -1.0 };
        let local = Vec3::new(
            sign(0) * half_extents.x,
            sign(1) * half_extents.y,
            sign(2) * half_extents.z,
        );
        let offset = second.rotation * local;
        let corner_height = offset.dot(&normal);
        if centre_height + corner_height > margin || corner_height > 0.0 {
            continue;
        }
        let distance = centre_height + corner_height;
        let position = second.position + offset - normal * (distance / 2.0);
        touches.push(Touch::new(distance, position, normal));
        found += 1;
        if found == 4 {
            return;
        }
    }
}

/// Sphere `first` against sphere `second`.
pub fn sphere_sphere(first: &Placed, second: &Placed, margin: f64, touches: &mut Vec<Touch>) {
    touches.extend(two_spheres(
        (&first.position, radius_of(first.shape), first.axis(2)),
        (&second.position, radius_of(second.shape), second.axis(2)),
        margin,
    ));
}

/// Sphere `first` against capsule `second`: the sphere of the capsule at the point of its
/// segment nearest the sphere's centre, `c₂ + clamp((c₁ − c₂)·z, −h, h) z`.
pub fn sphere_capsule(first: &Placed, second: &Placed, margin: f64, touches: &mut Vec<Touch>) {
    let (radius, half_length) = round_of(second.shape);
    let axis = second.axis(2);
    let along = axis
        .dot(&(first.position - second.position))
        .clamp(-half_length, half_length);
    let nearest = second.position + axis * along;
    touches.extend(two_spheres(
        (&first.position, radius_of(first.shape), first.axis(2)),
        (&nearest, radius, axis),
        margin,
    ));
}

/// Sphere `first` against cylinder `second`: its side where the sphere's centre lies between
/// the caps' planes, a cap where it lies within the side's tube, the rim elsewhere; a centre
/// inside the cylinder is pushed out through the nearer of side and cap.
pub fn sphere_cylinder(first: &Placed, second: &Placed, margin: f64, touches: &mut Vec<Touch>) {
    let sphere = (&first.position, radius_of(first.shape), first.axis(2));
    let (radius, half_length) = round_of(second.shape);
    let axis = second.axis(2);
    // the centre's offset split along the axis (x) and across it (across)
    let offset = first.position - second.position;
    let along = axis.dot(&offset);
    let across = offset - axis * along;
    let mut by_side = along.abs() < half_length;
    let mut by_cap = across.norm_squared() < radius * radius;
    if by_side && by_cap {
        // inside: out through the nearer surface
        if half_length - along.abs() < radius - across.norm() {
            by_side = false;
        } else {
            by_cap = false;
        }
    }
    if by_side {
        let on_axis = second.position + axis * along;
        touches.extend(two_spheres(sphere, (&on_axis, radius, axis), margin));
    } else if by_cap {
        // the cap's plane, its normal outwards, then the normal turned from sphere to cylinder
        let outward = if along > 0.0 { axis } else { -axis };
        let cap = second.position + outward * half_length;
        if let Some(touch) = plane_and_sphere(&cap, &outward, &first.position, sphere.1, margin) {
            touches.push(Touch {
                normal: -touch.normal,
                ..touch
            });
        }
    } else {
        // the rim point nearest the centre, as a sphere of radius zero
        let cap = if along > 0.0 {
            half_length
        } else {
            -half_length
        };
        let rim = second.position + axis * cap + across * (radius / across.norm());
        touches.extend(two_spheres(sphere, (&rim, 0.0, axis), margin));
    }
}

/// Capsule `first` against capsule `second`: the spheres at the nearest points of their
/// segments `c₁ + x₁ a₁` and `c₂ + x₂ a₂` (`aᵢ = hᵢ zᵢ`, xᵢ ∈ [−1, 1]). Parallel segments
/// (sin²θ below 1e-8) touch along the stretch where they overlap: at its two ends, in
/// the order of x₁, each end a point of one segment and the nearest point of the other.
pub fn capsule_capsule(first: &Placed, second: &Placed, margin: f64, touches: &mut Vec<Touch>) {
    let (radius1, half_length1) = round_of(first.shape);
    let (radius2, half_length2) = round_of(second.shape);
    let (z1, z2) = (first.axis(2), second.axis(2));
    let (a1, a2) = (z1 * half_length1, z2 * half_length2);
    let between = first.position - second.position;
    // minimise |c₁ + x₁a₁ − c₂ − x₂a₂|²: [ma mb; mb mc] [x₁; x₂] = [u; v]
    let (ma, mb, mc) = (a1.dot(&a1), -a1.dot(&a2), a2.dot(&a2));
    let (u, v) = (-a1.dot(&between), a2.dot(&between));
    let determinant = ma * mc - mb * mb;
    let sphere_pair = |x1: f64, x2: f64| {
        let point1 = first.position + a1 * x1;
        let point2 = second.position + a2 * x2;
        two_spheres((&point1, radius1, z1), (&point2, radius2, z2), margin)
    };
    // x₂ nearest a given x₁ (unclamped), and x₁ nearest a given x₂ (clamped)
    let for_first = |x1: f64| (v - mb * x1) / mc;
    let for_second = |x2: f64| ((u - mb * x2) / ma).clamp(-1.0, 1.0);
    // det = ma mc sin²θ
    if determinant >= PARALLEL * ma * mc {
        // the unconstrained minimum, then each coordinate clamped in turn
        let mut x1 = (mc * u - mb * v) / determinant;
        let mut x2 = (ma * v - mb * u) / determinant;
        if x1.abs() > 1.0 {
            x1 = x1.signum();
            x2 = for_first(x1);
        }
        if x2.abs() > 1.0 {
            x2 = x2.signum();
            x1 = for_second(x2);
        }
        touches.extend(sphere_pair(x1, x2));
        return;
    }
    // parallel: the second segment's ends seen along the first, x₁ = (u − mb x₂)/ma, the lower
    // one first; each end of the overlap is the inner of the two segments' ends
    let lower2 = if mb < 0.0 { -1.0 } else { 1.0 };
    let lower = if (u - mb * lower2) / ma > -1.0 {
        (for_second(lower2), lower2)
    } else {
        (-1.0, for_first(-1.0).clamp(-1.0, 1.0))
    };
    let upper = if (u + mb * lower2) / ma < 1.0 {
        (for_second(-lower2), -lower2)
    } else {
        (1.0, for_first(1.0).clamp(-1.0, 1.0))
    };
    for (x1, x2) in [lower, upper] {
        touches.extend(sphere_pair(x1, x2));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::Mat3;

    /// Closed forms computed by hand: exact up to round-off.
    const EXACT: f64 = 1e-14;

    fn placed(shape: &Shape, rotation: Mat3, position: [f64; 3]) -> Placed<'_> {
        Placed {
            shape,
            rotation,
            position: Vec3::from(position),
        }
    }

    fn touches_of(collider: super::super::Collider, first: &Placed, second: &Placed) -> Vec<Touch> {
        let mut touches = Vec::new();
        collider(first, second, 0.0, &mut touches);
        touches
    }

    /// z turned onto x: a capsule or cylinder lying along x.
    fn lying() -> Mat3 {
        Mat3::new(0.0, 0.0, 1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0)
    }

    const FLOOR: Shape = Shape::Plane {
        half_extents: [0.0, 0.0],
    };

    #[test]
    fn a_sphere_sunk_into_the_floor_touches_midway() {
        let ball = Shape::Sphere { radius: 0.1 };
        let floor = placed(&FLOOR, Mat3::identity(), [0.0; 3]);
        let touches = touches_of(
            plane_sphere,
            &floor,
            &placed(&ball, Mat3::identity(), [0.3, 0.0, 0.08]),
        );
        assert_eq!(touches.len(), 1);
        assert!((touches[0].distance + 0.02).abs() < EXACT);
        assert!((touches[0].position - Vec3::new(0.3, 0.0, -0.01)).norm() < EXACT);
        assert_eq!(touches[0].normal, Vec3::z());
    }

    #[test]
    fn a_capsule_lying_on_the_floor_touches_at_both_ends_along_its_axis() {
        let rod = Shape::Capsule {
            radius: 0.05,
            half_length: 0.2,
        };
        let floor = placed(&FLOOR, Mat3::identity(), [0.0; 3]);
        let touches = touches_of(
            plane_capsule,
            &floor,
            &placed(&rod, lying(), [0.0, 0.0, 0.04]),
        );
        assert_eq!(touches.len(), 2);
        for (touch, x) in touches.iter().zip([0.2, -0.2]) {
            assert!((touch.distance + 0.01).abs() < EXACT);
            assert!((touch.position - Vec3::new(x, 0.0, -0.005)).norm() < EXACT);
            assert_eq!(touch.tangent, Vec3::x());
        }
    }

    #[test]
    fn an_upright_cylinder_touches_at_four_rim_points_and_a_box_at_four_corners() {
        let drum = Shape::Cylinder {
            radius: 0.1,
            half_length: 0.2,
        };
        let floor = placed(&FLOOR, Mat3::identity(), [0.0; 3]);
        let touches = touches_of(
            plane_cylinder,
            &floor,
            &placed(&drum, Mat3::identity(), [0.0, 0.0, 0.19]),
        );
        assert_eq!(
            touches.len(),
            3,
            "the lowest point, then two at ±120° (the top disk is far)"
        );
        for touch in &touches {
            assert!((touch.distance + 0.01).abs() < EXACT);
            assert!((touch.position.xy().norm() - 0.1).abs() < EXACT);
        }
        let crate_ = Shape::Box {
            half_extents: Vec3::new(0.1, 0.2, 0.3),
        };
        let touches = touches_of(
            plane_box,
            &floor,
            &placed(&crate_, Mat3::identity(), [0.0, 0.0, 0.29]),
        );
        assert_eq!(touches.len(), 4);
        for touch in &touches {
            assert!((touch.distance + 0.01).abs() < EXACT);
            assert!((touch.position.z + 0.005).abs() < EXACT);
        }
    }

    #[test]
    fn parallel_capsules_touch_at_both_ends_of_their_overlap() {
        let rod = Shape::Capsule {
            radius: 0.05,
            half_length: 0.2,
        };
        let one = placed(&rod, lying(), [0.0, 0.0, 0.0]);
        let other = placed(&rod, lying(), [0.1, 0.0, 0.08]);
        let touches = touches_of(capsule_capsule, &one, &other);
        assert_eq!(touches.len(), 2);
        // along x the overlap runs from the other's end, x = −0.1, to the first's, x = 0.2
        for (touch, x) in touches.iter().zip([-0.1, 0.2]) {
            assert!((touch.distance + 0.02).abs() < EXACT);
            assert!((touch.position - Vec3::new(x, 0.0, 0.04)).norm() < EXACT);
            assert!((touch.normal - Vec3::z()).norm() < EXACT);
        }
    }

    #[test]
    fn a_sphere_inside_a_cylinder_leaves_through_the_nearer_surface() {
        let ball = Shape::Sphere { radius: 0.05 };
        let drum = Shape::Cylinder {
            radius: 0.1,
            half_length: 0.2,
        };
        let cylinder = placed(&drum, Mat3::identity(), [0.0; 3]);
        // 0.02 from the side, 0.2 from the caps: out through the side, normal towards −x
        let touches = touches_of(
            sphere_cylinder,
            &placed(&ball, Mat3::identity(), [0.08, 0.0, 0.0]),
            &cylinder,
        );
        assert_eq!(touches.len(), 1);
        assert!((touches[0].distance + 0.07).abs() < EXACT);
        assert!((touches[0].normal + Vec3::x()).norm() < EXACT);
        // 0.01 from the top cap: out through it, normal towards −z
        let touches = touches_of(
            sphere_cylinder,
            &placed(&ball, Mat3::identity(), [0.0, 0.0, 0.19]),
            &cylinder,
        );
        assert!((touches[0].distance + 0.06).abs() < EXACT);
        assert!((touches[0].normal + Vec3::z()).norm() < EXACT);
    }
}
