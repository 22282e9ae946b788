//! How heavy each body and each degree of freedom looks from outside, at the model's neutral
//! configuration: the approximate inverse inertias `Â` that scale MuJoCo's regulariser
//! `R = (1 − d)/d · Â` (MuJoCo's `body_invweight0` and `dof_invweight0`, computed once per model
//! by its `mj_setConst` at `qpos0`).
//!
//! Reference: MuJoCo's documentation, "Computation", §Soft constraints ("the approximate
//! diagonal"). For a body with centre of mass c, its 6 × nv Jacobian `J_c` (the velocity of c,
//! then the angular velocity, in world axes) gives the inverse inertia felt there,
//! ```text
//!   A = J_c M⁻¹ J_cᵀ,   Â_body = (tr A_tt / 3,  tr A_rr / 3)
//! ```
//! (0 for a body welded to the world), and a joint's block of `M⁻¹` gives its own:
//! `(M⁻¹)_ii` for a hinge or slide, the mean of the block's diagonal for a ball, of the
//! translation and rotation blocks apart for a free joint; a tendon's is `J M⁻¹ Jᵀ` (M with the
//! tendons' inertia, [`super::inertia`]). Both
//! traces are the same in any
//! coordinates of the velocities, so robodyn's free-joint velocities (linear in the body's axes)
//! give MuJoCo's numbers (linear in the world's).
//!
//! MuJoCo takes 1/m instead, for the body and for each of its slides, on a "simple" body (only
//! axis-aligned slides at its origin, its inertia frame its own, no child, under the world or a
//! jointless child of it: [`crate::model::SourceBody::simple`]).

use crate::algo::forward_kinematics;
use crate::error::Result;
use crate::joint::Joint;
use crate::model::Model;
use crate::spatial::{Transform, Vec3};
use crate::Data;

use super::inertia::inverse_inertia;
use super::tendons::TendonKinematics;
use super::TINY;
use nalgebra::DMatrix;

/// The approximate inverse inertias of the file's bodies and of the degrees of freedom.
#[derive(Debug, Clone, PartialEq)]
pub struct InverseWeights {
    /// Per file body ([`Model::source_bodies`]): (translation, rotation).
    pub bodies: Vec<[f64; 2]>,
    /// Per velocity coordinate.
    pub dofs: Vec<f64>,
    /// Per tendon: `J M⁻¹ Jᵀ` at qpos0 (MuJoCo's `tendon_invweight0`).
    pub tendons: Vec<f64>,
}

/// The weights of `model` at its neutral configuration (see the module's header).
pub fn inverse_weights(model: &Model, data: &mut Data) -> Result<InverseWeights> {
    let nv = model.nv;
    let q = model.neutral_configuration.as_slice();
    let inverse = inverse_inertia(model, data, q)?;
    let x_world = forward_kinematics(model, data, q)?.to_vec();
    // the bodies: A = J_c M⁻¹ J_cᵀ at each centre of mass
    let mut bodies = Vec::with_capacity(model.source_bodies.len());
    let mut jacobian = DMatrix::zeros(6, nv);
    for source in &model.source_bodies {
        if source.body == 0 {
            bodies.push([0.0, 0.0]);
            continue;
        }
        if source.simple {
            bodies.push([1.0 / source.mass.max(TINY), 0.0]);
            continue;
        }
        let centre = world_point(&x_world[source.body], &source.com);
        jacobian.fill(0.0);
        point_columns(
            model,
            &x_world,
            source.body,
            &centre,
            |column, linear, angular| {
                for r in 0..3 {
                    jacobian[(r, column)] = linear[r];
                    jacobian[(3 + r, column)] = angular[r];
                }
            },
        );
        let a = &jacobian * &inverse * jacobian.transpose();
        let trace = |from: usize| {
            (a[(from, from)] + a[(from + 1, from + 1)] + a[(from + 2, from + 2)]) / 3.0
        };
        bodies.push([trace(0), trace(3)]);
    }
    // the joints: their blocks of M⁻¹ (1/m on a simple body's slides)
    let mut dofs = vec![0.0; nv];
    let simple_mass = simple_body_masses(model);
    for (i, simple_mass) in simple_mass.iter().enumerate().skip(1) {
        let range = model.v_range(i);
        let mean = |from: usize, count: usize| {
            (from..from + count).map(|k| inverse[(k, k)]).sum::<f64>() / count as f64
        };
        match model.joints[i] {
            Joint::Free => {
                let (translation, rotation) = (mean(range.start, 3), mean(range.start + 3, 3));
                dofs[range.start..range.start + 3].fill(translation);
                dofs[range.start + 3..range.end].fill(rotation);
            }
            Joint::Spherical => {
                let value = mean(range.start, 3);
                dofs[range].fill(value);
            }
            _ => {
                for k in range {
                    dofs[k] = match simple_mass {
                        Some(mass) => 1.0 / mass.max(TINY),
                        None => inverse[(k, k)],
                    };
                }
            }
        }
    }
    // the tendons: J M⁻¹ Jᵀ of their J at qpos0
    let mut kinematics = TendonKinematics::default();
    kinematics.update(model, q, &x_world);
    let j = &kinematics.jacobian;
    let tendons = (&inverse * j.transpose())
        .column_iter()
        .zip(j.row_iter())
        .map(|(column, row)| row.dot(&column.transpose()))
        .collect();
    Ok(InverseWeights {
        bodies,
        dofs,
        tendons,
    })
}

/// Per model body, the mass of the simple file body whose slide it carries (see
/// [`crate::model::SourceBody::simple`]): the chain from that file body's model body to the
/// world is its own.
fn simple_body_masses(model: &Model) -> Vec<Option<f64>> {
    let mut masses = vec![None; model.nbodies()];
    for source in model.source_bodies.iter().filter(|s| s.simple) {
        let mut j = source.body;
        while j != 0 {
            masses[j] = Some(source.mass);
            j = model.parent[j];
        }
    }
    masses
}

/// The columns of the Jacobian of the world point `point` moving with `body`, those of the
/// joints between it and the world: each handed to `column(index, linear, angular)`, the point's
/// velocity and the body's angular velocity (world axes) that the coordinate makes.
pub(crate) fn point_columns(
    model: &Model,
    x_world: &[Transform],
    body: usize,
    point: &Vec3,
    mut column: impl FnMut(usize, &Vec3, &Vec3),
) {
    let mut j = body;
    while j != 0 {
        for (k, index) in model.v_range(j).enumerate() {
            // the joint's column (ω, v_O) at the world origin; at p: v_O + ω × p
            let s = model.joints[j].subspace_column_from(k, &x_world[j]);
            column(index, &(s.linear + s.angular.cross(point)), &s.angular);
        }
        j = model.parent[j];
    }
}

/// A point given in the frame of a body placed at `X_{body←0}` = (E, r), in world coordinates:
/// `Eᵀ p + r`.
pub(crate) fn world_point(x: &Transform, p: &Vec3) -> Vec3 {
    x.rotation.transpose() * p + x.translation
}
