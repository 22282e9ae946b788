//! MuJoCo's equality rows: a model's connect, weld, joint and tendon equalities as soft
//! constraints, the first block of rows.
//!
//! Reference: MuJoCo's documentation, "Computation", §Equality constraints (read to understand,
//! written anew here). With p₁, p₂ the constrained point as body1 and body2 carry it, q₁, q₂ the
//! weld frame's orientation as they carry it (unit quaternions, world axes), t the weld's
//! `torquescale`, J_p and J_ω a point's velocity and its body's angular velocity (world axes):
//! ```text
//!   connect  3 rows   pos = p₁ − p₂                   J = J_p₁ − J_p₂
//!   weld     6 rows   the connect's, then
//!                     pos = t vec(q̄₂ ⊗ q₁)            J = ½ t vec(q̄₂ ⊗ (0, J_ω₁ − J_ω₂) ⊗ q₁)
//!   joint    1 row    pos = (q_f − q_f,0) − p(q_l − q_l,0)      J = e_f − p′ e_l
//!   tendon   1 row    pos = (L₁ − L₁,₀) − p(L₂ − L₂,₀)          J = J_L₁ − p′ J_L₂
//! ```
//! The weld's rotation rows are the time derivative of its error: `vec(q̄₂ ⊗ (0, u) ⊗ q₁) =
//! (e₀ I − [e_v]×) R₂ᵀ u` with `e = q̄₂ ⊗ q₁` (taken with e₀ ≥ 0: past a relative turn of π
//! MuJoCo's rows are these negated, the same physics). A group's impedance d is that of the norm
//! of its positions (margin 0); its rows' Â are the two bodies' translation weights (a weld's
//! rotation rows: their rotation weights) or the two joints' or tendons' own. Connect and weld
//! rows ask their acceleration `J q̈ + J̇ q̇` to follow `−b J q̇ − k d pos`: their a_ref carries
//! `−J̇ q̇`, with, on the weld's rotation rows (q̇_k = ½ (0, ω_k) ⊗ q_k, Δω = ω₁ − ω₂),
//! ```text
//!   J̇ q̇ = ½ t vec(q̄̇₂ ⊗ (0, Δω) ⊗ q₁ + q̄₂ ⊗ (0, Δω̇) ⊗ q₁ + q̄₂ ⊗ (0, Δω) ⊗ q̇₁)
//! ```
//! The connect's and weld's position rows and their J̇ q̇ are robodyn's own point and frame
//! constraints in world axes ([`crate::constraint`]).

use super::rows::{RowKind, Rows};
use super::tendons::TendonKinematics;
use super::weights::InverseWeights;
use crate::algo::constrained::evaluate_rows;
use crate::constraint::{
    polynomial_at, Attachment, Constraint, ConstraintKind, ConstraintReference, ConstraintRows,
    ConstraintSet,
};
use crate::error::{Error, Result};
use crate::model::{Model, SolverParameters, TendonEquality, UnreadElements};
use crate::spatial::{Mat3, Vec3};
use crate::Data;
use nalgebra::{DMatrix, DVector, Quaternion, Rotation3, UnitQuaternion};

/// One active equality: what MuJoCo's rows of it need beyond robodyn's rows.
#[derive(Debug, Clone)]
struct Held {
    /// Its index among the file's equalities (MuJoCo's `efc_id`).
    index: usize,
    /// Connect, weld, joint or tendon.
    shape: Shape,
    /// Its place in the constraint set (a tendon equality has none).
    member: usize,
    /// Its `solref` and `solimp`.
    solver: SolverParameters,
    /// Each row's approximate inverse inertia Â.
    diagonal: [f64; 6],
}

/// The MuJoCo equality a robodyn constraint stands for.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Shape {
    Connect,
    /// With its torquescale.
    Weld(f64),
    Joint,
    /// [`Model::tendon_equalities`] index.
    Tendon(usize),
}

/// A model's active equalities and the scratch space their rows are made in.
#[derive(Debug, Clone)]
pub struct Equalities {
    held: Vec<Held>,
    /// The same constraints, point and frame ones in world axes.
    set: ConstraintSet,
    jacobian: DMatrix<f64>,
    drift: DVector<f64>,
    error: DVector<f64>,
    /// w = (ω × v, 0) on free joints: MuJoCo's accelerations are `T (q̈ + w)`.
    free_product: DVector<f64>,
    data: Data,
}

impl Equalities {
    /// The active equalities of `model` (none when its `equality` flag is off), with `weights`
    /// for their rows' Â. A constraint MuJoCo's equalities cannot state (a distance, a frame
    /// holding only some rows, a coupled joint of several coordinates) is refused, naming it.
    pub fn new(model: &Model, weights: &InverseWeights) -> Result<Self> {
        let mut held = Vec::new();
        let mut constraints = Vec::new();
        let enforced = model.options.flag("equality") && model.options.flag("constraint");
        // MuJoCo numbers the file's equalities in order: the tendon ones among the others
        let mut index = 0;
        for (k, declared) in model.constraints.iter().map(Some).chain([None]).enumerate() {
            for (j, equality) in model.tendon_equalities.iter().enumerate() {
                if equality.before != k {
                    continue;
                }
                if enforced && equality.active {
                    let (t1, t2) = equality.tendons;
                    let own = weights.tendons[t1] + t2.map_or(0.0, |t| weights.tendons[t]);
                    held.push(Held {
                        index: UnreadElements::mujoco_id(&model.unread.equalities, index),
                        shape: Shape::Tendon(j),
                        member: usize::MAX,
                        solver: equality.solver,
                        diagonal: [own; 6],
                    });
                }
                index += 1;
            }
            let Some(declared) = declared else {
                break;
            };
            let id = UnreadElements::mujoco_id(&model.unread.equalities, index);
            index += 1;
            if !(enforced && declared.active) {
                continue;
            }
            let constraint = &declared.constraint;
            // a connect's or weld's Â comes from its file bodies, which only an MJCF file names
            let moves = constraint
                .bodies(model)
                .into_iter()
                .flatten()
                .any(|b| b != 0);
            let weighed = declared.bodies != [0, 0] || !moves;
            let point_or_frame = matches!(
                constraint.kind,
                ConstraintKind::Point { .. } | ConstraintKind::Frame { .. }
            );
            if point_or_frame && !weighed {
                return Err(unweighed(model, k, constraint));
            }
            let body = |k: usize| {
                let weight = weights.bodies.get(declared.bodies[k]);
                weight.copied().unwrap_or_default()
            };
            let translation = body(0)[0] + body(1)[0];
            let (shape, diagonal) = match &constraint.kind {
                ConstraintKind::Point { .. } => (Shape::Connect, [translation; 6]),
                ConstraintKind::Frame { mask, .. } if mask.iter().all(|&kept| kept) => {
                    let rotation = body(0)[1] + body(1)[1];
                    let diagonal = [
                        translation,
                        translation,
                        translation,
                        rotation,
                        rotation,
                        rotation,
                    ];
                    (Shape::Weld(declared.torquescale), diagonal)
                }
                ConstraintKind::Coupling {
                    follower, leader, ..
                } => {
                    let dof = |b: usize| weights.dofs[model.idx_v[b]];
                    let own = dof(*follower) + leader.map_or(0.0, dof);
                    (Shape::Joint, [own; 6])
                }
                _ => return Err(unstated(model, k, constraint)),
            };
            held.push(Held {
                index: id,
                shape,
                member: constraints.len(),
                solver: SolverParameters {
                    solref: declared.solref,
                    solimp: declared.solimp,
                },
                diagonal,
            });
            constraints.push(Constraint {
                kind: constraint.kind.clone(),
                reference: ConstraintReference::World,
            });
        }
        let set = ConstraintSet::new(model, constraints)?;
        let m = set.rows();
        Ok(Equalities {
            held,
            jacobian: DMatrix::zeros(m, model.nv),
            drift: DVector::zeros(m),
            error: DVector::zeros(m),
            free_product: DVector::zeros(model.nv),
            set,
            data: Data::new(model),
        })
    }

    /// Appends the rows of every active equality at (q, q̇) to `rows` (see the module's header),
    /// each group closed by `close(rows, count, solver, diagonal)`, which leaves a_ref without
    /// the J̇ q̇ term added here.
    pub(super) fn append(
        &mut self,
        model: &Model,
        (q, v): (&[f64], &[f64]),
        tendons: &TendonKinematics,
        rows: &mut Rows,
        mut close: impl FnMut(&mut Rows, usize, &SolverParameters, &[f64]),
    ) -> Result<()> {
        if self.held.is_empty() {
            return Ok(());
        }
        let robodyn_rows = ConstraintRows {
            jacobian: &mut self.jacobian,
            drift: self.drift.as_mut_slice(),
            error: self.error.as_mut_slice(),
        };
        evaluate_rows(model, &mut self.data, &self.set, (q, v), robodyn_rows)?;
        super::dynamics::write_free_joint_product(model, v, &mut self.free_product);
        let nv = model.nv;
        for held in &self.held {
            if let Shape::Tendon(j) = held.shape {
                tendon_row(
                    model,
                    &model.tendon_equalities[j],
                    held.index,
                    tendons,
                    rows,
                );
                close(rows, 1, &held.solver, &held.diagonal[..1]);
                continue;
            }
            let k = held.member;
            let offset = self.set.offset(k);
            let count = self.set.constraints()[k].rows();
            // one that moves nothing (between bodies welded to the world) has no rows
            let moves =
                (offset..offset + count).any(|r| (0..nv).any(|c| self.jacobian[(r, c)] != 0.0));
            if !moves {
                continue;
            }
            let first = rows.len();
            for r in offset..offset + count {
                let row = rows.push(RowKind::Equality, held.index, self.error[r], 0.0);
                for (c, entry) in row.iter_mut().enumerate() {
                    *entry = self.jacobian[(r, c)];
                }
            }
            // J̇ q̇ as MuJoCo's accelerations see it: robodyn's γ less J w
            let mut drift = [0.0; 6];
            if held.shape != Shape::Joint {
                for (j, r) in (offset..offset + count).enumerate() {
                    let along_w: f64 = (0..nv)
                        .map(|c| self.jacobian[(r, c)] * self.free_product[c])
                        .sum();
                    drift[j] = self.drift[r] - along_w;
                }
            }
            if let Shape::Weld(torquescale) = held.shape {
                let turn =
                    WeldTurn::new(model, &self.data, &self.set.constraints()[k], torquescale);
                // pos = t e_v;  J = G J_ω;  J̇ q̇ from Δω̇, the angular rows' γ
                let g = turn.row_map();
                for j in 0..3 {
                    rows.position[first + 3 + j] = torquescale * turn.error.vector()[j];
                }
                for c in 0..nv {
                    let column = Vec3::new(
                        self.jacobian[(offset + 3, c)],
                        self.jacobian[(offset + 4, c)],
                        self.jacobian[(offset + 5, c)],
                    );
                    let turned = g * column;
                    for j in 0..3 {
                        rows.jacobian[(first + 3 + j) * nv + c] = turned[j];
                    }
                }
                let dw_dot = Vec3::new(
                    self.drift[offset + 3],
                    self.drift[offset + 4],
                    self.drift[offset + 5],
                );
                drift[3..6].copy_from_slice(turn.drift(&dw_dot).as_slice());
            }
            close(rows, count, &held.solver, &held.diagonal[..count]);
            for (reference, drift) in rows.reference[first..].iter_mut().zip(&drift) {
                *reference -= drift;
            }
        }
        Ok(())
    }
}

/// The row of a tendon equality at the tendons' lengths and Jacobians `tendons` (see the
/// module's header), its a_ref to be made.
fn tendon_row(
    model: &Model,
    equality: &TendonEquality,
    index: usize,
    tendons: &TendonKinematics,
    rows: &mut Rows,
) {
    let c = &equality.polynomial;
    let (first, second) = equality.tendons;
    let displacement = |t: usize| tendons.lengths[t] - model.tendons[t].length0;
    let follower = displacement(first);
    // p(x) and p′(x) of the leader's x = L₂ − L₂,₀ (without one: c₀ and 0)
    let [p, dp, _, _] = match second {
        Some(leader) => polynomial_at(c, displacement(leader)),
        None => [c[0], 0.0, 0.0, 0.0],
    };
    let row = rows.push(RowKind::Equality, index, follower - p, 0.0);
    tendons.add_to_row(first, 1.0, row);
    if let Some(leader) = second {
        tendons.add_to_row(leader, -dp, row);
    }
}

/// A weld's rotation at one state: the weld frame's orientation as each body carries it, and the
/// bodies' angular velocities (world axes).
struct WeldTurn {
    /// q₁, its sign such that e₀ ≥ 0.
    one: UnitQuaternion<f64>,
    /// q₂.
    other: UnitQuaternion<f64>,
    /// e = q̄₂ ⊗ q₁.
    error: UnitQuaternion<f64>,
    /// ω₁, ω₂.
    angular: [Vec3; 2],
    /// t.
    torquescale: f64,
}

impl WeldTurn {
    /// The weld `constraint` (a frame constraint) with the bodies' placements and velocities of
    /// `data`.
    fn new(model: &Model, data: &Data, constraint: &Constraint, torquescale: f64) -> Self {
        let ConstraintKind::Frame { first, second, .. } = &constraint.kind else {
            unreachable!("a weld is a frame constraint");
        };
        let carried = |attachment: Option<&Attachment>| -> (UnitQuaternion<f64>, Vec3) {
            let Some(attachment) = attachment else {
                return (UnitQuaternion::identity(), Vec3::zeros());
            };
            let (placement, angular) = match attachment.frame {
                None => (attachment.placement, Vec3::zeros()),
                Some(f) => {
                    let frame = &model.frames[f];
                    let x_body = &data.x_world[frame.body];
                    // X_{c←0} = X_{c←frame} X_{frame←body} X_{body←0};  ω in world axes
                    let placement = attachment.placement * (frame.placement * *x_body);
                    (
                        placement,
                        x_body.rotation.transpose() * data.v[frame.body].angular,
                    )
                }
            };
            // the frame's orientation in the world: Eᵀ
            let rotation = Rotation3::from_matrix_unchecked(placement.rotation.transpose());
            (UnitQuaternion::from_rotation_matrix(&rotation), angular)
        };
        let (mut one, angular_one) = carried(Some(first));
        let (other, angular_other) = carried(second.as_ref());
        let mut error = other.conjugate() * one;
        if error.w < 0.0 {
            one = UnitQuaternion::new_unchecked(-one.into_inner());
            error = UnitQuaternion::new_unchecked(-error.into_inner());
        }
        WeldTurn {
            one,
            other,
            error,
            angular: [angular_one, angular_other],
            torquescale,
        }
    }

    /// G = ½ t (e₀ I − [e_v]×) R₂ᵀ: the rotation rows are `G J_ω`.
    fn row_map(&self) -> Mat3 {
        let e = self.error.quaternion();
        let half = 0.5 * self.torquescale;
        let turn = Mat3::identity() * e.w - e.vector().cross_matrix();
        half * turn * self.other.to_rotation_matrix().matrix().transpose()
    }

    /// J̇ q̇ of the rotation rows, given Δω̇ (q̈ = 0): see the module's header.
    fn drift(&self, dw_dot: &Vec3) -> Vec3 {
        let pure = |w: &Vec3| Quaternion::from_imag(*w);
        // q̇ = ½ (0, ω) ⊗ q
        let rate = |w: &Vec3, q: &UnitQuaternion<f64>| pure(w) * q.quaternion() * 0.5;
        let (one, other) = (self.one.quaternion(), self.other.conjugate().into_inner());
        let dw = self.angular[0] - self.angular[1];
        let other_rate = rate(&self.angular[1], &self.other).conjugate();
        let one_rate = rate(&self.angular[0], &self.one);
        let sum = other_rate * pure(&dw) * one
            + other * pure(dw_dot) * one
            + other * pure(&dw) * one_rate;
        sum.imag() * (0.5 * self.torquescale)
    }
}

/// The error for a connect or weld without the file bodies whose weights soften it.
fn unweighed(model: &Model, index: usize, constraint: &Constraint) -> Error {
    Error::InvalidValue {
        argument: "model".into(),
        message: format!(
            "model constraint {index} ({}) names no file bodies (ModelConstraint.bodies): MuJoCo's \
             soft rows weigh a connect or weld by its bodies' body_invweight0",
            constraint.describe(model)
        ),
    }
}

/// The error for a model constraint MuJoCo's equalities cannot state.
fn unstated(model: &Model, index: usize, constraint: &Constraint) -> Error {
    Error::InvalidValue {
        argument: "model".into(),
        message: format!(
            "model constraint {index} ({}) has no MuJoCo equality (connect, weld of six rows, \
             joint coupling): its soft rows cannot be made",
            constraint.describe(model)
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algo::forward_kinematics;
    use crate::io::mjcf::load_mjcf_str;
    use crate::soft::impedance::spring_and_damper;
    use crate::soft::rows::constraint_rows;
    use crate::soft::weights::inverse_weights;

    /// A weld (with torquescale) between a two-joint arm and a free box, a free ball's point
    /// connected to the world, and a slide coupled to a hinge by a polynomial.
    const SCENE: &str = r#"<mujoco><option timestep="0.002"/>
      <worldbody>
        <body name="arm" pos="0 0 1"><joint name="h1" axis="0 1 0"/>
          <geom type="capsule" fromto="0 0 0 .5 0 0" size=".05"/>
          <body name="fore" pos=".5 0 0" euler="10 20 30">
            <joint name="h2" axis="0 0 1"/><joint name="s2" type="slide" axis="1 0 0"/>
            <geom type="box" size=".2 .05 .05" pos=".2 0 0"/></body></body>
        <body name="box" pos="1 .3 1.2" euler="5 -10 40"><freejoint/>
          <geom type="box" size=".1 .2 .3" mass="2"/></body>
        <body name="ball" pos="-1 0 1"><freejoint/><geom type="sphere" size=".1"/></body>
      </worldbody>
      <equality>
        <weld body1="fore" body2="box" torquescale="2" solref="0.03 0.8"/>
        <connect body1="ball" anchor="0 0 .1"/>
        <joint joint1="s2" joint2="h1" polycoef="0.1 0.5 0.2 0 0"/>
      </equality></mujoco>"#;

    /// The rows at (q, q̇), equality rows only (the scene has no contact).
    fn rows_at(model: &Model, q: &[f64], v: &[f64]) -> Rows {
        let mut data = Data::new(model);
        let weights = inverse_weights(model, &mut data).unwrap();
        let mut equalities = Equalities::new(model, &weights).unwrap();
        let x_world = forward_kinematics(model, &mut data, q).unwrap().to_vec();
        let tendons = TendonKinematics::at(model, &mut data, q).unwrap();
        let mut rows = Rows::default();
        constraint_rows(
            model,
            &weights,
            (q, v),
            (&x_world, &tendons),
            &[],
            &mut equalities,
            &mut rows,
        )
        .unwrap();
        rows
    }

    /// q ⊕ v t.
    fn along(model: &Model, q: &[f64], v: &[f64], t: f64) -> Vec<f64> {
        let step: Vec<f64> = v.iter().map(|x| x * t).collect();
        let mut out = vec![0.0; model.nq];
        model.integrate(q, &step, &mut out).unwrap();
        out
    }

    #[test]
    fn rows_are_the_errors_derivatives_and_a_ref_carries_their_curvature() {
        let model = load_mjcf_str(SCENE, "scene").unwrap();
        let mut q = model.neutral_configuration.as_slice().to_vec();
        let v: Vec<f64> = (0..model.nv)
            .map(|k| ((k * 7 + 3) % 11) as f64 / 5.0 - 1.0)
            .collect();
        // away from qpos0, so that every error is not zero
        q = along(&model, &q, &v, 0.1);
        let rows = rows_at(&model, &q, &v);
        assert_eq!(rows.len(), 10, "weld 6, connect 3, joint 1");
        let (step, position) = (1e-4, |t: f64| {
            rows_at(&model, &along(&model, &q, &v, t), &v).position
        });
        let (before, after) = (position(-step), position(step));
        let at_rest = rows_at(&model, &q, &vec![0.0; model.nv]);
        let mut w = DVector::zeros(model.nv);
        super::super::dynamics::write_free_joint_product(&model, &v, &mut w);
        let groups = [
            (0..6, [0.03, 0.8]),
            (6..9, crate::model::DEFAULT_SOLREF),
            (9..10, crate::model::DEFAULT_SOLREF),
        ];
        for (range, solref) in groups {
            let (_, damper) =
                spring_and_damper(&solref, &crate::model::DEFAULT_SOLIMP, Some(0.004));
            for i in range {
                // J q̇ = d pos/dt
                let velocity: f64 = rows.row(i).iter().zip(&v).map(|(j, v)| j * v).sum();
                let rate = (after[i] - before[i]) / (2.0 * step);
                assert!(
                    (velocity - rate).abs() < 1e-6 * (1.0 + rate.abs()),
                    "row {i}: J q̇ {velocity} vs {rate}"
                );
                // a_ref(q, 0) − a_ref(q, q̇) − b J q̇ = J̇ q̇ in MuJoCo's terms, d²pos/dt² − J w
                let drift = at_rest.reference[i] - rows.reference[i] - damper * velocity;
                let curvature = (after[i] - 2.0 * rows.position[i] + before[i]) / (step * step);
                let expected = if i == 9 {
                    0.0 // a joint equality's a_ref has no J̇ q̇ (as in MuJoCo)
                } else {
                    curvature
                        - rows
                            .row(i)
                            .iter()
                            .zip(w.iter())
                            .map(|(j, w)| j * w)
                            .sum::<f64>()
                };
                assert!(
                    (drift - expected).abs() < 1e-5 * (1.0 + expected.abs()),
                    "row {i}: J̇ q̇ {drift} vs {expected}"
                );
            }
        }
    }

    #[test]
    fn a_connect_without_file_bodies_is_refused_naming_it() {
        // a connect made elsewhere than in an MJCF file has no bodies to weigh it by
        let mut model = load_mjcf_str(SCENE, "scene").unwrap();
        let mut data = Data::new(&model);
        let weights = inverse_weights(&model, &mut data).unwrap();
        model.constraints[1].bodies = [0, 0];
        let error = Equalities::new(&model, &weights).unwrap_err().to_string();
        assert!(
            error.contains("model constraint 1") && error.contains("names no file bodies"),
            "{error}"
        );
    }
}
