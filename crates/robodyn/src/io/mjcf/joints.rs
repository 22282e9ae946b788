//! A joint's properties beyond its kind and frame, as MuJoCo's compiler reads them: its soft
//! limit and dry friction, the range its actuator forces are clamped to, `springdamper`,
//! `springyield`, and MuJoCo's rules for ranges (`limited`, `<compiler autolimits>`) and for aligned free bodies.

use super::Reader;
use crate::error::Result;
use crate::joint::Joint;
use crate::model::{JointSoftness, Model, SolverParameters};
use roxmltree::Node;

impl<'a> Reader<'a> {
    /// A joint's `springdamper` (time constant, damping ratio) where given and not "0 0"; both
    /// must then be positive, as MuJoCo requires.
    pub(super) fn spring_damper(
        &self,
        joint: Node<'a, 'a>,
        class: &str,
    ) -> Result<Option<[f64; 2]>> {
        match self.numbers::<2>(joint, class, "springdamper")? {
            None | Some([0.0, 0.0]) => Ok(None),
            Some([time, ratio]) if time > 0.0 && ratio > 0.0 => Ok(Some([time, ratio])),
            Some([time, ratio]) => {
                let message = format!(
                    "attribute 'springdamper': expected a positive time constant and damping \
                     ratio, got {time} {ratio}"
                );
                Err(self.error(joint, message))
            }
        }
    }

    /// A joint's `springyield` `value` (the compiler's angle unit on hinges and balls): not
    /// negative, and none on a free joint, as MuJoCo requires.
    pub(super) fn spring_yield(&self, node: Node<'a, 'a>, joint: Joint, value: f64) -> Result<f64> {
        if value < 0.0 || (value > 0.0 && joint == Joint::Free) {
            let message = format!(
                "attribute 'springyield': expected a yield ≥ 0 on a hinge, slide or ball (none on \
                 a free joint), got {value}"
            );
            return Err(self.error(node, message));
        }
        Ok(match joint {
            Joint::Revolute { .. } | Joint::Spherical => self.angle(value),
            _ => value,
        })
    }

    /// The stiffness and damping of each joint with a `springdamper`, set as MuJoCo's compiler
    /// sets them once the model is whole: with the joint's mean inertia
    /// `I = n / Σ Â_dof` over its n degrees of freedom (`Â` the inverse weights at qpos0,
    /// [`crate::soft::weights`]), time constant τ and damping ratio ζ,
    /// `k = I / (τ² ζ²)` and `b = 2 I / τ` (as `solref` turns into a stiffness and damping).
    /// They replace the joint's own linear terms; an actuator's damping stays added.
    pub(super) fn apply_spring_dampers(&self, model: &mut Model) -> Result<()> {
        let spring_dampers = self.spring_dampers.take();
        if spring_dampers.is_empty() {
            return Ok(());
        }
        let mut data = crate::Data::new(model);
        let weights = crate::soft::weights::inverse_weights(model, &mut data)?;
        for (body, [time, ratio], own_damping) in spring_dampers {
            let dofs = model.v_range(body);
            let inverse: f64 = weights.dofs[dofs.clone()].iter().sum();
            let inertia = dofs.len() as f64 / inverse.max(crate::soft::TINY);
            let stiffness = inertia / (time * time * ratio * ratio).max(crate::soft::TINY);
            let damping = 2.0 * inertia / time.max(crate::soft::TINY);
            for c in dofs {
                model.stiffness[c] = stiffness;
                model.damping[c] += damping - own_damping;
            }
        }
        Ok(())
    }

    /// A joint's limit and dry friction in MuJoCo's soft constraint model: `solreflimit`,
    /// `solimplimit`, `margin` (in radians for a hinge whatever the compiler's angle unit, as
    /// MuJoCo reads it), `solreffriction`, `solimpfriction`.
    pub(super) fn joint_softness(&self, joint: Node<'a, 'a>, class: &str) -> Result<JointSoftness> {
        // a <freejoint> takes no joint defaults
        let tag = joint.tag_name().name();
        let parameters = |solref: &str, solimp: &str| -> Result<SolverParameters> {
            let defaults = SolverParameters::default();
            Ok(SolverParameters {
                solref: self.leading_numbers(joint, class, tag, solref, defaults.solref)?,
                solimp: self.leading_numbers(joint, class, tag, solimp, defaults.solimp)?,
            })
        };
        Ok(JointSoftness {
            limit: parameters("solreflimit", "solimplimit")?,
            margin: self
                .numbers::<1>(joint, class, "margin")?
                .map_or(0.0, |[m]| m),
            friction: parameters("solreffriction", "solimpfriction")?,
            cone_limit: None,
        })
    }

    /// The range a joint's total actuator force is clamped to, as MuJoCo reads it:
    /// `actuatorfrcrange` where `actuatorfrclimited` is true (a range with low < high needed), or
    /// "auto" (the default) and a range with low < high is given.
    pub(super) fn actuator_force_range(
        &self,
        joint: Node<'a, 'a>,
        class: &str,
    ) -> Result<Option<(f64, f64)>> {
        let range = self.numbers::<2>(joint, class, "actuatorfrcrange")?;
        let limited = self.attribute(joint, class, "actuatorfrclimited");
        let message = "attribute 'actuatorfrclimited' is true: expected an 'actuatorfrcrange' \
                       with low < high";
        self.limited_range(
            joint,
            (range, limited.as_deref()),
            "actuatorfrclimited",
            message,
        )
    }

    /// A warning where MuJoCo aligns a free body with its inertial frame (`<freejoint align>`,
    /// or "auto" and `<compiler alignfree="true">`, on a body without child bodies): MuJoCo's
    /// qpos and qvel then place and move that frame, robodyn's the body's own.
    pub(super) fn warn_aligned_free_body(&self, body: Node<'a, 'a>, joint: Node<'a, 'a>) {
        let aligned = match joint.attribute("align") {
            Some("true") => true,
            Some("false") => false,
            _ => self.align_free,
        };
        let childless = !body.descendants().skip(1).any(|d| d.has_tag_name("body"));
        if aligned && childless {
            self.warnings.borrow_mut().push(format!(
                "{}: free-joint alignment not followed (robodyn's q places and moves the body's \
                 own frame; MuJoCo's qpos, and keyframes written for it, its inertial frame)",
                self.location(joint)
            ));
        }
    }

    /// With `<compiler autolimits="false">`, MuJoCo refuses a range (`given`) whose `limited`
    /// attribute (named `limited_name`) is absent or "auto"; so does robodyn.
    pub(super) fn check_auto_limits(
        &self,
        element: Node<'a, 'a>,
        given: bool,
        limited: Option<&str>,
        limited_name: &str,
    ) -> Result<()> {
        if self.auto_limits || !given || !matches!(limited, None | Some("auto")) {
            return Ok(());
        }
        let range = limited_name.replace("limited", "range");
        let message = format!(
            "attribute '{range}' without '{limited_name}': with <compiler autolimits=\"false\"> \
             MuJoCo needs '{limited_name}' set to true or false"
        );
        Err(self.error(element, message))
    }

    /// A range where limited, MuJoCo's way: its `limited` attribute (named `limited_name`)
    /// true, false, or auto (absent: limited where the range is given with low < high); a
    /// limited one without low < high refused with `message`.
    pub(super) fn limited_range(
        &self,
        element: Node<'a, 'a>,
        (range, limited): (Option<[f64; 2]>, Option<&str>),
        limited_name: &str,
        message: &str,
    ) -> Result<Option<(f64, f64)>> {
        self.check_auto_limits(element, range.is_some(), limited, limited_name)?;
        let valid = range
            .filter(|[low, high]| low < high)
            .map(|[low, high]| (low, high));
        match limited {
            None | Some("auto") => Ok(valid),
            Some("false") => Ok(None),
            Some("true") => valid.map(Some).ok_or_else(|| self.error(element, message)),
            Some(other) => Err(self.error(
                element,
                format!("attribute '{limited_name}': expected true, false or auto, got '{other}'"),
            )),
        }
    }
}
