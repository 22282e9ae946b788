//! Composite-rigid-body algorithm: the joint-space inertia matrix M(q).
//!
//! Reference: Featherstone, *Rigid Body Dynamics Algorithms* (2008), §6.2 and Table 6.2:
//! `H_ij = S_iᵀ I^c_i S_j` for j an ancestor of i (or i itself), with `I^c_i` the composite inertia
//! of the subtree rooted at body i. Two forms, the same M:
//! - Table 6.2 in body coordinates (bodies in depth-first order, as every loader gives, so that a
//!   subtree's coordinates are consecutive): composites and forces `F = I^c_i S_i` carried to the
//!   parent joint by joint. A joint that turns about a coordinate axis (after quarter turns)
//!   makes each carry a turned product (`spatial::turn`), and a coordinate axis makes `S_jᵀ F`
//!   one component of F. One state keeps its forces by component (a private row layout) and carries
//!   four per product.
//! - Otherwise every quantity once in world coordinates, where composites add without transforms
//!   and each `H_ij` is a 6-vector dot product.
//!
//! The UR5 dynamics notes obtain the same M from n RNEA calls; the tests check it.
//! Input: q (nq). Writes `data.x_up`; `data.i_c_body`, `data.f_subspace` (body coordinates) or
//! `data.x_world`, `data.s_world`, `data.i_c` (world coordinates); `data.mass_matrix` (full,
//! symmetric, armature on the diagonal).
//! Cost: O(n) transforms plus a force carried (body coordinates) or a dot product (world
//! coordinates) per pair (joint, ancestor joint).

use crate::algo::kinematics::{body_placements, joint_transforms};
use crate::dispatch::multiversion;
use crate::error::{check_length, Result};
use crate::model::Model;
use crate::spatial::{signed, Force, Inertia, Motion, Real, Transform, Turn};
use crate::Data;
use nalgebra::DMatrix;
use std::ops::Range;

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
    one_state_mass_matrix(model, q, MassMatrixBuffers::of(data, model.nv, out));
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
    /// One state's buffers, borrowed from `data` (of a model with `nv` coordinates), M written
    /// into `mass_matrix`.
    fn of(data: &'b mut Data, nv: usize, mass_matrix: &'b mut [f64]) -> Self {
        MassMatrixBuffers {
            x_up: &mut data.x_up,
            x_world: &mut data.x_world,
            world_composites: &mut data.i_c,
            subspaces: &mut data.s_world,
            body_composites: &mut data.i_c_body,
            forces: ForceRows::new(&mut data.f_subspace, nv),
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

/// M's storage as the body-coordinate CRBA fills it: column-major nv × nv, with the joints'
/// armature on the diagonal.
pub(crate) struct MassColumns<'b, S> {
    mass_matrix: &'b mut [S],
    nv: usize,
    armature: &'b [f64],
}

impl<S: Real> MassColumns<'_, S> {
    /// `H[d, col] = H[col, d] = h_d` for the values `h_col, h_col+1, …` (column col from its
    /// diagonal down, and row col from its diagonal right), the armature added to the diagonal.
    #[inline(always)]
    pub(crate) fn store(&mut self, col: usize, values: impl Iterator<Item = S>) {
        // H[col + j, col] down the column, H[col, col + j] a column apart along the row
        let diagonal = col * self.nv + col;
        for (j, h) in values.enumerate() {
            self.mass_matrix[diagonal + j] = h;
            self.mass_matrix[diagonal + j * self.nv] = h;
        }
        self.mass_matrix[diagonal] += S::splat(self.armature[col]);
    }
}

/// Where the body-coordinate CRBA keeps the forces `F_d = I^c S_d` of the coordinates d: one
/// state's by component ([`ForceRows`]), so that a joint carries four of its subtree's forces
/// per product; lanes' as forces, one after the other (each lane is a state already).
pub(crate) trait SubtreeForces<S: Real> {
    /// `F_d = force`.
    fn set(&mut self, d: usize, force: &Force<S>);

    /// `S_kᵀ F_d` for `S_k = ±e_c` (c in [`Force::plucker`]'s order; `negative`: −): ±
    /// component c of `F_d`, for the coordinates d of `rows` in turn.
    fn unit_projections(
        &self,
        c: usize,
        negative: bool,
        rows: Range<usize>,
    ) -> impl Iterator<Item = S>;

    /// `F_d`.
    fn force(&self, d: usize) -> Force<S>;

    /// `F_d ← Xᵀ F_d` for the coordinates d of `subtree`, X of the pattern `turn` where it is
    /// `Some` ([`Transform::transpose_apply_force_turned`]).
    fn carry(&mut self, x: &Transform<S>, turn: Option<Turn>, subtree: Range<usize>);
}

impl<S: Real> SubtreeForces<S> for &mut [Force<S>] {
    #[inline(always)]
    fn set(&mut self, d: usize, force: &Force<S>) {
        self[d] = *force;
    }

    #[inline(always)]
    fn unit_projections(
        &self,
        c: usize,
        negative: bool,
        rows: Range<usize>,
    ) -> impl Iterator<Item = S> {
        self[rows]
            .iter()
            .map(move |force| signed(force.component(c), negative))
    }

    #[inline(always)]
    fn force(&self, d: usize) -> Force<S> {
        self[d]
    }

    #[inline(always)]
    fn carry(&mut self, x: &Transform<S>, turn: Option<Turn>, subtree: Range<usize>) {
        x.transpose_apply_forces_turned(turn, &mut self[subtree]);
    }
}

/// One state's forces by component: `rows[c (nv + 3) + 3 + d]` is component c of `F_d`. Each
/// row starts with three unused values, so that a subtree's forces are carried in whole groups
/// of four ending at its last one; the places before its first hold forces of bodies not
/// reached yet (written when they are) or the unused values.
pub(crate) struct ForceRows<'r> {
    rows: &'r mut [f64],
    nv: usize,
}

impl<'r> ForceRows<'r> {
    /// The values unused at the start of each row.
    const PADDING: usize = 3;

    /// The values the forces of `nv` coordinates take.
    pub(crate) fn size(nv: usize) -> usize {
        6 * (nv + Self::PADDING)
    }

    pub(crate) fn new(rows: &'r mut [f64], nv: usize) -> Self {
        assert_eq!(
            rows.len(),
            Self::size(nv),
            "rows of forces for {nv} coordinates"
        );
        ForceRows { rows, nv }
    }

    #[inline(always)]
    fn at(&self, c: usize, d: usize) -> usize {
        c * (self.nv + Self::PADDING) + Self::PADDING + d
    }
}

impl SubtreeForces<f64> for ForceRows<'_> {
    #[inline(always)]
    fn set(&mut self, d: usize, force: &Force) {
        // the six components, a row apart: one bounds check for all
        let stride = self.nv + Self::PADDING;
        let first = self.at(0, d);
        let components = &mut self.rows[first..=first + 5 * stride];
        for (c, value) in force.plucker().into_iter().enumerate() {
            components[c * stride] = value;
        }
    }

    #[inline(always)]
    fn unit_projections(
        &self,
        c: usize,
        negative: bool,
        rows: Range<usize>,
    ) -> impl Iterator<Item = f64> {
        // component c of consecutive forces is consecutive
        let components = &self.rows[self.at(c, rows.start)..self.at(c, rows.end)];
        components
            .iter()
            .map(move |&component| signed(component, negative))
    }

    #[inline(always)]
    fn force(&self, d: usize) -> Force {
        let c = |c: usize| self.rows[self.at(c, d)];
        Force::from_plucker([c(0), c(1), c(2), c(3), c(4), c(5)])
    }

    #[inline(always)]
    fn carry(&mut self, x: &Transform, turn: Option<Turn>, subtree: Range<usize>) {
        let (stride, end) = (self.nv + Self::PADDING, Self::PADDING + subtree.end);
        let groups = subtree.len().div_ceil(4);
        x.transpose_apply_force_rows_turned(turn, self.rows, stride, end, groups);
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
        let buffers = MassMatrixBuffers::of(&mut data, model.nv, &mut mass_matrix);
        mass_matrix_of(&model, &q, buffers);
        assert_eq!(dispatched.mass_matrix.as_slice(), &mass_matrix[..]);
    }
}
