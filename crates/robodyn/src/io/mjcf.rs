//! MJCF loader (MuJoCo's XML, <https://mujoco.readthedocs.io/en/stable/XMLreference.html>), the
//! part that describes a robot's rigid-body tree.
//!
//! Reads `<include file>` (resolved against the including file's folder, each file once),
//! `<compiler angle eulerseq inertiafromgeom inertiagrouprange>`, `<default>` classes (nested,
//! with `class` and `childclass`), and in `<worldbody>` nested `<body>`s with `pos` and any
//! orientation (`quat` w-first, `axisangle`, `euler`, `xyaxes`, `zaxis`), `<inertial>` (`mass`,
//! `pos`, orientation, `diaginertia` or `fullinertia`), `<geom>`s (for the inertia of a body
//! without `<inertial>`, as visuals and as collision shapes: `mjcf/geoms.rs`), `<joint>` (`hinge`,
//! `slide`, `ball`, `free`; `pos`, `axis`, `ref`, `range`, `armature`, `damping`, `frictionloss`,
//! `stiffness` (both with polynomial terms), `springref`, `springdamper`, and the soft limit's and
//! friction's `solreflimit`, `solimplimit`, `margin`, `solreffriction`, `solimpfriction`),
//! `<freejoint>` and `<site>`s.
//! A body's `gravcomp` is kept for the scene's dynamics; the attributes MuJoCo reads and robodyn
//! does not model warn where given (`mjcf/unmodelled.rs`).
//! Bodies and sites become frames; a body without joints is merged into its parent; several joints
//! in one body become a chain of massless bodies, applied in order as MuJoCo does. A free joint's
//! q is the body's pose in the world (the XML pose is only MuJoCo's initial qpos).
//! Every element and attribute is first checked against MuJoCo's schema (`schema_table.rs`): an
//! unknown name is an error, as in MuJoCo.
//! `<equality>` `connect`, `weld` and `joint` become the model's constraints (`mjcf/equality.rs`),
//! `<actuator>` its actuators (`mjcf/actuators.rs`), `<keyframe>` keys its keyframes
//! (`mjcf/keyframes.rs`), `<option>` its simulation options and gravity (`mjcf/options.rs`),
//! `<contact>` its contact pairs and exclusions (`mjcf/contacts.rs`).
//! Not read (a warning each): sensors, tendons (and their equalities). Contacts are not yet
//! computed: a warning says so when geoms could touch.
//! Of the assets, the meshes are read, for the inertia of mesh geoms (`mjcf/meshes.rs`).

use crate::collision::{checked_pairs, collider, never_touch};
use crate::error::{Error, Result};
use crate::io::read_model_file;
use crate::io::schema;
use crate::io::xml::{check_nesting, location, parse_numbers};
use crate::model::{Model, ModelBuilder, PlasticSlot, SourceBody};
use crate::spatial::{Mat3, Transform, Vec3};
use nalgebra::{Rotation3, Unit, UnitQuaternion};
use roxmltree::{Document, Node};
use std::cell::{Cell, RefCell};
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

mod actuator_defaults;
mod actuators;
mod bodies;
mod contacts;
mod defaults;
mod equality;
mod geoms;
mod height_fields;
mod inertia;
mod joints;
mod keyframes;
mod mass;
mod meshes;
mod options;
mod schema_table;
mod tendons;
mod textures;
mod unmodelled;
mod visuals;

use actuator_defaults::ClassActuator;
use inertia::InertiaFromGeoms;
use mass::MassRules;
use schema_table::MJCF_SCHEMA;

/// Sections of an MJCF file that do not describe the tree.
const IGNORED_SECTIONS: [&str; 4] = ["sensor", "visual", "statistic", "deformable"];

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
        actuator_defaults: HashMap::new(),
        mass_rules: MassRules::default(),
        total_mass: Cell::new(0.0),
        meshes: HashMap::new(),
        materials: HashMap::new(),
        mesh_directory: None,
        fit_aabb: false,
        auto_limits: true,
        align_free: false,
        mesh_cache: RefCell::new(HashMap::new()),
        mesh_triangles: RefCell::new(HashMap::new()),
        hull_cache: RefCell::new(HashMap::new()),
        height_fields: HashMap::new(),
        height_field_cache: RefCell::new(HashMap::new()),
        paired_geoms: HashSet::new(),
        textures: HashMap::new(),
        skybox: None,
        texture_directory: None,
        warnings: RefCell::new(Vec::new()),
        source_bodies: RefCell::new(vec![SourceBody {
            name: "world".to_string(),
            parent: 0,
            body: 0,
            mass: 0.0,
            com: crate::spatial::Vec3::zeros(),
            simple: false,
            gravcomp: 0.0,
        }]),
        site_bodies: RefCell::new(HashMap::new()),
        site_points: RefCell::new(HashMap::new()),
        spring_dampers: RefCell::new(Vec::new()),
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
    for contact in sections.iter().filter(|c| c.has_tag_name("contact")) {
        reader.note_paired_geoms(*contact)?;
    }
    for asset in sections.iter().filter(|c| c.has_tag_name("asset")) {
        reader.read_assets(*asset)?;
        reader.read_height_fields(*asset)?;
        reader.read_textures(*asset)?;
    }
    let mut builder = ModelBuilder::new(root.attribute("model").unwrap_or("mjcf"), "world");
    builder.add_frame("world", 0, Transform::IDENTITY);
    for section in &sections {
        if IGNORED_SECTIONS.contains(&section.tag_name().name()) {
            builder.warn(format!(
                "{}: not read (robodyn models the rigid-body tree only)",
                reader.location(*section)
            ));
        }
    }
    for world in sections.iter().filter(|c| c.has_tag_name("worldbody")) {
        reader.add_geoms(
            &mut builder,
            &reader.children(*world)?,
            "main",
            (0, 0),
            Transform::IDENTITY,
        )?;
        reader.read_children(&mut builder, *world, (0, 0), Transform::IDENTITY, "main")?;
    }
    if let Some(skybox) = reader.skybox_texture()? {
        builder.set_skybox(skybox);
    }
    if let Some(factor) = reader.mass_rules.total_mass_scale(reader.total_mass.get()) {
        builder.scale_inertias(factor);
    }
    for message in reader.warnings.take() {
        builder.warn(message);
    }
    let mut model = builder.build();
    reader.read_tendons(&sections, &mut model)?;
    reader.read_equalities(&sections, &mut model)?;
    reader.read_actuators(&sections, &mut model)?;
    reader.read_keyframes(&sections, &mut model)?;
    reader.read_options(&sections, &mut model)?;
    model.source_bodies = reader.source_bodies.take();
    let compensated: Vec<String> = (model.source_bodies.iter())
        .filter(|s| s.gravcomp != 0.0)
        .map(|s| s.name.clone())
        .collect();
    let what = "the gravity compensation (gravcomp) of {} holds them up";
    let elsewhere = "feel their full weight";
    let warning = scene_only(&reader.location(root), what, &compensated, elsewhere);
    model.warnings.extend(warning);
    let plastic: Vec<String> = (model.plastic_slots())
        .map(|(slot, _)| match slot {
            PlasticSlot::Joint(i) => format!("joint '{}'", model.joint_names[i]),
            PlasticSlot::Tendon(t) => format!("tendon '{}'", model.tendons[t].name),
        })
        .collect();
    let what = "the springs of {} yield (springyield)";
    let elsewhere = "keep them elastic";
    let warning = scene_only(&reader.location(root), what, &plastic, elsewhere);
    model.warnings.extend(warning);
    reader.tendon_inertias(root, &mut model);
    reader.apply_spring_dampers(&mut model)?;
    reader.read_contacts(&sections, &mut model)?;
    for message in reader.warnings.take() {
        model.warnings.push(message);
    }
    // a warning only where MuJoCo would check some pair of geoms for contact
    let checked = checked_pairs(&model);
    if !checked.is_empty() && model.options.flag("contact") && model.options.flag("constraint") {
        // the kinds of pairs whose contacts are not found yet (planes and fields never touch)
        let mut unfound: Vec<String> = Vec::new();
        for pair in &checked {
            let (one, other) = (
                &model.geoms[pair.geoms.0].shape,
                &model.geoms[pair.geoms.1].shape,
            );
            let kinds = format!("{}–{}", one.kind(), other.kind());
            let unmodelled = collider(one, other).is_none() && !never_touch(one, other);
            if unmodelled && !unfound.contains(&kinds) {
                unfound.push(kinds);
            }
        }
        let unfound = if unfound.is_empty() {
            String::new()
        } else {
            format!(
                "; the contacts of {} pairs are not found yet (m.collide leaves them out)",
                unfound.join(", ")
            )
        };
        model.warnings.push(format!(
            "{}: geoms read as collision shapes (m.geoms, m.collide; their forces: \
             m.contact_forward_dynamics); robodyn.simulate feels them only with \
             integrator='mujoco' (the scene stepped as MuJoCo steps it): with its other \
             integrators bodies pass through each other and the floor{unfound}",
            reader.location(root)
        ));
    }
    Ok(model)
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
    /// (the actuator elements' under one tag, `defaults::defaults_tag`)
    defaults: HashMap<String, HashMap<String, HashMap<String, String>>>,
    /// class -> its actuator default's gain, bias and dynamics ([`actuator_defaults`])
    actuator_defaults: HashMap<String, ClassActuator>,
    /// `boundmass`, `boundinertia`, `balanceinertia`, `settotalmass`
    mass_rules: MassRules,
    /// the mass of every body read so far, those welded to the world included
    total_mass: Cell<f64>,
    /// `<asset><mesh>` elements by name, `<compiler meshdir>` (or `assetdir`), and each mesh's
    /// mass properties once computed
    meshes: HashMap<String, Node<'a, 'a>>,
    /// `<asset><material>` elements by name
    materials: HashMap<String, Node<'a, 'a>>,
    mesh_directory: Option<String>,
    /// `<compiler fitaabb>`: primitives fitted to a mesh's bounding box rather than its inertia
    fit_aabb: bool,
    /// `<compiler autolimits>`: a range without its `limited` limits (true, MuJoCo's default)
    /// or is refused (false).
    auto_limits: bool,
    /// `<compiler alignfree>`: whether a free body without children has its frame moved to its
    /// inertial frame where its `<freejoint align>` is "auto" (MuJoCo's default: false).
    align_free: bool,
    mesh_cache: RefCell<HashMap<String, meshes::CompiledMesh>>,
    /// each mesh's triangles in its geoms' frame, read once
    mesh_triangles: RefCell<HashMap<String, std::rc::Rc<crate::io::mesh::TriangleMesh>>>,
    /// each mesh's convex hull for its collision geoms, built once
    hull_cache: RefCell<HashMap<String, std::sync::Arc<crate::collision::hull::ConvexHull>>>,
    /// `<asset><hfield>` elements by name, and each field once read
    height_fields: HashMap<String, Node<'a, 'a>>,
    height_field_cache:
        RefCell<HashMap<String, std::sync::Arc<crate::collision::height_field::HeightField>>>,
    /// the geoms a `<contact><pair>` names: they collide whatever their bits say
    paired_geoms: HashSet<String>,
    /// `<asset><texture>` elements by name, the first skybox, and `<compiler texturedir>` (or
    /// `assetdir`)
    textures: HashMap<String, Node<'a, 'a>>,
    skybox: Option<Node<'a, 'a>>,
    texture_directory: Option<String>,
    /// what the model's warnings will say of the files read on the way (meshes' dropped faces)
    warnings: RefCell<Vec<String>>,
    /// the file's bodies' names by MuJoCo body id (the world first), as they are read
    source_bodies: RefCell<Vec<SourceBody>>,
    /// each site's file body (MuJoCo body id), by the site's name
    site_bodies: RefCell<HashMap<String, usize>>,
    /// each site's body in the model and its position in that body's frame
    site_points: RefCell<HashMap<String, (usize, Vec3)>>,
    /// Each joint with a `springdamper`: its body, (time constant, damping ratio) and the
    /// joint's own linear damping ([`Reader::apply_spring_dampers`]).
    spring_dampers: RefCell<Vec<(usize, [f64; 2], f64)>>,
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
        // where mesh files are: meshdir, else assetdir
        if let Some(folder) = compiler
            .attribute("meshdir")
            .or(compiler.attribute("assetdir"))
        {
            self.mesh_directory = Some(folder.to_string());
        }
        if let Some(folder) = compiler
            .attribute("texturedir")
            .or(compiler.attribute("assetdir"))
        {
            self.texture_directory = Some(folder.to_string());
        }
        if let Some(value) = compiler.attribute("fitaabb") {
            self.fit_aabb = value == "true";
        }
        if let Some(value) = compiler.attribute("alignfree") {
            self.align_free = value == "true";
        }
        if let Some(value) = compiler.attribute("autolimits") {
            self.auto_limits = value != "false";
        }
        if compiler.attribute("coordinate") == Some("global") {
            return Err(self.error(
                compiler,
                "attribute 'coordinate': global coordinates are refused, as MuJoCo (since 2.3.4) \
                 refuses them",
            ));
        }
        // the options that rewrite masses and inertias (mjcf/mass.rs)
        let number = |name: &str| self.own_number(compiler, name);
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
}

/// A warning that what `what` says of `names` (its `{}`) holds in the scene's own dynamics only,
/// while robodyn's other integrators and algorithms do what `elsewhere` says; none without names.
fn scene_only(location: &str, what: &str, names: &[String], elsewhere: &str) -> Option<String> {
    (!names.is_empty()).then(|| {
        format!(
            "{location}: {} in the scene's own dynamics (m.contact_forward_dynamics, simulate \
             with integrator='mujoco'); robodyn's other integrators and algorithms {elsewhere}",
            what.replace("{}", &names.join(", "))
        )
    })
}
