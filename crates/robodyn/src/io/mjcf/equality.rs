//! `<equality>`: MuJoCo's equality constraints as robodyn constraints, as MuJoCo compiles them
//! (<https://mujoco.readthedocs.io/en/stable/XMLreference.html#equality>).
//!
//! - `connect` (`body1`, `body2`, `anchor`, or `site1`, `site2`): a point of body1 (`anchor`, in
//!   its frame) held to body2 (the world without one) where it is at `qpos0`, the neutral
//!   configuration: body2's anchor is computed there, as MuJoCo's compiler does. With sites, the
//!   two sites' origins are held together.
//! - `weld` (`body1`, `body2`, `relpose`, `anchor`, `torquescale`, or `site1`, `site2`): the frame
//!   at `anchor` in body2 (body2's axes) held to body1: at `relpose` (the anchor's position in
//!   body1, then body2's orientation in body1 as a w-first quaternion, as MuJoCo's engine reads
//!   them) or, when relpose's quaternion is zero (the default), where it is at `qpos0`. With
//!   sites, the two sites' frames are held together.
//! - `joint` (`joint1`, `joint2`, `polycoef`): `q1 − q1,0 = Σ c_k (q2 − q2,0)^k` about the
//!   joints' `qpos0` values; without joint2, joint1 is held at `q1,0 + c_0`.
//!
//! - `tendon` (`tendon1`, `tendon2`, `polycoef`): the same between fixed tendons' lengths about
//!   their lengths at qpos0, a [`TendonEquality`] that MuJoCo's soft model holds (a warning
//!   says robodyn's exact constraints do not).
//!
//! `active`, `solref`, `solimp` (and a weld's `torquescale`) are kept with each constraint, from
//! the element or its class's `<equality>` default, with MuJoCo's defaults. `flex` and
//! `flexstrain` equalities are not read (a warning each).

use super::Reader;
use crate::algo::frame_pose;
use crate::constraint::{
    Attachment, Constraint, ConstraintKind, ConstraintReference, ConstraintSet, ModelConstraint,
    DEFAULT_SOLIMP, DEFAULT_SOLREF,
};
use crate::error::Result;
use crate::io::xml::parse_numbers;
use crate::model::{Model, SolverParameters, TendonEquality};
use crate::spatial::{Transform, Vec3};
use crate::Data;
use nalgebra::{Quaternion, UnitQuaternion};
use roxmltree::Node;

impl<'a> Reader<'a> {
    /// The constraints of the `<equality>` sections among `sections`, into `model.constraints`
    /// (after the tree is built: anchors come from the neutral configuration).
    pub(super) fn read_equalities(
        &self,
        sections: &[Node<'a, 'a>],
        model: &mut Model,
    ) -> Result<()> {
        let mut data = Data::new(model);
        // an equality left out keeps its place in MuJoCo's numbering
        let read_none = |model: &mut Model| {
            let read = model.constraints.len() + model.tendon_equalities.len();
            model.unread.equalities.push(read);
        };
        for section in sections.iter().filter(|c| c.has_tag_name("equality")) {
            for element in self.children(*section)? {
                let kind = match element.tag_name().name() {
                    "connect" => self.connect(element, model, &mut data)?,
                    "weld" => self.weld(element, model, &mut data)?,
                    "joint" => self.joint_equality(element, model)?,
                    "tendon" => {
                        let equality = self.tendon_equality(element, model)?;
                        model.tendon_equalities.push(equality);
                        continue;
                    }
                    _ => {
                        read_none(model);
                        let message = format!(
                            "{}: not read (robodyn holds connect, weld and joint equalities)",
                            self.location(element)
                        );
                        model.warnings.push(message);
                        continue;
                    }
                };
                let constraint = Constraint {
                    kind,
                    reference: ConstraintReference::World,
                };
                // the same checks as a user's constraint, named by the element
                ConstraintSet::new(model, vec![constraint.clone()])
                    .map_err(|e| self.error(element, e.to_string()))?;
                let declared = self.declared(element, constraint)?;
                model.constraints.push(declared);
            }
        }
        Ok(())
    }

    /// The constraint with the element's name, `active`, `solref`, `solimp`, `torquescale` and
    /// the bodies it attaches.
    fn declared(&self, element: Node<'a, 'a>, constraint: Constraint) -> Result<ModelConstraint> {
        let (active, solver) = self.activity_and_softness(element)?;
        Ok(ModelConstraint {
            name: element.attribute("name").unwrap_or_default().to_string(),
            constraint,
            active,
            solref: solver.solref,
            solimp: solver.solimp,
            torquescale: self
                .equality_numbers::<1>(element, "torquescale")?
                .map_or(1.0, |[t]| t),
            bodies: self.attached_bodies(element),
        })
    }

    /// An equality's `active`, `solref` and `solimp`.
    fn activity_and_softness(&self, element: Node<'a, 'a>) -> Result<(bool, SolverParameters)> {
        let active = match self.equality_attribute(element, "active")?.as_deref() {
            None | Some("true") => true,
            Some("false") => false,
            Some(other) => {
                let message = format!("attribute 'active': expected true or false, got '{other}'");
                return Err(self.error(element, message));
            }
        };
        let solver = SolverParameters {
            solref: self.leading_numbers(element, "main", "equality", "solref", DEFAULT_SOLREF)?,
            solimp: self.leading_numbers(element, "main", "equality", "solimp", DEFAULT_SOLIMP)?,
        };
        Ok((active, solver))
    }

    /// The file bodies a connect or weld attaches (its sites' or its bodies', the world 0):
    /// the names were checked when its constraint was made.
    fn attached_bodies(&self, element: Node<'a, 'a>) -> [usize; 2] {
        let sites = self.site_bodies.borrow();
        let bodies = self.source_bodies.borrow();
        let of = |site: &str, body: &str| {
            if let Some(name) = element.attribute(site) {
                return sites.get(name).copied().unwrap_or(0);
            }
            let name = element.attribute(body).unwrap_or("world");
            bodies.iter().position(|b| b.name == name).unwrap_or(0)
        };
        [of("site1", "body1"), of("site2", "body2")]
    }

    /// An attribute of an equality element, else its class's `<equality>` default (MuJoCo's
    /// defaults for equalities are one element for every type).
    fn equality_attribute(&self, element: Node<'a, 'a>, name: &str) -> Result<Option<String>> {
        if let Some(value) = element.attribute(name) {
            return Ok(Some(value.to_string()));
        }
        let class = self.declared_class(element, "class", "main")?;
        let default = self.defaults.get(class).and_then(|d| d.get("equality"));
        Ok(default.and_then(|d| d.get(name)).cloned())
    }

    fn equality_numbers<const N: usize>(
        &self,
        element: Node<'a, 'a>,
        name: &str,
    ) -> Result<Option<[f64; N]>> {
        self.equality_attribute(element, name)?
            .map(|text| parse_numbers::<N>(&text, name).map_err(|m| self.error(element, m)))
            .transpose()
    }

    /// The frame of the body or site named by `attribute`, `None` when the element has none.
    fn named_frame(
        &self,
        element: Node<'a, 'a>,
        attribute: &str,
        model: &Model,
    ) -> Result<Option<usize>> {
        let Some(name) = element.attribute(attribute) else {
            return Ok(None);
        };
        model.frame_index(name).map(Some).map_err(|_| {
            self.error(
                element,
                format!("attribute '{attribute}': no body or site is called '{name}'"),
            )
        })
    }

    /// The two sites of a site-defined connect or weld, if it is one.
    fn sites(&self, element: Node<'a, 'a>, model: &Model) -> Result<Option<(usize, usize)>> {
        let (one, other) = (
            self.named_frame(element, "site1", model)?,
            self.named_frame(element, "site2", model)?,
        );
        match (one, other) {
            (None, None) => Ok(None),
            (Some(one), Some(other)) => Ok(Some((one, other))),
            _ => Err(self.error(element, "expected both 'site1' and 'site2', or neither")),
        }
    }

    /// body1 (required) and body2 (`None`: the world) of a body-defined connect or weld.
    fn bodies(&self, element: Node<'a, 'a>, model: &Model) -> Result<(usize, Option<usize>)> {
        let one = self
            .named_frame(element, "body1", model)?
            .ok_or_else(|| self.error(element, "expected 'body1' (or 'site1' and 'site2')"))?;
        Ok((one, self.named_frame(element, "body2", model)?))
    }

    /// A connect: body1's anchor held to body2 (or the world) where it is at qpos0.
    fn connect(
        &self,
        element: Node<'a, 'a>,
        model: &Model,
        data: &mut Data,
    ) -> Result<ConstraintKind> {
        if let Some((one, other)) = self.sites(element, model)? {
            return Ok(ConstraintKind::Point {
                first: Attachment::at_frame(one),
                second: Some(Attachment::at_frame(other)),
            });
        }
        let (one, other) = self.bodies(element, model)?;
        let anchor = Vec3::from(
            self.equality_numbers::<3>(element, "anchor")?
                .unwrap_or([0.0; 3]),
        );
        // the anchor in the world at qpos0, then in body2's frame
        let neutral = model.neutral();
        let pose = frame_pose(model, data, neutral.as_slice(), one)?;
        let point = pose.translation + pose.rotation.tr_mul(&anchor);
        let second = match other {
            None => Attachment {
                frame: None,
                placement: Transform::from_translation(&point),
            },
            Some(other) => {
                let pose = frame_pose(model, data, neutral.as_slice(), other)?;
                let local = pose.rotation * (point - pose.translation);
                Attachment {
                    frame: Some(other),
                    placement: Transform::from_translation(&local),
                }
            }
        };
        Ok(ConstraintKind::Point {
            first: Attachment {
                frame: Some(one),
                placement: Transform::from_translation(&anchor),
            },
            second: Some(second),
        })
    }

    /// A weld: body2's frame at `anchor` held to body1 at `relpose`, or where it is at qpos0.
    fn weld(
        &self,
        element: Node<'a, 'a>,
        model: &Model,
        data: &mut Data,
    ) -> Result<ConstraintKind> {
        let all_rows = [true; 6];
        if let Some((one, other)) = self.sites(element, model)? {
            return Ok(ConstraintKind::Frame {
                first: Attachment::at_frame(one),
                second: Some(Attachment::at_frame(other)),
                mask: all_rows,
            });
        }
        let (one, other) = self.bodies(element, model)?;
        let anchor = Vec3::from(
            self.equality_numbers::<3>(element, "anchor")?
                .unwrap_or([0.0; 3]),
        );
        let relpose = self.equality_numbers::<7>(element, "relpose")?;
        // X_{c←2}: the weld frame at the anchor in body2 (or the world)
        let in_second = Transform::from_translation(&anchor);
        // X_{c←1}: the same frame in body1: relpose gives its origin (the anchor's place in
        // body1, as MuJoCo's engine reads it) and body2's orientation in body1; else both come
        // from the poses at qpos0
        let in_first = match relpose.filter(|r| r[3..].iter().any(|x| *x != 0.0)) {
            Some(r) => {
                let turn = Quaternion::new(r[3], r[4], r[5], r[6]);
                let rotation = UnitQuaternion::from_quaternion(turn).to_rotation_matrix();
                Transform::from_pose(rotation.matrix(), &Vec3::new(r[0], r[1], r[2]))
            }
            None => {
                let neutral = model.neutral();
                let first_pose = frame_pose(model, data, neutral.as_slice(), one)?;
                let second_pose = match other {
                    Some(other) => frame_pose(model, data, neutral.as_slice(), other)?,
                    None => Transform::IDENTITY,
                };
                // X_{c←1} = X_{c←2} X_{2←0} X_{1←0}⁻¹
                in_second * second_pose * first_pose.inverse()
            }
        };
        Ok(ConstraintKind::Frame {
            first: Attachment {
                frame: Some(one),
                placement: in_first,
            },
            second: Some(Attachment {
                frame: other,
                placement: in_second,
            }),
            mask: all_rows,
        })
    }

    /// A tendon equality: tendon1's length a polynomial of tendon2's about their lengths at
    /// qpos0.
    fn tendon_equality(&self, element: Node<'a, 'a>, model: &mut Model) -> Result<TendonEquality> {
        let tendon = |attribute: &str| -> Result<Option<usize>> {
            let Some(name) = element.attribute(attribute) else {
                return Ok(None);
            };
            let found = model.tendons.iter().position(|t| t.name == name);
            let message = || format!("attribute '{attribute}': no tendon is called '{name}'");
            found
                .map(Some)
                .ok_or_else(|| self.error(element, message()))
        };
        let first = tendon("tendon1")?
            .ok_or_else(|| self.error(element, "expected attribute 'tendon1'"))?;
        let second = tendon("tendon2")?;
        let (active, solver) = self.activity_and_softness(element)?;
        model.warnings.push(format!(
            "{}: held by MuJoCo's soft model only (contact_forward_dynamics, step, simulate with \
             integrator=\"mujoco\"), not by robodyn's exact constraints",
            self.location(element)
        ));
        Ok(TendonEquality {
            name: element.attribute("name").unwrap_or_default().to_string(),
            tendons: (first, second),
            polynomial: self.polynomial(element)?,
            active,
            solver,
            before: model.constraints.len(),
        })
    }

    /// A joint or tendon equality's `polycoef` (MuJoCo's default: the identity, 0 1 0 0 0).
    fn polynomial(&self, element: Node<'a, 'a>) -> Result<[f64; 5]> {
        let identity = [0.0, 1.0, 0.0, 0.0, 0.0];
        self.leading_numbers(element, "main", "equality", "polycoef", identity)
    }

    /// A joint equality: joint1 a polynomial of joint2 about their qpos0 values.
    fn joint_equality(&self, element: Node<'a, 'a>, model: &Model) -> Result<ConstraintKind> {
        let joint = |attribute: &str| -> Result<Option<usize>> {
            let Some(name) = element.attribute(attribute) else {
                return Ok(None);
            };
            let body = model.joint_names.iter().skip(1).position(|n| n == name);
            body.map(|k| Some(k + 1)).ok_or_else(|| {
                self.error(
                    element,
                    format!("attribute '{attribute}': no joint is called '{name}'"),
                )
            })
        };
        let follower =
            joint("joint1")?.ok_or_else(|| self.error(element, "expected attribute 'joint1'"))?;
        let leader = joint("joint2")?;
        let neutral = |body: usize| model.neutral_configuration[model.idx_q[body]];
        Ok(ConstraintKind::Coupling {
            follower,
            leader,
            polynomial: self.polynomial(element)?,
            references: (neutral(follower), leader.map_or(0.0, neutral)),
        })
    }
}
