//! MJCF loader (MuJoCo's XML, <https://mujoco.readthedocs.io/en/stable/XMLreference.html>), the
//! part that describes a robot's rigid-body tree.
//!
//! Reads `<include file>` (resolved against the including file's folder, each file once),
//! `<compiler angle eulerseq inertiafromgeom inertiagrouprange>`, `<option gravity>`, `<default>`
//! classes (nested, with `class` and `childclass`), and in `<worldbody>` nested `<body>`s with `pos`
//! and any orientation (`quat` w-first, `axisangle`, `euler`, `xyaxes`, `zaxis`), `<inertial>`
//! (`mass`, `pos`, orientation, `diaginertia` or `fullinertia`), `<geom>`s for the inertia of a body
//! without `<inertial>`, `<joint>` (`hinge`, `slide`, `ball`, `free`; `pos`, `axis`, `ref`, `range`,
//! `armature`, `damping`, `frictionloss`, `stiffness`, `springref`), `<freejoint>` and `<site>`s.
//! Bodies and sites become frames; a body without joints is merged into its parent; several joints
//! in one body become a chain of massless bodies, applied in order as MuJoCo does. A free joint's
//! q is the body's pose in the world (the XML pose is only MuJoCo's initial qpos).
//! Every element and attribute is first checked against MuJoCo's schema (`mjcf_schema.rs`): an
//! unknown name is an error, as in MuJoCo.
//! Not read (a warning each): actuators, sensors, contacts, equality constraints, tendons,
//! keyframes, assets. A mesh geom cannot give a body its inertia here (the mesh file is not read):
//! such a body needs an `<inertial>`, and the error says so.
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

use crate::error::{Error, Result};
use crate::io::mjcf_mass::MassRules;
use crate::io::mjcf_schema::MJCF_SCHEMA;
use crate::io::read_model_file;
use crate::io::schema;
use crate::io::xml::{check_nesting, location, parse_number_list, parse_numbers};
use crate::joint::Joint;
use crate::model::{
    check_mass_and_inertia, check_positive_semidefinite, JointProperties, Model, ModelBuilder,
    NewBody,
};
use crate::spatial::{Inertia, Mat3, Transform, Vec3};
use nalgebra::{Rotation3, Unit, UnitQuaternion};
use roxmltree::{Document, Node};
use std::cell::Cell;
use std::collections::{HashMap, HashSet};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

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

/// MuJoCo's default geom density, kg/m³ (water).
const DEFAULT_DENSITY: f64 = 1000.0;

/// Loads an MJCF file and the files it includes.
pub fn load_mjcf_file(path: &Path) -> Result<Model> {
    let main = SourceFile {
        source: path.display().to_string(),
        text: read_model_file(path)?,
        folder: Some(path.parent().unwrap_or(Path::new(".")).to_path_buf()),
    };
    load_sources(&gather_includes(main)?)
}

/// Loads an MJCF document held in `text`; `source` names it in error messages. `<include>` needs
/// a file to resolve against: use [`load_mjcf_file`].
pub fn load_mjcf_str(text: &str, source: &str) -> Result<Model> {
    let main = SourceFile {
        source: source.to_string(),
        text: text.to_string(),
        folder: None,
    };
    load_sources(&gather_includes(main)?)
}

/// One file's text, the name errors give it, and the folder its `<include>`s are resolved
/// against (its own, as MuJoCo resolves them; none for a string).
struct SourceFile {
    source: String,
    text: String,
    folder: Option<PathBuf>,
}

/// The main file (first) and the files it includes, with where each `<include>` stands:
/// (file index, the element's byte offset) -> index of the included file.
struct Sources {
    files: Vec<SourceFile>,
    includes: HashMap<(usize, usize), usize>,
}

fn parse(file: &SourceFile) -> Result<Document<'_>> {
    let document = Document::parse(&file.text)
        .map_err(|e| Error::model(&file.source, format!("malformed XML: {e}")))?;
    check_nesting(&file.source, &document)?;
    Ok(document)
}

/// Reads every file reachable through `<include file>` from `main`, breadth first.
fn gather_includes(main: SourceFile) -> Result<Sources> {
    let mut sources = Sources {
        files: vec![main],
        includes: HashMap::new(),
    };
    let mut seen: HashSet<PathBuf> = HashSet::new();
    let mut next = 0;
    while next < sources.files.len() {
        let file = &sources.files[next];
        let document = parse(file)?;
        let mut found = Vec::new();
        for include in document.descendants().filter(|n| n.has_tag_name("include")) {
            let error =
                |message: &str| Error::model(location(&file.source, &document, include), message);
            let name = include
                .attribute("file")
                .ok_or_else(|| error("missing attribute 'file'"))?;
            let folder = file.folder.as_deref().ok_or_else(|| {
                error("<include> is resolved against the model's folder: load the model from its file")
            })?;
            let path = folder.join(name);
            if !seen.insert(path.clone()) {
                return Err(error(&format!("'{name}' is included more than once")));
            }
            found.push((include.range().start, path));
        }
        drop(document);
        for (offset, path) in found {
            let text = read_model_file(&path)?;
            sources.includes.insert((next, offset), sources.files.len());
            sources.files.push(SourceFile {
                source: path.display().to_string(),
                text,
                folder: path.parent().map(Path::to_path_buf),
            });
        }
        next += 1;
    }
    Ok(sources)
}

fn load_sources(sources: &Sources) -> Result<Model> {
    let documents = sources
        .files
        .iter()
        .map(parse)
        .collect::<Result<Vec<Document>>>()?;
    let root = documents[0].root_element();
    let mut reader = Reader {
        sources,
        documents: &documents,
        degrees: true,
        euler_sequence: "xyz".to_string(),
        inertia_from_geoms: InertiaFromGeoms::Auto,
        inertia_groups: (0, 5),
        defaults: HashMap::new(),
        mass_rules: MassRules::default(),
        total_mass: Cell::new(0.0),
    };
    if !root.has_tag_name("mujoco") {
        return Err(reader.error(root, "expected the root element <mujoco>"));
    }
    // unknown elements and attributes are errors, as in MuJoCo
    schema::check(
        MJCF_SCHEMA,
        0,
        root,
        &|node| reader.children(node),
        &mut |node, message| Err(reader.error(node, message)),
    )?;
    let sections = reader.children(root)?;
    for compiler in sections.iter().filter(|c| c.has_tag_name("compiler")) {
        reader.read_compiler(*compiler)?;
    }
    for default in sections.iter().filter(|c| c.has_tag_name("default")) {
        reader.read_defaults(*default, None)?;
    }
    let mut builder = ModelBuilder::new(root.attribute("model").unwrap_or("mjcf"), "world");
    builder.add_frame("world", 0, Transform::IDENTITY);
    for option in sections.iter().filter(|c| c.has_tag_name("option")) {
        if let Some(text) = option.attribute("gravity") {
            let gravity =
                parse_numbers::<3>(text, "gravity").map_err(|m| reader.error(*option, m))?;
            builder.gravity(Vec3::from(gravity));
        }
    }
    for section in &sections {
        if IGNORED_SECTIONS.contains(&section.tag_name().name()) {
            builder.warn(format!(
                "{}: not read (robodyn models the rigid-body tree only)",
                reader.location(*section)
            ));
        }
    }
    for world in sections.iter().filter(|c| c.has_tag_name("worldbody")) {
        reader.read_children(&mut builder, *world, 0, Transform::IDENTITY, "main")?;
    }
    if let Some(factor) = reader.mass_rules.total_mass_scale(reader.total_mass.get()) {
        builder.scale_inertias(factor);
    }
    Ok(builder.build())
}

/// `<compiler inertiafromgeom>`: where a body's inertia comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum InertiaFromGeoms {
    /// From `<inertial>` when the body has one, else from its geoms (MuJoCo's default).
    Auto,
    /// Always from the geoms.
    Always,
    /// Only from `<inertial>`; a body without one is massless.
    Never,
}

struct Reader<'a> {
    sources: &'a Sources,
    documents: &'a [Document<'a>],
    degrees: bool,
    euler_sequence: String,
    inertia_from_geoms: InertiaFromGeoms,
    /// geoms whose `group` lies outside this range give no inertia (`inertiagrouprange`)
    inertia_groups: (i64, i64),
    /// class -> element tag -> attribute -> value, each class holding its parents' values too
    defaults: HashMap<String, HashMap<String, HashMap<String, String>>>,
    /// `boundmass`, `boundinertia`, `balanceinertia`, `settotalmass`
    mass_rules: MassRules,
    /// the mass of every body read so far, those welded to the world included
    total_mass: Cell<f64>,
}

impl<'a> Reader<'a> {
    /// Which file `node` belongs to.
    fn file_index(&self, node: Node) -> usize {
        self.documents
            .iter()
            .position(|d| std::ptr::eq(d, node.document()))
            .unwrap_or(0)
    }

    fn location(&self, node: Node) -> String {
        let index = self.file_index(node);
        location(
            &self.sources.files[index].source,
            &self.documents[index],
            node,
        )
    }

    /// The child elements of `node`, each `<include>` replaced by the children of the included
    /// file's `<mujoco>` root.
    fn children(&self, node: Node<'a, 'a>) -> Result<Vec<Node<'a, 'a>>> {
        let mut children = Vec::new();
        for child in node.children().filter(|c| c.is_element()) {
            if !child.has_tag_name("include") {
                children.push(child);
                continue;
            }
            let included = self.sources.includes[&(self.file_index(child), child.range().start)];
            let root = self.documents[included].root_element();
            if !root.has_tag_name("mujoco") {
                return Err(self.error(root, "an included file's root element must be <mujoco>"));
            }
            children.extend(self.children(root)?);
        }
        Ok(children)
    }

    /// `<compiler>`: angle unit, Euler sequence, where inertias come from.
    fn read_compiler(&mut self, compiler: Node<'a, 'a>) -> Result<()> {
        // each <compiler> changes only the attributes it sets
        match compiler.attribute("angle") {
            None => {}
            Some("degree") => self.degrees = true,
            Some("radian") => self.degrees = false,
            Some(other) => {
                return Err(self.error(
                    compiler,
                    format!("attribute 'angle': expected degree or radian, got '{other}'"),
                ))
            }
        }
        if let Some(sequence) = compiler.attribute("eulerseq") {
            if sequence.len() != 3 || !sequence.chars().all(|c| "xyzXYZ".contains(c)) {
                return Err(self.error(
                    compiler,
                    format!("attribute 'eulerseq': expected three of xyzXYZ, got '{sequence}'"),
                ));
            }
            self.euler_sequence = sequence.to_string();
        }
        self.inertia_from_geoms = match compiler.attribute("inertiafromgeom") {
            None => self.inertia_from_geoms,
            Some("auto") => InertiaFromGeoms::Auto,
            Some("true") => InertiaFromGeoms::Always,
            Some("false") => InertiaFromGeoms::Never,
            Some(other) => {
                return Err(self.error(
                    compiler,
                    format!(
                        "attribute 'inertiafromgeom': expected auto, true or false, got '{other}'"
                    ),
                ))
            }
        };
        if let Some(text) = compiler.attribute("inertiagrouprange") {
            let [low, high] = parse_numbers::<2>(text, "inertiagrouprange")
                .map_err(|m| self.error(compiler, m))?;
            self.inertia_groups = (low as i64, high as i64);
        }
        // the options that rewrite masses and inertias (mjcf_mass.rs)
        let number = |name: &str| -> Result<Option<f64>> {
            compiler
                .attribute(name)
                .map(|text| parse_numbers::<1>(text, name).map(|[x]| x))
                .transpose()
                .map_err(|m| self.error(compiler, m))
        };
        let mut rules = self.mass_rules;
        rules.bound_mass = number("boundmass")?.unwrap_or(rules.bound_mass);
        rules.bound_inertia = number("boundinertia")?.unwrap_or(rules.bound_inertia);
        rules.total_mass = number("settotalmass")?.unwrap_or(rules.total_mass);
        rules.balance_inertia = match compiler.attribute("balanceinertia") {
            None => rules.balance_inertia,
            Some("true") => true,
            Some("false") => false,
            Some(other) => {
                return Err(self.error(
                    compiler,
                    format!("attribute 'balanceinertia': expected true or false, got '{other}'"),
                ))
            }
        };
        self.mass_rules = rules;
        Ok(())
    }

    fn error(&self, node: Node, message: impl Into<String>) -> Error {
        Error::model(self.location(node), message)
    }

    /// A `<default>` element and its nested classes.
    fn read_defaults(&mut self, node: Node<'a, 'a>, parent: Option<&str>) -> Result<()> {
        let class = match (node.attribute("class"), parent) {
            (Some(class), _) => class.to_string(),
            (None, None) => "main".to_string(),
            (None, Some(_)) => return Err(self.error(node, "a nested <default> needs a 'class'")),
        };
        let mut values = parent
            .and_then(|p| self.defaults.get(p))
            .cloned()
            .unwrap_or_default();
        let elements = self.children(node)?;
        for element in elements.iter().filter(|c| !c.has_tag_name("default")) {
            let entry = values
                .entry(element.tag_name().name().to_string())
                .or_default();
            for attribute in element.attributes() {
                entry.insert(attribute.name().to_string(), attribute.value().to_string());
            }
        }
        self.defaults.insert(class.clone(), values);
        for child in elements.iter().filter(|c| c.has_tag_name("default")) {
            self.read_defaults(*child, Some(&class))?;
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

    /// The class named by `node`'s `attribute` (`class`: the one it takes its defaults from;
    /// `childclass`: the one its children default to), else `class`; an unknown class is an error.
    fn declared_class<'c>(
        &self,
        node: Node<'a, 'a>,
        attribute: &str,
        class: &'c str,
    ) -> Result<&'c str>
    where
        'a: 'c,
    {
        match node.attribute(attribute) {
            Some(own) if !self.defaults.contains_key(own) => {
                Err(self.error(node, format!("unknown class '{own}'")))
            }
            Some(own) => Ok(own),
            None => Ok(class),
        }
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

    /// A geom's or site's `fromto` (x1 y1 z1 x2 y2 z2), when it has one: the frame at the
    /// segment's midpoint with z pointing from the second point to the first (the shortest
    /// rotation from z, as MuJoCo places it), and the half-length. Only capsules, cylinders, boxes
    /// and ellipsoids take one.
    fn segment(
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

    /// The spatial inertia of a body, in its frame: from `<inertial>` or from its geoms, as
    /// `<compiler inertiafromgeom>` says.
    fn body_inertia(&self, elements: &[Node<'a, 'a>], class: &str) -> Result<Inertia> {
        let inertial = elements.iter().find(|c| c.has_tag_name("inertial"));
        match (self.inertia_from_geoms, inertial) {
            (InertiaFromGeoms::Never, None) => Ok(Inertia::ZERO),
            (InertiaFromGeoms::Auto | InertiaFromGeoms::Never, Some(inertial)) => {
                self.inertial(*inertial, class)
            }
            // each geom's mass and inertia is checked where it is read
            (InertiaFromGeoms::Always, _) | (InertiaFromGeoms::Auto, None) => {
                self.geoms_inertia(elements, class)
            }
        }
    }

    /// The inertia of the geoms among `elements` and inside their `<frame>`s, in the frame the
    /// elements are written in.
    fn geoms_inertia(&self, elements: &[Node<'a, 'a>], class: &str) -> Result<Inertia> {
        let mut total = Inertia::ZERO;
        for element in elements {
            if element.has_tag_name("geom") {
                total += self.geom_inertia(*element, class)?;
            } else if element.has_tag_name("frame") {
                let inner_class = self.declared_class(*element, "childclass", class)?;
                let inside = self.geoms_inertia(&self.children(*element)?, inner_class)?;
                total += self
                    .placement(*element, class)?
                    .transpose_apply_inertia(&inside);
            }
        }
        Ok(total)
    }

    /// `<inertial>`: mass, centre of mass and the inertia about it, in the body's frame.
    fn inertial(&self, inertial: Node<'a, 'a>, class: &str) -> Result<Inertia> {
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
    fn inertia_in_body(
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
    fn geom_inertia(&self, geom: Node<'a, 'a>, class: &str) -> Result<Inertia> {
        let class = self.declared_class(geom, "class", class)?;
        let text = |name: &str| self.attribute(geom, class, name);
        let group = match text("group") {
            None => 0,
            Some(g) => g.trim().parse::<i64>().map_err(|_| {
                self.error(
                    geom,
                    format!("attribute 'group': expected an integer, got '{g}'"),
                )
            })?,
        };
        if group < self.inertia_groups.0 || group > self.inertia_groups.1 {
            return Ok(Inertia::ZERO);
        }
        let given_mass = self.numbers::<1>(geom, class, "mass")?.map(|[m]| m);
        if given_mass == Some(0.0) {
            return Ok(Inertia::ZERO);
        }
        let kind = text("type").unwrap_or_else(|| "sphere".to_string());
        let mut size = match text("size") {
            Some(t) => parse_number_list(&t, "size").map_err(|m| self.error(geom, m))?,
            None => Vec::new(),
        };
        // `fromto`: the geom spans the segment; its axis is z, its half-length the last size
        let mut frame = self.placement(geom, class)?;
        if let Some((segment, half_length)) = self.segment(geom, class, &kind)? {
            let radius = size.first().copied().unwrap_or(0.0);
            // a box or ellipsoid along the segment has a square or round section of size[0]
            size = if matches!(kind.as_str(), "box" | "ellipsoid") {
                vec![radius, radius, half_length]
            } else {
                vec![radius, half_length]
            };
            frame = segment;
        }
        let needed = match kind.as_str() {
            "sphere" => 1,
            "capsule" | "cylinder" => 2,
            "ellipsoid" | "box" => 3,
            "mesh" | "sdf" => {
                return Err(self.error(
                    geom,
                    format!("the inertia of a {kind} geom needs its file, which robodyn does not read: give the body an <inertial>"),
                ))
            }
            other => {
                return Err(self.error(
                    geom,
                    format!("a '{other}' geom has no volume to give the body an inertia: give the body an <inertial>"),
                ))
            }
        };
        if size.len() < needed || size[..needed].iter().any(|x| *x <= 0.0) {
            return Err(self.error(
                geom,
                format!("attribute 'size': a {kind} needs {needed} positive numbers, got {size:?}"),
            ));
        }
        // volume, and the principal moments per unit mass about the centre
        let (volume, per_mass) = match kind.as_str() {
            "sphere" => {
                let r = size[0];
                (4.0 / 3.0 * PI * r.powi(3), Vec3::repeat(0.4 * r * r))
            }
            "ellipsoid" => {
                let (a, b, c) = (size[0], size[1], size[2]);
                let moments = Vec3::new(b * b + c * c, a * a + c * c, a * a + b * b) / 5.0;
                (4.0 / 3.0 * PI * a * b * c, moments)
            }
            "box" => {
                let (a, b, c) = (size[0], size[1], size[2]);
                let moments = Vec3::new(b * b + c * c, a * a + c * c, a * a + b * b) / 3.0;
                (8.0 * a * b * c, moments)
            }
            "cylinder" => {
                let (r, length) = (size[0], 2.0 * size[1]);
                let across = (3.0 * r * r + length * length) / 12.0;
                (PI * r * r * length, Vec3::new(across, across, r * r / 2.0))
            }
            _ => {
                // capsule: the mass splits between the cylinder and the two hemispheres by volume
                let (r, length) = (size[0], 2.0 * size[1]);
                let (cylinder, sphere) = (PI * r * r * length, 4.0 / 3.0 * PI * r.powi(3));
                let volume = cylinder + sphere;
                let (m_c, m_s) = (cylinder / volume, sphere / volume);
                let across = m_c * (length * length / 12.0 + r * r / 4.0)
                    + m_s * (0.4 * r * r + length * length / 4.0 + 3.0 * length * r / 8.0);
                let along = m_c * r * r / 2.0 + m_s * 0.4 * r * r;
                (volume, Vec3::new(across, across, along))
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
        for child in self.children(element)? {
            match child.tag_name().name() {
                "site" => {
                    let name = child
                        .attribute("name")
                        .map_or_else(|| format!("site{}", child.range().start), str::to_string);
                    let site_class = self.declared_class(child, "class", class)?;
                    let kind = self
                        .attribute(child, site_class, "type")
                        .unwrap_or_else(|| "sphere".to_string());
                    let placement = match self.segment(child, site_class, &kind)? {
                        Some((segment, _)) => segment,
                        None => self.placement(child, site_class)?,
                    };
                    builder.add_frame(&name, body, placement * to_element);
                }
                "body" => self.read_body(builder, child, body, to_element, class)?,
                // a <frame> only places what it holds: its pose composes with theirs
                "frame" => {
                    let to_frame = self.placement(child, class)? * to_element;
                    let frame_class = self.declared_class(child, "childclass", class)?;
                    self.read_children(builder, child, body, to_frame, frame_class)?;
                }
                "joint" | "freejoint" | "inertial" if element.has_tag_name("frame") => {
                    return Err(self.error(child, "expected in a <body>, not in a <frame>"));
                }
                tag @ ("replicate" | "attach" | "composite" | "flexcomp") => {
                    return Err(self.error(child, format!("<{tag}> is not supported")));
                }
                // joints, inertials and geoms are read with their body; cameras, lights and
                // plugins are not part of the tree
                _ => {}
            }
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
        let child_class = self.declared_class(node, "childclass", class)?;
        // X_{B←parent body}
        let mut to_body = self.placement(node, class)? * parent_element;
        let elements = self.children(node)?;
        let inertia = self
            .mass_rules
            .apply_to_body(self.body_inertia(&elements, child_class)?)
            .map_err(|m| self.error(node, m))?;
        self.total_mass.set(self.total_mass.get() + inertia.mass);
        let joints: Vec<Node> = elements
            .into_iter()
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
            let joint_class = self.declared_class(*joint_node, "class", child_class)?;
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
            // a hinge's positions (range, ref, springref) are angles in the compiler's unit
            let position_unit = |x: f64| {
                if matches!(joint, Joint::Revolute { .. }) {
                    self.angle(x)
                } else {
                    x
                }
            };
            let mut properties = JointProperties {
                armature: scalar("armature", 0.0)?,
                damping: scalar("damping", 0.0)?,
                friction: scalar("frictionloss", 0.0)?,
                stiffness: scalar("stiffness", 0.0)?,
                spring_reference: position_unit(scalar("springref", 0.0)?),
                ..JointProperties::default()
            };
            let limited = self
                .attribute(*joint_node, joint_class, "limited")
                .is_none_or(|l| l != "false");
            if let (true, Some([lower, upper])) = (
                limited,
                self.numbers::<2>(*joint_node, joint_class, "range")?,
            ) {
                properties.lower = position_unit(lower);
                properties.upper = position_unit(upper);
            }
            // `ref`: the joint position at which the body has its XML pose, so the joint moves
            // by q − ref: X_J(q − ref) X_tree = X_J(q) X_J(−ref) X_tree
            let reference = position_unit(scalar("ref", 0.0)?);
            let shift_by_reference = match (reference, joint.nq()) {
                (0.0, _) => Transform::IDENTITY,
                (_, 1) => joint.transform(&[-reference]),
                _ => {
                    return Err(self.error(
                        *joint_node,
                        "attribute 'ref': only hinge and slide joints take one",
                    ))
                }
            };
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
                shift_by_reference * Transform::from_translation(&position) * to_body
            } else {
                shift_by_reference * Transform::from_translation(&(position - previous_position))
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
