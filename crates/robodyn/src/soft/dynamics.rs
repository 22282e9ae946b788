//! Forward dynamics with MuJoCo's soft constraints: equalities, contacts, joint and tendon limits
//! and dry friction as MuJoCo's `mj_forward` computes them, its solver run to convergence.
//!
//! Reference: MuJoCo's documentation, "Computation", §Forward dynamics. At (q, q̇) and the
//! actuators' activations w under applied forces τ and controls u:
//! ```text
//!   1. contacts   where the geoms touch (crate::collision)
//!   2. q̈₀ = M⁻¹ (τ + τ_actuator(u, w) + τ_passive − C q̇ − g)   unconstrained; ẇ(u, w)
//!               (M and the bias with the tendons' inertia: super::inertia)
//!   3. rows       J, R, a_ref of every active constraint (super::rows)
//!   4. q̈, f      the soft model's solution (super::solver)
//! ```
//! MuJoCo measures a free joint's linear velocity in world axes, robodyn in the body's: its
//! accelerations are then `T (q̈ + w)`, w = (ω × v, 0) on free joints, and its rows ask
//! `J (q̈ + w)` to follow a_ref. Solving for robodyn's q̈ with `a_ref − J w` gives its very
//! solution, and the forces of its rows.

use super::equality::Equalities;
use super::inertia::{add_tendon_inertia, add_tendon_inertia_bias, has_tendon_inertia};
use super::rows::{constraint_rows, Rows};
use super::solver::{dot, Solution, Solver};
use super::tendons::TendonKinematics;
use super::weights::{inverse_weights, point_columns, world_point, InverseWeights};
use crate::algo::kinematics::update_velocity_products;
use crate::algo::{aba, crba, forward_kinematics};
use crate::collision::{checked_pairs, collide, CheckedPair, CollisionScratch, Contact};
use crate::error::{check_vector, Error, Result};
use crate::integrate::forces::spring_displacement;
use crate::joint::{quaternion_of, Joint};
use crate::model::{Model, SpringReferences};
use crate::spatial::{Transform, Vec3};
use crate::Data;
use nalgebra::{DMatrix, DVector};

/// What [`ContactDynamics::forward`] finds.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ContactForward {
    /// The contacts ([`crate::collision::collide`]).
    pub contacts: Vec<Contact>,
    /// The constraint rows.
    pub rows: Rows,
    /// q̈ and the rows' forces.
    pub solution: Solution,
    /// The actuators' generalised forces (MuJoCo's `qfrc_actuator`).
    pub actuator: DVector<f64>,
    /// ẇ: the rates of the actuators' activations (MuJoCo's `act_dot`, na).
    pub activation_rate: DVector<f64>,
    /// The constraints' generalised forces `Jᵀ f` (MuJoCo's `qfrc_constraint`).
    pub constraint: DVector<f64>,
    /// The joints' and tendons' springs and dampers and the gravity compensation (MuJoCo's
    /// `qfrc_passive`).
    pub passive: DVector<f64>,
    /// The mass matrix M at q, with the tendons' inertia ([`super::inertia`]).
    pub mass: DMatrix<f64>,
    /// The tendons' lengths and Jacobians at q (MuJoCo's `ten_length`, `ten_J`).
    pub tendons: TendonKinematics,
}

/// A model's soft-constraint dynamics: its constant weights, pairs and scratch space (sized by
/// the first call: the calls after allocate nothing of their own).
#[derive(Debug, Clone)]
pub struct ContactDynamics {
    weights: InverseWeights,
    pairs: Vec<CheckedPair>,
    data: Data,
    scratch: CollisionScratch,
    solver: Solver,
    equalities: Equalities,
    /// The bodies' world placements at q.
    x_world: Vec<Transform>,
    /// τ + τ_actuator + τ_passive, q̈₀, w (nv) and the rows' a_ref − J w.
    total: DVector<f64>,
    free: DVector<f64>,
    w: DVector<f64>,
    reference: Vec<f64>,
    /// The Cholesky factor of M with the tendons' inertia, where some tendon has one.
    factor: DMatrix<f64>,
    /// The springs' references with the state's plastic part in place.
    springs: SpringReferences,
    /// The bodies' gravity compensation (nv).
    gravcomp: DVector<f64>,
}

impl ContactDynamics {
    /// The weights and pairs of `model`.
    pub fn new(model: &Model) -> Result<Self> {
        let mut data = Data::new(model);
        let weights = inverse_weights(model, &mut data)?;
        Ok(ContactDynamics {
            equalities: Equalities::new(model, &weights)?,
            weights,
            pairs: checked_pairs(model),
            data,
            scratch: CollisionScratch::default(),
            solver: Solver::default(),
            x_world: Vec::new(),
            total: DVector::zeros(model.nv),
            free: DVector::zeros(model.nv),
            w: DVector::zeros(model.nv),
            reference: Vec::new(),
            factor: DMatrix::zeros(0, 0),
            springs: SpringReferences::default(),
            gravcomp: DVector::zeros(model.nv),
        })
    }

    /// The next forward dynamics starts its solver from q̈₀ rather than the last solution.
    pub fn forget_warm_start(&mut self) {
        self.solver.forget_warm_start();
    }

    /// The soft model's q̈ at (q, q̇), the activations `act` (na) and the plastic springs'
    /// references `plastic` (nplastic, [`crate::model::plastic`]) under applied forces `tau`
    /// (nv) and controls `ctrl` (nu), into `out` (see the module's header).
    pub fn forward(
        &mut self,
        model: &Model,
        (q, v, act, plastic): (&[f64], &[f64], &[f64], &[f64]),
        tau: &[f64],
        ctrl: &[f64],
        out: &mut ContactForward,
    ) -> Result<()> {
        check_vector("v", v, model.nv)?;
        check_vector("tau", tau, model.nv)?;
        model.check_plastic("plastic", plastic)?;
        let nv = model.nv;
        // 1. the contacts
        let placements = forward_kinematics(model, &mut self.data, q)?;
        self.x_world.clear();
        self.x_world.extend_from_slice(placements);
        collide(
            model,
            &self.x_world,
            &self.pairs,
            &mut self.scratch,
            &mut out.contacts,
        );
        out.tendons.update(model, q, &self.x_world);
        // 2. q̈₀ = M⁻¹ (τ + τ_actuator + τ_passive − C q̇ − g), by the articulated-body algorithm
        // τ_actuator: the actuators' forces and an actuatorgravcomp joint's gravity
        // compensation, clamped to the joint's range; the rest of the compensation is passive
        sized(&mut out.actuator, nv);
        let actuator = out.actuator.as_mut_slice();
        model.unclamped_actuator_forces((q, v), (ctrl, act), &out.tendons, actuator)?;
        sized(&mut self.gravcomp, nv);
        add_gravity_compensation(model, &self.x_world, self.gravcomp.as_mut_slice());
        // (with the actuation flag disabled it is lost, as in MuJoCo)
        let actuation = model.options.flag("actuation");
        for i in (1..model.nbodies()).filter(|&i| model.actuator_gravcomp[i]) {
            for c in model.v_range(i) {
                let compensation = std::mem::take(&mut self.gravcomp[c]);
                actuator[c] += if actuation { compensation } else { 0.0 };
            }
        }
        model.clamp_joint_actuator_forces(actuator);
        sized(&mut out.activation_rate, act.len());
        model.activation_rates(ctrl, act, out.activation_rate.as_mut_slice())?;
        sized(&mut out.passive, nv);
        self.springs.update(model, plastic);
        let state = (q, v, &self.springs);
        passive_forces(model, state, &out.tendons, out.passive.as_mut_slice());
        out.passive += &self.gravcomp;
        self.total.copy_from_slice(tau);
        self.total += &out.actuator;
        self.total += &out.passive;
        let free = aba(model, &mut self.data, q, v, self.total.as_slice(), None)?;
        self.free.copy_from(free);
        let mass = crba(model, &mut self.data, q)?;
        if out.mass.shape() == mass.shape() {
            out.mass.copy_from(mass);
        } else {
            out.mass = mass.clone();
        }
        write_free_joint_product(model, v, &mut self.w);
        if has_tendon_inertia(model) {
            self.add_tendon_inertia(model, v, out)?;
        }
        // 3. the rows, their a_ref as robodyn's accelerations see it: a_ref − J w
        constraint_rows(
            model,
            &self.weights,
            (q, v),
            (&self.x_world, &out.tendons),
            &out.contacts,
            &mut self.equalities,
            &mut out.rows,
        )?;
        let rows = &out.rows;
        self.reference.clear();
        self.reference.extend(
            (0..rows.len()).map(|i| rows.reference[i] - dot(rows.row(i), self.w.as_slice())),
        );
        // 4. the solution
        self.solver.solve(
            rows,
            &out.mass,
            &self.free,
            &self.reference,
            &mut out.solution,
        )?;
        sized(&mut out.constraint, nv);
        for (i, force) in out.solution.forces.iter().enumerate() {
            for (c, j) in out.rows.row(i).iter().enumerate() {
                out.constraint[c] += j * force;
            }
        }
        Ok(())
    }

    /// The tendons' inertia (super::inertia) in M and q̈₀, in MuJoCo's accelerations q̈ + w:
    /// `M' (q̈₀' + w) = M (q̈₀ + w) − Σ a Jᵀ (J̇ ν)`, M' = M + a JᵀJ on M's pattern.
    fn add_tendon_inertia(
        &mut self,
        model: &Model,
        v: &[f64],
        out: &mut ContactForward,
    ) -> Result<()> {
        // Σ a Jᵀ (J̇ ν), from the bodies' velocity products
        update_velocity_products(model, &mut self.data, v);
        self.total.fill(0.0);
        let bodies = (&self.x_world[..], &self.data.v[..], &self.data.a[..]);
        let w = self.w.as_slice();
        add_tendon_inertia_bias(model, &out.tendons, bodies, w, self.total.as_mut_slice());
        // M (q̈₀ + w) − Σ a Jᵀ (J̇ ν)
        self.free += &self.w;
        self.total.gemv(1.0, &out.mass, &self.free, -1.0);
        // q̈₀' = M'⁻¹ (…) − w
        add_tendon_inertia(model, &out.tendons, &mut out.mass);
        let mut factor = std::mem::replace(&mut self.factor, DMatrix::zeros(0, 0));
        if factor.shape() == out.mass.shape() {
            factor.copy_from(&out.mass);
        } else {
            factor = out.mass.clone();
        }
        let cholesky = factor.cholesky().ok_or_else(|| Error::InvalidValue {
            argument: "q".into(),
            message: "the mass matrix with the tendons' armature is not positive definite here"
                .into(),
        })?;
        self.free.copy_from(&self.total);
        cholesky.solve_mut(&mut self.free);
        self.free -= &self.w;
        self.factor = cholesky.unpack();
        Ok(())
    }
}

/// τ_passive = −K (q ⊖ q_ref) − D q̇ + Σ Jᵀ f_tendon (K and D with their polynomial terms,
/// [`Model::spring_forces`]; q_ref and the tendons' dead bands from `springs`): the joints' and
/// the tendons' springs and dampers (MuJoCo's `qfrc_passive` without the gravity compensation,
/// [`add_gravity_compensation`], and fluid forces; dry friction is a constraint row), into `tau`
/// (nv).
fn passive_forces(
    model: &Model,
    (q, v, springs): (&[f64], &[f64], &SpringReferences),
    tendons: &TendonKinematics,
    tau: &mut [f64],
) {
    let options = &model.options;
    let (spring, damper) = (options.flag("spring"), options.flag("damper"));
    tau.fill(0.0);
    if spring && model.has_springs() {
        mujoco_spring_displacement(model, &springs.configuration, q, tau);
        model.spring_forces(tau);
    }
    if damper {
        add_damper_forces(model, q, v, tau);
    }
    // each tendon's spring and damper along its length: τ += Jᵀ f
    for (t, tendon) in model.tendons.iter().enumerate() {
        let (length, rate) = (tendons.lengths[t], tendons.rate(t, v));
        let force = tendon.passive_force(springs.bands[t], length, rate, spring, damper);
        tendons.add_to_row(t, force, tau);
    }
}

/// τ += Σ_b J_b(c_b)ᵀ (−γ_b m_b g): MuJoCo's gravity compensation (`gravcomp` γ), a force at
/// each file body's centre of mass c_b holding up the fraction γ of its weight, J_b(c) the
/// Jacobian of that point (MuJoCo's `mj_gravcomp`; none without gravity).
fn add_gravity_compensation(model: &Model, x_world: &[Transform], tau: &mut [f64]) {
    let held = model
        .source_bodies
        .iter()
        .filter(|s| s.gravcomp != 0.0 && s.body != 0);
    for source in held {
        let force = -source.gravcomp * source.mass * model.gravity;
        let centre = world_point(&x_world[source.body], &source.com);
        point_columns(model, x_world, source.body, &centre, |c, linear, _| {
            tau[c] += linear.dot(&force);
        });
    }
}

/// τ += each joint damper's force (MuJoCo's per-dof `−(b + b₁ |ν| + b₂ ν²) ν`), on MuJoCo's
/// velocities ν: a free joint's translation dampers act along the world's axes, f = Rᵀ f(R v)
/// (the same as f(v) when they are linear).
fn add_damper_forces(model: &Model, q: &[f64], v: &[f64], tau: &mut [f64]) {
    let polynomial = |s: usize| model.damping_poly[s..s + 3].iter().any(|t| *t != [0.0; 2]);
    for i in 1..model.nbodies() {
        let (s, nv) = (model.idx_v[i], model.joints[i].nv());
        let mut along_own_axes = s..s + nv;
        if matches!(model.joints[i], Joint::Free) && polynomial(s) {
            let rotation = quaternion_of(&q[model.idx_q[i] + 3..model.idx_q[i] + 7]);
            let world = rotation * Vec3::new(v[s], v[s + 1], v[s + 2]);
            let force = Vec3::from_fn(|r, _| model.damper_force(s + r, world[r]));
            let local = rotation.inverse_transform_vector(&force);
            for r in 0..3 {
                tau[s + r] += local[r];
            }
            along_own_axes = s + 3..s + nv;
        }
        for k in along_own_axes {
            tau[k] += model.damper_force(k, v[k]);
        }
    }
}

/// `vector` resized to `n` entries (kept where it has them), all zero.
fn sized(vector: &mut DVector<f64>, n: usize) {
    if vector.len() == n {
        vector.fill(0.0);
    } else {
        *vector = DVector::zeros(n);
    }
}

/// q ⊖ q_ref as MuJoCo's springs measure it, as robodyn's generalised coordinates see it
/// (MuJoCo's `mj_passive`): a free joint's translation and rotation apart, Rᵀ (p − p_ref) (the
/// world-axes displacement MuJoCo pulls back, turned into the body's axes of robodyn's linear
/// velocity) and log(q_ref⁻¹ ⊗ q); every other joint as [`spring_displacement`] (a ball's is the
/// same log). `reference` is q_ref (nq).
fn mujoco_spring_displacement(model: &Model, reference: &[f64], q: &[f64], out: &mut [f64]) {
    spring_displacement(model, reference, q, out);
    for i in (1..model.nbodies()).filter(|&i| matches!(model.joints[i], Joint::Free)) {
        let (s, v) = (model.idx_q[i], model.idx_v[i]);
        let reference = &reference[s..s + 7];
        let rotation = quaternion_of(&q[s + 3..s + 7]);
        let moved = Vec3::new(q[s], q[s + 1], q[s + 2])
            - Vec3::new(reference[0], reference[1], reference[2]);
        let turned = (quaternion_of(&reference[3..7]).inverse() * rotation).scaled_axis();
        out[v..v + 3].copy_from_slice(rotation.inverse_transform_vector(&moved).as_slice());
        out[v + 3..v + 6].copy_from_slice(turned.as_slice());
    }
}

/// w = (ω × v, 0) on each free joint's coordinates, 0 elsewhere: MuJoCo's free-joint
/// acceleration is `T (q̈ + w)`.
pub(super) fn free_joint_velocity_product(model: &Model, v: &[f64]) -> DVector<f64> {
    let mut w = DVector::zeros(model.nv);
    write_free_joint_product(model, v, &mut w);
    w
}

/// [`free_joint_velocity_product`] into `w` (nv).
pub(super) fn write_free_joint_product(model: &Model, v: &[f64], w: &mut DVector<f64>) {
    w.fill(0.0);
    for i in 1..model.nbodies() {
        if matches!(model.joints[i], Joint::Free) {
            let s = model.idx_v[i];
            let linear = nalgebra::Vector3::new(v[s], v[s + 1], v[s + 2]);
            let angular = nalgebra::Vector3::new(v[s + 3], v[s + 4], v[s + 5]);
            let product = angular.cross(&linear);
            w.rows_mut(s, 3).copy_from(&product);
        }
    }
}
