//! Derivatives of the constraint rows with respect to q (tangent space) and q̇, and of the
//! generalized forces `Jᵀ λ` their forces apply, for the derivatives of constrained dynamics.
//!
//! Reference: the rows of `rows.rs`, differentiated through the world-axes motion of each
//! attachment's origin (`frame_derivatives`: ∂p/∂δ, ∂ṗ/∂δ, ∂p̈/∂δ, ∂p̈/∂q̇ and the angular
//! ones). Rows in the first frame's axes E turn with it: ∂(E x)/∂δ_k = E (∂x/∂δ_k − ω_k × x),
//! ω_k the angular column k of the first body's Jacobian.
//!
//! The forces: RNEA differentiates a force that is fixed in its body. A constraint force in world
//! axes (f, m) at a point p of body b is not: as coordinate k moves, the point moves with the
//! body but the direction stays. The difference of the two derivatives is the generalized force
//! of the force `−ω_k × f` and moment `−ω_k × m` at p:
//! ```text
//!   ∂(Jᵀλ)/∂δ_k − (RNEA's) = J_linᵀ [f]× d_k + J_angᵀ [m]× d_k,    d_k = ω_k(b) − ω_k(axes)
//! ```
//! where ω_k(axes) is zero for world axes and the first body's for a force in its axes (so a
//! force on the first body in its own axes needs nothing). A distance row's direction n = r/d
//! also turns: `∂n = (1 − n nᵀ) ∂r / d`. A coupling's force is not handed to RNEA at all:
//! `(Jᵀλ)_l = −p'(x) λ` gives `∂/∂q_l = −p''(x) λ`.

use super::rows::{kept, polynomial_at, six};
use super::{Attachment, ConstraintKind, ConstraintReference, ConstraintSet};
use crate::algo::frame_derivatives::attached_motion_derivatives;
use crate::algo::kinematics::update_support_placements;
use crate::algo::Reference;
use crate::model::Model;
use crate::spatial::{Force, Transform, Vec3};
use crate::Data;
use nalgebra::{DMatrix, Matrix3};

/// What is differentiated: the rows' acceleration `J(q) q̈ + γ(q, q̇)` at a fixed q̈, or their
/// velocity `J(q) w` at a fixed w.
#[derive(Debug, Clone, Copy)]
pub(crate) enum RowLevel<'a> {
    /// ∂(J q̈ + γ)/∂q and ∂(J q̈ + γ)/∂q̇.
    Acceleration { v: &'a [f64], qdd: &'a [f64] },
    /// ∂(J w)/∂q.
    Velocity { w: &'a [f64] },
}

/// Where the derivatives go.
pub(crate) struct RowDerivatives<'a> {
    /// ∂(rows)/∂q (rows × nv).
    pub by_q: &'a mut DMatrix<f64>,
    /// ∂(rows)/∂q̇ (rows × nv), at the acceleration level only.
    pub by_v: &'a mut DMatrix<f64>,
    /// The part of ∂(Jᵀ λ)/∂q that RNEA does not give for λ handed to it by [`add_body_forces`]
    /// (nv × nv).
    pub forces_by_q: &'a mut DMatrix<f64>,
}

/// One attachment's origin in world axes at this state: its motion and the derivatives of it
/// (6 × nv each, rows `[linear; angular]`: the origin's classical quantities and the angular ones).
#[derive(Debug, Clone)]
pub(crate) struct AttachedColumns {
    /// ∂[ṗ; ω]/∂q̇ (J).
    jacobian: DMatrix<f64>,
    /// ∂[ṗ; ω]/∂q.
    velocity_dq: DMatrix<f64>,
    /// ∂[p̈; ω̇]/∂q.
    acceleration_dq: DMatrix<f64>,
    /// ∂[p̈; ω̇]/∂q̇.
    acceleration_dv: DMatrix<f64>,
    /// E (world to the attachment's axes) and p.
    rotation: Matrix3<f64>,
    position: Vec3,
    /// [ṗ, ω] and [p̈, ω̇] (with the q̈ given).
    velocity: [Vec3; 2],
    acceleration: [Vec3; 2],
    /// The body it is fixed in (0: the world).
    body: usize,
}

impl AttachedColumns {
    fn new(nv: usize) -> Self {
        AttachedColumns {
            jacobian: DMatrix::zeros(6, nv),
            velocity_dq: DMatrix::zeros(6, nv),
            acceleration_dq: DMatrix::zeros(6, nv),
            acceleration_dv: DMatrix::zeros(6, nv),
            rotation: Matrix3::identity(),
            position: Vec3::zeros(),
            velocity: [Vec3::zeros(); 2],
            acceleration: [Vec3::zeros(); 2],
            body: 0,
        }
    }

    /// Fills the columns of `attachment` at (q, q̇, q̈) (`data` as scratch).
    fn fill(
        &mut self,
        model: &Model,
        data: &mut Data,
        q: &[f64],
        (v, a): (&[f64], &[f64]),
        attachment: &Attachment,
    ) {
        let Some(frame) = attachment.frame else {
            for matrix in self.matrices() {
                matrix.as_mut_slice().fill(0.0);
            }
            self.rotation = attachment.placement.rotation;
            self.position = attachment.placement.translation;
            self.velocity = [Vec3::zeros(); 2];
            self.acceleration = [Vec3::zeros(); 2];
            self.body = 0;
            return;
        };
        let body = model.frames[frame].body;
        // X_{c←body} = X_{c←frame} X_{frame←body}
        let placement: Transform = attachment.placement * model.frames[frame].placement;
        update_support_placements(model, data, q, body);
        attached_motion_derivatives(model, data, (v, a), body, &placement, Reference::World);
        let computed = [
            &data.jacobian,
            &data.frame_velocity_dq,
            &data.frame_acceleration_dq,
            &data.frame_acceleration_dv,
        ];
        for (matrix, from) in self.matrices().into_iter().zip(computed) {
            matrix.as_mut_slice().copy_from_slice(from.as_slice());
        }
        let pose = placement * data.x_world[body];
        let p = pose.translation;
        // ṗ = ν_lin + ω × p;  p̈ = α_lin + ω̇ × p + ω × ṗ
        let (nu, alpha) = (data.v_world[body], data.a_world[body]);
        let velocity = nu.linear + nu.angular.cross(&p);
        let acceleration = alpha.linear + alpha.angular.cross(&p) + nu.angular.cross(&velocity);
        self.rotation = pose.rotation;
        self.position = p;
        self.velocity = [velocity, nu.angular];
        self.acceleration = [acceleration, alpha.angular];
        self.body = body;
    }

    fn matrices(&mut self) -> [&mut DMatrix<f64>; 4] {
        [
            &mut self.jacobian,
            &mut self.velocity_dq,
            &mut self.acceleration_dq,
            &mut self.acceleration_dv,
        ]
    }

    /// Column k of rows `from..from + 3` of `matrix`.
    fn part(matrix: &DMatrix<f64>, from: usize, k: usize) -> Vec3 {
        matrix.fixed_view::<3, 1>(from, k).into_owned()
    }

    /// The angular column k of J: ω_k.
    fn omega(&self, k: usize) -> Vec3 {
        Self::part(&self.jacobian, 3, k)
    }
}

/// The two attachments' columns and a zero q̈, made once per set.
#[derive(Debug, Clone)]
pub(crate) struct RowScratch {
    first: AttachedColumns,
    second: AttachedColumns,
    zeros: Vec<f64>,
}

impl RowScratch {
    /// Scratch for a model of `nv` coordinates.
    pub(crate) fn new(nv: usize) -> Self {
        RowScratch {
            first: AttachedColumns::new(nv),
            second: AttachedColumns::new(nv),
            zeros: vec![0.0; nv],
        }
    }
}

/// Adds the forces λ of the point, frame and distance rows of `set` to `f_ext` (one force per
/// moving body, in its coordinates, as RNEA takes them): a force f and moment m in world axes at
/// a point p is the world spatial force `(p × f + m, f)`. Needs `x_world` of every body.
pub(crate) fn add_body_forces(
    model: &Model,
    x_world: &[Transform],
    set: &ConstraintSet,
    forces: &[f64],
    f_ext: &mut [Force],
) {
    // X_{c←0} of an attachment
    let placement = |a: &Attachment| match a.frame {
        None => a.placement,
        Some(frame) => {
            let body = model.frames[frame].body;
            a.placement * model.frames[frame].placement * x_world[body]
        }
    };
    let mut apply = |attachment: &Attachment, (f, m): (Vec3, Vec3)| {
        let Some(frame) = attachment.frame else {
            return;
        };
        let body = model.frames[frame].body;
        if body == 0 {
            return;
        }
        let p = placement(attachment).translation;
        let world = Force::new(p.cross(&f) + m, f);
        f_ext[body - 1] += x_world[body].apply_force(&world);
    };
    for (k, constraint) in set.constraints().iter().enumerate() {
        let row = set.offset(k);
        let local = constraint.reference == ConstraintReference::Local;
        match &constraint.kind {
            ConstraintKind::Point { first, second }
            | ConstraintKind::Frame { first, second, .. } => {
                // Eᵀ λ in world axes (E: the first frame's axes for local rows)
                let (f, m) = kept_force(&held_mask(&constraint.kind), &forces[row..]);
                let axes = if local {
                    placement(first).rotation.transpose()
                } else {
                    Matrix3::identity()
                };
                let (f, m) = (axes * f, axes * m);
                apply(first, (f, m));
                second.iter().for_each(|s| apply(s, (-f, -m)));
            }
            ConstraintKind::Distance { first, second, .. } => {
                let r = placement(first).translation - placement(second).translation;
                let f = r / r.norm().max(f64::MIN_POSITIVE) * forces[row];
                apply(first, (f, Vec3::zeros()));
                apply(second, (-f, Vec3::zeros()));
            }
            ConstraintKind::Coupling { .. } => {}
        }
    }
}

/// The force and moment `(λ_lin, λ_ang)` of the rows `mask` keeps (from the first of `forces`),
/// in the rows' axes.
fn kept_force(mask: &[bool; 6], forces: &[f64]) -> (Vec3, Vec3) {
    let mut full = [0.0; 6];
    let mut rows = forces.iter();
    for (value, _) in full.iter_mut().zip(mask).filter(|(_, &keep)| keep) {
        *value = *rows.next().unwrap_or(&0.0);
    }
    (
        Vec3::new(full[0], full[1], full[2]),
        Vec3::new(full[3], full[4], full[5]),
    )
}

/// The rows a point or frame constraint keeps of `[linear; angular]`.
fn held_mask(kind: &ConstraintKind) -> [bool; 6] {
    match kind {
        ConstraintKind::Frame { mask, .. } => *mask,
        _ => [true, true, true, false, false, false],
    }
}

/// Writes the derivatives of every row of `set` at `level` into `out` (zeroed first), and the
/// part of ∂(Jᵀ λ)/∂q that RNEA misses for the forces `forces`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn differentiate_rows(
    model: &Model,
    data: &mut Data,
    set: &ConstraintSet,
    q: &[f64],
    level: RowLevel,
    forces: &[f64],
    scratch: &mut RowScratch,
    mut out: RowDerivatives,
) {
    for matrix in [&mut out.by_q, &mut out.by_v, &mut out.forces_by_q] {
        matrix.as_mut_slice().fill(0.0);
    }
    let RowScratch {
        first: one,
        second: other,
        zeros,
    } = scratch;
    let motion = match level {
        RowLevel::Acceleration { v, qdd } => (v, qdd),
        RowLevel::Velocity { w } => (w, zeros.as_slice()),
    };
    let world = Attachment {
        frame: None,
        placement: Transform::IDENTITY,
    };
    for (k, constraint) in set.constraints().iter().enumerate() {
        let row = set.offset(k);
        let local = constraint.reference == ConstraintReference::Local;
        match &constraint.kind {
            ConstraintKind::Point { first, second }
            | ConstraintKind::Frame { first, second, .. } => {
                let mask = held_mask(&constraint.kind);
                one.fill(model, data, q, motion, first);
                other.fill(model, data, q, motion, second.as_ref().unwrap_or(&world));
                let held = HeldRows { mask, local, row };
                held.write(model, (one, other), level, forces, &mut out);
            }
            ConstraintKind::Distance { first, second, .. } => {
                one.fill(model, data, q, motion, first);
                other.fill(model, data, q, motion, second);
                distance_row(model, (one, other), level, forces[row], row, &mut out);
            }
            ConstraintKind::Coupling {
                leader: Some(leader),
                polynomial,
                references,
                ..
            } => {
                let l = model.idx_v[*leader];
                let x = q[model.idx_q[*leader]] - references.1;
                let [_, _, ddp, dddp] = polynomial_at(polynomial, x);
                // row = q̈_f − p'(x) q̈_l − p''(x) q̇_l² (or w_f − p'(x) w_l)
                match level {
                    RowLevel::Acceleration { v, qdd } => {
                        out.by_q[(row, l)] -= ddp * qdd[l] + dddp * v[l] * v[l];
                        out.by_v[(row, l)] -= 2.0 * ddp * v[l];
                    }
                    RowLevel::Velocity { w } => out.by_q[(row, l)] -= ddp * w[l],
                }
                // (Jᵀλ)_l = −p'(x) λ
                out.forces_by_q[(l, l)] -= ddp * forces[row];
            }
            ConstraintKind::Coupling { leader: None, .. } => {}
        }
    }
}

/// The rows of a point or frame constraint: `mask`ed, in world or the first frame's axes.
struct HeldRows {
    mask: [bool; 6],
    local: bool,
    row: usize,
}

impl HeldRows {
    fn write(
        &self,
        model: &Model,
        (one, other): (&AttachedColumns, &AttachedColumns),
        level: RowLevel,
        forces: &[f64],
        out: &mut RowDerivatives,
    ) {
        let axes = if self.local {
            one.rotation
        } else {
            Matrix3::identity()
        };
        // the differentiated quantity x = x_1 − x_2 and its columns
        let (by_q, value) = match level {
            RowLevel::Acceleration { .. } => (
                (&one.acceleration_dq, &other.acceleration_dq),
                (one.acceleration, other.acceleration),
            ),
            RowLevel::Velocity { .. } => (
                (&one.velocity_dq, &other.velocity_dq),
                (one.velocity, other.velocity),
            ),
        };
        let x = [value.0[0] - value.1[0], value.0[1] - value.1[1]];
        for k in 0..model.nv {
            let part = |m: (&DMatrix<f64>, &DMatrix<f64>), from| {
                AttachedColumns::part(m.0, from, k) - AttachedColumns::part(m.1, from, k)
            };
            let (mut linear, mut angular) = (part(by_q, 0), part(by_q, 3));
            if self.local {
                // ∂(E x) = E (∂x − ω_k × x)
                let omega = one.omega(k);
                linear -= omega.cross(&x[0]);
                angular -= omega.cross(&x[1]);
            }
            self.put(out.by_q, k, &(axes * linear), &(axes * angular));
            if let RowLevel::Acceleration { .. } = level {
                let by_v = (&one.acceleration_dv, &other.acceleration_dv);
                self.put(
                    out.by_v,
                    k,
                    &(axes * part(by_v, 0)),
                    &(axes * part(by_v, 3)),
                );
            }
        }
        // the forces (Eᵀ λ) on the first, their opposite on the second
        let (f, m) = kept_force(&self.mask, &forces[self.row..]);
        let (f, m) = (axes.transpose() * f, axes.transpose() * m);
        let turning_axes = self.local.then_some(one);
        for (attached, sign) in [(one, 1.0), (other, -1.0)] {
            add_turning_force(
                out.forces_by_q,
                attached,
                (sign * f, sign * m),
                turning_axes,
            );
        }
    }

    /// Writes the kept entries of `[linear; angular]` into column k from this row on.
    fn put(&self, matrix: &mut DMatrix<f64>, k: usize, linear: &Vec3, angular: &Vec3) {
        for (r, value) in kept(&self.mask, &six(linear, angular)) {
            matrix[(self.row + r, k)] = value;
        }
    }
}

/// The distance row `a = nᵀ A + (|V|² − (nᵀV)²)/d` (A = p̈_1 − p̈_2, V = ṗ_1 − ṗ_2, r = p_1 − p_2,
/// d = |r|, n = r/d), or `nᵀ W` at the velocity level, and its forces `±λ n`.
fn distance_row(
    model: &Model,
    (one, other): (&AttachedColumns, &AttachedColumns),
    level: RowLevel,
    force: f64,
    row: usize,
    out: &mut RowDerivatives,
) {
    let r = one.position - other.position;
    let d = r.norm().max(f64::MIN_POSITIVE);
    let n = r / d;
    let column = |m: (&DMatrix<f64>, &DMatrix<f64>), k| {
        AttachedColumns::part(m.0, 0, k) - AttachedColumns::part(m.1, 0, k)
    };
    let jacobians = (&one.jacobian, &other.jacobian);
    for k in 0..model.nv {
        // ∂r = J_1 − J_2 (linear);  ∂n = (1 − n nᵀ) ∂r / d;  ∂d = nᵀ ∂r
        let dr = column(jacobians, k);
        let dn = (dr - n * n.dot(&dr)) / d;
        let dd = n.dot(&dr);
        match level {
            RowLevel::Acceleration { .. } => {
                let (a, v) = (
                    one.acceleration[0] - other.acceleration[0],
                    one.velocity[0] - other.velocity[0],
                );
                let along = n.dot(&v);
                let sideways = v.norm_squared() - along * along;
                let da = column((&one.acceleration_dq, &other.acceleration_dq), k);
                let dv = column((&one.velocity_dq, &other.velocity_dq), k);
                // ∂a = ∂nᵀA + nᵀ∂A + (2Vᵀ∂V − 2(nᵀV)(∂nᵀV + nᵀ∂V))/d − (|V|² − (nᵀV)²) ∂d/d²
                out.by_q[(row, k)] = dn.dot(&a)
                    + n.dot(&da)
                    + 2.0 * (v.dot(&dv) - along * (dn.dot(&v) + n.dot(&dv))) / d
                    - sideways * dd / (d * d);
                // along q̇: ∂V = ∂r's columns, ∂n = 0
                let da_dv = column((&one.acceleration_dv, &other.acceleration_dv), k);
                out.by_v[(row, k)] = n.dot(&da_dv) + 2.0 * (v.dot(&dr) - along * n.dot(&dr)) / d;
            }
            RowLevel::Velocity { .. } => {
                let w = one.velocity[0] - other.velocity[0];
                let dw = column((&one.velocity_dq, &other.velocity_dq), k);
                out.by_q[(row, k)] = dn.dot(&w) + n.dot(&dw);
            }
        }
        // (J_1 − J_2)ᵀ λ ∂n
        for j in 0..model.nv {
            out.forces_by_q[(j, k)] += force * column(jacobians, j).dot(&dn);
        }
    }
    for (attached, sign) in [(one, 1.0), (other, -1.0)] {
        add_turning_force(
            out.forces_by_q,
            attached,
            (sign * force * n, Vec3::zeros()),
            None,
        );
    }
}

/// Adds `J_linᵀ [f]× d_k + J_angᵀ [m]× d_k` to column k of `forces_by_q` for the world-axes force
/// (f, m) on `attached`, d_k = ω_k(attached) − ω_k(axes) (`axes`: the attachment whose axes the
/// force turns with; none for world axes).
fn add_turning_force(
    forces_by_q: &mut DMatrix<f64>,
    attached: &AttachedColumns,
    (f, m): (Vec3, Vec3),
    axes: Option<&AttachedColumns>,
) {
    if attached.body == 0 {
        return;
    }
    let nv = forces_by_q.ncols();
    for k in 0..nv {
        let d = attached.omega(k) - axes.map_or(Vec3::zeros(), |a| a.omega(k));
        if d == Vec3::zeros() {
            continue;
        }
        let (torque, couple) = (f.cross(&d), m.cross(&d));
        for j in 0..nv {
            let linear = AttachedColumns::part(&attached.jacobian, 0, j);
            forces_by_q[(j, k)] += linear.dot(&torque) + attached.omega(j).dot(&couple);
        }
    }
}
