//! OBJ polygons cut into triangles the way MuJoCo's OBJ reader (tinyobjloader, `triangulate`
//! on, its built-in method) cuts them, so that a non-planar polygon encloses the same volume:
//!
//! - a quad is split along its shorter diagonal: (0 1 2)(0 2 3) when |p₂ − p₀| < |p₃ − p₁|,
//!   else (0 1 3)(1 2 3);
//! - a larger polygon is projected onto two coordinate axes (those of the first non-degenerate
//!   corner's normal: dropping x when |n_x| is the largest component, else y, or z when |n_z| is),
//!   then ears are clipped: starting at corner g, the triangle (g, g+1, g+2) is an ear when its
//!   turn e₀ × e₁ has the sign of the area term ½(x₀y₁ − y₀x₁) and no other remaining corner lies
//!   inside it (even–odd rule); an ear is emitted and its middle corner removed, otherwise g moves
//!   on. After as many failures in a row as corners remain, the rest of the polygon is dropped.
//!
//! The arithmetic is single precision, as the reader's; the file's coordinates are float32.

/// A polygon's triangles, as corner indices into `polygon`'s entries (which index `positions`,
/// three float32 per vertex).
pub fn triangulate(positions: &[f32], polygon: &[u32], triangles: &mut Vec<[u32; 3]>) {
    let point = |v: u32| {
        let i = 3 * v as usize;
        [positions[i], positions[i + 1], positions[i + 2]]
    };
    match polygon.len() {
        0..=2 => {}
        3 => triangles.push([polygon[0], polygon[1], polygon[2]]),
        4 => {
            let [a, b, c, d] = [polygon[0], polygon[1], polygon[2], polygon[3]];
            if squared_distance(point(a), point(c)) < squared_distance(point(b), point(d)) {
                triangles.extend([[a, b, c], [a, c, d]]);
            } else {
                triangles.extend([[a, b, d], [b, c, d]]);
            }
        }
        _ => clip_ears(&point, polygon, triangles),
    }
}

fn squared_distance(p: [f32; 3], q: [f32; 3]) -> f32 {
    let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
}

/// The two coordinate axes a polygon is projected on: from the normal of its first corner that
/// turns (|e₀ × e₁| above float epsilon in some component).
fn projection_axes(point: &impl Fn(u32) -> [f32; 3], polygon: &[u32]) -> [usize; 2] {
    let n = polygon.len();
    for k in 0..n {
        let [p0, p1, p2] = [0, 1, 2].map(|j| point(polygon[(k + j) % n]));
        let e0 = [p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]];
        let e1 = [p2[0] - p1[0], p2[1] - p1[1], p2[2] - p1[2]];
        let cx = (e0[1] * e1[2] - e0[2] * e1[1]).abs();
        let cy = (e0[2] * e1[0] - e0[0] * e1[2]).abs();
        let cz = (e0[0] * e1[1] - e0[1] * e1[0]).abs();
        if cx > f32::EPSILON || cy > f32::EPSILON || cz > f32::EPSILON {
            return if cx > cy && cx > cz {
                [1, 2]
            } else if cz > cx && cz > cy {
                [0, 1]
            } else {
                [0, 2]
            };
        }
    }
    [1, 2]
}

/// Ear clipping in the projection plane (see the module's description).
fn clip_ears(point: &impl Fn(u32) -> [f32; 3], polygon: &[u32], triangles: &mut Vec<[u32; 3]>) {
    let [ax, ay] = projection_axes(point, polygon);
    let planar = |v: u32| {
        let p = point(v);
        (p[ax], p[ay])
    };
    let mut remaining = polygon.to_vec();
    let mut guess = 0;
    let mut tries_left = remaining.len();
    let mut previous_len = remaining.len();
    while remaining.len() > 3 && tries_left > 0 {
        let n = remaining.len();
        if guess >= n {
            guess -= n;
        }
        // a removed corner resets the count of tries
        if previous_len != n {
            previous_len = n;
            tries_left = n;
        } else {
            tries_left -= 1;
        }
        let corners = [0, 1, 2].map(|k| remaining[(guess + k) % n]);
        let [(x0, y0), (x1, y1), (x2, y2)] = corners.map(planar);
        // turn e₀ × e₁ against the area term ½(x₀y₁ − y₀x₁)
        let turn = (x1 - x0) * (y2 - y1) - (y1 - y0) * (x2 - x1);
        let area = (x0 * y1 - y0 * x1) * 0.5;
        if turn * area < 0.0 {
            guess += 1;
            continue;
        }
        let xs = [x0, x1, x2];
        let ys = [y0, y1, y2];
        let holds_another = (3..n).any(|k| {
            let (x, y) = planar(remaining[(guess + k) % n]);
            inside_triangle(&xs, &ys, x, y)
        });
        if holds_another {
            guess += 1;
            continue;
        }
        triangles.push(corners);
        remaining.remove((guess + 1) % n);
    }
    if let [a, b, c] = remaining[..] {
        triangles.push([a, b, c]);
    }
}

/// Even–odd crossing test of (x, y) against a triangle's edges.
fn inside_triangle(xs: &[f32; 3], ys: &[f32; 3], x: f32, y: f32) -> bool {
    let mut inside = false;
    let mut j = 2;
    for i in 0..3 {
        if (ys[i] > y) != (ys[j] > y) && x < (xs[j] - xs[i]) * (y - ys[i]) / (ys[j] - ys[i]) + xs[i]
        {
            inside = !inside;
        }
        j = i;
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cut(positions: &[f32], polygon: &[u32]) -> Vec<[u32; 3]> {
        let mut triangles = Vec::new();
        triangulate(positions, polygon, &mut triangles);
        triangles
    }

    #[test]
    fn quad_is_split_along_its_shorter_diagonal() {
        // 0–2 is the long diagonal of this kite, 1–3 the short one
        let kite = [0.0, 0.0, 0.0, 1.0, -0.5, 0.0, 3.0, 0.0, 0.0, 1.0, 0.5, 0.0];
        assert_eq!(cut(&kite, &[0, 1, 2, 3]), vec![[0, 1, 3], [1, 2, 3]]);
        assert_eq!(cut(&kite, &[1, 2, 3, 0]), vec![[1, 2, 3], [1, 3, 0]]);
    }

    #[test]
    fn convex_pentagon_is_clipped_from_its_first_corner() {
        let pentagon: Vec<f32> = (0..5)
            .flat_map(|k| {
                let a = 2.0 * std::f32::consts::PI * k as f32 / 5.0;
                [a.cos() + 2.0, a.sin() + 2.0, 0.0]
            })
            .collect();
        assert_eq!(
            cut(&pentagon, &[0, 1, 2, 3, 4]),
            vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]
        );
    }

    #[test]
    fn concave_polygon_gets_no_triangle_outside_it() {
        // an L in the plane z = 1: the corner at index 3 is reflex
        let l_shape = [
            1.0, 1.0, 1.0, 3.0, 1.0, 1.0, 3.0, 2.0, 1.0, 2.0, 2.0, 1.0, 2.0, 3.0, 1.0, 1.0, 3.0,
            1.0,
        ];
        let triangles = cut(&l_shape, &[0, 1, 2, 3, 4, 5]);
        assert_eq!(triangles.len(), 4);
        let area = |t: &[u32; 3]| {
            let p = |v: u32| (l_shape[3 * v as usize], l_shape[3 * v as usize + 1]);
            let [(x0, y0), (x1, y1), (x2, y2)] = t.map(p);
            ((x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0)).abs() / 2.0
        };
        let total: f32 = triangles.iter().map(area).sum();
        assert!((total - 3.0).abs() < 1e-6, "area {total}");
    }
}
