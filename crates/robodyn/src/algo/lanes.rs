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

use crate::algo::rnea::{newton_euler, newton_euler_passes, NewtonEulerBuffers};
use crate::error::{check_length, check_vector, Error, Result};
use crate::model::Model;
use crate::spatial::{Force, Motion, Real, Transform};
use crate::Data;
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

/// The per-lane buffers of one lane type: inputs gathered into lanes and the kernel's results.
#[derive(Debug, Clone)]
struct Lanes<S> {
    q: Vec<S>,
    v: Vec<S>,
    a: Vec<S>,
    x_up: Vec<Transform<S>>,
    velocities: Vec<Motion<S>>,
    accelerations: Vec<Motion<S>>,
    forces: Vec<Force<S>>,
    tau: Vec<S>,
}

impl<S: Real> Lanes<S> {
    fn new(model: &Model) -> Self {
        let bodies = model.nbodies();
        let zero = S::splat(0.0);
        Lanes {
            q: vec![zero; model.nq],
            v: vec![zero; model.nv],
            a: vec![zero; model.nv],
            x_up: vec![Transform::splat(&Transform::IDENTITY); bodies],
            velocities: vec![Motion::zeros(); bodies],
            accelerations: vec![Motion::zeros(); bodies],
            forces: vec![Force::splat(&Force::ZERO); bodies],
            tau: vec![zero; model.nv],
        }
    }
}

/// What a batch kernel works in: a [`Data`] for single states and the lane buffers of its width.
/// Made once per model (and per thread); running a batch then allocates nothing.
#[derive(Debug, Clone)]
pub struct BatchWorkspace {
    width: LaneWidth,
    data: Data,
    four: Lanes<AutoF64x4>,
    eight: Lanes<AutoF64x8>,
}

impl BatchWorkspace {
    /// A workspace for `model` at the widest width this CPU runs.
    pub fn new(model: &Model) -> Self {
        BatchWorkspace {
            width: LaneWidth::detect(),
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
}

/// A batch of states, each row-major: `q` is n × nq, `v` and `a` n × nv or `None` for zero.
#[derive(Debug, Clone, Copy)]
pub struct States<'s> {
    pub q: &'s [f64],
    pub v: Option<&'s [f64]>,
    pub a: Option<&'s [f64]>,
}

/// A batch error: the state it came from and what was wrong with it.
pub type BatchResult = std::result::Result<(), (usize, Error)>;

/// Newton–Euler over a batch, `tau` (n × nv) = ID(q, v, a) of every state: inverse dynamics,
/// bias forces (`a = None`) or gravity (`v = a = None`). Every state is checked first (the error
/// names the first bad one); then the states run in groups of the workspace's width.
pub fn newton_euler_batch(
    model: &Model,
    workspace: &mut BatchWorkspace,
    states: States,
    tau: &mut [f64],
) -> BatchResult {
    if model.nv == 0 {
        return Ok(());
    }
    let n = tau.len() / model.nv;
    check_states(model, &states, n)?;
    let grouped = match workspace.width {
        LaneWidth::One => 0,
        width => n - n % width.states(),
    };
    match workspace.width {
        LaneWidth::One => {}
        // SAFETY (both): the width was found available on this CPU when the workspace was made
        LaneWidth::Four => unsafe {
            newton_euler_four(
                model,
                &mut workspace.four,
                states,
                &mut tau[..grouped * model.nv],
            )
        },
        LaneWidth::Eight => unsafe {
            newton_euler_eight(
                model,
                &mut workspace.eight,
                states,
                &mut tau[..grouped * model.nv],
            )
        },
    }
    // what is left, one state at a time
    for k in grouped..n {
        let state = state(model, &states, k);
        let result = newton_euler(model, &mut workspace.data, state.q, state.v, state.a, None)
            .map_err(|e| (k, e))?;
        tau[k * model.nv..(k + 1) * model.nv].copy_from_slice(result.as_slice());
    }
    Ok(())
}

/// [`newton_euler_groups`] compiled for AVX2. Safety: only on a CPU with AVX2 and FMA.
#[cfg_attr(target_arch = "x86_64", target_feature(enable = "avx2,fma"))]
unsafe fn newton_euler_four(
    model: &Model,
    lanes: &mut Lanes<AutoF64x4>,
    states: States,
    tau: &mut [f64],
) {
    newton_euler_groups(model, lanes, states, tau);
}

/// [`newton_euler_groups`] compiled for AVX-512. Safety: only on a CPU with AVX-512F.
#[cfg_attr(target_arch = "x86_64", target_feature(enable = "avx512f"))]
unsafe fn newton_euler_eight(
    model: &Model,
    lanes: &mut Lanes<AutoF64x8>,
    states: States,
    tau: &mut [f64],
) {
    newton_euler_groups(model, lanes, states, tau);
}

/// The Newton–Euler passes on the groups of states that fill `tau`, `S::LANES` at a time.
#[inline(always)]
fn newton_euler_groups<S: Real>(
    model: &Model,
    lanes: &mut Lanes<S>,
    states: States,
    tau: &mut [f64],
) {
    let (nq, nv) = (model.nq, model.nv);
    for (g, tau) in tau.chunks_exact_mut(S::LANES * nv).enumerate() {
        let first = g * S::LANES;
        gather(&mut lanes.q, states.q, first, nq);
        if let Some(v) = states.v {
            gather(&mut lanes.v, v, first, nv);
        }
        if let Some(a) = states.a {
            gather(&mut lanes.a, a, first, nv);
        }
        let buffers = NewtonEulerBuffers {
            x_up: &mut lanes.x_up,
            v: &mut lanes.velocities,
            a: &mut lanes.accelerations,
            f: &mut lanes.forces,
            tau: &mut lanes.tau,
        };
        let v = states.v.map(|_| &lanes.v[..]);
        let a = states.a.map(|_| &lanes.a[..]);
        newton_euler_passes(model, &lanes.q, v, a, None, buffers);
        scatter(&lanes.tau, tau, nv);
    }
}

/// Lane l of `lanes[j]` = entry j of row `first + l` of the row-major `rows` (width `size`).
#[inline(always)]
fn gather<S: Real>(lanes: &mut [S], rows: &[f64], first: usize, size: usize) {
    let rows = &rows[first * size..(first + S::LANES) * size];
    for (j, lane) in lanes.iter_mut().enumerate() {
        for l in 0..S::LANES {
            lane.replace(l, rows[l * size + j]);
        }
    }
}

/// Entry j of row l of the row-major `rows` (width `size`) = lane l of `lanes[j]`.
#[inline(always)]
fn scatter<S: Real>(lanes: &[S], rows: &mut [f64], size: usize) {
    for (j, lane) in lanes.iter().enumerate() {
        for l in 0..S::LANES {
            rows[l * size + j] = lane.extract(l);
        }
    }
}

/// State k of the batch.
fn state<'s>(model: &Model, states: &States<'s>, k: usize) -> States<'s> {
    let (nq, nv) = (model.nq, model.nv);
    States {
        q: &states.q[k * nq..(k + 1) * nq],
        v: states.v.map(|v| &v[k * nv..(k + 1) * nv]),
        a: states.a.map(|a| &a[k * nv..(k + 1) * nv]),
    }
}

/// Checks the batch's shapes, then every state as a one-state call would.
fn check_states(model: &Model, states: &States, n: usize) -> BatchResult {
    let whole = |e| (0, e);
    check_length("q", states.q.len(), n * model.nq).map_err(whole)?;
    for (name, values) in [("v", states.v), ("a", states.a)] {
        if let Some(values) = values {
            check_length(name, values.len(), n * model.nv).map_err(whole)?;
        }
    }
    for k in 0..n {
        let state = state(model, states, k);
        model.check_configuration(state.q).map_err(|e| (k, e))?;
        for (name, values) in [("v", state.v), ("a", state.a)] {
            if let Some(values) = values {
                check_vector(name, values, model.nv).map_err(|e| (k, e))?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::bundled_model;

    /// The lane kernels themselves, compiled without the wide instruction sets, so that they are
    /// checked on a CPU that lacks them too: each lane equals the one-state call bit for bit.
    fn lanes_equal_one_state<S: Real>() {
        let model = bundled_model("ur5", true).unwrap();
        let mut rng = <rand::rngs::StdRng as rand::SeedableRng>::seed_from_u64(7);
        let n = 2 * S::LANES;
        let (mut q, mut v, mut a) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..n {
            q.extend(model.random_configuration(&mut rng).iter());
            v.extend((0..model.nv).map(|j| (k + j) as f64 * 0.1 - 0.3));
            a.extend((0..model.nv).map(|j| (k * j) as f64 * 0.05 - 0.2));
        }
        let states = States {
            q: &q,
            v: Some(&v),
            a: Some(&a),
        };
        let mut tau = vec![0.0; n * model.nv];
        newton_euler_groups(&model, &mut Lanes::<S>::new(&model), states, &mut tau);
        let mut data = Data::new(&model);
        for k in 0..n {
            let one = state(&model, &states, k);
            let expected = newton_euler(&model, &mut data, one.q, one.v, one.a, None).unwrap();
            let row = &tau[k * model.nv..(k + 1) * model.nv];
            assert!(row
                .iter()
                .zip(expected.iter())
                .all(|(x, y)| x.to_bits() == y.to_bits()));
        }
    }

    #[test]
    fn four_and_eight_lanes_equal_one_state_without_wide_instructions() {
        lanes_equal_one_state::<AutoF64x4>();
        lanes_equal_one_state::<AutoF64x8>();
    }
}
