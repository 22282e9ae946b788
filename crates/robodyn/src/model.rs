//! The model: topology and constants of a robot. Algorithms never mutate it; everything they
//! write goes into [`crate::Data`].

mod actuator;
mod builder;
mod derived;
mod geom;
mod keyframe;
mod options;
mod physical;
pub mod plastic;
mod springs;
mod tendon;

pub use actuator::{ActivationDynamics, Actuator, ActuatorForce};
pub use builder::{ModelBuilder, NewBody};
use derived::run_start;
pub(crate) use derived::tree_transform;
pub use derived::AncestorRuns;
pub use geom::{
    ContactExclude, ContactPair, ContactParameters, Geom, JointSoftness, SourceBody,
    CONTACT_DIMENSIONS, DEFAULT_GEOM_FRICTION, DEFAULT_PAIR_FRICTION,
};
pub use keyframe::Keyframe;
pub use options::{
    ConstraintSolver, FrictionCone, Integrator, SimulationOptions, SolverParameters,
    DEFAULT_SOLIMP, DEFAULT_SOLREF, DISABLE_FLAGS, ENABLE_FLAGS,
};
pub use physical::{
    check_mass_and_inertia, check_physical_parameters, check_positive_semidefinite, Unphysical,
};
pub use plastic::{PlasticSlot, SpringReferences};
pub use tendon::{PathPoint, PathSite, Tendon, TendonEquality, UnreadElements};

use crate::error::{check_length, check_vector, Error, Result};
use crate::joint::{Joint, MotionSubspace};
use crate::spatial::{Inertia, Mat3, Transform, Turn, Vec3};
use crate::visual::{Texture, Visual};
use nalgebra::DVector;
use rand::Rng;

/// How far a quaternion in q may be from unit norm before it is rejected.
pub const QUATERNION_NORM_TOLERANCE: f64 = 1e-6;
/// Slack allowed when checking that a rotational inertia is positive semi-definite, relative to
/// its largest entry ...
pub const INERTIA_EIGENVALUE_TOLERANCE: f64 = 1e-9;
/// ... and in absolute terms (kg m²), so that round-off on a near-zero tensor is accepted.
pub const INERTIA_ABSOLUTE_TOLERANCE: f64 = 1e-12;
/// How far a tree transform's rotation E may be from orthonormal (`|EᵀE − 1|`, largest entry)
/// before [`Model::set_tree_transform`] rejects it.
pub const ROTATION_TOLERANCE: f64 = 1e-9;
/// Standard gravity, m/s², used by the default gravity vector `[0, 0, -9.81]`.
pub const STANDARD_GRAVITY: f64 = 9.81;

/// A named frame rigidly attached to a body: a URDF link (moving or merged through a fixed joint)
/// or a user frame.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Frame {
    /// The frame's name (a link's or a user frame's).
    pub name: String,
    /// The body it is attached to (0 = world).
    pub body: usize,
    /// `X_{frame←body}`: the frame's placement relative to its body.
    pub placement: Transform,
}

/// A mimic relation from URDF: `q[joint] = multiplier * q[mimicked] + offset`. robodyn keeps both
/// joints independent and reports the relation; enforcing it is the caller's choice.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Mimic {
    /// Body index of the mimicking joint.
    pub joint: usize,
    /// Body index of the mimicked joint.
    pub mimicked: usize,
    /// Factor applied to the mimicked joint's position.
    pub multiplier: f64,
    /// Offset added after the factor (rad or m).
    pub offset: f64,
}

/// Per-joint constants other than its kind and placement. Scalars apply to every velocity
/// coordinate of the joint; limits to every configuration coordinate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointProperties {
    /// Lower position limit (rad or m; -inf where none).
    pub lower: f64,
    /// Upper position limit (rad or m; +inf where none).
    pub upper: f64,
    /// Velocity limit (rad/s or m/s; inf where none).
    pub velocity_limit: f64,
    /// Effort limit (N·m or N; inf where none).
    pub effort_limit: f64,
    /// Rotor inertia reflected through the transmission; adds to M's diagonal.
    pub armature: f64,
    /// Viscous damping coefficient (torque or force per unit velocity).
    pub damping: f64,
    /// Dry (Coulomb) friction torque or force.
    pub friction: f64,
    /// Joint spring stiffness (MJCF `stiffness`), pulling q towards `spring_reference`.
    pub stiffness: f64,
    /// The spring's higher coefficients k₁, k₂ (MJCF `stiffness="k k₁ k₂"`): its force is
    /// −x (k + k₁ x + k₂ x²) ([`Model::spring_forces`]).
    pub stiffness_poly: [f64; 2],
    /// The damper's higher coefficients b₁, b₂ (MJCF `damping="b b₁ b₂"`): its force is
    /// −q̇ (b + b₁ |q̇| + b₂ q̇²) ([`Model::damper_force`]).
    pub damping_poly: [f64; 2],
    /// The position at which the spring is relaxed (MJCF `springref`); one-coordinate joints only.
    pub spring_reference: f64,
    /// The spring's yield (MJCF `springyield`, rad or m; 0: elastic): past it the reference
    /// moves ([`Model::yield_springs`]). Hinges, slides and balls only.
    pub spring_yield: f64,
    /// Whether its bodies' gravity compensation (`gravcomp`) is an actuator force on it (MJCF
    /// `actuatorgravcomp`: counted in `qfrc_actuator` and clamped with the actuators' by
    /// `actuator_force_range`) rather than a passive one.
    pub actuator_gravcomp: bool,
    /// How its limit and dry friction act in MuJoCo's soft constraint model.
    pub softness: JointSoftness,
    /// The range the total actuator force on it is clamped to (MJCF `actuatorfrcrange`);
    /// one-coordinate joints only.
    pub actuator_force_range: Option<(f64, f64)>,
}

impl Default for JointProperties {
    fn default() -> Self {
        JointProperties {
            lower: f64::NEG_INFINITY,
            upper: f64::INFINITY,
            velocity_limit: f64::INFINITY,
            effort_limit: f64::INFINITY,
            armature: 0.0,
            damping: 0.0,
            friction: 0.0,
            stiffness: 0.0,
            stiffness_poly: [0.0; 2],
            damping_poly: [0.0; 2],
            spring_reference: 0.0,
            spring_yield: 0.0,
            actuator_gravcomp: false,
            softness: JointSoftness::default(),
            actuator_force_range: None,
        }
    }
}

/// A rigid multibody tree. Bodies are numbered so that `parent[i] < i`; body 0 is the world and
/// has no joint (`Joint::Fixed`). Body `i ≥ 1` moves relative to its parent through `joints[i]`.
/// The tree's structure (`parent`, `joints`, `idx_q`, `idx_v`, `dof_parent`) is made by
/// [`ModelBuilder`] and read through its accessors ([`Model::parent`], …): add bodies with a
/// builder instead. What the algorithms derive from it and from the tree transforms (each
/// joint's turn and motion subspace components, the coordinates' runs and subtrees) is private
/// and found again by every method that changes its sources ([`Model::set_tree_transform`]).
/// Values (inertias, limits, armature, gravity) are public fields and may be edited.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Model {
    /// The model's name (the URDF robot name, for instance).
    pub name: String,
    /// Number of configuration coordinates.
    pub nq: usize,
    /// Number of velocity coordinates (degrees of freedom).
    pub nv: usize,
    /// Parent body of each body (`parent[0] = 0`).
    pub(crate) parent: Vec<usize>,
    /// Joint of each body (`joints[0] = Joint::Fixed`, the world).
    pub(crate) joints: Vec<Joint>,
    /// Name of each body's joint (`"universe"` for the world).
    pub joint_names: Vec<String>,
    /// Name of each body (its link).
    pub body_names: Vec<String>,
    /// `x_tree[i]`: Featherstone's `X_T`, from the parent body frame to body i's joint frame.
    pub(crate) x_tree: Vec<Transform>,
    /// Spatial inertia of each body about its own origin, in its own axes (fixed links merged).
    pub inertias: Vec<Inertia>,
    /// First index of body i's joint in q.
    pub(crate) idx_q: Vec<usize>,
    /// First index of body i's joint in v.
    pub(crate) idx_v: Vec<usize>,
    /// The parent of each velocity coordinate: the one before it in its joint, or the last of the
    /// nearest ancestor body's joint (`None` at a root); nv. M_ij ≠ 0 only along these chains.
    pub(crate) dof_parent: Vec<Option<usize>>,
    /// Derived from `dof_parent`, nv: the first coordinate of the run ending at coordinate k in
    /// which each coordinate is the parent of the next (`dof_parent[c] = c - 1`). The ancestors
    /// of a coordinate are a few such runs, so a loop over them need not wait on each parent's
    /// load before the next column (see [`Model::ancestor_runs`]). Not stored in snapshots.
    #[serde(skip)]
    dof_run_start: Vec<usize>,
    /// Derived from `parent` and `idx_v` when the model is built, nbodies: one past the last
    /// velocity coordinate of body i's subtree, whose coordinates are then `idx_v[i]..end` —
    /// when the bodies are in depth-first order (each subtree's bodies follow its root without
    /// a gap, as every loader adds them); `None` otherwise. Not stored in snapshots.
    #[serde(skip)]
    subtree_dof_end: Option<Vec<usize>>,
    /// Derived from `joints` and `x_tree` when the model is built, nbodies: [`Joint::turn`] of
    /// each body (asked by every transform of every call, so found once). Not stored in
    /// snapshots.
    #[serde(skip)]
    turns: Vec<Option<Turn>>,
    /// Derived from `joints` when the model is built, nv: [`Joint::subspace_component`] of
    /// each velocity coordinate (asked for every coordinate of every mass matrix, so found
    /// once). Not stored in snapshots.
    #[serde(skip)]
    subspace_components: Vec<Option<(usize, bool)>>,
    /// Lower position limits, length nq (-inf where none).
    pub lower_position_limit: DVector<f64>,
    /// Upper position limits, length nq (+inf where none).
    pub upper_position_limit: DVector<f64>,
    /// Velocity limits, length nv (inf where none).
    pub velocity_limit: DVector<f64>,
    /// Effort limits, length nv (inf where none).
    pub effort_limit: DVector<f64>,
    /// Rotor inertia per velocity coordinate, added to M's diagonal, RNEA and ABA.
    pub armature: DVector<f64>,
    /// Viscous damping per velocity coordinate (kept for simulation; the dynamics algorithms do
    /// not apply it).
    pub damping: DVector<f64>,
    /// Dry friction per velocity coordinate (kept for simulation, like damping).
    pub friction: DVector<f64>,
    /// Joint spring stiffness per velocity coordinate, length nv. Kept for simulation, like
    /// damping and friction.
    pub stiffness: DVector<f64>,
    /// The springs' higher coefficients (k₁, k₂) per velocity coordinate, length nv (the
    /// joint's on each of its coordinates; [`Model::spring_forces`]).
    pub stiffness_poly: Vec<[f64; 2]>,
    /// The dampers' higher coefficients (b₁, b₂) per velocity coordinate, length nv
    /// ([`Model::damper_force`]).
    pub damping_poly: Vec<[f64; 2]>,
    /// The configuration where the joint springs are relaxed, length nq (the neutral
    /// configuration for spherical and free joints).
    pub spring_reference: DVector<f64>,
    /// The configuration [`Model::neutral`] returns, length nq: zero angles and displacements and
    /// identity quaternions, except where the loader knows the pose the file draws (an MJCF
    /// model's MuJoCo `qpos0`: a free joint at its body's pose in the file, a hinge or slide at
    /// its `ref`).
    pub neutral_configuration: DVector<f64>,
    /// Named frames: one per link, moving or merged.
    pub frames: Vec<Frame>,
    /// Gravitational acceleration in world axes.
    pub gravity: Vec3,
    /// Mimic relations, reported, not enforced.
    pub mimics: Vec<Mimic>,
    /// The constraints the model file declares (MJCF `<equality>`), active or not.
    #[serde(default)]
    pub constraints: Vec<crate::constraint::ModelConstraint>,
    /// The states the model file names (MJCF `<keyframe>`), in its order.
    #[serde(default)]
    pub keyframes: Vec<Keyframe>,
    /// The actuators (MJCF `<actuator>`), in the file's order: the controls' order.
    #[serde(default)]
    pub actuators: Vec<Actuator>,
    /// The tendons (MJCF `<tendon>`: fixed, and spatial ones through sites), in the file's order.
    #[serde(default)]
    pub tendons: Vec<Tendon>,
    /// The equalities between tendon lengths (MJCF `<equality><tendon>`), in the file's order.
    #[serde(default)]
    pub tendon_equalities: Vec<TendonEquality>,
    /// Where the file's tendons and equalities that robodyn does not read sit among those it
    /// reads, so that rows carry MuJoCo's ids ([`UnreadElements::mujoco_id`]).
    #[serde(default)]
    pub unread: UnreadElements,
    /// The range each body's joint's total actuator force is clamped to (MJCF
    /// `actuatorfrcrange`), nbodies; read for hinges and slides only.
    #[serde(default)]
    pub actuator_force_range: Vec<Option<(f64, f64)>>,
    /// Each body's joint limit and dry friction in MuJoCo's soft constraint model, nbodies (the
    /// world's unused).
    #[serde(default)]
    pub joint_softness: Vec<JointSoftness>,
    /// Each body's joint spring yield (MJCF `springyield`; 0: elastic), nbodies (the world's
    /// 0): its plastic state [`Model::plastic_slots`].
    pub spring_yield: Vec<f64>,
    /// Each body's joint's `actuatorgravcomp` ([`JointProperties::actuator_gravcomp`]), nbodies.
    pub actuator_gravcomp: Vec<bool>,
    /// The collision shapes (MJCF geoms), in the file's order.
    #[serde(default)]
    pub geoms: Vec<Geom>,
    /// The file's bodies by MuJoCo body id (the world first), which [`Geom::source_body`] and
    /// [`ContactExclude`] number; empty for a model from another format.
    #[serde(default)]
    pub source_bodies: Vec<SourceBody>,
    /// The geom pairs the file asks to be checked for contact (MJCF `<contact><pair>`).
    #[serde(default)]
    pub contact_pairs: Vec<ContactPair>,
    /// The file's bodies whose geoms never touch (MJCF `<contact><exclude>`).
    #[serde(default)]
    pub contact_excludes: Vec<ContactExclude>,
    /// How the file asks to be simulated (MJCF `<option>`; MuJoCo's defaults otherwise).
    #[serde(default)]
    pub options: SimulationOptions,
    /// What the loader accepted but the user should know (ignored tags, unchecked inertias).
    pub warnings: Vec<String>,
    /// What the links look like (URDF `<visual>`, MJCF geoms); only the viewer reads it.
    pub visuals: Vec<Visual>,
    /// The scene's background (MJCF's first `<texture type="skybox">`); only the viewer reads it.
    pub skybox: Option<Texture>,
}

impl Model {
    /// Number of bodies including the world.
    pub fn nbodies(&self) -> usize {
        self.parent.len()
    }

    /// Index of the frame called `name`.
    pub fn frame_index(&self, name: &str) -> Result<usize> {
        self.frames
            .iter()
            .position(|f| f.name == name)
            .ok_or_else(|| Error::UnknownFrame {
                name: name.to_string(),
                available: format!(
                    "[{}]",
                    self.frames
                        .iter()
                        .map(|f| format!("'{}'", f.name))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            })
    }

    /// The coordinates from `top` to the root (`top`, its parent, …), as runs of consecutive
    /// coordinates, nearest first, each a non-empty `start..end`.
    #[inline(always)]
    pub fn ancestor_runs(&self, top: usize) -> AncestorRuns<'_> {
        AncestorRuns {
            model: self,
            top: Some(top),
        }
    }

    /// Whether velocity coordinates `a` and `b` lie on one branch of the tree (one is the other
    /// or among its ancestors): where M_ab may be nonzero (MuJoCo's sparsity of M).
    pub fn dofs_on_one_branch(&self, a: usize, b: usize) -> bool {
        let (top, mut below) = (a.min(b), Some(a.max(b)));
        while let Some(k) = below.filter(|k| *k > top) {
            below = self.dof_parent[k];
        }
        below == Some(top)
    }

    /// Parent body of each body (`parent()[0] = 0`).
    pub fn parent(&self) -> &[usize] {
        &self.parent
    }

    /// Joint of each body (`joints()[0] = Joint::Fixed`, the world).
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// `x_tree()[i]`: Featherstone's `X_T`, from the parent body frame to body i's joint frame.
    pub fn x_tree(&self) -> &[Transform] {
        &self.x_tree
    }

    /// First index of each body's joint in q.
    pub fn idx_q(&self) -> &[usize] {
        &self.idx_q
    }

    /// First index of each body's joint in v.
    pub fn idx_v(&self) -> &[usize] {
        &self.idx_v
    }

    /// The parent of each velocity coordinate: the one before it in its joint, or the last of the
    /// nearest ancestor body's joint (`None` at a root); nv. M_ij ≠ 0 only along these chains.
    pub fn dof_parent(&self) -> &[Option<usize>] {
        &self.dof_parent
    }

    /// For bodies in depth-first order (each subtree's bodies follow its root without a gap, as
    /// every loader adds them), one past the last velocity coordinate of each body's subtree,
    /// whose coordinates are then `idx_v[i]..end`; `None` otherwise.
    pub fn subtree_dof_end(&self) -> Option<&[usize]> {
        self.subtree_dof_end.as_deref()
    }

    /// The first coordinate of the run of parent-linked coordinates ending at each coordinate
    /// (see [`Model::ancestor_runs`]); nv.
    pub fn dof_run_start(&self) -> &[usize] {
        &self.dof_run_start
    }

    /// Sets body i's tree transform `X_T` (parent frame to joint frame; `1 ≤ i < nbodies`) and
    /// finds again what the algorithms derive from it (the joint's turn), so that every
    /// algorithm computes with the new placement. A rotation within round-off of a quarter-turn
    /// pattern is stored exactly, as the builder stores it.
    pub fn set_tree_transform(&mut self, i: usize, x_tree: Transform) -> Result<()> {
        let refuse = |message: String| {
            Err(Error::InvalidValue {
                argument: "x_tree".into(),
                message,
            })
        };
        if i == 0 || i >= self.nbodies() {
            return refuse(format!(
                "expected a moving body 1..{}, got {i}",
                self.nbodies()
            ));
        }
        let (rotation, translation) = (&x_tree.rotation, &x_tree.translation);
        if rotation
            .iter()
            .chain(translation.iter())
            .any(|x| !x.is_finite())
        {
            return refuse(format!("body {i}: expected finite entries"));
        }
        let departure = (rotation.transpose() * rotation - Mat3::identity())
            .abs()
            .max();
        if departure > ROTATION_TOLERANCE || rotation.determinant() < 0.0 {
            return refuse(format!(
                "body {i}: expected a rotation (EᵀE = 1 within {ROTATION_TOLERANCE:e}, det E = 1), \
                 got EᵀE off by {departure:e} and det E = {}",
                rotation.determinant()
            ));
        }
        self.x_tree[i] = tree_transform(x_tree);
        self.derive();
        Ok(())
    }

    /// The same model with every joint taking the general products (no turn, no motion subspace
    /// component): the same values, computed as for any joint axis and tree rotation. For tests
    /// and benchmarks of the specialisations.
    pub fn without_joint_specialisations(&self) -> Model {
        let mut general = self.clone();
        general.turns = vec![None; self.nbodies()];
        general.subspace_components = vec![None; self.nv];
        general
    }

    /// The same model taking the forms the algorithms have for bodies out of depth-first order
    /// (no [`Model::subtree_dof_end`]: CRBA in world coordinates). For tests and benchmarks of
    /// the two forms.
    pub fn without_subtree_order(&self) -> Model {
        let mut model = self.clone();
        model.subtree_dof_end = None;
        model
    }

    /// [`Joint::turn`] of body i's joint and tree transform.
    #[inline(always)]
    pub fn turn(&self, i: usize) -> Option<Turn> {
        // none where the model was not built (any rotation: the same values, more products)
        self.turns.get(i).copied().flatten()
    }

    /// [`Joint::subspace_component`] of body i's joint's coordinate k.
    #[inline(always)]
    pub fn subspace_component(&self, i: usize, k: usize) -> Option<(usize, bool)> {
        match self.subspace_components.get(self.idx_v[i] + k) {
            Some(component) => *component,
            // a model that was not built: asked of the joint
            None => self.joints[i].subspace_component(k),
        }
    }

    /// `Some((c, negative))` where body i's joint has one velocity coordinate whose motion
    /// subspace is the unit motion ±e_c ([`Joint::subspace_component`]): `S q̇` is then one
    /// component.
    #[inline(always)]
    pub fn unit_axis(&self, i: usize) -> Option<(usize, bool)> {
        if self.joints[i].nv() == 1 {
            self.subspace_component(i, 0)
        } else {
            None
        }
    }

    /// Body i's motion subspace as the algorithms take it: one coordinate axis where
    /// [`Model::unit_axis`] finds one, else the joint's columns with their
    /// [`Model::subspace_component`]s.
    #[inline(always)]
    pub(crate) fn subspace(&self, i: usize) -> MotionSubspace<'_> {
        match self.unit_axis(i) {
            Some((c, negative)) => MotionSubspace::Axis {
                c,
                negative,
                dof: self.idx_v[i],
            },
            None => MotionSubspace::Columns {
                joint: &self.joints[i],
                first: self.idx_v[i],
                // empty where the model was not built: asked of the joint
                components: self.subspace_components.get(self.v_range(i)).unwrap_or(&[]),
            },
        }
    }

    /// The range of body i's coordinates in q.
    pub fn q_range(&self, i: usize) -> std::ops::Range<usize> {
        self.idx_q[i]..self.idx_q[i] + self.joints[i].nq()
    }

    /// The range of body i's coordinates in v.
    pub fn v_range(&self, i: usize) -> std::ops::Range<usize> {
        self.idx_v[i]..self.idx_v[i] + self.joints[i].nv()
    }

    /// The neutral configuration ([`Model::neutral_configuration`]): zero angles and
    /// displacements and identity quaternions for URDF and DH models; an MJCF model's MuJoCo
    /// `qpos0`, the pose its file draws.
    pub fn neutral(&self) -> DVector<f64> {
        self.neutral_configuration.clone()
    }

    /// A random configuration within the position limits (see [`Joint::random`]).
    pub fn random_configuration<R: Rng>(&self, rng: &mut R) -> DVector<f64> {
        let mut q = DVector::zeros(self.nq);
        for i in 1..self.nbodies() {
            let range = self.q_range(i);
            self.joints[i].random(
                rng,
                &self.lower_position_limit.as_slice()[range.clone()],
                &self.upper_position_limit.as_slice()[range.clone()],
                &mut q.as_mut_slice()[range],
            );
        }
        q
    }

    /// Checks a configuration: length nq, finite, unit quaternions.
    pub fn check_configuration(&self, q: &[f64]) -> Result<()> {
        check_vector("q", q, self.nq)?;
        // only the quaternion joints (spherical, free) have more coordinates than velocities,
        // one more each: the search ends at the last of them (a floating base's is the first)
        let mut quaternions = self.nq - self.nv;
        for i in 1..self.nbodies() {
            if quaternions == 0 {
                break;
            }
            if let Some(offset) = self.joints[i].quaternion_offset() {
                quaternions -= 1;
                let start = self.idx_q[i] + offset;
                if let Err(norm) = check_unit_quaternion(&q[start..start + 4]) {
                    return Err(Error::InvalidValue {
                        argument: "q".into(),
                        message: format!(
                            "expected a unit quaternion [qx, qy, qz, qw] at q[{}..{}] (joint '{}'), \
                             got norm {norm}",
                            start,
                            start + 4,
                            self.joint_names[i]
                        ),
                    });
                }
            }
        }
        Ok(())
    }

    /// `q ⊕ v`: integrates every joint on its Lie group for unit time (scale v for a time step).
    pub fn integrate(&self, q: &[f64], v: &[f64], out: &mut [f64]) -> Result<()> {
        self.check_configuration(q)?;
        check_vector("v", v, self.nv)?;
        check_length("out", out.len(), self.nq)?;
        for i in 1..self.nbodies() {
            self.joints[i].integrate(
                &q[self.q_range(i)],
                &v[self.v_range(i)],
                &mut out[self.q_range(i)],
            );
        }
        Ok(())
    }

    /// `q1 ⊖ q0`: the velocity that integrates q0 into q1 in unit time.
    pub fn difference(&self, q0: &[f64], q1: &[f64], v: &mut [f64]) -> Result<()> {
        self.check_configuration(q0)?;
        self.check_configuration(q1)?;
        check_length("out", v.len(), self.nv)?;
        for i in 1..self.nbodies() {
            self.joints[i].difference(
                &q0[self.q_range(i)],
                &q1[self.q_range(i)],
                &mut v[self.v_range(i)],
            );
        }
        Ok(())
    }

    /// Checks a per-coordinate armature for this model (non-negative everywhere is the caller's
    /// check): a free joint's must be the same on its three linear coordinates.
    pub fn check_armature(&self, armature: &[f64]) -> Result<()> {
        for i in 1..self.nbodies() {
            self.joints[i]
                .check_armature(&armature[self.v_range(i)])
                .map_err(|message| Error::InvalidValue {
                    argument: "armature".into(),
                    message: format!("joint '{}': {message}", self.joint_names[i]),
                })?;
        }
        Ok(())
    }

    /// The ten standard inertial parameters [m, m c, Ī_O] of every moving body, in body order
    /// (see [`Inertia::to_parameters`]).
    pub fn inertial_parameters(&self) -> Vec<[f64; 10]> {
        self.inertias[1..]
            .iter()
            .map(Inertia::to_parameters)
            .collect()
    }

    /// Replaces the inertia of every moving body by its ten parameters, after checking each
    /// against the rule for physical inertias ([`check_physical_parameters`]): a body no
    /// algorithm can compute with is an error and nothing changes; a body that breaks only the
    /// triangle inequality is set, and its message returned as a warning (as a file's is).
    pub fn set_inertial_parameters(&mut self, parameters: &[[f64; 10]]) -> Result<Vec<String>> {
        check_length("inertial_parameters", parameters.len(), self.nbodies() - 1)?;
        let mut warnings = Vec::new();
        for (k, p) in parameters.iter().enumerate() {
            let row = format!("row {k} (body '{}')", self.body_names[k + 1]);
            match check_physical_parameters(p) {
                Ok(()) => {}
                Err(Unphysical::Invalid(message)) => {
                    return Err(Error::InvalidValue {
                        argument: "inertial_parameters".into(),
                        message: format!("{row}: {message}"),
                    })
                }
                Err(Unphysical::TriangleInequality(message)) => {
                    warnings.push(format!("argument 'inertial_parameters': {row}: {message}"));
                }
            }
        }
        for (inertia, p) in self.inertias[1..].iter_mut().zip(parameters) {
            *inertia = Inertia::from_parameters(p);
        }
        Ok(warnings)
    }

    /// Total mass.
    pub fn total_mass(&self) -> f64 {
        self.inertias.iter().skip(1).map(|i| i.mass).sum()
    }
}

/// Checks that four coordinates are a unit quaternion within [`QUATERNION_NORM_TOLERANCE`];
/// the error is their norm.
pub(crate) fn check_unit_quaternion(q: &[f64]) -> std::result::Result<(), f64> {
    let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    if (norm - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
        return Err(norm);
    }
    Ok(())
}
