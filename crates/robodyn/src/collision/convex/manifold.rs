//! Single-shot multi-contact: the features (vertex, edge, face) two shapes touch along, and the
//! polygon of one face clipped by the other (see [`super`]'s header).

use super::{dot, gjk, inflate, unit_or_x, Body, Kind, Manifold, Witness};
use crate::collision::gjk::Vertex;
use crate::collision::hull::MAX_VERTEX_FACES;
use crate::spatial::Vec3;
use std::cell::RefCell;

/// Faces whose normals are within ~5° of opposite count as parallel (MuJoCo's `mjFACE_TOL`).
const FACE_TOLERANCE: f64 = 0.996;
/// An edge within ~5° of a face's plane counts as lying in it (MuJoCo's `mjEDGE_TOL`).
const EDGE_TOLERANCE: f64 = 0.0888;
/// A cylinder's cap as a 16-gon: cos and sin of k·22.5°, to the (15) digits MuJoCo uses.
#[rustfmt::skip]
#[allow(clippy::approx_constant)]
const RIM_COS: [f64; 16] = [
    1.0, 0.923879532511287, 0.707106781186548, 0.38268343236509,
    0.0, -0.38268343236509, -0.707106781186547, -0.923879532511287,
    -1.0, -0.923879532511287, -0.707106781186548, -0.38268343236509,
    0.0, 0.38268343236509, 0.707106781186547, 0.923879532511287,
];
#[rustfmt::skip]
#[allow(clippy::approx_constant)]
const RIM_SIN: [f64; 16] = [
    0.0, 0.38268343236509, 0.707106781186547, 0.923879532511287,
    1.0, 0.923879532511287, 0.707106781186548, 0.38268343236509,
    0.0, -0.38268343236509, -0.707106781186547, -0.923879532511287,
    -1.0, -0.923879532511287, -0.707106781186548, -0.38268343236509,
];
thread_local! {
    /// The polygons of a multi-contact, kept from call to call: they allocate only when a larger
    /// face than any before comes (a mesh's).
    static POLYGONS: RefCell<Polygons> = RefCell::new(Polygons::default());
}

/// Room for the two faces and the clipped polygon (an n-gon clipped by an m-gon has at most
/// n + m corners).
#[derive(Debug, Default)]
struct Polygons {
    face_a: Vec<Vec3>,
    face_b: Vec<Vec3>,
    current: Vec<Vec3>,
    next: Vec<Vec3>,
}

/// The part of a shape a contact lies on, from the support points (and tags) of the simplex
/// that found it: `dim` 1 a vertex, 2 an edge, 3 a face.
#[derive(Debug, Clone, Copy)]
struct Feature {
    points: [Vec3; 3],
    tags: [i32; 3],
    dim: usize,
}

impl Feature {
    /// The feature of shape `side` (0: A, 1: B) in the simplex, repeated tags merged.
    fn of(simplex: &[Vertex], side: usize) -> Self {
        let pick = |k: usize| simplex[if k < simplex.len() { k } else { 0 }];
        let point = |v: Vertex| if side == 0 { v.on_first } else { v.on_second };
        let mut points = [point(pick(0)), point(pick(1)), point(pick(2))];
        let mut tags = [pick(0).tags[side], pick(1).tags[side], pick(2).tags[side]];
        let dim = if tags[0] == tags[1] {
            if tags[0] == tags[2] {
                1
            } else {
                tags[1] = tags[2];
                points[1] = points[2];
                2
            }
        } else if tags[2] == tags[0] || tags[2] == tags[1] {
            2
        } else {
            3
        };
        Feature { points, tags, dim }
    }
}

/// Up to [`MAX_VERTEX_FACES`] directions (face normals or edge directions) with a face id or
/// an edge's end; more are left out.
#[derive(Debug, Clone, Copy)]
struct Directions {
    vectors: [Vec3; MAX_VERTEX_FACES],
    ids: [i32; MAX_VERTEX_FACES],
    ends: [Vec3; MAX_VERTEX_FACES],
    len: usize,
}

impl Default for Directions {
    fn default() -> Self {
        Directions {
            vectors: [Vec3::zeros(); MAX_VERTEX_FACES],
            ids: [0; MAX_VERTEX_FACES],
            ends: [Vec3::zeros(); MAX_VERTEX_FACES],
            len: 0,
        }
    }
}

impl Directions {
    /// Orders the directions by how far they point along `toward`, the most first (a stable
    /// insertion sort: equals keep their order).
    fn sort_along(&mut self, toward: &Vec3) {
        for i in 1..self.len {
            let mut j = i;
            while j > 0 && dot(&self.vectors[j], toward) > dot(&self.vectors[j - 1], toward) {
                self.vectors.swap(j, j - 1);
                self.ids.swap(j, j - 1);
                self.ends.swap(j, j - 1);
                j -= 1;
            }
        }
    }

    fn push(&mut self, vector: Vec3, id: i32, end: Vec3) {
        if self.len == MAX_VERTEX_FACES {
            return;
        }
        self.vectors[self.len] = vector;
        self.ids[self.len] = id;
        self.ends[self.len] = end;
        self.len += 1;
    }
}

/// A box's face ids: 2k for +x_k, 2k + 1 for −x_k; its corners, counter-clockwise from outside.
const BOX_FACES: [[i32; 4]; 6] = [
    [0b111, 0b011, 0b001, 0b101],
    [0b010, 0b110, 0b100, 0b000],
    [0b010, 0b011, 0b111, 0b110],
    [0b100, 0b101, 0b001, 0b000],
    [0b110, 0b111, 0b101, 0b100],
    [0b011, 0b010, 0b000, 0b001],
];

impl Body<'_> {
    /// The box corner with sign bits `tag` (bit k set: +half-extent along axis k).
    fn corner(&self, tag: i32, half: &Vec3) -> Vec3 {
        let sign = |k: i32| if tag & (1 << k) != 0 { 1.0 } else { -1.0 };
        self.world_of(&Vec3::new(
            sign(0) * half.x,
            sign(1) * half.y,
            sign(2) * half.z,
        ))
    }

    /// The outward normals of the faces the feature may lie on, with their ids: a box's faces
    /// shared by its corners (one of them picked by `toward`, the direction to the other
    /// shape, when they share none), a cylinder's cap holding the whole feature, a mesh's
    /// faces holding all the feature's corners (the first one for three corners), those facing
    /// along `toward` the most first.
    fn face_normals(&self, feature: &Feature, toward: &Vec3) -> Directions {
        let mut normals = Directions::default();
        let mut push = |local: Vec3, id: i32| normals.push(self.turn(&local), id, Vec3::zeros());
        match self.kind {
            Kind::Cylinder { .. } if feature.dim == 1 => {
                let cap = feature.tags[0];
                push(Vec3::new(0.0, 0.0, if cap == 0 { 1.0 } else { -1.0 }), cap);
            }
            Kind::Cuboid { .. } => {
                // +1 when all corners have bit k set, −1 when none has, 0 otherwise
                let tags = &feature.tags[..feature.dim];
                let shared = |bit: i32| {
                    tags.iter().all(|t| t & bit != 0) as i32
                        - tags.iter().all(|t| t & bit == 0) as i32
                };
                let unit = |k: usize, sign: i32| {
                    let mut local = Vec3::zeros();
                    local[k] = sign as f64;
                    (local, 2 * k as i32 + (sign < 0) as i32)
                };
                match feature.dim {
                    3 => {
                        let s = [shared(1), shared(2), shared(4)];
                        if s.iter().filter(|&&x| x != 0).count() == 1 {
                            let k = s.iter().position(|&x| x != 0).unwrap_or(0);
                            let local = Vec3::new(s[0] as f64, s[1] as f64, s[2] as f64);
                            push(local, unit(k, s[k]).1);
                        }
                    }
                    2 => {
                        for (k, bit) in [1, 2, 4].into_iter().enumerate() {
                            if shared(bit) != 0 {
                                let (local, id) = unit(k, shared(bit));
                                push(local, id);
                            }
                        }
                    }
                    _ => {
                        for (k, bit) in [1, 2, 4].into_iter().enumerate() {
                            let (local, id) =
                                unit(k, if feature.tags[0] & bit != 0 { 1 } else { -1 });
                            push(local, id);
                        }
                    }
                }
                if normals.len == 0 {
                    // the face whose normal is within the face tolerance of `toward`
                    let local = self.local_of(toward);
                    let local = local * (1.0 / dot(&local, &local).sqrt());
                    for id in 0..6 {
                        let (unit, id) = unit(id / 2, if id % 2 == 0 { 1 } else { -1 });
                        if dot(&local, &unit) > FACE_TOLERANCE {
                            normals.push(self.turn(&unit), id, Vec3::zeros());
                            break;
                        }
                    }
                }
            }
            Kind::Mesh { hull } => {
                let corners = &feature.tags[..feature.dim];
                for &face in hull.faces_at(corners[0] as usize) {
                    if corners[1..]
                        .iter()
                        .all(|&c| hull.faces_at(c as usize).contains(&face))
                    {
                        push(hull.normals[face], face as i32);
                        if feature.dim == 3 {
                            break;
                        }
                    }
                }
                normals.sort_along(toward);
            }
            _ => {}
        }
        normals
    }

    /// The edges the feature may lie on, as unit directions from `start` (moved onto the
    /// shape's own surface) to the edges' ends: a capsule's generator through its witness
    /// point `witness`, a cylinder's side line from the feature's cap, a box's or a mesh's
    /// edge, or the edges at a corner (a mesh's: to the corner before it on each of its faces).
    fn edges(
        &self,
        feature: &Feature,
        start: &mut Vec3,
        witness: &Vec3,
        margin: f64,
    ) -> Directions {
        let mut edges = Directions::default();
        match self.kind {
            Kind::Capsule { half_length, .. } => {
                let axis = self.axis(2);
                let along = dot(&(witness - self.position), &axis);
                *start = axis * (-along - half_length) + witness;
                edges.push(axis, 0, axis * (half_length - along) + witness);
            }
            Kind::Cylinder {
                radius,
                half_length,
            } => {
                let side = if feature.tags[0] == 0 { -1.0 } else { 1.0 };
                let direction = self.axis(2) * side;
                if margin > 0.0 {
                    // back from the grown surface onto the rim
                    let l = self.local_of(&(*start - self.position));
                    let across = l.x * l.x + l.y * l.y;
                    let scale = if across >= gjk::TINY * gjk::TINY {
                        radius / across.sqrt()
                    } else {
                        0.0
                    };
                    *start =
                        self.world_of(&Vec3::new(l.x * scale, l.y * scale, -side * half_length));
                }
                edges.push(
                    direction,
                    0,
                    direction * (half_length + half_length) + *start,
                );
            }
            Kind::Cuboid { half_extents } => {
                *start = self.corner(feature.tags[0], &half_extents);
                let ends: &[i32] = match feature.dim {
                    2 => &[feature.tags[1]],
                    1 => &[
                        feature.tags[0] ^ 1,
                        feature.tags[0] ^ 2,
                        feature.tags[0] ^ 4,
                    ],
                    _ => &[],
                };
                for (k, tag) in ends.iter().enumerate() {
                    let end = self.corner(*tag, &half_extents);
                    edges.push(unit_or_x(&(end - *start)), k as i32, end);
                }
            }
            Kind::Mesh { hull } => {
                let corner = feature.tags[0] as usize;
                *start = self.world_of(&hull.vertices[corner]);
                let mut push = |other: usize, k: usize| {
                    let end = self.world_of(&hull.vertices[other]);
                    edges.push(unit_or_x(&(end - *start)), k as i32, end);
                };
                match feature.dim {
                    2 => push(feature.tags[1] as usize, 0),
                    1 => {
                        for (k, &face) in hull.faces_at(corner).iter().enumerate() {
                            let corners = hull.face(face);
                            let at = corners.iter().position(|&c| c == corner).unwrap_or(0);
                            push(corners[(at + corners.len() - 1) % corners.len()], k);
                        }
                    }
                    _ => {}
                }
            }
            _ => {}
        }
        edges
    }

    /// The polygon of face `id` into `polygon`, clockwise seen from outside: a box's 4 corners, a
    /// cylinder's cap (id 0 top, 1 bottom) as a 16-gon, a mesh's face.
    fn face(&self, id: i32, polygon: &mut Vec<Vec3>) {
        polygon.clear();
        match self.kind {
            Kind::Cuboid { half_extents } => {
                for tag in &BOX_FACES[id as usize] {
                    polygon.push(self.corner(*tag, &half_extents));
                }
            }
            Kind::Cylinder {
                radius,
                half_length,
            } => {
                let side = if id == 0 { 1.0 } else { -1.0 };
                for k in 0..16 {
                    let local = Vec3::new(
                        radius * RIM_COS[k],
                        side * (radius * -RIM_SIN[k]),
                        side * half_length,
                    );
                    polygon.push(self.world_of(&local));
                }
            }
            Kind::Mesh { hull } => {
                for &corner in hull.face(id as usize).iter().rev() {
                    polygon.push(self.world_of(&hull.vertices[corner]));
                }
            }
            _ => {}
        }
    }
}

/// How the two features meet: two faces (indices into A's and B's normals), or an edge of one
/// shape (its edges and the index there) in a face of the other (index into its normals).
enum Meeting {
    Faces(usize, usize),
    EdgeOfA(Directions, usize, usize),
    EdgeOfB(Directions, usize, usize),
}

/// The first edge nearly in one of the faces that face `toward` (its index and the face's).
fn edge_in_face(edges: &Directions, faces: &Directions, toward: &Vec3) -> Option<(usize, usize)> {
    (0..faces.len)
        .filter(|&j| dot(&faces.vectors[j], toward) > gjk::TINY)
        .find_map(|j| {
            (0..edges.len)
                .find(|&i| dot(&edges.vectors[i], &faces.vectors[j]).abs() < EDGE_TOLERANCE)
                .map(|i| (i, j))
        })
}

/// Single-shot multi-contact: when the contact's features are two nearly parallel faces, or an
/// edge nearly in a face, clip one against the other; the clipped polygon's vertices (within
/// the margins of the face) replace `found`.
pub(super) fn manifold(
    a: &Body,
    b: &Body,
    margin: f64,
    simplex: &[Vertex],
    witness: &[Vec3; 2],
    budget: usize,
    found: &mut Manifold,
) {
    let (fa, fb) = (Feature::of(simplex, 0), Feature::of(simplex, 1));
    let (toward_b, toward_a) = (witness[1] - witness[0], witness[0] - witness[1]);
    let normals_a = a.face_normals(&fa, &toward_a);
    let normals_b = b.face_normals(&fb, &toward_b);
    // the most opposed pair of faces, each turned (by more than ~5°) towards the other shape
    let mut faces = None;
    let facing = dot(&toward_b, &toward_b).sqrt() * EDGE_TOLERANCE;
    let mut most = -FACE_TOLERANCE;
    for i in 0..normals_a.len {
        if dot(&normals_a.vectors[i], &toward_b) >= -facing {
            continue;
        }
        for j in 0..normals_b.len {
            let opposition = dot(&normals_a.vectors[i], &normals_b.vectors[j]);
            if facing < dot(&normals_b.vectors[j], &toward_b) && most > opposition {
                most = opposition;
                faces = Some(Meeting::Faces(i, j));
            }
        }
    }
    // otherwise an edge in a face, B's edges first when B's feature is the smaller one
    let (mut start_a, mut start_b) = (fa.points[0], fb.points[0]);
    let meeting = faces.or_else(|| {
        let b_first = normals_a.len != 0 && fb.dim != 3 && (fb.dim < fa.dim || normals_b.len == 0);
        let mut of_a = || {
            if fa.dim == 3 || normals_b.len == 0 {
                return None;
            }
            let edges = a.edges(&fa, &mut start_a, &witness[0], margin);
            edge_in_face(&edges, &normals_b, &toward_b).map(|(i, j)| Meeting::EdgeOfA(edges, i, j))
        };
        let mut of_b = || {
            if fb.dim == 3 || normals_a.len == 0 {
                return None;
            }
            let edges = b.edges(&fb, &mut start_b, &witness[1], margin);
            edge_in_face(&edges, &normals_a, &toward_a).map(|(j, i)| Meeting::EdgeOfB(edges, i, j))
        };
        if b_first {
            of_b().or_else(of_a)
        } else {
            of_a().or_else(of_b)
        }
    });
    let Some(meeting) = meeting else {
        return;
    };
    // a capsule's witness already lies on its surface; the other shapes grow by their margin
    let grow = |body: &Body| match body.kind {
        Kind::Capsule { .. } => 0.0,
        _ => 0.5 * margin,
    };
    let grow = [grow(a), grow(b)];
    let reach = grow[0] + grow[1];
    let mut clipped = Manifold::default();
    let out = POLYGONS.with_borrow_mut(|polygons| {
        let Polygons {
            face_a,
            face_b,
            current,
            next,
        } = polygons;
        match meeting {
            Meeting::Faces(i, j) => {
                a.face(normals_a.ids[i], face_a);
                b.face(normals_b.ids[j], face_b);
                let normals = (normals_a.vectors[i], normals_b.vectors[j]);
                let clip_a = Clip {
                    normals,
                    reach,
                    budget,
                    b_face: false,
                };
                clip_a.run(face_a, face_b, (current, next), &mut clipped);
                -normals.1
            }
            Meeting::EdgeOfA(edges, i, j) => {
                b.face(normals_b.ids[j], face_b);
                let n = normals_b.vectors[j];
                let clip_b = Clip {
                    normals: (n, -n),
                    reach,
                    budget,
                    b_face: true,
                };
                let edge = [start_a, edges.ends[i]];
                clip_b.run(face_b, &edge, (current, next), &mut clipped);
                -n
            }
            Meeting::EdgeOfB(edges, i, j) => {
                a.face(normals_a.ids[i], face_a);
                let n = normals_a.vectors[i];
                let clip_a = Clip {
                    normals: (n, -n),
                    reach,
                    budget,
                    b_face: false,
                };
                let edge = [start_b, edges.ends[j]];
                clip_a.run(face_a, &edge, (current, next), &mut clipped);
                n
            }
        }
    });
    if clipped.len > 0 {
        inflate(&mut clipped.witnesses[..clipped.len], grow, &out);
        *found = clipped;
    }
}

/// Clipping a polygon against a face: `normals` (the face's outward normal n, the direction w
/// back onto the polygon's plane), how far past the face a vertex may lie, the most contacts,
/// and whether the face is B's.
struct Clip {
    normals: (Vec3, Vec3),
    reach: f64,
    budget: usize,
    b_face: bool,
}

impl Clip {
    /// Clips `polygon` by the planes through `face`'s edges perpendicular to it (Sutherland–
    /// Hodgman), keeps the vertices within `reach` of the face's plane, and makes a contact of
    /// each (at most `budget`: more reduced to the largest quadrilateral, a clipped edge to its
    /// two farthest points): `x_face = v − ((v − f₀)·n) n`, `x_poly = x_face − ((x_face − v)·w) w`,
    /// distance `(x_face − v)·w`. `scratch`: room for the clipped polygon.
    fn run(
        &self,
        face: &[Vec3],
        polygon: &[Vec3],
        scratch: (&mut Vec<Vec3>, &mut Vec<Vec3>),
        out: &mut Manifold,
    ) {
        let (n, w) = self.normals;
        if face.len() < 3 {
            return;
        }
        let (mut current, mut next) = scratch;
        current.clear();
        current.extend_from_slice(polygon);
        for (e, corner) in face.iter().enumerate() {
            // inward normal of the plane through edge e: (q − p) × ((p + n) − p)
            let q = face[(e + 1) % face.len()];
            let inward = unit_or_x(&(q - corner).cross(&((corner + n) - corner)));
            next.clear();
            let len = current.len();
            for i in 0..len {
                let (p, q) = (current[i], current[if i + 1 < len { i + 1 } else { 0 }]);
                let (dp, dq) = (dot(&(p - corner), &inward), dot(&(q - corner), &inward));
                let (in_p, in_q) = (dp > -gjk::TINY, dq > -gjk::TINY);
                if in_p != in_q && dp - dq != 0.0 {
                    // where pq crosses the plane: p + t (q − p), t = dp/(dp − dq)
                    let t = dp / (dp - dq);
                    if (0.0..=1.0).contains(&t) {
                        next.push((q - p) * t + p);
                    }
                }
                if in_q {
                    next.push(q);
                }
            }
            std::mem::swap(&mut current, &mut next);
        }
        let origin = face.first().copied().unwrap_or_default();
        current.retain(|v| self.reach >= dot(&(v - origin), &n));
        let vertices = &current[..];
        if vertices.is_empty() {
            return;
        }
        let contact = |v: &Vec3| {
            let on_face = v - n * dot(&(v - origin), &n);
            let back = dot(&(on_face - v), &w);
            let on_polygon = on_face - w * back;
            let points = if self.b_face {
                [on_polygon, on_face]
            } else {
                [on_face, on_polygon]
            };
            Witness {
                distance: back,
                points,
            }
        };
        if self.budget < 5 && vertices.len() >= 5 {
            for k in largest_quadrilateral(vertices) {
                out.push(contact(&vertices[k]));
            }
        } else if polygon.len() == 2 && vertices.len() >= 3 {
            let (mut ends, mut farthest) = ((0, 1), 0.0);
            for i in 0..vertices.len() {
                for j in i + 1..vertices.len() {
                    let d = vertices[j] - vertices[i];
                    if dot(&d, &d) > farthest {
                        (ends, farthest) = ((i, j), dot(&d, &d));
                    }
                }
            }
            out.push(contact(&vertices[ends.0]));
            out.push(contact(&vertices[ends.1]));
        } else {
            for v in &vertices[..vertices.len().min(self.budget)] {
                out.push(contact(v));
            }
        }
    }
}

/// The corners (as indices) of a convex polygon's largest quadrilateral, by rotating calipers
/// on the area `½ |(a − c) × (b − d)|` of the quadrilateral `a b c d`.
fn largest_quadrilateral(p: &[Vec3]) -> [usize; 4] {
    let n = p.len();
    let area = |a: usize, b: usize, c: usize, d: usize| {
        let cross = (p[a] - p[c]).cross(&(p[b] - p[d]));
        dot(&cross, &cross).sqrt() * 0.5
    };
    let mut best = area(0, 1, 2, 3);
    let mut chosen = [0, 1, 2, 3];
    let (mut j_next, mut k_next, mut l) = (1, 2, 3);
    for i in 0..n {
        let (mut j, mut k) = (j_next, k_next);
        loop {
            let after_l = (l + 1) % n;
            let candidate = area(i, j, k, after_l);
            if best >= candidate {
                // no gain: the free corners move on for the next i
                (j_next, k_next) = (j, k);
                if i == j {
                    if k != (j + 1) % n {
                        j_next = (j + 1) % n;
                    } else {
                        if l == (k + 1) % n {
                            l = after_l;
                        }
                        (j_next, k_next) = (k, (k + 1) % n);
                    }
                }
                break;
            }
            // gain: push the opposite corner, then the second one, while the area grows
            let mut grown = candidate;
            while grown < area(i, j, (k + 1) % n, after_l) {
                k = (k + 1) % n;
                grown = area(i, j, k, after_l);
            }
            while grown < area(i, (j + 1) % n, k, after_l) {
                j = (j + 1) % n;
                grown = area(i, j, k, after_l);
            }
            (chosen, best, l) = ([i, j, k, after_l], grown, after_l);
        }
    }
    chosen
}
