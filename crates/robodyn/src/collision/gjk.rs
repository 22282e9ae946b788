//! Distance and penetration of two convex shapes known only by their support functions.
//!
//! References: E. G. Gilbert, D. W. Johnson, S. S. Keerthi, "A fast procedure for computing the
//! distance between complex objects in three-dimensional space", IEEE J. Robotics and Automation
//! 4(2), 1988 (GJK); M. Montanari, N. Petrinic, E. Barbieri, "Improving the GJK algorithm for
//! faster and more reliable distance queries between convex objects", ACM TOG 36(3), 2017 (the
//! signed-volume sub-algorithm); G. van den Bergen, "Proximity queries and penetration depth
//! computation on 3D game objects", GDC 2001 (EPA); and MuJoCo's documentation, "Computation",
//! §Collision detection, whose native pipeline ("nativeccd") fixes the choices made here:
//! starting points, stopping rules, the initial polytopes, tolerance and iteration count.
//!
//! Everything happens in the Minkowski difference `A − B`: a vertex `w = a − b` remembers the
//! points `a ∈ A`, `b ∈ B` it came from, so that the closest point of `A − B` to the origin gives
//! the witness points on each shape by the same barycentric weights.

use crate::spatial::Vec3;
pub use epa::{epa, Penetration};

mod epa;

/// Below this a length counts as zero (MuJoCo's `mjMINVAL`).
pub const TINY: f64 = 1e-15;

/// EPA's vertex budget beyond the iterations (the starting polytope has at most five).
const EXTRA_VERTICES: usize = 5;

/// The most iterations a polytope has room for.
pub const MAX_ITERATIONS: usize = 35;

/// A convex shape as GJK sees it.
pub trait Convex {
    /// The shape's point farthest along `direction` (not always a unit vector: the supports
    /// scale as MuJoCo's do) and a tag of the feature it lies on (−1: none).
    fn support(&self, direction: &Vec3) -> (Vec3, i32);
    /// A point inside the shape, where the search starts.
    fn centre(&self) -> Vec3;
}

/// A point of the Minkowski difference `A − B` and the points of A and B it is made of.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Vertex {
    /// `a − b`.
    pub point: Vec3,
    /// The point of A.
    pub on_first: Vec3,
    /// The point of B.
    pub on_second: Vec3,
    /// The feature tags of `a` and `b` (see [`Convex::support`]).
    pub tags: [i32; 2],
}

/// `S_{A−B}(d) = S_A(d) − S_B(−d)`.
fn support_of_difference(a: &impl Convex, b: &impl Convex, direction: &Vec3) -> Vertex {
    let (on_first, tag_first) = a.support(direction);
    let (on_second, tag_second) = b.support(&-direction);
    Vertex {
        point: on_first - on_second,
        on_first,
        on_second,
        tags: [tag_first, tag_second],
    }
}

/// `v₁·v₂`, summed left to right.
#[inline]
fn dot(v1: &Vec3, v2: &Vec3) -> f64 {
    v1.x * v2.x + v1.y * v2.y + v1.z * v2.z
}

/// `v₁·(v₂ × v₃)`, the determinant of the columns v₁, v₂, v₃.
#[inline]
fn determinant(v1: &Vec3, v2: &Vec3, v3: &Vec3) -> f64 {
    v1.x * (v2.y * v3.z - v2.z * v3.y)
        + v1.y * (v2.z * v3.x - v2.x * v3.z)
        + v1.z * (v2.x * v3.y - v2.y * v3.x)
}

/// `Σ λᵢ vᵢ` over the first `weights.len()` points.
fn combine<'a>(weights: &[f64], points: impl Iterator<Item = &'a Vec3>) -> Vec3 {
    let mut sum = Vec3::zeros();
    for (index, (weight, point)) in weights.iter().zip(points).enumerate() {
        sum = if index == 0 {
            point * *weight
        } else {
            sum + point * *weight
        };
    }
    sum
}

/// Both positive or both negative.
#[inline]
fn same_sign(a: f64, b: f64) -> bool {
    (a > 0.0 && b > 0.0) || (a < 0.0 && b < 0.0)
}

/// The origin projected on the plane through `v1`, `v2`, `v3`: `n (n·v)/(n·n)` for a normal n
/// (tried from each corner in turn); `None` for a degenerate triangle.
fn project_on_plane(v1: &Vec3, v2: &Vec3, v3: &Vec3) -> Option<Vec3> {
    let (e21, e31, e32) = (v2 - v1, v3 - v1, v3 - v2);
    let tries = [
        (e32.cross(&e21), v2),
        (e21.cross(&e31), v1),
        (e31.cross(&e32), v3),
    ];
    for (attempt, (normal, corner)) in tries.iter().enumerate() {
        let (along, square) = (dot(normal, corner), dot(normal, normal));
        if square == 0.0 {
            return None;
        }
        if attempt == 2 || (along != 0.0 && square > TINY) {
            return Some(normal * (along / square));
        }
    }
    None
}

/// Barycentric weights of the point of segment `s1 s2` nearest the origin (signed volumes:
/// the segment's longest shadow on a coordinate axis).
fn nearest_on_segment(s1: &Vec3, s2: &Vec3) -> [f64; 2] {
    let edge = s2 - s1;
    let square = dot(&edge, &edge);
    if square < TINY * TINY {
        return [0.0, 1.0];
    }
    let projected = edge * (-dot(s2, &edge) / square) + s2;
    let mut axis = 0;
    let mut extent = s1[0] - s2[0];
    for k in 1..3 {
        let candidate = s1[k] - s2[k];
        if candidate.abs() >= extent.abs() {
            extent = candidate;
            axis = k;
        }
    }
    let c1 = projected[axis] - s2[axis];
    let c2 = s1[axis] - projected[axis];
    match (same_sign(extent, c1), same_sign(extent, c2)) {
        (true, true) => [c1 / extent, c2 / extent],
        (true, false) => [1.0, 0.0],
        _ => [0.0, 1.0],
    }
}

/// The sub-areas of the triangle `s1 s2 s3` seen from `p` in its plane — `(p s2 s3)`,
/// `(p s3 s1)`, `(p s1 s2)` — in the coordinate plane of the triangle's largest shadow, and
/// the triangle's own area there.
fn sub_areas(s1: &Vec3, s2: &Vec3, s3: &Vec3, p: &Vec3) -> ([f64; 3], f64) {
    let (e2, e3) = (s2 - s1, s3 - s1);
    let shadows = [
        e3.z * e2.y - e2.z * e3.y,
        e3.z * e2.x - e2.z * e3.x,
        e2.x * e3.y - e2.y * e3.x,
    ];
    let [m1, m2, m3] = shadows.map(f64::abs);
    let ((u, v), area) = if m1 >= m2 && m1 >= m3 {
        ((1, 2), shadows[0])
    } else if m2 >= m3 {
        ((0, 2), shadows[1])
    } else {
        ((0, 1), shadows[2])
    };
    let (a, b, c) = (s1 - p, s2 - p, s3 - p);
    let areas = [
        c[v] * b[u] - c[u] * b[v],
        c[u] * a[v] - a[u] * c[v],
        a[u] * b[v] - b[u] * a[v],
    ];
    (areas, area)
}

/// Barycentric coordinates of `p` (in the triangle's plane) on the triangle `s1 s2 s3`.
fn triangle_coordinates(s1: &Vec3, s2: &Vec3, s3: &Vec3, p: &Vec3) -> [f64; 3] {
    let (areas, _) = sub_areas(s1, s2, s3, p);
    let total = areas[0] + areas[1] + areas[2];
    areas.map(|a| a / total)
}

/// Barycentric weights of the point of triangle `s1 s2 s3` nearest the origin: inside when the
/// projection's sub-areas share the triangle's sign, otherwise the nearest of the edges opposite
/// the corners that fail (all three for a degenerate triangle).
fn nearest_on_triangle(s1: &Vec3, s2: &Vec3, s3: &Vec3) -> [f64; 3] {
    let mut inside = [false; 3];
    if let Some(projected) = project_on_plane(s1, s2, s3) {
        let (areas, area) = sub_areas(s1, s2, s3, &projected);
        inside = areas.map(|sub| same_sign(area, sub));
        if inside.iter().all(|&b| b) {
            let total = areas[0] + areas[1] + areas[2];
            return areas.map(|sub| sub / total);
        }
    }
    let corners = [s1, s2, s3];
    let mut best = [0.0; 3];
    let mut nearest = f64::MAX;
    for (dropped, &holds) in inside.iter().enumerate() {
        if holds {
            continue;
        }
        let (first, second) = if dropped == 0 {
            (1, 2)
        } else {
            (0, 3 - dropped)
        };
        let weights = nearest_on_segment(corners[first], corners[second]);
        let point = corners[first] * weights[0] + corners[second] * weights[1];
        let distance = dot(&point, &point);
        if distance < nearest {
            nearest = distance;
            best = [0.0; 3];
            best[first] = weights[0];
            best[second] = weights[1];
        }
    }
    best
}

/// Barycentric weights of the point of tetrahedron `s` nearest the origin: inside when the
/// cofactors share the sign of the volume, otherwise the nearest of the faces that fail.
fn nearest_on_tetrahedron(s: [&Vec3; 4]) -> [f64; 4] {
    let cofactors = [
        -determinant(s[1], s[2], s[3]),
        determinant(s[0], s[2], s[3]),
        -determinant(s[0], s[1], s[3]),
        determinant(s[0], s[1], s[2]),
    ];
    let volume = cofactors[0] + cofactors[1] + cofactors[2] + cofactors[3];
    let inside = cofactors.map(|c| same_sign(volume, c));
    if inside.iter().all(|&b| b) {
        return cofactors.map(|c| c / volume);
    }
    let mut best = [0.0; 4];
    let mut nearest = f64::MAX;
    for (dropped, &holds) in inside.iter().enumerate() {
        if holds {
            continue;
        }
        let kept: [usize; 3] = match dropped {
            0 => [1, 2, 3],
            1 => [0, 2, 3],
            2 => [0, 1, 3],
            _ => [0, 1, 2],
        };
        let weights = nearest_on_triangle(s[kept[0]], s[kept[1]], s[kept[2]]);
        let point = s[kept[0]] * weights[0] + s[kept[1]] * weights[1] + s[kept[2]] * weights[2];
        let distance = dot(&point, &point);
        if distance < nearest {
            nearest = distance;
            best = [0.0; 4];
            for (slot, weight) in kept.iter().zip(weights) {
                best[*slot] = weight;
            }
        }
    }
    best
}

/// Barycentric weights of the point of the simplex nearest the origin.
fn nearest_on_simplex(simplex: &[Vertex]) -> [f64; 4] {
    let p = |k: usize| &simplex[k].point;
    match simplex.len() {
        4 => nearest_on_tetrahedron([p(0), p(1), p(2), p(3)]),
        3 => {
            let [a, b, c] = nearest_on_triangle(p(0), p(1), p(2));
            [a, b, c, 0.0]
        }
        2 => {
            let [a, b] = nearest_on_segment(p(0), p(1));
            [a, b, 0.0, 0.0]
        }
        _ => [1.0, 0.0, 0.0, 0.0],
    }
}

/// What GJK leaves: the last simplex, and either the shapes' distance with its witness points,
/// or that they overlap (distance 0).
#[derive(Debug, Clone, Copy)]
pub struct Proximity {
    /// The simplex, `len` vertices.
    pub simplex: [Vertex; 4],
    /// Its vertices.
    pub len: usize,
    /// The shapes are certainly apart.
    pub separated: bool,
    /// The distance found (0: overlapping, `f64::MAX`: apart beyond the cut-off).
    pub distance: f64,
    /// The nearest points on A and on B (meaningful when `distance` is a distance).
    pub witness: [Vec3; 2],
}

/// The settings of a query: tolerance on lengths, iteration budget, and `cutoff` (> 0: the
/// distance is wanted up to this much, beyond which the shapes count as apart; 0: only whether
/// they overlap).
#[derive(Debug, Clone, Copy)]
pub struct Query {
    /// Convergence tolerance on lengths (MuJoCo's `ccd_tolerance`).
    pub tolerance: f64,
    /// Iteration budget of GJK and of EPA (MuJoCo's `ccd_iterations`).
    pub iterations: usize,
    /// See the type's doc.
    pub cutoff: f64,
    /// Both shapes are polytopes without margins (boxes, meshes, a height field's prisms):
    /// GJK and EPA run to exact convergence (MuJoCo's "discrete geoms"), and EPA stops at a
    /// support point whose two feature tags it has met before.
    pub discrete: bool,
}

/// GJK from the points `start` of A and B: iterate `x ← nearest point of conv{simplex}` towards
/// the origin, adding `S_{A−B}(−x)` each step, until the Frank–Wolfe gap `x·(x − s)` is below
/// ½ tol², x stalls or vanishes, or the simplex encloses the origin. A support point with
/// `x·s > 0` proves the shapes apart: without a cut-off the search stops there; with one it
/// stops once `x·s/|x|` exceeds the cut-off.
pub fn gjk(a: &impl Convex, b: &impl Convex, start: [Vec3; 2], query: &Query) -> Proximity {
    let wants_distance = query.cutoff > 0.0;
    let epsilon = if query.discrete {
        0.0
    } else {
        0.5 * query.tolerance * query.tolerance
    };
    let least_norm = if wants_distance || query.discrete {
        TINY
    } else {
        query.tolerance
    };
    let apart = Proximity {
        simplex: [Vertex::default(); 4],
        len: 0,
        separated: true,
        distance: f64::MAX,
        witness: start,
    };
    let mut simplex = [Vertex::default(); 4];
    let mut len = 0;
    let mut weights = [1.0, 0.0, 0.0, 0.0];
    let mut separated = false;
    let mut x = start[0] - start[1];
    let mut x_norm = x.norm();
    if x_norm < TINY {
        x = Vec3::x();
        x_norm = 1.0;
    }
    let mut distance = x_norm;
    for k in 0..query.iterations {
        // the support point against x: S(−x/|x|)
        simplex[len] = support_of_difference(a, b, &(x * (1.0 / x_norm) * -1.0));
        let s = simplex[len].point;
        // x·s / |x| bounds the distance from below
        let lower = dot(&x, &s);
        if lower > 0.0 {
            if !wants_distance {
                return apart;
            }
            separated = true;
            if query.cutoff < f64::MAX && lower >= query.cutoff * x_norm {
                return apart;
            }
        }
        if k > 0 && dot(&x, &(x - s)) < epsilon {
            break;
        }
        // keep the vertices that carry the nearest point
        let all = nearest_on_simplex(&simplex[..len + 1]);
        len = 0;
        for i in 0..4 {
            if all[i] != 0.0 {
                simplex[len] = simplex[i];
                weights[len] = all[i];
                len += 1;
            }
        }
        if len == 0 {
            return apart;
        }
        if len == 4 {
            distance = if separated { x_norm } else { 0.0 };
            break;
        }
        let next = nearest_point(&simplex[..len], &weights[..len]);
        let next_norm = next.norm();
        x = next;
        distance = next_norm;
        let least = if len == 1 { TINY } else { least_norm };
        if next_norm < least || (k > 0 && (next_norm - x_norm).abs() < TINY) {
            break;
        }
        x_norm = next_norm;
    }
    let witness = [
        combine(&weights[..len], simplex[..len].iter().map(|v| &v.on_first)),
        combine(&weights[..len], simplex[..len].iter().map(|v| &v.on_second)),
    ];
    // a last look along −x: a support point beyond the origin proves them apart
    if len <= 3 && !separated && distance >= TINY {
        let probe = support_of_difference(a, b, &(x * (1.0 / distance) * -1.0));
        separated = dot(&x, &probe.point) > 0.0;
    }
    Proximity {
        simplex,
        len,
        separated,
        distance,
        witness,
    }
}

/// The point of the simplex's hull nearest the origin, given its barycentric weights: the
/// origin projected on the simplex's line or plane (more accurate than the weighted sum, which
/// serves when the simplex is degenerate).
fn nearest_point(simplex: &[Vertex], weights: &[f64]) -> Vec3 {
    let p = |k: usize| simplex[k].point;
    let weighted = || combine(weights, simplex.iter().map(|v| &v.point));
    match simplex.len() {
        1 => p(0) * weights[0],
        2 => {
            let edge = p(1) - p(0);
            let square = dot(&edge, &edge);
            if square < TINY * TINY {
                weighted()
            } else {
                edge * (-dot(&p(1), &edge) / square) + p(1)
            }
        }
        _ => project_on_plane(&p(0), &p(1), &p(2)).unwrap_or_else(weighted),
    }
}
