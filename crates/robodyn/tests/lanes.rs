//! Batches in lanes (`algo::lanes`) against the one-state calls: every width, every test model,
//! inverse dynamics, bias forces and gravity, bit for bit.

mod common;

use common::*;
use robodyn::algo::{
    bias_forces, generalized_gravity, newton_euler_batch, rnea, BatchWorkspace, LaneWidth, States,
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
    match (states.v.map(row), states.a.map(row)) {
        (Some(v), Some(a)) => rnea(model, data, q, &v, &a, None),
        (Some(v), None) => bias_forces(model, data, q, &v),
        (None, None) => generalized_gravity(model, data, q),
        (None, Some(_)) => unreachable!("no acceleration without a velocity here"),
    }
    .unwrap()
    .as_slice()
    .to_vec()
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
            },
            States {
                q: &q,
                v: Some(&v),
                a: None,
            },
            States {
                q: &q,
                v: None,
                a: None,
            },
        ] {
            for width in LaneWidth::ALL {
                let Ok(mut workspace) = BatchWorkspace::with_width(&model, width) else {
                    assert!(!width.available(), "{width:?} is available but refused");
                    continue;
                };
                exercised += 1;
                let mut tau = vec![f64::NAN; STATES * model.nv];
                newton_euler_batch(&model, &mut workspace, states, &mut tau).unwrap();
                for (k, row) in tau.chunks(model.nv).enumerate() {
                    let expected = one_state(&model, &mut data, &states, k);
                    let same = row
                        .iter()
                        .zip(&expected)
                        .all(|(x, y)| x.to_bits() == y.to_bits());
                    assert!(
                        same,
                        "{name}, {width:?}, state {k}: {row:?} != {expected:?}"
                    );
                }
            }
        }
    }
    // the one-state width runs everywhere
    assert!(exercised >= 3 * test_models().len());
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
        };
        let result = newton_euler_batch(&model, &mut workspace, states, &mut tau);
        assert!(matches!(result, Err((5, _))), "{name}: {result:?}");
        // a q of the wrong length names no state
        let states = States {
            q: &q[1..],
            v: Some(&v),
            a: Some(&a),
        };
        let result = newton_euler_batch(&model, &mut workspace, states, &mut tau);
        assert!(
            matches!(result, Err((0, Error::Shape { .. }))),
            "{name}: {result:?}"
        );
    }
}
