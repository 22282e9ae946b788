//! Batches in lanes (`algo::lanes`) against the one-state calls: every width, every test model,
//! inverse dynamics, bias forces, gravity, forward dynamics, the mass matrix and the derivatives
//! of inverse and forward dynamics, bit for bit.

mod common;

use common::*;
use robodyn::algo::{
    aba, aba_batch, aba_derivatives, aba_derivatives_batch, bias_forces, crba, crba_batch,
    generalized_gravity, newton_euler_batch, rnea, rnea_derivatives, rnea_derivatives_batch,
    BatchWorkspace, DerivativesInto, DynamicsState, LaneWidth, States,
};
use robodyn::{Data, Error, Model};

/// More states than two groups of the widest width, and a remainder for each width.
const STATES: usize = 21;

/// `STATES` random states of `model`, row-major.
fn batch(model: &Model) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut rng = rng();
    let (mut q, mut v, mut a) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..STATES {
        let (q_k, v_k, a_k) = state(model, &mut rng);
        q.extend(q_k.iter());
        v.extend(v_k.iter());
        a.extend(a_k.iter());
    }
    (q, v, a)
}

/// The one-state result for state k.
fn one_state(model: &Model, data: &mut Data, states: &States, k: usize) -> Vec<f64> {
    let (nq, nv) = (model.nq, model.nv);
    let q = &states.q[k * nq..(k + 1) * nq];
    let row = |x: &[f64]| x[k * nv..(k + 1) * nv].to_vec();
    match (states.v.map(row), states.a.map(row), states.tau.map(row)) {
        (Some(v), None, Some(tau)) => aba(model, data, q, &v, &tau, None),
        (Some(v), Some(a), None) => rnea(model, data, q, &v, &a, None),
        (Some(v), None, None) => bias_forces(model, data, q, &v),
        (None, None, None) => generalized_gravity(model, data, q),
        _ => unreachable!("not a combination these tests make"),
    }
    .unwrap()
    .as_slice()
    .to_vec()
}

/// A workspace at `width`, or `None` where this CPU lacks it.
fn workspace_at(model: &Model, width: LaneWidth) -> Option<BatchWorkspace> {
    let workspace = BatchWorkspace::with_width(model, width);
    assert!(
        workspace.is_ok() || !width.available(),
        "{width:?} is available but refused"
    );
    workspace.ok()
}

/// The batch of `states` at `width`, or `None` where this CPU lacks the width.
fn batch_at(model: &Model, width: LaneWidth, states: States) -> Option<Vec<f64>> {
    let mut workspace = workspace_at(model, width)?;
    let mut out = vec![f64::NAN; STATES * model.nv];
    match states.tau {
        Some(_) => aba_batch(model, &mut workspace, states, &mut out),
        None => newton_euler_batch(model, &mut workspace, states, &mut out),
    }
    .unwrap();
    assert_groups_ran_in_lanes(&workspace, width.states(), &format!("{width:?}"));
    Some(out)
}

/// The same numbers, bit for bit (signed zeros and NaN payloads included).
fn bit_equal(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// The last batch ran its full groups of `group` states in lanes (none for a group of one).
fn assert_groups_ran_in_lanes(workspace: &BatchWorkspace, group: usize, name: &str) {
    let expected = if group > 1 {
        STATES - STATES % group
    } else {
        0
    };
    assert_eq!(
        workspace.states_in_lanes(),
        expected,
        "{name}, groups of {group}"
    );
}

#[test]
fn every_lane_width_equals_the_one_state_call_bit_for_bit() {
    let mut exercised = 0;
    for (name, model) in test_models() {
        let (q, v, a) = batch(&model);
        let mut data = Data::new(&model);
        for states in [
            States {
                q: &q,
                v: Some(&v),
                a: Some(&a),
                tau: None,
            },
            States {
                q: &q,
                v: Some(&v),
                ..States::default()
            },
            States {
                q: &q,
                ..States::default()
            },
            States {
                q: &q,
                v: Some(&v),
                a: None,
                tau: Some(&a),
            },
        ] {
            for width in LaneWidth::ALL {
                let Some(out) = batch_at(&model, width, states) else {
                    continue;
                };
                exercised += 1;
                for (k, row) in out.chunks(model.nv).enumerate() {
                    let expected = one_state(&model, &mut data, &states, k);
                    let same = bit_equal(row, &expected);
                    assert!(
                        same,
                        "{name}, {width:?}, state {k}: {row:?} != {expected:?}"
                    );
                }
            }
        }
    }
    // the one-state width runs everywhere, on each of the four kinds of state
    assert!(exercised >= 4 * test_models().len());
}

#[test]
fn the_default_width_is_the_widest_this_cpu_runs() {
    let model = &test_models()[0].1;
    let width = BatchWorkspace::new(model).width();
    assert!(width.available());
    for wider in LaneWidth::ALL
        .iter()
        .filter(|w| w.states() > width.states())
    {
        assert!(
            !wider.available(),
            "{wider:?} is available but {width:?} was chosen"
        );
    }
}

#[test]
fn a_bad_state_is_named_by_its_index() {
    for (name, model) in test_models() {
        let (mut q, mut v, a) = batch(&model);
        let mut workspace = BatchWorkspace::new(&model);
        let mut tau = vec![0.0; STATES * model.nv];
        v[13 * model.nv + model.nv - 1] = f64::NAN;
        let states = States {
            q: &q,
            v: Some(&v),
            a: Some(&a),
            tau: None,
        };
        match newton_euler_batch(&model, &mut workspace, states, &mut tau) {
            Err((13, Error::NotFinite { argument, .. })) => assert_eq!(argument, "v", "{name}"),
            other => panic!("{name}: expected state 13's v to be refused, got {other:?}"),
        }
        v[13 * model.nv + model.nv - 1] = 0.0;
        q[5 * model.nq] = f64::INFINITY;
        let states = States {
            q: &q,
            v: Some(&v),
            a: Some(&a),
            tau: None,
        };
        let result = newton_euler_batch(&model, &mut workspace, states, &mut tau);
        assert!(matches!(result, Err((5, _))), "{name}: {result:?}");
        // a q of the wrong length names no state
        let states = States {
            q: &q[1..],
            v: Some(&v),
            a: Some(&a),
            tau: None,
        };
        let result = newton_euler_batch(&model, &mut workspace, states, &mut tau);
        assert!(
            matches!(result, Err((0, Error::Shape { .. }))),
            "{name}: {result:?}"
        );
    }
}

#[test]
fn a_singular_state_in_a_group_is_named_by_its_index() {
    // the floating UR5's base link is massless: forward dynamics is singular at every state, so
    // the group in lanes fails and the first state is named, as a one-state call would name it
    let model = robodyn::io::bundled_model("ur5", true).unwrap();
    let (q, v, a) = batch(&model);
    let mut workspace = BatchWorkspace::new(&model);
    let mut out = vec![0.0; STATES * model.nv];
    let states = States {
        q: &q,
        v: Some(&v),
        a: None,
        tau: Some(&a),
    };
    match aba_batch(&model, &mut workspace, states, &mut out) {
        Err((0, Error::InvalidValue { message, .. })) => assert!(message.contains("singular")),
        other => panic!("expected state 0 to be singular, got {other:?}"),
    }
    // and so is its mass matrix, which the forward-dynamics derivatives factor
    let mut stacked = vec![0.0; STATES * 3 * model.nv * model.nv];
    match aba_derivatives_batch(&model, &mut workspace, states, &mut stacked) {
        Err((0, Error::InvalidValue { message, .. })) => assert!(message.contains("singular")),
        other => panic!("expected state 0 to be singular, got {other:?}"),
    }
    let states = States {
        q: &q,
        v: Some(&v),
        ..States::default()
    };
    let result = aba_batch(&model, &mut workspace, states, &mut out);
    assert!(
        matches!(result, Err((0, Error::InvalidValue { .. }))),
        "{result:?}"
    );
}

#[test]
fn mass_matrices_in_lanes_equal_crba_bit_for_bit() {
    // each model in both of CRBA's forms
    let models = test_models().into_iter().flat_map(|(name, model)| {
        let world_form = not_depth_first(&model);
        [(name, model), (name, world_form)]
    });
    for (name, model) in models {
        let (q, _, _) = batch(&model);
        let mut data = Data::new(&model);
        let size = model.nv * model.nv;
        for width in LaneWidth::ALL {
            let Some(mut workspace) = workspace_at(&model, width) else {
                continue;
            };
            let mut out = vec![f64::NAN; STATES * size];
            crba_batch(&model, &mut workspace, &q, &mut out).unwrap();
            assert_groups_ran_in_lanes(&workspace, width.states(), name);
            for (k, m) in out.chunks(size).enumerate() {
                let expected = crba(&model, &mut data, &q[k * model.nq..(k + 1) * model.nq]);
                let same = bit_equal(m, expected.unwrap().as_slice());
                assert!(same, "{name}, {width:?}, state {k}");
            }
        }
    }
}

/// A derivatives batch function, and the one-state function whose results it must equal.
type BatchOf = fn(&Model, &mut BatchWorkspace, States, &mut [f64]) -> robodyn::algo::BatchResult;
type OneOf = fn(&Model, &mut Data, DynamicsState, &mut [f64]) -> robodyn::Result<()>;

/// One state's RNEA derivatives, stacked as a batch stores them.
fn rnea_derivatives_stacked(
    model: &Model,
    data: &mut Data,
    (q, v, a, f_ext): DynamicsState,
    out: &mut [f64],
) -> robodyn::Result<()> {
    rnea_derivatives(model, data, q, v, a, f_ext, DerivativesInto::Stacked(out))
}

/// One state's ABA derivatives, stacked as a batch stores them.
fn aba_derivatives_stacked(
    model: &Model,
    data: &mut Data,
    (q, v, tau, f_ext): DynamicsState,
    out: &mut [f64],
) -> robodyn::Result<()> {
    aba_derivatives(model, data, q, v, tau, f_ext, DerivativesInto::Stacked(out))
}

/// `batch` at every width on every test model against `one` state by state, the third input
/// given as a (RNEA) or τ (ABA).
fn derivatives_equal_one_state(batch_of: BatchOf, one: OneOf, third_is_tau: bool) {
    for (name, model) in test_models() {
        let (q, v, x) = batch(&model);
        let mut data = Data::new(&model);
        let size = 3 * model.nv * model.nv;
        let states = States {
            q: &q,
            v: Some(&v),
            a: Some(&x).filter(|_| !third_is_tau).map(|x| &x[..]),
            tau: Some(&x).filter(|_| third_is_tau).map(|x| &x[..]),
        };
        for width in LaneWidth::ALL {
            let Ok(mut workspace) = BatchWorkspace::with_width(&model, width) else {
                continue;
            };
            let mut out = vec![f64::NAN; STATES * size];
            batch_of(&model, &mut workspace, states, &mut out).unwrap();
            assert_groups_ran_in_lanes(&workspace, width.states(), name);
            let mut expected = vec![0.0; size];
            for (k, stacked) in out.chunks(size).enumerate() {
                let (nq, nv) = (model.nq, model.nv);
                let row = |x: &[f64]| x[k * nv..(k + 1) * nv].to_vec();
                let state = (&q[k * nq..(k + 1) * nq], &row(&v)[..], &row(&x)[..], None);
                one(&model, &mut data, state, &mut expected).unwrap();
                let same = bit_equal(stacked, &expected);
                assert!(same, "{name}, {width:?}, state {k}");
            }
        }
    }
}

#[test]
fn inverse_dynamics_derivatives_in_lanes_equal_the_one_state_call_bit_for_bit() {
    derivatives_equal_one_state(rnea_derivatives_batch, rnea_derivatives_stacked, false);
}

#[test]
fn forward_dynamics_derivatives_in_lanes_equal_the_one_state_call_bit_for_bit() {
    derivatives_equal_one_state(aba_derivatives_batch, aba_derivatives_stacked, true);
}
