//! What a model derives from its own fields for speed (the joints' turns and subspace components,
//! the runs of coordinates, the subtree ends): never stored, found again whenever a source
//! changes.

use super::Model;
use crate::spatial::turn::snapped_signed_permutation;
use crate::spatial::Transform;

impl Model {
    /// The fields derived from the others, not stored in snapshots: found when a model is
    /// built or read back.
    pub(crate) fn derive(&mut self) {
        self.dof_run_start = dof_run_starts(&self.dof_parent);
        self.subtree_dof_end = subtree_dof_ends(&self.parent, &self.idx_v, self.nv);
        self.turns = (self.joints.iter().zip(&self.x_tree))
            .map(|(joint, x)| joint.turn(x))
            .collect();
        self.subspace_components = (self.joints.iter())
            .flat_map(|joint| (0..joint.nv()).map(|k| joint.subspace_component(k)))
            .collect();
    }
}

/// A tree transform as the model stores it: a rotation within round-off of quarter turns stored
/// exactly, so that the joint's transforms leave out their zeros.
pub(crate) fn tree_transform(x_tree: Transform) -> Transform {
    let rotation = snapped_signed_permutation(&x_tree.rotation).unwrap_or(x_tree.rotation);
    Transform { rotation, ..x_tree }
}

/// [`Model::dof_run_start`] from the coordinates' parents.
fn dof_run_starts(dof_parent: &[Option<usize>]) -> Vec<usize> {
    let mut starts = Vec::with_capacity(dof_parent.len());
    for (k, parent) in dof_parent.iter().enumerate() {
        starts.push(run_start(&starts, *parent, k));
    }
    starts
}

/// [`Model::subtree_dof_end`] from the bodies' parents and first coordinates (`nv` in all).
fn subtree_dof_ends(parent: &[usize], idx_v: &[usize], nv: usize) -> Option<Vec<usize>> {
    // depth-first order: each body's parent is on the path from the world to the body before it
    let mut path = vec![0];
    for (body, &p) in parent.iter().enumerate().skip(1) {
        while *path.last()? != p {
            path.pop();
        }
        path.push(body);
    }
    // then a subtree's bodies are the next `size` ones, its coordinates end where the body
    // after them begins
    let mut size = vec![1; parent.len()];
    for body in (1..parent.len()).rev() {
        size[parent[body]] += size[body];
    }
    let first_coordinate = |body: usize| idx_v.get(body).copied().unwrap_or(nv);
    Some(
        (0..parent.len())
            .map(|body| first_coordinate(body + size[body]))
            .collect(),
    )
}

/// The start of coordinate k's run, given the runs of the coordinates before it.
pub(super) fn run_start(starts: &[usize], parent: Option<usize>, k: usize) -> usize {
    match parent {
        Some(p) if p + 1 == k => starts[p],
        _ => k,
    }
}

/// Iterator of [`Model::ancestor_runs`].
pub struct AncestorRuns<'m> {
    pub(super) model: &'m Model,
    pub(super) top: Option<usize>,
}

impl Iterator for AncestorRuns<'_> {
    type Item = std::ops::Range<usize>;

    #[inline(always)]
    fn next(&mut self) -> Option<Self::Item> {
        let end = self.top?;
        let start = self.model.dof_run_start[end];
        self.top = self.model.dof_parent[start];
        Some(start..end + 1)
    }
}
