//! Composite-rigid-body algorithm: the joint-space inertia matrix M(q).
//!
//! Reference: Featherstone, *Rigid Body Dynamics Algorithms* (2008), Table 6.2. Seeds 000/003 give
//! the same matrix as Σ mᵢ J_vᵢᵀ J_vᵢ + J_ωᵢᵀ Iᵢ J_ωᵢ and as n RNEA calls; the tests check both.
//! Input: q (nq). Writes `data.x_up`, `data.i_c`, `data.mass_matrix` (full, symmetric, armature on
//! the diagonal). Cost: O(n d), d the depth of the tree.

use crate::algo::kinematics::update_joint_transforms;
use crate::error::Result;
use crate::model::Model;
use crate::Data;
use nalgebra::DMatrix;

/// M(q), written into `data.mass_matrix`.
pub fn crba<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> Result<&'d DMatrix<f64>> {
    model.check_configuration(q)?;
    update_joint_transforms(model, data, q);

    // composite inertias, leaves to root: I^c_λ(i) += X_iᵀ I^c_i X_i
    data.i_c.copy_from_slice(&model.inertias);
    for i in (1..model.nbodies()).rev() {
        let parent = model.parent[i];
        if parent != 0 {
            let inertia = data.x_up[i].transpose_apply_inertia(&data.i_c[i]);
            data.i_c[parent] += inertia;
        }
    }

    // one column block per joint: F = I^c_i S_i, walked up to the root; entries between
    // different branches stay zero
    data.mass_matrix.as_mut_slice().fill(0.0);
    for i in 1..model.nbodies() {
        let joint = &model.joints[i];
        for (k, row) in model.v_range(i).enumerate() {
            let mut f = data.i_c[i].mul_motion(&joint.subspace_column(k));
            // H_ii = S_iᵀ F (the block's upper triangle, mirrored)
            for (l, col) in model.v_range(i).enumerate().skip(k) {
                let h = joint.project_force(l, &f);
                data.mass_matrix[(row, col)] = h;
                data.mass_matrix[(col, row)] = h;
            }
            data.mass_matrix[(row, row)] += model.armature[row];
            let mut j = i;
            while model.parent[j] != 0 {
                // F = X_jᵀ F;  j = λ(j);  H_ij = Fᵀ S_j = H_ji
                f = data.x_up[j].transpose_apply_force(&f);
                j = model.parent[j];
                for (l, col) in model.v_range(j).enumerate() {
                    let h = model.joints[j].project_force(l, &f);
                    data.mass_matrix[(row, col)] = h;
                    data.mass_matrix[(col, row)] = h;
                }
            }
        }
    }

    Ok(&data.mass_matrix)
}
