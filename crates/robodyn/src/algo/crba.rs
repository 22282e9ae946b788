//! Composite-rigid-body algorithm: the joint-space inertia matrix M(q).
//!
//! Reference: Featherstone, *Rigid Body Dynamics Algorithms* (2008), §6.2 and Table 6.2:
//! `H_ij = S_iᵀ I^c_i S_j` for j an ancestor of i (or i itself), with `I^c_i` the composite inertia
//! of the subtree rooted at body i. Two forms, the same M:
//! - Table 6.2 in body coordinates (bodies in depth-first order, as every loader gives, so that a
//!   subtree's coordinates are consecutive): composites and forces `F = I^c_i S_i` carried to the
//!   parent joint by joint. The products with `S` are the joint's (`joint::subspace`); where the
//!   forces are kept, and how a joint carries them, is `layout`'s.
//! - Otherwise every quantity once in world coordinates, where composites add without transforms
//!   and each `H_ij` is a 6-vector dot product.
//!
//! The UR5 dynamics notes obtain the same M from n RNEA calls; the tests check it.
//! Input: q (nq). Writes `data.x_up`; `data.i_c_body` (body coordinates) or
//! `data.x_world`, `data.s_world`, `data.i_c` (world coordinates); `data.mass_matrix` (full,
//! symmetric, armature on the diagonal).
//! Cost: O(n) transforms plus a force carried (body coordinates) or a dot product (world
//! coordinates) per pair (joint, ancestor joint).

use crate::algo::kinematics::{body_placements, joint_transforms};
use crate::dispatch::multiversion;
use crate::error::{check_length, Result};
use crate::model::Model;
use crate::spatial::{Inertia, Motion, Real, Transform};
use crate::Data;
use nalgebra::DMatrix;

mod layout;

pub(crate) use layout::{ForceRows, ForceRowsRoom, MassColumns, SubtreeForces};

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
    one_state_mass_matrix(model, q, MassMatrixBuffers::of(data, out));
    Ok(())
}

multiversion! {
    /// [`mass_matrix_of`] of one state, built for AVX2 and FMA as well ([`crate::dispatch`]):
    /// the forces' carries take four forces per product ([`ForceRows`]), in one AVX2 vector so
    /// built.
    #[inline(never)]
    fn one_state_mass_matrix(model: &Model, q: &[f64], out: MassMatrixBuffers<f64, ForceRows>) {
        one_state_mass_matrix_avx2 for ["avx2", "fma"] => { mass_matrix_of(model, q, out) }
        baseline => { mass_matrix_of(model, q, out) }
    }
}

/// What the CRBA writes in either form: one state's, borrowed from [`Data`], or several states'
/// in lanes ([`crate::algo::lanes`]).
pub(crate) struct MassMatrixBuffers<'b, S, F> {
    pub x_up: &'b mut [Transform<S>],
    pub x_world: &'b mut [Transform<S>],
    pub world_composites: &'b mut [Inertia<S>],
    pub subspaces: &'b mut [Motion<S>],
    pub body_composites: &'b mut [Inertia<S>],
    pub forces: F,
    pub mass_matrix: &'b mut [S],
}

impl<'b> MassMatrixBuffers<'b, f64, ForceRows<'b>> {
    /// One state's buffers, borrowed from `data`, M written into `mass_matrix`.
    fn of(data: &'b mut Data, mass_matrix: &'b mut [f64]) -> Self {
        MassMatrixBuffers {
            x_up: &mut data.x_up,
            x_world: &mut data.x_world,
            world_composites: &mut data.i_c,
            subspaces: &mut data.s_world,
            body_composites: &mut data.i_c_body,
            forces: data.crba_forces.rows(),
            mass_matrix,
        }
    }
}

/// M into `out.mass_matrix` (column-major, nv × nv), in `f64` or lanes: in body coordinates
/// when the bodies are in depth-first order, else in world coordinates.
#[inline(always)]
pub(crate) fn mass_matrix_of<S: Real, F: SubtreeForces<S>>(
    model: &Model,
    q: &[S],
    out: MassMatrixBuffers<S, F>,
) {
    match model.subtree_dof_end() {
        Some(subtree_dof_end) => {
            let buffers = BodyFrameBuffers {
                x_up: out.x_up,
                composites: out.body_composites,
                forces: out.forces,
                mass_matrix: out.mass_matrix,
            };
            body_frame_mass_matrix(model, subtree_dof_end, q, buffers);
        }
        None => {
            let buffers = CompositeBuffers {
                x_up: out.x_up,
                x_world: out.x_world,
                composites: out.world_composites,
                subspaces: out.subspaces,
            };
            world_inertias_of(model, q, buffers);
            add_composites(model, out.world_composites);
            mass_matrix_of_composites(model, out.world_composites, out.subspaces, out.mass_matrix);
        }
    }
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

/// What the body-coordinate CRBA writes: one state's, or several states' in lanes.
pub(crate) struct BodyFrameBuffers<'b, S, F> {
    pub x_up: &'b mut [Transform<S>],
    pub composites: &'b mut [Inertia<S>],
    pub forces: F,
    pub mass_matrix: &'b mut [S],
}

/// M by Table 6.2 in body coordinates, in `f64` or lanes, for bodies in depth-first order
/// (`subtree_dof_end`: each subtree's coordinates are `idx_v[i]..subtree_dof_end[i]`). Leaves to
/// root, body i's composite is complete when it is reached; then
/// `F_k = I^c_i S_k` for its own coordinates k, `H_dk = S_kᵀ F_d` for every coordinate d of its
/// subtree (whose forces are in i's coordinates by now), and the subtree's inertia and forces
/// are carried to the parent: `I^c_λ(i) += X_{i←λ(i)}ᵀ I^c_i X_{i←λ(i)}`, `F_d ← X_{i←λ(i)}ᵀ F_d`.
/// Each body's transform acts on all its subtree's forces at once (independent products), and a
/// joint that turns about a coordinate axis after quarter turns (`Model::turn`) makes both
/// products turned ones.
#[inline(always)]
pub(crate) fn body_frame_mass_matrix<S: Real, F: SubtreeForces<S>>(
    model: &Model,
    subtree_dof_end: &[usize],
    q: &[S],
    out: BodyFrameBuffers<S, F>,
) {
    let nv = model.nv;
    joint_transforms(model, q, out.x_up);
    for (composite, inertia) in out.composites.iter_mut().zip(&model.inertias) {
        *composite = Inertia::splat(inertia);
    }
    out.mass_matrix.fill(S::splat(0.0));
    let mut forces = out.forces;
    let mut columns = MassColumns {
        mass_matrix: out.mass_matrix,
        nv,
        armature: model.armature.as_slice(),
    };
    for i in (1..model.nbodies()).rev() {
        let subtree = model.idx_v[i]..subtree_dof_end[i];
        // F_k = I^c_i S_k;  H_dk = S_kᵀ F_d for the coordinates d ≥ k of the subtree (F_d in
        // body i's coordinates by now)
        let composite = &out.composites[i];
        model
            .subspace(i)
            .composite_columns(composite, subtree.end, &mut forces, &mut columns);
        // the subtree's inertia and forces into the parent's coordinates
        let parent = model.parent[i];
        if parent != 0 {
            let (x_up, turn) = (&out.x_up[i], model.turn(i));
            let carried = x_up.transpose_apply_inertia_turned(turn, &out.composites[i]);
            out.composites[parent] += carried;
            forces.carry(x_up, turn, subtree);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::bundled::floating_ur5_state;

    /// A single call, built for AVX2 and FMA where the processor has them, equals the baseline
    /// build of the same passes bit for bit (the claim of `one_state_mass_matrix`).
    #[test]
    fn the_dispatched_passes_equal_the_baseline_build_bit_for_bit() {
        let (model, q, _, _) = floating_ur5_state();
        let mut dispatched = Data::new(&model);
        crba(&model, &mut dispatched, &q).unwrap();
        let mut data = Data::new(&model);
        let mut mass_matrix = vec![f64::NAN; model.nv * model.nv];
        let buffers = MassMatrixBuffers::of(&mut data, &mut mass_matrix);
        mass_matrix_of(&model, &q, buffers);
        assert_eq!(dispatched.mass_matrix.as_slice(), &mass_matrix[..]);
    }
}
