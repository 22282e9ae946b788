//! The batch kernels in lanes that a method can run on a thread's run of samples.

use super::workspace::Workspace;
use robodyn::algo::{self, BatchResult, States};
use robodyn::Model;

/// The batch kernels in lanes (`robodyn::algo::lanes`) a method can run on each thread's run of
/// consecutive samples instead of one sample at a time.
#[derive(Debug, Clone, Copy)]
pub(crate) enum LaneKernel {
    /// Inputs q[, v[, a]] (zero where absent): inverse dynamics, bias forces, gravity.
    NewtonEuler,
    /// Inputs q, v, τ: forward dynamics.
    ArticulatedBody,
    /// Input q: the mass matrix.
    CompositeRigidBody,
    /// Inputs q, v, a: ∂τ/∂q, ∂τ/∂v and M stacked.
    RneaDerivatives,
    /// Inputs q, v, τ: ∂q̈/∂q, ∂q̈/∂v and M⁻¹ stacked.
    AbaDerivatives,
    /// Input q: the pose of a frame (its index), 4 × 4.
    FramePose(usize),
    /// Input q: the Jacobian of a frame (its index) in a reference's coordinates, 6 × nv.
    Jacobian(usize, algo::Reference),
}

impl LaneKernel {
    /// Runs on a run of samples: `inputs` hold the run's rows, `out` its results; an error names
    /// the sample by its place in the run.
    pub(super) fn run(
        self,
        model: &Model,
        workspace: &mut Workspace,
        inputs: &[&[f64]],
        out: &mut [f64],
    ) -> BatchResult {
        let lanes = workspace.lanes(model);
        let (q, input) = (inputs[0], |k: usize| inputs.get(k).copied());
        let dynamics = States {
            q,
            v: input(1),
            a: input(2),
            tau: None,
        };
        match self {
            LaneKernel::NewtonEuler => algo::newton_euler_batch(model, lanes, dynamics, out),
            LaneKernel::RneaDerivatives => {
                algo::rnea_derivatives_batch(model, lanes, dynamics, out)
            }
            LaneKernel::CompositeRigidBody => algo::crba_batch(model, lanes, q, out),
            LaneKernel::FramePose(frame) => algo::frame_pose_batch(model, lanes, q, frame, out),
            LaneKernel::Jacobian(frame, reference) => {
                algo::jacobian_batch(model, lanes, q, (frame, reference), out)
            }
            LaneKernel::ArticulatedBody | LaneKernel::AbaDerivatives => {
                let forward = States {
                    a: None,
                    tau: input(2),
                    ..dynamics
                };
                match self {
                    LaneKernel::ArticulatedBody => algo::aba_batch(model, lanes, forward, out),
                    _ => algo::aba_derivatives_batch(model, lanes, forward, out),
                }
            }
        }
    }
}
