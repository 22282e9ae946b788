//! The integrators: convergence orders, RK45's tolerance and dense output, Lie-group integration
//! of a free body, passive forces and the native controllers.

mod common;

use nalgebra::DVector;
use robodyn::integrate::{
    simulate, ControlLaw, DesiredMotion, Integrator, LimitModel, NativeController, PassiveForces,
    SimulationOptions, Trajectory,
};
use robodyn::io::{bundled_model, load_urdf_str, LoadOptions};
use robodyn::Model;

/// Richardson ratio of a first-order scheme when dt halves (ideally 2), accepted band.
const FIRST_ORDER_RATIO: (f64, f64) = (1.8, 2.2);
/// ... of a fourth-order scheme (ideally 16).
const FOURTH_ORDER_RATIO: (f64, f64) = (14.0, 18.0);
/// How far beyond its (local) tolerance RK45's global error may go over two periods of a
/// pendulum swinging at 2 rad; SciPy's RK45 reaches 65x on the same problem.
const RK45_TOLERANCE_FACTOR: f64 = 100.0;

fn passive_run(model: &Model, q0: &[f64], v0: &[f64], options: &SimulationOptions) -> Trajectory {
    let mut zero = NativeController::new(
        model,
        ControlLaw::Constant(DVector::zeros(model.nv)),
        options.passive,
        options.t_end,
    )
    .unwrap();
    simulate(model, q0, v0, options, &mut zero, None, None).unwrap()
}

/// The final configuration and velocity of a passive run, as a tangent error against `reference`.
fn final_error(model: &Model, run: &Trajectory, reference: &Trajectory) -> f64 {
    let (nq, nv) = (model.nq, model.nv);
    let last = |t: &Trajectory| {
        (
            t.q[t.q.len() - nq..].to_vec(),
            t.v[t.v.len() - nv..].to_vec(),
        )
    };
    let ((q, v), (q_ref, v_ref)) = (last(run), last(reference));
    let mut delta = vec![0.0; nv];
    model.difference(&q_ref, &q, &mut delta).unwrap();
    let dv = v
        .iter()
        .zip(&v_ref)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>();
    (delta.iter().map(|x| x * x).sum::<f64>() + dv).sqrt()
}

fn ratio(
    model: &Model,
    integrator: Integrator,
    dt: f64,
    q0: &[f64],
    v0: &[f64],
    t_end: f64,
) -> f64 {
    let reference = passive_run(
        model,
        q0,
        v0,
        &SimulationOptions::new(Integrator::Rk4, dt / 16.0, t_end),
    );
    let coarse = passive_run(
        model,
        q0,
        v0,
        &SimulationOptions::new(integrator, dt, t_end),
    );
    let fine = passive_run(
        model,
        q0,
        v0,
        &SimulationOptions::new(integrator, dt / 2.0, t_end),
    );
    final_error(model, &coarse, &reference) / final_error(model, &fine, &reference)
}

/// A rigid box (0.1 × 0.2 × 0.3 m, 2 kg) on a free joint, without gravity.
fn free_box() -> Model {
    let urdf = r#"<robot name="box"><link name="box"><inertial><mass value="2"/>
        <inertia ixx="0.0217" iyy="0.0167" izz="0.0083" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>"#;
    let mut model = load_urdf_str(urdf, "box.urdf", LoadOptions::floating(true)).unwrap();
    model.gravity.fill(0.0);
    model
}

fn in_band(value: f64, band: (f64, f64)) -> bool {
    value > band.0 && value < band.1
}

#[test]
fn euler_and_rk4_converge_at_their_order_on_the_pendulum() {
    let model = bundled_model("pendulum", false).unwrap();
    let (q0, v0) = ([1.0], [0.0]);
    for (integrator, band) in [
        (Integrator::ExplicitEuler, FIRST_ORDER_RATIO),
        (Integrator::SemiImplicitEuler, FIRST_ORDER_RATIO),
        (Integrator::Rk4, FOURTH_ORDER_RATIO),
    ] {
        let dt = if integrator == Integrator::Rk4 {
            0.02
        } else {
            2e-3
        };
        let r = ratio(&model, integrator, dt, &q0, &v0, 1.0);
        assert!(in_band(r, band), "{integrator:?}: ratio {r}");
    }
}

#[test]
fn rk4_keeps_its_order_on_a_tumbling_free_body() {
    // the Lie-group correction dexp⁻¹ matters here: without it (or with its sign wrong) the
    // rotation would converge at order 2, a ratio of 4
    let model = free_box();
    let q0 = [0.0, 0.0, 0.0, 0.1, 0.2, 0.3, (1.0f64 - 0.14).sqrt()];
    let v0 = [0.3, -0.2, 0.1, 1.0, 5.0, 0.2];
    let r = ratio(&model, Integrator::Rk4, 0.02, &q0, &v0, 2.0);
    assert!(in_band(r, FOURTH_ORDER_RATIO), "ratio {r}");
}

#[test]
fn rk45_meets_its_tolerance_at_every_sample() {
    // a regular (not chaotic) motion, where the global error follows the local tolerance
    let model = bundled_model("pendulum", false).unwrap();
    let (q0, v0) = ([2.0], [0.0]);
    let reference = passive_run(
        &model,
        &q0,
        &v0,
        &SimulationOptions::new(Integrator::Rk4, 2.5e-4, 5.0),
    );
    let every = 40;
    for tolerance in [1e-6, 1e-9] {
        let options = SimulationOptions::new(
            Integrator::Rk45 {
                rtol: tolerance,
                atol: tolerance,
            },
            0.01,
            5.0,
        );
        let run = passive_run(&model, &q0, &v0, &options);
        assert_eq!(run.len(), 501);
        // every 40th sample of the reference is a sample of the run, most by dense output
        let worst = (0..run.len())
            .map(|k| {
                (run.q[k] - reference.q[every * k])
                    .abs()
                    .max((run.v[k] - reference.v[every * k]).abs())
            })
            .fold(0.0, f64::max);
        assert!(
            worst < RK45_TOLERANCE_FACTOR * tolerance,
            "tolerance {tolerance}: error {worst}"
        );
        // within the first steps the error is the local one
        let early = (0..=5)
            .map(|k| (run.q[k] - reference.q[every * k]).abs())
            .fold(0.0, f64::max);
        assert!(
            early < tolerance,
            "tolerance {tolerance}: early error {early}"
        );
        // far fewer steps than samples: the samples come from dense output
        assert!(run.statistics.steps < 300, "{:?}", run.statistics);
    }
}

#[test]
fn quaternions_stay_unit_without_renormalisation() {
    let model = free_box();
    let q0 = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
    let v0 = [1.0, 0.0, 0.0, 0.1, 8.0, 0.1];
    let run = passive_run(
        &model,
        &q0,
        &v0,
        &SimulationOptions::new(Integrator::Rk4, 1e-2, 20.0),
    );
    for row in run.q.chunks_exact(7) {
        let norm = row[3..7].iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!((norm - 1.0).abs() < 1e-13, "norm {norm}");
    }
}

#[test]
fn damping_springs_and_limits_act_as_documented() {
    let mut model = bundled_model("pendulum", false).unwrap();
    model.gravity.fill(0.0);
    model.stiffness[0] = 4.0;
    model.spring_reference[0] = 0.5;
    model.damping[0] = 0.4;
    // m l² q̈ + d q̇ + k (q − q_ref) = 0 with m l² = 1: a damped oscillator about q_ref
    let run = passive_run(
        &model,
        &[0.0],
        &[0.0],
        &SimulationOptions::new(Integrator::Rk4, 1e-3, 2.0),
    );
    let (omega, zeta) = (2.0_f64, 0.1_f64);
    let omega_d = omega * (1.0 - zeta * zeta).sqrt();
    for (k, t) in run.t.iter().enumerate() {
        let envelope = (-zeta * omega * t).exp();
        let exact = 0.5
            - 0.5 * envelope * ((omega_d * t).cos() + zeta * omega / omega_d * (omega_d * t).sin());
        assert!(
            (run.q[k] - exact).abs() < 1e-10,
            "t = {t}: {} vs {exact}",
            run.q[k]
        );
    }
    // a limit at 0.2 rad with the penalty holds the joint near it
    model.upper_position_limit[0] = 0.2;
    let mut options = SimulationOptions::new(Integrator::Rk4, 1e-4, 2.0);
    options.passive.limits = LimitModel::Penalty {
        stiffness: 1e4,
        damping: 100.0,
    };
    let run = passive_run(&model, &[0.0], &[0.0], &options);
    let highest = run.q.iter().copied().fold(f64::MIN, f64::max);
    assert!(highest > 0.2 && highest < 0.21, "highest {highest}");
    // at rest the spring pushes with k (q_ref − 0.2) = 1.2 N·m: δ = 1.2 / 1e4 rad past the limit
    let rest = run.q[run.len() - 1];
    assert!((rest - (0.2 + 1.2e-4)).abs() < 1e-6, "rest {rest}");
}

#[test]
fn computed_torque_tracks_a_sampled_reference() {
    let model = bundled_model("ur5", false).unwrap();
    let nv = model.nv;
    let times: Vec<f64> = (0..=20).map(|k| k as f64 * 0.05).collect();
    let mut q = Vec::new();
    let mut v = Vec::new();
    for t in &times {
        for j in 0..nv {
            let w = 1.0 + j as f64 * 0.3;
            q.push(0.5 * (w * t).sin());
            v.push(0.5 * w * (w * t).cos());
        }
    }
    let reference = DesiredMotion::Samples {
        times: times.clone(),
        q: q.clone(),
        v: v.clone(),
    };
    let law = ControlLaw::ComputedTorque {
        kp: DVector::from_element(nv, 100.0),
        kd: DVector::from_element(nv, 20.0),
        reference,
    };
    let options = SimulationOptions::new(Integrator::Rk4, 1e-3, 1.0);
    let mut controller = NativeController::new(&model, law, options.passive, 1.0).unwrap();
    let v0 = v[..nv].to_vec();
    let run = simulate(&model, &q[..nv], &v0, &options, &mut controller, None, None).unwrap();
    // at the knots the reference is exact
    for (k, t) in times.iter().enumerate() {
        let sample = (t / 1e-3).round() as usize;
        for j in 0..nv {
            let error = (run.q[sample * nv + j] - q[k * nv + j]).abs();
            assert!(error < 1e-6, "t = {t}, joint {j}: {error}");
        }
    }
}

#[test]
fn bad_options_are_refused_with_their_name() {
    let model = bundled_model("pendulum", false).unwrap();
    let mut zero = NativeController::new(
        &model,
        ControlLaw::Constant(DVector::zeros(1)),
        PassiveForces::default(),
        1.0,
    )
    .unwrap();
    let cases = [
        (SimulationOptions::new(Integrator::Rk4, 0.0, 1.0), "dt"),
        (
            SimulationOptions::new(Integrator::Rk4, 1e-3, f64::NAN),
            "t_end",
        ),
        (
            SimulationOptions::new(
                Integrator::Rk45 {
                    rtol: -1.0,
                    atol: 1e-6,
                },
                1e-3,
                1.0,
            ),
            "rtol",
        ),
        (SimulationOptions::new(Integrator::Rk4, 1e-12, 1e6), "dt"),
    ];
    for (options, argument) in cases {
        let error = simulate(&model, &[0.0], &[0.0], &options, &mut zero, None, None).unwrap_err();
        assert!(
            error.to_string().contains(&format!("'{argument}'")),
            "{error}"
        );
    }
    let options = SimulationOptions::new(Integrator::Rk4, 1e-3, 1.0);
    let error = simulate(&model, &[f64::NAN], &[0.0], &options, &mut zero, None, None).unwrap_err();
    assert!(error.to_string().contains("'q0'"), "{error}");
    assert!(Integrator::from_name("rk5", 1e-6, 1e-6).is_err());
}

#[test]
fn a_diverging_run_stops_with_the_time_joint_and_a_stable_step() {
    let model = bundled_model("ur5", false).unwrap();
    let q0 = vec![0.3; model.nv];
    let mut zero = NativeController::new(
        &model,
        ControlLaw::Constant(DVector::zeros(model.nv)),
        PassiveForces::default(),
        2.0,
    )
    .unwrap();
    let options = SimulationOptions::new(Integrator::Rk4, 0.1, 2.0);
    let error = simulate(&model, &q0, &[0.0; 6], &options, &mut zero, None, None).unwrap_err();
    let robodyn::Error::Diverged { time, message } = &error else {
        panic!("expected a divergence, got {error}");
    };
    assert!(*time > 0.0 && *time <= 2.0);
    assert!(
        message.contains("joint '") && message.contains("keeps it stable"),
        "{message}"
    );
    // the same motion at a sane step is untouched by the guard
    let options = SimulationOptions::new(Integrator::Rk4, 1e-3, 2.0);
    assert!(simulate(&model, &q0, &[0.0; 6], &options, &mut zero, None, None).is_ok());
}
