//! The algorithms that run in batches, as one list ([`BatchAlgorithm`]) with one entry point
//! ([`batch`]), and a function per algorithm for callers that know which they run.

use super::{run_batch, BatchResult, BatchWorkspace, States};
use crate::algo::jacobian::Reference;
use crate::algo::kinematics::check_frame;
use crate::error::Error;
use crate::model::Model;

/// The algorithms that run in batches, in lanes where the processor has them: the list a caller
/// (the Python binding) picks from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BatchAlgorithm {
    /// τ = ID(q, v, a) (Newton–Euler; bias forces without a, gravity without v and a).
    NewtonEuler,
    /// q̈ = FD(q, v, τ) (the articulated-body algorithm).
    ArticulatedBody,
    /// M(q) (the composite-rigid-body algorithm).
    CompositeRigidBody,
    /// ∂τ/∂q, ∂τ/∂q̇ and M of τ = ID(q, v, a), stacked.
    RneaDerivatives,
    /// ∂q̈/∂q, ∂q̈/∂q̇ and M⁻¹ of q̈ = FD(q, v, τ), stacked.
    AbaDerivatives,
    /// The pose of frame `frame` in the world, a 4 × 4 homogeneous matrix (forward kinematics
    /// along the frame's support).
    FramePose {
        /// The frame's index.
        frame: usize,
    },
    /// The Jacobian of frame `frame` (6 × nv, row-major) in `reference`'s coordinates.
    Jacobian {
        /// The frame's index.
        frame: usize,
        /// The coordinates of the Jacobian.
        reference: Reference,
    },
}

impl BatchAlgorithm {
    /// The values of one state's result.
    pub fn output_size(self, model: &Model) -> usize {
        let nv = model.nv;
        match self {
            BatchAlgorithm::CompositeRigidBody => nv * nv,
            BatchAlgorithm::RneaDerivatives | BatchAlgorithm::AbaDerivatives => 3 * nv * nv,
            BatchAlgorithm::FramePose { .. } => 16,
            BatchAlgorithm::Jacobian { .. } => 6 * nv,
            BatchAlgorithm::NewtonEuler | BatchAlgorithm::ArticulatedBody => nv,
        }
    }

    /// The inputs it reads, in order (Newton–Euler takes zero for a missing a, or v and a).
    pub fn inputs(self) -> &'static [&'static str] {
        match self {
            BatchAlgorithm::NewtonEuler | BatchAlgorithm::RneaDerivatives => &["q", "v", "a"],
            BatchAlgorithm::ArticulatedBody | BatchAlgorithm::AbaDerivatives => &["q", "v", "tau"],
            BatchAlgorithm::CompositeRigidBody
            | BatchAlgorithm::FramePose { .. }
            | BatchAlgorithm::Jacobian { .. } => &["q"],
        }
    }

    /// The batch of `inputs`, given in the order of [`inputs`](Self::inputs) (those left out
    /// are `None`).
    pub fn states<'s>(self, inputs: &[&'s [f64]]) -> States<'s> {
        let mut states = States {
            q: inputs.first().copied().unwrap_or_default(),
            ..States::default()
        };
        for (name, values) in self.inputs().iter().zip(inputs).skip(1) {
            match *name {
                "v" => states.v = Some(values),
                "a" => states.a = Some(values),
                _ => states.tau = Some(values),
            }
        }
        states
    }
}

/// Runs `algorithm` over a batch into `out` (n × its output size): every state is checked first
/// (the error names the first bad one, or an input the algorithm needs and lacks); then the
/// states run in groups of the workspace's width, and the rest one at a time.
pub fn batch(
    algorithm: BatchAlgorithm,
    model: &Model,
    workspace: &mut BatchWorkspace,
    states: States,
    out: &mut [f64],
) -> BatchResult {
    match algorithm {
        BatchAlgorithm::NewtonEuler | BatchAlgorithm::CompositeRigidBody => Ok(()),
        BatchAlgorithm::ArticulatedBody => {
            require(&[("v", states.v), ("tau", states.tau)], "forward dynamics")
        }
        BatchAlgorithm::RneaDerivatives => require(
            &[("v", states.v), ("a", states.a)],
            "the derivatives of inverse dynamics",
        ),
        BatchAlgorithm::AbaDerivatives => require(
            &[("v", states.v), ("tau", states.tau)],
            "the derivatives of forward dynamics",
        ),
        BatchAlgorithm::FramePose { frame } | BatchAlgorithm::Jacobian { frame, .. } => {
            check_frame(model, frame).map_err(|e| (0, e))
        }
    }?;
    run_batch(algorithm, model, workspace, states, out)
}

/// Newton–Euler over a batch, `tau` (n × nv) = ID(q, v, a) of every state: inverse dynamics,
/// bias forces (`a = None`) or gravity (`v = a = None`); checked and grouped as [`batch`].
pub fn newton_euler_batch(
    model: &Model,
    workspace: &mut BatchWorkspace,
    states: States,
    tau: &mut [f64],
) -> BatchResult {
    batch(BatchAlgorithm::NewtonEuler, model, workspace, states, tau)
}

/// The articulated-body algorithm over a batch, `qdd` (n × nv) = FD(q, v, τ) of every state
/// (`states.v` and `states.tau` are required), checked and grouped as [`batch`].
pub fn aba_batch(
    model: &Model,
    workspace: &mut BatchWorkspace,
    states: States,
    qdd: &mut [f64],
) -> BatchResult {
    batch(
        BatchAlgorithm::ArticulatedBody,
        model,
        workspace,
        states,
        qdd,
    )
}

/// CRBA over a batch, `mass_matrix` (n × nv × nv) = M(q) of every configuration of `q`,
/// checked and grouped as [`batch`].
pub fn crba_batch(
    model: &Model,
    workspace: &mut BatchWorkspace,
    q: &[f64],
    mass_matrix: &mut [f64],
) -> BatchResult {
    let algorithm = BatchAlgorithm::CompositeRigidBody;
    batch(
        algorithm,
        model,
        workspace,
        algorithm.states(&[q]),
        mass_matrix,
    )
}

/// The RNEA derivatives over a batch: per state, ∂τ/∂q, ∂τ/∂q̇ and M (each nv × nv row-major,
/// stacked: `out` is n × 3 × nv × nv) at (q, v, a) (`states.v` and `states.a` are required),
/// checked and grouped as [`batch`].
pub fn rnea_derivatives_batch(
    model: &Model,
    workspace: &mut BatchWorkspace,
    states: States,
    out: &mut [f64],
) -> BatchResult {
    batch(
        BatchAlgorithm::RneaDerivatives,
        model,
        workspace,
        states,
        out,
    )
}

/// The ABA derivatives over a batch: per state, ∂q̈/∂q, ∂q̈/∂q̇ and M⁻¹ (each nv × nv row-major,
/// stacked: `out` is n × 3 × nv × nv) at (q, v, τ) (`states.v` and `states.tau` are required),
/// checked and grouped as [`batch`].
pub fn aba_derivatives_batch(
    model: &Model,
    workspace: &mut BatchWorkspace,
    states: States,
    out: &mut [f64],
) -> BatchResult {
    batch(
        BatchAlgorithm::AbaDerivatives,
        model,
        workspace,
        states,
        out,
    )
}

/// The pose of frame `frame` for every configuration of `q` (n × nq): `poses` (n × 4 × 4, each
/// the homogeneous matrix `[R p; 0 1]` row by row), checked and grouped as [`batch`].
pub fn frame_pose_batch(
    model: &Model,
    workspace: &mut BatchWorkspace,
    q: &[f64],
    frame: usize,
    poses: &mut [f64],
) -> BatchResult {
    let algorithm = BatchAlgorithm::FramePose { frame };
    batch(algorithm, model, workspace, algorithm.states(&[q]), poses)
}

/// The Jacobian of frame `frame` in `reference`'s coordinates for every configuration of `q`
/// (n × nq): `jacobians` (n × 6 × nv, each row-major), checked and grouped as [`batch`].
pub fn jacobian_batch(
    model: &Model,
    workspace: &mut BatchWorkspace,
    q: &[f64],
    (frame, reference): (usize, Reference),
    jacobians: &mut [f64],
) -> BatchResult {
    let algorithm = BatchAlgorithm::Jacobian { frame, reference };
    batch(
        algorithm,
        model,
        workspace,
        algorithm.states(&[q]),
        jacobians,
    )
}

/// An error if one of `inputs` is missing.
fn require(inputs: &[(&str, Option<&[f64]>)], what: &str) -> BatchResult {
    match inputs.iter().find(|(_, values)| values.is_none()) {
        Some((name, _)) => Err((
            0,
            Error::InvalidValue {
                argument: (*name).into(),
                message: format!("{what} needs it"),
            },
        )),
        None => Ok(()),
    }
}
