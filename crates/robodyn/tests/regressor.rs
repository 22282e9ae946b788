//! The joint-torque regressor and the inertial parameters: τ = Y(q, q̇, q̈) π is inverse dynamics,
//! and new parameters change every algorithm consistently.

mod common;

use common::*;
use nalgebra::DVector;
use rand::Rng;
use robodyn::algo::*;
use robodyn::model::{check_physical_parameters, Unphysical};
use robodyn::Data;

/// τ = Y π against RNEA: the same sums in another order.
const REGRESSOR_TOLERANCE: f64 = 1e-12;

#[test]
fn regressor_times_parameters_is_inverse_dynamics() {
    let mut rng = rng();
    for (name, mut model) in test_models() {
        // armature is not a body's parameter: τ = Y π + armature terms
        model.armature.fill(0.0);
        let mut data = Data::new(&model);
        let pi = DVector::from_iterator(
            10 * (model.nbodies() - 1),
            model.inertial_parameters().into_iter().flatten(),
        );
        for _ in 0..3 {
            let (q, v, a) = state(&model, &mut rng);
            let (q, v, a) = (q.as_slice(), v.as_slice(), a.as_slice());
            let y = torque_regressor(&model, &mut data, q, v, a)
                .unwrap()
                .clone();
            let tau = rnea(&model, &mut data, q, v, a, None).unwrap().clone();
            assert_close(
                &format!("{name}: Y π"),
                (y * &pi).as_slice(),
                tau.as_slice(),
                REGRESSOR_TOLERANCE,
            );
        }
    }
}

#[test]
fn new_parameters_change_every_algorithm_consistently() {
    let mut rng = rng();
    for (name, mut model) in test_models() {
        let mut data = Data::new(&model);
        let (q, v, a) = state(&model, &mut rng);
        let (q, v, a) = (q.as_slice(), v.as_slice(), a.as_slice());
        let y = torque_regressor(&model, &mut data, q, v, a)
            .unwrap()
            .clone();
        // each body twice as heavy, its centre of mass and inertia scaled with it
        let doubled: Vec<[f64; 10]> = model
            .inertial_parameters()
            .iter()
            .map(|p| p.map(|x| 2.0 * x))
            .collect();
        let before = rnea(&model, &mut data, q, v, a, None).unwrap().clone();
        model.set_inertial_parameters(&doubled).unwrap();
        assert_eq!(model.inertial_parameters(), doubled, "{name}: round trip");
        let after = rnea(&model, &mut data, q, v, a, None).unwrap().clone();
        // τ_new − τ_old = Y (π_new − π_old) = Y π_old (the armature terms cancel)
        let pi = DVector::from_iterator(y.ncols(), doubled.iter().flatten().map(|x| x / 2.0));
        assert_close(
            &format!("{name}: τ difference"),
            (&after - &before).as_slice(),
            (&y * pi).as_slice(),
            REGRESSOR_TOLERANCE,
        );
        // ABA of the new model inverts its RNEA
        let qdd = aba(&model, &mut data, q, v, after.as_slice(), None)
            .unwrap()
            .clone();
        assert_close(
            &format!("{name}: aba∘rnea"),
            qdd.as_slice(),
            a,
            IDENTITY_TOLERANCE,
        );
        // M of the new model: CRBA equals M from RNEA columns
        let m = crba(&model, &mut data, q).unwrap().clone();
        let by_rnea = mass_matrix_by_rnea(&model, &mut data, q).unwrap().clone();
        assert_close(
            &format!("{name}: M"),
            m.as_slice(),
            by_rnea.as_slice(),
            IDENTITY_TOLERANCE,
        );
    }
}

#[test]
fn unphysical_parameters_are_refused_or_reported_by_name() {
    let (_, mut model) = test_models().remove(0);
    let good = model.inertial_parameters();
    let mut rng = rng();
    let row = rng.random_range(0..good.len());
    type Spoil = fn(&mut [f64; 10]);
    let cases: [(&str, Spoil); 3] = [
        ("expected a mass >= 0", |p| p[0] = -1.0),
        ("expected finite parameters", |p| p[4] = f64::NAN),
        ("positive semi-definite", |p| {
            p[4] = -1.0;
            p[6] = -1.0;
            p[9] = -1.0;
        }),
    ];
    for (message, spoil) in cases {
        let mut bad = good.clone();
        spoil(&mut bad[row]);
        let error = model.set_inertial_parameters(&bad).unwrap_err().to_string();
        assert!(error.contains(message), "{error}");
        assert!(
            error.contains(&format!("row {row} (body '{}')", model.body_names[row + 1])),
            "{error}"
        );
        assert_eq!(
            model.inertial_parameters(),
            good,
            "a refused set changes nothing"
        );
    }
    assert!(model.set_inertial_parameters(&good[1..]).is_err());
    // principal moments that break only the triangle inequality are set, with a warning
    let mut unusual = good.clone();
    break_the_triangle_inequality(&mut unusual[row]);
    let warnings = model.set_inertial_parameters(&unusual).unwrap();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains("triangle inequality"), "{warnings:?}");
    assert!(warnings[0].contains(&format!("row {row} (body '{}')", model.body_names[row + 1])));
    assert_eq!(model.inertial_parameters(), unusual);
    assert!(matches!(
        check_physical_parameters(&unusual[row]),
        Err(Unphysical::TriangleInequality(_))
    ));
    // a point mass and a massless body are physical
    assert!(
        check_physical_parameters(&[1.0, 0.1, 0.0, 0.0, 0.0, 0.0, 0.01, 0.0, 0.0, 0.01]).is_ok()
    );
    assert!(check_physical_parameters(&[0.0; 10]).is_ok());
    assert!(
        check_physical_parameters(&[0.0, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]).is_err()
    );
}

/// Principal moments 1, 1, 3 about the centre of mass (1 + 1 < 3), the centre of mass kept.
fn break_the_triangle_inequality(p: &mut [f64; 10]) {
    let m = p[0].max(1.0);
    let c = [p[1] / m, p[2] / m, p[3] / m];
    let shift = |i: usize, j: usize| {
        let cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
        m * (if i == j { cc } else { 0.0 } - c[i] * c[j])
    };
    p[0] = m;
    let moments = [1.0, 1.0, 3.0];
    for (k, (i, j)) in [(0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2)]
        .into_iter()
        .enumerate()
    {
        p[4 + k] = if i == j { moments[i] } else { 0.0 } + shift(i, j);
    }
}
