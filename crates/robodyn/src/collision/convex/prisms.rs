//! A height field against a convex geom, one prism at a time.
//!
//! Reference: MuJoCo's documentation, "Computation", §Collision detection (height fields:
//! "collided as a union of triangular prisms"), and its 4.0 engine's contacts, which these
//! reproduce (read to understand, written anew here). In the field's frame:
//! 1. the geom's bounding sphere, then its bounding box (its support points along ±x, ±y, ±z),
//!    must reach the field's box `[−s₀, s₀] × [−s₁, s₁] × [−s₃, s₂]` (each grown by the margin);
//! 2. the grid cells under the bounding box grown by the margin m, columns `c` from
//!    `⌊(x_min − m + s₀)/(2s₀) (columns − 1)⌋` to `⌈(x_max + m + s₀)/(2s₀) (columns − 1)⌉` (rows
//!    the same in y);
//! 3. each cell's two triangles, walked as a strip along the row, each the top of a prism down
//!    to z = −s₃: a prism whose top lies wholly below the geom's lowest point (less the margin)
//!    is passed over; the others are collided as two convex shapes (GJK and EPA of
//!    [`super::penetration`]), one contact each, at most [`MAX_CONTACTS`] in all.

use super::{push_touches, Body, Kind};
use crate::collision::gjk::Convex;
use crate::collision::{bounding_radius, Placed, Touch};
use crate::spatial::{Mat3, Vec3};
use crate::visual::Shape;

/// The most contacts of one pair (MuJoCo's `mjMAXCONPAIR`).
pub const MAX_CONTACTS: usize = 50;

/// Slides the prism's corners along the strip: the oldest corner leaves, the surface's point
/// `surface` and the base's below it (at z = −`base`) come last.
fn slide_in(corners: &mut [Vec3; 6], surface: Vec3, base: f64) {
    corners.copy_within(1..3, 0);
    corners.copy_within(4..6, 3);
    corners[2] = Vec3::new(surface.x, surface.y, -base);
    corners[5] = surface;
}

/// Height field `first` against a convex `second` (see the module's header): contacts with
/// normals from the field to the geom.
pub fn height_field_convex(first: &Placed, second: &Placed, margin: f64, touches: &mut Vec<Touch>) {
    let Shape::HeightField { field } = first.shape else {
        return;
    };
    // the geom in the field's frame: R = R_fᵀ R_g, p = R_fᵀ (p_g − p_f)
    let to_field = first.rotation.transpose();
    let local = Placed {
        shape: second.shape,
        rotation: to_field * second.rotation,
        position: to_field * (second.position - first.position),
    };
    let Some(geom) = Body::new(&local) else {
        return;
    };
    let [sx, sy] = field.half_extents;
    let base = field.base;
    // 1: its bounding sphere, then its bounding box, must reach the field's box
    let (low_corner, high_corner) = (Vec3::new(-sx, -sy, -base), Vec3::new(sx, sy, field.top));
    let apart =
        |low: Vec3, high: Vec3| (0..3).any(|k| low[k] > high_corner[k] || high[k] < low_corner[k]);
    let reach = Vec3::repeat(bounding_radius(second.shape) + margin);
    if apart(local.position - reach, local.position + reach) {
        return;
    }
    let extent = |k: usize| {
        let mut d = Vec3::zeros();
        d[k] = 1.0;
        let high = geom.support(&d).0[k];
        d[k] = -1.0;
        (geom.support(&d).0[k], high)
    };
    let ((x_min, x_max), (y_min, y_max), (z_min, z_max)) = (extent(0), extent(1), extent(2));
    let grown = Vec3::repeat(margin);
    let (low, high) = (
        Vec3::new(x_min, y_min, z_min),
        Vec3::new(x_max, y_max, z_max),
    );
    if apart(low - grown, high + grown) {
        return;
    }
    // 2: the cells under the box grown by the margin
    let (rows, columns) = (field.rows as i64, field.columns as i64);
    let grid = |v: f64, s: f64, n: i64| (v + s) / (2.0 * s) * (n - 1) as f64;
    let c_min = (grid(x_min - margin, sx, columns).floor() as i64).max(0);
    let c_max = (grid(x_max + margin, sx, columns).ceil() as i64).min(columns - 1);
    let r_min = (grid(y_min - margin, sy, rows).floor() as i64).max(0);
    let r_max = (grid(y_max + margin, sy, rows).ceil() as i64).min(rows - 1);
    // 3: the prisms of each row's strip, two a cell
    let surface = |r: i64, c: i64| field.sample(r as usize, c as usize);
    let start = touches.len();
    let mut corners = [Vec3::zeros(); 6];
    'strips: for r in r_min..r_max {
        for row in [r + 1, r] {
            slide_in(&mut corners, surface(row, c_min), base);
        }
        for c in c_min + 1..=c_max {
            for row in [r + 1, r] {
                slide_in(&mut corners, surface(row, c), base);
                // a top wholly below the geom, by more than the margin, touches nothing
                if corners[3..].iter().all(|v| v.z + margin < z_min) {
                    continue;
                }
                let prism = Body {
                    kind: Kind::Prism { corners: &corners },
                    rotation: Mat3::identity(),
                    position: Vec3::zeros(),
                    inflation: 0.0,
                };
                push_touches(&prism, &geom, margin, touches);
                if touches.len() - start >= MAX_CONTACTS {
                    break 'strips;
                }
            }
        }
    }
    // back in the world: n = R_f n', p = R_f p' + p_f
    for touch in &mut touches[start..] {
        touch.normal = first.rotation * touch.normal;
        touch.position = first.rotation * touch.position + first.position;
    }
}

#[cfg(test)]
mod tests {
    use super::super::TOLERANCE;
    use super::*;
    use crate::collision::height_field::HeightField;
    use std::sync::Arc;

    /// A field of `rows × columns` samples of `height(x, y)` over [−1, 1]², top 1, base 0.5.
    fn field(rows: usize, columns: usize, height: impl Fn(f64, f64) -> f64) -> Shape {
        let mut samples = Vec::new();
        for r in 0..rows {
            for c in 0..columns {
                let x = -1.0 + 2.0 * c as f64 / (columns - 1) as f64;
                let y = -1.0 + 2.0 * r as f64 / (rows - 1) as f64;
                samples.push(height(x, y) as f32);
            }
        }
        let field = HeightField::new([1.0, 1.0, 1.0, 0.5], rows, columns, &samples).unwrap();
        Shape::HeightField {
            field: Arc::new(field),
        }
    }

    fn touches(field: &Shape, shape: &Shape, at: Vec3, margin: f64) -> Vec<Touch> {
        let placed_field = Placed {
            shape: field,
            rotation: Mat3::identity(),
            position: Vec3::zeros(),
        };
        let geom = Placed {
            shape,
            rotation: Mat3::identity(),
            position: at,
        };
        let mut found = Vec::new();
        height_field_convex(&placed_field, &geom, margin, &mut found);
        found
    }

    #[test]
    fn a_sphere_on_a_slope_touches_it_along_its_normal() {
        // z = 0.2 + 0.1 x: the samples span [0.1, 0.3], scaled to [0, 1] (top 1)
        let slope = field(5, 7, |x, _| 0.2 + 0.1 * x);
        let sphere = Shape::Sphere { radius: 0.2 };
        // the surface after scaling: z = (0.1 x + 0.1)/0.2 = 0.5 x + 0.5
        let surface = |x: f64| 0.5 * x + 0.5;
        let steep = Vec3::new(-0.5, 0.0, 1.0).normalize();
        for depth in [0.001, 0.03] {
            let point = Vec3::new(0.1, 0.2, surface(0.1));
            let centre = point + steep * (0.2 - depth);
            let found = touches(&slope, &sphere, centre, 0.0);
            // one contact a prism the sphere reaches into; the deepest through the surface
            assert!(!found.is_empty());
            let touch = *found
                .iter()
                .min_by(|a, b| a.distance.total_cmp(&b.distance))
                .unwrap();
            // GJK and EPA stop within their tolerance
            assert!((touch.distance + depth).abs() < TOLERANCE, "{touch:?}");
            assert!((touch.normal - steep).norm() < TOLERANCE, "{touch:?}");
            let midway = point - steep * (0.5 * depth);
            assert!((touch.position - midway).norm() < TOLERANCE, "{touch:?}");
        }
        // above the surface by more than the margin: nothing; within it: a positive distance
        let above = Vec3::new(0.1, 0.2, surface(0.1)) + steep * 0.205;
        assert!(touches(&slope, &sphere, above, 0.0).is_empty());
        let near = touches(&slope, &sphere, above, 0.01);
        let nearest = near
            .iter()
            .map(|t| t.distance)
            .fold(f64::INFINITY, f64::min);
        assert!((nearest - 0.005).abs() < TOLERANCE, "{near:?}");
        // beyond the field's edge: nothing
        assert!(touches(&slope, &sphere, Vec3::new(1.5, 0.0, 0.5), 0.0).is_empty());
    }

    #[test]
    fn a_pair_has_at_most_fifty_contacts() {
        // a wide box sunk into a fine bumpy field touches every prism under it
        let bumps = field(21, 21, |x, y| 0.05 * (7.0 * x).sin() * (5.0 * y).cos());
        let slab = Shape::Box {
            half_extents: Vec3::new(0.9, 0.9, 0.1),
        };
        let found = touches(&bumps, &slab, Vec3::new(0.0, 0.0, 0.55), 0.0);
        assert_eq!(found.len(), MAX_CONTACTS);
        assert!(found.iter().all(|t| t.distance < 0.0));
    }
}
