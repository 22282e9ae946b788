//! Constrained forward dynamics and impulses of a batch: in lanes at every width this CPU has,
//! each state's result equals the one-state call's bit for bit (the lanes perform its
//! operations); groups the lanes cannot share (dependent rows, damping) run one state at a time
//! and say so.

mod common;

use common::constraints::*;
use common::*;
use robodyn::algo::{
    constrained_forward_dynamics, constrained_forward_dynamics_batch, impulse_dynamics,
    impulse_dynamics_batch, ConstrainedBatchWorkspace, ConstrainedOptions, ConstraintData,
    LaneWidth, States,
};
use robodyn::constraint::ConstraintSet;
use robodyn::{Data, Model};

/// States enough for two groups of the widest lanes and three left over.
const STATES: usize = 19;

/// `STATES` random states, each row-major: q, v, τ.
fn batch(model: &Model) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let (mut q, mut v, mut tau) = (Vec::new(), Vec::new(), Vec::new());
    let mut rng = rng();
    for _ in 0..STATES {
        let (q_k, v_k, tau_k) = state(model, &mut rng);
        q.extend(q_k.iter());
        v.extend(v_k.iter());
        tau.extend(tau_k.iter());
    }
    (q, v, tau)
}

/// The batch's states as the batch call takes them.
fn states<'a>(q: &'a [f64], v: &'a [f64], tau: &'a [f64]) -> States<'a> {
    States {
        q,
        v: Some(v),
        a: None,
        tau: Some(tau),
    }
}

/// Each state's one-state call, rows of q̈ then λ.
fn one_by_one(
    model: &Model,
    set: &ConstraintSet,
    (q, v, tau): (&[f64], &[f64], &[f64]),
    options: &ConstrainedOptions,
) -> Vec<f64> {
    let (mut data, mut c) = (Data::new(model), ConstraintData::new(model, set));
    let (nq, nv) = (model.nq, model.nv);
    let mut out = Vec::new();
    for k in 0..STATES {
        let state = (
            &q[k * nq..(k + 1) * nq],
            &v[k * nv..(k + 1) * nv],
            &tau[k * nv..(k + 1) * nv],
        );
        constrained_forward_dynamics(model, &mut data, &mut c, set, state, None, options).unwrap();
        out.extend(c.qdd.iter().chain(c.forces.iter()));
    }
    out
}

/// Each state's one-state impulses, rows of q̇ after then the impulses.
fn impulses_one_by_one(
    model: &Model,
    set: &ConstraintSet,
    (q, v): (&[f64], &[f64]),
    restitution: f64,
) -> Vec<f64> {
    let (mut data, mut c) = (Data::new(model), ConstraintData::new(model, set));
    let (nq, nv) = (model.nq, model.nv);
    let mut out = Vec::new();
    for k in 0..STATES {
        let state = (&q[k * nq..(k + 1) * nq], &v[k * nv..(k + 1) * nv]);
        impulse_dynamics(model, &mut data, &mut c, set, state, restitution, 0.0).unwrap();
        out.extend(c.qdd.iter().chain(c.forces.iter()));
    }
    out
}

/// Whether two results are equal bit for bit.
fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

fn available_widths() -> Vec<LaneWidth> {
    LaneWidth::ALL
        .into_iter()
        .filter(|w| w.available())
        .collect()
}

#[test]
fn each_lane_equals_the_one_state_call_bit_for_bit() {
    let baumgarte = ConstrainedOptions {
        baumgarte: Some((40.0, 12.0)),
        damping: 0.0,
    };
    for (name, model, constraints) in cases() {
        let set = ConstraintSet::new(&model, constraints).unwrap();
        let (q, v, tau) = batch(&model);
        let states = states(&q, &v, &tau);
        for options in [ConstrainedOptions::default(), baumgarte] {
            let expected = one_by_one(&model, &set, (&q, &v, &tau), &options);
            for width in available_widths() {
                let mut workspace =
                    ConstrainedBatchWorkspace::with_width(&model, &set, width).unwrap();
                let mut out = vec![f64::NAN; expected.len()];
                constrained_forward_dynamics_batch(
                    &model,
                    &mut workspace,
                    &set,
                    states,
                    &options,
                    &mut out,
                )
                .unwrap();
                let grouped = match width {
                    LaneWidth::One => 0,
                    width => STATES - STATES % width.states(),
                };
                assert_eq!(workspace.states_in_lanes(), grouped, "{name}, {width:?}");
                assert!(same_bits(&out, &expected), "{name}, {width:?}, {options:?}");
            }
        }
        // impulses: q and v only
        let restitution = 0.5;
        let expected = impulses_one_by_one(&model, &set, (&q, &v), restitution);
        let at_impact = States {
            tau: None,
            ..states
        };
        for width in available_widths() {
            let mut workspace = ConstrainedBatchWorkspace::with_width(&model, &set, width).unwrap();
            let mut out = vec![f64::NAN; expected.len()];
            let impact = (restitution, 0.0);
            impulse_dynamics_batch(&model, &mut workspace, &set, at_impact, impact, &mut out)
                .unwrap();
            assert!(same_bits(&out, &expected), "{name}, {width:?}, impulses");
        }
    }
}

#[test]
fn damping_and_dependent_rows_run_one_state_at_a_time() {
    let model = test_model("tree");
    let loop_closure = tree_constraints(&model).swap_remove(2);
    let set = ConstraintSet::new(&model, vec![loop_closure.clone(), loop_closure]).unwrap();
    let (q, v, tau) = batch(&model);
    let states = states(&q, &v, &tau);
    let size = model.nv + set.rows();
    for width in available_widths() {
        let mut workspace = ConstrainedBatchWorkspace::with_width(&model, &set, width).unwrap();
        let mut out = vec![0.0; STATES * size];
        // rigid: the one-state call names the dependent row of the first state
        let rigid = ConstrainedOptions::default();
        let (k, error) = constrained_forward_dynamics_batch(
            &model,
            &mut workspace,
            &set,
            states,
            &rigid,
            &mut out,
        )
        .unwrap_err();
        assert_eq!(k, 0);
        assert!(error.to_string().contains("row x"), "{error}");
        // damped: every state by the proximal iterations, as one-state calls
        let damped = ConstrainedOptions {
            baumgarte: None,
            damping: 1e-6,
        };
        constrained_forward_dynamics_batch(&model, &mut workspace, &set, states, &damped, &mut out)
            .unwrap();
        assert_eq!(workspace.states_in_lanes(), 0);
        assert_eq!(
            out,
            one_by_one(&model, &set, (&q, &v, &tau), &damped),
            "{width:?}"
        );
    }
}

#[test]
fn a_workspace_for_another_set_or_a_missing_input_is_refused() {
    let model = test_model("tree");
    let set = ConstraintSet::new(&model, tree_constraints(&model)).unwrap();
    let smaller =
        ConstraintSet::new(&model, vec![tree_constraints(&model).swap_remove(0)]).unwrap();
    let (q, v, tau) = batch(&model);
    let mut out = vec![0.0; STATES * (model.nv + set.rows())];
    let options = ConstrainedOptions::default();
    let mut workspace = ConstrainedBatchWorkspace::new(&model, &smaller);
    let full = states(&q, &v, &tau);
    let (_, error) =
        constrained_forward_dynamics_batch(&model, &mut workspace, &set, full, &options, &mut out)
            .unwrap_err();
    assert!(error.to_string().contains("workspace"), "{error}");
    let mut workspace = ConstrainedBatchWorkspace::new(&model, &set);
    let without_tau = States { tau: None, ..full };
    let (_, error) = constrained_forward_dynamics_batch(
        &model,
        &mut workspace,
        &set,
        without_tau,
        &options,
        &mut out,
    )
    .unwrap_err();
    assert!(error.to_string().contains("tau"), "{error}");
}

#[test]
fn an_empty_set_gives_the_free_dynamics() {
    let model = test_model("tree");
    let set = ConstraintSet::new(&model, Vec::new()).unwrap();
    let (q, v, tau) = batch(&model);
    let options = ConstrainedOptions {
        baumgarte: Some((40.0, 12.0)),
        damping: 0.0,
    };
    let expected = one_by_one(&model, &set, (&q, &v, &tau), &options);
    let mut data = Data::new(&model);
    let nv = model.nv;
    for (k, qdd) in expected.chunks_exact(nv).enumerate() {
        let (q, v, tau) = (
            &q[k * model.nq..(k + 1) * model.nq],
            &v[k * nv..(k + 1) * nv],
            &tau[k * nv..(k + 1) * nv],
        );
        let free = robodyn::algo::aba(&model, &mut data, q, v, tau, None).unwrap();
        assert_eq!(qdd, free.as_slice(), "state {k}");
    }
    for width in available_widths() {
        let mut workspace = ConstrainedBatchWorkspace::with_width(&model, &set, width).unwrap();
        let mut out = vec![f64::NAN; expected.len()];
        let states = states(&q, &v, &tau);
        constrained_forward_dynamics_batch(
            &model,
            &mut workspace,
            &set,
            states,
            &options,
            &mut out,
        )
        .unwrap();
        assert_eq!(out, expected, "{width:?}");
    }
}
