//! An actuator's gain, bias and activation dynamics as MuJoCo (≥ 4.0) compiles them from the
//! element and its class's actuator default.
//!
//! Every actuator element compiles to MuJoCo's one actuator: a gain (`gaintype`, `gainprm`), a
//! bias (`biastype`, `biasprm`) and activation dynamics (`dyntype`, `dynprm`), a
//! [`RawActuator`]. A class has a single actuator default, written with `general` or with a
//! shortcut; several actuator elements in one `<default>` apply in order.
//! - `general` takes the raw parameters of its class's default, whatever wrote it, and replaces
//!   only those it gives.
//! - A shortcut (`motor`, `position`, `intvelocity`, `velocity`, `damper`, `cylinder`) sets its
//!   whole table from its own parameters (`kp`, `kv`, `area`, ...). It inherits them only from
//!   the nearest class (its own, then its ancestors) whose default was written with the same
//!   shortcut or with a `general` of the shortcut's gain type, whose raw parameters it reads as
//!   its own; without one, from its documented defaults.
//!
//! Mechanical attributes (`ctrlrange`, `gear`, `forcerange`, ...) pass from an actuator default
//! of any kind: the reader keeps them under one `actuator` entry of each class.
//!
//! Reference: MuJoCo's modeling guide, "Actuator shortcuts" (actuator defaults), and its XML
//! reference for each shortcut's table.

use super::Reader;
use crate::error::Result;
use crate::io::xml::parse_number_list;
use roxmltree::Node;
use std::collections::HashMap;

/// The MJCF actuator elements; in a `<default>` they share one actuator default.
pub(super) const ACTUATOR_KINDS: [&str; 12] = [
    "general",
    "motor",
    "position",
    "velocity",
    "intvelocity",
    "damper",
    "cylinder",
    "muscle",
    "adhesion",
    "pid",
    "dcmotor",
    "orientation",
];

/// The number of gain, bias and dynamics parameters MuJoCo keeps (`mjNGAIN`, `mjNBIAS`,
/// `mjNDYN`).
const PARAMETERS: usize = 10;

/// MuJoCo's raw actuator parameters, and the element kind that wrote them.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct RawActuator {
    /// The element that last set them (`""`: none yet, MuJoCo's defaults).
    pub written_with: String,
    pub gain_type: String,
    pub gain: [f64; PARAMETERS],
    pub bias_type: String,
    pub bias: [f64; PARAMETERS],
    pub dyn_type: String,
    pub dynamics: [f64; PARAMETERS],
    /// `inheritrange`: the transmission's range scaled about its middle (0: none).
    pub inherit_range: f64,
    /// `actdim`, where given (a `general`'s).
    pub act_dim: Option<f64>,
    /// `actearly` (a `general`'s; a shortcut sets its activation layout without it).
    pub act_early: bool,
}

impl Default for RawActuator {
    /// MuJoCo's defaults: a unit fixed gain, no bias, no dynamics.
    fn default() -> Self {
        let mut unit = [0.0; PARAMETERS];
        unit[0] = 1.0;
        RawActuator {
            written_with: String::new(),
            gain_type: "fixed".into(),
            gain: unit,
            bias_type: "none".into(),
            bias: [0.0; PARAMETERS],
            dyn_type: "none".into(),
            dynamics: unit,
            inherit_range: 0.0,
            act_dim: None,
            act_early: false,
        }
    }
}

/// The shortcuts robodyn models, by the table each sets.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Shortcut {
    /// `motor`: a unit gain.
    Motor,
    /// `position` (`integrated`: `intvelocity`): gain kp, bias −kp l − kv l̇.
    Servo { integrated: bool },
    /// `velocity`: gain kv, bias −kv l̇.
    Velocity,
    /// `damper`: an affine gain −kv l̇.
    Damper,
    /// `cylinder`: gain `area` on a filtered activation, bias `bias`.
    Cylinder,
}

impl Shortcut {
    fn of(tag: &str) -> Option<Shortcut> {
        Some(match tag {
            "motor" => Shortcut::Motor,
            "position" => Shortcut::Servo { integrated: false },
            "intvelocity" => Shortcut::Servo { integrated: true },
            "velocity" => Shortcut::Velocity,
            "damper" => Shortcut::Damper,
            "cylinder" => Shortcut::Cylinder,
            _ => return None,
        })
    }

    /// The gain type of the `general` defaults it may inherit from.
    fn gain_type(self) -> &'static str {
        match self {
            Shortcut::Damper => "affine",
            _ => "fixed",
        }
    }

    /// Its whole table, its parameters read from `source` (a default written with it or with a
    /// `general` of its gain type; MuJoCo's defaults give the documented ones).
    fn table(self, tag: &str, source: &RawActuator) -> RawActuator {
        let mut raw = RawActuator {
            written_with: tag.to_string(),
            ..RawActuator::default()
        };
        match self {
            Shortcut::Motor => {}
            Shortcut::Servo { integrated } => {
                // kp = gainprm[0]; biasprm[2]: −kv, or a damping ratio when positive
                let kp = source.gain[0];
                raw.gain[0] = kp;
                raw.bias_type = "affine".into();
                raw.bias[1] = -kp;
                raw.bias[2] = source.bias[2];
                raw.inherit_range = source.inherit_range;
                // a filterexact source's time constant stays (an intvelocity keeps it unused)
                if source.dyn_type == "filterexact" {
                    raw.dyn_type = "filterexact".into();
                    raw.dynamics[0] = source.dynamics[0];
                }
                if integrated {
                    raw.dyn_type = "integrator".into();
                }
            }
            Shortcut::Velocity => {
                let kv = source.gain[0];
                raw.gain[0] = kv;
                raw.bias_type = "affine".into();
                raw.bias[2] = -kv;
            }
            Shortcut::Damper => {
                raw.gain_type = "affine".into();
                raw.gain[0] = 0.0;
                raw.gain[2] = source.gain[2];
            }
            Shortcut::Cylinder => {
                raw.dyn_type = "filter".into();
                raw.dynamics[0] = source.dynamics[0];
                raw.gain[0] = source.gain[0];
                raw.bias_type = "affine".into();
                raw.bias[..3].copy_from_slice(&source.bias[..3]);
            }
        }
        raw
    }
}

/// A class's actuator default and the class above it.
#[derive(Debug, Clone)]
pub(super) struct ClassActuator {
    pub raw: RawActuator,
    pub parent: Option<String>,
}

impl<'a> Reader<'a> {
    /// The actuator defaults of `class` and the classes above it, nearest first.
    pub(super) fn class_actuators<'r>(
        &'r self,
        class: Option<&str>,
    ) -> impl Iterator<Item = &'r RawActuator> {
        let first = class.and_then(|c| self.actuator_defaults.get(c));
        std::iter::successors(first, |c| {
            c.parent
                .as_deref()
                .and_then(|p| self.actuator_defaults.get(p))
        })
        .map(|c| &c.raw)
    }

    /// The raw parameters of actuator element `element` (of an `<actuator>` section) in `class`.
    pub(super) fn element_raw_actuator(
        &self,
        element: Node<'a, 'a>,
        class: &str,
    ) -> Result<RawActuator> {
        let fallback = RawActuator::default();
        let mut classes = self.class_actuators(Some(class));
        let current = classes.next().unwrap_or(&fallback);
        self.raw_actuator(element, current, classes)
    }

    /// The raw parameters of actuator `element` (in a `<default>` or an `<actuator>`) on those
    /// of its class's default `current`, with `ancestors` the defaults of the classes above it,
    /// nearest first.
    pub(super) fn raw_actuator<'r>(
        &self,
        element: Node<'a, 'a>,
        current: &'r RawActuator,
        ancestors: impl Iterator<Item = &'r RawActuator>,
    ) -> Result<RawActuator> {
        let tag = element.tag_name().name();
        if tag == "general" {
            return self.general_raw(element, current);
        }
        let Some(shortcut) = Shortcut::of(tag) else {
            // a kind robodyn does not model: a `general` in its class is not read either
            return Ok(RawActuator {
                written_with: tag.to_string(),
                gain_type: format!("of a <{tag}> default"),
                ..RawActuator::default()
            });
        };
        // the nearest default it inherits its parameters from
        let inherits = |raw: &&RawActuator| {
            raw.written_with == tag
                || (raw.written_with == "general" && raw.gain_type == shortcut.gain_type())
        };
        let fallback = RawActuator::default();
        let source = std::iter::once(current)
            .chain(ancestors)
            .find(inherits)
            .unwrap_or(&fallback);
        let mut raw = shortcut.table(tag, source);
        self.overlay_shortcut(element, shortcut, &mut raw)?;
        Ok(raw)
    }

    /// `general`: `current` with the raw parameters `element` gives.
    fn general_raw(&self, element: Node<'a, 'a>, current: &RawActuator) -> Result<RawActuator> {
        let mut raw = current.clone();
        raw.written_with = "general".into();
        for (name, kind) in [
            ("gaintype", &mut raw.gain_type),
            ("biastype", &mut raw.bias_type),
            ("dyntype", &mut raw.dyn_type),
        ] {
            if let Some(given) = element.attribute(name) {
                *kind = given.trim().to_string();
            }
        }
        for (name, values) in [
            ("gainprm", &mut raw.gain),
            ("biasprm", &mut raw.bias),
            ("dynprm", &mut raw.dynamics),
        ] {
            for (value, given) in values.iter_mut().zip(self.own_list(element, name)?) {
                *value = given;
            }
        }
        if let Some(x) = self.own_first(element, "inheritrange")? {
            raw.inherit_range = x;
        }
        if let Some(x) = self.own_first(element, "actdim")? {
            raw.act_dim = Some(x);
        }
        match element.attribute("actearly") {
            None => {}
            Some("true") => raw.act_early = true,
            Some("false") => raw.act_early = false,
            Some(other) => {
                let message =
                    format!("attribute 'actearly': expected true or false, got '{other}'");
                return Err(self.error(element, message));
            }
        }
        Ok(raw)
    }

    /// The shortcut's own parameters that `element` gives, into its table `raw`.
    fn overlay_shortcut(
        &self,
        element: Node<'a, 'a>,
        shortcut: Shortcut,
        raw: &mut RawActuator,
    ) -> Result<()> {
        let non_negative = |name: &str| -> Result<Option<f64>> {
            match self.own_first(element, name)? {
                Some(value) if value < 0.0 => {
                    let message = format!("attribute '{name}': expected a value ≥ 0, got {value}");
                    Err(self.error(element, message))
                }
                given => Ok(given),
            }
        };
        match shortcut {
            Shortcut::Motor => {}
            Shortcut::Servo { integrated } => {
                if let Some(kp) = self.own_first(element, "kp")? {
                    raw.gain[0] = kp;
                    raw.bias[1] = -kp;
                }
                match (non_negative("kv")?, non_negative("dampratio")?) {
                    (Some(_), Some(_)) => {
                        let message = "attributes 'kv' and 'dampratio': give one, not both";
                        return Err(self.error(element, message));
                    }
                    (Some(kv), None) => raw.bias[2] = -kv,
                    (None, Some(ratio)) => raw.bias[2] = ratio,
                    (None, None) => {}
                }
                if let Some(time_constant) = non_negative("timeconst")? {
                    raw.dynamics[0] = time_constant;
                    if !integrated {
                        raw.dyn_type = if time_constant > 0.0 {
                            "filterexact"
                        } else {
                            "none"
                        }
                        .into();
                    }
                }
                let range = if integrated { "actrange" } else { "ctrlrange" };
                if let Some(x) = self.own_first(element, "inheritrange")? {
                    if x > 0.0 && element.attribute(range).is_some() {
                        let message =
                            format!("attributes '{range}' and 'inheritrange': give one, not both");
                        return Err(self.error(element, message));
                    }
                    raw.inherit_range = x;
                } else if element.attribute(range).is_some() {
                    // a range given here overrides an inherited inheritrange
                    raw.inherit_range = 0.0;
                }
            }
            Shortcut::Velocity => {
                if let Some(kv) = self.own_first(element, "kv")? {
                    raw.gain[0] = kv;
                    raw.bias[2] = -kv;
                }
            }
            Shortcut::Damper => {
                if let Some(kv) = non_negative("kv")? {
                    raw.gain[2] = -kv;
                }
                if raw.gain[2] > 0.0 {
                    let message = format!(
                        "a damper's kv must be ≥ 0, got {} (from its class's default)",
                        -raw.gain[2]
                    );
                    return Err(self.error(element, message));
                }
            }
            Shortcut::Cylinder => {
                if let Some(time_constant) = self.own_first(element, "timeconst")? {
                    raw.dynamics[0] = time_constant;
                }
                if let Some(area) = self.own_first(element, "area")? {
                    raw.gain[0] = area;
                }
                if let Some(diameter) = self.own_first(element, "diameter")? {
                    if diameter >= 0.0 {
                        raw.gain[0] = std::f64::consts::PI / 4.0 * diameter * diameter;
                    }
                }
                let bias = self.own_list(element, "bias")?;
                match bias.len() {
                    0 => {}
                    3 => raw.bias[..3].copy_from_slice(&bias),
                    n => {
                        let message = format!("attribute 'bias': expected 3 numbers, got {n}");
                        return Err(self.error(element, message));
                    }
                }
            }
        }
        Ok(())
    }

    /// What a shortcut in a `<default>` does to its class's ranges (`ranges`: the class's
    /// actuator attributes so far, this element's in): a `damper` limits the control (its range
    /// non-negative); a `position`'s or `intvelocity`'s own `inheritrange` clears the range it
    /// sets (the control's, the activation's).
    pub(super) fn shortcut_ranges(
        &self,
        element: Node<'a, 'a>,
        ranges: &mut HashMap<String, String>,
    ) -> Result<()> {
        match element.tag_name().name() {
            "damper" => {
                ranges.insert("ctrllimited".into(), "true".into());
                let range = ranges
                    .get("ctrlrange")
                    .map(|t| parse_number_list(t, "ctrlrange"));
                let range = range.transpose().map_err(|m| self.error(element, m))?;
                if range.is_some_and(|r| r.iter().any(|x| *x < 0.0)) {
                    let message = "attribute 'ctrlrange': a damper's range cannot be negative";
                    return Err(self.error(element, message));
                }
            }
            tag @ ("position" | "intvelocity")
                if self
                    .own_first(element, "inheritrange")?
                    .is_some_and(|x| x > 0.0) =>
            {
                ranges.remove(if tag == "position" {
                    "ctrlrange"
                } else {
                    "actrange"
                });
            }
            _ => {}
        }
        Ok(())
    }

    /// The numbers of attribute `name` that `element` itself gives (none when it does not).
    fn own_list(&self, element: Node<'a, 'a>, name: &str) -> Result<Vec<f64>> {
        element
            .attribute(name)
            .map(|text| parse_number_list(text, name).map_err(|m| self.error(element, m)))
            .transpose()
            .map(Option::unwrap_or_default)
    }

    /// The first number of attribute `name` that `element` itself gives.
    fn own_first(&self, element: Node<'a, 'a>, name: &str) -> Result<Option<f64>> {
        Ok(self.own_list(element, name)?.first().copied())
    }
}
