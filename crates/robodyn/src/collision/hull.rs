//! A mesh geom as contacts see it: the convex hull of its vertices (MuJoCo collides a mesh by its
//! hull: "Computation", §Collision detection), with its coplanar triangles merged into polygons
//! for the single-shot multi-contact of [`super::convex`].
//!
//! The hull is parry3d's (the algorithm MuJoCo takes from qhull); its triangles are grouped by
//! their outward normal n, rounded to a grid of 0.01 rad in its spherical angles
//! ```text
//!   θ = atan2(n_y, n_x),   φ = acos(n_z)        (a normal within 1e-7 of ±z: θ = 0, φ = 0 or π)
//! ```
//! as MuJoCo's compiler groups them (its `<mesh>` polygons), and each group's boundary, walked
//! along its triangles' edges, is one polygon (two, if the group is two islands). A polygon's
//! normal is its area vector made unit (Newell's formula), `Σ (vₖ × vₖ₊₁) / |Σ vₖ × vₖ₊₁|`.

use crate::io::mesh::TriangleMesh;
use crate::spatial::Vec3;
use rustc_hash::{FxHashMap, FxHashSet};
use std::collections::BTreeMap;

/// The grid on which triangle normals are rounded to group them into polygons (rad).
const ANGLE_GRID: f64 = 0.01;
/// A triangle whose doubled area is below this is left out of the polygons (MuJoCo's mjMINVAL).
const MIN_AREA: f64 = 1e-15;
/// A hull whose volume is below this fraction of its bounding sphere's radius cubed is flat.
const FLAT: f64 = 1e-12;
/// The most faces at a corner that multi-contact considers: the others are left out.
pub const MAX_VERTEX_FACES: usize = 32;

/// A convex mesh: its corners, and its faces as polygons.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ConvexHull {
    /// The hull's corners in the geom's frame, in the order of the mesh's vertices.
    pub vertices: Vec<Vec3>,
    /// The faces' outward unit normals.
    pub normals: Vec<Vec3>,
    /// Face `f`'s corners are `corners[face_starts[f]..face_starts[f + 1]]`, counter-clockwise
    /// seen from outside.
    face_starts: Vec<usize>,
    corners: Vec<usize>,
    /// Vertex `v` lies on the faces `vertex_faces[vertex_starts[v]..vertex_starts[v + 1]]`.
    vertex_starts: Vec<usize>,
    vertex_faces: Vec<usize>,
    /// The radius of the smallest sphere about the geom's origin that holds the hull.
    pub radius: f64,
}

impl ConvexHull {
    /// The hull of `mesh`'s vertices (in the geom's frame): [`TriangleMesh::convex_hull`], its
    /// corners put back in the mesh's vertex order.
    pub fn new(mesh: &TriangleMesh) -> Result<Self, String> {
        let hull = mesh.convex_hull()?;
        // the hull's corners in the order of the mesh's vertices (the first of equal ones)
        let mut first_index: FxHashMap<[u64; 3], usize> = FxHashMap::default();
        for (k, p) in mesh.vertices.iter().enumerate().rev() {
            first_index.insert([p.x, p.y, p.z].map(f64::to_bits), k);
        }
        let original = |c: &Vec3| first_index.get(&[c.x, c.y, c.z].map(f64::to_bits)).copied();
        let mut order: Vec<usize> = (0..hull.vertices.len()).collect();
        order.sort_by_key(|&k| original(&hull.vertices[k]).unwrap_or(usize::MAX));
        let mut renumbered = vec![0; order.len()];
        for (new, &old) in order.iter().enumerate() {
            renumbered[old] = new;
        }
        let vertices: Vec<Vec3> = order.iter().map(|&k| hull.vertices[k]).collect();
        let triangles: Vec<[usize; 3]> = hull
            .faces
            .iter()
            .map(|t| t.map(|k| renumbered[k]))
            .collect();
        let mut hull = ConvexHull {
            radius: vertices.iter().map(|v| v.norm()).fold(0.0, f64::max),
            vertices,
            normals: Vec::new(),
            face_starts: vec![0],
            corners: Vec::new(),
            vertex_starts: Vec::new(),
            vertex_faces: Vec::new(),
        };
        // coplanar points give a flat hull, two faces back to back: no volume
        let volume: f64 = triangles
            .iter()
            .map(|&[a, b, c]| {
                let [pa, pb, pc] = [a, b, c].map(|k| hull.vertices[k]);
                pa.dot(&pb.cross(&pc)) / 6.0
            })
            .sum();
        if volume <= FLAT * hull.radius.powi(3) {
            return Err(
                "its vertices are coplanar, so it has no convex hull to collide (as MuJoCo says): use a plane or a thin box"
                    .into(),
            );
        }
        hull.merge_coplanar(&triangles);
        Ok(hull)
    }

    /// Groups the triangles by rounded normal and keeps each group's boundary loops as faces.
    fn merge_coplanar(&mut self, triangles: &[[usize; 3]]) {
        let mut groups: BTreeMap<(i64, i64), Vec<[usize; 3]>> = BTreeMap::new();
        for &[a, b, c] in triangles {
            let [pa, pb, pc] = [a, b, c].map(|k| self.vertices[k]);
            let w = (pb - pa).cross(&(pc - pa));
            if w.norm() < MIN_AREA {
                continue;
            }
            groups
                .entry(grid_key(&w.normalize()))
                .or_default()
                .push([a, b, c]);
        }
        for group in groups.values() {
            // boundary edges: those whose reverse is not in the group
            let edges: Vec<(usize, usize)> = group
                .iter()
                .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
                .collect();
            let inner: FxHashSet<(usize, usize)> = edges.iter().copied().collect();
            let mut boundary: Vec<(usize, usize)> = edges
                .iter()
                .copied()
                .filter(|&(a, b)| !inner.contains(&(b, a)))
                .collect();
            // walk each loop from its first remaining edge
            while let Some((start, mut next)) = boundary.first().copied() {
                boundary.swap_remove(0);
                let mut path = vec![start];
                while next != start {
                    path.push(next);
                    let Some(k) = boundary.iter().position(|&(a, _)| a == next) else {
                        break;
                    };
                    next = boundary.swap_remove(k).1;
                }
                if path.len() >= 3 {
                    self.push_face(&path);
                }
            }
        }
        // which faces each vertex lies on
        let mut on: Vec<Vec<usize>> = vec![Vec::new(); self.vertices.len()];
        for f in 0..self.normals.len() {
            for &v in self.face(f) {
                on[v].push(f);
            }
        }
        self.vertex_starts = vec![0];
        for faces in on {
            self.vertex_faces.extend(faces);
            self.vertex_starts.push(self.vertex_faces.len());
        }
    }

    /// Adds the polygon `path` (counter-clockwise from outside) with its Newell normal.
    fn push_face(&mut self, path: &[usize]) {
        let mut area = Vec3::zeros();
        for (k, &v) in path.iter().enumerate() {
            let next = path[(k + 1) % path.len()];
            area += self.vertices[v].cross(&self.vertices[next]);
        }
        self.normals.push(area.normalize());
        self.corners.extend_from_slice(path);
        self.face_starts.push(self.corners.len());
    }

    /// The corners of face `f`, counter-clockwise seen from outside.
    pub fn face(&self, f: usize) -> &[usize] {
        &self.corners[self.face_starts[f]..self.face_starts[f + 1]]
    }

    /// The faces vertex `v` lies on.
    pub fn faces_at(&self, v: usize) -> &[usize] {
        &self.vertex_faces[self.vertex_starts[v]..self.vertex_starts[v + 1]]
    }

    /// How many faces the hull has.
    pub fn face_count(&self) -> usize {
        self.normals.len()
    }

    /// The most corners of any face.
    pub fn largest_face(&self) -> usize {
        (0..self.face_count())
            .map(|f| self.face(f).len())
            .max()
            .unwrap_or(0)
    }

    /// The most faces at any corner.
    pub fn most_faces_at_a_corner(&self) -> usize {
        (0..self.vertices.len())
            .map(|v| self.faces_at(v).len())
            .max()
            .unwrap_or(0)
    }

    /// The corner farthest along the local direction `d` (the first of equals) and its index.
    pub fn support(&self, d: &Vec3) -> (Vec3, usize) {
        let mut best = (f64::NEG_INFINITY, 0);
        for (k, v) in self.vertices.iter().enumerate() {
            let along = v.x * d.x + v.y * d.y + v.z * d.z;
            if along > best.0 {
                best = (along, k);
            }
        }
        (self.vertices[best.1], best.1)
    }
}

/// A unit normal's rounded spherical angles (see the module's header).
fn grid_key(n: &Vec3) -> (i64, i64) {
    // + 0.0 makes a −0 a +0, whose atan2 differs
    let (x, y, z) = (n.x + 0.0, n.y + 0.0, n.z + 0.0);
    if z.abs() > 1.0 - 1e-7 {
        let polar = if z < 0.0 {
            (std::f64::consts::PI / ANGLE_GRID).round()
        } else {
            0.0
        };
        return (0, polar as i64);
    }
    let theta = (y.atan2(x) / ANGLE_GRID).round();
    let phi = (z.acos() / ANGLE_GRID).round();
    (theta as i64, phi as i64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Vertices without faces.
    fn mesh_of(points: &[Vec3]) -> TriangleMesh {
        TriangleMesh {
            vertices: points.to_vec(),
            faces: Vec::new(),
        }
    }

    /// The corners of a box with half-sides `h`, and an inner point.
    fn box_points(h: Vec3) -> Vec<Vec3> {
        let mut points: Vec<Vec3> = (0..8)
            .map(|k| {
                let s = |bit: usize| if k >> bit & 1 == 1 { 1.0 } else { -1.0 };
                Vec3::new(s(0) * h.x, s(1) * h.y, s(2) * h.z)
            })
            .collect();
        points.insert(3, Vec3::zeros());
        points
    }

    #[test]
    fn a_box_has_six_square_faces_in_the_mesh_vertex_order() {
        let points = box_points(Vec3::new(0.3, 0.2, 0.1));
        let hull = ConvexHull::new(&mesh_of(&points)).unwrap();
        // the inner point is not a corner; the corners keep the mesh's order
        let expected: Vec<Vec3> = points.iter().copied().filter(|p| p.norm() > 0.0).collect();
        assert_eq!(hull.vertices, expected);
        assert_eq!(hull.face_count(), 6);
        for f in 0..6 {
            let face = hull.face(f);
            assert_eq!(face.len(), 4);
            let n = hull.normals[f];
            // one axis, pointing out, the corners counter-clockwise about it
            assert!((n.abs().max() - 1.0).abs() < 1e-15);
            let centre: Vec3 = face.iter().map(|&v| hull.vertices[v]).sum::<Vec3>() / 4.0;
            assert!(centre.dot(&n) > 0.0);
            let [a, b, c] = [face[0], face[1], face[2]].map(|v| hull.vertices[v]);
            assert!((b - a).cross(&(c - b)).dot(&n) > 0.0);
        }
        for v in 0..8 {
            assert_eq!(hull.faces_at(v).len(), 3);
        }
        assert!((hull.radius - Vec3::new(0.3, 0.2, 0.1).norm()).abs() < 1e-15);
    }

    #[test]
    fn support_takes_the_first_of_equal_corners() {
        let hull = ConvexHull::new(&mesh_of(&box_points(Vec3::new(0.3, 0.2, 0.1)))).unwrap();
        // along +x four corners are equal: the first in the mesh's order
        let (point, index) = hull.support(&Vec3::x());
        assert_eq!(index, 1);
        assert_eq!(point, Vec3::new(0.3, -0.2, -0.1));
        let (point, _) = hull.support(&Vec3::new(-1.0, 2.0, 3.0));
        assert_eq!(point, Vec3::new(-0.3, 0.2, 0.1));
    }

    #[test]
    fn a_prism_merges_its_fan_of_triangles_into_caps() {
        let sides = 16;
        let mut points = Vec::new();
        for z in [-0.1, 0.1] {
            for k in 0..sides {
                let angle = 2.0 * std::f64::consts::PI * k as f64 / sides as f64;
                points.push(Vec3::new(0.1 * angle.cos(), 0.1 * angle.sin(), z));
            }
        }
        let hull = ConvexHull::new(&mesh_of(&points)).unwrap();
        assert_eq!(hull.face_count(), sides + 2);
        let largest = (0..hull.face_count()).map(|f| hull.face(f).len()).max();
        assert_eq!(largest, Some(sides));
    }

    #[test]
    fn coplanar_points_have_no_hull() {
        let points: Vec<Vec3> = (0..5)
            .map(|k| Vec3::new(k as f64, (k * k) as f64, 0.0))
            .collect();
        assert!(ConvexHull::new(&mesh_of(&points))
            .unwrap_err()
            .contains("coplanar"));
    }
}
