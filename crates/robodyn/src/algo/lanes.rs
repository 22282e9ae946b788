//! Batches in lanes: a batch runs one model on many states, so the same instructions can serve 4
//! (AVX2) or 8 (AVX-512) states at once. The kernels are the one-state algorithms themselves,
//! generic over [`Real`]: run on a lane type (`simba`'s `AutoSimd<[f64; N]>`, plain arrays the
//! compiler turns into vector instructions), every lane performs exactly the operations of a
//! one-state call, so each lane's result equals that call's bit for bit.
//!
//! The batch is stored state after state (row-major, as NumPy gives it); each group of N states
//! is gathered into lanes (structure of arrays: coordinate j of the N states in one lane value),
//! run, and scattered back. States left over after the last full group run one at a time. The
//! width is chosen at run time by the CPU found ([`LaneWidth::detect`]); the wide kernels are
//! compiled once per instruction set (`#[target_feature]`), so one binary serves every x86-64 CPU.

mod algorithms;
mod constrained;
mod groups;
mod scatter;

pub use algorithms::{
    aba_batch, aba_derivatives_batch, batch, crba_batch, frame_pose_batch, jacobian_batch,
    newton_euler_batch, rnea_derivatives_batch, BatchAlgorithm,
};
pub use constrained::{
    constrained_forward_dynamics_batch, impulse_dynamics_batch, ConstrainedBatchWorkspace,
};

use crate::algo::aba::aba;
use crate::algo::crba::crba_into;
use crate::algo::derivatives::{aba_derivatives, rnea_derivatives, DerivativesInto};
use crate::algo::jacobian::jacobian_columns;
use crate::algo::kinematics::frame_pose;
use crate::algo::rnea::newton_euler;
use crate::error::{check_length, check_vector, Error, Result};
use crate::model::Model;
use crate::spatial::{Real, Vec3};
use crate::Data;
use groups::{groups_eight, groups_four, Lanes};
use nalgebra::Vector3;
use simba::simd::{AutoF64x4, AutoF64x8};

/// How many states a batch kernel runs at once.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LaneWidth {
    /// One state at a time (any CPU).
    One,
    /// Four states per instruction (x86-64 with AVX2 and FMA).
    Four,
    /// Eight states per instruction (x86-64 with AVX-512F).
    Eight,
}

impl LaneWidth {
    /// Every width, narrowest first.
    pub const ALL: [LaneWidth; 3] = [LaneWidth::One, LaneWidth::Four, LaneWidth::Eight];

    /// The number of states per group.
    pub fn states(self) -> usize {
        match self {
            LaneWidth::One => 1,
            LaneWidth::Four => 4,
            LaneWidth::Eight => 8,
        }
    }

    /// Whether this CPU has the instructions the width is compiled for.
    pub fn available(self) -> bool {
        match self {
            LaneWidth::One => true,
            #[cfg(target_arch = "x86_64")]
            LaneWidth::Four => is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma"),
            #[cfg(target_arch = "x86_64")]
            LaneWidth::Eight => is_x86_feature_detected!("avx512f"),
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }

    /// The widest width this CPU runs.
    pub fn detect() -> LaneWidth {
        *LaneWidth::ALL
            .iter()
            .rev()
            .find(|width| width.available())
            .unwrap_or(&LaneWidth::One)
    }
}

/// What a batch kernel works in: a [`Data`] for single states and the lane buffers of its width.
/// Made once per model (and per thread); running a batch then allocates nothing.
#[derive(Debug, Clone)]
pub struct BatchWorkspace {
    width: LaneWidth,
    /// How many states of the last batch ran in lanes.
    in_lanes: usize,
    data: Data,
    four: Lanes<AutoF64x4>,
    eight: Lanes<AutoF64x8>,
}

impl BatchWorkspace {
    /// A workspace for `model` at the widest width this CPU runs.
    pub fn new(model: &Model) -> Self {
        BatchWorkspace {
            width: LaneWidth::detect(),
            in_lanes: 0,
            data: Data::new(model),
            four: Lanes::new(model),
            eight: Lanes::new(model),
        }
    }

    /// A workspace forced to `width` (to compare the widths); an error if this CPU lacks it.
    pub fn with_width(model: &Model, width: LaneWidth) -> Result<Self> {
        if !width.available() {
            return Err(Error::InvalidValue {
                argument: "width".into(),
                message: format!("this CPU lacks the instructions of lane width {width:?}"),
            });
        }
        Ok(BatchWorkspace {
            width,
            ..BatchWorkspace::new(model)
        })
    }

    /// The width this workspace runs at.
    pub fn width(&self) -> LaneWidth {
        self.width
    }

    /// How many states of the last batch ran in lanes (the others ran one at a time).
    pub fn states_in_lanes(&self) -> usize {
        self.in_lanes
    }
}

/// A batch of states, each row-major: `q` is n × nq; `v`, `a` and `tau` n × nv, or `None` where
/// the algorithm takes zero (Newton–Euler's v and a) or does not take them.
#[derive(Debug, Clone, Copy, Default)]
pub struct States<'s> {
    /// Configurations, n × nq.
    pub q: &'s [f64],
    /// Velocities, n × nv.
    pub v: Option<&'s [f64]>,
    /// Accelerations, n × nv.
    pub a: Option<&'s [f64]>,
    /// Joint torques or forces, n × nv.
    pub tau: Option<&'s [f64]>,
}

/// A batch error: the state it came from and what was wrong with it.
pub type BatchResult = std::result::Result<(), (usize, Error)>;

/// Checks the states, runs the full groups in lanes and the rest (and any group where a lane
/// failed, to name the state) one state at a time.
fn run_batch(
    algorithm: BatchAlgorithm,
    model: &Model,
    workspace: &mut BatchWorkspace,
    states: States,
    out: &mut [f64],
) -> BatchResult {
    let (nv, size) = (model.nv, algorithm.output_size(model));
    if size == 0 {
        return Ok(());
    }
    let n = out.len() / size;
    check_states(model, &states, n)?;
    let width = workspace.width;
    let grouped = match width {
        LaneWidth::One => 0,
        width => n - n % width.states(),
    };
    let lanes_out = &mut out[..grouped * size];
    let in_lanes = match width {
        LaneWidth::One => Ok(()),
        // SAFETY (both): the width was found available on this CPU when the workspace was made
        LaneWidth::Four => unsafe {
            groups_four(algorithm, model, &mut workspace.four, states, lanes_out)
        },
        LaneWidth::Eight => unsafe {
            groups_eight(algorithm, model, &mut workspace.eight, states, lanes_out)
        },
    };
    // what is left, one state at a time
    let first = in_lanes.err().unwrap_or(grouped);
    workspace.in_lanes = first;
    for k in first..n {
        let state = state(model, &states, k);
        let data = &mut workspace.data;
        let out = &mut out[k * size..(k + 1) * size];
        let result = match algorithm {
            BatchAlgorithm::NewtonEuler => {
                newton_euler(model, data, state.q, state.v, state.a, None)
            }
            BatchAlgorithm::ArticulatedBody => {
                let (v, tau) = (state.v.unwrap_or_default(), state.tau.unwrap_or_default());
                aba(model, data, state.q, v, tau, None)
            }
            BatchAlgorithm::CompositeRigidBody => {
                crba_into(model, data, state.q, out).map_err(|e| (k, e))?;
                continue;
            }
            BatchAlgorithm::RneaDerivatives => {
                let (v, a) = (state.v.unwrap_or_default(), state.a.unwrap_or_default());
                let into = DerivativesInto::Stacked(out);
                rnea_derivatives(model, data, state.q, v, a, None, into).map_err(|e| (k, e))?;
                continue;
            }
            BatchAlgorithm::AbaDerivatives => {
                let (v, tau) = (state.v.unwrap_or_default(), state.tau.unwrap_or_default());
                let into = DerivativesInto::Stacked(out);
                aba_derivatives(model, data, state.q, v, tau, None, into).map_err(|e| (k, e))?;
                continue;
            }
            BatchAlgorithm::FramePose { frame } => {
                let pose = frame_pose(model, data, state.q, frame).map_err(|e| (k, e))?;
                pose.write_homogeneous(out);
                continue;
            }
            BatchAlgorithm::Jacobian { frame, reference } => {
                out.fill(0.0);
                let column = |c: usize, linear: &Vec3, angular: &Vec3| {
                    write_jacobian_column(out, nv, c, linear, angular)
                };
                jacobian_columns(model, data, state.q, frame, reference, column)
                    .map_err(|e| (k, e))?;
                continue;
            }
        };
        out.copy_from_slice(result.map_err(|e| (k, e))?.as_slice());
    }
    Ok(())
}

/// Column `c` of a row-major 6 × nv Jacobian, `[linear; angular]`, in `f64` or lanes (what
/// [`jacobian_columns`] hands on, written as NumPy lays J out).
#[inline(always)]
pub fn write_jacobian_column<S: Real>(
    jacobian: &mut [S],
    nv: usize,
    c: usize,
    linear: &Vector3<S>,
    angular: &Vector3<S>,
) {
    for row in 0..3 {
        jacobian[row * nv + c] = linear[row];
        jacobian[(row + 3) * nv + c] = angular[row];
    }
}

/// State k of the batch.
pub(super) fn state<'s>(model: &Model, states: &States<'s>, k: usize) -> States<'s> {
    let (nq, nv) = (model.nq, model.nv);
    let row = |x: &'s [f64]| &x[k * nv..(k + 1) * nv];
    States {
        q: &states.q[k * nq..(k + 1) * nq],
        v: states.v.map(row),
        a: states.a.map(row),
        tau: states.tau.map(row),
    }
}

/// Checks the batch's shapes, then every state as a one-state call would.
pub(super) fn check_states(model: &Model, states: &States, n: usize) -> BatchResult {
    let whole = |e| (0, e);
    check_length("q", states.q.len(), n * model.nq).map_err(whole)?;
    for (name, values) in [("v", states.v), ("a", states.a), ("tau", states.tau)] {
        if let Some(values) = values {
            check_length(name, values.len(), n * model.nv).map_err(whole)?;
        }
    }
    for k in 0..n {
        let state = state(model, states, k);
        model.check_configuration(state.q).map_err(|e| (k, e))?;
        for (name, values) in [("v", state.v), ("a", state.a), ("tau", state.tau)] {
            if let Some(values) = values {
                check_vector(name, values, model.nv).map_err(|e| (k, e))?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::groups::groups;
    use super::*;
    use crate::algo::Reference;
    use crate::io::bundled_model;
    use crate::spatial::Inertia;
    use crate::spatial::{Mat3, Vec3};

    /// The lane kernels themselves, compiled without the wide instruction sets, so that they are
    /// checked on a CPU that lacks them too: each lane equals the one-state call bit for bit.
    fn lanes_equal_one_state<S: scatter::LaneRows>(algorithm: BatchAlgorithm) {
        let mut model = bundled_model("ur5", true).unwrap();
        // a floating UR5 needs a base inertia for forward dynamics
        let base = Mat3::from_diagonal_element(0.01);
        model.inertias[1] = Inertia::from_com(4.0, &Vec3::new(0.0, 0.0, 0.02), &base);
        let mut rng = <rand::rngs::StdRng as rand::SeedableRng>::seed_from_u64(7);
        let n = 2 * S::LANES;
        let (mut q, mut v, mut a) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..n {
            q.extend(model.random_configuration(&mut rng).iter());
            v.extend((0..model.nv).map(|j| (k + j) as f64 * 0.1 - 0.3));
            a.extend((0..model.nv).map(|j| (k * j) as f64 * 0.05 - 0.2));
        }
        let inputs = [&q[..], &v[..], &a[..]];
        let states = algorithm.states(&inputs[..algorithm.inputs().len()]);
        let size = algorithm.output_size(&model);
        let mut lanes = vec![0.0; n * size];
        groups(
            algorithm,
            &model,
            &mut Lanes::<S>::new(&model),
            states,
            &mut lanes,
        )
        .unwrap();
        let mut one_by_one = vec![0.0; n * size];
        let mut workspace = BatchWorkspace::with_width(&model, LaneWidth::One).unwrap();
        run_batch(algorithm, &model, &mut workspace, states, &mut one_by_one).unwrap();
        let same = lanes
            .iter()
            .zip(&one_by_one)
            .all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same, "{algorithm:?}, {} lanes", S::LANES);
    }

    #[test]
    fn four_and_eight_lanes_equal_one_state_without_wide_instructions() {
        for algorithm in [
            BatchAlgorithm::NewtonEuler,
            BatchAlgorithm::ArticulatedBody,
            BatchAlgorithm::CompositeRigidBody,
            BatchAlgorithm::RneaDerivatives,
            BatchAlgorithm::AbaDerivatives,
            BatchAlgorithm::FramePose { frame: 7 },
            BatchAlgorithm::Jacobian {
                frame: 7,
                reference: Reference::World,
            },
            BatchAlgorithm::Jacobian {
                frame: 5,
                reference: Reference::Local,
            },
            BatchAlgorithm::Jacobian {
                frame: 7,
                reference: Reference::Spatial,
            },
        ] {
            lanes_equal_one_state::<AutoF64x4>(algorithm);
            lanes_equal_one_state::<AutoF64x8>(algorithm);
        }
    }
}
