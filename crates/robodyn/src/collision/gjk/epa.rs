//! The expanding polytope (EPA): how deep two overlapping convex shapes are, from the simplex
//! GJK ends with (see [`super`]'s header for the references).

use super::*;

/// A triangle of the expanding polytope.
#[derive(Debug, Clone, Copy, Default)]
struct Face {
    /// Its corners (indices into the vertices).
    corners: [usize; 3],
    /// The face across each edge `[c₀c₁]`, `[c₁c₂]`, `[c₂c₀]`.
    neighbours: [usize; 3],
    /// The origin projected on its plane, pointing out of the polytope.
    nearest: Vec3,
    /// `|nearest|²`.
    distance2: f64,
    /// Its place in the candidate list; `None` when not listed; `deleted` when gone.
    listed: Option<usize>,
    /// Removed from the polytope.
    deleted: bool,
}

/// The expanding polytope: vertices, faces, the faces still candidates for the nearest one, and
/// the horizon seen from a new vertex.
struct Polytope {
    vertices: [Vertex; MAX_ITERATIONS + EXTRA_VERTICES],
    vertex_count: usize,
    faces: [Face; 6 * MAX_ITERATIONS],
    face_count: usize,
    candidates: [usize; 6 * MAX_ITERATIONS],
    candidate_count: usize,
    centre: Vec3,
    horizon: [(usize, usize); HORIZON],
    horizon_len: usize,
    overflow: bool,
}

/// The most edges a horizon may have (MuJoCo's buffer for it).
const HORIZON: usize = 24;

impl Polytope {
    fn new() -> Self {
        Polytope {
            vertices: [Vertex::default(); MAX_ITERATIONS + EXTRA_VERTICES],
            vertex_count: 0,
            faces: [Face::default(); 6 * MAX_ITERATIONS],
            face_count: 0,
            candidates: [0; 6 * MAX_ITERATIONS],
            candidate_count: 0,
            centre: Vec3::zeros(),
            horizon: [(0, 0); HORIZON],
            horizon_len: 0,
            overflow: false,
        }
    }

    fn add_vertex(&mut self, vertex: Vertex) -> usize {
        self.vertices[self.vertex_count] = vertex;
        self.vertex_count += 1;
        self.vertex_count - 1
    }

    /// The support vertex along `direction` (normalised; x when too short).
    fn add_support(
        &mut self,
        a: &impl Convex,
        b: &impl Convex,
        direction: &Vec3,
        length: f64,
    ) -> usize {
        let unit = if length > TINY {
            Vec3::new(
                direction.x / length,
                direction.y / length,
                direction.z / length,
            )
        } else {
            Vec3::x()
        };
        self.add_vertex(support_of_difference(a, b, &unit))
    }

    /// Appends the face `c₀ c₁ c₂` with its neighbours; returns its squared distance to the
    /// origin (0 for a degenerate face).
    fn add_face(&mut self, corners: [usize; 3], neighbours: [usize; 3]) -> f64 {
        let p = |k: usize| self.vertices[corners[k]].point;
        let mut face = Face {
            corners,
            neighbours,
            ..Face::default()
        };
        if let Some(nearest) = project_on_plane(&p(2), &p(1), &p(0)) {
            let outward = p(0) - self.centre;
            face.nearest = if dot(&nearest, &outward) < 0.0 {
                -nearest
            } else {
                nearest
            };
            face.distance2 = dot(&face.nearest, &face.nearest);
        }
        self.faces[self.face_count] = face;
        self.face_count += 1;
        face.distance2
    }

    /// Lists every face as a candidate.
    fn list_all(&mut self) {
        for i in 0..self.face_count {
            self.candidates[i] = i;
            self.faces[i].listed = Some(i);
        }
        self.candidate_count = self.face_count;
    }

    /// Lists the last face added.
    fn list_last(&mut self) {
        let face = self.face_count - 1;
        self.candidates[self.candidate_count] = face;
        self.faces[face].listed = Some(self.candidate_count);
        self.candidate_count += 1;
    }

    /// Removes a face from the polytope and from the candidates.
    fn delete(&mut self, face: usize) {
        if let Some(slot) = self.faces[face].listed {
            self.candidate_count -= 1;
            let moved = self.candidates[self.candidate_count];
            self.candidates[slot] = moved;
            self.faces[moved].listed = Some(slot);
        }
        self.faces[face].listed = None;
        self.faces[face].deleted = true;
    }

    /// The edge of `face` that starts at vertex `corner`.
    fn edge_from(&self, face: usize, corner: usize) -> usize {
        let corners = self.faces[face].corners;
        if corners[0] == corner {
            0
        } else if corners[1] == corner {
            1
        } else {
            2
        }
    }

    /// Adds an edge to the horizon (or notes that it has no room).
    fn add_edge(&mut self, face: usize, edge: usize) {
        if self.horizon_len < HORIZON {
            self.horizon[self.horizon_len] = (face, edge);
            self.horizon_len += 1;
        } else {
            self.overflow = true;
        }
    }

    /// Deletes `face` if `w` sees it, then looks across its two other edges; returns whether it
    /// was seen. Edges between a seen and an unseen face make the horizon.
    fn carve(&mut self, face: usize, entry: usize, w: &Vec3) -> bool {
        // seen when w lies beyond the face's plane, by a margin relative to its distance
        let seen = &self.faces[face];
        let margin = (seen.distance2.sqrt() * TINY).max(TINY);
        if dot(&seen.nearest, w) - seen.distance2 <= margin {
            return false;
        }
        let (corners, neighbours) = (seen.corners, seen.neighbours);
        self.delete(face);
        for step in 1..3 {
            let edge = (entry + step) % 3;
            let across = neighbours[edge];
            if !self.faces[across].deleted {
                let across_edge = self.edge_from(across, corners[(edge + 1) % 3]);
                if !self.carve(across, across_edge, w) {
                    self.add_edge(across, across_edge);
                }
            }
        }
        true
    }

    /// The horizon seen from `w` beyond `face`: `face` goes, then its neighbours recursively.
    fn horizon_from(&mut self, face: usize, w: &Vec3) {
        let (corners, neighbours) = (self.faces[face].corners, self.faces[face].neighbours);
        self.delete(face);
        for edge in 0..3 {
            let across = neighbours[edge];
            if self.faces[across].deleted {
                continue;
            }
            let across_edge = self.edge_from(across, corners[(edge + 1) % 3]);
            if !self.carve(across, across_edge, w) {
                self.add_edge(across, across_edge);
            }
        }
    }
}

/// What EPA finds: the penetration (negative distance), its witness points on A and B, and the
/// face of A − B nearest the origin.
#[derive(Debug, Clone, Copy)]
pub struct Penetration {
    /// `−depth`.
    pub distance: f64,
    /// The deepest points of A in B and of B in A.
    pub witness: [Vec3; 2],
    /// The three vertices of the face.
    pub face: [Vertex; 3],
}

/// Builds EPA's starting polytope from GJK's simplex, then expands it: take the face nearest the
/// origin, add the support point `w` along its normal, replace the faces `w` sees by a fan from
/// `w` to their horizon; stop when the support's bound `n̂·w` is within the tolerance of the
/// face's distance. `None` when the shapes only touch or the numbers give out.
pub fn epa(
    a: &impl Convex,
    b: &impl Convex,
    proximity: &Proximity,
    query: &Query,
) -> Option<Penetration> {
    let mut polytope = Polytope::new();
    let built = match proximity.len {
        2 => from_segment(&mut polytope, a, b, proximity, query.tolerance),
        3 => from_triangle(&mut polytope, a, b, proximity.simplex, query.tolerance),
        _ => from_tetrahedron(&mut polytope, a, b, proximity, query.tolerance),
    };
    if !built {
        return None;
    }
    expand(&mut polytope, a, b, query)
}

/// The expansion loop of [`epa`].
fn expand(
    polytope: &mut Polytope,
    a: &impl Convex,
    b: &impl Convex,
    query: &Query,
) -> Option<Penetration> {
    let mut upper = f64::MAX;
    let mut upper2 = f64::MAX;
    let mut best: Option<usize> = None;
    // polytopes converge in finitely many steps: a tolerance of TINY only avoids absurd bounds
    let tolerance = if query.discrete {
        TINY
    } else {
        query.tolerance
    };
    for k in 0..query.iterations.min(MAX_ITERATIONS) {
        let previous = best;
        // the candidate nearest the origin bounds the depth from below
        let mut lower2 = f64::MAX;
        for &face in &polytope.candidates[..polytope.candidate_count] {
            if polytope.faces[face].distance2 < lower2 {
                lower2 = polytope.faces[face].distance2;
                best = Some(face);
            }
        }
        if lower2 > upper2 || best.is_none() {
            best = previous;
            break;
        }
        let face = best?;
        if lower2 <= 0.0 {
            break;
        }
        let lower = lower2.sqrt();
        let normal = polytope.faces[face].nearest;
        let w_index = polytope.add_support(a, b, &normal, lower);
        let w = polytope.vertices[w_index].point;
        // n·w / |n| bounds the depth from above
        let upper_k = dot(&normal, &w) / lower;
        let bound = upper_k.min(upper);
        if upper_k - lower < tolerance {
            if k == 0 && lower - tolerance > bound {
                best = None;
            }
            break;
        }
        // a polytope's support point met before (by its features' tags): nothing more to find
        let tags = polytope.vertices[w_index].tags;
        if query.discrete && polytope.vertices[..w_index].iter().any(|v| v.tags == tags) {
            break;
        }
        if upper_k < upper {
            upper2 = upper_k * upper_k;
        }
        upper = bound;
        polytope.horizon_len = 0;
        polytope.horizon_from(face, &w);
        let edges = polytope.horizon_len;
        if edges < 3 || polytope.overflow {
            best = None;
            break;
        }
        if edges > polytope.faces.len() - polytope.face_count {
            break;
        }
        // the fan from w to the horizon, each face between its two neighbours in the fan
        let first_new = polytope.face_count;
        for i in 0..edges {
            let (across, edge) = polytope.horizon[i];
            let corners = polytope.faces[across].corners;
            let (v1, v2) = (corners[edge], corners[(edge + 1) % 3]);
            polytope.faces[across].neighbours[edge] = first_new + i;
            let before = if i == 0 {
                first_new + edges - 1
            } else {
                first_new + i - 1
            };
            let after = first_new + (i + 1) % edges;
            let distance2 = polytope.add_face([w_index, v2, v1], [before, across, after]);
            if distance2 == 0.0 {
                polytope.candidate_count = 0;
                break;
            }
            if distance2 >= lower2 && distance2 <= upper2 {
                polytope.list_last();
            }
        }
        if polytope.candidate_count == 0 || best.is_none() {
            break;
        }
    }
    let face = polytope.faces[best?];
    let corner = |k: usize| polytope.vertices[face.corners[k]];
    let vertices = [corner(0), corner(1), corner(2)];
    let weights = triangle_coordinates(
        &vertices[0].point,
        &vertices[1].point,
        &vertices[2].point,
        &face.nearest,
    );
    Some(Penetration {
        distance: -face.distance2.sqrt(),
        witness: [
            combine(&weights, vertices.iter().map(|v| &v.on_first)),
            combine(&weights, vertices.iter().map(|v| &v.on_second)),
        ],
        face: vertices,
    })
}

/// Squared distances below these mean the origin lies on a face of the starting polytope.
const ON_FACE: f64 = TINY * TINY;

/// Whether the origin and `p3` lie strictly on the same side of the plane of `p0 p1 p2`.
fn same_side(p0: &Vec3, p1: &Vec3, p2: &Vec3, p3: &Vec3) -> bool {
    let normal = (p1 - p0).cross(&(p2 - p0));
    let (to_p3, to_origin) = (dot(&normal, &(p3 - p0)), dot(&normal, &(p0 * -1.0)));
    (to_p3 > 0.0 && to_origin > 0.0) || (to_p3 < 0.0 && to_origin < 0.0)
}

/// Whether the origin lies inside the tetrahedron.
fn encloses_origin(p: [&Vec3; 4]) -> bool {
    same_side(p[0], p[1], p[2], p[3])
        && same_side(p[1], p[2], p[3], p[0])
        && same_side(p[2], p[3], p[0], p[1])
        && same_side(p[3], p[0], p[1], p[2])
}

/// Starting polytope from a segment `v1 v2` through (or near) the origin: three support points
/// around it, 120° apart, and the hexahedron of the six triangles they make with its ends. A
/// triangle through the origin restarts from that triangle.
fn from_segment(
    polytope: &mut Polytope,
    a: &impl Convex,
    b: &impl Convex,
    proximity: &Proximity,
    tolerance: f64,
) -> bool {
    let (v1, v2) = (proximity.simplex[0], proximity.simplex[1]);
    polytope.centre = (v1.point + v2.point) * 0.5;
    let axis = v2.point - v1.point;
    // the coordinate axis most across the segment
    let mut least = f64::MAX;
    let mut across = Vec3::zeros();
    for k in 0..3 {
        if axis[k].abs() < least {
            least = axis[k].abs();
            across = Vec3::zeros();
            across[k] = 1.0;
        }
    }
    let d1 = across.cross(&axis);
    let turn = third_turn(&axis);
    let d2 = multiply(&turn, &d1);
    let d3 = multiply(&turn, &d2);
    let i1 = polytope.add_vertex(v1);
    let i2 = polytope.add_vertex(v2);
    let i3 = polytope.add_support(a, b, &d1, d1.norm());
    let i4 = polytope.add_support(a, b, &d2, d2.norm());
    let i5 = polytope.add_support(a, b, &d3, d3.norm());
    let hexahedron = [
        ([i1, i3, i4], [1, 3, 2]),
        ([i1, i5, i3], [2, 4, 0]),
        ([i1, i4, i5], [0, 5, 1]),
        ([i2, i4, i3], [5, 0, 4]),
        ([i2, i3, i5], [3, 1, 5]),
        ([i2, i5, i4], [4, 2, 3]),
    ];
    for (corners, neighbours) in hexahedron {
        if polytope.add_face(corners, neighbours) < ON_FACE {
            let triangle = corners.map(|c| polytope.vertices[c]);
            *polytope = Polytope::new();
            let mut simplex = [Vertex::default(); 4];
            simplex[..3].copy_from_slice(&triangle);
            return from_triangle(polytope, a, b, simplex, tolerance);
        }
    }
    let p = |i: usize| polytope.vertices[i].point;
    let volumes = ray_volumes(&p(i1), &p(i2), &p(i3), &p(i4), &p(i5));
    if !(volumes.iter().all(|&v| v >= 0.0) || volumes.iter().all(|&v| v <= 0.0)) {
        return false;
    }
    polytope.list_all();
    true
}

/// The rotation by 120° about `axis`.
fn third_turn(axis: &Vec3) -> [f64; 9] {
    let length = axis.norm();
    let (u1, u2, u3) = (axis.x / length, axis.y / length, axis.z / length);
    // sin 120° to the digits MuJoCo uses, cos 120° = −½
    let (s, c) = (0.86602540378, -0.5);
    [
        c + u1 * u1 * (1.0 - c),
        u1 * u2 * (1.0 - c) - u3 * s,
        u1 * u3 * (1.0 - c) + u2 * s,
        u2 * u1 * (1.0 - c) + u3 * s,
        c + u2 * u2 * (1.0 - c),
        u2 * u3 * (1.0 - c) - u1 * s,
        u1 * u3 * (1.0 - c) - u2 * s,
        u2 * u3 * (1.0 - c) + u1 * s,
        c + u3 * u3 * (1.0 - c),
    ]
}

/// `R v` for a row-major `R`.
fn multiply(r: &[f64; 9], v: &Vec3) -> Vec3 {
    Vec3::new(
        r[0] * v.x + r[1] * v.y + r[2] * v.z,
        r[3] * v.x + r[4] * v.y + r[5] * v.z,
        r[6] * v.x + r[7] * v.y + r[8] * v.z,
    )
}

/// The signed volumes of the tetrahedra the line from `v1` to `v2` makes with the edges of the
/// triangle `v3 v4 v5`: all of one sign when the line crosses it.
fn ray_volumes(v1: &Vec3, v2: &Vec3, v3: &Vec3, v4: &Vec3, v5: &Vec3) -> [f64; 3] {
    let (ray, to3, to4, to5) = (v2 - v1, v3 - v1, v4 - v1, v5 - v1);
    [
        determinant(&to3, &to4, &ray),
        determinant(&to4, &to5, &ray),
        determinant(&to5, &to3, &ray),
    ]
}

/// Whether `p` lies on the triangle `v1 v2 v3` (within [`TINY`]).
fn on_triangle(v1: &Vec3, v2: &Vec3, v3: &Vec3, p: &Vec3) -> bool {
    let weights = triangle_coordinates(v1, v2, v3, p);
    if weights.iter().any(|&w| w < 0.0) {
        return false;
    }
    let back = v1 * weights[0] + v2 * weights[1] + v3 * weights[2];
    (back - p).norm() < TINY
}

/// Starting polytope from a triangle: the support points on either side of it make a double
/// pyramid of six faces, which must hold the origin.
fn from_triangle(
    polytope: &mut Polytope,
    a: &impl Convex,
    b: &impl Convex,
    simplex: [Vertex; 4],
    tolerance: f64,
) -> bool {
    let (p1, p2, p3) = (simplex[0].point, simplex[1].point, simplex[2].point);
    let normal = (p2 - p1).cross(&(p3 - p1));
    let length = normal.norm();
    if length < TINY {
        return false;
    }
    let i1 = polytope.add_vertex(simplex[0]);
    let i2 = polytope.add_vertex(simplex[1]);
    let i3 = polytope.add_vertex(simplex[2]);
    let below = polytope.add_support(a, b, &(normal * -1.0), length);
    let above = polytope.add_support(a, b, &normal, length);
    let (p4, p5) = (
        polytope.vertices[above].point,
        polytope.vertices[below].point,
    );
    if on_triangle(&p1, &p2, &p3, &p4) || on_triangle(&p1, &p2, &p3, &p5) {
        return false;
    }
    // both apexes must stand off the triangle's plane
    let least = length * TINY;
    if least > dot(&normal, &(p4 - p1)) || least > dot(&(normal * -1.0), &(p5 - p1)) {
        return false;
    }
    let mut ids = [i1, i2, i3, above, below];
    let volumes = ray_volumes(&p4, &p5, &p1, &p2, &p3);
    let hits = volumes.iter().all(|&v| v >= 0.0) || volumes.iter().all(|&v| v <= 0.0);
    let within = tolerance * tolerance;
    if hits || relabel_double_pyramid(&mut ids, volumes) {
        double_pyramid(polytope, ids, within)
    } else {
        tetrahedron(polytope, [ids[0], ids[1], ids[3], ids[4]], within)
    }
}

/// When the segment between the apexes `p4 p5` misses the triangle, a relabelling of the five
/// points (by the signs of the volumes of [`ray_volumes`]) that makes a double pyramid through
/// which it passes, if there is one; otherwise `ids` keeps, first, the two triangle corners of
/// the tetrahedron to use instead.
fn relabel_double_pyramid(ids: &mut [usize; 5], [v1, v2, v3]: [f64; 3]) -> bool {
    let [c, x0, x1, x2, x3] = *ids;
    let negative = |v: f64| v < -TINY;
    if v1 > 0.0 && negative(v2) && negative(v3) {
        *ids = [x1, x3, x2, c, x0];
    } else if v2 > 0.0 && negative(v1) && negative(v3) {
        *ids = [c, x3, x2, x0, x1];
    } else if negative(v2) && negative(v1) && v3 > 0.0 {
        *ids = [x0, x3, x2, x1, c];
    } else {
        if v2 < v1 || v3 < v1 {
            if v2 <= v1 && v2 <= v3 {
                ids[0] = x0;
                ids[1] = x1;
            } else {
                ids[0] = x1;
                ids[1] = c;
            }
        }
        return false;
    }
    true
}

/// The double pyramid over the triangle `ids[0..3]` with apexes `ids[3]`, `ids[4]`; the origin
/// must be inside, up to faces within `within` (a squared length) of it.
fn double_pyramid(polytope: &mut Polytope, ids: [usize; 5], within: f64) -> bool {
    let points = ids.map(|i| polytope.vertices[i].point);
    let p = |k: usize| points[k];
    polytope.centre = ((((p(0) + p(1)) + p(2)) + p(3)) + p(4)) * 0.2;
    let [v1, v2, v3, v4, v5] = ids;
    let faces = [
        ([v4, v1, v2], [1, 3, 2]),
        ([v4, v3, v1], [2, 4, 0]),
        ([v4, v2, v3], [0, 5, 1]),
        ([v5, v2, v1], [5, 0, 4]),
        ([v5, v1, v3], [3, 1, 5]),
        ([v5, v3, v2], [4, 2, 3]),
    ];
    let sides = [
        (3, 0, 1, 2),
        (3, 2, 0, 1),
        (3, 1, 2, 0),
        (4, 1, 0, 2),
        (4, 0, 2, 1),
    ];
    encloses(polytope, &points, faces, &sides, within)
}

/// Adds the starting polytope's `faces` (corners, neighbours) and tells whether the origin is
/// inside: no face through it, and for each of `sides` (a face k's opposite point, then the
/// face's three, indices into `points`) the point on the inner side of face k, unless that face
/// is within `within` of the origin. Lists every face as a candidate when it is.
fn encloses<const F: usize>(
    polytope: &mut Polytope,
    points: &[Vec3],
    faces: [([usize; 3], [usize; 3]); F],
    sides: &[(usize, usize, usize, usize)],
    within: f64,
) -> bool {
    let mut distances = [0.0; F];
    for (k, (corners, neighbours)) in faces.into_iter().enumerate() {
        distances[k] = polytope.add_face(corners, neighbours);
    }
    if distances.iter().any(|&d| d < ON_FACE) {
        return false;
    }
    for (k, &(q0, q1, q2, q3)) in sides.iter().enumerate() {
        let p = |k: usize| &points[k];
        if !same_side(p(q0), p(q1), p(q2), p(q3)) && distances[k] >= within {
            return false;
        }
    }
    polytope.list_all();
    true
}

/// The tetrahedron `ids`; the origin must be inside, up to faces within `within` of it.
fn tetrahedron(polytope: &mut Polytope, ids: [usize; 4], within: f64) -> bool {
    let points = ids.map(|i| polytope.vertices[i].point);
    let p = |k: usize| points[k];
    polytope.centre = (((p(0) + p(1)) + p(2)) + p(3)) * 0.25;
    let [t1, t2, t3, t4] = ids;
    let faces = [
        ([t1, t2, t3], [1, 3, 2]),
        ([t1, t4, t2], [2, 3, 0]),
        ([t1, t3, t4], [0, 3, 1]),
        ([t4, t3, t2], [2, 0, 1]),
    ];
    let sides = [(0, 1, 2, 3), (0, 3, 1, 2), (0, 2, 3, 1), (3, 2, 1, 0)];
    encloses(polytope, &points, faces, &sides, within)
}

/// Starting polytope from GJK's tetrahedron; a face through the origin restarts from that face.
fn from_tetrahedron(
    polytope: &mut Polytope,
    a: &impl Convex,
    b: &impl Convex,
    proximity: &Proximity,
    tolerance: f64,
) -> bool {
    let ids = proximity.simplex.map(|v| polytope.add_vertex(v));
    let p = |k: usize| proximity.simplex[k].point;
    polytope.centre = (p(0) + p(1) + p(2) + p(3)) * 0.25;
    let [i1, i2, i3, i4] = ids;
    let faces = [
        ([i1, i2, i3], [1, 3, 2]),
        ([i1, i4, i2], [2, 3, 0]),
        ([i1, i3, i4], [0, 3, 1]),
        ([i4, i3, i2], [2, 0, 1]),
    ];
    for (corners, neighbours) in faces {
        if polytope.add_face(corners, neighbours) < ON_FACE {
            let mut simplex = [Vertex::default(); 4];
            for (slot, corner) in corners.iter().enumerate() {
                simplex[slot] = polytope.vertices[*corner];
            }
            *polytope = Polytope::new();
            return from_triangle(polytope, a, b, simplex, tolerance);
        }
    }
    if !encloses_origin([&p(0), &p(1), &p(2), &p(3)]) {
        return false;
    }
    polytope.list_all();
    true
}
