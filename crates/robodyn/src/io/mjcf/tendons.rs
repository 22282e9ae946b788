//! `<tendon>`: each `<fixed>` element a [`Tendon`], as MuJoCo compiles it
//! (<https://mujoco.readthedocs.io/en/stable/XMLreference.html#tendon-fixed>).
//!
//! A fixed tendon's `<joint joint coef>` children (hinges and slides, each once) give its length
//! `L = Σ coef q`; `limited` ("auto": where `range` is a valid range), `range`, `margin`,
//! `solreflimit`/`solimplimit`, `frictionloss`, `solreffriction`/`solimpfriction`, `stiffness`
//! and `damping` (their first value), `springlength` (one value, a dead band of two, or the
//! length at the joints' `springref` when not given) come from the element or its class's
//! `<tendon>` default. Spatial tendons, a tendon's `armature`, polynomial `stiffness` or
//! `damping`, `springyield` and `actuatorfrcrange` are not modelled (a warning each).

use super::Reader;
use crate::error::Result;
use crate::io::xml::parse_number_list;
use crate::model::{Model, SolverParameters, Tendon, DEFAULT_SOLIMP, DEFAULT_SOLREF};
use roxmltree::Node;

/// What robodyn models, for the warnings about the rest.
const MODELLED: &str = "robodyn models fixed tendons with a linear spring and damper";

impl<'a> Reader<'a> {
    /// The `<fixed>` elements of the `<tendon>` sections among `sections`, in order, into
    /// `model.tendons` (after the tree is built: they name joints).
    pub(super) fn read_tendons(&self, sections: &[Node<'a, 'a>], model: &mut Model) -> Result<()> {
        for section in sections.iter().filter(|c| c.has_tag_name("tendon")) {
            for element in self.children(*section)? {
                if element.tag_name().name() != "fixed" {
                    let name = element.attribute("name").unwrap_or_default().to_string();
                    self.unread_tendons.borrow_mut().push(name);
                    model.unread.tendons.push(model.tendons.len());
                    model.warnings.push(format!(
                        "{}: not read ({MODELLED}): its limits, friction, equalities and \
                         actuators are left out",
                        self.location(element)
                    ));
                    continue;
                }
                let tendon = self.fixed_tendon(element, model)?;
                model.tendons.push(tendon);
            }
        }
        Ok(())
    }

    /// One `<fixed>` element.
    fn fixed_tendon(&self, element: Node<'a, 'a>, model: &mut Model) -> Result<Tendon> {
        let index = model.tendons.len();
        let mut joints: Vec<(usize, f64)> = Vec::new();
        for child in self.children(element)? {
            let name = child.attribute("joint").unwrap_or_default();
            let body = model.joint_names.iter().skip(1).position(|n| n == name);
            let body = body.map(|b| b + 1).ok_or_else(|| {
                self.error(
                    child,
                    format!("attribute 'joint': no joint is called '{name}'"),
                )
            })?;
            if model.joints[body].nv() != 1 || model.joints[body].nq() != 1 {
                let kind = model.joints[body].kind();
                let message = format!(
                    "a fixed tendon's joint must be a hinge or slide, got '{name}' ({kind})"
                );
                return Err(self.error(child, message));
            }
            if joints.iter().any(|(b, _)| *b == body) {
                return Err(self.error(child, format!("joint '{name}' is repeated")));
            }
            let coef = child
                .attribute("coef")
                .ok_or_else(|| self.error(child, "expected attribute 'coef'"))?;
            let coef = crate::io::xml::parse_numbers::<1>(coef, "coef")
                .map_err(|m| self.error(child, m))?[0];
            joints.push((body, coef));
        }
        let values = |name: &str| -> Result<Option<Vec<f64>>> {
            self.tendon_attribute(element, name)
                .map(|t| parse_number_list(&t, name).map_err(|m| self.error(element, m)))
                .transpose()
        };
        let first = |name: &str, default: f64| -> Result<f64> {
            Ok(values(name)?
                .and_then(|v| v.first().copied())
                .unwrap_or(default))
        };
        let solver = |solref: &str, solimp: &str| -> Result<SolverParameters> {
            Ok(SolverParameters {
                solref: self.leading_numbers(element, "main", "tendon", solref, DEFAULT_SOLREF)?,
                solimp: self.leading_numbers(element, "main", "tendon", solimp, DEFAULT_SOLIMP)?,
            })
        };
        // what is not modelled: warned
        let mut unmodelled = Vec::new();
        for name in ["stiffness", "damping"] {
            if values(name)?.is_some_and(|v| v.iter().skip(1).any(|x| *x != 0.0)) {
                unmodelled.push(format!("a polynomial '{name}'"));
            }
        }
        for name in ["armature", "springyield"] {
            if first(name, 0.0)? != 0.0 {
                unmodelled.push(format!("'{name}'"));
            }
        }
        if self.tendon_attribute(element, "actuatorfrcrange").is_some() {
            unmodelled.push("'actuatorfrcrange'".into());
        }
        if !unmodelled.is_empty() {
            model.warnings.push(format!(
                "{}: {} not modelled ({MODELLED})",
                self.location(element),
                unmodelled.join(", ")
            ));
        }
        let mut tendon = Tendon {
            name: element
                .attribute("name")
                .map_or_else(|| format!("tendon{index}"), str::to_string),
            joints,
            length0: 0.0,
            range: self.tendon_range(element)?,
            margin: first("margin", 0.0)?,
            limit: solver("solreflimit", "solimplimit")?,
            frictionloss: first("frictionloss", 0.0)?,
            friction: solver("solreffriction", "solimpfriction")?,
            stiffness: first("stiffness", 0.0)?,
            spring_length: [0.0; 2],
            damping: first("damping", 0.0)?,
        };
        tendon.length0 = tendon.length(model, model.neutral_configuration.as_slice());
        // the dead band: given, or the length at the joints' springref (MuJoCo's (−1, −1))
        tendon.spring_length = match values("springlength")?.as_deref() {
            None | Some([-1.0]) | Some([-1.0, -1.0]) => {
                let at_rest = tendon.length(model, model.spring_reference.as_slice());
                [at_rest; 2]
            }
            Some([length]) => [*length; 2],
            Some([low, high]) if low <= high => [*low, *high],
            Some(_) => {
                let message = "attribute 'springlength': expected one length or low ≤ high";
                return Err(self.error(element, message));
            }
        };
        Ok(tendon)
    }

    /// An attribute of a tendon element, else its class's `<tendon>` default.
    fn tendon_attribute(&self, element: Node<'a, 'a>, name: &str) -> Option<String> {
        if let Some(value) = element.attribute(name) {
            return Some(value.to_string());
        }
        let class = element.attribute("class").unwrap_or("main");
        self.defaults.get(class)?.get("tendon")?.get(name).cloned()
    }

    /// `range` where `limited` limits it: "auto" (the default) where a valid range (lower <
    /// upper) is given, as MuJoCo; "true" with an invalid one is refused.
    fn tendon_range(&self, element: Node<'a, 'a>) -> Result<Option<(f64, f64)>> {
        let range = match self.tendon_attribute(element, "range") {
            Some(text) => Some(
                crate::io::xml::parse_numbers::<2>(&text, "range")
                    .map_err(|m| self.error(element, m))?,
            ),
            None => None,
        };
        let valid = range.filter(|[lower, upper]| lower < upper);
        match self.tendon_attribute(element, "limited").as_deref() {
            None | Some("auto") => Ok(valid.map(|[lower, upper]| (lower, upper))),
            Some("false") => Ok(None),
            Some("true") => valid
                .map(|[lower, upper]| Some((lower, upper)))
                .ok_or_else(|| {
                    self.error(
                        element,
                        "attribute 'range': a limited tendon needs lower < upper",
                    )
                }),
            Some(other) => Err(self.error(
                element,
                format!("attribute 'limited': expected true, false or auto, got '{other}'"),
            )),
        }
    }
}
