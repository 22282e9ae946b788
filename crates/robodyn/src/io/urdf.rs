//! URDF loader (ROS's Unified Robot Description Format, <http://wiki.ros.org/urdf/XML>).
//!
//! Reads links with their inertials, and joints (`revolute`, `continuous`, `prismatic`, `fixed`,
//! `floating`, and robodyn's extension `spherical`) with origins, axes, limits, dynamics and mimic
//! tags. Fixed joints are merged into the parent body and the child link is kept as a frame.
//! Bodies are numbered depth-first, children in file order. The root link is the world unless
//! `floating_base` puts a free joint named `root_joint` between the world and the root.
//! Inertias follow the rule for physical inertias ([`check_physical_parameters`]): one that is not
//! positive semi-definite is an error unless `check_inertia` is off, when it becomes a warning on
//! the model; one whose principal moments break the triangle inequality is a warning. A mimic tag on a fixed joint, or naming a joint that does not
//! move, is ignored with a warning.
//! Visuals are read for the viewer (`urdf/visuals.rs`); collision, transmission and gazebo
//! elements are ignored.

use crate::constraint::{Constraint, ConstraintKind, ConstraintReference, ModelConstraint};
use crate::error::{Error, Result};
use crate::io::schema;
use crate::io::urdf_schema::URDF_SCHEMA;
use crate::io::xml::{check_nesting, location, parse_numbers};
use crate::io::{read_model_file, LoadOptions};
use crate::joint::Joint;
use crate::model::{
    check_mass_and_inertia, check_physical_parameters, JointProperties, Mimic, Model, ModelBuilder,
    NewBody, Unphysical,
};
use crate::spatial::{rotation_from_rpy, Inertia, Mat3, Transform, Vec3};
use roxmltree::{Document, Node};
use std::collections::HashMap;
use std::path::Path;

mod visuals;

/// Loads a URDF file.
pub fn load_urdf_file(path: &Path, options: LoadOptions) -> Result<Model> {
    let text = read_model_file(path)?;
    load_urdf_str(&text, &path.display().to_string(), options)
}

/// Loads a URDF document held in `text`; `source` names it in error messages.
pub fn load_urdf_str(text: &str, source: &str, options: LoadOptions) -> Result<Model> {
    let mut warnings = Vec::new();
    let document = match Document::parse(text) {
        Ok(document) => document,
        Err(error) => {
            // ROS's parser accepts an XML declaration after comments or blank lines; so do we
            let late = late_declaration(text)
                .ok_or_else(|| Error::model(source, format!("malformed XML: {error}")))?;
            warnings.push(format!(
                "{source}: the XML declaration is not at the start of the file (line {}): read \
                 as if it were",
                text[..late.start].matches('\n').count() + 1
            ));
            let mut blanked = text.to_string();
            blanked.replace_range(late.clone(), &" ".repeat(late.len()));
            return load_urdf_document(&blanked, source, options, warnings);
        }
    };
    parse_urdf(&document, source, options, warnings)
}

/// The byte range of an `<?xml …?>` declaration that follows comments or white space, if any.
fn late_declaration(text: &str) -> Option<std::ops::Range<usize>> {
    let start = text.find("<?xml")?;
    let end = start + text[start..].find("?>")? + 2;
    (start > 0).then_some(start..end)
}

/// Parses `text` (whose declaration was blanked out) and loads it.
fn load_urdf_document(
    text: &str,
    source: &str,
    options: LoadOptions,
    warnings: Vec<String>,
) -> Result<Model> {
    let document =
        Document::parse(text).map_err(|e| Error::model(source, format!("malformed XML: {e}")))?;
    parse_urdf(&document, source, options, warnings)
}

fn parse_urdf(
    document: &Document,
    source: &str,
    options: LoadOptions,
    warnings: Vec<String>,
) -> Result<Model> {
    let mut parser = Parser {
        source,
        document,
        options,
        warnings,
    };
    check_nesting(source, document)?;
    let robot = document.root_element();
    if robot.tag_name().name() != "robot" {
        return Err(parser.error(robot, "expected the root element <robot>"));
    }
    // unknown elements and attributes are warnings naming the nearest known name, one per name
    let mut unknown: Vec<(String, String, usize)> = Vec::new();
    schema::check(
        URDF_SCHEMA,
        0,
        robot,
        &schema::element_children,
        &mut |node, message| {
            match unknown.iter_mut().find(|(known, _, _)| *known == message) {
                Some((_, _, count)) => *count += 1,
                None => unknown.push((message, parser.location(node), 1)),
            }
            Ok(())
        },
    )?;
    parser.warnings.extend(
        unknown
            .into_iter()
            .map(|(message, first, count)| match count {
                1 => format!("{first}: {message}"),
                _ => format!("{first}: {message} ({count} times; the first is here)"),
            }),
    );
    let links = parser.links(robot)?;
    let joints = parser.joints(robot, &links)?;
    parser.build(robot, &links, &joints)
}

/// A parsed `<link>`.
struct Link<'a> {
    name: &'a str,
    node: Node<'a, 'a>,
    inertia: Inertia,
}

/// A parsed `<joint>`; `joint` is `None` for a fixed joint.
struct UrdfJoint<'a> {
    name: &'a str,
    node: Node<'a, 'a>,
    joint: Option<Joint>,
    parent: usize,
    child: usize,
    origin: Transform,
    properties: JointProperties,
    mimic: Option<(&'a str, f64, f64)>,
}

struct Parser<'a> {
    source: &'a str,
    document: &'a Document<'a>,
    options: LoadOptions,
    warnings: Vec<String>,
}

impl<'a> Parser<'a> {
    /// An error located at `node`: file, element (with its name attribute) and line.
    fn error(&self, node: Node, message: impl Into<String>) -> Error {
        Error::model(self.location(node), message)
    }

    fn location(&self, node: Node) -> String {
        location(self.source, self.document, node)
    }

    /// A required attribute.
    fn attribute(&self, node: Node<'a, 'a>, name: &str) -> Result<&'a str> {
        node.attribute(name)
            .ok_or_else(|| self.missing_attribute(node, name))
    }

    /// The error for a required attribute that is absent, naming a close unknown one beside it.
    fn missing_attribute(&self, node: Node, name: &str) -> Error {
        let typo = schema::misspelt_attribute(URDF_SCHEMA, node, name);
        self.error(node, format!("missing attribute '{name}'{typo}"))
    }

    /// The error for a required child element that is absent, naming a close unknown one.
    fn missing_child(&self, node: Node, tag: &str) -> Error {
        let typo = schema::misspelt_child(URDF_SCHEMA, node, tag);
        self.error(node, format!("missing <{tag}>{typo}"))
    }

    /// An attribute of `n` numbers, or `default` when absent.
    fn numbers<const N: usize>(
        &self,
        node: Node,
        name: &str,
        default: [f64; N],
    ) -> Result<[f64; N]> {
        match node.attribute(name) {
            None => Ok(default),
            Some(text) => parse_numbers(text, name).map_err(|message| self.error(node, message)),
        }
    }

    /// `<origin xyz rpy>` of `node` (identity when absent), as the transform into that frame.
    fn origin(&self, node: Node) -> Result<Transform> {
        let Some(origin) = node.children().find(|c| c.has_tag_name("origin")) else {
            return Ok(Transform::IDENTITY);
        };
        let [x, y, z] = self.numbers(origin, "xyz", [0.0; 3])?;
        let [roll, pitch, yaw] = self.numbers(origin, "rpy", [0.0; 3])?;
        Ok(Transform::from_pose(
            &rotation_from_rpy(roll, pitch, yaw),
            &Vec3::new(x, y, z),
        ))
    }

    fn child(node: Node<'a, 'a>, tag: &str) -> Option<Node<'a, 'a>> {
        node.children().find(|c| c.has_tag_name(tag))
    }

    /// Every `<link>` with its spatial inertia in the link frame.
    fn links(&mut self, robot: Node<'a, 'a>) -> Result<Vec<Link<'a>>> {
        let mut links: Vec<Link<'a>> = Vec::new();
        for node in robot.children().filter(|c| c.has_tag_name("link")) {
            let name = self.attribute(node, "name")?;
            if links.iter().any(|l| l.name == name) {
                return Err(self.error(node, "duplicate link name"));
            }
            let inertia = match Self::child(node, "inertial") {
                None => Inertia::ZERO,
                Some(inertial) => self.inertial(inertial)?,
            };
            links.push(Link {
                name,
                node,
                inertia,
            });
        }
        if links.is_empty() {
            return Err(self.error(robot, "expected at least one <link>"));
        }
        Ok(links)
    }

    /// `<inertial>`: mass, centre of mass and rotational inertia, with their own origin.
    fn inertial(&mut self, inertial: Node<'a, 'a>) -> Result<Inertia> {
        let mass_node =
            Self::child(inertial, "mass").ok_or_else(|| self.missing_child(inertial, "mass"))?;
        let [mass] = self.numbers(mass_node, "value", [f64::NAN])?;
        if mass.is_nan() {
            return Err(self.missing_attribute(mass_node, "value"));
        }
        let inertia_com = match Self::child(inertial, "inertia") {
            None => Mat3::zeros(),
            Some(node) => {
                let get = |name: &str| -> Result<f64> {
                    let [value] = self.numbers(node, name, [f64::NAN])?;
                    if value.is_nan() {
                        return Err(self.missing_attribute(node, name));
                    }
                    Ok(value)
                };
                let (ixx, ixy, ixz) = (get("ixx")?, get("ixy")?, get("ixz")?);
                let (iyy, iyz, izz) = (get("iyy")?, get("iyz")?, get("izz")?);
                Mat3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz)
            }
        };
        // the inertial frame: origin at the centre of mass, axes rotated by R = rpy
        let frame = self.origin(inertial)?;
        let rotation = frame.rotation.transpose();
        let inertia_com = rotation * inertia_com * rotation.transpose();
        check_mass_and_inertia(mass, &inertia_com)
            .map_err(|message| self.error(inertial, message))?;
        let inertia = Inertia::from_com(mass, &frame.translation, &inertia_com);
        // the rule for physical inertias: an invalid tensor is an error (a warning with
        // check_inertia off), one that breaks only the triangle inequality a warning
        match check_physical_parameters(&inertia.to_parameters()) {
            Ok(()) => {}
            Err(Unphysical::Invalid(message)) => {
                let error = self.error(inertial, message);
                if self.options.check_inertia {
                    return Err(error);
                }
                self.warnings
                    .push(format!("{error} (loaded anyway: check_inertia is off)"));
            }
            Err(Unphysical::TriangleInequality(message)) => {
                let error = self.error(inertial, message);
                self.warnings
                    .push(format!("{error} (loaded as given; strict=True refuses it)"));
            }
        }
        Ok(inertia)
    }

    /// Every `<joint>`, with its links resolved to indices into `links`.
    fn joints(&self, robot: Node<'a, 'a>, links: &[Link<'a>]) -> Result<Vec<UrdfJoint<'a>>> {
        let index: HashMap<&str, usize> =
            links.iter().enumerate().map(|(i, l)| (l.name, i)).collect();
        let mut joints: Vec<UrdfJoint<'a>> = Vec::new();
        for node in robot.children().filter(|c| c.has_tag_name("joint")) {
            let name = self.attribute(node, "name")?;
            if joints.iter().any(|j| j.name == name) {
                return Err(self.error(node, "duplicate joint name"));
            }
            let link_of = |tag: &str| -> Result<usize> {
                let element =
                    Self::child(node, tag).ok_or_else(|| self.missing_child(node, tag))?;
                let link = self.attribute(element, "link")?;
                index.get(link).copied().ok_or_else(|| {
                    self.error(node, format!("<{tag} link='{link}'>: no link of that name"))
                })
            };
            let (parent, child) = (link_of("parent")?, link_of("child")?);
            let kind = self.attribute(node, "type")?;
            let axis = match Self::child(node, "axis") {
                None => Vec3::x(),
                Some(a) => Vec3::from(
                    parse_numbers::<3>(self.attribute(a, "xyz")?, "xyz")
                        .map_err(|message| self.error(a, message))?,
                ),
            };
            let unit_axis = || -> Result<Vec3> {
                let norm = axis.norm();
                if norm < 1e-12 {
                    return Err(self.error(node, "<axis>: expected a non-zero vector, got 0 0 0"));
                }
                Ok(axis / norm)
            };
            let joint = match kind {
                "revolute" | "continuous" => Some(Joint::Revolute { axis: unit_axis()? }),
                "prismatic" => Some(Joint::Prismatic { axis: unit_axis()? }),
                "floating" => Some(Joint::Free),
                "spherical" => Some(Joint::Spherical),
                "fixed" => None,
                other => {
                    return Err(self.error(
                        node,
                        format!(
                        "unknown joint type '{other}': expected revolute, continuous, prismatic, \
                             fixed, floating or spherical"
                    ),
                    ))
                }
            };
            let mut properties = JointProperties::default();
            if let Some(limit) = Self::child(node, "limit") {
                if kind != "continuous" {
                    [properties.lower] = self.numbers(limit, "lower", [f64::NEG_INFINITY])?;
                    [properties.upper] = self.numbers(limit, "upper", [f64::INFINITY])?;
                    // URDF's default for an absent lower/upper pair is 0 0, meaning no limits
                    if properties.lower == 0.0 && properties.upper == 0.0 {
                        properties.lower = f64::NEG_INFINITY;
                        properties.upper = f64::INFINITY;
                    }
                }
                [properties.effort_limit] = self.numbers(limit, "effort", [f64::INFINITY])?;
                [properties.velocity_limit] = self.numbers(limit, "velocity", [f64::INFINITY])?;
            }
            if let Some(dynamics) = Self::child(node, "dynamics") {
                [properties.damping] = self.numbers(dynamics, "damping", [0.0])?;
                [properties.friction] = self.numbers(dynamics, "friction", [0.0])?;
            }
            let mimic = match Self::child(node, "mimic") {
                None => None,
                Some(m) => Some((
                    self.attribute(m, "joint")?,
                    self.numbers(m, "multiplier", [1.0])?[0],
                    self.numbers(m, "offset", [0.0])?[0],
                )),
            };
            joints.push(UrdfJoint {
                name,
                node,
                joint,
                parent,
                child,
                origin: self.origin(node)?,
                properties,
                mimic,
            });
        }
        Ok(joints)
    }

    /// Checks that links and joints form one tree and builds the model depth-first.
    fn build(
        &self,
        robot: Node<'a, 'a>,
        links: &[Link<'a>],
        joints: &[UrdfJoint<'a>],
    ) -> Result<Model> {
        // the tree: one parent joint per link, exactly one root
        let mut parent_joint: Vec<Option<usize>> = vec![None; links.len()];
        for (j, joint) in joints.iter().enumerate() {
            if let Some(other) = parent_joint[joint.child] {
                return Err(self.error(
                    joint.node,
                    format!(
                        "link '{}' already has the parent joint '{}': a link may have only one \
                         (the description must be a tree)",
                        links[joint.child].name, joints[other].name
                    ),
                ));
            }
            parent_joint[joint.child] = Some(j);
        }
        let roots: Vec<usize> = (0..links.len())
            .filter(|&l| parent_joint[l].is_none())
            .collect();
        let root = match roots.as_slice() {
            [root] => *root,
            [] => {
                return Err(self.error(
                    robot,
                    "every link has a parent joint: the joints form a cycle",
                ))
            }
            many => {
                let names: Vec<&str> = many.iter().map(|&l| links[l].name).collect();
                return Err(self.error(
                    robot,
                    format!(
                        "expected one root link, got {} not connected to each other: {names:?}",
                        many.len()
                    ),
                ));
            }
        };

        let robot_name = robot.attribute("name").unwrap_or("robot");
        let mut builder = ModelBuilder::new(robot_name, links[root].name);
        // each link's body and X_{link←body}
        let mut placement: Vec<Option<(usize, Transform)>> = vec![None; links.len()];
        for warning in &self.warnings {
            builder.warn(warning.clone());
        }
        if self.options.floating_base {
            let body = builder.add_body(NewBody {
                parent: 0,
                joint: Joint::Free,
                joint_name: "root_joint",
                x_tree: Transform::IDENTITY,
                properties: JointProperties::default(),
                name: links[root].name,
                inertia: links[root].inertia,
            })?;
            placement[root] = Some((body, Transform::IDENTITY));
        } else {
            builder.add_frame(links[root].name, 0, Transform::IDENTITY);
            placement[root] = Some((0, Transform::IDENTITY));
        }

        // depth-first from the root, children in file order
        let mut body_of_joint: HashMap<&str, usize> = HashMap::new();
        let mut stack: Vec<usize> = joints
            .iter()
            .enumerate()
            .rev()
            .filter(|(_, j)| j.parent == root)
            .map(|(i, _)| i)
            .collect();
        while let Some(j) = stack.pop() {
            let joint = &joints[j];
            let (body, link_placement) = placement[joint.parent]
                .ok_or_else(|| self.error(joint.node, "parent link not reached from the root"))?;
            // X_T = X_{joint←parent link} X_{parent link←body}
            let x_tree = joint.origin * link_placement;
            let child = &links[joint.child];
            placement[joint.child] = Some(match joint.joint {
                None => {
                    builder.add_fixed_link(body, x_tree, child.inertia, child.name);
                    (body, x_tree)
                }
                Some(kind) => {
                    let index = builder.add_body(NewBody {
                        parent: body,
                        joint: kind,
                        joint_name: joint.name,
                        x_tree,
                        properties: joint.properties,
                        name: child.name,
                        inertia: child.inertia,
                    })?;
                    body_of_joint.insert(joint.name, index);
                    (index, Transform::IDENTITY)
                }
            });
            stack.extend(
                joints
                    .iter()
                    .enumerate()
                    .rev()
                    .filter(|(_, c)| c.parent == joint.child)
                    .map(|(i, _)| i),
            );
        }
        if let Some(orphan) = placement.iter().position(|p| p.is_none()) {
            return Err(self.error(
                links[orphan].node,
                "link not connected to the root link (the joints form a cycle or a separate tree)",
            ));
        }

        // mimic relations, between moving joints; the others are reported in one warning
        let mut ignored = Vec::new();
        for joint in joints {
            if let Some((mimicked, multiplier, offset)) = joint.mimic {
                match (body_of_joint.get(joint.name), body_of_joint.get(mimicked)) {
                    (Some(&joint_body), Some(&mimicked_body)) => builder.add_mimic(Mimic {
                        joint: joint_body,
                        mimicked: mimicked_body,
                        multiplier,
                        offset,
                    }),
                    _ => ignored.push(format!(
                        "'{}' (line {}) mimics '{mimicked}'",
                        joint.name,
                        self.document.text_pos_at(joint.node.range().start).row
                    )),
                }
            }
        }
        if !ignored.is_empty() {
            builder.warn(format!(
                "{}: {} <mimic> tag(s) ignored, because the joint or the joint it mimics is not a \
                 moving joint of the model: {}",
                self.source,
                ignored.len(),
                ignored.join(", ")
            ));
        }
        self.add_visuals(&mut builder, robot, links, &placement)?;
        let mut model = builder.build();
        hold_mimics(&mut model, self.source);
        Ok(model)
    }
}

/// Each mimic relation between two revolute or prismatic joints as a held
/// [`ConstraintKind::Coupling`] in `model.constraints` (q_f = multiplier q_l + offset), so that
/// simulation holds it; the others (continuous joints) are reported in one warning.
fn hold_mimics(model: &mut Model, source: &str) {
    let mut reported = Vec::new();
    for mimic in model.mimics.clone() {
        let constraint = Constraint {
            kind: ConstraintKind::Coupling {
                follower: mimic.joint,
                leader: Some(mimic.mimicked),
                polynomial: [mimic.offset, mimic.multiplier, 0.0, 0.0, 0.0],
                references: (0.0, 0.0),
            },
            reference: ConstraintReference::World,
        };
        match constraint.check(model) {
            Ok(()) => {
                let name = format!("mimic {}", model.joint_names[mimic.joint]);
                model
                    .constraints
                    .push(ModelConstraint::active(name, constraint));
            }
            Err(reason) => reported.push(reason),
        }
    }
    if !reported.is_empty() {
        model.warnings.push(format!(
            "{source}: {} <mimic> relation(s) reported (m.mimic_joints) but not held as \
             constraints: {}",
            reported.len(),
            reported.join("; ")
        ));
    }
}
