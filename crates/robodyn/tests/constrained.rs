//! Constrained dynamics: the constrained equations hold (KKT residuals), the results equal a dense
//! KKT solve, the rows equal finite differences of the constraint errors, impulses and inverse
//! dynamics invert as they should, and redundant or malformed constraints are refused by name.

mod common;

use common::constraints::*;
use common::*;
use nalgebra::{DMatrix, DVector};
use robodyn::algo::{
    self, close_constraints, constrained_forward_dynamics, constrained_inverse_dynamics,
    constraint_jacobian, delassus, impulse_dynamics, ClosureOptions, ConstrainedOptions,
    ConstraintData,
};
use robodyn::constraint::{Attachment, ConstraintKind, ConstraintReference, ConstraintSet};
use robodyn::{Data, Model};

/// Central differences of the constraint errors with step `h`: first and second derivatives.
const DIFFERENCE_STEP: f64 = 1e-4;
/// Their truncation error, O(h²) with h = 1e-4, and rounding, ε/h² ≈ 1e-8.
const DIFFERENCE_TOLERANCE: f64 = 1e-6;

/// `[M −Jᵀ; J 0] [q̈; λ] = [τ − h; −γ]`, densely.
fn dense_kkt(
    model: &Model,
    data: &mut Data,
    constraints: &ConstraintData,
    (q, v, tau): (&[f64], &[f64], &[f64]),
) -> (DVector<f64>, DVector<f64>) {
    let (nv, m) = (model.nv, constraints.jacobian.nrows());
    let mass = algo::crba(model, data, q).unwrap().clone();
    let h = algo::bias_forces(model, data, q, v).unwrap().clone();
    let mut kkt = DMatrix::zeros(nv + m, nv + m);
    kkt.view_mut((0, 0), (nv, nv)).copy_from(&mass);
    kkt.view_mut((0, nv), (nv, m))
        .copy_from(&(-constraints.jacobian.transpose()));
    kkt.view_mut((nv, 0), (m, nv))
        .copy_from(&constraints.jacobian);
    let mut rhs = DVector::zeros(nv + m);
    rhs.rows_mut(0, nv)
        .copy_from(&(DVector::from_column_slice(tau) - h));
    rhs.rows_mut(nv, m).copy_from(&(-&constraints.drift));
    let solution = kkt.lu().solve(&rhs).expect("the KKT matrix is regular");
    (
        solution.rows(0, nv).into_owned(),
        solution.rows(nv, m).into_owned(),
    )
}

#[test]
fn forward_dynamics_solves_the_constrained_equations_and_equals_a_dense_kkt_solve() {
    let mut rng = rng();
    for (name, model, constraints) in cases() {
        let set = ConstraintSet::new(&model, constraints).unwrap();
        let (mut data, mut c) = (Data::new(&model), ConstraintData::new(&model, &set));
        for _ in 0..5 {
            let (q, v, tau) = state(&model, &mut rng);
            let options = ConstrainedOptions::default();
            let args = (q.as_slice(), v.as_slice(), tau.as_slice());
            constrained_forward_dynamics(&model, &mut data, &mut c, &set, args, None, &options)
                .unwrap();
            let (qdd, forces) = (c.qdd.clone(), c.forces.clone());
            // M q̈ + h − τ − Jᵀ λ = 0 and J q̈ + γ = 0
            let mass = algo::crba(&model, &mut data, q.as_slice()).unwrap().clone();
            let h = algo::bias_forces(&model, &mut data, q.as_slice(), v.as_slice())
                .unwrap()
                .clone();
            let dynamics = &mass * &qdd + h - &tau - c.jacobian.transpose() * &forces;
            let scale = 1.0 + tau.amax() + forces.amax();
            assert!(
                dynamics.amax() < IDENTITY_TOLERANCE * scale,
                "{name}: {dynamics}"
            );
            let held = &c.jacobian * &qdd + &c.drift;
            assert!(held.amax() < IDENTITY_TOLERANCE * scale, "{name}: {held}");
            // its Delassus matrix, from ABA's terms, is J M⁻¹ Jᵀ
            let inverse = mass.clone().try_inverse().expect("M is regular");
            let expected = &c.jacobian * inverse * c.jacobian.transpose();
            let label = format!("{name}: Delassus");
            let (ours, expected) = (c.delassus.as_slice(), expected.as_slice());
            assert_close(&label, ours, expected, IDENTITY_TOLERANCE);
            let (dense_qdd, dense_forces) = dense_kkt(&model, &mut data, &c, args);
            assert_close(
                name,
                qdd.as_slice(),
                dense_qdd.as_slice(),
                IDENTITY_TOLERANCE,
            );
            assert_close(name, forces.as_slice(), dense_forces.as_slice(), 1e-8);
        }
    }
}

/// The errors φ at q ⊕ t v for t = −h, 0, h.
fn errors_along(
    model: &Model,
    set: &ConstraintSet,
    q: &DVector<f64>,
    v: &DVector<f64>,
) -> [DVector<f64>; 3] {
    let (mut data, mut c) = (Data::new(model), ConstraintData::new(model, set));
    [-DIFFERENCE_STEP, 0.0, DIFFERENCE_STEP].map(|t| {
        let moved = displaced(model, q, &(v * t));
        constraint_jacobian(model, &mut data, &mut c, set, moved.as_slice()).unwrap();
        c.error.clone()
    })
}

#[test]
fn rows_and_drift_are_the_derivatives_of_the_constraint_errors() {
    let mut rng = rng();
    for (name, model, constraints) in cases() {
        // the errors of frame rows (angular) and of rows in local axes are differentiated by
        // the rows only where they hold: those are left to the other tests
        let set = ConstraintSet::new(&model, constraints).unwrap();
        let (mut data, mut c) = (Data::new(&model), ConstraintData::new(&model, &set));
        for _ in 0..3 {
            let (q, v, _) = state(&model, &mut rng);
            let zero = DVector::zeros(model.nv);
            let args = (q.as_slice(), v.as_slice(), zero.as_slice());
            let options = ConstrainedOptions::default();
            constrained_forward_dynamics(&model, &mut data, &mut c, &set, args, None, &options)
                .unwrap();
            let [before, now, after] = errors_along(&model, &set, &q, &v);
            let h = DIFFERENCE_STEP;
            let rate = (&after - &before) / (2.0 * h);
            let curvature = (&after - 2.0 * &now + &before) / (h * h);
            for r in 0..set.rows() {
                let (k, _) = set.row_owner(r);
                let constraint = &set.constraints()[k];
                let point = matches!(constraint.kind, ConstraintKind::Point { .. });
                let frame = matches!(constraint.kind, ConstraintKind::Frame { .. });
                if frame || (point && constraint.reference == ConstraintReference::Local) {
                    continue;
                }
                let jv = c.jacobian.row(r).dot(&v.transpose());
                let label = format!("{name} row {r}");
                assert_close(&label, &[jv], &[rate[r]], DIFFERENCE_TOLERANCE);
                assert_close(
                    &label,
                    &[c.drift[r]],
                    &[curvature[r]],
                    1e3 * DIFFERENCE_TOLERANCE,
                );
            }
        }
    }
}

#[test]
fn baumgarte_terms_set_the_rows_acceleration() {
    let model = test_model("tree");
    let set = ConstraintSet::new(&model, tree_constraints(&model)).unwrap();
    let (mut data, mut c) = (Data::new(&model), ConstraintData::new(&model, &set));
    let (q, v, tau) = state(&model, &mut rng());
    let options = ConstrainedOptions {
        baumgarte: Some((40.0, 12.0)),
        damping: 0.0,
    };
    let args = (q.as_slice(), v.as_slice(), tau.as_slice());
    constrained_forward_dynamics(&model, &mut data, &mut c, &set, args, None, &options).unwrap();
    assert!(c.error.amax() > 1e-3, "the test needs errors to correct");
    // J q̈ + γ = −K_d J q̇ − K_p φ
    let target = -12.0 * (&c.jacobian * &v) - 40.0 * &c.error;
    let reached = &c.jacobian * &c.qdd + &c.drift;
    assert_close(
        "baumgarte",
        reached.as_slice(),
        target.as_slice(),
        IDENTITY_TOLERANCE,
    );
}

#[test]
fn delassus_is_j_m_inverse_j_transpose() {
    let model = test_model("tree");
    let set = ConstraintSet::new(&model, tree_constraints(&model)).unwrap();
    let (mut data, mut c) = (Data::new(&model), ConstraintData::new(&model, &set));
    let q = model.random_configuration(&mut rng());
    let delassus = delassus(&model, &mut data, &mut c, &set, q.as_slice())
        .unwrap()
        .clone();
    let inverse = algo::inverse_mass_matrix(&model, &mut data, q.as_slice())
        .unwrap()
        .clone();
    let expected = &c.jacobian * inverse * c.jacobian.transpose();
    assert_close(
        "delassus",
        delassus.as_slice(),
        expected.as_slice(),
        IDENTITY_TOLERANCE,
    );
}

#[test]
fn impulses_stop_the_constrained_motion_or_reverse_it() {
    let model = test_model("tree");
    let set = ConstraintSet::new(&model, tree_constraints(&model)).unwrap();
    let (mut data, mut c) = (Data::new(&model), ConstraintData::new(&model, &set));
    let (q, v, _) = state(&model, &mut rng());
    for restitution in [0.0, 0.4, 1.0] {
        let args = (q.as_slice(), v.as_slice());
        impulse_dynamics(&model, &mut data, &mut c, &set, args, restitution, 0.0).unwrap();
        // J q̇⁺ = −e J q̇;  M (q̇⁺ − q̇) = Jᵀ Λ
        let after = &c.jacobian * &c.qdd;
        let expected = -restitution * (&c.jacobian * &v);
        assert_close(
            "J v+",
            after.as_slice(),
            expected.as_slice(),
            IDENTITY_TOLERANCE,
        );
        let mass = algo::crba(&model, &mut data, q.as_slice()).unwrap().clone();
        let momentum = mass * (&c.qdd - &v);
        let applied = c.jacobian.transpose() * &c.forces;
        assert_close(
            "M dv",
            momentum.as_slice(),
            applied.as_slice(),
            IDENTITY_TOLERANCE,
        );
    }
}

/// Forward dynamics with the base unactuated (τ zero on its six coordinates) at a random state.
fn base_unactuated_state(
    model: &Model,
    rng: &mut rand::rngs::StdRng,
) -> (DVector<f64>, DVector<f64>, DVector<f64>) {
    let (q, v, mut tau) = state(model, rng);
    tau.rows_mut(0, 6).fill(0.0);
    (q, v, tau)
}

#[test]
fn inverse_dynamics_recovers_the_torques_and_forces_of_forward_dynamics() {
    let model = test_model("tree");
    // the shin's frame held: six rows against the six unactuated base coordinates, unique forces
    let held = constraint(
        ConstraintKind::Frame {
            first: at(&model, "shin", [0.0, 0.0, -0.3]),
            second: None,
            mask: [true; 6],
        },
        ConstraintReference::World,
    );
    let set = ConstraintSet::new(&model, vec![held]).unwrap();
    let (mut data, mut c) = (Data::new(&model), ConstraintData::new(&model, &set));
    let mut rng = rng();
    let actuated: Vec<bool> = (0..model.nv).map(|k| k >= 6).collect();
    for _ in 0..3 {
        let (q, v, tau) = base_unactuated_state(&model, &mut rng);
        let options = ConstrainedOptions::default();
        let args = (q.as_slice(), v.as_slice(), tau.as_slice());
        constrained_forward_dynamics(&model, &mut data, &mut c, &set, args, None, &options)
            .unwrap();
        let (qdd, forces) = (c.qdd.clone(), c.forces.clone());
        let args = (q.as_slice(), v.as_slice(), qdd.as_slice());
        constrained_inverse_dynamics(&model, &mut data, &mut c, &set, args, None, &actuated, None)
            .unwrap();
        assert_close("tau", c.tau.as_slice(), tau.as_slice(), 1e-8);
        assert_close("forces", c.forces.as_slice(), forces.as_slice(), 1e-8);
        // an acceleration the constraints forbid is refused, naming the row
        let wrong = &qdd + DVector::from_element(model.nv, 0.1);
        let args = (q.as_slice(), v.as_slice(), wrong.as_slice());
        let error = constrained_inverse_dynamics(
            &model, &mut data, &mut c, &set, args, None, &actuated, None,
        )
        .unwrap_err()
        .to_string();
        assert!(
            error.contains("breaks the constraints") && error.contains("constraints[0]"),
            "{error}"
        );
    }
}

/// Two points of the tree held, with the base unactuated, and the state (q, q̇, q̈) of forward
/// dynamics there: the base may still turn about the line through the points, and the forces
/// along that line are not unique.
struct TwoPoints {
    set: ConstraintSet,
    data: Data,
    c: ConstraintData,
    actuated: Vec<bool>,
    state: (DVector<f64>, DVector<f64>, DVector<f64>),
}

fn two_points(model: &Model) -> TwoPoints {
    let point = |frame: &str, offset: [f64; 3]| {
        let kind = ConstraintKind::Point {
            first: at(model, frame, offset),
            second: None,
        };
        constraint(kind, ConstraintReference::World)
    };
    let constraints = vec![point("tip", [0.0; 3]), point("shin", [0.0, 0.0, -0.3])];
    let set = ConstraintSet::new(model, constraints).unwrap();
    let (mut data, mut c) = (Data::new(model), ConstraintData::new(model, &set));
    let actuated: Vec<bool> = (0..model.nv).map(|k| k >= 6).collect();
    let (q, v, tau) = base_unactuated_state(model, &mut rng());
    let args = (q.as_slice(), v.as_slice(), tau.as_slice());
    let options = ConstrainedOptions::default();
    constrained_forward_dynamics(model, &mut data, &mut c, &set, args, None, &options).unwrap();
    let qdd = c.qdd.clone();
    TwoPoints {
        set,
        data,
        c,
        actuated,
        state: (q, v, qdd),
    }
}

#[test]
fn inverse_dynamics_gives_the_least_norm_forces_where_they_are_not_unique() {
    let model = test_model("tree");
    let TwoPoints {
        set,
        mut data,
        mut c,
        actuated,
        state: (q, v, qdd),
    } = two_points(&model);
    let args = (q.as_slice(), v.as_slice(), qdd.as_slice());
    constrained_inverse_dynamics(&model, &mut data, &mut c, &set, args, None, &actuated, None)
        .unwrap();
    // M q̈ + h = τ + Jᵀ λ with τ zero on the base
    let mass = algo::crba(&model, &mut data, q.as_slice()).unwrap().clone();
    let h = algo::bias_forces(&model, &mut data, q.as_slice(), v.as_slice())
        .unwrap()
        .clone();
    let residual = &mass * &qdd + h - &c.tau - c.jacobian.transpose() * &c.forces;
    assert!(
        residual.amax() < IDENTITY_TOLERANCE * (1.0 + c.forces.amax()),
        "{residual}"
    );
    assert!(c.tau.rows(0, 6).amax() == 0.0);
    // least norm: λ = J_u y lies in the column space of J_u (the base's columns of J)
    let base_columns = c.jacobian.columns(0, 6).into_owned();
    assert_in_column_space(&base_columns, &c.forces);
}

/// `vector` has no part along the left null space of `matrix` (rank 5: the line through the two
/// points leaves one rotation of the base free).
fn assert_in_column_space(matrix: &DMatrix<f64>, vector: &DVector<f64>) {
    let svd = matrix.clone().svd(true, false);
    let u = svd.u.unwrap();
    let rank = svd.singular_values.iter().filter(|s| **s > 1e-9).count();
    assert_eq!(
        rank, 5,
        "the line through the points leaves one rotation free"
    );
    for k in 0..u.ncols() {
        if svd.singular_values[k] <= 1e-9 {
            let along_null = u.column(k).dot(vector);
            assert!(along_null.abs() < 1e-8 * vector.amax(), "{along_null}");
        }
    }
}

#[test]
fn weighted_inverse_dynamics_gives_the_forces_of_least_weighted_norm() {
    let model = test_model("tree");
    // the two points of the test above, their rows weighted unequally
    let TwoPoints {
        set,
        mut data,
        mut c,
        actuated,
        state: (q, v, qdd),
    } = two_points(&model);
    let args = (q.as_slice(), v.as_slice(), qdd.as_slice());
    constrained_inverse_dynamics(&model, &mut data, &mut c, &set, args, None, &actuated, None)
        .unwrap();
    let plain = c.forces.clone();
    let weights = [1.0, 2.0, 3.0, 10.0, 0.5, 4.0];
    let weighted = Some(&weights[..]);
    constrained_inverse_dynamics(
        &model, &mut data, &mut c, &set, args, None, &actuated, weighted,
    )
    .unwrap();
    // the base's rows hold with either, and W λ lies in the column space of J_u
    let base_columns = c.jacobian.columns(0, 6).into_owned();
    let balance = base_columns.transpose() * (&c.forces - &plain);
    assert!(
        balance.amax() < IDENTITY_TOLERANCE * (1.0 + plain.amax()),
        "{balance}"
    );
    let scaled = DVector::from_iterator(6, c.forces.iter().zip(weights).map(|(f, w)| f * w));
    assert_in_column_space(&base_columns, &scaled);
    assert!((&c.forces - &plain).amax() > 1e-3 * plain.amax());
    // a weight that is not positive is named
    let bad = [1.0, 2.0, 0.0, 1.0, 1.0, 1.0];
    let error = constrained_inverse_dynamics(
        &model,
        &mut data,
        &mut c,
        &set,
        args,
        None,
        &actuated,
        Some(&bad),
    )
    .unwrap_err()
    .to_string();
    assert!(
        error.contains("weights") && error.contains("row 2"),
        "{error}"
    );
}

#[test]
fn a_closure_stated_twice_is_named_without_damping_and_shared_with_it() {
    let model = test_model("tree");
    let loop_closure = tree_constraints(&model).swap_remove(2);
    let set = ConstraintSet::new(&model, vec![loop_closure.clone(), loop_closure]).unwrap();
    let (mut data, mut c) = (Data::new(&model), ConstraintData::new(&model, &set));
    let (q, v, tau) = state(&model, &mut rng());
    let args = (q.as_slice(), v.as_slice(), tau.as_slice());
    let rigid = ConstrainedOptions::default();
    let error = constrained_forward_dynamics(&model, &mut data, &mut c, &set, args, None, &rigid)
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("constraints[1] (PointAnchor('forearm' to 'thigh')), row x")
            && error.contains("damping"),
        "{error}"
    );
    let damped = ConstrainedOptions {
        baumgarte: None,
        damping: 1e-6,
    };
    constrained_forward_dynamics(&model, &mut data, &mut c, &set, args, None, &damped).unwrap();
    assert!(c.iterations > 0);
    // each statement carries half of the single closure's force
    let single = ConstraintSet::new(&model, vec![set.constraints()[0].clone()]).unwrap();
    let mut one = ConstraintData::new(&model, &single);
    constrained_forward_dynamics(&model, &mut data, &mut one, &single, args, None, &rigid).unwrap();
    let halves: Vec<f64> = one.forces.iter().map(|f| f / 2.0).collect();
    assert_close("first", &c.forces.as_slice()[..3], &halves, 1e-8);
    assert_close("second", &c.forces.as_slice()[3..], &halves, 1e-8);
    assert_close("qdd", c.qdd.as_slice(), one.qdd.as_slice(), 1e-8);
}

#[test]
fn malformed_constraints_are_refused_by_name() {
    let model = test_model("tree");
    let coupled = |follower: &str, leader: &str| {
        let kind = ConstraintKind::Coupling {
            follower: body_of(&model, follower),
            leader: Some(body_of(&model, leader)),
            polynomial: [0.0, 1.0, 0.0, 0.0, 0.0],
            references: (0.0, 0.0),
        };
        ConstraintSet::new(&model, vec![constraint(kind, ConstraintReference::World)])
    };
    // a revolute joint may drive a prismatic one (a rack and pinion); a spherical one neither
    // follows nor leads
    assert!(coupled("slide", "elbow").is_ok());
    let error = coupled("ball", "elbow").unwrap_err().to_string();
    assert!(error.contains("'ball' (spherical)"), "{error}");
    let error = coupled("elbow", "ball").unwrap_err().to_string();
    assert!(
        error.contains("led by a revolute or prismatic joint, got 'ball' (spherical)"),
        "{error}"
    );
    let error = coupled("knee", "knee").unwrap_err().to_string();
    assert!(error.contains("coupled to itself"), "{error}");
    assert!(coupled("knee", "leg").is_ok());
    let frame = ConstraintKind::Frame {
        first: at(&model, "tip", [0.0; 3]),
        second: None,
        mask: [false; 6],
    };
    let error = ConstraintSet::new(&model, vec![constraint(frame, ConstraintReference::World)])
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("constraints[0]") && error.contains("mask"),
        "{error}"
    );
    let distance = ConstraintKind::Distance {
        first: at(&model, "tip", [0.0; 3]),
        second: at(&model, "base", [0.0; 3]),
        length: -1.0,
    };
    let error = ConstraintSet::new(
        &model,
        vec![constraint(distance, ConstraintReference::World)],
    )
    .unwrap_err()
    .to_string();
    assert!(error.contains("positive finite length"), "{error}");
}

/// A planar four-bar: crank (0.2 m), coupler (0.6 m) and rocker (0.5 m) turning about y from a
/// fixed base, the rocker's tip held to the ground pivot 0.6 m from the crank's.
/// How far the simulated loop may come apart over 10 s at dt = 1e-3 with RK4 (m).
const LOOP_DRIFT: f64 = 1e-8;

#[test]
fn a_simulated_four_bar_stays_closed_and_keeps_its_energy() {
    use robodyn::integrate::{
        simulate_with, Constrained, ControlLaw, Integrator, NativeController, SimulationOptions,
    };
    let (model, set, q0) = four_bar();
    let v0 = DVector::zeros(model.nv);
    let options = SimulationOptions::new(Integrator::Rk4, 1e-3, 10.0);
    let law = ControlLaw::Constant(DVector::zeros(model.nv));
    let mut controller = NativeController::new(&model, law, options.passive, 10.0).unwrap();
    let forward = Constrained::new(&model, set.clone(), ConstrainedOptions::default());
    let trajectory = simulate_with(
        &model,
        q0.as_slice(),
        v0.as_slice(),
        &options,
        forward,
        &mut controller,
        None,
        None,
    )
    .unwrap();
    let (mut data, mut c) = (Data::new(&model), ConstraintData::new(&model, &set));
    let energy = |data: &mut Data, q: &[f64], v: &[f64]| {
        algo::kinetic_energy(&model, data, q, v).unwrap()
            + algo::potential_energy(&model, data, q).unwrap()
    };
    let start = energy(&mut data, q0.as_slice(), v0.as_slice());
    let (mut drift, mut energy_change, mut travel) = (0.0f64, 0.0f64, 0.0f64);
    let nv = model.nv;
    for (q, v) in trajectory.q.chunks(nv).zip(trajectory.v.chunks(nv)) {
        constraint_jacobian(&model, &mut data, &mut c, &set, q).unwrap();
        drift = drift.max(c.error.amax());
        energy_change = energy_change.max((energy(&mut data, q, v) - start).abs());
        travel = travel.max((q[0] - q0[0]).abs());
    }
    assert!(
        travel > 0.3,
        "the linkage swings: the crank turns {travel} rad"
    );
    assert!(drift < LOOP_DRIFT, "the loop came {drift:e} m apart");
    assert!(
        energy_change < 1e-7,
        "energy changed by {energy_change:e} J"
    );
}

#[test]
fn a_closed_weld_has_a_finite_zero_error() {
    // rounding can put the trace of R₂ᵀR₁ of coinciding frames above 3: the error stays finite
    let model = test_model("ur5");
    let tool = model.frame_index("tool0").unwrap();
    let mut data = Data::new(&model);
    let mut rng = rng();
    for _ in 0..200 {
        let q = model.random_configuration(&mut rng);
        algo::forward_kinematics(&model, &mut data, q.as_slice()).unwrap();
        let weld = ConstraintKind::Frame {
            first: Attachment::at_frame(tool),
            second: Some(Attachment {
                frame: None,
                placement: algo::frame_placement(&model, &data, tool),
            }),
            mask: [true; 6],
        };
        let set =
            ConstraintSet::new(&model, vec![constraint(weld, ConstraintReference::World)]).unwrap();
        let mut c = ConstraintData::new(&model, &set);
        constraint_jacobian(&model, &mut data, &mut c, &set, q.as_slice()).unwrap();
        assert!(c.error.amax() < IDENTITY_TOLERANCE, "{}", c.error);
    }
}

/// How closely [`close_constraints`] closes a loop by default (m): its tolerance.
const CLOSED: f64 = 1e-12;

#[test]
fn closing_constraints_brings_an_opened_loop_back_onto_them() {
    let (model, set, closed) = four_bar();
    let (mut data, mut c) = (Data::new(&model), ConstraintData::new(&model, &set));
    let options = ClosureOptions::default();
    let mut q = DVector::zeros(model.nq);
    // opened by a few degrees at each joint: Gauss–Newton's quadratic convergence
    let opened = &closed + DVector::from_vec(vec![0.05, -0.03, 0.04]);
    let closure = close_constraints(
        &model,
        &mut data,
        &mut c,
        &set,
        opened.as_slice(),
        q.as_mut_slice(),
        &options,
    )
    .unwrap();
    assert!(closure.success && closure.iterations <= 6, "{closure:?}");
    constraint_jacobian(&model, &mut data, &mut c, &set, q.as_slice()).unwrap();
    assert!(c.error.amax() <= CLOSED && closure.residual == c.error.amax());
    // the correction is (to first order) across the loop's motion, not along it: its part along
    // the null space of J is of second order in the opening
    let correction = &q - &opened;
    // (three joints, two rows: the null space is the cross product of the rows)
    let row = |r: usize| nalgebra::Vector3::from_iterator(c.jacobian.row(r).iter().copied());
    let along = row(0).cross(&row(1)).normalize();
    let correction = nalgebra::Vector3::from_iterator(correction.iter().copied());
    assert!(
        along.dot(&correction).abs() < 0.1 * correction.norm(),
        "{correction}"
    );
    // a closed configuration is left as it is
    let again = close_constraints(
        &model,
        &mut data,
        &mut c,
        &set,
        closed.as_slice(),
        q.as_mut_slice(),
        &options,
    )
    .unwrap();
    assert_eq!((again.iterations, q.as_slice()), (0, closed.as_slice()));
    // the closure stated twice (dependent rows) closes as well
    let twice =
        ConstraintSet::new(&model, [set.constraints(), set.constraints()].concat()).unwrap();
    let mut c2 = ConstraintData::new(&model, &twice);
    let closure = close_constraints(
        &model,
        &mut data,
        &mut c2,
        &twice,
        opened.as_slice(),
        q.as_mut_slice(),
        &options,
    )
    .unwrap();
    assert!(closure.success && closure.residual <= CLOSED, "{closure:?}");
}

#[test]
fn constraints_that_cannot_hold_are_reported_not_closed() {
    let (model, set, closed) = four_bar();
    // the tip held at the pivot and 10 m away from it
    let far = Attachment {
        frame: None,
        placement: robodyn::spatial::Transform::from_translation(&robodyn::spatial::Vec3::new(
            10.0, 0.0, 0.0,
        )),
    };
    let mut both = set.constraints().to_vec();
    let mut away = both[0].clone();
    if let ConstraintKind::Frame { second, .. } = &mut away.kind {
        *second = Some(far);
    }
    both.push(away);
    let impossible = ConstraintSet::new(&model, both).unwrap();
    let (mut data, mut c) = (Data::new(&model), ConstraintData::new(&model, &impossible));
    let options = ClosureOptions {
        max_iterations: 20,
        ..ClosureOptions::default()
    };
    let mut q = DVector::zeros(model.nq);
    let mut close = |options: &ClosureOptions| {
        let start = closed.as_slice();
        close_constraints(
            &model,
            &mut data,
            &mut c,
            &impossible,
            start,
            q.as_mut_slice(),
            options,
        )
    };
    let closure = close(&options).unwrap();
    assert!(
        !closure.success && closure.iterations == 20 && closure.residual > 1.0,
        "{closure:?}"
    );
    for bad in [
        ClosureOptions {
            tolerance: 0.0,
            ..options
        },
        ClosureOptions {
            damping: f64::NAN,
            ..options
        },
    ] {
        let error = close(&bad).unwrap_err();
        assert!(
            error.to_string().contains("expected a finite value > 0"),
            "{error}"
        );
    }
}
