//! What a robot looks like: the visual geometry of its links (URDF `<visual>`, MJCF geoms), each
//! placed on the body it moves with. The dynamics never read it; the viewer draws it.

use crate::io::mesh::TriangleMesh;
use crate::spatial::{Transform, Vec3};
use nalgebra::Matrix4;
use std::path::PathBuf;

/// MuJoCo's geom colour when neither the geom nor a material gives one.
pub const DEFAULT_RGBA: [f64; 4] = [0.5, 0.5, 0.5, 1.0];

/// Where a mesh's triangles come from.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum MeshSource {
    /// A file on disk (STL, OBJ, MuJoCo's .msh, Collada, glTF, ...), found when the model loaded.
    File(PathBuf),
    /// Vertices and faces written in the model file itself (MJCF `<mesh vertex face>`).
    Inline(TriangleMesh),
    /// A file that could not be found: the message names the element, the file and every folder
    /// tried. Loading succeeds (the dynamics do not need it); drawing the mesh fails with it.
    Missing(String),
}

/// The shape of a visual, in its own frame (the z axis is the axis of cylinders and capsules).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Shape {
    Box {
        half_extents: Vec3,
    },
    Sphere {
        radius: f64,
    },
    Cylinder {
        radius: f64,
        half_length: f64,
    },
    Capsule {
        radius: f64,
        half_length: f64,
    },
    Ellipsoid {
        radii: Vec3,
    },
    /// A plane z = 0 of half-sides x, y (0: unbounded, drawn as the viewer's ground).
    Plane {
        half_extents: [f64; 2],
    },
    /// A triangle mesh; `file_to_visual` maps the file's coordinates into the visual's frame
    /// (scale, and MJCF's `refpos`/`refquat`), an affine map that may scale.
    Mesh {
        source: MeshSource,
        file_to_visual: Matrix4<f64>,
    },
}

impl Shape {
    /// The shape's kind, as MJCF names geom types.
    pub fn kind(&self) -> &'static str {
        match self {
            Shape::Box { .. } => "box",
            Shape::Sphere { .. } => "sphere",
            Shape::Cylinder { .. } => "cylinder",
            Shape::Capsule { .. } => "capsule",
            Shape::Ellipsoid { .. } => "ellipsoid",
            Shape::Plane { .. } => "plane",
            Shape::Mesh { .. } => "mesh",
        }
    }
}

/// One piece of visual geometry.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Visual {
    /// Its name in the file, or one made from the link or body and its position there.
    pub name: String,
    /// The body it moves with (0 = world).
    pub body: usize,
    /// `X_{visual←body}`: the visual's frame relative to its body.
    pub placement: Transform,
    pub shape: Shape,
    /// Colour and opacity, each in [0, 1].
    pub rgba: [f64; 4],
    /// MJCF's geom group (0 for URDF); MuJoCo shows groups 0, 1 and 2 by default.
    pub group: i64,
    /// The element it comes from (file, element, line), for messages about it.
    pub element: String,
}
