//! Collision detection: where a model's geoms touch. This layer knows shapes, bodies and the
//! file's filters, nothing of dynamics.
//!
//! Reference: MuJoCo's documentation, "Computation", §Collision detection; the contacts are the
//! ones MuJoCo's collision functions generate (read to understand, written anew here): the same
//! number of contacts per pair, at the same points, with the same frames and distances.
//!
//! A contact between geoms A and B (A the one of lower MuJoCo type: plane, height field,
//! sphere, capsule, ellipsoid, cylinder, box, mesh) is
//! ```text
//!   distance d   signed: negative when they overlap (m)
//!   position p   midway between the two surfaces along the normal
//!   frame        rows n, t₁, t₂: n the unit normal from A to B, t₁, t₂ tangents, n × t₁ = t₂
//! ```
//! and exists when `d ≤ margin + gap` of the pair ([`crate::soft::contact_parameters`]).
//!
//! The modules: [`pairs`] (which geoms may touch), [`primitives`] (planes, spheres, capsules,
//! cylinders, in closed form), [`boxes`] and [`box_box`] (boxes against spheres, capsules
//! and boxes), and [`convex`] with [`gjk`] for the pairs MuJoCo collides by the support
//! functions of convex shapes (an ellipsoid against anything, a cylinder against a capsule, a
//! cylinder or a box), meshes by their convex hulls ([`hull`]), and height fields
//! ([`height_field`]) prism by prism.

pub mod box_box;
pub mod boxes;
pub mod convex;
pub mod gjk;
pub mod height_field;
pub mod hull;
pub mod pairs;
pub mod primitives;

pub use pairs::candidate_pairs;

use crate::model::Model;
use crate::spatial::{Mat3, Transform, Vec3};
use crate::visual::Shape;

/// A shape where it is in the world.
#[derive(Debug, Clone, Copy)]
pub struct Placed<'a> {
    /// Its shape, in its own frame.
    pub shape: &'a Shape,
    /// Its axes in world coordinates (the columns): maps its frame's vectors to the world's.
    pub rotation: Mat3,
    /// Its origin in world coordinates.
    pub position: Vec3,
}

impl<'a> Placed<'a> {
    /// `shape` placed by `X_{shape←world}` (a Featherstone transform).
    pub fn new(shape: &'a Shape, x_shape_world: &Transform) -> Self {
        Placed {
            shape,
            rotation: x_shape_world.rotation.transpose(),
            position: x_shape_world.translation,
        }
    }

    /// Its `k`-th axis in world coordinates.
    #[inline]
    pub fn axis(&self, k: usize) -> Vec3 {
        self.rotation.column(k).into_owned()
    }
}

/// What a collision function finds: one point where two shapes touch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Touch {
    /// Signed distance between the surfaces (negative: overlap).
    pub distance: f64,
    /// Midway between the two surfaces along the normal.
    pub position: Vec3,
    /// Unit normal from the first shape to the second.
    pub normal: Vec3,
    /// A first tangent the function prefers (zero: none; see [`contact_frame`]).
    pub tangent: Vec3,
}

impl Touch {
    /// A touch without a preferred tangent.
    #[inline]
    pub fn new(distance: f64, position: Vec3, normal: Vec3) -> Self {
        Touch {
            distance,
            position,
            normal,
            tangent: Vec3::zeros(),
        }
    }
}

/// A collision function: appends to `touches` the points where `first` and `second` are within
/// `margin` (MuJoCo keeps a distance equal to it), normals from `first` to `second`.
pub type Collider = fn(first: &Placed, second: &Placed, margin: f64, touches: &mut Vec<Touch>);

/// MuJoCo's order of geom types (`mjtGeom`): of two geoms the lower one comes first.
pub fn type_rank(shape: &Shape) -> usize {
    match shape {
        Shape::Plane { .. } => 0,
        Shape::HeightField { .. } => 1,
        Shape::Sphere { .. } => 2,
        Shape::Capsule { .. } => 3,
        Shape::Ellipsoid { .. } => 4,
        Shape::Cylinder { .. } => 5,
        Shape::Box { .. } => 6,
        Shape::Mesh { .. } => 7,
    }
}

/// The contact frame (rows: normal, first tangent, second tangent) from a unit `normal` and a
/// preferred `tangent`. A tangent shorter than ½ is replaced by y = (0, 1, 0), or by
/// z = (0, 0, 1) when the normal is within 60° of y; then
/// ```text
///   t₁ = (t − n (n·t)) / |t − n (n·t)|,   t₂ = n × t₁
/// ```
/// (t₁ = x when the tangent is along the normal: an upright capsule on a plane).
pub fn contact_frame(normal: &Vec3, tangent: &Vec3) -> Mat3 {
    // the normal made unit once more, n (1/|n|), as MuJoCo does
    let normal = normal * (1.0 / normal.norm());
    let mut t = *tangent;
    if t.norm_squared() < 0.25 {
        t = if normal.y > -0.5 && normal.y < 0.5 {
            Vec3::new(0.0, 1.0, 0.0)
        } else {
            Vec3::new(0.0, 0.0, 1.0)
        };
    }
    // a tangent along the normal leaves nothing: x, as MuJoCo takes it
    let across = t - normal * normal.dot(&t);
    let length = across.norm();
    let t1 = if length < 1e-15 {
        Vec3::x()
    } else {
        across / length
    };
    let t2 = normal.cross(&t1);
    Mat3::from_rows(&[normal.transpose(), t1.transpose(), t2.transpose()])
}

/// The collision function of two shapes, the lower type first (`None`: a mesh without its hull,
/// which is only drawn, or two of planes and height fields, which never touch).
pub fn collider(first: &Shape, second: &Shape) -> Option<Collider> {
    use Shape::*;
    let function: Collider = match (first, second) {
        (Mesh { hull: None, .. }, _) | (_, Mesh { hull: None, .. }) => return None,
        (Plane { .. }, Mesh { .. }) => convex::plane_mesh,
        (Plane { .. }, Sphere { .. }) => primitives::plane_sphere,
        (Plane { .. }, Capsule { .. }) => primitives::plane_capsule,
        (Plane { .. }, Cylinder { .. }) => primitives::plane_cylinder,
        (Plane { .. }, Box { .. }) => primitives::plane_box,
        (Sphere { .. }, Sphere { .. }) => primitives::sphere_sphere,
        (Sphere { .. }, Capsule { .. }) => primitives::sphere_capsule,
        (Sphere { .. }, Cylinder { .. }) => primitives::sphere_cylinder,
        (Sphere { .. }, Box { .. }) => boxes::sphere_box,
        (Capsule { .. }, Capsule { .. }) => primitives::capsule_capsule,
        (Capsule { .. }, Box { .. }) => boxes::capsule_box,
        (Box { .. }, Box { .. }) => box_box::box_box,
        (Plane { .. }, Ellipsoid { .. }) => convex::plane_convex,
        (Plane { .. }, _) | (_, Plane { .. }) => return None,
        (HeightField { .. }, HeightField { .. }) => return None,
        (HeightField { .. }, _) => convex::height_field_convex,
        _ => convex::convex_convex,
    };
    Some(function)
}

/// Whether two shapes never touch in MuJoCo: planes and height fields have no collision
/// function between them (its table's empty entries).
pub fn never_touch(first: &Shape, second: &Shape) -> bool {
    let ground = |shape: &Shape| matches!(shape, Shape::Plane { .. } | Shape::HeightField { .. });
    ground(first) && ground(second)
}

/// One contact between two of a model's geoms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// The two geoms (indices into [`Model::geoms`]), the lower type first.
    pub geoms: (usize, usize),
    /// The explicit pair ([`Model::contact_pairs`]) it comes from, if any.
    pub pair: Option<usize>,
    /// Signed distance (m; negative: overlap).
    pub distance: f64,
    /// Midway between the surfaces (world coordinates).
    pub position: Vec3,
    /// Rows: the normal from the first geom to the second, then two tangents.
    pub frame: Mat3,
}

/// A pair of geoms checked for contact: the geoms (lower type first) and the explicit pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckedPair {
    /// The two geoms, the lower type first.
    pub geoms: (usize, usize),
    /// The explicit pair it is, if any.
    pub pair: Option<usize>,
    /// The distance within which a contact counts (MuJoCo's margin: the contact's `margin`
    /// and `gap` together).
    pub margin: f64,
    /// Geoms whose origins are farther apart than this cannot touch: their bounding spheres'
    /// radii and the margin (infinite when one is a plane).
    pub reach: f64,
}

/// Every pair of geoms checked for contact, in MuJoCo's order: by the two file bodies (the lower
/// body id first), an explicit pair before the dynamic ones of the same bodies. Dynamic pairs of
/// two bodies come in the order of their geoms, (lower type, other), as MuJoCo sorts the
/// contacts of its bounding-volume trees (the `midphase`); with the `midphase` flag disabled,
/// in the order of the file, the first body's geom first. None when the `contact` or
/// `constraint` flag is disabled.
pub fn checked_pairs(model: &Model) -> Vec<CheckedPair> {
    let options = &model.options;
    if !options.flag("contact") || !options.flag("constraint") {
        return Vec::new();
    }
    let signature = |g1: usize, g2: usize| {
        let (b1, b2) = (model.geoms[g1].source_body, model.geoms[g2].source_body);
        (b1.min(b2), b1.max(b2))
    };
    let midphase = options.flag("midphase");
    // (the two bodies, explicit 0 or dynamic 1, the order within, the pair)
    type Keyed = ((usize, usize), usize, (usize, usize), CheckedPair);
    let mut keyed: Vec<Keyed> = Vec::new();
    for (index, pair) in model.contact_pairs.iter().enumerate() {
        let (g1, g2) = pair.geoms;
        let checked = lower_type_first(model, g1, g2, Some(index));
        keyed.push((signature(g1, g2), 0, (index, 0), checked));
    }
    for (g1, g2) in candidate_pairs(model) {
        let checked = lower_type_first(model, g1, g2, None);
        let order = if midphase { checked.geoms } else { (g1, g2) };
        keyed.push((signature(g1, g2), 1, order, checked));
    }
    keyed.sort_by_key(|&(signature, kind, order, _)| (signature, kind, order));
    keyed.into_iter().map(|(.., pair)| pair).collect()
}

/// The pair with its geom of lower type first.
fn lower_type_first(model: &Model, g1: usize, g2: usize, pair: Option<usize>) -> CheckedPair {
    let rank = |g: usize| type_rank(&model.geoms[g].shape);
    let geoms = if rank(g1) > rank(g2) {
        (g2, g1)
    } else {
        (g1, g2)
    };
    let parameters = crate::soft::contact_parameters(model, g1, g2);
    let margin = parameters.margin + parameters.gap;
    let radius = |g: usize| bounding_radius(&model.geoms[g].shape);
    CheckedPair {
        geoms,
        pair,
        margin,
        reach: radius(g1) + radius(g2) + margin,
    }
}

/// The radius of the smallest sphere about the shape's origin that holds it (MuJoCo's
/// `rbound`; for a mesh, its hull's corners' farthest); infinite for a plane and a mesh
/// without its hull.
fn bounding_radius(shape: &Shape) -> f64 {
    match shape {
        Shape::Sphere { radius } => *radius,
        Shape::Capsule {
            radius,
            half_length,
        } => radius + half_length,
        Shape::Cylinder {
            radius,
            half_length,
        } => radius.hypot(*half_length),
        Shape::Box { half_extents } => half_extents.norm(),
        Shape::Ellipsoid { radii } => radii.max(),
        Shape::Mesh {
            hull: Some(hull), ..
        } => hull.radius,
        Shape::HeightField { field } => field.radius(),
        Shape::Plane { .. } | Shape::Mesh { hull: None, .. } => f64::INFINITY,
    }
}

/// The contacts of the geom pairs `pairs` ([`checked_pairs`]) with the bodies placed at
/// `x_world` (`X_{i←0}` of each body, as [`crate::algo::forward_kinematics`] leaves them), into
/// `contacts` (cleared first). Allocates nothing once `scratch` and `contacts` have grown to
/// their size.
pub fn collide(
    model: &Model,
    x_world: &[Transform],
    pairs: &[CheckedPair],
    scratch: &mut CollisionScratch,
    contacts: &mut Vec<Contact>,
) {
    // each geom placed once: X_{geom←0} = X_{geom←body} X_{body←0}
    let CollisionScratch { touches, poses } = scratch;
    poses.clear();
    poses.extend(model.geoms.iter().map(|geom| {
        let x = geom.placement * x_world[geom.body];
        (x.rotation.transpose(), x.translation)
    }));
    let place = |g: usize| Placed {
        shape: &model.geoms[g].shape,
        rotation: poses[g].0,
        position: poses[g].1,
    };
    collide_placed(model, place, pairs, touches, contacts);
}

/// [`collide`]'s scratch space.
#[derive(Debug, Clone, Default)]
pub struct CollisionScratch {
    /// One pair's contacts.
    pub touches: Vec<Touch>,
    /// Each geom's axes and origin in world coordinates.
    poses: Vec<(Mat3, Vec3)>,
}

/// [`collide`] with each geom `g` placed in the world by `place(g)` instead of by its body.
pub fn collide_placed<'m>(
    model: &'m Model,
    place: impl Fn(usize) -> Placed<'m>,
    pairs: &[CheckedPair],
    touches: &mut Vec<Touch>,
    contacts: &mut Vec<Contact>,
) {
    contacts.clear();
    for checked in pairs {
        let (g1, g2) = checked.geoms;
        let (one, other) = (&model.geoms[g1], &model.geoms[g2]);
        let Some(function) = collider(&one.shape, &other.shape) else {
            continue;
        };
        // bounding spheres apart: no contact (MuJoCo's `rbound` test)
        let (first, second) = (place(g1), place(g2));
        if (first.position - second.position).norm() > checked.reach {
            continue;
        }
        touches.clear();
        function(&first, &second, checked.margin, touches);
        contacts.extend(touches.iter().map(|touch| Contact {
            geoms: checked.geoms,
            pair: checked.pair,
            distance: touch.distance,
            position: touch.position,
            frame: contact_frame(&touch.normal, &touch.tangent),
        }));
    }
}
