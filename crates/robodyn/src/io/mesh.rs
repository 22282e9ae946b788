//! Triangle meshes: reading STL (binary directly, ASCII with `stl_io`), Wavefront OBJ (with `tobj`) and
//! MuJoCo's binary `.msh`, and their mass properties as MuJoCo's compiler computes them
//! (MJCF reference, `<mesh inertia>`):
//!
//! - vertex coordinates are read as the files store them (float32) and then transformed in double
//!   precision: moved by −`refpos`, rotated by `refquat`ᵀ, scaled by `scale` (a left-handed
//!   scale reverses every face, so that normals keep pointing out);
//! - c_f, the area-weighted centroid of the faces, is the apex of one pyramid per face;
//! - volume V = Σ_t V_t, V_t = (c_t − c_f)·n_t A_t / 3 = (c_t − c_f)·w_t / 6 over the triangles t
//!   (n_t the unit normal, A_t the area, c_t the centroid, w_t = (b − a) × (c − a) = 2 A_t n_t),
//!   and the centre of mass Σ V_t (¾ c_t + ¼ c_f) / V;
//! - about the centre of mass, with D, E, F a triangle's corners relative to it, the second
//!   moments P = Σ_t V_t / C (2(D Dᵀ + E Eᵀ + F Fᵀ) + D Eᵀ + E Dᵀ + D Fᵀ + F Dᵀ + E Fᵀ + F Eᵀ)
//!   = Σ_t V_t / C (D Dᵀ + E Eᵀ + F Fᵀ + S Sᵀ) with S = D + E + F, C = 20 (solid) or 12
//!   (shell), and I = tr(P) 1 − P (unit density).
//!
//! The `inertia` modes: `legacy` (MuJoCo's default) takes |V_t|, so a mesh with flipped faces still
//! counts them; `exact` takes the signed V_t and refuses faces of inconsistent orientation; `shell`
//! puts the mass on the surface (V_t = A_t); `convex` takes the convex hull (parry3d's: a
//! well-kept implementation of the algorithm MuJoCo takes from qhull) as an exact mesh.

use crate::spatial::{Mat3, Vec3};
use nalgebra::{Isometry3, Matrix4, Translation3, UnitQuaternion};
use rustc_hash::FxHashMap;
use std::io::Cursor;

mod polygon;

/// Below this an area or volume is zero (MuJoCo's mjMINVAL).
const MIN_VALUE: f64 = 1e-15;

/// A mesh as read from its file: vertices and triangles (indices into the vertices).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TriangleMesh {
    /// The vertices, in the file's coordinates.
    pub vertices: Vec<Vec3>,
    /// The triangles, as indices into `vertices`, counter-clockwise seen from outside.
    pub faces: Vec<[usize; 3]>,
}

/// The most corners of an OBJ polygon that MuJoCo (4.0) cuts into triangles: a larger polygon
/// gives no triangles, silently, in its compiler and its renderer alike.
pub const MAX_POLYGON_CORNERS: usize = 100;

/// A mesh file as read: its triangles, and the polygons left out as MuJoCo leaves them out.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshFile {
    /// The triangles read.
    pub mesh: TriangleMesh,
    /// The polygons that gave no triangles.
    pub dropped_polygons: Vec<DroppedPolygon>,
}

/// An OBJ polygon of more than [`MAX_POLYGON_CORNERS`] corners, which gives no triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DroppedPolygon {
    /// Its line in the file (1-based), when the face lines could be matched to the polygons.
    pub line: Option<usize>,
    /// How many corners it has.
    pub corners: usize,
}

impl DroppedPolygon {
    /// What a model's warning says of it, after the file's name.
    pub fn describe(&self) -> String {
        let line = self
            .line
            .map_or_else(String::new, |l| format!("line {l}: "));
        format!(
            "{line}a face of {} corners gives no triangles, as in MuJoCo, which cuts faces of at most {MAX_POLYGON_CORNERS} corners (the mesh's mass properties and its drawing leave it out)",
            self.corners
        )
    }
}

/// How a mesh's inertia is computed (`<mesh inertia>`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshInertia {
    /// MuJoCo's former rule: every triangle's pyramid counts with a positive volume.
    Legacy,
    /// The solid the (closed, consistently oriented) mesh encloses.
    Exact,
    /// A thin shell: the mass spread over the surface.
    Shell,
    /// The solid of the mesh's convex hull.
    Convex,
}

impl MeshInertia {
    /// From the attribute's value.
    pub fn from_name(name: &str) -> Result<Self, String> {
        match name {
            "legacy" => Ok(MeshInertia::Legacy),
            "exact" => Ok(MeshInertia::Exact),
            "shell" => Ok(MeshInertia::Shell),
            "convex" => Ok(MeshInertia::Convex),
            other => Err(format!(
                "attribute 'inertia': expected legacy, exact, shell or convex, got '{other}'"
            )),
        }
    }
}

impl MeshInertia {
    /// What a triangle with area vector `w` = (b − a) × (c − a) (along its normal n, twice its
    /// area A long) and centroid `c` (relative to the apex) contributes: the pyramid's volume
    /// c·n A / 3 = c·w / 6 (its magnitude for `legacy`), or its area for a shell.
    fn pyramid(self, w: &Vec3, c: &Vec3) -> f64 {
        match self {
            MeshInertia::Shell => w.norm() / 2.0,
            MeshInertia::Legacy => (c.dot(w) / 6.0).abs(),
            MeshInertia::Exact | MeshInertia::Convex => c.dot(w) / 6.0,
        }
    }
}

/// A mesh's mass properties at unit density: its volume (or area, for a shell), centre of mass
/// and rotational inertia about the centre of mass, in the mesh's (transformed) frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshMassProperties {
    /// Volume (m³), or area (m²) for a shell: the mass at unit density.
    pub volume: f64,
    /// Centre of mass.
    pub com: Vec3,
    /// Rotational inertia about the centre of mass, at unit density.
    pub inertia: Mat3,
}

/// MuJoCo's map from a mesh file's coordinates to the mesh's: p ↦ S Rᵀ (p − refpos), with R the
/// rotation of `refquat` (w, x, y, z) and S = diag(`scale`), as a homogeneous 4x4 matrix.
pub fn reference_map(refpos: Vec3, refquat: [f64; 4], scale: Vec3) -> Matrix4<f64> {
    let [w, x, y, z] = refquat;
    let rotation = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z));
    let rotated = Isometry3::from_parts(Translation3::identity(), rotation.inverse())
        * Translation3::from(-refpos);
    Matrix4::new_nonuniform_scaling(&scale) * rotated.to_homogeneous()
}

/// Reads a mesh file by its extension: `.stl`, `.obj` or `.msh`.
pub fn read_mesh(bytes: &[u8], extension: &str) -> Result<MeshFile, String> {
    let whole = |mesh| MeshFile {
        mesh,
        dropped_polygons: Vec::new(),
    };
    match extension.to_ascii_lowercase().as_str() {
        "stl" => read_stl(bytes).map(whole),
        "obj" => read_obj(bytes),
        "msh" => read_msh(bytes).map(whole),
        other => Err(format!(
            "expected a mesh file ending in .stl, .obj or .msh, got '.{other}'"
        )),
    }
}

/// STL: a binary file (80-byte header, a u32 triangle count, then 50 bytes per triangle: a normal
/// and three corners as float32, and a u16) is read directly, its corners merged by exact value;
/// anything else goes to `stl_io` (ASCII STL, and the error for what is neither).
fn read_stl(bytes: &[u8]) -> Result<TriangleMesh, String> {
    const HEADER: usize = 84;
    const RECORD: usize = 50;
    let count = bytes
        .get(80..HEADER)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as usize);
    let Some(count) = count.filter(|&n| bytes.len() == HEADER + RECORD * n) else {
        let stl = stl_io::read_stl(&mut Cursor::new(bytes))
            .map_err(|e| format!("not a readable STL file: {e}"))?;
        let vertices = stl
            .vertices
            .iter()
            .map(|v| Vec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2])))
            .collect();
        let faces = stl.faces.iter().map(|f| f.vertices).collect();
        return Ok(TriangleMesh { vertices, faces });
    };
    // a corner's index by its coordinates' bits (−0 counted as +0)
    let mut index: FxHashMap<[u32; 3], usize> = FxHashMap::default();
    index.reserve(count);
    let mut vertices = Vec::with_capacity(count);
    let mut faces = Vec::with_capacity(count);
    for record in bytes[HEADER..].chunks_exact(RECORD) {
        let float = |at: usize| {
            f32::from_le_bytes([record[at], record[at + 1], record[at + 2], record[at + 3]]) + 0.0
        };
        faces.push([12, 24, 36].map(|at| {
            let corner = [float(at), float(at + 4), float(at + 8)];
            *index.entry(corner.map(f32::to_bits)).or_insert_with(|| {
                vertices.push(Vec3::from(corner.map(f64::from)));
                vertices.len() - 1
            })
        }));
    }
    Ok(TriangleMesh { vertices, faces })
}

/// OBJ as MuJoCo reads it: every vertex of the file, and the faces of its first object (`o`/`g`
/// group; MuJoCo ignores the rest), polygons cut into triangles as its reader cuts them
/// ([`polygon::triangulate`]), those of more than [`MAX_POLYGON_CORNERS`] corners left out.
fn read_obj(bytes: &[u8]) -> Result<MeshFile, String> {
    let options = tobj::LoadOptions {
        triangulate: false,
        single_index: false,
        ..tobj::LoadOptions::default()
    };
    let (models, _) = tobj::load_obj_buf(&mut Cursor::new(bytes), &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| format!("not a readable OBJ file: {e}"))?;
    // the first object's vertices come first, so its indices need no offset
    let vertices = models
        .iter()
        .flat_map(|model| model.mesh.positions.chunks_exact(3))
        .map(|p| Vec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])))
        .collect();
    let mut triangles = Vec::new();
    let mut dropped_polygons = Vec::new();
    if let Some(first) = models.first() {
        let (indices, arities) = (&first.mesh.indices, &first.mesh.face_arities);
        // polygon sizes; none listed means triangles only
        let sizes: Vec<usize> = if arities.is_empty() {
            vec![3; indices.len() / 3]
        } else {
            arities.iter().map(|&n| n as usize).collect()
        };
        let mut start = 0;
        for (k, &n) in sizes.iter().enumerate() {
            if n > MAX_POLYGON_CORNERS {
                dropped_polygons.push(DroppedPolygon {
                    line: face_line(bytes, k, n),
                    corners: n,
                });
            } else {
                let corners = &indices[start..start + n];
                polygon::triangulate(&first.mesh.positions, corners, &mut triangles);
            }
            start += n;
        }
    }
    let faces = triangles.iter().map(|t| t.map(|v| v as usize)).collect();
    Ok(MeshFile {
        mesh: TriangleMesh { vertices, faces },
        dropped_polygons,
    })
}

/// The line (1-based) of the file's `k`-th face (`f …`), if it has `corners` corners: the first
/// object's polygons are the file's first face lines, in order.
fn face_line(bytes: &[u8], k: usize, corners: usize) -> Option<usize> {
    let (number, line) = bytes
        .split(|&b| b == b'\n')
        .enumerate()
        .filter(|(_, line)| line.trim_ascii_start().starts_with(b"f "))
        .nth(k)?;
    let found = line
        .split(|b| b.is_ascii_whitespace())
        .filter(|w| !w.is_empty())
        .count()
        - 1;
    (found == corners).then_some(number + 1)
}

/// MuJoCo's `.msh`: four int32 counts (vertices, normals, texture coordinates, faces), then the
/// vertices (3 float32 each), normals, texture coordinates (2 float32 each) and faces (3 int32;
/// none: the mesh is its vertices' convex hull, [`TriangleMesh::closed`]).
fn read_msh(bytes: &[u8]) -> Result<TriangleMesh, String> {
    let int = |k: usize| -> Option<i32> {
        bytes
            .get(4 * k..4 * k + 4)
            .map(|b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let header: Option<Vec<i32>> = (0..4).map(int).collect();
    let Some([nv, nn, nt, nf]) = header.and_then(|h| <[i32; 4]>::try_from(h).ok()) else {
        return Err("not a MSH file: the header of four counts is missing".into());
    };
    let counts_fit = nv >= 4 && nf >= 0 && (nn == 0 || nn == nv) && (nt == 0 || nt == nv);
    let [nv, nn, nt, nf] = [nv, nn, nt, nf].map(|n| n.max(0) as usize);
    let expected = 16 + 12 * nv + 12 * nn + 8 * nt + 12 * nf;
    if !counts_fit || bytes.len() != expected {
        return Err(format!(
            "not a MSH file: its header gives {nv} vertices, {nn} normals, {nt} texture \
             coordinates and {nf} faces, which needs {expected} bytes, and the file has {}",
            bytes.len()
        ));
    }
    let float = |k: usize| {
        let b = &bytes[4 * k..4 * k + 4];
        f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let vertices = (0..nv)
        .map(|i| Vec3::new(float(4 + 3 * i), float(5 + 3 * i), float(6 + 3 * i)))
        .collect();
    let start = 4 + 3 * nv + 3 * nn + 2 * nt;
    let faces = (0..nf)
        .map(|i| {
            let index = |j: usize| int(start + 3 * i + j).unwrap_or(-1) as usize;
            [index(0), index(1), index(2)]
        })
        .collect();
    Ok(TriangleMesh { vertices, faces })
}

impl TriangleMesh {
    /// Checks the indices and the size MuJoCo asks for (at least 4 vertices and one face).
    pub fn check(&self) -> Result<(), String> {
        if self.vertices.len() < 4 {
            return Err(format!(
                "expected at least 4 vertices, got {}",
                self.vertices.len()
            ));
        }
        if self.faces.is_empty() {
            return Err("expected at least one face, got none".into());
        }
        if let Some((k, face)) = self
            .faces
            .iter()
            .enumerate()
            .find(|(_, f)| f.iter().any(|&v| v >= self.vertices.len()))
        {
            return Err(format!(
                "face {k} names vertex {:?}, but the mesh has {} vertices",
                face,
                self.vertices.len()
            ));
        }
        if let Some(k) = self
            .vertices
            .iter()
            .position(|v| !v.iter().all(|x| x.is_finite()))
        {
            return Err(format!("vertex {k} is not finite"));
        }
        Ok(())
    }

    /// The mesh moved by −`refpos`, rotated into the frame `refquat` (w, x, y, z) describes, and
    /// scaled, as MuJoCo applies `refpos`, `refquat` and `scale` (see [`reference_map`]).
    pub fn transformed(mut self, refpos: Vec3, refquat: [f64; 4], scale: Vec3) -> Self {
        let map = reference_map(refpos, refquat, scale);
        for vertex in &mut self.vertices {
            *vertex = map.transform_point(&(*vertex).into()).coords;
        }
        // a left-handed scale turns the faces inside out: reverse them
        if scale.x * scale.y * scale.z < 0.0 {
            for face in &mut self.faces {
                face.swap(1, 2);
            }
        }
        self
    }

    /// Area vector (b − a) × (c − a) and centroid (relative to `origin`) of face `f`.
    fn triangle(&self, f: &[usize; 3], origin: &Vec3) -> (Vec3, Vec3) {
        let [a, b, c] = f.map(|k| self.vertices[k] - origin);
        ((b - a).cross(&(c - a)), (a + b + c) / 3.0)
    }

    /// Volume (area for a shell), centre of mass and inertia about it, at unit density.
    pub fn mass_properties(&self, mode: MeshInertia) -> Result<MeshMassProperties, String> {
        if mode == MeshInertia::Convex {
            return self.convex_hull()?.mass_properties(MeshInertia::Exact);
        }
        if mode == MeshInertia::Exact {
            self.check_orientation()?;
        }
        // c_f: the faces' centroid, weighted by area
        let origin = Vec3::zeros();
        let (mut area, mut face_centre) = (0.0, Vec3::zeros());
        for face in &self.faces {
            let (w, centre) = self.triangle(face, &origin);
            let a = w.norm() / 2.0;
            area += a;
            face_centre += centre * a;
        }
        if area < MIN_VALUE {
            return Err("the mesh's surface area is too small".into());
        }
        face_centre /= area;
        // V and the centre of mass: one pyramid per face with its apex at c_f
        let (mut volume, mut com) = (0.0, Vec3::zeros());
        for face in &self.faces {
            let (w, centre) = self.triangle(face, &face_centre);
            let v = mode.pyramid(&w, &centre);
            volume += v;
            // ¾ c_t + ¼ c_f, with c_t relative to c_f here
            com += (centre * 0.75 + face_centre) * v;
        }
        if volume < MIN_VALUE {
            return Err(if volume < 0.0 {
                "the mesh's volume is negative (its triangles point inwards)".into()
            } else {
                "the mesh's volume is too small: try inertia='shell'".into()
            });
        }
        com /= volume;
        // P about the centre of mass; the volumes again, from the centre of mass
        let denominator = if mode == MeshInertia::Shell {
            12.0
        } else {
            20.0
        };
        let (mut p, mut total) = (Mat3::zeros(), 0.0);
        for face in &self.faces {
            let (w, centre) = self.triangle(face, &com);
            let v = mode.pyramid(&w, &centre);
            total += v;
            let [d, e, f] = face.map(|k| self.vertices[k] - com);
            // 2(D Dᵀ + E Eᵀ + F Fᵀ) + D Eᵀ + E Dᵀ + D Fᵀ + F Dᵀ + E Fᵀ + F Eᵀ
            //   = D Dᵀ + E Eᵀ + F Fᵀ + S Sᵀ, with S = D + E + F
            let s = d + e + f;
            let products =
                d * d.transpose() + e * e.transpose() + f * f.transpose() + s * s.transpose();
            p += products * (v / denominator);
        }
        // I = tr(P) 1 − P
        let inertia = Mat3::identity() * p.trace() - p;
        Ok(MeshMassProperties {
            volume: total,
            com,
            inertia,
        })
    }

    /// The mesh itself, or, when it has vertices only, their convex hull: MuJoCo's mesh of a
    /// `<mesh vertex>` without `face` (or a `.msh` without faces).
    pub fn closed(self) -> Result<TriangleMesh, String> {
        if self.faces.is_empty() && self.vertices.len() >= 4 {
            self.convex_hull()
        } else {
            Ok(self)
        }
    }

    /// The convex hull of the vertices (parry3d's), its triangles pointing out.
    pub fn convex_hull(&self) -> Result<TriangleMesh, String> {
        use parry3d_f64::math::Vector3;
        let points: Vec<Vector3> = self
            .vertices
            .iter()
            .map(|v| Vector3::new(v.x, v.y, v.z))
            .collect();
        let (vertices, faces) =
            parry3d_f64::transformation::try_convex_hull(&points).map_err(|e| {
                format!("the mesh has no convex hull ({e:?}): are its vertices coplanar?")
            })?;
        Ok(TriangleMesh {
            vertices: vertices.iter().map(|v| Vec3::new(v.x, v.y, v.z)).collect(),
            faces: faces.iter().map(|f| f.map(|k| k as usize)).collect(),
        })
    }

    /// `exact` needs every edge to be walked once each way: no two faces may share a directed
    /// edge (as MuJoCo checks it).
    fn check_orientation(&self) -> Result<(), String> {
        let mut edges: Vec<(usize, usize)> = self
            .faces
            .iter()
            .filter(|f| self.triangle(f, &Vec3::zeros()).0.norm() / 2.0 > MIN_VALUE.sqrt())
            .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
            .collect();
        edges.sort_unstable();
        match edges.windows(2).find(|w| w[0] == w[1]) {
            Some(w) => Err(format!(
                "the faces have inconsistent orientation (two faces walk from vertex {} to vertex \
                 {}): inertia='exact' needs a consistently oriented mesh",
                w[0].0 + 1,
                w[0].1 + 1
            )),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The corners of every face, by value.
    fn corners(mesh: &TriangleMesh) -> Vec<[Vec3; 3]> {
        mesh.faces
            .iter()
            .map(|f| f.map(|k| mesh.vertices[k]))
            .collect()
    }

    #[test]
    fn binary_and_ascii_stl_give_the_same_mesh() {
        let cube = cube();
        let mut triangles = Vec::new();
        for face in &cube.faces {
            let [a, b, c] = face.map(|k| {
                let v = cube.vertices[k].map(|x| x as f32);
                stl_io::Vector::new([v.x, v.y, v.z])
            });
            triangles.push(stl_io::Triangle {
                normal: stl_io::Vector::new([0.0; 3]),
                vertices: [a, b, c],
            });
        }
        let mut binary = Vec::new();
        stl_io::write_stl(&mut binary, triangles.iter()).unwrap();
        // a binary header may begin with "solid", as an ASCII file does
        binary[..5].copy_from_slice(b"solid");
        let mut ascii = String::from("solid cube\n");
        for t in &triangles {
            ascii += "facet normal 0 0 0\nouter loop\n";
            for v in t.vertices {
                ascii += &format!("vertex {} {} {}\n", v[0], v[1], v[2]);
            }
            ascii += "endloop\nendfacet\n";
        }
        ascii += "endsolid cube\n";
        let from_binary = read_stl(&binary).unwrap();
        let from_ascii = read_stl(ascii.as_bytes()).unwrap();
        assert_eq!(from_binary.vertices.len(), 8);
        assert_eq!(corners(&from_binary), corners(&cube));
        assert_eq!(corners(&from_ascii), corners(&cube));
    }

    /// The unit cube [0, 1]³, faces pointing out.
    fn cube() -> TriangleMesh {
        let vertices = (0..8)
            .map(|k| Vec3::new((k >> 2 & 1) as f64, (k >> 1 & 1) as f64, (k & 1) as f64))
            .collect();
        let faces = vec![
            [0, 1, 3],
            [0, 3, 2],
            [4, 6, 7],
            [4, 7, 5],
            [0, 4, 5],
            [0, 5, 1],
            [2, 3, 7],
            [2, 7, 6],
            [0, 2, 6],
            [0, 6, 4],
            [1, 5, 7],
            [1, 7, 3],
        ];
        TriangleMesh { vertices, faces }
    }

    #[test]
    fn a_unit_cube_has_the_closed_form_volume_centre_and_inertia() {
        for mode in [MeshInertia::Legacy, MeshInertia::Exact] {
            let properties = cube().mass_properties(mode).unwrap();
            assert!((properties.volume - 1.0).abs() < 1e-15);
            assert!((properties.com - Vec3::repeat(0.5)).norm() < 1e-15);
            // a cube of side 1 and mass 1: 1/6 about each axis through its centre
            assert!((properties.inertia - Mat3::identity() / 6.0).abs().max() < 1e-15);
        }
        // a shell of six unit squares: area 6, and 5/3 about each axis at unit areal density (5/18 per
        // unit mass)
        let shell = cube().mass_properties(MeshInertia::Shell).unwrap();
        assert!((shell.volume - 6.0).abs() < 1e-15);
        assert!((shell.inertia - Mat3::identity() * (5.0 / 3.0)).abs().max() < 1e-14);
    }

    #[test]
    fn inverted_or_inconsistent_faces_behave_as_in_mujoco() {
        let mut inverted = cube();
        for face in &mut inverted.faces {
            face.swap(1, 2);
        }
        // legacy counts each pyramid's volume positive; exact refuses a negative volume
        assert!(
            (inverted
                .mass_properties(MeshInertia::Legacy)
                .unwrap()
                .volume
                - 1.0)
                .abs()
                < 1e-15
        );
        assert!(inverted
            .mass_properties(MeshInertia::Exact)
            .unwrap_err()
            .contains("negative"));
        let mut mixed = cube();
        mixed.faces[0].swap(1, 2);
        assert!(mixed
            .mass_properties(MeshInertia::Exact)
            .unwrap_err()
            .contains("inconsistent orientation"));
        // the convex hull ignores the faces: the cube's hull is the cube
        let hull = mixed.mass_properties(MeshInertia::Convex).unwrap();
        assert!((hull.volume - 1.0).abs() < 1e-14);
        assert!((hull.com - Vec3::repeat(0.5)).norm() < 1e-14);
    }

    #[test]
    fn transforms_move_rotate_and_scale_the_vertices() {
        let moved = cube().transformed(
            Vec3::new(0.5, 0.5, 0.5),
            [1.0, 0.0, 0.0, 0.0],
            Vec3::new(2.0, 1.0, 1.0),
        );
        let properties = moved.mass_properties(MeshInertia::Exact).unwrap();
        assert!((properties.volume - 2.0).abs() < 1e-14 && properties.com.norm() < 1e-15);
        // a mirror turns the faces inside out; they are reversed, so the volume stays positive
        let mirrored = cube().transformed(
            Vec3::zeros(),
            [1.0, 0.0, 0.0, 0.0],
            Vec3::new(-1.0, 1.0, 1.0),
        );
        assert!((mirrored.mass_properties(MeshInertia::Exact).unwrap().volume - 1.0).abs() < 1e-15);
    }

    /// An OBJ pyramid: a regular `n`-gon base as one face (after a comment line) and `n` sides.
    fn pyramid_obj(n: usize) -> String {
        let mut text = String::from("# pyramid\n");
        for k in 0..n {
            let angle = std::f64::consts::TAU * k as f64 / n as f64;
            text += &format!("v {} {} 0\n", angle.cos(), angle.sin());
        }
        text += "v 0 0 1\nf";
        for k in (1..=n).rev() {
            text += &format!(" {k}");
        }
        text += "\n";
        for k in 1..=n {
            text += &format!("f {k} {} {}\n", k % n + 1, n + 1);
        }
        text
    }

    #[test]
    fn obj_faces_past_the_corner_limit_give_no_triangles() {
        let at_limit = read_mesh(pyramid_obj(MAX_POLYGON_CORNERS).as_bytes(), "obj").unwrap();
        assert!(at_limit.dropped_polygons.is_empty());
        // n − 2 triangles for the base, n for the sides
        assert_eq!(at_limit.mesh.faces.len(), 2 * MAX_POLYGON_CORNERS - 2);
        let n = MAX_POLYGON_CORNERS + 1;
        let past = read_mesh(pyramid_obj(n).as_bytes(), "obj").unwrap();
        assert_eq!(past.mesh.faces.len(), n);
        // the base is the first face, after the comment, the n + 1 vertices
        assert_eq!(
            past.dropped_polygons,
            vec![DroppedPolygon {
                line: Some(n + 3),
                corners: n
            }]
        );
        assert!(past.dropped_polygons[0]
            .describe()
            .starts_with(&format!("line {}: a face of {n} corners", n + 3)));
    }

    #[test]
    fn malformed_files_are_errors() {
        assert!(
            read_mesh(b"solid nothing", "stl").is_err()
                || read_mesh(b"solid nothing", "stl")
                    .unwrap()
                    .mesh
                    .check()
                    .is_err()
        );
        assert!(read_mesh(&[0u8; 10], "msh").unwrap_err().contains("header"));
        assert!(read_mesh(b"", "ply")
            .unwrap_err()
            .contains(".stl, .obj or .msh"));
        let obj = read_mesh(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "obj").unwrap();
        assert!(obj
            .mesh
            .check()
            .unwrap_err()
            .contains("at least 4 vertices"));
    }
}
