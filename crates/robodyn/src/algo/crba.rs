//! Composite-rigid-body algorithm: the joint-space inertia matrix M(q).
//!
//! Reference: Featherstone, *Rigid Body Dynamics Algorithms* (2008), §6.2 and Table 6.2:
//! `H_ij = S_iᵀ I^c_i S_j` for j an ancestor of i (or i itself), with `I^c_i` the composite inertia
//! of the subtree rooted at body i. Table 6.2 evaluates it in body coordinates, carrying the force
//! `F = I^c_i S_i` up the tree; here every quantity is expressed once in world coordinates, where
//! composite inertias add without transforms and each `H_ij` is a single dot product (the form
//! Pinocchio uses). The UR5 dynamics notes obtain the same M from n RNEA calls; the tests check it.
//! Input: q (nq). Writes `data.x_up`, `data.x_world`, `data.s_world`, `data.i_c` (world
//! coordinates), `data.mass_matrix` (full, symmetric, armature on the diagonal).
//! Cost: O(n) transforms plus one 6-vector dot product per pair (joint, ancestor joint).

use crate::algo::kinematics::body_placements;
use crate::error::{check_length, Result};
use crate::model::Model;
use crate::spatial::{Inertia, Motion, Real, Transform};
use crate::Data;
use nalgebra::DMatrix;

/// M(q), written into `data.mass_matrix`.
pub fn crba<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> Result<&'d DMatrix<f64>> {
    let mut mass_matrix = std::mem::take(&mut data.mass_matrix);
    let result = crba_into(model, data, q, mass_matrix.as_mut_slice());
    data.mass_matrix = mass_matrix;
    result.map(|()| &data.mass_matrix)
}

/// [`crba`] with M written into `out` (nv × nv; M is mirrored, exactly symmetric, so its
/// row-major and column-major layouts are the same) instead of `data.mass_matrix`: for a caller
/// that hands it on (NumPy) without a copy.
pub fn crba_into(model: &Model, data: &mut Data, q: &[f64], out: &mut [f64]) -> Result<()> {
    model.check_configuration(q)?;
    check_length("out", out.len(), model.nv * model.nv)?;
    world_inertias_and_subspaces(model, data, q);
    add_composite_inertias(model, data);
    composite_mass_matrix(model, data, out);
    Ok(())
}

/// M into `mass_matrix` (column-major, nv × nv) from the world-frame composites in `data.i_c`
/// and subspaces in `data.s_world`, armature on the diagonal.
pub(crate) fn composite_mass_matrix(model: &Model, data: &Data, mass_matrix: &mut [f64]) {
    mass_matrix_of_composites(model, &data.i_c, &data.s_world, mass_matrix);
}

/// M from world-frame composites and subspaces, in `f64` or lanes.
#[inline(always)]
pub(crate) fn mass_matrix_of_composites<S: Real>(
    model: &Model,
    composites: &[Inertia<S>],
    subspaces: &[Motion<S>],
    mass_matrix: &mut [S],
) {
    // H_ij = ⁰S_jᵀ (I^c_i ⁰S_i) for j on the path from i to the root; other entries are zero
    let nv = model.nv;
    mass_matrix.fill(S::splat(0.0));
    for (i, composite) in composites.iter().enumerate().skip(1) {
        for row in model.v_range(i) {
            // F = I^c_i S_i
            let f = composite.mul_motion(&subspaces[row]);
            // the row itself, then up its coordinates' path (the joint's earlier ones, the
            // ancestors'), in runs of consecutive columns
            for run in model.ancestor_runs(row) {
                for col in run {
                    // column-major storage: H[row, col] at row + col nv
                    let h = subspaces[col].dot(&f);
                    mass_matrix[row + col * nv] = h;
                    mass_matrix[col + row * nv] = h;
                }
            }
            mass_matrix[row + row * nv] += S::splat(model.armature[row]);
        }
    }
}

/// Poses, then each body's own inertia in world coordinates in `data.i_c` and the motion subspace
/// columns in `data.s_world`: ⁰I_i = X_{i←0}ᵀ I_i X_{i←0}, ⁰S_i = X_{i←0}⁻¹ S_i.
pub(crate) fn world_inertias_and_subspaces(model: &Model, data: &mut Data, q: &[f64]) {
    let buffers = CompositeBuffers {
        x_up: &mut data.x_up,
        x_world: &mut data.x_world,
        composites: &mut data.i_c,
        subspaces: &mut data.s_world,
    };
    world_inertias_of(model, q, buffers);
}

/// What the CRBA's passes write: one state's, borrowed from [`Data`], or several states' in
/// lanes ([`crate::algo::lanes`]).
pub(crate) struct CompositeBuffers<'b, S> {
    pub x_up: &'b mut [Transform<S>],
    pub x_world: &'b mut [Transform<S>],
    pub composites: &'b mut [Inertia<S>],
    pub subspaces: &'b mut [Motion<S>],
}

/// [`world_inertias_and_subspaces`] in `f64` or lanes.
#[inline(always)]
pub(crate) fn world_inertias_of<S: Real>(model: &Model, q: &[S], out: CompositeBuffers<S>) {
    body_placements(model, q, out.x_up, out.x_world);
    for i in 1..model.nbodies() {
        let x_world = &out.x_world[i];
        out.composites[i] = x_world.transpose_apply_inertia(&Inertia::splat(&model.inertias[i]));
        for (k, dof) in model.v_range(i).enumerate() {
            out.subspaces[dof] = model.joints[i].subspace_column_from(k, x_world);
        }
    }
}

/// Composite inertias, leaves to root: I^c_λ(i) += I^c_i (world coordinates, no transform).
pub(crate) fn add_composite_inertias(model: &Model, data: &mut Data) {
    add_composites(model, &mut data.i_c);
}

/// [`add_composite_inertias`] in `f64` or lanes.
#[inline(always)]
pub(crate) fn add_composites<S: Real>(model: &Model, composites: &mut [Inertia<S>]) {
    for i in (1..model.nbodies()).rev() {
        let parent = model.parent[i];
        if parent != 0 {
            let subtree = composites[i];
            composites[parent] += subtree;
        }
    }
}
