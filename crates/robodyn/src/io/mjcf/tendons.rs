//! `<tendon>`: each `<fixed>` element, and each `<spatial>` one through sites and pulleys, a
//! [`Tendon`], as MuJoCo compiles it
//! (<https://mujoco.readthedocs.io/en/stable/XMLreference.html#tendon>).
//!
//! A fixed tendon's `<joint joint coef>` children (hinges and slides, each once) give its length
//! `L = Σ coef q`; a spatial tendon's `<site site>`, `<geom geom sidesite>` and `<pulley divisor>`
//! children its path (from a site to a site; a geom, a sphere or a cylinder, between two sites;
//! a pulley starts a branch at a site). Either kind's `limited` ("auto": where `range` is a
//! valid range), `range`, `margin`, `solreflimit`/`solimplimit`, `frictionloss`,
//! `solreffriction`/`solimpfriction`, `stiffness` and `damping` (a linear coefficient and up to
//! two higher ones),
//! `springlength` (one value, a dead band of two, or the length at the joints' `springref` when
//! not given) come from the element or its class's `<tendon>` default; L at qpos0 and the
//! default dead band are measured once the model's tendons are all read; `actuatorfrclimited`
//! and `actuatorfrcrange` bound its actuators' forces together; its `armature` (with its
//! actuators' g² `armature`, [`tendon_inertias`]) is an inertia moving with L; its
//! `springyield` makes its spring plastic ([`crate::model::plastic`]).

use super::Reader;
use crate::error::Result;
use crate::io::xml::parse_number_list;
use crate::model::{Model, PathPoint, SolverParameters, Tendon, DEFAULT_SOLIMP, DEFAULT_SOLREF};
use crate::soft::tendons::TendonKinematics;
use crate::soft::wrap::Surface;
use crate::spatial::Vec3;
use crate::Data;
use roxmltree::Node;

/// A tendon's joints and coefficients (a fixed tendon's) and its path (a spatial one's).
type TendonShape = (Vec<(usize, f64)>, Vec<PathPoint>);

/// MuJoCo's `springlength` that asks for the length at the joints' `springref`.
const UNGIVEN_SPRING_LENGTH: [f64; 2] = [-1.0, -1.0];

impl<'a> Reader<'a> {
    /// The `<fixed>` and `<spatial>` elements of the `<tendon>` sections among `sections`, in
    /// order, into `model.tendons` (after the tree is built: they name joints and sites).
    pub(super) fn read_tendons(&self, sections: &[Node<'a, 'a>], model: &mut Model) -> Result<()> {
        let first = model.tendons.len();
        for section in sections.iter().filter(|c| c.has_tag_name("tendon")) {
            for element in self.children(*section)? {
                let (joints, path) = match element.tag_name().name() {
                    "fixed" => self.fixed_path(element, model)?,
                    _ => self.spatial_path(element, model)?,
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

    /// After the actuators (which add their armature to their tendons'): a body a tendon with an
    /// inertia moves (a fixed tendon's joints' bodies, a spatial one's sites') is no simple body
    /// (MuJoCo 4.0 demotes it, measured), and a warning for each tendon whose inertia couples two
    /// branches of the tree, which MuJoCo's M leaves out ([`crate::soft::inertia`]).
    pub(super) fn tendon_inertias(&self, root: Node<'a, 'a>, model: &mut Model) {
        let mut body_of = vec![0; model.nv];
        for i in 1..model.nbodies() {
            body_of[model.v_range(i)].fill(i);
        }
        for tendon in model.tendons.iter().filter(|t| t.armature != 0.0) {
            // the bodies it moves, and the coordinates of its J
            let mut bodies: Vec<usize> = tendon.joints.iter().map(|(b, _)| *b).collect();
            let mut columns: Vec<usize> = bodies.iter().map(|b| model.idx_v[*b]).collect();
            for point in &tendon.path {
                if let PathPoint::Site { body, .. } = point {
                    bodies.push(*body);
                    let mut j = *body;
                    while j != 0 {
                        columns.extend(model.v_range(j));
                        j = model.parent[j];
                    }
                }
            }
            for source in model.source_bodies.iter_mut().filter(|s| s.simple) {
                let mut chain = source.body;
                while chain != 0 && !bodies.contains(&chain) {
                    chain = model.parent[chain];
                }
                source.simple = chain == 0;
            }
            let apart = columns.iter().find_map(|&k| {
                let other = columns.iter().find(|&&l| !model.dofs_on_one_branch(k, l));
                other.map(|&l| (body_of[k], body_of[l]))
            });
            if let Some((one, other)) = apart {
                model.warnings.push(format!(
                    "{}: tendon '{}': its armature couples joints '{}' and '{}', on two branches \
                     of the tree; MuJoCo's mass matrix keeps only the terms a J_k J_l along one \
                     branch, and robodyn does as MuJoCo",
                    self.location(root),
                    tendon.name,
                    model.joint_names[one],
                    model.joint_names[other]
                ));
            }
        }
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

    /// A `<spatial>` element's path: its sites, the spheres and cylinders it wraps around (with
    /// their side sites) and its pulleys. Refused as MuJoCo refuses them: fewer than two stops,
    /// consecutive pulleys, a pulley last, a site between pulleys (or the path's ends), a site
    /// repeated next to itself, a geom not between two sites or neither a sphere nor a cylinder.
    fn spatial_path(&self, element: Node<'a, 'a>, model: &Model) -> Result<TendonShape> {
        let children = self.children(element)?;
        let mut path = Vec::new();
        let site = |child: Node<'a, 'a>, attribute: &str| -> Result<(usize, Vec3)> {
            let name = child.attribute(attribute).unwrap_or_default();
            let found = self.site_points.borrow().get(name).copied();
            found.ok_or_else(|| {
                self.error(
                    child,
                    format!("attribute '{attribute}': no site named '{name}'"),
                )
            })
        };
        for child in &children {
            match child.tag_name().name() {
                "site" => {
                    let (body, point) = site(*child, "site")?;
                    path.push(PathPoint::Site { body, point });
                }
                "geom" => {
                    let geom = self.wrapped_geom(*child, model)?;
                    let side = match child.attribute("sidesite") {
                        Some(_) => Some(site(*child, "sidesite")?),
                        None => None,
                    };
                    path.push(PathPoint::Geom { geom, side });
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
                other => {
                    let message = format!("expected <site>, <geom> or <pulley>, got <{other}>");
                    return Err(self.error(*child, message));
                }
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
        let site_at = |k: Option<usize>| {
            k.and_then(|k| path.get(k))
                .is_some_and(|p| matches!(p, PathPoint::Site { .. }))
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
                PathPoint::Geom { .. } if !(site_at(k.checked_sub(1)) && site_at(Some(k + 1))) => {
                    "a geom must have a site on either side of it"
                }
                _ => continue,
            };
            return Err(self.error(*child, message));
        }
        Ok((Vec::new(), path))
    }

    /// The geom a `<geom geom>` stop of a path names: a sphere or a cylinder of the model.
    fn wrapped_geom(&self, child: Node<'a, 'a>, model: &Model) -> Result<usize> {
        let name = child.attribute("geom").unwrap_or_default();
        let geom = model.geoms.iter().position(|g| g.name == name);
        let geom = geom.ok_or_else(|| {
            self.error(child, format!("attribute 'geom': no geom named '{name}'"))
        })?;
        match Surface::of(&model.geoms[geom].shape) {
            Some(_) => Ok(geom),
            None => {
                let message = format!(
                    "attribute 'geom': a tendon wraps around a sphere or a cylinder, '{name}' is \
                     neither"
                );
                Err(self.error(child, message))
            }
        }
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
        // an inertia: not negative, and none on a path that wraps around a geom (MuJoCo's J̇
        // does not follow such a path)
        let armature = first("armature", 0.0)?;
        if armature < 0.0 {
            let message = format!("attribute 'armature': expected a value ≥ 0, got {armature}");
            return Err(self.error(element, message));
        }
        let wraps = path.iter().any(|p| matches!(p, PathPoint::Geom { .. }));
        if wraps && armature > 0.0 {
            let message = "attribute 'armature': a tendon that wraps around a geom has none";
            return Err(self.error(element, message));
        }
        // a spring's or damper's coefficients: its linear one, then up to two higher
        let polynomial = |name: &str| {
            self.spring_polynomial(
                element,
                name,
                self.tendon_attribute(element, name).as_deref(),
            )
        };
        let ((stiffness, stiffness_poly), (damping, damping_poly)) =
            (polynomial("stiffness")?, polynomial("damping")?);
        let spring_yield = first("springyield", 0.0)?;
        if spring_yield < 0.0 {
            let message =
                format!("attribute 'springyield': expected a yield ≥ 0, got {spring_yield}");
            return Err(self.error(element, message));
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
            stiffness,
            spring_length: [0.0; 2],
            damping,
            actuator_force_range: self.tendon_actuator_force_range(element)?,
            armature,
            stiffness_poly,
            damping_poly,
            spring_yield,
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
        let range = self.tendon_pair(element, "range")?;
        let limited = self.tendon_attribute(element, "limited");
        let message = "attribute 'range': a limited tendon needs lower < upper";
        self.limited_range(element, (range, limited.as_deref()), "limited", message)
    }

    /// The range [f₋, f₊] the forces of a tendon's actuators are scaled into where limited
    /// (`actuatorfrclimited`, `actuatorfrcrange`); MuJoCo refuses a limited one without
    /// f₋ < f₊ or with 0 outside it.
    fn tendon_actuator_force_range(&self, element: Node<'a, 'a>) -> Result<Option<(f64, f64)>> {
        let range = self.tendon_pair(element, "actuatorfrcrange")?;
        let limited = self.tendon_attribute(element, "actuatorfrclimited");
        let message = "attribute 'actuatorfrcrange': a limited tendon needs low < high";
        let range = self.limited_range(
            element,
            (range, limited.as_deref()),
            "actuatorfrclimited",
            message,
        )?;
        match range {
            Some((low, high)) if low > 0.0 || high < 0.0 => {
                let message = format!(
                    "attribute 'actuatorfrcrange': expected low ≤ 0 ≤ high, got '{low} {high}'"
                );
                Err(self.error(element, message))
            }
            _ => Ok(range),
        }
    }

    /// Two numbers of a tendon element or its class's default, where given.
    fn tendon_pair(&self, element: Node<'a, 'a>, name: &str) -> Result<Option<[f64; 2]>> {
        self.tendon_attribute(element, name)
            .map(|text| {
                crate::io::xml::parse_numbers::<2>(&text, name).map_err(|m| self.error(element, m))
            })
            .transpose()
    }
}
