//! Criterion benchmarks of the core algorithms on the robots of `cases` (the bundled UR5 and
//! example-robot-data's UR5, Panda and Talos, the robots `benchmarks/pinocchio_native.sh` times
//! with Pinocchio), and a rollout.

mod cases;

use cases::{models, Bench, ALGORITHMS};
use criterion::{criterion_group, criterion_main, Criterion};
use robodyn::Data;
use std::hint::black_box;

fn benchmarks(c: &mut Criterion) {
    for (name, model, frame) in models() {
        let mut bench = Bench::new(&model, frame);
        for algorithm in ALGORITHMS {
            c.bench_function(&format!("{name}/{algorithm}"), |b| {
                b.iter(|| bench.run(algorithm))
            });
        }
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
