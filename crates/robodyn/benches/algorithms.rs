//! Criterion benchmarks of the core algorithms on the bundled UR5 and, when the
//! `example-robot-data` URDFs are found (`ROBODYN_ROBOTS_DIR` or the test virtual environment),
//! on its UR5, Panda and Talos, the robots `benchmarks/pinocchio_native.sh` times with Pinocchio.

use criterion::{criterion_group, criterion_main, Criterion};
use rand::{rngs::StdRng, SeedableRng};
use robodyn::algo::{
    aba, aba_derivatives, centroidal_momentum_matrix, coriolis_matrix, crba, forward_kinematics,
    frame_pose, jacobian, rnea, rnea_derivatives, Reference,
};
use robodyn::io::{bundled_model, load_urdf_file, LoadOptions};
use robodyn::{Data, Model};
use std::hint::black_box;
use std::path::PathBuf;

/// The example-robot-data robots directory, if present.
fn robots_dir() -> Option<PathBuf> {
    let dir = std::env::var("ROBODYN_ROBOTS_DIR").map(PathBuf::from).unwrap_or_else(|_| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../../.venv/lib/python3.11/site-packages/cmeel.prefix/share/example-robot-data/robots")
    });
    dir.is_dir().then_some(dir)
}

/// (name, model, the frame whose Jacobian and pose are timed): the bundled UR5, and the
/// example-robot-data robots that benchmarks/pinocchio_native.sh times with Pinocchio.
fn models() -> Vec<(&'static str, Model, &'static str)> {
    let mut models = vec![(
        "ur5 (bundled)",
        bundled_model("ur5", false).expect("bundled ur5"),
        "tool0",
    )];
    if let Some(dir) = robots_dir() {
        for (name, path, floating, frame) in [
            ("ur5", "ur_description/urdf/ur5_robot.urdf", false, "tool0"),
            (
                "panda",
                "panda_description/urdf/panda.urdf",
                false,
                "panda_hand_tcp",
            ),
            (
                "talos",
                "talos_data/robots/talos_full_v2.urdf",
                true,
                "gripper_left_fingertip_1_link",
            ),
        ] {
            if let Ok(model) = load_urdf_file(&dir.join(path), LoadOptions::floating(floating)) {
                models.push((name, model, frame));
            }
        }
    }
    models
}

fn benchmarks(c: &mut Criterion) {
    for (name, model, frame) in models() {
        let mut data = Data::new(&model);
        let mut rng = StdRng::seed_from_u64(7);
        let q = model.random_configuration(&mut rng);
        let v = nalgebra::DVector::from_element(model.nv, 0.5);
        let a = nalgebra::DVector::from_element(model.nv, 0.25);
        let q = q.as_slice();
        let frame = model.frame_index(frame).expect("benchmark frame");
        c.bench_function(&format!("{name}/forward_kinematics"), |b| {
            b.iter(|| forward_kinematics(&model, &mut data, black_box(q)).map(|x| x.len()))
        });
        c.bench_function(&format!("{name}/frame_pose"), |b| {
            b.iter(|| frame_pose(&model, &mut data, black_box(q), frame).map(|x| x.translation.x))
        });
        c.bench_function(&format!("{name}/jacobian"), |b| {
            b.iter(|| {
                jacobian(&model, &mut data, black_box(q), frame, Reference::World).map(|j| j[0])
            })
        });
        c.bench_function(&format!("{name}/rnea"), |b| {
            b.iter(|| {
                rnea(
                    &model,
                    &mut data,
                    black_box(q),
                    v.as_slice(),
                    a.as_slice(),
                    None,
                )
                .map(|t| t[0])
            })
        });
        c.bench_function(&format!("{name}/crba"), |b| {
            b.iter(|| crba(&model, &mut data, black_box(q)).map(|m| m[0]))
        });
        c.bench_function(&format!("{name}/coriolis_matrix"), |b| {
            b.iter(|| coriolis_matrix(&model, &mut data, black_box(q), v.as_slice()).map(|m| m[0]))
        });
        c.bench_function(&format!("{name}/centroidal_momentum_matrix"), |b| {
            b.iter(|| centroidal_momentum_matrix(&model, &mut data, black_box(q)).map(|m| m[0]))
        });
        c.bench_function(&format!("{name}/aba"), |b| {
            b.iter(|| {
                aba(
                    &model,
                    &mut data,
                    black_box(q),
                    v.as_slice(),
                    a.as_slice(),
                    None,
                )
                .map(|t| t[0])
            })
        });
        c.bench_function(&format!("{name}/rnea_derivatives"), |b| {
            b.iter(|| {
                rnea_derivatives(
                    &model,
                    &mut data,
                    black_box(q),
                    v.as_slice(),
                    a.as_slice(),
                    None,
                )
                .map(|()| data.dtau_dq[0])
            })
        });
        c.bench_function(&format!("{name}/aba_derivatives"), |b| {
            b.iter(|| {
                aba_derivatives(
                    &model,
                    &mut data,
                    black_box(q),
                    v.as_slice(),
                    a.as_slice(),
                    None,
                )
                .map(|()| data.dqdd_dq[0])
            })
        });
    }
}

/// A 1 s rollout of the bundled UR5 at dt = 1 ms with RK4 and a native PD controller with gravity
/// compensation holding the neutral configuration from a displaced start (gains scaled by M's
/// diagonal so the stiff wrist stays stable at this step).
fn rollout(c: &mut Criterion) {
    use robodyn::integrate::{
        simulate, ControlLaw, DesiredMotion, Integrator, NativeController, SimulationOptions,
    };
    let model = robodyn::io::bundled_model("ur5", false).unwrap();
    let q0 = nalgebra::DVector::from_element(model.nv, 0.3);
    let mut data = Data::new(&model);
    let inertia = robodyn::algo::crba(&model, &mut data, q0.as_slice())
        .unwrap()
        .diagonal();
    let options = SimulationOptions::new(Integrator::Rk4, 1e-3, 1.0);
    let law = ControlLaw::Pd {
        kp: inertia.scale(100.0),
        kd: inertia.scale(20.0),
        reference: DesiredMotion::Setpoint(model.neutral()),
        gravity_compensation: true,
    };
    let v0 = vec![0.0; model.nv];
    c.bench_function("ur5/rollout_rk4_pd_1s", |b| {
        b.iter(|| {
            let mut controller =
                NativeController::new(&model, law.clone(), options.passive, 1.0).unwrap();
            simulate(
                &model,
                black_box(q0.as_slice()),
                &v0,
                &options,
                &mut controller,
                None,
                None,
            )
            .map(|t| t.q[0])
        })
    });
}

criterion_group!(benches, benchmarks, rollout);
criterion_main!(benches);
