//! A kernel's workspace, and the pool of them that a batch's threads take from and give back to.

use nalgebra::DMatrix;
use robodyn::algo::{
    BatchWorkspace, ConstrainedBatchWorkspace, ConstrainedDerivatives, ConstraintData,
};
use robodyn::integrate::{Constrained, StepWorkspace};
use robodyn::spatial::Force;
use robodyn::{Data, Model};
use std::sync::Mutex;

/// What a kernel works in: the algorithm workspace and a buffer for external forces.
pub(crate) struct Workspace {
    pub(crate) data: Data,
    pub(crate) forces: Vec<Force>,
    /// Two nv × nv results of a pair of Jacobians (`integrate_jacobians`, ...).
    pub(crate) jacobians: (DMatrix<f64>, DMatrix<f64>),
    /// The stages of a simulation step, made on the first `step` call.
    pub(crate) step: Option<Box<StepWorkspace>>,
    /// The stages of a constrained step, made for the last call's constraints.
    pub(crate) constrained_step: Option<Box<StepWorkspace<Constrained>>>,
    /// The lane buffers of the batch kernels, made on the first batch that uses them.
    pub(crate) lanes: Option<Box<BatchWorkspace>>,
    /// The constrained algorithms' workspace, made for the last constraint set's size.
    pub(crate) constrained: Option<Box<ConstraintData>>,
    /// The constrained derivatives' workspace, made for the last constraint set's size.
    pub(crate) constrained_derivatives: Option<Box<ConstrainedDerivatives>>,
    /// The lane buffers of constrained batches, made for the last constraint set's size.
    pub(crate) constrained_lanes: Option<Box<ConstrainedBatchWorkspace>>,
}

impl Workspace {
    pub(crate) fn new(model: &Model) -> Self {
        Workspace {
            data: Data::new(model),
            forces: vec![Force::ZERO; model.nbodies() - 1],
            jacobians: (
                DMatrix::zeros(model.nv, model.nv),
                DMatrix::zeros(model.nv, model.nv),
            ),
            step: None,
            constrained_step: None,
            lanes: None,
            constrained: None,
            constrained_derivatives: None,
            constrained_lanes: None,
        }
    }

    /// The lane buffers of the batch kernels, made on first use.
    pub(super) fn lanes(&mut self, model: &Model) -> &mut BatchWorkspace {
        self.lanes
            .get_or_insert_with(|| Box::new(BatchWorkspace::new(model)))
    }
}

/// Workspaces for the threads of a batch, kept between calls (making one allocates).
#[derive(Default)]
pub(crate) struct WorkspacePool(Mutex<Vec<Workspace>>);

impl WorkspacePool {
    /// A workspace from the pool, or a new one when the pool is empty (or its lock poisoned).
    pub(super) fn take(&self, model: &Model) -> Workspace {
        let taken = self.0.lock().ok().and_then(|mut pool| pool.pop());
        taken.unwrap_or_else(|| Workspace::new(model))
    }

    /// Gives a workspace back for the next batch.
    pub(super) fn give_back(&self, workspace: Workspace) {
        if let Ok(mut pool) = self.0.lock() {
            pool.push(workspace);
        }
    }
}

/// Copies a flat array of `[linear; angular]` rows, one per body, into `forces`.
pub(crate) fn fill_forces(forces: &mut [Force], flat: &[f64]) {
    for (force, row) in forces.iter_mut().zip(flat.chunks_exact(6)) {
        *force = Force::from_array(&[row[0], row[1], row[2], row[3], row[4], row[5]]);
    }
}
