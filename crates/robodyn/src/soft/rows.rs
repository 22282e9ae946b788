//! MuJoCo's constraint rows at one state: each row's Jacobian, position, margin, regulariser
//! and reference acceleration (MuJoCo's `efc_*` arrays), in MuJoCo's order.
//!
//! Reference: MuJoCo's documentation, "Computation", §Constraint model and §Soft constraints
//! (read to understand, written anew here). The rows come in blocks:
//! ```text
//!   equalities      connect (3 rows), weld (6), joint or tendon (1): see super::equality
//!   friction loss   one per degree of freedom with frictionloss > 0:  J = e_i,  pos = 0,
//!                   then one per such tendon:  J = J_L (its length L = J q)
//!   limits          each side of a limited hinge or slide within its margin:
//!                     lower  pos = q − lo,  J = +e_i      upper  pos = hi − q,  J = −e_i
//!                   then each side of a limited tendon, the same with L and J_L
//!   contacts        per contact within its margin, c the rows of F (J(b₂, p) − J(b₁, p)):
//!                     condim 1            c_n
//!                     pyramidal           c_n ± μ_k c_k,  k = 1 … condim − 1
//!                     elliptic            c_n, c_t₁, c_t₂ (, c_spin, c_roll₁, c_roll₂)
//! ```
//! F the contact frame (normal, tangents; spin and rolls about the same axes), p the contact
//! point. One element's rows share its impedance d (of `|pos − margin|` of its first row; of the
//! norm of an equality's positions). With
//! `Â` a row's approximate inverse inertia ([`super::weights`]):
//! ```text
//!   R = max(1e-15, (1 − d)/d · Â)
//!   elliptic:  R_t₁ = R_n / impratio,  R_k = R_t₁ f₀²/f_k²;   μ = f₀ √(R_t₁/R_n)
//!   pyramidal: every row 2 μ² R₀,  μ = f₀/√impratio,  R₀ the first row's own
//!   a_ref = −b (J q̇) − k d (pos − margin)        (k = 0 on friction rows)
//! ```
//! with (k, b) from `solref` ([`super::impedance::spring_and_damper`]).

use super::equality::Equalities;
use super::impedance::{impedance, spring_and_damper};
use super::tendons::TendonKinematics;
use super::weights::{point_columns, InverseWeights};
use crate::collision::Contact;
use crate::error::Result;
use crate::joint::Joint;
use crate::model::{FrictionCone, Model, SolverParameters, UnreadElements};
use crate::spatial::{Mat3, Transform, Vec3};

use super::TINY;

/// What made a row (MuJoCo's `mjtConstraint`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RowKind {
    /// An equality constraint's row.
    Equality,
    /// Dry friction of one degree of freedom.
    FrictionDof,
    /// Dry friction of a tendon.
    FrictionTendon,
    /// One side of a joint's limit.
    LimitJoint,
    /// One side of a tendon's limit.
    LimitTendon,
    /// A contact without friction (condim 1).
    ContactFrictionless,
    /// A contact's pyramid edge.
    ContactPyramidal,
    /// A contact's normal or friction direction in an elliptic cone.
    ContactElliptic,
}

impl RowKind {
    /// MuJoCo's name, lower case without its `mjCNSTR_` prefix.
    pub fn name(self) -> &'static str {
        match self {
            RowKind::Equality => "equality",
            RowKind::FrictionDof => "friction_dof",
            RowKind::FrictionTendon => "friction_tendon",
            RowKind::LimitJoint => "limit_joint",
            RowKind::LimitTendon => "limit_tendon",
            RowKind::ContactFrictionless => "contact_frictionless",
            RowKind::ContactPyramidal => "contact_pyramidal",
            RowKind::ContactElliptic => "contact_elliptic",
        }
    }
}

/// The rows one element makes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Group {
    /// Its first row.
    pub first: usize,
    /// How many.
    pub len: usize,
    /// Their kind.
    pub kind: RowKind,
    /// An elliptic contact's regularised friction coefficient μ (0 otherwise).
    pub mu: f64,
    /// A contact's friction coefficients (sliding ×2, torsional, rolling ×2).
    pub friction: [f64; 5],
}

/// The constraint rows at one state (MuJoCo's `efc_*` arrays); see the module's header.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Rows {
    /// nv, the row length.
    pub nv: usize,
    /// The Jacobian, row by row (rows × nv), in robodyn's velocity coordinates.
    pub jacobian: Vec<f64>,
    /// Each row's kind.
    pub kind: Vec<RowKind>,
    /// Each row's element: the equality (its place among the file's equalities), the degree of
    /// freedom or tendon, the joint (MuJoCo's joint id) or tendon, the contact.
    pub id: Vec<usize>,
    /// Position (m or rad): negative when violated.
    pub position: Vec<f64>,
    /// Margin: the position below which the row is active.
    pub margin: Vec<f64>,
    /// Dry friction's largest force (friction-loss rows; 0 elsewhere).
    pub frictionloss: Vec<f64>,
    /// The regulariser R.
    pub regulariser: Vec<f64>,
    /// The reference acceleration a_ref.
    pub reference: Vec<f64>,
    /// The groups of rows.
    pub groups: Vec<Group>,
    /// Per contact, its first row (`None`: it has none).
    pub contact_rows: Vec<Option<usize>>,
}

impl Rows {
    /// The number of rows.
    pub fn len(&self) -> usize {
        self.kind.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.kind.is_empty()
    }

    /// Row `i` of the Jacobian.
    pub fn row(&self, i: usize) -> &[f64] {
        &self.jacobian[i * self.nv..(i + 1) * self.nv]
    }

    /// Contact `contact`'s force in its frame from the rows' `forces` (MuJoCo's
    /// `mj_contactForce`): the normal, the two tangents, the spin and the two rolls (condim of
    /// them, the rest 0; all 0 for a contact without rows). An elliptic contact's rows are these;
    /// a pyramidal one's edges n ± μ_k t_k (in pairs per direction k) give
    /// ```text
    ///   f_n = Σ edges,   f_k = μ_k (f_{k+} − f_{k−})
    /// ```
    pub fn contact_force(&self, forces: &[f64], contact: usize) -> [f64; 6] {
        let mut force = [0.0; 6];
        let Some(first) = self.contact_rows.get(contact).copied().flatten() else {
            return force;
        };
        let Some(group) = self.groups.iter().find(|g| g.first == first) else {
            return force;
        };
        let rows = &forces[first..first + group.len];
        match group.kind {
            RowKind::ContactPyramidal => {
                force[0] = rows.iter().sum();
                for (k, edges) in rows.chunks(2).enumerate() {
                    force[k + 1] = group.friction[k] * (edges[0] - edges[1]);
                }
            }
            _ => force[..rows.len()].copy_from_slice(rows),
        }
        force
    }

    fn clear(&mut self, nv: usize) {
        self.nv = nv;
        self.jacobian.clear();
        self.kind.clear();
        self.id.clear();
        self.position.clear();
        self.margin.clear();
        self.frictionloss.clear();
        self.regulariser.clear();
        self.reference.clear();
        self.groups.clear();
        self.contact_rows.clear();
    }

    /// Adds a row; its Jacobian zero, to be written.
    pub(super) fn push(
        &mut self,
        kind: RowKind,
        id: usize,
        position: f64,
        margin: f64,
    ) -> &mut [f64] {
        self.kind.push(kind);
        self.id.push(id);
        self.position.push(position);
        self.margin.push(margin);
        self.frictionloss.push(0.0);
        let start = self.jacobian.len();
        self.jacobian.resize(start + self.nv, 0.0);
        &mut self.jacobian[start..]
    }

    /// Removes the last `count` rows pushed (before their group is finished).
    fn discard_last(&mut self, count: usize) {
        let kept = self.len() - count;
        self.kind.truncate(kept);
        self.id.truncate(kept);
        self.position.truncate(kept);
        self.margin.truncate(kept);
        self.frictionloss.truncate(kept);
        self.jacobian.truncate(kept * self.nv);
    }
}

/// What the rows of one element need beyond their Jacobians.
struct Softness<'a> {
    solver: &'a SolverParameters,
    /// The friction rows' `solref` of an elliptic contact ([0, 0]: the normal's).
    friction_solref: [f64; 2],
    /// Each row's approximate inverse inertia Â.
    diagonal: &'a [f64],
}

/// The rows of `model` at (q, q̇) with its bodies at `x_world`, its tendons' lengths and
/// Jacobians `tendons` and `contacts` found there, into `rows`. `weights` are the model's
/// ([`super::weights::inverse_weights`]).
pub fn constraint_rows(
    model: &Model,
    weights: &InverseWeights,
    (q, v): (&[f64], &[f64]),
    (x_world, tendons): (&[Transform], &TendonKinematics),
    contacts: &[Contact],
    equalities: &mut Equalities,
    rows: &mut Rows,
) -> Result<()> {
    let options = &model.options;
    let nv = model.nv;
    rows.clear(nv);
    rows.contact_rows.resize(contacts.len(), None);
    if !options.flag("constraint") {
        return Ok(());
    }
    let safe_after = options.flag("refsafe").then_some(2.0 * options.timestep);
    // equality constraints, each a group of rows with its own softness
    equalities.append(
        model,
        (q, v),
        tendons,
        rows,
        |rows, count, solver, diagonal| {
            let softness = Softness {
                solver,
                friction_solref: [0.0; 2],
                diagonal,
            };
            finish_group(rows, RowKind::Equality, count, &softness, safe_after, v);
        },
    )?;
    // friction loss, degree of freedom by degree of freedom: J = e_i in MuJoCo's velocities
    if options.flag("frictionloss") {
        for i in 1..model.nbodies() {
            for (k, dof) in model.v_range(i).enumerate() {
                let loss = model.friction[dof];
                if loss <= 0.0 {
                    continue;
                }
                let first = rows.len();
                let row = rows.push(RowKind::FrictionDof, dof, 0.0, 0.0);
                mujoco_dof_row(model, x_world, i, k, row);
                rows.frictionloss[first] = loss;
                let softness = Softness {
                    solver: &model.joint_softness[i].friction,
                    friction_solref: [0.0; 2],
                    diagonal: &[weights.dofs[dof]],
                };
                finish_group(rows, RowKind::FrictionDof, 1, &softness, safe_after, v);
            }
        }
        // then tendon by tendon: J = J_tendon
        for (t, tendon) in model.tendons.iter().enumerate() {
            if tendon.frictionloss <= 0.0 {
                continue;
            }
            let first = rows.len();
            let id = UnreadElements::mujoco_id(&model.unread.tendons, t);
            let row = rows.push(RowKind::FrictionTendon, id, 0.0, 0.0);
            tendons.add_to_row(t, 1.0, row);
            rows.frictionloss[first] = tendon.frictionloss;
            let softness = Softness {
                solver: &tendon.friction,
                friction_solref: [0.0; 2],
                diagonal: &[weights.tendons[t]],
            };
            finish_group(rows, RowKind::FrictionTendon, 1, &softness, safe_after, v);
        }
    }
    // limits, joint by joint: each side within the margin, a ball's cone
    if options.flag("limit") {
        for i in 1..model.nbodies() {
            let softness = &model.joint_softness[i];
            let (index_q, dof) = (model.idx_q[i], model.idx_v[i]);
            let diagonal = [weights.dofs[dof]];
            let group = Softness {
                solver: &softness.limit,
                friction_solref: [0.0; 2],
                diagonal: &diagonal,
            };
            if let Some(largest) = softness.cone_limit {
                // θ u the ball's rotation vector: pos = max(range) − |θ|, J = −u
                let (angle, axis) = rotation_vector(&q[index_q..index_q + 4]);
                let distance = largest - angle;
                if distance < softness.margin {
                    let row = rows.push(RowKind::LimitJoint, i - 1, distance, softness.margin);
                    for k in 0..3 {
                        row[dof + k] = -axis[k];
                    }
                    finish_group(rows, RowKind::LimitJoint, 1, &group, safe_after, v);
                }
                continue;
            }
            let (lower, upper) = (
                model.lower_position_limit[index_q],
                model.upper_position_limit[index_q],
            );
            if !lower.is_finite() && !upper.is_finite() {
                continue;
            }
            for (side, range_end) in [(1.0, lower), (-1.0, upper)] {
                // lower: q − lo, J = +e;  upper: hi − q, J = −e
                let distance = side * (q[index_q] - range_end);
                if distance >= softness.margin || distance.is_nan() {
                    continue;
                }
                let row = rows.push(RowKind::LimitJoint, i - 1, distance, softness.margin);
                row[dof] = side;
                finish_group(rows, RowKind::LimitJoint, 1, &group, safe_after, v);
            }
        }
        // then tendon by tendon, the same with L and J_tendon
        for (t, tendon) in model.tendons.iter().enumerate() {
            let Some((lower, upper)) = tendon.range else {
                continue;
            };
            let length = tendons.lengths[t];
            let group = Softness {
                solver: &tendon.limit,
                friction_solref: [0.0; 2],
                diagonal: &[weights.tendons[t]],
            };
            for (side, range_end) in [(1.0, lower), (-1.0, upper)] {
                let distance = side * (length - range_end);
                if distance >= tendon.margin || distance.is_nan() {
                    continue;
                }
                let id = UnreadElements::mujoco_id(&model.unread.tendons, t);
                let row = rows.push(RowKind::LimitTendon, id, distance, tendon.margin);
                tendons.add_to_row(t, side, row);
                finish_group(rows, RowKind::LimitTendon, 1, &group, safe_after, v);
            }
        }
    }
    // contacts within their margin (the gap band keeps its contacts, without rows)
    if options.flag("contact") {
        let mut local = vec![0.0; 6 * nv];
        for (index, contact) in contacts.iter().enumerate() {
            let parameters =
                crate::soft::contact_parameters(model, contact.geoms.0, contact.geoms.1);
            let (g1, g2) = (&model.geoms[contact.geoms.0], &model.geoms[contact.geoms.1]);
            if contact.distance >= parameters.margin || (g1.body == 0 && g2.body == 0) {
                continue;
            }
            // the six rows F (J(b₂, p) − J(b₁, p)): normal, tangents, spin, rolls
            local.fill(0.0);
            contact_jacobian(model, x_world, (g1.body, g2.body), contact, &mut local);
            let [b1, b2] = [g1.source_body, g2.source_body].map(|b| weights.bodies[b]);
            let (translation, rotation) = (b1[0] + b2[0], b1[1] + b2[1]);
            let first = rows.len();
            rows.contact_rows[index] = Some(first);
            let f = parameters.friction;
            let dim = parameters.condim;
            let mut diagonal = [0.0; 10];
            let (kind, count) = if dim == 1 {
                rows.push(
                    RowKind::ContactFrictionless,
                    index,
                    contact.distance,
                    parameters.margin,
                )
                .copy_from_slice(&local[..nv]);
                diagonal[0] = translation;
                (RowKind::ContactFrictionless, 1)
            } else if options.cone == FrictionCone::Elliptic {
                for k in 0..dim {
                    // the friction rows have no position
                    let (position, margin) = if k == 0 {
                        (contact.distance, parameters.margin)
                    } else {
                        (0.0, 0.0)
                    };
                    rows.push(RowKind::ContactElliptic, index, position, margin)
                        .copy_from_slice(&local[k * nv..(k + 1) * nv]);
                    diagonal[k] = if k < 3 { translation } else { rotation };
                }
                (RowKind::ContactElliptic, dim)
            } else {
                for k in 1..dim {
                    // c_n + μ_k c_k, then c_n − μ_k c_k
                    let mu = f[k - 1];
                    let across = if k < 3 { translation } else { rotation };
                    for sign in [1.0, -1.0] {
                        let row = rows.push(
                            RowKind::ContactPyramidal,
                            index,
                            contact.distance,
                            parameters.margin,
                        );
                        for c in 0..nv {
                            row[c] = local[c] + sign * mu * local[k * nv + c];
                        }
                        diagonal[2 * (k - 1) + (sign < 0.0) as usize] =
                            translation + mu * mu * across;
                    }
                }
                (RowKind::ContactPyramidal, 2 * (dim - 1))
            };
            let softness = Softness {
                solver: &parameters.solver,
                friction_solref: parameters.solreffriction,
                diagonal: &diagonal[..count],
            };
            finish_group(rows, kind, count, &softness, safe_after, v);
            let group = rows.groups.last_mut().expect("just added");
            group.friction = f;
            if kind != RowKind::ContactFrictionless {
                contact_regularisers(rows, options.cone, options.impratio);
            }
        }
    }
    Ok(())
}

/// Closes the group of the last `count` rows: their impedance, regularisers and reference
/// accelerations.
fn finish_group(
    rows: &mut Rows,
    kind: RowKind,
    count: usize,
    softness: &Softness,
    safe_after: Option<f64>,
    v: &[f64],
) {
    let first = rows.len() - count;
    // MuJoCo leaves out a group that moves nothing (a tendon whose Jacobian cancels), but a contact
    let contact = matches!(
        kind,
        RowKind::ContactFrictionless | RowKind::ContactPyramidal | RowKind::ContactElliptic
    );
    if !contact && rows.jacobian[first * rows.nv..].iter().all(|j| *j == 0.0) {
        rows.discard_last(count);
        return;
    }
    let solimp = &softness.solver.solimp;
    // d of the first row's |pos − margin|, of an equality's |pos| over its rows
    let violation = if kind == RowKind::Equality {
        rows.position[first..]
            .iter()
            .map(|p| p * p)
            .sum::<f64>()
            .sqrt()
    } else {
        rows.position[first] - rows.margin[first]
    };
    let (d, _) = impedance(solimp, violation);
    for k in 0..count {
        let i = first + k;
        rows.regulariser
            .push(((1.0 - d) / d * softness.diagonal[k]).max(TINY));
        // a friction row (dry friction, an elliptic cone's tangents) has no spring
        let friction_row = matches!(kind, RowKind::FrictionDof | RowKind::FrictionTendon)
            || (kind == RowKind::ContactElliptic && k > 0);
        let solref = if kind == RowKind::ContactElliptic
            && k > 0
            && softness.friction_solref != [0.0, 0.0]
        {
            softness.friction_solref
        } else {
            softness.solver.solref
        };
        let (stiffness, damper) = spring_and_damper(&solref, solimp, safe_after);
        let stiffness = if friction_row { 0.0 } else { stiffness };
        let velocity: f64 = rows.row(i).iter().zip(v).map(|(j, v)| j * v).sum();
        let reference = -damper * velocity - stiffness * d * (rows.position[i] - rows.margin[i]);
        rows.reference.push(reference);
    }
    rows.groups.push(Group {
        first,
        len: count,
        kind,
        mu: 0.0,
        friction: [0.0; 5],
    });
}

/// A contact's friction regularisers (the last group): the elliptic cone's tangents softer by
/// impratio and scaled by f₀²/f_k², or the pyramid's rows all 2 μ² R₀.
fn contact_regularisers(rows: &mut Rows, cone: FrictionCone, impratio: f64) {
    let group = rows.groups.last_mut().expect("a contact's group");
    let (first, f) = (group.first, group.friction);
    let normal = rows.regulariser[first];
    let tangent = normal / impratio.max(TINY);
    // μ = f₀ √(R_t₁ / R_n)
    let mu = f[0] * (tangent / normal).sqrt();
    if cone == FrictionCone::Elliptic {
        group.mu = mu;
        rows.regulariser[first + 1] = tangent;
        for j in 1..group.len - 1 {
            rows.regulariser[first + j + 1] = tangent * f[0] * f[0] / (f[j] * f[j]);
        }
    } else {
        let edge = 2.0 * mu * mu * normal;
        rows.regulariser[first..first + group.len].fill(edge);
    }
}

/// The rotation of a unit quaternion (x, y, z, w) as an angle |θ| ∈ [0, π] and a unit axis u
/// (x when there is no rotation): θ = 2 atan2(|(x, y, z)|, w) taken into (−π, π], the axis
/// turned over with a negative θ.
fn rotation_vector(quaternion: &[f64]) -> (f64, Vec3) {
    let norm = quaternion.iter().map(|x| x * x).sum::<f64>().sqrt();
    let vector = Vec3::new(quaternion[0], quaternion[1], quaternion[2]) / norm;
    let w = quaternion[3] / norm;
    let sine = vector.norm();
    if sine < TINY {
        return (0.0, Vec3::x());
    }
    let mut angle = 2.0 * sine.atan2(w);
    if angle > std::f64::consts::PI {
        angle -= 2.0 * std::f64::consts::PI;
    }
    (angle.abs(), vector / sine * angle.signum())
}

/// Row `e_k` of body `i`'s joint in MuJoCo's velocities, in robodyn's: the same but for a free
/// joint's linear velocity, which MuJoCo takes in world axes (v_world = Eᵀ v_body), so that its
/// row k is column k of E.
fn mujoco_dof_row(model: &Model, x_world: &[Transform], i: usize, k: usize, row: &mut [f64]) {
    let start = model.idx_v[i];
    if matches!(model.joints[i], Joint::Free) && k < 3 {
        let e = &x_world[i].rotation;
        for c in 0..3 {
            row[start + c] = e[(c, k)];
        }
    } else {
        row[start + k] = 1.0;
    }
}

/// The six rows `F (J(b₂, p) − J(b₁, p))` of a contact at p with frame F (normal, tangents:
/// translation, then rotation) into `out` (6 × nv, zero on entry).
fn contact_jacobian(
    model: &Model,
    x_world: &[Transform],
    (b1, b2): (usize, usize),
    contact: &Contact,
    out: &mut [f64],
) {
    let nv = model.nv;
    let frame: &Mat3 = &contact.frame;
    for (body, sign) in [(b2, 1.0), (b1, -1.0)] {
        point_columns(
            model,
            x_world,
            body,
            &contact.position,
            |column, linear, angular| {
                let (t, r) = (frame * linear, frame * angular);
                for row in 0..3 {
                    out[row * nv + column] += sign * t[row];
                    out[(3 + row) * nv + column] += sign * r[row];
                }
            },
        );
    }
}
