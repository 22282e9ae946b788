//! `<option>` and its `<flag>`: how the file asks to be simulated, into [`SimulationOptions`]
//! and the model's gravity.
//!
//! Read as MuJoCo reads them (each `<option>` changes only what it sets; MuJoCo's defaults
//! otherwise): `timestep`, `integrator`, `cone`, `solver`, `impratio`, `tolerance`, `iterations`,
//! `ls_iterations`, `ls_tolerance`, `noslip_iterations`, `noslip_tolerance`, `o_margin`,
//! `o_solref`, `o_solimp`, `o_friction`, `gravity`, and every flag. A disabled `gravity` leaves
//! the model without gravity and a disabled `equality` or `constraint` its equalities inactive,
//! as MuJoCo's simulation has them. Fluid forces (`density`, `viscosity`, `wind`) and the flags
//! that change what robodyn computes but it does not yet follow are warnings naming them.

use super::Reader;
use crate::error::Result;
use crate::io::xml::{parse_number_list, parse_numbers};
use crate::model::{
    ConstraintSolver, FrictionCone, Integrator, Model, SimulationOptions, DISABLE_FLAGS,
    ENABLE_FLAGS,
};
use crate::spatial::Vec3;
use roxmltree::Node;

/// Flags that change nothing robodyn computes (the solver's warm start and islands, collision
/// acceleration, sensors, energy bookkeeping, MuJoCo's own checks). `multiccd` (one contact per
/// convex pair when disabled), `diagexact` (the exact diagonal in R) and `sleep` (still trees
/// frozen) change MuJoCo's results, and warn.
const FLAGS_WITHOUT_EFFECT: [&str; 10] = [
    "warmstart",
    "midphase",
    "nativeccd",
    "island",
    "sensor",
    "autoreset",
    "refsafe",
    "energy",
    "fwdinv",
    "invdiscrete",
];

/// Flags robodyn follows by changing the model (`gravity`, `equality`, `constraint`), or that
/// the scene's own dynamics (`m.contact_forward_dynamics`, `simulate` with
/// `integrator="mujoco"`) follows as MuJoCo does; robodyn's other integrators have no contacts,
/// soft limits or dry-friction rows to switch off.
const FLAGS_FOLLOWED: [&str; 13] = [
    "gravity",
    "actuation",
    "clampctrl",
    "equality",
    "constraint",
    "contact",
    "limit",
    "frictionloss",
    "filterparent",
    "refsafe",
    "eulerdamp",
    "override",
    "midphase",
];

/// Flags the scene's own dynamics follows and robodyn's other integrators do not: they apply
/// the joints' springs and dampers whatever the file says.
const FLAGS_FOLLOWED_BY_THE_SCENE: [&str; 2] = ["spring", "damper"];

impl<'a> Reader<'a> {
    /// The `<option>` sections among `sections`, in order, into `model.options` and
    /// `model.gravity`; call after the equalities are read.
    pub(super) fn read_options(&self, sections: &[Node<'a, 'a>], model: &mut Model) -> Result<()> {
        let mut options = SimulationOptions::default();
        for option in sections.iter().filter(|c| c.has_tag_name("option")) {
            self.read_option(*option, &mut options, model)?;
            for flag in self.children(*option)? {
                self.read_flags(flag, &mut options)?;
            }
        }
        // what MuJoCo's simulation leaves out when these are disabled
        if !options.flag("gravity") {
            model.gravity = Vec3::zeros();
        }
        if !options.flag("equality") || !options.flag("constraint") {
            model.constraints.iter_mut().for_each(|c| c.active = false);
        }
        let set = || options.disabled.iter().chain(&options.enabled);
        let named = |flags: Vec<&String>| -> Vec<String> {
            flags.iter().map(|f| format!("'{f}'")).collect()
        };
        let unfollowed = named(
            set()
                .filter(|f| !FLAGS_WITHOUT_EFFECT.contains(&f.as_str()))
                .filter(|f| !FLAGS_FOLLOWED.contains(&f.as_str()))
                .filter(|f| !FLAGS_FOLLOWED_BY_THE_SCENE.contains(&f.as_str()))
                .collect(),
        );
        let scene_only = named(
            set()
                .filter(|f| FLAGS_FOLLOWED_BY_THE_SCENE.contains(&f.as_str()))
                .collect(),
        );
        if let Some(option) = sections.iter().find(|c| c.has_tag_name("option")) {
            if !unfollowed.is_empty() {
                model.warnings.push(format!(
                    "{}: <flag> {} not followed (robodyn's simulation does not change with it)",
                    self.location(*option),
                    unfollowed.join(", ")
                ));
            }
            if !scene_only.is_empty() {
                model.warnings.push(format!(
                    "{}: <flag> {} followed by the scene's own dynamics (integrator='mujoco', \
                     m.contact_forward_dynamics) only: robodyn's other integrators apply the \
                     joints' springs and dampers",
                    self.location(*option),
                    scene_only.join(", ")
                ));
            }
        }
        model.options = options;
        self.warn_disabled_actuator_groups(sections, model)
    }

    /// `<option actuatorgroupdisable>`: MuJoCo switches off the actuators of those groups
    /// (`group`, 0–30); robodyn does not, and names them in a warning.
    fn warn_disabled_actuator_groups(
        &self,
        sections: &[Node<'a, 'a>],
        model: &mut Model,
    ) -> Result<()> {
        let mut disabled: Vec<i64> = Vec::new();
        for option in sections.iter().filter(|c| c.has_tag_name("option")) {
            if let Some(text) = option.attribute("actuatorgroupdisable") {
                disabled = parse_number_list(text, "actuatorgroupdisable")
                    .map_err(|m| self.error(*option, m))?
                    .iter()
                    .map(|g| *g as i64)
                    .collect();
            }
        }
        let mut named = Vec::new();
        for section in sections.iter().filter(|c| c.has_tag_name("actuator")) {
            for (element, actuator) in self.children(*section)?.into_iter().zip(&model.actuators) {
                let group = self.integer(element, "main", "group", 0)?;
                if (0..=30).contains(&group) && disabled.contains(&group) {
                    named.push(format!("'{}'", actuator.name));
                }
            }
        }
        if !named.is_empty() {
            model.warnings.push(format!(
                "actuatorgroupdisable: MuJoCo switches off actuators {} (their groups are \
                 disabled); robodyn does not follow it and drives them",
                named.join(", ")
            ));
        }
        Ok(())
    }

    /// One `<option>`'s attributes.
    fn read_option(
        &self,
        option: Node<'a, 'a>,
        options: &mut SimulationOptions,
        model: &mut Model,
    ) -> Result<()> {
        let number = |name: &str| self.own_number(option, name);
        let count = |name: &str| -> Result<Option<usize>> {
            option
                .attribute(name)
                .map(|text| {
                    text.trim().parse::<usize>().map_err(|_| {
                        self.error(
                            option,
                            format!(
                                "attribute '{name}': expected a non-negative integer, got '{text}'"
                            ),
                        )
                    })
                })
                .transpose()
        };
        let keyword = |name: &str, words: &[&str]| -> Result<Option<usize>> {
            let Some(text) = option.attribute(name) else {
                return Ok(None);
            };
            words
                .iter()
                .position(|w| *w == text)
                .map(Some)
                .ok_or_else(|| {
                    let expected = words.join(", ");
                    self.error(
                        option,
                        format!("attribute '{name}': expected one of {expected}, got '{text}'"),
                    )
                })
        };
        if let Some(timestep) = number("timestep")? {
            if timestep <= 0.0 {
                let message = format!(
                    "attribute 'timestep': expected a positive time step (s), got {timestep}"
                );
                return Err(self.error(option, message));
            }
            options.timestep = timestep;
        }
        if let Some(k) = keyword("integrator", &Integrator::KEYWORDS)? {
            options.integrator =
                Integrator::from_keyword(Integrator::KEYWORDS[k]).expect("a keyword of the list");
        }
        if let Some(k) = keyword("cone", &["pyramidal", "elliptic"])? {
            options.cone = [FrictionCone::Pyramidal, FrictionCone::Elliptic][k];
        }
        if let Some(k) = keyword("solver", &["PGS", "CG", "Newton"])? {
            options.solver = [
                ConstraintSolver::Pgs,
                ConstraintSolver::Cg,
                ConstraintSolver::Newton,
            ][k];
        }
        options.impratio = number("impratio")?.unwrap_or(options.impratio);
        options.tolerance = number("tolerance")?.unwrap_or(options.tolerance);
        options.ls_tolerance = number("ls_tolerance")?.unwrap_or(options.ls_tolerance);
        options.noslip_tolerance = number("noslip_tolerance")?.unwrap_or(options.noslip_tolerance);
        options.iterations = count("iterations")?.unwrap_or(options.iterations);
        options.ls_iterations = count("ls_iterations")?.unwrap_or(options.ls_iterations);
        options.noslip_iterations =
            count("noslip_iterations")?.unwrap_or(options.noslip_iterations);
        options.override_margin = number("o_margin")?.unwrap_or(options.override_margin);
        let solver = &mut options.override_solver;
        solver.solref =
            self.leading_numbers(option, "main", "option", "o_solref", solver.solref)?;
        solver.solimp =
            self.leading_numbers(option, "main", "option", "o_solimp", solver.solimp)?;
        options.override_friction = self.leading_numbers(
            option,
            "main",
            "option",
            "o_friction",
            options.override_friction,
        )?;
        if let Some(text) = option.attribute("gravity") {
            let gravity = parse_numbers::<3>(text, "gravity").map_err(|m| self.error(option, m))?;
            model.gravity = Vec3::from(gravity);
        }
        // fluid forces are not modelled
        for name in ["density", "viscosity"] {
            if number(name)?.is_some_and(|x| x != 0.0) {
                model.warnings.push(format!(
                    "{}: attribute '{name}' not read (robodyn models no fluid forces)",
                    self.location(option)
                ));
            }
        }
        if let Some(text) = option.attribute("wind") {
            let wind = parse_numbers::<3>(text, "wind").map_err(|m| self.error(option, m))?;
            if wind != [0.0; 3] {
                model.warnings.push(format!(
                    "{}: attribute 'wind' not read (robodyn models no fluid forces)",
                    self.location(option)
                ));
            }
        }
        Ok(())
    }

    /// A `<flag>`'s attributes, each `enable` or `disable`.
    fn read_flags(&self, flag: Node<'a, 'a>, options: &mut SimulationOptions) -> Result<()> {
        for attribute in flag.attributes() {
            let (name, value) = (attribute.name(), attribute.value());
            let on = match value {
                "enable" => true,
                "disable" => false,
                other => {
                    let message =
                        format!("attribute '{name}': expected enable or disable, got '{other}'");
                    return Err(self.error(flag, message));
                }
            };
            // a disable bit is listed when off, an enable bit when on
            let (list, listed) = if DISABLE_FLAGS.contains(&name) {
                (&mut options.disabled, !on)
            } else if ENABLE_FLAGS.contains(&name) {
                (&mut options.enabled, on)
            } else {
                return Err(self.error(flag, format!("unknown flag '{name}'")));
            };
            list.retain(|f| f != name);
            if listed {
                list.push(name.to_string());
            }
        }
        Ok(())
    }
}
