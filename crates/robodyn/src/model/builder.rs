//! [`ModelBuilder`]: a model built body by body, as every loader builds one.

use super::{
    check_unit_quaternion, run_start, tree_transform, Frame, Geom, JointProperties, JointSoftness,
    Mimic, Model, SimulationOptions, STANDARD_GRAVITY,
};
use crate::error::{Error, Result};
use crate::joint::Joint;
use crate::spatial::{Inertia, Transform, Vec3};
use crate::visual::{Texture, Visual};
use nalgebra::DVector;

/// A moving body for [`ModelBuilder::add_body`].
#[derive(Debug, Clone)]
pub struct NewBody<'a> {
    /// Index of the parent body (0 = world).
    pub parent: usize,
    /// The joint connecting it to its parent.
    pub joint: Joint,
    /// The joint's name.
    pub joint_name: &'a str,
    /// Featherstone's `X_T`: from the parent body's frame to the joint frame.
    pub x_tree: Transform,
    /// The joint's limits, armature, damping, friction and spring.
    pub properties: JointProperties,
    /// The body's (link's) name.
    pub name: &'a str,
    /// Spatial inertia in the body's own frame.
    pub inertia: Inertia,
}

/// Builds a [`Model`] body by body; every loader ends here.
#[derive(Debug, Clone)]
pub struct ModelBuilder {
    model: Model,
}

impl ModelBuilder {
    /// A model holding only the world (body 0), named `world_name`.
    pub fn new(name: &str, world_name: &str) -> Self {
        ModelBuilder {
            model: Model {
                name: name.to_string(),
                nq: 0,
                nv: 0,
                parent: vec![0],
                joints: vec![Joint::Fixed],
                joint_names: vec!["universe".into()],
                body_names: vec![world_name.to_string()],
                x_tree: vec![Transform::IDENTITY],
                inertias: vec![Inertia::ZERO],
                idx_q: vec![0],
                idx_v: vec![0],
                dof_parent: Vec::new(),
                dof_run_start: Vec::new(),
                subtree_dof_end: None,
                turns: Vec::new(),
                subspace_components: Vec::new(),
                lower_position_limit: DVector::zeros(0),
                upper_position_limit: DVector::zeros(0),
                velocity_limit: DVector::zeros(0),
                effort_limit: DVector::zeros(0),
                armature: DVector::zeros(0),
                damping: DVector::zeros(0),
                friction: DVector::zeros(0),
                stiffness: DVector::zeros(0),
                stiffness_poly: Vec::new(),
                damping_poly: Vec::new(),
                spring_reference: DVector::zeros(0),
                neutral_configuration: DVector::zeros(0),
                frames: Vec::new(),
                gravity: Vec3::new(0.0, 0.0, -STANDARD_GRAVITY),
                mimics: Vec::new(),
                constraints: Vec::new(),
                keyframes: Vec::new(),
                actuators: Vec::new(),
                tendons: Vec::new(),
                tendon_equalities: Vec::new(),
                unread: Default::default(),
                actuator_force_range: vec![None],
                joint_softness: vec![JointSoftness::default()],
                spring_yield: vec![0.0],
                actuator_gravcomp: vec![false],
                geoms: Vec::new(),
                source_bodies: Vec::new(),
                contact_pairs: Vec::new(),
                contact_excludes: Vec::new(),
                options: SimulationOptions::default(),
                warnings: Vec::new(),
                visuals: Vec::new(),
                skybox: None,
            },
        }
    }

    /// Adds a moving body (see [`NewBody`]) and a frame with its name. Returns the body index.
    pub fn add_body(&mut self, body: NewBody) -> Result<usize> {
        let NewBody {
            parent,
            joint,
            joint_name,
            x_tree,
            properties,
            name,
            inertia,
        } = body;
        let m = &mut self.model;
        if parent >= m.parent.len() {
            return Err(Error::model(
                format!("joint '{joint_name}'"),
                format!("parent body {parent} does not exist"),
            ));
        }
        if matches!(joint, Joint::Fixed) {
            return Err(Error::model(
                format!("joint '{joint_name}'"),
                "a fixed joint is merged with add_fixed_link, not added as a body",
            ));
        }
        let index = m.parent.len();
        m.parent.push(parent);
        m.joints.push(joint);
        m.joint_names.push(joint_name.to_string());
        m.body_names.push(name.to_string());
        m.x_tree.push(tree_transform(x_tree));
        m.inertias.push(inertia);
        m.joint_softness.push(properties.softness);
        m.spring_yield.push(properties.spring_yield);
        m.actuator_gravcomp.push(properties.actuator_gravcomp);
        m.actuator_force_range.push(properties.actuator_force_range);
        m.idx_q.push(m.nq);
        m.idx_v.push(m.nv);
        let (nq, nv) = (joint.nq(), joint.nv());
        // the first coordinate hangs from the last of the nearest ancestor joint that moves
        let mut ancestor = parent;
        while ancestor != 0 && m.joints[ancestor].nv() == 0 {
            ancestor = m.parent[ancestor];
        }
        let mut previous = (ancestor != 0).then(|| m.idx_v[ancestor] + m.joints[ancestor].nv() - 1);
        for k in m.nv..m.nv + nv {
            m.dof_parent.push(previous);
            m.dof_run_start
                .push(run_start(&m.dof_run_start, previous, k));
            previous = Some(k);
        }
        m.nq += nq;
        m.nv += nv;
        // quaternion coordinates carry no limits
        let limited = joint.quaternion_offset().is_none();
        let extend = |v: &mut DVector<f64>, n: usize, value: f64| {
            *v = DVector::from_iterator(
                v.len() + n,
                v.iter().copied().chain(std::iter::repeat_n(value, n)),
            );
        };
        let (lower, upper) = if limited {
            (properties.lower, properties.upper)
        } else {
            (f64::NEG_INFINITY, f64::INFINITY)
        };
        extend(&mut m.lower_position_limit, nq, lower);
        extend(&mut m.upper_position_limit, nq, upper);
        extend(&mut m.velocity_limit, nv, properties.velocity_limit);
        extend(&mut m.effort_limit, nv, properties.effort_limit);
        extend(&mut m.armature, nv, properties.armature);
        extend(&mut m.damping, nv, properties.damping);
        extend(&mut m.friction, nv, properties.friction);
        extend(&mut m.stiffness, nv, properties.stiffness);
        m.stiffness_poly
            .extend(std::iter::repeat_n(properties.stiffness_poly, nv));
        m.damping_poly
            .extend(std::iter::repeat_n(properties.damping_poly, nv));
        extend(&mut m.spring_reference, nq, properties.spring_reference);
        extend(&mut m.neutral_configuration, nq, 0.0);
        joint.neutral(&mut m.neutral_configuration.as_mut_slice()[m.nq - nq..]);
        if nq > 1 {
            joint.neutral(&mut m.spring_reference.as_mut_slice()[m.nq - nq..]);
        }
        m.frames.push(Frame {
            name: name.to_string(),
            body: index,
            placement: Transform::IDENTITY,
        });
        Ok(index)
    }

    /// Merges a link attached by a fixed joint into `body`: `placement` is `X_{link←body}`,
    /// `inertia` the link's spatial inertia in its own frame. The link stays as a frame.
    pub fn add_fixed_link(
        &mut self,
        body: usize,
        placement: Transform,
        inertia: Inertia,
        name: &str,
    ) {
        let merged = placement.transpose_apply_inertia(&inertia);
        self.model.inertias[body] += merged;
        self.add_frame(name, body, placement);
    }

    /// Scales every body's mass and inertia by `factor` (MJCF's `settotalmass`).
    pub fn scale_inertias(&mut self, factor: f64) {
        for inertia in &mut self.model.inertias {
            inertia.mass *= factor;
            inertia.first_moment *= factor;
            inertia.rotational *= factor;
        }
    }

    /// Adds a piece of visual geometry.
    pub fn add_visual(&mut self, visual: Visual) {
        self.model.visuals.push(visual);
    }

    /// Sets the scene's background texture.
    pub fn set_skybox(&mut self, texture: Texture) {
        self.model.skybox = Some(texture);
    }

    /// Adds a named frame on `body` at `placement` (`X_{frame←body}`).
    pub fn add_frame(&mut self, name: &str, body: usize, placement: Transform) {
        self.model.frames.push(Frame {
            name: name.to_string(),
            body,
            placement,
        });
    }

    /// Records a mimic relation between two joints (body indices).
    pub fn add_mimic(&mut self, mimic: Mimic) {
        self.model.mimics.push(mimic);
    }

    /// Records something the user should know about the model.
    pub fn warn(&mut self, message: String) {
        self.model.warnings.push(message);
    }

    /// Sets body `body`'s joint coordinates in the neutral configuration (the pose the file
    /// draws, [`Model::neutral`]); a quaternion among them must have unit norm. A free joint's
    /// spring relaxes there too (MuJoCo's `qpos_spring` is `qpos0` for a free joint).
    pub fn set_neutral(&mut self, body: usize, q: &[f64]) -> Result<()> {
        let m = &mut self.model;
        let joint_name = m.joint_names.get(body).cloned().unwrap_or_default();
        let refuse = |message: String| Err(Error::model(format!("joint '{joint_name}'"), message));
        if body == 0 || body >= m.parent.len() {
            return refuse(format!("body {body} does not exist or has no joint"));
        }
        let joint = m.joints[body];
        if q.len() != joint.nq() {
            return refuse(format!(
                "expected {} neutral coordinates, got {}",
                joint.nq(),
                q.len()
            ));
        }
        if let Some(offset) = joint.quaternion_offset() {
            if let Err(norm) = check_unit_quaternion(&q[offset..offset + 4]) {
                return refuse(format!(
                    "the neutral quaternion has norm {norm}, expected 1"
                ));
            }
        }
        let start = m.idx_q[body];
        m.neutral_configuration.as_mut_slice()[start..start + q.len()].copy_from_slice(q);
        if joint == Joint::Free {
            m.spring_reference.as_mut_slice()[start..start + q.len()].copy_from_slice(q);
        }
        Ok(())
    }

    /// Adds a collision shape.
    pub fn add_geom(&mut self, geom: Geom) {
        self.model.geoms.push(geom);
    }

    /// Sets the gravity vector.
    pub fn gravity(&mut self, gravity: Vec3) {
        self.model.gravity = gravity;
    }

    /// The finished model.
    pub fn build(mut self) -> Model {
        self.model.derive();
        self.model
    }
}
