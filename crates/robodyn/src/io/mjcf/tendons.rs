//! `<tendon>`: each `<fixed>` element, and each `<spatial>` one through sites and pulleys, a
//! [`Tendon`], as MuJoCo compiles it
//! (<https://mujoco.readthedocs.io/en/stable/XMLreference.html#tendon>).
//!
//! A fixed tendon's `<joint joint coef>` children (hinges and slides, each once) give its length
//! `L = Σ coef q`; a spatial tendon's `<site site>` and `<pulley divisor>` children its path
//! (from a site to a site; a pulley starts a branch at a site). A spatial tendon that wraps
//! around a `<geom>` is not read (a warning). Either kind's `limited` ("auto": where `range` is a
//! valid range), `range`, `margin`, `solreflimit`/`solimplimit`, `frictionloss`,
//! `solreffriction`/`solimpfriction`, `stiffness` and `damping` (their first value),
//! `springlength` (one value, a dead band of two, or the length at the joints' `springref` when
//! not given) come from the element or its class's `<tendon>` default; L at qpos0 and the
//! default dead band are measured once the model's tendons are all read. A tendon's `armature`,
//! polynomial `stiffness` or `damping`, `springyield` and `actuatorfrcrange` are not modelled (a
//! warning each).

use super::Reader;
use crate::error::Result;
use crate::io::xml::parse_number_list;
use crate::model::{Model, PathPoint, SolverParameters, Tendon, DEFAULT_SOLIMP, DEFAULT_SOLREF};
use crate::soft::tendons::TendonKinematics;
use crate::Data;
use roxmltree::Node;

/// A tendon's joints and coefficients (a fixed tendon's) and its path (a spatial one's).
type TendonShape = (Vec<(usize, f64)>, Vec<PathPoint>);

/// MuJoCo's `springlength` that asks for the length at the joints' `springref`.
const UNGIVEN_SPRING_LENGTH: [f64; 2] = [-1.0, -1.0];

/// What robodyn models, for the warnings about the rest.
const MODELLED: &str = "robodyn models fixed tendons and spatial ones through sites and pulleys, \
                        with a linear spring and damper";

impl<'a> Reader<'a> {
    /// The `<fixed>` and `<spatial>` elements of the `<tendon>` sections among `sections`, in
    /// order, into `model.tendons` (after the tree is built: they name joints and sites).
    pub(super) fn read_tendons(&self, sections: &[Node<'a, 'a>], model: &mut Model) -> Result<()> {
        let first = model.tendons.len();
        for section in sections.iter().filter(|c| c.has_tag_name("tendon")) {
            for element in self.children(*section)? {
                let read = match element.tag_name().name() {
                    "fixed" => Some(self.fixed_path(element, model)?),
                    _ => self.spatial_path(element)?,
                };
                let Some((joints, path)) = read else {
                    let name = element.attribute("name").unwrap_or_default().to_string();
                    self.unread_tendons.borrow_mut().push(name);
                    model.unread.tendons.push(model.tendons.len());
                    model.warnings.push(format!(
                        "{}: not read (its path wraps around a geom; {MODELLED}): its limits, \
                         friction, equalities and actuators are left out",
                        self.location(element)
                    ));
                    continue;
                };
                let tendon = self.tendon(element, model, joints, path)?;
                model.tendons.push(tendon);
            }
        }
        // L at qpos0, and the dead band where not given: L at the joints' springref
        let mut data = Data::new(model);
        let neutral =
            TendonKinematics::at(model, &mut data, model.neutral_configuration.as_slice())?;
        let at_rest = TendonKinematics::at(model, &mut data, model.spring_reference.as_slice())?;
        for (t, tendon) in model.tendons.iter_mut().enumerate().skip(first) {
            tendon.length0 = neutral.lengths[t];
            if tendon.spring_length == UNGIVEN_SPRING_LENGTH {
                tendon.spring_length = [at_rest.lengths[t]; 2];
            }
        }
        Ok(())
    }

    /// A `<fixed>` element's joints (each a hinge or slide, once) and their coefficients.
    fn fixed_path(&self, element: Node<'a, 'a>, model: &Model) -> Result<TendonShape> {
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
        Ok((joints, Vec::new()))
    }

    /// A `<spatial>` element's path: its sites and pulleys; `None` where it wraps around a geom.
    /// Refused as MuJoCo refuses them: fewer than two stops, consecutive pulleys, a pulley last,
    /// a site between pulleys (or the path's ends), a site repeated next to itself.
    fn spatial_path(&self, element: Node<'a, 'a>) -> Result<Option<TendonShape>> {
        let children = self.children(element)?;
        let mut path = Vec::new();
        for child in &children {
            match child.tag_name().name() {
                "site" => {
                    let name = child.attribute("site").unwrap_or_default();
                    let (body, point) = *self.site_points.borrow().get(name).ok_or_else(|| {
                        self.error(*child, format!("attribute 'site': no site named '{name}'"))
                    })?;
                    path.push(PathPoint::Site { body, point });
                }
                "pulley" => {
                    let divisor = child
                        .attribute("divisor")
                        .map(|t| crate::io::xml::parse_numbers::<1>(t, "divisor"))
                        .transpose()
                        .map_err(|m| self.error(*child, m))?
                        .map_or(0.0, |[d]| d);
                    if divisor <= 0.0 {
                        let message = format!("attribute 'divisor': expected > 0, got {divisor}");
                        return Err(self.error(*child, message));
                    }
                    path.push(PathPoint::Pulley { divisor });
                }
                _ => return Ok(None),
            }
        }
        if path.len() < 2 {
            let message = "a spatial tendon's path needs two stops or more";
            return Err(self.error(element, message));
        }
        let pulley = |k: Option<usize>| {
            k.and_then(|k| path.get(k))
                .is_none_or(|p| matches!(p, PathPoint::Pulley { .. }))
        };
        for (k, (point, child)) in path.iter().zip(&children).enumerate() {
            let message = match point {
                PathPoint::Pulley { .. } if k > 0 && pulley(Some(k - 1)) => "consecutive pulleys",
                PathPoint::Pulley { .. } if k + 1 == path.len() => "the path ends with a pulley",
                PathPoint::Site { .. } if pulley(k.checked_sub(1)) && pulley(Some(k + 1)) => {
                    "a site needs a neighbour that is not a pulley"
                }
                PathPoint::Site { .. }
                    if children.get(k + 1).is_some_and(|next| {
                        next.has_tag_name("site")
                            && next.attribute("site") == child.attribute("site")
                    }) =>
                {
                    "a site is repeated next to itself"
                }
                _ => continue,
            };
            return Err(self.error(*child, message));
        }
        Ok(Some((Vec::new(), path)))
    }

    /// A tendon element (fixed or spatial) on its joints or path.
    fn tendon(
        &self,
        element: Node<'a, 'a>,
        model: &mut Model,
        joints: Vec<(usize, f64)>,
        path: Vec<PathPoint>,
    ) -> Result<Tendon> {
        let index = model.tendons.len();
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
        // a spatial tendon is drawn with a positive width (MuJoCo refuses others)
        let width = first("width", 0.003)?;
        if !path.is_empty() && width <= 0.0 {
            let message = format!("attribute 'width': expected a positive width, got {width}");
            return Err(self.error(element, message));
        }
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
            path,
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
        // the dead band: given, or (MuJoCo's (−1, −1)) the length at the joints' springref
        tendon.spring_length = match values("springlength")?.as_deref() {
            None | Some([-1.0]) | Some([-1.0, -1.0]) => UNGIVEN_SPRING_LENGTH,
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
