//! MJCF loader (MuJoCo's XML, <https://mujoco.readthedocs.io/en/stable/XMLreference.html>), the
//! part that describes a robot's rigid-body tree.
//!
//! Reads `<compiler angle eulerseq>`, `<option gravity>`, `<default>` classes (nested, with
//! `class` and `childclass`), and in `<worldbody>` nested `<body>`s with `pos` and any orientation
//! (`quat` w-first, `axisangle`, `euler`, `xyaxes`, `zaxis`), `<inertial>` (`mass`, `pos`,
//! orientation, `diaginertia` or `fullinertia`), `<joint>` (`hinge`, `slide`, `ball`, `free`; `pos`,
//! `axis`, `range`, `armature`, `damping`, `frictionloss`), `<freejoint>` and `<site>`s. Bodies and
//! sites become frames; a body without joints is merged into its parent; several joints in one
//! body become a chain of massless bodies, applied in order as MuJoCo does. A free joint's q is
//! the body's pose in the world (the XML pose is only MuJoCo's initial qpos).
//! Not read (a warning each): actuators, sensors, contacts, equality constraints, tendons,
//! keyframes, assets. A body whose inertia would come from its geoms is an error naming it
//! (inertia from geoms is not implemented yet).

use crate::error::{Error, Result};
use crate::io::read_model_file;
use crate::io::xml::{location, parse_numbers};
use crate::joint::Joint;
use crate::model::{
    check_mass_and_inertia, check_positive_semidefinite, JointProperties, Model, ModelBuilder,
    NewBody,
};
use crate::spatial::{Inertia, Mat3, Transform, Vec3};
use nalgebra::{Rotation3, Unit, UnitQuaternion};
use roxmltree::{Document, Node};
use std::collections::HashMap;
use std::path::Path;

/// Sections of an MJCF file that do not describe the tree.
const IGNORED_SECTIONS: [&str; 9] = [
    "actuator",
    "sensor",
    "contact",
    "equality",
    "tendon",
    "keyframe",
    "asset",
    "visual",
    "statistic",
];

/// Loads an MJCF file.
pub fn load_mjcf_file(path: &Path) -> Result<Model> {
    let text = read_model_file(path)?;
    load_mjcf_str(&text, &path.display().to_string())
}

/// Loads an MJCF document held in `text`; `source` names it in error messages.
pub fn load_mjcf_str(text: &str, source: &str) -> Result<Model> {
    let document =
        Document::parse(text).map_err(|e| Error::model(source, format!("malformed XML: {e}")))?;
    let root = document.root_element();
    let mut reader = Reader {
        source,
        document: &document,
        degrees: true,
        euler_sequence: "xyz".to_string(),
        defaults: HashMap::new(),
    };
    if !root.has_tag_name("mujoco") {
        return Err(reader.error(root, "expected the root element <mujoco>"));
    }
    for compiler in root.children().filter(|c| c.has_tag_name("compiler")) {
        match compiler.attribute("angle") {
            None | Some("degree") => {}
            Some("radian") => reader.degrees = false,
            Some(other) => {
                return Err(reader.error(
                    compiler,
                    format!("attribute 'angle': expected degree or radian, got '{other}'"),
                ))
            }
        }
        if let Some(sequence) = compiler.attribute("eulerseq") {
            if sequence.len() != 3 || !sequence.chars().all(|c| "xyzXYZ".contains(c)) {
                return Err(reader.error(
                    compiler,
                    format!("attribute 'eulerseq': expected three of xyzXYZ, got '{sequence}'"),
                ));
            }
            reader.euler_sequence = sequence.to_string();
        }
    }
    for default in root.children().filter(|c| c.has_tag_name("default")) {
        reader.read_defaults(default, None)?;
    }
    let mut builder = ModelBuilder::new(root.attribute("model").unwrap_or("mjcf"), "world");
    builder.add_frame("world", 0, Transform::IDENTITY);
    for option in root.children().filter(|c| c.has_tag_name("option")) {
        if let Some(text) = option.attribute("gravity") {
            let gravity =
                parse_numbers::<3>(text, "gravity").map_err(|m| reader.error(option, m))?;
            builder.gravity(Vec3::from(gravity));
        }
    }
    for section in root.children().filter(|c| c.is_element()) {
        let tag = section.tag_name().name();
        if IGNORED_SECTIONS.contains(&tag) {
            builder.warn(format!(
                "{}: not read (robodyn models the rigid-body tree only)",
                reader.location(section)
            ));
        }
    }
    for world in root.children().filter(|c| c.has_tag_name("worldbody")) {
        reader.read_children(&mut builder, world, 0, Transform::IDENTITY, "main")?;
    }
    Ok(builder.build())
}

struct Reader<'a> {
    source: &'a str,
    document: &'a Document<'a>,
    degrees: bool,
    euler_sequence: String,
    /// class -> element tag -> attribute -> value, each class holding its parents' values too
    defaults: HashMap<String, HashMap<String, HashMap<String, String>>>,
}

impl<'a> Reader<'a> {
    fn location(&self, node: Node) -> String {
        location(self.source, self.document, node)
    }

    fn error(&self, node: Node, message: impl Into<String>) -> Error {
        Error::model(self.location(node), message)
    }

    /// A `<default>` element and its nested classes.
    fn read_defaults(&mut self, node: Node, parent: Option<&str>) -> Result<()> {
        let class = match (node.attribute("class"), parent) {
            (Some(class), _) => class.to_string(),
            (None, None) => "main".to_string(),
            (None, Some(_)) => return Err(self.error(node, "a nested <default> needs a 'class'")),
        };
        let mut values = parent
            .and_then(|p| self.defaults.get(p))
            .cloned()
            .unwrap_or_default();
        for element in node
            .children()
            .filter(|c| c.is_element() && !c.has_tag_name("default"))
        {
            let entry = values
                .entry(element.tag_name().name().to_string())
                .or_default();
            for attribute in element.attributes() {
                entry.insert(attribute.name().to_string(), attribute.value().to_string());
            }
        }
        self.defaults.insert(class.clone(), values);
        for child in node.children().filter(|c| c.has_tag_name("default")) {
            self.read_defaults(child, Some(&class))?;
        }
        Ok(())
    }

    /// An attribute of `node`, else from its class (`class`, else the enclosing `childclass`).
    fn attribute(&self, node: Node<'a, 'a>, class: &str, name: &str) -> Option<String> {
        if let Some(value) = node.attribute(name) {
            return Some(value.to_string());
        }
        let class = node.attribute("class").unwrap_or(class);
        self.defaults
            .get(class)?
            .get(node.tag_name().name())?
            .get(name)
            .cloned()
    }

    fn numbers<const N: usize>(
        &self,
        node: Node<'a, 'a>,
        class: &str,
        name: &str,
    ) -> Result<Option<[f64; N]>> {
        self.attribute(node, class, name)
            .map(|text| parse_numbers::<N>(&text, name).map_err(|m| self.error(node, m)))
            .transpose()
    }

    fn angle(&self, value: f64) -> f64 {
        if self.degrees {
            value.to_radians()
        } else {
            value
        }
    }

    /// The rotation of an element's frame from `quat`, `axisangle`, `euler`, `xyaxes` or `zaxis`.
    fn orientation(&self, node: Node<'a, 'a>, class: &str) -> Result<Mat3> {
        if let Some([w, x, y, z]) = self.numbers::<4>(node, class, "quat")? {
            let quaternion = nalgebra::Quaternion::new(w, x, y, z);
            if quaternion.norm() < 1e-12 {
                return Err(self.error(node, "attribute 'quat': expected a non-zero quaternion"));
            }
            return Ok(*UnitQuaternion::from_quaternion(quaternion)
                .to_rotation_matrix()
                .matrix());
        }
        if let Some([x, y, z, angle]) = self.numbers::<4>(node, class, "axisangle")? {
            let axis = Unit::try_new(Vec3::new(x, y, z), 1e-12).ok_or_else(|| {
                self.error(node, "attribute 'axisangle': expected a non-zero axis")
            })?;
            return Ok(*Rotation3::from_axis_angle(&axis, self.angle(angle)).matrix());
        }
        if let Some(angles) = self.numbers::<3>(node, class, "euler")? {
            let mut rotation = Mat3::identity();
            for (axis, angle) in self.euler_sequence.chars().zip(angles) {
                let unit = match axis.to_ascii_lowercase() {
                    'x' => Vec3::x_axis(),
                    'y' => Vec3::y_axis(),
                    _ => Vec3::z_axis(),
                };
                let turn = *Rotation3::from_axis_angle(&unit, self.angle(angle)).matrix();
                // lower case: about the moving axes (intrinsic); upper case: fixed axes
                rotation = if axis.is_ascii_lowercase() {
                    rotation * turn
                } else {
                    turn * rotation
                };
            }
            return Ok(rotation);
        }
        if let Some([x1, x2, x3, y1, y2, y3]) = self.numbers::<6>(node, class, "xyaxes")? {
            let x = Vec3::new(x1, x2, x3);
            let y = Vec3::new(y1, y2, y3);
            let (x, y) = (
                x.normalize(),
                (y - x.normalize() * x.normalize().dot(&y)).normalize(),
            );
            let z = x.cross(&y);
            if !(x
                .iter()
                .chain(y.iter())
                .chain(z.iter())
                .all(|v| v.is_finite()))
            {
                return Err(self.error(node, "attribute 'xyaxes': expected two independent axes"));
            }
            return Ok(Mat3::from_columns(&[x, y, z]));
        }
        if let Some(z) = self.numbers::<3>(node, class, "zaxis")? {
            let z = Unit::try_new(Vec3::from(z), 1e-12)
                .ok_or_else(|| self.error(node, "attribute 'zaxis': expected a non-zero axis"))?;
            let rotation = Rotation3::rotation_between(&Vec3::z(), &z).unwrap_or_else(|| {
                Rotation3::from_axis_angle(&Vec3::x_axis(), std::f64::consts::PI)
            });
            return Ok(*rotation.matrix());
        }
        Ok(Mat3::identity())
    }

    /// `X` into an element's frame from its `pos` and orientation.
    fn placement(&self, node: Node<'a, 'a>, class: &str) -> Result<Transform> {
        let position = self.numbers::<3>(node, class, "pos")?.unwrap_or([0.0; 3]);
        Ok(Transform::from_pose(
            &self.orientation(node, class)?,
            &Vec3::from(position),
        ))
    }

    /// The spatial inertia of a body, in its frame, from `<inertial>`.
    fn inertia(&self, body: Node<'a, 'a>, class: &str) -> Result<Inertia> {
        let Some(inertial) = body.children().find(|c| c.has_tag_name("inertial")) else {
            if body.children().any(|c| c.has_tag_name("geom")) {
                return Err(self.error(
                    body,
                    "no <inertial>: inertia from geoms (MuJoCo's inertiafromgeom) is not implemented; add an <inertial>",
                ));
            }
            return Ok(Inertia::ZERO);
        };
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
                return Err(self.error(inertial, "expected 'diaginertia' or 'fullinertia'"));
            };
        let frame = self.placement(inertial, class)?;
        let rotation = frame.rotation.transpose();
        let inertia_com = rotation * principal * rotation.transpose();
        check_mass_and_inertia(mass, &inertia_com)
            .and_then(|_| check_positive_semidefinite(&inertia_com))
            .map_err(|m| self.error(inertial, m))?;
        Ok(Inertia::from_com(mass, &frame.translation, &inertia_com))
    }

    /// The children of a body element (or the worldbody) attached to model body `body`, whose
    /// frame is at `to_element` (`X_{element←body}`).
    fn read_children(
        &self,
        builder: &mut ModelBuilder,
        element: Node<'a, 'a>,
        body: usize,
        to_element: Transform,
        class: &str,
    ) -> Result<()> {
        for site in element.children().filter(|c| c.has_tag_name("site")) {
            let name = site
                .attribute("name")
                .map_or_else(|| format!("site{}", site.range().start), str::to_string);
            builder.add_frame(&name, body, self.placement(site, class)? * to_element);
        }
        for child in element.children().filter(|c| c.has_tag_name("body")) {
            self.read_body(builder, child, body, to_element, class)?;
        }
        Ok(())
    }

    fn read_body(
        &self,
        builder: &mut ModelBuilder,
        node: Node<'a, 'a>,
        parent: usize,
        parent_element: Transform,
        class: &str,
    ) -> Result<()> {
        let name = node
            .attribute("name")
            .map_or_else(|| format!("body{}", node.range().start), str::to_string);
        let child_class = node.attribute("childclass").unwrap_or(class);
        if node
            .attribute("childclass")
            .is_some_and(|c| !self.defaults.contains_key(c))
        {
            return Err(self.error(node, format!("unknown class '{child_class}'")));
        }
        // X_{B←parent body}
        let mut to_body = self.placement(node, class)? * parent_element;
        let inertia = self.inertia(node, child_class)?;
        let joints: Vec<Node> = node
            .children()
            .filter(|c| c.has_tag_name("joint") || c.has_tag_name("freejoint"))
            .collect();
        if joints.is_empty() {
            // no joint: merged into the parent, kept as a frame
            builder.add_fixed_link(parent, to_body, inertia, &name);
            return self.read_children(builder, node, parent, to_body, child_class);
        }
        let mut body = parent;
        let mut previous_position = Vec3::zeros();
        for (k, joint_node) in joints.iter().enumerate() {
            let joint_class = joint_node.attribute("class").unwrap_or(child_class);
            if joint_node
                .attribute("class")
                .is_some_and(|c| !self.defaults.contains_key(c))
            {
                return Err(self.error(*joint_node, format!("unknown class '{joint_class}'")));
            }
            let kind = if joint_node.has_tag_name("freejoint") {
                "free".to_string()
            } else {
                self.attribute(*joint_node, joint_class, "type")
                    .unwrap_or_else(|| "hinge".to_string())
            };
            let axis = Vec3::from(
                self.numbers::<3>(*joint_node, joint_class, "axis")?
                    .unwrap_or([0.0, 0.0, 1.0]),
            );
            let unit_axis = || {
                Unit::try_new(axis, 1e-12)
                    .map(|a| a.into_inner())
                    .ok_or_else(|| {
                        self.error(*joint_node, "attribute 'axis': expected a non-zero vector")
                    })
            };
            let joint = match kind.as_str() {
                "hinge" => Joint::Revolute { axis: unit_axis()? },
                "slide" => Joint::Prismatic { axis: unit_axis()? },
                "ball" => Joint::Spherical,
                "free" => Joint::Free,
                other => {
                    return Err(self.error(
                        *joint_node,
                        format!(
                            "unknown joint type '{other}': expected hinge, slide, ball or free"
                        ),
                    ))
                }
            };
            let position = if joint == Joint::Free {
                Vec3::zeros()
            } else {
                Vec3::from(
                    self.numbers::<3>(*joint_node, joint_class, "pos")?
                        .unwrap_or([0.0; 3]),
                )
            };
            let scalar = |key: &str, default: f64| -> Result<f64> {
                Ok(self
                    .numbers::<1>(*joint_node, joint_class, key)?
                    .map_or(default, |[x]| x))
            };
            let mut properties = JointProperties {
                armature: scalar("armature", 0.0)?,
                damping: scalar("damping", 0.0)?,
                friction: scalar("frictionloss", 0.0)?,
                ..JointProperties::default()
            };
            let limited = self
                .attribute(*joint_node, joint_class, "limited")
                .is_none_or(|l| l != "false");
            if let (true, Some([lower, upper])) = (
                limited,
                self.numbers::<2>(*joint_node, joint_class, "range")?,
            ) {
                let unit = |x: f64| {
                    if matches!(joint, Joint::Revolute { .. }) {
                        self.angle(x)
                    } else {
                        x
                    }
                };
                properties.lower = unit(lower);
                properties.upper = unit(upper);
            }
            // a free joint places the body in the world: its XML pose is only MuJoCo's qpos0
            let x_tree = if joint == Joint::Free {
                if k > 0
                    || !node
                        .parent_element()
                        .is_some_and(|p| p.has_tag_name("worldbody"))
                {
                    return Err(self.error(
                        *joint_node,
                        "a free joint must be the only joint of a child of the worldbody",
                    ));
                }
                Transform::IDENTITY
            } else if k == 0 {
                // the joint frame sits at `pos` in the body's frame
                Transform::from_translation(&position) * to_body
            } else {
                Transform::from_translation(&(position - previous_position))
            };
            let joint_name = joint_node
                .attribute("name")
                .map_or_else(|| format!("{name}_joint{k}"), str::to_string);
            let last = k + 1 == joints.len();
            // the body's own frame, relative to the last joint frame: X_{B←J} = translation(-pos)
            let to_own_frame = if joint == Joint::Free {
                Transform::IDENTITY
            } else {
                Transform::from_translation(&(-position))
            };
            // the model body carries the MJCF body's name when their frames coincide
            let body_name = if last && to_own_frame == Transform::IDENTITY {
                name.clone()
            } else {
                format!("{name}/{joint_name}")
            };
            body = builder.add_body(NewBody {
                parent: body,
                joint,
                joint_name: &joint_name,
                x_tree,
                properties,
                name: &body_name,
                inertia: if last {
                    to_own_frame.transpose_apply_inertia(&inertia)
                } else {
                    Inertia::ZERO
                },
            })?;
            previous_position = position;
            to_body = to_own_frame;
        }
        if to_body != Transform::IDENTITY {
            builder.add_frame(&name, body, to_body);
        }
        self.read_children(builder, node, body, to_body, child_class)
    }
}
