//! The body tree of an MJCF file: bodies, their joints (those in `<frame>`s too), sites and
//! frames, into the model builder.

use super::inertia::InertiaAxes;
use super::Reader;
use crate::error::Result;
use crate::joint::Joint;
use crate::model::{JointProperties, ModelBuilder, NewBody, SourceBody};
use crate::spatial::{Inertia, Mat3, Transform, Vec3};
use nalgebra::{Rotation3, Unit, UnitQuaternion};
use roxmltree::Node;

/// Whether `element` is a `<frame>` of the worldbody itself (not of one of its bodies).
fn in_world_frame(element: Node) -> bool {
    element.has_tag_name("frame")
        && element
            .ancestors()
            .skip(1)
            .find(|a| a.has_tag_name("body") || a.has_tag_name("worldbody"))
            .is_some_and(|a| a.has_tag_name("worldbody"))
}

/// Whether a body's parent, through any `<frame>`s, is the worldbody.
fn under_world(body: Node) -> bool {
    let mut parent = body.parent_element();
    while parent.is_some_and(|p| p.has_tag_name("frame")) {
        parent = parent.and_then(|p| p.parent_element());
    }
    parent.is_some_and(|p| p.has_tag_name("worldbody"))
}

/// A free joint's `[x, y, z, qx, qy, qz, qw]` that places its body at `to_body`
/// (`X_{B←world}`).
fn free_joint_coordinates(to_body: &Transform) -> [f64; 7] {
    let rotation = Rotation3::from_matrix_unchecked(to_body.rotation.transpose());
    let quaternion = UnitQuaternion::from_rotation_matrix(&rotation);
    let p = to_body.translation;
    [
        p.x,
        p.y,
        p.z,
        quaternion.i,
        quaternion.j,
        quaternion.k,
        quaternion.w,
    ]
}

impl<'a> Reader<'a> {
    /// The elements among a body's `elements` whose tag is one of `tags`, its own and those inside
    /// its `<frame>`s (document order), each with `X_{frame←body}` (the identity for its own) and
    /// the class in effect there.
    pub(super) fn framed_elements<'c>(
        &self,
        elements: &[Node<'a, 'a>],
        class: &'c str,
        tags: &[&str],
        to_frame: Transform,
        found: &mut Vec<(Node<'a, 'a>, Transform, &'c str)>,
    ) -> Result<()>
    where
        'a: 'c,
    {
        for element in elements {
            let tag = element.tag_name().name();
            if tags.contains(&tag) {
                found.push((*element, to_frame, class));
            } else if tag == "frame" {
                let inner_class = self.declared_class(*element, "childclass", class)?;
                let inner = self.placement(*element, class)? * to_frame;
                self.framed_elements(&self.children(*element)?, inner_class, tags, inner, found)?;
            }
        }
        Ok(())
    }

    /// The children of a body element (or the worldbody) attached to model body `body`, whose
    /// frame is at `to_element` (`X_{element←body}`); `source_body` is the element's MuJoCo body
    /// id.
    pub(super) fn read_children(
        &self,
        builder: &mut ModelBuilder,
        element: Node<'a, 'a>,
        (body, source_body): (usize, usize),
        to_element: Transform,
        class: &str,
    ) -> Result<()> {
        for child in self.children(element)? {
            match child.tag_name().name() {
                "site" => {
                    let name = child
                        .attribute("name")
                        .map_or_else(|| format!("site{}", child.range().start), str::to_string);
                    let site_class = self.declared_class(child, "class", class)?;
                    let kind = self
                        .attribute(child, site_class, "type")
                        .unwrap_or_else(|| "sphere".to_string());
                    let placement = match self.segment(child, site_class, &kind)? {
                        Some((segment, _)) => segment,
                        None => self.placement(child, site_class)?,
                    };
                    let placement = placement * to_element;
                    builder.add_frame(&name, body, placement);
                    let point = (body, placement.translation);
                    self.site_points.borrow_mut().insert(name.clone(), point);
                    self.site_bodies.borrow_mut().insert(name, source_body);
                }
                "body" => self.read_body(builder, child, (body, source_body), to_element, class)?,
                // a <frame> only places what it holds: its pose composes with theirs
                "frame" => {
                    let to_frame = self.placement(child, class)? * to_element;
                    let frame_class = self.declared_class(child, "childclass", class)?;
                    self.read_children(builder, child, (body, source_body), to_frame, frame_class)?;
                }
                // in a body's <frame>s they are read with the body; the world has none
                "joint" | "freejoint" | "inertial" if in_world_frame(element) => {
                    return Err(self.error(
                        child,
                        "the world body cannot have joints or an inertial (as in MuJoCo)",
                    ));
                }
                tag @ ("replicate" | "attach" | "composite" | "flexcomp") => {
                    return Err(self.error(child, format!("<{tag}> is not supported")));
                }
                "plugin" => self.warnings.borrow_mut().push(format!(
                    "{}: not read (robodyn runs no MuJoCo plugins: the forces it would add are \
                     left out)",
                    self.location(child)
                )),
                // joints, inertials and geoms are read with their body; cameras and lights are
                // not part of the tree
                _ => {}
            }
        }
        Ok(())
    }

    /// A body element under model body `parent` (whose file body is `parent_source`), where its
    /// parent element's frame is at `parent_element` (`X_{element←parent body}`).
    pub(super) fn read_body(
        &self,
        builder: &mut ModelBuilder,
        node: Node<'a, 'a>,
        (parent, parent_source): (usize, usize),
        parent_element: Transform,
        class: &str,
    ) -> Result<()> {
        let name = node
            .attribute("name")
            .map_or_else(|| format!("body{}", node.range().start), str::to_string);
        let child_class = self.declared_class(node, "childclass", class)?;
        self.warn_unmodelled(node, class);
        // MuJoCo numbers the file's bodies in document order, the world 0
        let source_body = {
            let mut bodies = self.source_bodies.borrow_mut();
            // a parent is no simple body
            bodies[parent_source].simple = false;
            bodies.push(SourceBody {
                name: name.clone(),
                parent: parent_source,
                body: parent,
                mass: 0.0,
                com: Vec3::zeros(),
                simple: false,
                gravcomp: self.own_number(node, "gravcomp")?.unwrap_or(0.0),
            });
            bodies.len() - 1
        };
        // X_{B←parent body}
        let mut to_body = self.placement(node, class)? * parent_element;
        let elements = self.children(node)?;
        let (inertia, axes) = self.body_inertia(&elements, child_class)?;
        let inertia = self
            .mass_rules
            .apply_to_body(inertia)
            .map_err(|m| self.error(node, m))?;
        self.total_mass.set(self.total_mass.get() + inertia.mass);
        // the body's joints, those in its <frame>s too, with X_{frame←body}
        let mut joints = Vec::new();
        self.framed_elements(
            &elements,
            child_class,
            &["joint", "freejoint"],
            Transform::IDENTITY,
            &mut joints,
        )?;
        if node.attribute("mocap") == Some("true") && !(joints.is_empty() && under_world(node)) {
            return Err(self.error(
                node,
                "a mocap body must be a child of the worldbody without joints, as MuJoCo requires",
            ));
        }
        if joints.is_empty() {
            // no joint: merged into the parent, kept as a frame
            self.record_source_mass(source_body, parent, &inertia, &to_body);
            builder.add_fixed_link(parent, to_body, inertia, &name);
            self.add_geoms(
                builder,
                &elements,
                child_class,
                (parent, source_body),
                to_body,
            )?;
            return self.read_children(builder, node, (parent, source_body), to_body, child_class);
        }
        let mut body = parent;
        let mut previous_position = Vec3::zeros();
        // MuJoCo's simple body: only slides at its origin along a coordinate axis (so far)
        let mut only_aligned_slides = true;
        for (k, (joint_node, to_frame, frame_class)) in joints.iter().enumerate() {
            let joint_class = self.declared_class(*joint_node, "class", frame_class)?;
            self.warn_unmodelled(*joint_node, joint_class);
            // a joint in a <frame> has its pos and axis in the frame's axes
            let in_body = to_frame.rotation.transpose();
            let kind = if joint_node.has_tag_name("freejoint") {
                "free".to_string()
            } else {
                self.attribute(*joint_node, joint_class, "type")
                    .unwrap_or_else(|| "hinge".to_string())
            };
            let axis = in_body
                * Vec3::from(
                    self.numbers::<3>(*joint_node, joint_class, "axis")?
                        .unwrap_or([0.0, 0.0, 1.0]),
                );
            let unit_axis = || {
                Unit::try_new(axis, 1e-12)
                    .map(|a| a.into_inner())
                    .ok_or_else(|| {
                        self.error(*joint_node, "attribute 'axis': expected a non-zero vector")
                    })
            };
            let joint = match kind.as_str() {
                "hinge" => Joint::Revolute { axis: unit_axis()? },
                "slide" => Joint::Prismatic { axis: unit_axis()? },
                "ball" => Joint::Spherical,
                "free" => Joint::Free,
                other => {
                    return Err(self.error(
                        *joint_node,
                        format!(
                            "unknown joint type '{other}': expected hinge, slide, ball or free"
                        ),
                    ))
                }
            };
            let position = if joint == Joint::Free {
                Vec3::zeros()
            } else {
                in_body
                    * Vec3::from(
                        self.numbers::<3>(*joint_node, joint_class, "pos")?
                            .unwrap_or([0.0; 3]),
                    )
                    + to_frame.translation
            };
            let aligned = axis.iter().filter(|x| x.abs() > AXIS_TOLERANCE).count() == 1;
            only_aligned_slides &= matches!(joint, Joint::Prismatic { .. })
                && aligned
                && position.abs().max() < FRAME_TOLERANCE;
            let scalar = |key: &str, default: f64| -> Result<f64> {
                Ok(self
                    .numbers::<1>(*joint_node, joint_class, key)?
                    .map_or(default, |[x]| x))
            };
            // a hinge's positions (range, ref, springref) are angles in the compiler's unit
            let position_unit = |x: f64| {
                if matches!(joint, Joint::Revolute { .. }) {
                    self.angle(x)
                } else {
                    x
                }
            };
            // "c c₁ c₂": a linear coefficient and up to two higher ones
            let polynomial = |key: &str| {
                let text = self.attribute(*joint_node, joint_class, key);
                self.spring_polynomial(*joint_node, key, text.as_deref())
            };
            let (stiffness, stiffness_poly) = polynomial("stiffness")?;
            let (damping, damping_poly) = polynomial("damping")?;
            let spring_yield =
                self.spring_yield(*joint_node, joint, scalar("springyield", 0.0)?)?;
            let mut properties = JointProperties {
                armature: scalar("armature", 0.0)?,
                damping,
                damping_poly,
                friction: scalar("frictionloss", 0.0)?,
                stiffness,
                stiffness_poly,
                spring_reference: position_unit(scalar("springref", 0.0)?),
                spring_yield,
                actuator_gravcomp: self.flag(*joint_node, joint_class, "actuatorgravcomp")?,
                softness: self.joint_softness(*joint_node, joint_class)?,
                ..JointProperties::default()
            };
            let limited = self.attribute(*joint_node, joint_class, "limited");
            let range = self.numbers::<2>(*joint_node, joint_class, "range")?;
            self.check_auto_limits(*joint_node, range.is_some(), limited.as_deref(), "limited")?;
            if let (true, Some([lower, upper])) = (limited.is_none_or(|l| l != "false"), range) {
                properties.lower = position_unit(lower);
                properties.upper = position_unit(upper);
                // a ball's limit is a cone: its largest angle
                if joint == Joint::Spherical {
                    properties.softness.cone_limit = Some(self.angle(lower.max(upper)));
                }
            }
            properties.actuator_force_range =
                self.actuator_force_range(*joint_node, joint_class)?;
            let spring_damper = self.spring_damper(*joint_node, joint_class)?;
            // `ref`: the joint position at which the body has its XML pose, so the joint moves
            // by q − ref: X_J(q − ref) X_tree = X_J(q) X_J(−ref) X_tree
            let reference = position_unit(scalar("ref", 0.0)?);
            let shift_by_reference = match (reference, joint.nq()) {
                (0.0, _) => Transform::IDENTITY,
                (_, 1) => joint.transform(&[-reference]),
                _ => {
                    return Err(self.error(
                        *joint_node,
                        "attribute 'ref': only hinge and slide joints take one",
                    ))
                }
            };
            // a free joint places the body in the world: its XML pose is only MuJoCo's qpos0
            let x_tree = if joint == Joint::Free {
                if k > 0 || !under_world(node) {
                    return Err(self.error(
                        *joint_node,
                        "a free joint must be the only joint of a child of the worldbody",
                    ));
                }
                self.warn_aligned_free_body(node, *joint_node);
                Transform::IDENTITY
            } else if k == 0 {
                // the joint frame sits at `pos` in the body's frame
                shift_by_reference * Transform::from_translation(&position) * to_body
            } else {
                shift_by_reference * Transform::from_translation(&(position - previous_position))
            };
            let joint_name = joint_node
                .attribute("name")
                .map_or_else(|| format!("{name}_joint{k}"), str::to_string);
            let last = k + 1 == joints.len();
            // the body's own frame, relative to the last joint frame: X_{B←J} = translation(-pos)
            let to_own_frame = if joint == Joint::Free {
                Transform::IDENTITY
            } else {
                Transform::from_translation(&(-position))
            };
            // the model body carries the MJCF body's name when their frames coincide
            let body_name = if last && to_own_frame == Transform::IDENTITY {
                name.clone()
            } else {
                format!("{name}/{joint_name}")
            };
            body = builder.add_body(NewBody {
                parent: body,
                joint,
                joint_name: &joint_name,
                x_tree,
                properties,
                name: &body_name,
                inertia: if last {
                    to_own_frame.transpose_apply_inertia(&inertia)
                } else {
                    Inertia::ZERO
                },
            })?;
            if let Some(spring_damper) = spring_damper {
                let own_damping = properties.damping;
                self.spring_dampers
                    .borrow_mut()
                    .push((body, spring_damper, own_damping));
            }
            // MuJoCo's qpos0: a hinge or slide at its ref, a free joint at the body's XML pose
            if joint == Joint::Free {
                builder.set_neutral(body, &free_joint_coordinates(&to_body))?;
            } else if joint.nq() == 1 {
                builder.set_neutral(body, &[reference])?;
            }
            previous_position = position;
            to_body = to_own_frame;
        }
        if to_body != Transform::IDENTITY {
            builder.add_frame(&name, body, to_body);
        }
        self.record_source_mass(source_body, body, &inertia, &to_body);
        // `simple="false"`: the file turns MuJoCo's simple-body shortcut off
        self.source_bodies.borrow_mut()[source_body].simple = only_aligned_slides
            && self.placed_simply(parent_source, parent)
            && own_frame(&inertia, axes)
            && node.attribute("simple") != Some("false");
        self.add_geoms(
            builder,
            &elements,
            child_class,
            (body, source_body),
            to_body,
        )?;
        self.read_children(builder, node, (body, source_body), to_body, child_class)
    }

    /// Whether a body under file body `parent_source` (model body `parent`) sits where MuJoCo's
    /// simple bodies do: a child of the world, or of a jointless child of it.
    fn placed_simply(&self, parent_source: usize, parent: usize) -> bool {
        let bodies = self.source_bodies.borrow();
        parent_source == 0 || (bodies[parent_source].parent == 0 && parent == 0)
    }

    /// The file body `source_body`'s own mass and centre of mass, in the frame of the model
    /// body `body` it moves with (`to_body`: X_{its frame←body}); its frame's origin when
    /// massless.
    fn record_source_mass(
        &self,
        source_body: usize,
        body: usize,
        inertia: &Inertia,
        to_body: &Transform,
    ) {
        let own = to_body.transpose_apply_inertia(inertia);
        let com = if inertia.mass > 0.0 {
            own.first_moment / own.mass
        } else {
            to_body.translation
        };
        let mut bodies = self.source_bodies.borrow_mut();
        let source = &mut bodies[source_body];
        (source.body, source.mass, source.com) = (body, inertia.mass, com);
    }
}

/// Below this an axis component counts as zero for MuJoCo's simple bodies (its `mjEPS`).
const AXIS_TOLERANCE: f64 = 1e-14;
/// Below this, entry by entry, a position (m) or a quaternion is the null pose for MuJoCo's simple
/// bodies (its compiler's `kFrameEps`).
const FRAME_TOLERANCE: f64 = 1e-6;
/// At most this many sweeps find a body's principal axes (a 3 × 3 tensor takes a handful).
const EIGEN_ITERATIONS: usize = 100;

/// Whether a body's inertia frame is its own (MuJoCo's `sameframe`): its centre of mass at its
/// origin and its principal axes, where MuJoCo's compiler puts them (`axes`), its own: the axes
/// given turned by nothing (a quarter turn that keeps the tensor diagonal still turns them), or,
/// found by eigen-decomposition, the moments in decreasing order along the body's axes (else
/// MuJoCo's axes are a permutation of the body's); each to [`FRAME_TOLERANCE`] entry by entry.
fn own_frame(inertia: &Inertia, axes: InertiaAxes) -> bool {
    let centre = inertia.first_moment / inertia.mass.max(f64::MIN_POSITIVE);
    if centre.abs().max() >= FRAME_TOLERANCE {
        return false;
    }
    let rotation = match axes {
        InertiaAxes::Given(rotation) => rotation,
        InertiaAxes::Principal => {
            // the eigenvectors by decreasing moment, each turned towards its body axis
            let Some(eigen) = inertia
                .rotational
                .try_symmetric_eigen(f64::EPSILON, EIGEN_ITERATIONS)
            else {
                return false;
            };
            let mut order = [0, 1, 2];
            order.sort_by(|&a, &b| eigen.eigenvalues[b].total_cmp(&eigen.eigenvalues[a]));
            Mat3::from_fn(|r, c| {
                let column = eigen.eigenvectors.column(order[c]);
                column[r] * column[c].signum()
            })
        }
    };
    // a permutation of the axes may be a reflection, which no quaternion is; q and −q are one turn
    let q = UnitQuaternion::from_matrix(&rotation);
    let null = |w: f64| {
        [q.w - w, q.i, q.j, q.k]
            .iter()
            .all(|x| x.abs() < FRAME_TOLERANCE)
    };
    rotation.determinant() > 0.0 && (null(1.0) || null(-1.0))
}
