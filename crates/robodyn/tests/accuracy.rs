//! The accuracy check of the fixed-step schemes: the issue's case (the UR5 from neutral + 0.3,
//! no damping, RK4 at dt = 0.05 s for 5 s) is flagged with a step that meets the tolerance, the
//! same motion at dt = 1 ms is not, and damped or controlled runs raise no false alarm.

use nalgebra::DVector;
use robodyn::integrate::{
    simulate, AccuracyMeasure, ControlLaw, DesiredMotion, Integrator, NativeController,
    SimulationOptions, Trajectory,
};
use robodyn::io::bundled_model;
use robodyn::Model;

/// The issue's start: every joint 0.3 rad from neutral, at rest.
fn displaced(model: &Model) -> Vec<f64> {
    model.neutral().iter().map(|q| q + 0.3).collect()
}

fn run(model: &Model, law: ControlLaw, options: &SimulationOptions) -> Trajectory {
    let mut controller = NativeController::new(model, law, options.passive, options.t_end).unwrap();
    let q0 = displaced(model);
    simulate(
        model,
        &q0,
        &vec![0.0; model.nv],
        options,
        &mut controller,
        None,
        None,
    )
    .unwrap()
}

fn passive(model: &Model) -> ControlLaw {
    ControlLaw::Constant(DVector::zeros(model.nv))
}

/// Gains in proportion to each joint's inertia at neutral (the wrist is light).
fn pd(model: &Model) -> ControlLaw {
    let mut data = robodyn::Data::new(model);
    let inertia = robodyn::algo::crba(model, &mut data, model.neutral().as_slice())
        .unwrap()
        .diagonal();
    ControlLaw::Pd {
        kp: inertia.scale(100.0),
        kd: inertia.scale(20.0),
        reference: DesiredMotion::Setpoint(model.neutral()),
        gravity_compensation: true,
    }
}

#[test]
fn the_coarse_swing_is_flagged_and_the_fine_one_is_not() {
    let model = bundled_model("ur5", false).unwrap();
    let coarse = run(
        &model,
        passive(&model),
        &SimulationOptions::new(Integrator::Rk4, 0.05, 5.0),
    );
    let accuracy = &coarse.accuracy;
    let issue = accuracy.issue.expect("dt = 0.05 s misses rtol = 1e-3");
    // the energy drift asks for the smaller step; the local error misses the tolerance too
    assert_eq!(issue.measure, AccuracyMeasure::EnergyDrift);
    assert!(issue.error > 0.1 && issue.error == accuracy.energy_drift.unwrap());
    assert!(accuracy.local_errors.iter().any(|e| *e > accuracy.rtol));
    assert!(issue.largest_step > 1e-3 && issue.largest_step < 0.05);
    assert!(issue.time > 0.0 && issue.time <= 5.0);
    // the starts of the first step and of every 50th of 100
    assert_eq!(accuracy.check_times, [0, 49, 99].map(|k| coarse.t[k]));
    // the same swing at the suggested step, and at 1 ms, meets the tolerance
    for dt in [issue.largest_step, 1e-3] {
        let fine = run(
            &model,
            passive(&model),
            &SimulationOptions::new(Integrator::Rk4, dt, 5.0),
        );
        let accuracy = &fine.accuracy;
        assert_eq!(accuracy.issue, None, "dt = {dt}");
        assert!(accuracy.energy_drift.unwrap() <= accuracy.rtol, "dt = {dt}");
    }
}

#[test]
fn damped_and_controlled_runs_track_no_energy_and_raise_no_false_alarm() {
    let mut model = bundled_model("ur5", false).unwrap();
    let options = SimulationOptions::new(Integrator::Rk4, 1e-3, 5.0);
    let controlled = run(&model, pd(&model), &options);
    assert_eq!(controlled.accuracy.energy_drift, None);
    assert_eq!(controlled.accuracy.issue, None);
    assert!(controlled.accuracy.local_errors.iter().all(|e| *e < 1e-4));
    // the light wrist's velocity decays at 150 s⁻¹
    model.damping.fill(0.02);
    let damped = run(&model, passive(&model), &options);
    assert_eq!(damped.accuracy.energy_drift, None);
    assert_eq!(damped.accuracy.issue, None);
}

#[test]
fn rk45_controls_its_own_error_and_records_none() {
    let model = bundled_model("ur5", false).unwrap();
    let rk45 = Integrator::Rk45 {
        rtol: 1e-6,
        atol: 1e-9,
    };
    let accuracy = run(
        &model,
        passive(&model),
        &SimulationOptions::new(rk45, 0.05, 5.0),
    )
    .accuracy;
    assert!(accuracy.check_times.is_empty() && accuracy.local_errors.is_empty());
    assert_eq!((accuracy.energy_drift, accuracy.issue), (None, None));
}

#[test]
fn a_bad_tolerance_is_refused_with_its_name() {
    for rtol in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
        let mut options = SimulationOptions::new(Integrator::Rk4, 1e-3, 0.1);
        options.accuracy_rtol = rtol;
        let error = options.check().unwrap_err().to_string();
        assert!(
            error.contains("'rtol'") && error.contains("expected a finite number > 0"),
            "{error}"
        );
    }
}
