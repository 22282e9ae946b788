//! `<actuator>`: each element an [`Actuator`], in the file's order (the controls' order).
//!
//! Modelled, as MuJoCo compiles them: `motor`, `position` (`kp`, `kv` or `dampratio`,
//! `inheritrange`, `timeconst`: a filterexact activation), `intvelocity` (an integrator
//! activation, `inheritrange` its `actrange`), `velocity` (`kv`), `damper` (`kv`, a gain −kv l̇ on
//! a control in its non-negative `ctrlrange`), `cylinder` (`timeconst`, `area` or `diameter`,
//! `bias`: a filter activation) and `general` with `dyntype` none, integrator, filter or
//! filterexact (`dynprm`) and a fixed or affine gain and bias (`gainprm`, `biasprm`,
//! `inheritrange`), with `actrange`/`actlimited` and `actearly`; on a hinge or slide (`joint`) or
//! a tendon (`tendon`: fixed, or spatial through sites and pulleys), `gear`'s first entry its
//! moment arm, with `ctrlrange` and `forcerange` (`ctrllimited`, `forcelimited`: "auto" limits
//! where a range is given); an
//! actuator's `damping` and `armature` join its joint's or its tendon's, times gear² (as MuJoCo
//! adds them). A
//! damping ratio becomes kv as MuJoCo's compiler makes it, from the inertia the transmission
//! sees at qpos0.
//!
//! Any other actuator (muscles, user dynamics, site or body transmissions, a ball or free joint) keeps its place in the controls (and its activation, if
//! it has one) but exerts no force, with a warning naming it. Defaults: a class has one actuator default, whichever
//! element wrote it; what a shortcut inherits from it is in [`super::actuator_defaults`].

use super::actuator_defaults::RawActuator;
use super::Reader;
use crate::error::Result;
use crate::io::xml::parse_number_list;
use crate::model::{ActivationDynamics, Actuator, Model, PathPoint};
use crate::soft::inertia::inverse_inertia;
use crate::soft::tendons::TendonKinematics;
use crate::soft::TINY;
use crate::Data;
use nalgebra::DVector;
use roxmltree::Node;

/// What robodyn models, for the warning about an actuator it does not.
const MODELLED: &str = "robodyn models motor, position, intvelocity, velocity, damper, cylinder \
                        and general actuators (dyntype none, integrator, filter, filterexact) on a \
                        hinge, a slide or a tendon";

impl<'a> Reader<'a> {
    /// The elements of the `<actuator>` sections among `sections`, in order, into
    /// `model.actuators` (after the tree is built: a transmission names a joint).
    pub(super) fn read_actuators(
        &self,
        sections: &[Node<'a, 'a>],
        model: &mut Model,
    ) -> Result<()> {
        let mut elements = Vec::new();
        for section in sections.iter().filter(|c| c.has_tag_name("actuator")) {
            for element in self.children(*section)? {
                let index = model.actuators.len();
                elements.push(element);
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
        self.resolve_damping_ratios(&elements, model)
    }

    /// A position-like actuator (gain kp, bias −kp l + r l̇) with r > 0 holds a damping ratio
    /// (`dampratio`), which MuJoCo's compiler turns into kv = 2 r √(kp m): m = 1 / (g M⁻¹ gᵀ) is
    /// the inertia the transmission reflects at qpos0 (g its moment arms, the row of ∂l/∂q̇; M the
    /// mass matrix with every armature, those of actuators and tendons too). Measured against
    /// MuJoCo 4.0.0.
    fn resolve_damping_ratios(&self, elements: &[Node<'a, 'a>], model: &mut Model) -> Result<()> {
        let has_ratio = |a: &Actuator| {
            (a.coordinate.is_some() || a.tendon.is_some())
                && a.gain[0] == -a.bias[1]
                && a.bias[2] > 0.0
        };
        if !model.actuators.iter().any(has_ratio) {
            return Ok(());
        }
        let mut data = Data::new(model);
        let q = model.neutral_configuration.clone();
        let inverse = inverse_inertia(model, &mut data, q.as_slice())?;
        let tendons = TendonKinematics::at(model, &mut data, q.as_slice())?;
        let mut moment = DVector::zeros(model.nv);
        for (k, element) in elements.iter().enumerate() {
            let actuator = &model.actuators[k];
            if !has_ratio(actuator) {
                continue;
            }
            // the moment arms g
            moment.fill(0.0);
            for (c, arm) in model.actuator_arms(actuator, &tendons) {
                moment[c] += arm;
            }
            // m = 1 / (g M⁻¹ gᵀ)
            let inertia = 1.0 / moment.dot(&(&inverse * &moment)).max(TINY);
            let kp = actuator.gain[0];
            if kp < 0.0 {
                let message = format!("attribute 'dampratio': needs kp ≥ 0, got kp = {kp}");
                return Err(self.error(*element, message));
            }
            let ratio = actuator.bias[2];
            model.actuators[k].bias[2] = -2.0 * ratio * (kp * inertia).sqrt();
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
        let class = self.declared_class(element, "class", "main")?;
        let mut actuator = Actuator {
            name: element
                .attribute("name")
                .map_or_else(|| format!("actuator{index}"), str::to_string),
            coordinate: None,
            position: 0,
            tendon: None,
            gear: self.transmission_term(element, "gear")?.unwrap_or(1.0),
            gain: [1.0, 0.0, 0.0],
            bias: [0.0; 3],
            ctrl_range: self.range(element, "ctrl")?,
            force_range: self.range(element, "force")?,
            dynamics: ActivationDynamics::None,
            act_range: self.range(element, "act")?,
            act_early: false,
        };
        let unmodelled = |actuator: Actuator, why: String| Ok(Err((actuator, why)));

        // the kinds robodyn does not model keep their activations' places
        let own = |name: &str| self.numbers::<1>(element, "main", name);
        match tag {
            "general" | "motor" | "position" | "intvelocity" | "velocity" | "damper"
            | "cylinder" => {
                // a delay reads the control from a history of `nsample` samples
                let delay = self
                    .numbers::<1>(element, class, "delay")?
                    .map_or(0.0, |[d]| d);
                let samples = self
                    .numbers::<1>(element, class, "nsample")?
                    .map_or(0.0, |[n]| n);
                if delay > 0.0 && samples <= 0.0 {
                    let message = format!(
                        "attribute 'delay': {delay} s needs a history buffer ('nsample' > 0), as \
                         MuJoCo requires"
                    );
                    return Err(self.error(element, message));
                }
                self.warn_unmodelled(element, class);
            }
            "muscle" => {
                actuator.dynamics = ActivationDynamics::Held { states: 1 };
                return unmodelled(actuator, "<muscle>".into());
            }
            "pid" => {
                // an integral state with `ki`, a slew state with `slewmax`
                let mut states = 0;
                for name in ["ki", "slewmax"] {
                    states += usize::from(own(name)?.is_some_and(|[x]| x != 0.0));
                }
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

        // the gain, bias and activation dynamics MuJoCo compiles the element to
        let raw = self.element_raw_actuator(element, class)?;
        let time_constant = raw.dynamics[0];
        actuator.dynamics = match raw.dyn_type.as_str() {
            "none" => ActivationDynamics::None,
            "integrator" => ActivationDynamics::Integrator,
            "filter" => ActivationDynamics::Filter { time_constant },
            "filterexact" => ActivationDynamics::FilterExact { time_constant },
            other => {
                // its activation keeps its place among the activations
                let states = raw.act_dim.map_or(1, |n| n.max(0.0) as usize);
                actuator.dynamics = ActivationDynamics::Held { states };
                return unmodelled(actuator, format!("dyntype '{other}'"));
            }
        };
        let [a, b] = [&raw.gain, &raw.bias].map(|p| [p[0], p[1], p[2]]);
        actuator.gain = match raw.gain_type.as_str() {
            "fixed" => [a[0], 0.0, 0.0],
            "affine" => a,
            other => return unmodelled(actuator, format!("gaintype '{other}'")),
        };
        actuator.bias = match raw.bias_type.as_str() {
            "none" => [0.0; 3],
            "affine" => b,
            other => return unmodelled(actuator, format!("biastype '{other}'")),
        };
        actuator.act_early = raw.act_early;
        self.check_activation_size(element, &actuator, raw.act_dim)?;
        if actuator.act_range.is_some() && !actuator.has_activation() {
            let message = "attribute 'actrange': an actuator without activation dynamics has no \
                           activation to limit";
            return Err(self.error(element, message));
        }
        if tag == "damper" {
            // f = −k_v l̇ u, u limited (whatever ctrllimited says) to a non-negative range
            match self.numbers::<2>(element, "main", "ctrlrange")? {
                Some([low, high]) if 0.0 <= low && low < high => {
                    actuator.ctrl_range = Some((low, high));
                }
                _ => {
                    let message = "attribute 'ctrlrange': a damper needs a range 0 ≤ lower < upper";
                    return Err(self.error(element, message));
                }
            }
        }

        // the transmission: a tendon, or a hinge or slide
        let range = if let Some(tendon_name) = element.attribute("tendon") {
            let Some(t) = model.tendons.iter().position(|t| t.name == tendon_name) else {
                let message = format!("attribute 'tendon': no tendon named '{tendon_name}'");
                return Err(self.error(element, message));
            };
            actuator.tendon = Some(t);
            model.tendons[t].range.map(|(lower, upper)| [lower, upper])
        } else {
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
            (lower.is_finite() && upper.is_finite()).then_some([lower, upper])
        };
        self.inherit_range(element, &raw, range, &mut actuator)?;
        Ok(Ok(actuator))
    }

    /// `inheritrange` (MuJoCo's compiler rule): on a position-like actuator (a fixed gain kp
    /// with an affine bias −kp l), the transmission's `range` scaled about its middle becomes
    /// the control's range (no dynamics or filterexact: a position servo) or the activation's
    /// (an integrator: `intvelocity`), over any range given (a shortcut's own range has already
    /// cleared an inherited `inheritrange`, [`super::actuator_defaults`]).
    fn inherit_range(
        &self,
        element: Node<'a, 'a>,
        raw: &RawActuator,
        range: Option<[f64; 2]>,
        actuator: &mut Actuator,
    ) -> Result<()> {
        let integrated = actuator.dynamics == ActivationDynamics::Integrator;
        let limited = if integrated {
            "actlimited"
        } else {
            "ctrllimited"
        };
        let inherit = raw.inherit_range;
        let position_like =
            raw.gain_type == "fixed" && raw.bias_type == "affine" && raw.gain[0] == -raw.bias[1];
        if inherit <= 0.0 || !position_like {
            return Ok(());
        }
        if !matches!(
            actuator.dynamics,
            ActivationDynamics::None
                | ActivationDynamics::FilterExact { .. }
                | ActivationDynamics::Integrator
        ) {
            let message = "attribute 'inheritrange': only for position and intvelocity actuators \
                           (dyntype none, filterexact or integrator)";
            return Err(self.error(element, message));
        }
        let Some([lower, upper]) = range else {
            let message = "attribute 'inheritrange': the transmission has no range to inherit";
            return Err(self.error(element, message));
        };
        if self.attribute(element, "main", limited).as_deref() == Some("false") {
            return Ok(());
        }
        let (middle, half) = ((lower + upper) / 2.0, inherit * (upper - lower) / 2.0);
        let inherited = Some((middle - half, middle + half));
        if integrated {
            actuator.act_range = inherited;
        } else {
            actuator.ctrl_range = inherited;
        }
        Ok(())
    }

    /// `actdim`: 1 for an actuator with activation dynamics, 0 without (MuJoCo refuses others).
    fn check_activation_size(
        &self,
        element: Node<'a, 'a>,
        actuator: &Actuator,
        given: Option<f64>,
    ) -> Result<()> {
        let expected = usize::from(actuator.has_activation());
        match given {
            Some(given) if given != expected as f64 => {
                let message = format!(
                    "attribute 'actdim': expected {expected} for dyntype {}, got {given}",
                    actuator.dynamics.keyword()
                );
                Err(self.error(element, message))
            }
            _ => Ok(()),
        }
    }

    /// The actuator's own `damping` and `armature` (MuJoCo ≥ 3.5), which MuJoCo adds to its
    /// joint's (or its tendon's), scaled by gear²: a passive damper −g² b q̇ and a rotor
    /// inertia g² I_a (on a tendon: its inertia, [`crate::soft::inertia`]). A polynomial
    /// damping's terms past the linear one (MuJoCo's `actuator_dampingpoly`) join the tendon's
    /// or the joint's, times g² (as MuJoCo 4.0 applies them).
    fn add_transmission_terms(
        &self,
        element: Node<'a, 'a>,
        actuator: &Actuator,
        model: &mut Model,
    ) -> Result<()> {
        let scale = actuator.gear * actuator.gear;
        // damping b (not negative) and its higher terms [b₁, b₂]
        let text = self.attribute(element, "main", "damping");
        let (damping, higher) = self.spring_polynomial(element, "damping", text.as_deref())?;
        if damping < 0.0 {
            let message = format!("attribute 'damping': expected a value ≥ 0, got {damping}");
            return Err(self.error(element, message));
        }
        if let Some(t) = actuator.tendon {
            let tendon = &mut model.tendons[t];
            tendon.damping += scale * damping;
            for (term, value) in tendon.damping_poly.iter_mut().zip(higher) {
                *term += scale * value;
            }
            let armature = self.non_negative_term(element, "armature")?;
            // MuJoCo's J̇ does not follow a path around a geom (its first step fails)
            let wraps = tendon
                .path
                .iter()
                .any(|p| matches!(p, PathPoint::Geom { .. }));
            if wraps && armature > 0.0 {
                let message = format!(
                    "attribute 'armature': tendon '{}' wraps around a geom, and has none",
                    tendon.name
                );
                return Err(self.error(element, message));
            }
            tendon.armature += scale * armature;
            return Ok(());
        }
        let Some(c) = actuator.coordinate else {
            return Ok(());
        };
        model.damping[c] += scale * damping;
        for (term, value) in model.damping_poly[c].iter_mut().zip(higher) {
            *term += scale * value;
        }
        model.armature[c] += scale * self.non_negative_term(element, "armature")?;
        Ok(())
    }

    /// The first number of an actuator's `gear`, `damping` or `armature`, where given.
    fn transmission_term(&self, element: Node<'a, 'a>, name: &str) -> Result<Option<f64>> {
        let Some(text) = self.attribute(element, "main", name) else {
            return Ok(None);
        };
        let values = parse_number_list(&text, name).map_err(|m| self.error(element, m))?;
        Ok(values.first().copied())
    }

    /// An actuator's `damping` or `armature` (0 when not given), refused when negative.
    fn non_negative_term(&self, element: Node<'a, 'a>, name: &str) -> Result<f64> {
        let value = self.transmission_term(element, name)?.unwrap_or(0.0);
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
        let flag = self.attribute(element, "main", &limited);
        self.check_auto_limits(element, values.is_some(), flag.as_deref(), &limited)?;
        let limited = match flag.as_deref() {
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
