//! Constrained forward dynamics and impulses of a batch in lanes: the articulated route of
//! [`crate::algo::constrained_forward_dynamics`] and [`crate::algo::impulse_dynamics`] (ABA, the
//! rows, their inward passes, Λ⁻¹, its Cholesky solve and the forces' outward pass) run on
//! `S::LANES` states at once, each lane performing the operations of a one-state call, so that
//! each lane's result equals that call's bit for bit.
//!
//! A group runs one state at a time instead where its lanes cannot share the instructions: a
//! lane whose rows are dependent (the Cholesky pivot test fails in some lane; the one-state call
//! then names the row, or solves it with damping), and every state when `damping` > 0 (the
//! proximal iterations stop at a different count in each lane).

use super::groups::gather;
use super::scatter::LaneRows;
use super::{check_states, state, BatchResult, LaneWidth, States};
use crate::algo::aba::{articulated_inertia_passes, AbaBuffers};
use crate::algo::constrained::{
    accelerated_right_side, articulated_delassus, check_impact, constrained_accelerations,
    constrained_forward_dynamics, constraint_response, impact_right_side, impulse_dynamics,
    rows_under_free_motion, solve_direct, support_acceleration_pass, AbaTerms, ConstrainedOptions,
    ConstraintData, RouteBuffers,
};
use crate::constraint::ConstraintSet;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::spatial::{splat_matrix6, Force, Mat6, Motion, Real, Transform};
use crate::Data;
use nalgebra::{DMatrix, Matrix6, Vector6};
use simba::simd::{AutoF64x4, AutoF64x8};

/// What a constrained batch works in, for one model and one constraint set: a [`Data`] and a
/// [`ConstraintData`] for single states and the lane buffers of its width. Made once; running
/// a batch then allocates nothing.
#[derive(Debug, Clone)]
pub struct ConstrainedBatchWorkspace {
    width: LaneWidth,
    /// How many states of the last batch ran in lanes.
    in_lanes: usize,
    data: Data,
    constraints: ConstraintData,
    four: ConstrainedLanes<AutoF64x4>,
    eight: ConstrainedLanes<AutoF64x8>,
}

impl ConstrainedBatchWorkspace {
    /// A workspace for `set` on `model` at the widest width this CPU runs.
    pub fn new(model: &Model, set: &ConstraintSet) -> Self {
        ConstrainedBatchWorkspace {
            width: LaneWidth::detect(),
            in_lanes: 0,
            data: Data::new(model),
            constraints: ConstraintData::new(model, set),
            four: ConstrainedLanes::new(model, set),
            eight: ConstrainedLanes::new(model, set),
        }
    }

    /// A workspace forced to `width` (to compare the widths); an error if this CPU lacks it.
    pub fn with_width(model: &Model, set: &ConstraintSet, width: LaneWidth) -> Result<Self> {
        if !width.available() {
            return Err(Error::InvalidValue {
                argument: "width".into(),
                message: format!("this CPU lacks the instructions of lane width {width:?}"),
            });
        }
        Ok(ConstrainedBatchWorkspace {
            width,
            ..ConstrainedBatchWorkspace::new(model, set)
        })
    }

    /// Whether this workspace was made for a set of `set`'s size on `model`.
    pub fn fits(&self, model: &Model, set: &ConstraintSet) -> bool {
        self.constraints.fits(model, set)
    }

    /// How many states of the last batch ran in lanes (the others ran one at a time).
    pub fn states_in_lanes(&self) -> usize {
        self.in_lanes
    }
}

/// [`constrained_forward_dynamics`] on every state of a batch (`states`: q, v and τ; no external
/// forces), in lanes where it can: `out` is n × (nv + m), each row q̈ then λ.
pub fn constrained_forward_dynamics_batch(
    model: &Model,
    workspace: &mut ConstrainedBatchWorkspace,
    set: &ConstraintSet,
    states: States,
    options: &ConstrainedOptions,
    out: &mut [f64],
) -> BatchResult {
    options.check().map_err(|e| (0, e))?;
    run_route(model, workspace, set, states, Route::Forward(options), out)
}

/// [`impulse_dynamics`] on every state of a batch (`states`: q and v), in lanes where it can:
/// `out` is n × (nv + m), each row q̇ after the impact then the impulses.
pub fn impulse_dynamics_batch(
    model: &Model,
    workspace: &mut ConstrainedBatchWorkspace,
    set: &ConstraintSet,
    states: States,
    (restitution, damping): (f64, f64),
    out: &mut [f64],
) -> BatchResult {
    check_impact(restitution, damping).map_err(|e| (0, e))?;
    let route = Route::Impulse {
        restitution,
        damping,
    };
    run_route(model, workspace, set, states, route, out)
}

/// Which computation a constrained batch runs.
#[derive(Debug, Clone, Copy)]
pub(super) enum Route<'a> {
    /// Forward dynamics on (q, v, τ): q̈, then λ.
    Forward(&'a ConstrainedOptions),
    /// Impulses on (q, v): q̇ after, then the impulses.
    Impulse { restitution: f64, damping: f64 },
}

impl Route<'_> {
    fn damping(self) -> f64 {
        match self {
            Route::Forward(options) => options.damping,
            Route::Impulse { damping, .. } => damping,
        }
    }
}

/// Checks the workspace and the states, runs the full groups in lanes (none with damping) and
/// the rest, with any group from the first whose lanes could not share, one state at a time.
fn run_route(
    model: &Model,
    workspace: &mut ConstrainedBatchWorkspace,
    set: &ConstraintSet,
    states: States,
    route: Route,
    out: &mut [f64],
) -> BatchResult {
    let (nv, size) = (model.nv, model.nv + set.rows());
    let whole = |e| (0, e);
    if !workspace.fits(model, set) {
        return Err(whole(Error::Shape {
            argument: "workspace".into(),
            expected: format!("one made for {} rows on this model", set.rows()),
            received: format!(
                "one made for {} rows",
                workspace.constraints.jacobian.nrows()
            ),
        }));
    }
    let n = out.len() / size;
    check_states(model, &states, n)?;
    let forward = matches!(route, Route::Forward(_));
    if states.v.is_none() || (forward && states.tau.is_none()) {
        let needed = if forward { "v and tau" } else { "v" };
        return Err(whole(Error::InvalidValue {
            argument: "states".into(),
            message: format!("this batch needs {needed}"),
        }));
    }
    let grouped = match (workspace.width, route.damping() > 0.0) {
        (LaneWidth::One, _) | (_, true) => 0,
        (width, false) => n - n % width.states(),
    };
    let lanes_out = &mut out[..grouped * size];
    let in_lanes = match workspace.width {
        LaneWidth::One => Ok(()),
        // SAFETY (both): the width was found available on this CPU when the workspace was made
        LaneWidth::Four => unsafe {
            constrained_four(model, set, route, &mut workspace.four, states, lanes_out)
        },
        LaneWidth::Eight => unsafe {
            constrained_eight(model, set, route, &mut workspace.eight, states, lanes_out)
        },
    };
    // what is left, and any group from the first whose lanes could not share, one at a time
    let first = in_lanes.err().unwrap_or(grouped);
    workspace.in_lanes = first;
    let ConstrainedBatchWorkspace {
        data, constraints, ..
    } = workspace;
    for k in first..n {
        let one = state(model, &states, k);
        let v = one.v.unwrap_or_default();
        let solved = match route {
            Route::Forward(options) => {
                let state = (one.q, v, one.tau.unwrap_or_default());
                constrained_forward_dynamics(model, data, constraints, set, state, None, options)
            }
            Route::Impulse {
                restitution,
                damping,
            } => {
                let state = (one.q, v);
                impulse_dynamics(model, data, constraints, set, state, restitution, damping)
            }
        };
        solved.map_err(|e| (k, e))?;
        let row = &mut out[k * size..(k + 1) * size];
        row[..nv].copy_from_slice(constraints.qdd.as_slice());
        row[nv..].copy_from_slice(constraints.forces.as_slice());
    }
    Ok(())
}

/// [`constrained_groups`] compiled for AVX2. Safety: only on a CPU with AVX2 and FMA.
#[cfg_attr(target_arch = "x86_64", target_feature(enable = "avx2,fma"))]
unsafe fn constrained_four(
    model: &Model,
    set: &ConstraintSet,
    route: Route,
    lanes: &mut ConstrainedLanes<AutoF64x4>,
    states: States,
    out: &mut [f64],
) -> std::result::Result<(), usize> {
    constrained_groups(model, set, route, lanes, states, out)
}

/// [`constrained_groups`] compiled for AVX-512. Safety: only on a CPU with AVX-512F.
#[cfg_attr(target_arch = "x86_64", target_feature(enable = "avx512f"))]
unsafe fn constrained_eight(
    model: &Model,
    set: &ConstraintSet,
    route: Route,
    lanes: &mut ConstrainedLanes<AutoF64x8>,
    states: States,
    out: &mut [f64],
) -> std::result::Result<(), usize> {
    constrained_groups(model, set, route, lanes, states, out)
}

/// The groups of states that fill `out` (rows of q̈ or q̇ after, then λ), `S::LANES` at a time.
/// An error gives the first state of a group whose lanes could not share the instructions.
#[inline(always)]
pub(super) fn constrained_groups<S: LaneRows>(
    model: &Model,
    set: &ConstraintSet,
    route: Route,
    lanes: &mut ConstrainedLanes<S>,
    states: States,
    out: &mut [f64],
) -> std::result::Result<(), usize> {
    let (nv, size) = (model.nv, model.nv + set.rows());
    let Some(v) = states.v else {
        return Err(0);
    };
    // impulses: ABA's terms at τ = 0, as the one-state call takes them
    lanes.tau.fill(S::zero());
    for (g, out) in out.chunks_exact_mut(S::LANES * size).enumerate() {
        let first = g * S::LANES;
        gather(&mut lanes.q, states.q, first);
        gather(&mut lanes.v, v, first);
        if let (Route::Forward(_), Some(tau)) = (route, states.tau) {
            gather(&mut lanes.tau, tau, first);
        }
        lanes.solve(model, set, route).map_err(|()| first)?;
        S::scatter(&lanes.qdd, out, size, 0);
        S::scatter(&lanes.forces, out, size, nv);
    }
    Ok(())
}

/// The lane buffers of the constrained route: the inputs, ABA's terms, the rows and their
/// workspace, the results.
#[derive(Debug, Clone)]
pub(super) struct ConstrainedLanes<S> {
    q: Vec<S>,
    v: Vec<S>,
    tau: Vec<S>,
    x_up: Vec<Transform<S>>,
    velocities: Vec<Motion<S>>,
    velocity_products: Vec<Motion<S>>,
    accelerations: Vec<Motion<S>>,
    articulated_inertias: Vec<Matrix6<S>>,
    articulated_biases: Vec<Force<S>>,
    u: Vec<[Force<S>; 6]>,
    u_tau: Vec<[S; 6]>,
    d_inv: Vec<Matrix6<S>>,
    free_acceleration: Vec<S>,
    x_world: Vec<Transform<S>>,
    jacobian: DMatrix<S>,
    drift: Vec<S>,
    error: Vec<S>,
    rhs: Vec<S>,
    transmitted_rows: DMatrix<S>,
    delassus: DMatrix<S>,
    body_forces: Vec<[Force<S>; 6]>,
    body_accelerations: Vec<Motion<S>>,
    joint_forces: Vec<S>,
    body_rows: Vec<(Vector6<S>, Vector6<S>)>,
    factor: Vec<S>,
    forces: Vec<S>,
    qdd: Vec<S>,
}

impl<S: Real> ConstrainedLanes<S> {
    fn new(model: &Model, set: &ConstraintSet) -> Self {
        let (bodies, nv, m) = (model.nbodies(), model.nv, set.rows());
        let zero = S::splat(0.0);
        let zero_force = Force::splat(&Force::ZERO);
        let zero_matrix = splat_matrix6(&Mat6::zeros());
        let identity = Transform::splat(&Transform::IDENTITY);
        ConstrainedLanes {
            q: vec![zero; model.nq],
            v: vec![zero; nv],
            tau: vec![zero; nv],
            x_up: vec![identity; bodies],
            velocities: vec![Motion::zeros(); bodies],
            velocity_products: vec![Motion::zeros(); bodies],
            accelerations: vec![Motion::zeros(); bodies],
            articulated_inertias: vec![zero_matrix; bodies],
            articulated_biases: vec![zero_force; bodies],
            u: vec![[zero_force; 6]; bodies],
            u_tau: vec![[zero; 6]; bodies],
            d_inv: vec![zero_matrix; bodies],
            free_acceleration: vec![zero; nv],
            x_world: vec![identity; bodies],
            jacobian: DMatrix::from_element(m, nv, zero),
            drift: vec![zero; m],
            error: vec![zero; m],
            rhs: vec![zero; m],
            transmitted_rows: DMatrix::from_element(m, nv, zero),
            delassus: DMatrix::from_element(m, m, zero),
            body_forces: vec![[zero_force; 6]; bodies],
            body_accelerations: vec![Motion::zeros(); bodies],
            joint_forces: vec![zero; nv],
            body_rows: vec![(Vector6::from_element(zero), Vector6::from_element(zero)); m],
            factor: vec![zero; m * m],
            forces: vec![zero; m],
            qdd: vec![zero; nv],
        }
    }

    /// The steps of [`constrained_forward_dynamics`] or [`impulse_dynamics`] on the gathered
    /// states (their Cholesky solve, without damping); `Err` where some lane's articulated
    /// inertia or rows are singular.
    #[inline(always)]
    fn solve(
        &mut self,
        model: &Model,
        set: &ConstraintSet,
        route: Route,
    ) -> std::result::Result<(), ()> {
        let m = set.rows();
        // ABA's passes 1 and 2 at (q, q̇, τ), and a_f along the rows' support
        let mut buffers = AbaBuffers {
            x_up: &mut self.x_up,
            v: &mut self.velocities,
            c: &mut self.velocity_products,
            a: &mut self.accelerations,
            i_a: &mut self.articulated_inertias,
            p_a: &mut self.articulated_biases,
            u: &mut self.u,
            u_tau: &mut self.u_tau,
            d_inv: &mut self.d_inv,
            qdd: &mut self.free_acceleration,
        };
        let state = (&self.q[..], &self.v[..], &self.tau[..]);
        articulated_inertia_passes(model, state, None, &mut buffers).map_err(|_| ())?;
        support_acceleration_pass(model, set, &mut buffers);
        let mut terms = AbaTerms {
            x_up: &self.x_up,
            v: &self.velocities,
            c: &self.velocity_products,
            u: &self.u,
            u_tau: &self.u_tau,
            d_inv: &self.d_inv,
            x_world: &mut self.x_world,
            free_acceleration: &self.free_acceleration,
        };
        let mut route_buffers = RouteBuffers {
            jacobian: &mut self.jacobian,
            drift: &mut self.drift,
            error: &mut self.error,
            rhs: &mut self.rhs,
            transmitted_rows: &mut self.transmitted_rows,
            delassus: &mut self.delassus,
            body_forces: &mut self.body_forces,
            body_accelerations: &mut self.body_accelerations,
            joint_forces: &mut self.joint_forces,
            body_rows: &mut self.body_rows,
            forces: &mut self.forces,
            qdd: &mut self.qdd,
        };
        let buffers = &mut route_buffers;
        // J, φ, γ, J a_f + γ;  Y = K Jᵀ and Λ⁻¹
        rows_under_free_motion(model, set, &mut terms, buffers, (&self.q, &self.v));
        articulated_delassus(model, set, &terms, buffers);
        // Λ⁻¹ λ = −(J a_f + γ + K_d J q̇ + K_p φ), or Λ⁻¹ Λ = −(1 + e) J q̇
        let (jacobian, rhs) = (&*buffers.jacobian, &mut buffers.rhs[..m]);
        match route {
            Route::Forward(options) => {
                accelerated_right_side(jacobian, buffers.error, rhs, &self.v, options.baumgarte)
            }
            Route::Impulse { restitution, .. } => {
                impact_right_side(jacobian, rhs, &self.v, restitution)
            }
        }
        let delassus = buffers.delassus.as_slice();
        solve_direct(m, delassus, &mut self.factor, buffers.rhs, buffers.forces).map_err(|_| ())?;
        // q̈ = M⁻¹ (τ − h + Jᵀ λ), or q̇⁺ = q̇ + M⁻¹ Jᵀ Λ
        match route {
            Route::Forward(_) => constrained_accelerations(model, set, &terms, buffers),
            Route::Impulse { .. } => constraint_response(model, set, &terms, buffers, &self.v),
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraint::{Attachment, Constraint, ConstraintKind, ConstraintReference};
    use crate::io::bundled::floating_ur5_state;

    /// The lane kernel itself, compiled without the wide instruction sets, so that it is checked
    /// on a CPU that lacks them too: each lane equals the one-state call bit for bit.
    fn lanes_equal_one_state<S: LaneRows>() {
        let (model, q0, v0, tau0) = floating_ur5_state();
        let frame = |name: &str| model.frame_index(name).expect("a UR5 frame");
        let held = |kind, reference| Constraint { kind, reference };
        let rod = Attachment {
            frame: Some(frame("forearm_link")),
            placement: Transform::from_translation(&crate::spatial::Vec3::new(0.2, 0.0, 0.1)),
        };
        let set = ConstraintSet::new(
            &model,
            vec![
                held(
                    ConstraintKind::Point {
                        first: Attachment::at_frame(frame("tool0")),
                        second: Some(rod),
                    },
                    ConstraintReference::Local,
                ),
                held(
                    ConstraintKind::Frame {
                        first: Attachment::at_frame(frame("base_link")),
                        second: None,
                        mask: [true, true, true, true, false, true],
                    },
                    ConstraintReference::World,
                ),
            ],
        )
        .unwrap();
        let (n, nv) = (2 * S::LANES, model.nv);
        let (mut q, mut v, mut tau) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..n {
            q.extend(q0.iter());
            v.extend(v0.iter().map(|x| x * (1.0 + 0.1 * k as f64)));
            tau.extend(tau0.iter().map(|x| x - 0.3 * k as f64));
        }
        let states = States {
            q: &q,
            v: Some(&v),
            a: None,
            tau: Some(&tau),
        };
        let size = nv + set.rows();
        let options = ConstrainedOptions {
            baumgarte: Some((40.0, 12.0)),
            damping: 0.0,
        };
        let mut lanes = vec![0.0; n * size];
        let mut buffers = ConstrainedLanes::<S>::new(&model, &set);
        let route = Route::Forward(&options);
        constrained_groups(&model, &set, route, &mut buffers, states, &mut lanes).unwrap();
        let mut workspace =
            ConstrainedBatchWorkspace::with_width(&model, &set, LaneWidth::One).unwrap();
        let mut one_by_one = vec![0.0; n * size];
        constrained_forward_dynamics_batch(
            &model,
            &mut workspace,
            &set,
            states,
            &options,
            &mut one_by_one,
        )
        .unwrap();
        let same = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same(&lanes, &one_by_one), "{} lanes", S::LANES);
        // impulses
        let impact = Route::Impulse {
            restitution: 0.5,
            damping: 0.0,
        };
        constrained_groups(&model, &set, impact, &mut buffers, states, &mut lanes).unwrap();
        let at_impact = (0.5, 0.0);
        impulse_dynamics_batch(
            &model,
            &mut workspace,
            &set,
            states,
            at_impact,
            &mut one_by_one,
        )
        .unwrap();
        assert!(same(&lanes, &one_by_one), "{} lanes, impulses", S::LANES);
    }

    #[test]
    fn four_and_eight_lanes_equal_one_state_without_wide_instructions() {
        lanes_equal_one_state::<AutoF64x4>();
        lanes_equal_one_state::<AutoF64x8>();
    }
}
