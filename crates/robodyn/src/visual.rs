//! What a robot looks like: the visual geometry of its links (URDF `<visual>`, MJCF geoms), each
//! placed on the body it moves with. The dynamics never read it; the viewer draws it.

use crate::collision::height_field::HeightField;
use crate::collision::hull::ConvexHull;
use crate::io::mesh::TriangleMesh;
use crate::spatial::{Transform, Vec3};
use nalgebra::Matrix4;
use std::path::PathBuf;
use std::sync::Arc;

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
    /// A box centred on the origin.
    Box {
        /// Half its sides along x, y and z.
        half_extents: Vec3,
    },
    /// A sphere centred on the origin.
    Sphere {
        /// Its radius.
        radius: f64,
    },
    /// A cylinder along z, centred on the origin.
    Cylinder {
        /// Its radius.
        radius: f64,
        /// Half its length along z.
        half_length: f64,
    },
    /// A capsule along z: a cylinder with a half-sphere on each end.
    Capsule {
        /// The radius of the cylinder and of its end caps.
        radius: f64,
        /// Half the length of its cylinder along z (the caps not counted).
        half_length: f64,
    },
    /// An ellipsoid centred on the origin, its axes along x, y and z.
    Ellipsoid {
        /// Its semi-axes along x, y and z.
        radii: Vec3,
    },
    /// A plane z = 0 of half-sides x, y (0: unbounded, drawn as the viewer's ground).
    Plane {
        /// Half its sides along x and y.
        half_extents: [f64; 2],
    },
    /// A triangle mesh; `file_to_visual` maps the file's coordinates into the visual's frame
    /// (scale, and MJCF's `refpos`/`refquat`), an affine map that may scale.
    Mesh {
        /// Where its triangles come from.
        source: MeshSource,
        /// The homogeneous map from the file's coordinates to the visual's frame.
        file_to_visual: Matrix4<f64>,
        /// Its convex hull in the visual's frame, what contacts see: set on a model's collision
        /// geoms (MJCF mesh geoms that may touch something), `None` on what is only drawn.
        #[serde(default)]
        hull: Option<Arc<ConvexHull>>,
    },
    /// A height field: a terrain sampled on a grid over a rectangle about the origin.
    HeightField {
        /// Its grid and elevations.
        field: Arc<HeightField>,
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
            Shape::HeightField { .. } => "hfield",
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
    /// Its shape, in the visual's frame.
    pub shape: Shape,
    /// Colour and opacity, each in [0, 1].
    pub rgba: [f64; 4],
    /// MJCF's geom group (0 for URDF); MuJoCo shows groups 0, 1 and 2 by default.
    pub group: i64,
    /// The element it comes from (file, element, line), for messages about it.
    pub element: String,
    /// The texture its material lays on it (MJCF), drawn times `rgba`.
    pub texture: Option<TextureMapping>,
}

/// What an MJCF `<texture>` is for (`type`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum TextureKind {
    /// An image laid on a surface by texture coordinates (`2d`).
    Planar,
    /// Six square faces around the object (`cube`).
    Cube,
    /// Six square faces around the whole scene, its background (`skybox`).
    Skybox,
}

impl TextureKind {
    /// The kind as MJCF names it.
    pub fn as_str(&self) -> &'static str {
        match self {
            TextureKind::Planar => "2d",
            TextureKind::Cube => "cube",
            TextureKind::Skybox => "skybox",
        }
    }
}

/// The image of a texture MuJoCo draws itself (`builtin`): `pattern` in `rgb1` and `rgb2`, then
/// the `mark` in `markrgb`, on `width` x `height` pixels (each face of a cube `width` square).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BuiltinTexture {
    /// "gradient", "checker" or "flat".
    pub pattern: String,
    /// The first colour of the pattern (RGB in [0, 1]).
    pub rgb1: [f64; 3],
    /// The second colour of the pattern (RGB in [0, 1]).
    pub rgb2: [f64; 3],
    /// "none", "edge", "cross" or "random" (dots, each pixel with probability `random`).
    pub mark: String,
    /// The colour of the mark (RGB in [0, 1]).
    pub mark_rgb: [f64; 3],
    /// The probability of a random dot per pixel (mark "random").
    pub random: f64,
    /// Its width in pixels.
    pub width: usize,
    /// Its height in pixels.
    pub height: usize,
}

/// Where a texture's image comes from.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum TextureImage {
    /// A PNG file, mirrored left to right (`hflip`) or top to bottom (`vflip`) when drawn.
    File {
        /// The PNG file, found when the model loaded.
        path: PathBuf,
        /// Mirror it left to right.
        hflip: bool,
        /// Mirror it top to bottom.
        vflip: bool,
    },
    /// An image MuJoCo draws itself.
    Builtin(BuiltinTexture),
    /// A texture robodyn cannot draw, and why (a file not found, not a PNG, a cube's faces from
    /// files): the viewer draws the material's colour and warns.
    Undrawable(String),
}

/// An MJCF `<texture>`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Texture {
    /// Its name in the file (or one made from its position there).
    pub name: String,
    /// What it is for.
    pub kind: TextureKind,
    /// Where its image comes from.
    pub image: TextureImage,
    /// The element it comes from (file, element, line), for messages about it.
    pub element: String,
}

/// A texture as a material lays it on a geom: `repeat` times over the geom (`texrepeat`), or
/// per two spatial units where `uniform` (`texuniform`).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TextureMapping {
    /// The texture laid on.
    pub texture: Texture,
    /// How many times it repeats over the geom in each direction (`texrepeat`).
    pub repeat: [f64; 2],
    /// Repeat per two spatial units rather than over the whole geom (`texuniform`).
    pub uniform: bool,
}
