//! Robots from Denavit–Hartenberg tables, standard (Denavit–Hartenberg 1955) or modified (Craig,
//! *Introduction to Robotics*, §3.4; the convention of the ECE 470 notes).
//!
//! Row i of a table holds (a, α, d, θ) and the joint kind; the joint variable adds to θ_i
//! (revolute) or to d_i (prismatic), so the table's θ or d is the joint offset.
//! - standard: `ⁱ⁻¹T_i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i)`, with (a_i, α_i) on row i;
//! - modified: `ⁱ⁻¹T_i = Rx(α_{i-1}) Tx(a_{i-1}) Rz(θ_i) Tz(d_i)`, with (a_{i-1}, α_{i-1}) on row i.
//!
//! Each row's mass, centre of mass and inertia (about the centre of mass) are given in DH frame i,
//! the frame the row ends in. The frames named after the rows are DH frames 1..n (with the
//! standard convention the bodies' own frames, at the joints, are "`<row>_joint`"); "base" is DH
//! frame 0 and "tool" the tool frame. Every table ends in the same [`ModelBuilder`] as the URDF
//! loader; the joints are named after the rows.

use crate::error::{Error, Result};
use crate::io::read_model_file;
use crate::joint::Joint;
use crate::model::{
    check_mass_and_inertia, check_physical_parameters, JointProperties, Model, ModelBuilder,
    NewBody, Unphysical,
};
use crate::spatial::{Inertia, Mat3, Transform, Vec3};

/// Which DH convention a table uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DhConvention {
    /// Denavit–Hartenberg's: `ⁱ⁻¹T_i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i)`.
    Standard,
    /// Craig's: `ⁱ⁻¹T_i = Rx(α_{i-1}) Tx(a_{i-1}) Rz(θ_i) Tz(d_i)`.
    Modified,
}

/// The joint of a DH row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DhJoint {
    /// q adds to θ.
    Revolute,
    /// q adds to d.
    Prismatic,
}

/// One row of a DH table with the link's mass properties (in DH frame i).
#[derive(Debug, Clone, PartialEq)]
pub struct DhRow {
    /// The row's name: its joint's and its DH frame's.
    pub name: String,
    /// Whether q adds to θ or to d.
    pub joint: DhJoint,
    /// Link length a (m).
    pub a: f64,
    /// Link twist α (rad).
    pub alpha: f64,
    /// Link offset d (m); the joint offset of a prismatic joint.
    pub d: f64,
    /// Joint angle θ (rad); the joint offset of a revolute joint.
    pub theta: f64,
    /// The link's mass (kg).
    pub mass: f64,
    /// Centre of mass in DH frame i.
    pub com: Vec3,
    /// Rotational inertia about the centre of mass, in DH frame i's axes.
    pub inertia: Mat3,
    /// The joint's lower position limit.
    pub lower: f64,
    /// The joint's upper position limit.
    pub upper: f64,
}

/// A robot given as a DH table.
#[derive(Debug, Clone, PartialEq)]
pub struct DhTable {
    /// The robot's name.
    pub name: String,
    /// Which convention the rows follow.
    pub convention: DhConvention,
    /// The rows, from the base outwards.
    pub rows: Vec<DhRow>,
    /// Pose of DH frame 0 in the world.
    pub base: Transform,
    /// Pose of the tool frame in the last DH frame.
    pub tool: Transform,
}

/// An elementary rotation about x or z, as the transform into the rotated frame.
fn rotation(axis: &Vec3, angle: f64) -> Transform {
    Transform::from_axis_angle(axis, angle)
}

fn translation(x: f64, y: f64, z: f64) -> Transform {
    Transform::from_translation(&Vec3::new(x, y, z))
}

/// The transform of a chain of poses `P_1 P_2 … P_k` (each relative to the previous frame).
fn chain(poses: &[Transform]) -> Transform {
    // X(P_1 P_2) = X(P_2) X(P_1)
    poses.iter().fold(Transform::IDENTITY, |x, pose| *pose * x)
}

/// Row i split around its joint motion: (before, after) with `ⁱ⁻¹T_i = before · J(q) · after`.
fn split_row(convention: DhConvention, row: &DhRow) -> (Transform, Transform) {
    let (x, z) = (Vec3::x(), Vec3::z());
    match (convention, row.joint) {
        // Rx(α) Tx(a) Rz(θ + q) Tz(d) = [Rx(α) Tx(a) Rz(θ) Tz(d)] Rz(q), and likewise for d + q
        (DhConvention::Modified, _) => (
            chain(&[
                rotation(&x, row.alpha),
                translation(row.a, 0.0, 0.0),
                rotation(&z, row.theta),
                translation(0.0, 0.0, row.d),
            ]),
            Transform::IDENTITY,
        ),
        // Rz(θ + q) Tz(d) Tx(a) Rx(α) = [Rz(θ)] Rz(q) [Tz(d) Tx(a) Rx(α)]
        (DhConvention::Standard, DhJoint::Revolute) => (
            rotation(&z, row.theta),
            chain(&[
                translation(0.0, 0.0, row.d),
                translation(row.a, 0.0, 0.0),
                rotation(&x, row.alpha),
            ]),
        ),
        // Rz(θ) Tz(d + q) Tx(a) Rx(α) = [Rz(θ) Tz(d)] Tz(q) [Tx(a) Rx(α)]
        (DhConvention::Standard, DhJoint::Prismatic) => (
            chain(&[rotation(&z, row.theta), translation(0.0, 0.0, row.d)]),
            chain(&[translation(row.a, 0.0, 0.0), rotation(&x, row.alpha)]),
        ),
    }
}

/// Builds the model of a DH table. Body i's frame is the joint frame of row i (DH frame i for the
/// modified convention, DH frame i-1 turned by joint i for the standard one).
pub fn build_dh(table: &DhTable) -> Result<Model> {
    if table.rows.is_empty() {
        return Err(Error::model(
            format!("DH table '{}'", table.name),
            "expected at least one row",
        ));
    }
    let mut builder = ModelBuilder::new(&table.name, "world");
    builder.add_frame("base", 0, table.base);
    // X from the current body's frame to the last DH frame
    let mut dh_frame = table.base;
    let mut body = 0;
    for (i, row) in table.rows.iter().enumerate() {
        let location = format!("DH table '{}', row {} ('{}')", table.name, i + 1, row.name);
        let parameters = [row.a, row.alpha, row.d, row.theta, row.mass];
        if parameters
            .iter()
            .chain(row.com.iter())
            .chain(row.inertia.iter())
            .any(|x| !x.is_finite())
        {
            return Err(Error::model(
                location,
                "expected finite a, alpha, d, theta, mass, com and inertia",
            ));
        }
        if row.lower.is_nan() || row.upper.is_nan() || row.lower > row.upper {
            return Err(Error::model(
                location,
                format!(
                    "expected limits lower <= upper, got {} and {}",
                    row.lower, row.upper
                ),
            ));
        }
        check_mass_and_inertia(row.mass, &row.inertia)
            .map_err(|message| Error::model(location.clone(), message))?;
        // the rule for physical inertias: invalid is an error, the triangle inequality a warning
        let link = Inertia::from_com(row.mass, &row.com, &row.inertia);
        match check_physical_parameters(&link.to_parameters()) {
            Ok(()) => {}
            Err(Unphysical::Invalid(message)) => return Err(Error::model(location, message)),
            Err(Unphysical::TriangleInequality(message)) => builder.warn(format!(
                "{location}: {message} (loaded as given; strict=True refuses it)"
            )),
        }
        let (before, after) = split_row(table.convention, row);
        let joint = match row.joint {
            DhJoint::Revolute => Joint::Revolute { axis: Vec3::z() },
            DhJoint::Prismatic => Joint::Prismatic { axis: Vec3::z() },
        };
        // the link's inertia (above), given in DH frame i, is moved into the body frame
        // the body frame is DH frame i when nothing follows the joint (modified convention)
        let dh_frame_is_body = after == Transform::IDENTITY;
        let body_name = if dh_frame_is_body {
            row.name.clone()
        } else {
            format!("{}_joint", row.name)
        };
        body = builder.add_body(NewBody {
            parent: body,
            joint,
            joint_name: &row.name,
            x_tree: before * dh_frame,
            properties: JointProperties {
                lower: row.lower,
                upper: row.upper,
                ..JointProperties::default()
            },
            name: &body_name,
            inertia: after.transpose_apply_inertia(&link),
        })?;
        if !dh_frame_is_body {
            builder.add_frame(&row.name, body, after);
        }
        dh_frame = after;
    }
    builder.add_frame("tool", body, table.tool * dh_frame);
    Ok(builder.build())
}

/// Loads a DH table file (TOML; the format is in `docs/guide/loading-models.md`).
pub fn load_dh_file(path: &std::path::Path) -> Result<Model> {
    let text = read_model_file(path)?;
    load_dh_str(&text, &path.display().to_string())
}

/// Loads a DH table from TOML text; `source` names it in error messages.
pub fn load_dh_str(text: &str, source: &str) -> Result<Model> {
    let document: toml::Table = text.parse().map_err(|e: toml::de::Error| {
        Error::model(
            source,
            format!("malformed TOML: {}", e.to_string().trim_end()),
        )
    })?;
    load_dh_document(&document, source)
}

/// Builds the model of a DH table held in a TOML document (or anything converted to one).
pub fn load_dh_document(document: &toml::Table, source: &str) -> Result<Model> {
    let reader = DocumentReader { source };
    let (table, gravity) = reader.table(document)?;
    let mut model = build_dh(&table)?;
    if let Some(gravity) = gravity {
        model.gravity = gravity;
    }
    Ok(model)
}

const TOP_KEYS: [&str; 7] = [
    "name",
    "convention",
    "angle_unit",
    "gravity",
    "base",
    "tool",
    "joint",
];
const ROW_KEYS: [&str; 12] = [
    "name", "type", "a", "alpha", "d", "theta", "mass", "com", "inertia", "lower", "upper",
    "comment",
];
const POSE_KEYS: [&str; 2] = ["xyz", "rpy"];

/// Reads the DH document, with errors that name the file and the key.
struct DocumentReader<'a> {
    source: &'a str,
}

impl DocumentReader<'_> {
    fn error(&self, place: &str, message: impl Into<String>) -> Error {
        Error::model(format!("{}: {place}", self.source), message)
    }

    fn check_keys(&self, place: &str, table: &toml::Table, allowed: &[&str]) -> Result<()> {
        match table.keys().find(|k| !allowed.contains(&k.as_str())) {
            None => Ok(()),
            Some(key) => Err(self.error(
                place,
                format!("unknown key '{key}': expected one of {allowed:?}"),
            )),
        }
    }

    fn number(
        &self,
        place: &str,
        table: &toml::Table,
        key: &str,
        default: Option<f64>,
    ) -> Result<f64> {
        match table.get(key) {
            None => default.ok_or_else(|| self.error(place, format!("missing key '{key}'"))),
            Some(toml::Value::Float(x)) => Ok(*x),
            Some(toml::Value::Integer(x)) => Ok(*x as f64),
            Some(other) => {
                Err(self.error(place, format!("'{key}': expected a number, got {other}")))
            }
        }
    }

    fn numbers<const N: usize>(
        &self,
        place: &str,
        table: &toml::Table,
        key: &str,
        default: [f64; N],
    ) -> Result<[f64; N]> {
        let Some(value) = table.get(key) else {
            return Ok(default);
        };
        let expected = || {
            self.error(
                place,
                format!("'{key}': expected an array of {N} numbers, got {value}"),
            )
        };
        let items = value
            .as_array()
            .filter(|a| a.len() == N)
            .ok_or_else(expected)?;
        let mut out = [0.0; N];
        for (slot, item) in out.iter_mut().zip(items) {
            *slot = match item {
                toml::Value::Float(x) => *x,
                toml::Value::Integer(x) => *x as f64,
                _ => return Err(expected()),
            };
        }
        Ok(out)
    }

    fn text<'t>(&self, place: &str, table: &'t toml::Table, key: &str) -> Result<Option<&'t str>> {
        match table.get(key) {
            None => Ok(None),
            Some(toml::Value::String(s)) => Ok(Some(s)),
            Some(other) => {
                Err(self.error(place, format!("'{key}': expected a string, got {other}")))
            }
        }
    }

    /// `{ xyz, rpy }` as the transform into that frame.
    fn pose(&self, document: &toml::Table, key: &str, angle: f64) -> Result<Transform> {
        let Some(value) = document.get(key) else {
            return Ok(Transform::IDENTITY);
        };
        let place = format!("[{key}]");
        let table = value
            .as_table()
            .ok_or_else(|| self.error(&place, "expected a table with 'xyz' and 'rpy'"))?;
        self.check_keys(&place, table, &POSE_KEYS)?;
        let xyz = self.numbers(&place, table, "xyz", [0.0; 3])?;
        let [roll, pitch, yaw] = self.numbers(&place, table, "rpy", [0.0; 3])?;
        let rotation = crate::spatial::rotation_from_rpy(roll * angle, pitch * angle, yaw * angle);
        Ok(Transform::from_pose(&rotation, &Vec3::from(xyz)))
    }

    fn table(&self, document: &toml::Table) -> Result<(DhTable, Option<Vec3>)> {
        self.check_keys("top level", document, &TOP_KEYS)?;
        let name = self
            .text("top level", document, "name")?
            .unwrap_or("dh_robot")
            .to_string();
        let convention = match self.text("top level", document, "convention")? {
            Some("standard") => DhConvention::Standard,
            Some("modified") => DhConvention::Modified,
            Some(other) => {
                return Err(self.error(
                    "top level",
                    format!("'convention': expected \"standard\" or \"modified\", got \"{other}\""),
                ))
            }
            None => {
                return Err(self.error(
                    "top level",
                    "'convention': missing; expected \"standard\" or \"modified\"".to_string(),
                ))
            }
        };
        let angle = match self.text("top level", document, "angle_unit")? {
            None | Some("radian") => 1.0,
            Some("degree") => std::f64::consts::PI / 180.0,
            Some(other) => {
                return Err(self.error(
                    "top level",
                    format!("'angle_unit': expected \"radian\" or \"degree\", got \"{other}\""),
                ))
            }
        };
        let gravity = match document.get("gravity") {
            None => None,
            Some(_) => Some(Vec3::from(self.numbers(
                "top level",
                document,
                "gravity",
                [0.0; 3],
            )?)),
        };
        let rows = document
            .get("joint")
            .and_then(|j| j.as_array())
            .ok_or_else(|| self.error("top level", "expected [[joint]] rows"))?;
        let rows = rows
            .iter()
            .enumerate()
            .map(|(i, row)| {
                let place = format!("[[joint]] {}", i + 1);
                let row = row
                    .as_table()
                    .ok_or_else(|| self.error(&place, "expected a table"))?;
                self.row(&place, row, i, angle)
            })
            .collect::<Result<Vec<_>>>()?;
        let table = DhTable {
            name,
            convention,
            rows,
            base: self.pose(document, "base", angle)?,
            tool: self.pose(document, "tool", angle)?,
        };
        Ok((table, gravity))
    }

    fn row(&self, place: &str, row: &toml::Table, index: usize, angle: f64) -> Result<DhRow> {
        self.check_keys(place, row, &ROW_KEYS)?;
        let joint = match self.text(place, row, "type")? {
            Some("revolute") => DhJoint::Revolute,
            Some("prismatic") => DhJoint::Prismatic,
            Some(other) => {
                return Err(self.error(
                    place,
                    format!("'type': expected \"revolute\" or \"prismatic\", got \"{other}\""),
                ))
            }
            None => {
                return Err(self.error(
                    place,
                    "'type': missing; expected \"revolute\" or \"prismatic\"".to_string(),
                ))
            }
        };
        let [ixx, iyy, izz, ixy, ixz, iyz] = self.numbers(place, row, "inertia", [0.0; 6])?;
        // limits of a revolute joint are angles
        let limit_unit = if joint == DhJoint::Revolute {
            angle
        } else {
            1.0
        };
        Ok(DhRow {
            name: self
                .text(place, row, "name")?
                .map_or_else(|| format!("joint{}", index + 1), str::to_string),
            joint,
            a: self.number(place, row, "a", None)?,
            alpha: self.number(place, row, "alpha", None)? * angle,
            d: self.number(place, row, "d", None)?,
            theta: self.number(place, row, "theta", None)? * angle,
            mass: self.number(place, row, "mass", Some(0.0))?,
            com: Vec3::from(self.numbers(place, row, "com", [0.0; 3])?),
            inertia: Mat3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz),
            lower: self.number(place, row, "lower", Some(f64::NEG_INFINITY))? * limit_unit,
            upper: self.number(place, row, "upper", Some(f64::INFINITY))? * limit_unit,
        })
    }
}
