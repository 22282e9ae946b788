//! How a batch is scheduled: runs of consecutive samples spread over all cores, each run in a
//! workspace from the pool, by one sample at a time or by lanes in pieces that fit in cache, and
//! every result checked for overflow.

use super::workspace::Workspace;
use super::PyModel;
use crate::errors::batch_element_error;
use pyo3::prelude::*;
use rayon::prelude::*;
use robodyn::algo::{self, BatchAlgorithm, ConstrainedBatchWorkspace, ConstrainedOptions, States};
use robodyn::constraint::ConstraintSet;
use robodyn::{Error, Model};

/// One computation on one sample: inputs (flattened, in argument order) to a flattened output.
pub(crate) type Kernel<'k> =
    dyn Fn(&Model, &mut Workspace, &[&[f64]], &mut [f64]) -> robodyn::Result<()> + Sync + 'k;

/// A batch computation that runs in lanes (`robodyn::algo::lanes`) on runs of samples.
#[derive(Clone, Copy)]
pub(crate) enum LaneRun<'a> {
    /// One of the free-space algorithms, its inputs as it names them.
    Algorithm(BatchAlgorithm),
    /// Constrained forward dynamics on (q, v, τ): rows of q̈ then the forces.
    ConstrainedForward(&'a ConstraintSet, &'a ConstrainedOptions),
    /// Impulses on (q, v) with (restitution, damping): rows of q̇ after then the impulses.
    Impulse(&'a ConstraintSet, (f64, f64)),
}

impl LaneRun<'_> {
    /// Runs on the `states` given as `inputs` (in argument order) into `out`, in `workspace`'s
    /// lane buffers.
    fn run(
        self,
        model: &Model,
        workspace: &mut Workspace,
        inputs: &[&[f64]],
        out: &mut [f64],
    ) -> algo::BatchResult {
        match self {
            LaneRun::Algorithm(algorithm) => {
                let width = workspace.lanes(model);
                algo::batch(algorithm, model, width, algorithm.states(inputs), out)
            }
            LaneRun::ConstrainedForward(set, options) => {
                let states = States {
                    q: inputs[0],
                    v: Some(inputs[1]),
                    a: None,
                    tau: Some(inputs[2]),
                };
                let lanes = constrained_lanes(workspace, model, set);
                algo::constrained_forward_dynamics_batch(model, lanes, set, states, options, out)
            }
            LaneRun::Impulse(set, impact) => {
                let states = States {
                    q: inputs[0],
                    v: Some(inputs[1]),
                    a: None,
                    tau: None,
                };
                let lanes = constrained_lanes(workspace, model, set);
                algo::impulse_dynamics_batch(model, lanes, set, states, impact, out)
            }
        }
    }
}

/// The lane buffers of constrained batches in `workspace`, made for `set`'s size.
fn constrained_lanes<'w>(
    workspace: &'w mut Workspace,
    model: &Model,
    set: &ConstraintSet,
) -> &'w mut ConstrainedBatchWorkspace {
    crate::constrained::made_for(
        &mut workspace.constrained_lanes,
        |w| w.fits(model, set),
        || ConstrainedBatchWorkspace::new(model, set),
    )
}

/// The most numeric arguments a method takes (q, v, a, f_ext).
pub(super) const MAX_ARGUMENTS: usize = 4;

/// Runs `kernel` and rejects a result that is not finite (finite inputs so large that the
/// arithmetic overflowed), so that no NaN or infinity reaches the caller.
pub(super) fn run_kernel(
    kernel: &Kernel,
    model: &Model,
    workspace: &mut Workspace,
    inputs: &[&[f64]],
    out: &mut [f64],
) -> robodyn::Result<()> {
    kernel(model, workspace, inputs, out)?;
    match first_overflow(out) {
        Some(index) => Err(Error::Overflow {
            index,
            value: out[index],
        }),
        None => Ok(()),
    }
}

/// The first entry of `out` that is not finite, if any: one vectorised pass, then the search.
pub(super) fn first_overflow(out: &[f64]) -> Option<usize> {
    if robodyn::error::all_finite(out) {
        return None;
    }
    out.iter().position(|x| !x.is_finite())
}

/// How many states a batch in lanes evaluates before checking their results for overflow: as
/// many as fill about a core's L2 cache (so the check reads them from cache, not from memory),
/// in whole groups of the widest lanes.
pub(super) fn states_per_piece(output_size: usize) -> usize {
    const CACHED_BYTES: usize = 256 * 1024;
    const WIDEST_LANES: usize = 8;
    (CACHED_BYTES / (8 * output_size))
        .next_multiple_of(WIDEST_LANES)
        .max(WIDEST_LANES)
}

/// The inputs of a batch: each argument's values, flattened, and its size per sample.
pub(super) struct BatchInputs<'v> {
    pub(super) values: &'v [&'v [f64]],
    pub(super) sizes: &'v [usize],
    pub(super) output_size: usize,
}

impl PyModel {
    /// Runs `kernel` on every sample of a batch into `out` (or `lanes` on runs of samples), with
    /// the GIL released, on all cores: a few runs of consecutive samples per thread (for
    /// balance), each in a workspace taken from the pool and given back.
    pub(super) fn run_batch(
        &self,
        py: Python,
        batch: &BatchInputs,
        out: &mut [f64],
        kernel: &Kernel,
        lanes: Option<LaneRun>,
    ) -> PyResult<()> {
        let (model, pool) = (&self.model, &self.batch_workspaces);
        let output_size = batch.output_size.max(1);
        let n = out.len() / output_size;
        let run = n.div_ceil(4 * rayon::current_num_threads()).max(1);
        let result = py.detach(|| {
            out.par_chunks_mut(run * output_size)
                .enumerate()
                .try_for_each(|(r, outputs)| {
                    let mut workspace = pool.take(model);
                    let first = r * run;
                    let mut inputs: [&[f64]; MAX_ARGUMENTS] = [&[]; MAX_ARGUMENTS];
                    let mut select = |first: usize, count: usize| {
                        for ((input, value), size) in
                            inputs.iter_mut().zip(batch.values).zip(batch.sizes)
                        {
                            *input = &value[first * size..(first + count) * size];
                        }
                        inputs
                    };
                    let arguments = batch.values.len();
                    match lanes {
                        Some(lanes) => {
                            // in pieces whose results are still in cache when checked
                            let piece = states_per_piece(output_size);
                            for (p, outputs) in outputs.chunks_mut(piece * output_size).enumerate()
                            {
                                let first = first + p * piece;
                                let count = outputs.len() / output_size;
                                let inputs = select(first, count);
                                lanes
                                    .run(model, &mut workspace, &inputs[..arguments], outputs)
                                    .map_err(|(k, e)| (first + k, e))?;
                                if let Some(index) = first_overflow(outputs) {
                                    let value = outputs[index];
                                    let (k, index) = (index / output_size, index % output_size);
                                    return Err((first + k, Error::Overflow { index, value }));
                                }
                            }
                        }
                        None => {
                            for (k, out) in (first..).zip(outputs.chunks_mut(output_size)) {
                                let inputs = select(k, 1);
                                run_kernel(
                                    kernel,
                                    model,
                                    &mut workspace,
                                    &inputs[..arguments],
                                    out,
                                )
                                .map_err(|e| (k, e))?;
                            }
                        }
                    }
                    pool.give_back(workspace);
                    Ok(())
                })
        });
        result.map_err(|(k, error)| batch_element_error(k, error))
    }
}
