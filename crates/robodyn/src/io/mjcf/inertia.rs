//! The inertia of an MJCF body: from its `<inertial>` or from its geoms.
//!
//! Inertia from geoms, as MuJoCo's compiler computes it: each primitive is a solid of uniform
//! density (`density`, default 1000 kg/m³, or the geom's `mass`; with `fromto`, the segment is the
//! z axis, and a box or ellipsoid on it has x and y half-sizes both `size[0]`) whose principal
//! moments about its centre are, with m its mass,
//!   sphere of radius r:            ⅖ m r² (all three)
//!   ellipsoid of semi-axes a,b,c:  m(b²+c²)/5, m(a²+c²)/5, m(a²+b²)/5
//!   box of half-sides a,b,c:       m(b²+c²)/3, m(a²+c²)/3, m(a²+b²)/3
//!   cylinder, radius r, length L:  m(3r²+L²)/12 across, m r²/2 along its axis
//!   capsule, cylinder (mass m_c, length L) and two hemispheres (together a sphere of mass m_s):
//!     across m_c(L²/12 + r²/4) + m_s(2r²/5 + L²/4 + 3Lr/8), along m_c r²/2 + m_s 2r²/5
//! and the body's inertia is their sum, each shifted from its own pose (parallel-axis theorem).

use super::Reader;
use crate::error::Result;
use crate::io::xml::parse_number_list;
use crate::model::{check_mass_and_inertia, check_positive_semidefinite};
use crate::spatial::{Inertia, Mat3, Transform, Vec3};
use crate::visual::Shape;
use nalgebra::Rotation3;
use roxmltree::Node;
use std::f64::consts::PI;

/// MuJoCo's default geom density, kg/m³ (water).
const DEFAULT_DENSITY: f64 = 1000.0;

/// Below this a geom's mass does not count among a body's geoms (MuJoCo's `mjEPS`).
const MASSLESS: f64 = 1e-14;

/// Where MuJoCo's compiler puts a body's principal axes of inertia (its `iquat`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum InertiaAxes {
    /// The axes given: an `<inertial>`'s with `diaginertia`, or the one massive geom's own
    /// (rotation from them to the body's axes).
    Given(Mat3),
    /// Found by an eigen-decomposition of the total (several geoms, a mesh, `fullinertia`):
    /// the moments in decreasing order.
    Principal,
}

/// `<compiler inertiafromgeom>`: where a body's inertia comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum InertiaFromGeoms {
    /// From `<inertial>` when the body has one, else from its geoms (MuJoCo's default).
    Auto,
    /// Always from the geoms.
    Always,
    /// Only from `<inertial>`; a body without one is massless.
    Never,
}

impl<'a> Reader<'a> {
    /// A geom's or site's `fromto` (x1 y1 z1 x2 y2 z2), when it has one: the frame at the
    /// segment's midpoint with z pointing from the second point to the first (the shortest
    /// rotation from z, as MuJoCo places it), and the half-length. Only capsules, cylinders, boxes
    /// and ellipsoids take one.
    pub(super) fn segment(
        &self,
        node: Node<'a, 'a>,
        class: &str,
        kind: &str,
    ) -> Result<Option<(Transform, f64)>> {
        let Some([x1, y1, z1, x2, y2, z2]) = self.numbers::<6>(node, class, "fromto")? else {
            return Ok(None);
        };
        let (from, to) = (Vec3::new(x1, y1, z1), Vec3::new(x2, y2, z2));
        let axis = from - to;
        let half_length = axis.norm() / 2.0;
        if half_length == 0.0 || !matches!(kind, "capsule" | "cylinder" | "box" | "ellipsoid") {
            return Err(self.error(
                node,
                "attribute 'fromto': expected two distinct points on a capsule, cylinder, box or ellipsoid",
            ));
        }
        let rotation = Rotation3::rotation_between(&Vec3::z(), &axis)
            .unwrap_or_else(|| Rotation3::from_axis_angle(&Vec3::x_axis(), PI));
        Ok(Some((
            Transform::from_pose(rotation.matrix(), &((from + to) / 2.0)),
            half_length,
        )))
    }

    /// A geom's `group` (0 unless given).
    pub(super) fn geom_group(&self, geom: Node<'a, 'a>, class: &str) -> Result<i64> {
        self.integer(geom, class, "group", 0)
    }

    /// A geom's `type` (MuJoCo's default: a sphere).
    pub(super) fn geom_type(&self, geom: Node<'a, 'a>, class: &str) -> String {
        self.attribute(geom, class, "type")
            .unwrap_or_else(|| "sphere".to_string())
    }

    /// A geom's `size` and `X_{geom←element}`, as MuJoCo sizes and places it: along its `fromto`
    /// segment (z the segment, the last size its half-length; a box or ellipsoid on it has a
    /// square or round section of `size[0]`), or fitted to its `mesh` when a primitive names one.
    pub(super) fn geom_size_and_frame(
        &self,
        geom: Node<'a, 'a>,
        class: &str,
        kind: &str,
    ) -> Result<(Vec<f64>, Transform)> {
        let mut size = match self.attribute(geom, class, "size") {
            Some(t) => parse_number_list(&t, "size").map_err(|m| self.error(geom, m))?,
            None => Vec::new(),
        };
        let mut frame = self.placement(geom, class)?;
        if let Some((segment, half_length)) = self.segment(geom, class, kind)? {
            let radius = size.first().copied().unwrap_or(0.0);
            size = if matches!(kind, "box" | "ellipsoid") {
                vec![radius, radius, half_length]
            } else {
                vec![radius, half_length]
            };
            frame = segment;
        }
        if let (Some(mesh), true) = (self.attribute(geom, class, "mesh"), kind != "mesh") {
            (size, frame) = self.fitted_primitive(geom, class, &mesh, kind, &frame)?;
        }
        Ok((size, frame))
    }

    /// The spatial inertia of a body, in its frame: from `<inertial>` or from its geoms, as
    /// `<compiler inertiafromgeom>` says; and where MuJoCo's compiler puts its principal axes.
    pub(super) fn body_inertia(
        &self,
        elements: &[Node<'a, 'a>],
        class: &str,
    ) -> Result<(Inertia, InertiaAxes)> {
        let mut inertials = Vec::new();
        self.framed_elements(
            elements,
            class,
            &["inertial"],
            Transform::IDENTITY,
            &mut inertials,
        )?;
        match (self.inertia_from_geoms, inertials.first()) {
            (InertiaFromGeoms::Never, None) => {
                Ok((Inertia::ZERO, InertiaAxes::Given(Mat3::identity())))
            }
            (
                InertiaFromGeoms::Auto | InertiaFromGeoms::Never,
                Some((inertial, to_frame, class)),
            ) => {
                let inertia = to_frame.transpose_apply_inertia(&self.inertial(*inertial, class)?);
                let rotation = to_frame.rotation.transpose()
                    * self.placement(*inertial, class)?.rotation.transpose();
                let axes = match self.numbers::<6>(*inertial, class, "fullinertia")? {
                    Some(_) => InertiaAxes::Principal,
                    None => InertiaAxes::Given(rotation),
                };
                Ok((inertia, axes))
            }
            // each geom's mass and inertia is checked where it is read
            (InertiaFromGeoms::Always, _) | (InertiaFromGeoms::Auto, None) => {
                let mut parts = Vec::new();
                self.geom_parts(elements, class, &Mat3::identity(), &mut parts)?;
                let total = parts
                    .iter()
                    .fold(Inertia::ZERO, |sum, (inertia, _)| sum + *inertia);
                let massive: Vec<_> = parts.iter().filter(|(i, _)| i.mass > MASSLESS).collect();
                let axes = match massive.as_slice() {
                    [] => InertiaAxes::Given(Mat3::identity()),
                    [(_, Some(rotation))] => InertiaAxes::Given(*rotation),
                    _ => InertiaAxes::Principal,
                };
                Ok((total, axes))
            }
        }
    }

    /// The inertia of each geom among `elements` and inside their `<frame>`s, in the frame the
    /// elements are written in (turned by `rotation` from the body's), with its axes' rotation
    /// in the body's frame (`None` for a mesh, whose axes are its principal ones).
    fn geom_parts(
        &self,
        elements: &[Node<'a, 'a>],
        class: &str,
        rotation: &Mat3,
        parts: &mut Vec<(Inertia, Option<Mat3>)>,
    ) -> Result<()> {
        for element in elements {
            if element.has_tag_name("geom") {
                let inertia = self.geom_inertia(*element, class)?;
                let geom_class = self.declared_class(*element, "class", class)?;
                let kind = self.geom_type(*element, geom_class);
                let axes = match kind.as_str() {
                    "mesh" => None,
                    _ => {
                        let (_, frame) = self.geom_size_and_frame(*element, geom_class, &kind)?;
                        Some(rotation * frame.rotation.transpose())
                    }
                };
                parts.push((inertia, axes));
            } else if element.has_tag_name("frame") {
                let inner_class = self.declared_class(*element, "childclass", class)?;
                let placement = self.placement(*element, class)?;
                let mut inside = Vec::new();
                let turned = rotation * placement.rotation.transpose();
                self.geom_parts(&self.children(*element)?, inner_class, &turned, &mut inside)?;
                parts.extend(
                    inside
                        .into_iter()
                        .map(|(inertia, axes)| (placement.transpose_apply_inertia(&inertia), axes)),
                );
            }
        }
        Ok(())
    }

    /// `<inertial>`: mass, centre of mass and the inertia about it, in the body's frame.
    pub(super) fn inertial(&self, inertial: Node<'a, 'a>, class: &str) -> Result<Inertia> {
        let mass = self
            .numbers::<1>(inertial, class, "mass")?
            .ok_or_else(|| self.error(inertial, "missing attribute 'mass'"))?[0];
        let principal =
            if let Some([a, b, c]) = self.numbers::<3>(inertial, class, "diaginertia")? {
                Mat3::from_diagonal(&Vec3::new(a, b, c))
            } else if let Some([xx, yy, zz, xy, xz, yz]) =
                self.numbers::<6>(inertial, class, "fullinertia")?
            {
                Mat3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz)
            } else {
                // MuJoCo reads an <inertial> without a tensor as a point mass
                Mat3::zeros()
            };
        let frame = self.placement(inertial, class)?;
        self.inertia_in_body(inertial, mass, &principal, &frame)
    }

    /// A solid of `mass` whose inertia about its centre, in its own axes, is `principal`, placed
    /// at `X_{element←body}`: its spatial inertia in the body's frame (I_body = R I Rᵀ at the
    /// centre, shifted by the parallel-axis theorem inside `Inertia::from_com`).
    pub(super) fn inertia_in_body(
        &self,
        element: Node<'a, 'a>,
        mass: f64,
        principal: &Mat3,
        frame: &Transform,
    ) -> Result<Inertia> {
        let rotation = frame.rotation.transpose();
        let inertia_com = rotation * principal * rotation.transpose();
        check_mass_and_inertia(mass, &inertia_com)
            .and_then(|_| check_positive_semidefinite(&inertia_com))
            .map_err(|m| self.error(element, m))?;
        Ok(Inertia::from_com(mass, &frame.translation, &inertia_com))
    }

    /// The inertia of a primitive `<geom>` of uniform density, in the body's frame.
    pub(super) fn geom_inertia(&self, geom: Node<'a, 'a>, class: &str) -> Result<Inertia> {
        let class = self.declared_class(geom, "class", class)?;
        let text = |name: &str| self.attribute(geom, class, name);
        let group = self.geom_group(geom, class)?;
        if group < self.inertia_groups.0 || group > self.inertia_groups.1 {
            return Ok(Inertia::ZERO);
        }
        let given_mass = self.numbers::<1>(geom, class, "mass")?.map(|[m]| m);
        if given_mass == Some(0.0) {
            return Ok(Inertia::ZERO);
        }
        let kind = self.geom_type(geom, class);
        let (size, frame) = self.geom_size_and_frame(geom, class, &kind)?;
        let no_volume = || {
            self.error(
                geom,
                format!("a '{kind}' geom has no volume to give the body an inertia: give the body an <inertial>"),
            )
        };
        match kind.as_str() {
            "mesh" => {
                let density = self.numbers::<1>(geom, class, "density")?.map_or(DEFAULT_DENSITY, |[d]| d);
                return self.mesh_geom_inertia(geom, class, &frame, given_mass, density);
            }
            "sdf" => {
                return Err(self.error(
                    geom,
                    "an sdf geom's inertia comes from its plugin, which robodyn does not run: give the body an <inertial>",
                ))
            }
            // a plane has no mass (it may only be on a body welded to the world)
            "plane" => return Ok(Inertia::ZERO),
            _ => {}
        }
        // the shape checks the size, as the viewer reads it; a height field weighs as MuJoCo's
        // box of half-sides (s₀, s₁, s₂/4 + s₃/2)
        let shape = match self.geom_shape(geom, class, &kind, &size)? {
            Shape::HeightField { field } => Shape::Box {
                half_extents: Vec3::new(
                    field.half_extents[0],
                    field.half_extents[1],
                    0.25 * field.top + 0.5 * field.base,
                ),
            },
            shape => shape,
        };
        if text("shellinertia").as_deref() == Some("true") {
            return Err(self.error(
                geom,
                format!("attribute 'shellinertia': a hollow {kind} is not supported (only a mesh's shell): give the body an <inertial>"),
            ));
        }
        // volume, and the principal moments per unit mass about the centre
        let (volume, per_mass) = match shape {
            Shape::Sphere { radius: r } => (4.0 / 3.0 * PI * r.powi(3), Vec3::repeat(0.4 * r * r)),
            Shape::Ellipsoid { radii } => {
                let (a, b, c) = (radii.x, radii.y, radii.z);
                let moments = Vec3::new(b * b + c * c, a * a + c * c, a * a + b * b) / 5.0;
                (4.0 / 3.0 * PI * a * b * c, moments)
            }
            Shape::Box { half_extents } => {
                let (a, b, c) = (half_extents.x, half_extents.y, half_extents.z);
                let moments = Vec3::new(b * b + c * c, a * a + c * c, a * a + b * b) / 3.0;
                (8.0 * a * b * c, moments)
            }
            Shape::Cylinder {
                radius: r,
                half_length,
            } => {
                let length = 2.0 * half_length;
                let across = (3.0 * r * r + length * length) / 12.0;
                (PI * r * r * length, Vec3::new(across, across, r * r / 2.0))
            }
            Shape::Capsule {
                radius: r,
                half_length,
            } => {
                // the mass splits between the cylinder and the two hemispheres by volume
                let length = 2.0 * half_length;
                let (cylinder, sphere) = (PI * r * r * length, 4.0 / 3.0 * PI * r.powi(3));
                let volume = cylinder + sphere;
                let (m_c, m_s) = (cylinder / volume, sphere / volume);
                let across = m_c * (length * length / 12.0 + r * r / 4.0)
                    + m_s * (0.4 * r * r + length * length / 4.0 + 3.0 * length * r / 8.0);
                let along = m_c * r * r / 2.0 + m_s * 0.4 * r * r;
                (volume, Vec3::new(across, across, along))
            }
            Shape::Plane { .. } | Shape::Mesh { .. } | Shape::HeightField { .. } => {
                return Err(no_volume())
            }
        };
        let mass = match given_mass {
            Some(mass) => mass,
            None => {
                self.numbers::<1>(geom, class, "density")?
                    .map_or(DEFAULT_DENSITY, |[d]| d)
                    * volume
            }
        };
        let moments = per_mass * mass;
        self.inertia_in_body(geom, mass, &Mat3::from_diagonal(&moments), &frame)
    }
}
