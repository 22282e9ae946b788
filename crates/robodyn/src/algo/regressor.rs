//! The joint-torque regressor: τ = Y(q, q̇, q̈) π, linear in the ten standard inertial parameters
//! π_i = [m, m c, Ī_O] of every moving body (see [`Inertia::to_parameters`]).
//!
//! Reference: Atkeson, An and Hollerbach, "Estimation of inertial parameters of manipulator loads
//! and links", IJRR 5(3), 1986; Featherstone (2008) §5.3 for the recursion. Body i's Newton–Euler
//! force f_i = I_i a_i + v_i ×* I_i v_i is linear in π_i (`Inertia::force_regressor`), and joint j
//! carries the forces of every body in its subtree: τ_j = S_jᵀ Σ_{i ∈ subtree(j)} X_{i←j}ᵀ f_i. So
//! the block of Y for joint j and body i (j on i's path to the world) is S_jᵀ X_{i←j}ᵀ F_i(v_i, a_i),
//! built by carrying F_i from body i towards the world one transform at a time.
//! Armature is not an inertial parameter of a body: τ = Y π + armature · (q̈ + its velocity terms),
//! which is zero for models without armature. Writes `data.regressor` (nv × 10 (nbodies − 1)) and
//! what `rnea` writes. Cost: O(n · depth).

use crate::algo::rnea::newton_euler;
use crate::error::{check_vector, Result};
use crate::model::Model;
use crate::spatial::Inertia;
use crate::Data;
use nalgebra::DMatrix;

/// Y(q, q̇, q̈), nv × 10 (nbodies − 1): column block i − 1 holds body i's ten parameters.
pub fn torque_regressor<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
) -> Result<&'d DMatrix<f64>> {
    check_vector("v", v, model.nv)?;
    check_vector("a", a, model.nv)?;
    // the bodies' velocities and accelerations (gravity as a base acceleration)
    newton_euler(model, data, q, Some(v), Some(a), None)?;
    data.regressor.as_mut_slice().fill(0.0);
    for i in 1..model.nbodies() {
        // F_i, then X_{i←j}ᵀ F_i for each joint j from i towards the world
        let mut columns = Inertia::force_regressor(&data.v[i], &data.a[i]);
        let mut j = i;
        loop {
            for (k, dof) in model.v_range(j).enumerate() {
                for (c, column) in columns.iter().enumerate() {
                    data.regressor[(dof, 10 * (i - 1) + c)] =
                        model.joints[j].project_force(k, column);
                }
            }
            if model.parent[j] == 0 {
                break;
            }
            for column in &mut columns {
                *column = data.x_up[j].transpose_apply_force(column);
            }
            j = model.parent[j];
        }
    }
    Ok(&data.regressor)
}
