//! `<actuator>`: each element an [`Actuator`], in the file's order (the controls' order).
//!
//! Modelled, as MuJoCo compiles them: `motor`, `position` (`kp`, `kv`, `inheritrange`,
//! `timeconst`: a filterexact activation), `intvelocity` (an integrator activation, `inheritrange`
//! its `actrange`), `velocity` (`kv`), `damper` (`kv`, a gain −kv l̇ on a control in its
//! non-negative `ctrlrange`), `cylinder` (`timeconst`, `area` or `diameter`, `bias`: a filter
//! activation) and `general` with `dyntype` none, integrator, filter or filterexact (`dynprm`)
//! and a fixed or affine gain and bias (`gainprm`, `biasprm`), with `actrange`/`actlimited` and
//! `actearly`; on a hinge or slide (`joint`) or a fixed tendon (`tendon`), `gear`'s first entry
//! its moment arm, with `ctrlrange`
//! and `forcerange` (`ctrllimited`, `forcelimited`: "auto" limits where a range is given); an
//! actuator's `damping` and `armature` join its joint's, times gear² (as MuJoCo adds them).
//! Any other actuator (muscles, user dynamics, `dampratio`, spatial tendon, site or body
//! transmissions, a ball or free joint) keeps its place in the controls (and its activation,
//! if it has one) but exerts no force, with a warning naming it. Defaults come from the
//! element's class, per element name.

use super::Reader;
use crate::error::Result;
use crate::io::xml::parse_number_list;
use crate::model::{ActivationDynamics, Actuator, Model};
use roxmltree::Node;

/// What robodyn models, for the warning about an actuator it does not.
const MODELLED: &str = "robodyn models motor, position, intvelocity, velocity, damper, cylinder \
                        and general actuators (dyntype none, integrator, filter, filterexact) on a \
                        hinge, a slide or a fixed tendon";

impl<'a> Reader<'a> {
    /// The elements of the `<actuator>` sections among `sections`, in order, into
    /// `model.actuators` (after the tree is built: a transmission names a joint).
    pub(super) fn read_actuators(
        &self,
        sections: &[Node<'a, 'a>],
        model: &mut Model,
    ) -> Result<()> {
        for section in sections.iter().filter(|c| c.has_tag_name("actuator")) {
            for element in self.children(*section)? {
                let index = model.actuators.len();
                let actuator = match self.actuator(element, model, index)? {
                    Ok(actuator) => {
                        self.add_transmission_terms(element, &actuator, model)?;
                        actuator
                    }
                    Err((actuator, why)) => {
                        model.warnings.push(format!(
                            "{}: not read ({why}; {MODELLED}): it keeps its place in the \
                             controls and exerts no force",
                            self.location(element)
                        ));
                        actuator
                    }
                };
                model.actuators.push(actuator);
            }
        }
        Ok(())
    }

    /// One actuator element: `Ok` the modelled actuator, or `Ok(Err)` one that exerts no force
    /// and why; `Err` for a value MuJoCo refuses.
    #[allow(clippy::type_complexity)]
    fn actuator(
        &self,
        element: Node<'a, 'a>,
        model: &Model,
        index: usize,
    ) -> Result<std::result::Result<Actuator, (Actuator, String)>> {
        let tag = element.tag_name().name();
        let text = |name: &str| self.attribute(element, "main", name);
        let list = |name: &str| -> Result<Option<Vec<f64>>> {
            text(name)
                .map(|t| parse_number_list(&t, name).map_err(|m| self.error(element, m)))
                .transpose()
        };
        let scalar = |name: &str, default: f64| -> Result<f64> {
            Ok(list(name)?
                .and_then(|v| v.first().copied())
                .unwrap_or(default))
        };
        let mut actuator = Actuator {
            name: element
                .attribute("name")
                .map_or_else(|| format!("actuator{index}"), str::to_string),
            coordinate: None,
            position: 0,
            tendon: None,
            gear: scalar("gear", 1.0)?,
            gain: [1.0, 0.0, 0.0],
            bias: [0.0; 3],
            ctrl_range: self.range(element, "ctrl")?,
            force_range: self.range(element, "force")?,
            dynamics: ActivationDynamics::None,
            act_range: self.range(element, "act")?,
            act_early: self.flag(element, "main", "actearly")?,
        };
        let unmodelled = |actuator: Actuator, why: String| Ok(Err((actuator, why)));

        // the gain, bias and activation dynamics of each kind
        let non_negative = |name: &str, default: f64| -> Result<f64> {
            let value = scalar(name, default)?;
            if value < 0.0 {
                let message = format!("attribute '{name}': expected a value ≥ 0, got {value}");
                return Err(self.error(element, message));
            }
            Ok(value)
        };
        let mut unmodelled_why = None;
        match tag {
            "motor" => {}
            "position" | "intvelocity" => {
                if scalar("dampratio", 0.0)? != 0.0 {
                    unmodelled_why = Some("attribute 'dampratio'".to_string());
                }
                let (kp, kv) = (scalar("kp", 1.0)?, non_negative("kv", 0.0)?);
                actuator.gain = [kp, 0.0, 0.0];
                actuator.bias = [0.0, -kp, -kv];
                let time_constant = non_negative("timeconst", 0.0)?;
                if time_constant > 0.0 {
                    actuator.dynamics = ActivationDynamics::FilterExact { time_constant };
                }
                if tag == "intvelocity" {
                    actuator.dynamics = ActivationDynamics::Integrator;
                }
            }
            "velocity" => {
                let kv = scalar("kv", 1.0)?;
                actuator.gain = [kv, 0.0, 0.0];
                actuator.bias = [0.0, 0.0, -kv];
            }
            "damper" => {
                // f = −k_v l̇ u, u in a non-negative range
                actuator.gain = [0.0, 0.0, -non_negative("kv", 0.0)?];
                match self.numbers::<2>(element, "main", "ctrlrange")? {
                    Some([low, high]) if 0.0 <= low && low < high => {
                        actuator.ctrl_range = Some((low, high));
                    }
                    _ => {
                        let message = "attribute 'ctrlrange': a damper needs a range \
                                       0 ≤ lower < upper";
                        return Err(self.error(element, message));
                    }
                }
            }
            "cylinder" => {
                // f = area u_act + b₀ + b₁ l + b₂ l̇
                let time_constant = scalar("timeconst", 1.0)?;
                actuator.dynamics = ActivationDynamics::Filter { time_constant };
                let area = match scalar("diameter", -1.0)? {
                    d if d >= 0.0 => std::f64::consts::PI / 4.0 * d * d,
                    _ => scalar("area", 1.0)?,
                };
                actuator.gain = [area, 0.0, 0.0];
                actuator.bias = [0.0; 3];
                for (value, given) in actuator
                    .bias
                    .iter_mut()
                    .zip(list("bias")?.unwrap_or_default())
                {
                    *value = given;
                }
            }
            "general" => {
                let kinds = ["dyntype", "gaintype", "biastype"].map(text);
                let [dynamics, gain, bias] = kinds.each_ref().map(|k| k.as_deref());
                let time_constant = scalar("dynprm", 1.0)?;
                match dynamics {
                    None | Some("none") => {}
                    Some("integrator") => actuator.dynamics = ActivationDynamics::Integrator,
                    Some("filter") => {
                        actuator.dynamics = ActivationDynamics::Filter { time_constant }
                    }
                    Some("filterexact") => {
                        actuator.dynamics = ActivationDynamics::FilterExact { time_constant }
                    }
                    Some(other) => {
                        // its activation keeps its place among the activations
                        let states = self.numbers::<1>(element, "main", "actdim")?;
                        let states = states.map_or(1, |[n]| n.max(0.0) as usize);
                        actuator.dynamics = ActivationDynamics::Held { states };
                        return unmodelled(actuator, format!("dyntype '{other}'"));
                    }
                }
                let prm = |name: &str, default: [f64; 3]| -> Result<[f64; 3]> {
                    let mut values = default;
                    for (value, given) in values.iter_mut().zip(list(name)?.unwrap_or_default()) {
                        *value = given;
                    }
                    Ok(values)
                };
                actuator.gain = match gain {
                    None | Some("fixed") => [prm("gainprm", [1.0, 0.0, 0.0])?[0], 0.0, 0.0],
                    Some("affine") => prm("gainprm", [1.0, 0.0, 0.0])?,
                    Some(other) => return unmodelled(actuator, format!("gaintype '{other}'")),
                };
                actuator.bias = match bias {
                    None | Some("none") => [0.0; 3],
                    Some("affine") => prm("biasprm", [0.0; 3])?,
                    Some(other) => return unmodelled(actuator, format!("biastype '{other}'")),
                };
            }
            "muscle" => {
                // its activation keeps its place among the activations
                actuator.dynamics = ActivationDynamics::Held { states: 1 };
                return unmodelled(actuator, "<muscle>".into());
            }
            "pid" => {
                // an integral state with `ki`, a slew state with `slewmax`
                let states = ["ki", "slewmax"]
                    .iter()
                    .map(|name| scalar(name, 0.0).map(|x| usize::from(x != 0.0)))
                    .sum::<Result<usize>>()?;
                if states > 0 {
                    actuator.dynamics = ActivationDynamics::Held { states };
                }
                return unmodelled(actuator, "<pid>".into());
            }
            "dcmotor" | "plugin" => {
                let why =
                    format!("<{tag}>; its activation states, if any, are not in robodyn's act");
                return unmodelled(actuator, why);
            }
            other => return unmodelled(actuator, format!("<{other}>")),
        }
        self.check_activation_size(element, &actuator)?;
        if let Some(why) = unmodelled_why {
            return unmodelled(actuator, why);
        }

        // the transmission: a fixed tendon, or a hinge or slide
        if let Some(tendon_name) = element.attribute("tendon") {
            let Some(t) = model.tendons.iter().position(|t| t.name == tendon_name) else {
                if self
                    .unread_tendons
                    .borrow()
                    .iter()
                    .any(|n| n == tendon_name)
                {
                    return unmodelled(actuator, format!("spatial tendon '{tendon_name}'"));
                }
                let message = format!("attribute 'tendon': no tendon named '{tendon_name}'");
                return Err(self.error(element, message));
            };
            actuator.tendon = Some(t);
            let range = model.tendons[t].range.map(|(lower, upper)| [lower, upper]);
            self.inherit_range(element, range, &mut actuator)?;
            return Ok(Ok(actuator));
        }
        let Some(joint_name) = element.attribute("joint") else {
            return unmodelled(
                actuator,
                "a transmission other than 'joint' or 'tendon'".into(),
            );
        };
        let body = model.joint_names.iter().position(|n| n == joint_name);
        let body = body.ok_or_else(|| {
            self.error(
                element,
                format!("attribute 'joint': no joint named '{joint_name}'"),
            )
        })?;
        if model.joints()[body].nv() != 1 {
            let kind = model.joints()[body].kind();
            return unmodelled(actuator, format!("a {kind} joint's transmission"));
        }
        actuator.coordinate = Some(model.v_range(body).start);
        actuator.position = model.q_range(body).start;

        let (lower, upper) = (
            model.lower_position_limit[actuator.position],
            model.upper_position_limit[actuator.position],
        );
        let range = (lower.is_finite() && upper.is_finite()).then_some([lower, upper]);
        self.inherit_range(element, range, &mut actuator)?;
        Ok(Ok(actuator))
    }

    /// `inheritrange` of a `position` (its control range) or an `intvelocity` (its activation
    /// range): the transmission's `range` scaled about its middle.
    fn inherit_range(
        &self,
        element: Node<'a, 'a>,
        range: Option<[f64; 2]>,
        actuator: &mut Actuator,
    ) -> Result<()> {
        let inherit = self
            .numbers::<1>(element, "main", "inheritrange")?
            .map_or(0.0, |[x]| x);
        if inherit <= 0.0 {
            return Ok(());
        }
        let inherited = Some(self.inherited_range(element, range, inherit)?);
        match element.tag_name().name() {
            "position" => actuator.ctrl_range = inherited,
            "intvelocity" => actuator.act_range = inherited,
            _ => {}
        }
        Ok(())
    }

    /// `actdim`: 1 for an actuator with activation dynamics, 0 without (MuJoCo refuses others).
    fn check_activation_size(&self, element: Node<'a, 'a>, actuator: &Actuator) -> Result<()> {
        let expected = usize::from(actuator.has_activation());
        match self.numbers::<1>(element, "main", "actdim")? {
            Some([given]) if given != expected as f64 => {
                let message = format!(
                    "attribute 'actdim': expected {expected} for dyntype {}, got {given}",
                    actuator.dynamics.keyword()
                );
                Err(self.error(element, message))
            }
            _ => Ok(()),
        }
    }

    /// `inheritrange`: the range of the joint or tendon (`None`: it has none, refused) scaled by
    /// `inherit` about its middle.
    fn inherited_range(
        &self,
        element: Node<'a, 'a>,
        range: Option<[f64; 2]>,
        inherit: f64,
    ) -> Result<(f64, f64)> {
        let Some([lower, upper]) = range else {
            let message = "attribute 'inheritrange': the transmission has no range to inherit";
            return Err(self.error(element, message));
        };
        let (middle, half) = ((lower + upper) / 2.0, inherit * (upper - lower) / 2.0);
        Ok((middle - half, middle + half))
    }

    /// The actuator's own `damping` and `armature` (MuJoCo ≥ 3.5), which MuJoCo adds to its
    /// joint's (or its tendon's), scaled by gear²: a passive damper −g² b q̇ and a rotor
    /// inertia g² I_a. A tendon's armature is not modelled (a warning).
    fn add_transmission_terms(
        &self,
        element: Node<'a, 'a>,
        actuator: &Actuator,
        model: &mut Model,
    ) -> Result<()> {
        let scale = actuator.gear * actuator.gear;
        if let Some(t) = actuator.tendon {
            let damping = self.transmission_term(element, "damping")?;
            model.tendons[t].damping += scale * damping;
            if self.transmission_term(element, "armature")? != 0.0 {
                model.warnings.push(format!(
                    "{}: 'armature' on a tendon not modelled (the tendon's inertia JᵀJ)",
                    self.location(element)
                ));
            }
            return Ok(());
        }
        let Some(c) = actuator.coordinate else {
            return Ok(());
        };
        for (name, values) in [
            ("damping", &mut model.damping),
            ("armature", &mut model.armature),
        ] {
            values[c] += scale * self.transmission_term(element, name)?;
        }
        Ok(())
    }

    /// An actuator's `damping` or `armature` (its first value; 0 when not given), refused when
    /// negative.
    fn transmission_term(&self, element: Node<'a, 'a>, name: &str) -> Result<f64> {
        let Some(text) = self.attribute(element, "main", name) else {
            return Ok(0.0);
        };
        let value = parse_number_list(&text, name)
            .map_err(|m| self.error(element, m))?
            .first()
            .copied()
            .unwrap_or(0.0);
        if value < 0.0 {
            let message = format!("attribute '{name}': expected a value ≥ 0, got {value}");
            return Err(self.error(element, message));
        }
        Ok(value)
    }

    /// `<name>range` where `<name>limited` limits it ("auto": where the range is given); a
    /// limited range whose lower end is not below its upper end is refused, as in MuJoCo.
    fn range(&self, element: Node<'a, 'a>, name: &str) -> Result<Option<(f64, f64)>> {
        let (range, limited) = (format!("{name}range"), format!("{name}limited"));
        let values = self.numbers::<2>(element, "main", &range)?;
        let limited = match self.attribute(element, "main", &limited).as_deref() {
            None | Some("auto") => values.is_some(),
            Some("true") => true,
            Some("false") => false,
            Some(other) => {
                let message =
                    format!("attribute '{limited}': expected true, false or auto, got '{other}'");
                return Err(self.error(element, message));
            }
        };
        match (limited, values) {
            (false, _) => Ok(None),
            (true, Some([lower, upper])) if lower < upper => Ok(Some((lower, upper))),
            (true, _) => {
                let message = format!("attribute '{range}': a limited range needs lower < upper");
                Err(self.error(element, message))
            }
        }
    }
}
