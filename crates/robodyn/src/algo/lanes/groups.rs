//! The lane kernels: a group of `S::LANES` states gathered into lanes, run through an algorithm's
//! generic passes, scattered back; compiled once per instruction set.

use super::scatter::LaneRows;
use super::{write_jacobian_column, BatchAlgorithm, States};
use crate::algo::aba::{articulated_body_passes, AbaBuffers};
use crate::algo::crba::{mass_matrix_of, MassMatrixBuffers};
use crate::algo::derivatives::{
    aba_derivative_passes, derivative_passes, DerivativeBuffers, RowMajor, SolveBuffers,
};
use crate::algo::jacobian::columns_of;
use crate::algo::kinematics::{placement_of_frame, support_of, support_placements};
use crate::algo::rnea::{newton_euler_passes, NewtonEulerBuffers};
use crate::model::Model;
use crate::spatial::{
    splat_matrix6, CoriolisFactor, Force, Inertia, Mat6, Motion, Real, Transform,
};
use nalgebra::Matrix6;
use simba::simd::{AutoF64x4, AutoF64x8};

/// The per-lane buffers of one lane type: inputs gathered into lanes, the kernels' intermediates
/// and their result.
#[derive(Debug, Clone)]
pub(super) struct Lanes<S> {
    q: Vec<S>,
    v: Vec<S>,
    a: Vec<S>,
    tau: Vec<S>,
    x_up: Vec<Transform<S>>,
    velocities: Vec<Motion<S>>,
    accelerations: Vec<Motion<S>>,
    forces: Vec<Force<S>>,
    velocity_products: Vec<Motion<S>>,
    articulated_inertias: Vec<Matrix6<S>>,
    articulated_biases: Vec<Force<S>>,
    u: Vec<[Force<S>; 6]>,
    u_tau: Vec<[S; 6]>,
    d_inv: Vec<Matrix6<S>>,
    x_world: Vec<Transform<S>>,
    composites: Vec<Inertia<S>>,
    subspaces: Vec<Motion<S>>,
    body_composites: Vec<Inertia<S>>,
    subspace_forces: Vec<Force<S>>,
    mass_matrix: Vec<S>,
    motion_terms: Vec<[Motion<S>; 3]>,
    body_inertias: Vec<Inertia<S>>,
    velocity_forces: Vec<Force<S>>,
    coriolis_factors: Vec<CoriolisFactor<S>>,
    dtau_dq: Vec<S>,
    dtau_dv: Vec<S>,
    bias: Vec<S>,
    factor: Vec<S>,
    rows: Vec<S>,
    out: Vec<S>,
    support: Vec<usize>,
    pose: Vec<S>,
    jacobian: Vec<S>,
}

impl<S: Real> Lanes<S> {
    pub(super) fn new(model: &Model) -> Self {
        let bodies = model.nbodies();
        let zero = S::splat(0.0);
        let zero_force = Force::splat(&Force::ZERO);
        let zero_matrix = splat_matrix6(&Mat6::zeros());
        Lanes {
            q: vec![zero; model.nq],
            v: vec![zero; model.nv],
            a: vec![zero; model.nv],
            tau: vec![zero; model.nv],
            x_up: vec![Transform::splat(&Transform::IDENTITY); bodies],
            velocities: vec![Motion::zeros(); bodies],
            accelerations: vec![Motion::zeros(); bodies],
            forces: vec![zero_force; bodies],
            velocity_products: vec![Motion::zeros(); bodies],
            articulated_inertias: vec![zero_matrix; bodies],
            articulated_biases: vec![zero_force; bodies],
            u: vec![[zero_force; 6]; bodies],
            u_tau: vec![[zero; 6]; bodies],
            d_inv: vec![zero_matrix; bodies],
            x_world: vec![Transform::splat(&Transform::IDENTITY); bodies],
            composites: vec![Inertia::splat(&Inertia::ZERO); bodies],
            subspaces: vec![Motion::zeros(); model.nv],
            body_composites: vec![Inertia::splat(&Inertia::ZERO); bodies],
            subspace_forces: vec![zero_force; model.nv],
            mass_matrix: vec![zero; model.nv * model.nv],
            motion_terms: vec![[Motion::zeros(); 3]; model.nv],
            body_inertias: vec![Inertia::splat(&Inertia::ZERO); bodies],
            velocity_forces: vec![zero_force; bodies],
            coriolis_factors: vec![CoriolisFactor::splat(&CoriolisFactor::ZERO); bodies],
            dtau_dq: vec![zero; model.nv * model.nv],
            dtau_dv: vec![zero; model.nv * model.nv],
            bias: vec![zero; model.nv],
            factor: vec![zero; model.nv * model.nv],
            rows: vec![zero; 3 * model.nv * model.nv],
            out: vec![zero; model.nv],
            support: Vec::with_capacity(bodies),
            pose: vec![zero; 16],
            jacobian: vec![zero; 6 * model.nv],
        }
    }
}

/// The lane buffers the derivative passes work in, and beside them the inputs and the
/// buffers the callers of those passes use.
struct DerivativeInputs<'b, S> {
    q: &'b [S],
    v: &'b [S],
    a: &'b [S],
    tau: &'b [S],
    dtau_dq: &'b mut [S],
    dtau_dv: &'b mut [S],
    factor: &'b mut [S],
    qdd: &'b mut [S],
    rows: &'b mut [S],
}

impl<S: Real> Lanes<S> {
    /// The derivative passes' buffers and the rest, borrowed apart.
    #[inline(always)]
    fn derivative_buffers(&mut self) -> (DerivativeBuffers<'_, S>, DerivativeInputs<'_, S>) {
        let buffers = DerivativeBuffers {
            x_up: &mut self.x_up,
            x_world: &mut self.x_world,
            i_c: &mut self.composites,
            s_world: &mut self.subspaces,
            v_world: &mut self.velocities,
            a_world: &mut self.accelerations,
            motion_terms: &mut self.motion_terms,
            i_world: &mut self.body_inertias,
            f_velocity: &mut self.velocity_forces,
            f_world: &mut self.forces,
            coriolis_factors: &mut self.coriolis_factors,
            tau: &mut self.bias,
            mass_matrix: &mut self.mass_matrix,
        };
        let inputs = DerivativeInputs {
            q: &self.q,
            v: &self.v,
            a: &self.a,
            tau: &self.tau,
            dtau_dq: &mut self.dtau_dq,
            dtau_dv: &mut self.dtau_dv,
            factor: &mut self.factor,
            qdd: &mut self.out,
            rows: &mut self.rows,
        };
        (buffers, inputs)
    }
}

/// [`groups`] compiled for AVX2. Safety: only on a CPU with AVX2 and FMA.
#[cfg_attr(target_arch = "x86_64", target_feature(enable = "avx2,fma"))]
pub(super) unsafe fn groups_four(
    algorithm: BatchAlgorithm,
    model: &Model,
    lanes: &mut Lanes<AutoF64x4>,
    states: States,
    out: &mut [f64],
) -> std::result::Result<(), usize> {
    groups(algorithm, model, lanes, states, out)
}

/// [`groups`] compiled for AVX-512. Safety: only on a CPU with AVX-512F.
#[cfg_attr(target_arch = "x86_64", target_feature(enable = "avx512f"))]
pub(super) unsafe fn groups_eight(
    algorithm: BatchAlgorithm,
    model: &Model,
    lanes: &mut Lanes<AutoF64x8>,
    states: States,
    out: &mut [f64],
) -> std::result::Result<(), usize> {
    groups(algorithm, model, lanes, states, out)
}

/// `algorithm` on the groups of states that fill `out`, `S::LANES` at a time. An error gives the
/// first state of a group where a lane failed (a singular articulated inertia or mass matrix).
#[inline(always)]
pub(super) fn groups<S: LaneRows>(
    algorithm: BatchAlgorithm,
    model: &Model,
    lanes: &mut Lanes<S>,
    states: States,
    out: &mut [f64],
) -> std::result::Result<(), usize> {
    let (nv, size) = (model.nv, algorithm.output_size(model));
    for (g, out) in out.chunks_exact_mut(S::LANES * size).enumerate() {
        let first = g * S::LANES;
        gather(&mut lanes.q, states.q, first);
        for (input, lanes) in [
            (states.v, &mut lanes.v),
            (states.a, &mut lanes.a),
            (states.tau, &mut lanes.tau),
        ] {
            if let Some(input) = input {
                gather(lanes, input, first);
            }
        }
        match algorithm {
            BatchAlgorithm::NewtonEuler => {
                let buffers = NewtonEulerBuffers {
                    x_up: &mut lanes.x_up,
                    v: &mut lanes.velocities,
                    a: &mut lanes.accelerations,
                    f: &mut lanes.forces,
                    tau: &mut lanes.out,
                };
                let v = states.v.map(|_| &lanes.v[..]);
                let a = states.a.map(|_| &lanes.a[..]);
                newton_euler_passes(model, &lanes.q, v, a, None, buffers);
            }
            BatchAlgorithm::ArticulatedBody => {
                let buffers = AbaBuffers {
                    x_up: &mut lanes.x_up,
                    v: &mut lanes.velocities,
                    c: &mut lanes.velocity_products,
                    a: &mut lanes.accelerations,
                    i_a: &mut lanes.articulated_inertias,
                    p_a: &mut lanes.articulated_biases,
                    u: &mut lanes.u,
                    u_tau: &mut lanes.u_tau,
                    d_inv: &mut lanes.d_inv,
                    qdd: &mut lanes.out,
                };
                articulated_body_passes(model, &lanes.q, &lanes.v, &lanes.tau, None, buffers)
                    .map_err(|_| first)?;
            }
            BatchAlgorithm::CompositeRigidBody => {
                let buffers = MassMatrixBuffers {
                    x_up: &mut lanes.x_up,
                    x_world: &mut lanes.x_world,
                    world_composites: &mut lanes.composites,
                    subspaces: &mut lanes.subspaces,
                    body_composites: &mut lanes.body_composites,
                    forces: lanes.subspace_forces.as_mut_slice(),
                    mass_matrix: &mut lanes.mass_matrix,
                };
                mass_matrix_of(model, &lanes.q, buffers);
                S::scatter(&lanes.mass_matrix, out, size, 0);
                continue;
            }
            BatchAlgorithm::RneaDerivatives => {
                let zero = S::splat(0.0);
                lanes.dtau_dq.fill(zero);
                lanes.dtau_dv.fill(zero);
                let (mut buffers, inputs) = lanes.derivative_buffers();
                let mut sink = RowMajor {
                    by_q: inputs.dtau_dq,
                    by_v: inputs.dtau_dv,
                    nv,
                };
                let state = (inputs.q, inputs.v, inputs.a, None);
                derivative_passes(model, &mut buffers, state, &mut sink);
                let block = nv * nv;
                for (part, lanes) in [&lanes.dtau_dq, &lanes.dtau_dv, &lanes.mass_matrix]
                    .into_iter()
                    .enumerate()
                {
                    S::scatter(lanes, out, size, part * block);
                }
                continue;
            }
            BatchAlgorithm::AbaDerivatives => {
                let (mut buffers, inputs) = lanes.derivative_buffers();
                let solve = SolveBuffers {
                    factor: inputs.factor,
                    qdd: inputs.qdd,
                    rows: inputs.rows,
                };
                let state = (inputs.q, inputs.v, inputs.tau, None);
                aba_derivative_passes(model, &mut buffers, solve, state).map_err(|()| first)?;
                // row i = [∂q̈_i/∂q, ∂q̈_i/∂q̇, (M⁻¹)_i]: each third to row i of its block
                for (i, row) in lanes.rows.chunks_exact(3 * nv).enumerate() {
                    for (block, part) in row.chunks_exact(nv).enumerate() {
                        S::scatter(part, out, size, (block * nv + i) * nv);
                    }
                }
                continue;
            }
            BatchAlgorithm::FramePose { frame } => {
                let x_world = &mut lanes.x_world;
                support_of(model, model.frames[frame].body, &mut lanes.support);
                support_placements(model, &lanes.q, &lanes.support, &mut lanes.x_up, x_world);
                placement_of_frame(model, x_world, frame).write_homogeneous(&mut lanes.pose);
                S::scatter(&lanes.pose, out, size, 0);
                continue;
            }
            BatchAlgorithm::Jacobian { frame, reference } => {
                let x_world = &mut lanes.x_world;
                support_of(model, model.frames[frame].body, &mut lanes.support);
                support_placements(model, &lanes.q, &lanes.support, &mut lanes.x_up, x_world);
                let jacobian = &mut lanes.jacobian;
                jacobian.fill(S::splat(0.0));
                let placements = (&lanes.support[..], &x_world[..]);
                columns_of(model, placements, frame, reference, |c, linear, angular| {
                    write_jacobian_column(jacobian, nv, c, linear, angular)
                });
                S::scatter(jacobian, out, size, 0);
                continue;
            }
        }
        S::scatter(&lanes.out, out, nv, 0);
    }
    Ok(())
}

/// Lane l of `lanes[j]` = entry j of row `first + l` of the row-major `rows` (width
/// `lanes.len()`).
#[inline(always)]
pub(super) fn gather<S: LaneRows>(lanes: &mut [S], rows: &[f64], first: usize) {
    let size = lanes.len();
    S::gather(&rows[first * size..(first + S::LANES) * size], lanes);
}
