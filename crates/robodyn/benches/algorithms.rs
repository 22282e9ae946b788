//! Criterion benchmarks of the core algorithms on the robots of `cases` (the bundled UR5 and
//! example-robot-data's UR5, Panda and Talos, the robots `benchmarks/pinocchio_native.sh` times
//! with Pinocchio), the batch kernels at each lane width the CPU runs, and a rollout.

mod cases;

use cases::{models, Bench, ALGORITHMS};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
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

/// States in one benchmarked batch: enough groups of eight that the leftovers do not count.
const BATCH: usize = 256;

/// Batches of `BATCH` states through the lane kernels (`algo::lanes`: RNEA, gravity, ABA, CRBA,
/// RNEA derivatives) at every width this CPU runs, in states per second: the one-state width is
/// the plain loop of single calls.
fn lanes(c: &mut Criterion) {
    use rand::{rngs::StdRng, SeedableRng};
    use robodyn::algo::States;
    use robodyn::algo::{
        aba_batch, aba_derivatives_batch, crba_batch, newton_euler_batch, rnea_derivatives_batch,
        BatchWorkspace, LaneWidth,
    };
    let mut group = c.benchmark_group("lanes");
    group.throughput(Throughput::Elements(BATCH as u64));
    for (name, model, _) in models() {
        let mut rng = StdRng::seed_from_u64(3);
        let q: Vec<f64> = (0..BATCH)
            .flat_map(|_| model.random_configuration(&mut rng).as_slice().to_vec())
            .collect();
        let v: Vec<f64> = (0..BATCH * model.nv)
            .map(|k| (k % 7) as f64 * 0.2 - 0.6)
            .collect();
        let (mut out, mut matrices) = (vec![0.0; v.len()], vec![0.0; 3 * v.len() * model.nv]);
        for width in LaneWidth::ALL.into_iter().filter(|w| w.available()) {
            let mut workspace = BatchWorkspace::with_width(&model, width).unwrap();
            let id = |algorithm: &str| format!("{name}/{algorithm}/{width:?}");
            let dynamics = States {
                q: &q,
                v: Some(&v),
                a: Some(&v),
                tau: None,
            };
            group.bench_function(id("rnea"), |b| {
                b.iter(|| newton_euler_batch(&model, &mut workspace, dynamics, &mut out))
            });
            let at_rest = States {
                q: &q,
                ..States::default()
            };
            group.bench_function(id("gravity"), |b| {
                b.iter(|| newton_euler_batch(&model, &mut workspace, at_rest, &mut out))
            });
            let forward = States {
                q: &q,
                v: Some(&v),
                a: None,
                tau: Some(&v),
            };
            group.bench_function(id("aba"), |b| {
                b.iter(|| aba_batch(&model, &mut workspace, forward, &mut out))
            });
            let square = BATCH * model.nv * model.nv;
            group.bench_function(id("crba"), |b| {
                b.iter(|| crba_batch(&model, &mut workspace, &q, &mut matrices[..square]))
            });
            group.bench_function(id("rnea_derivatives"), |b| {
                b.iter(|| rnea_derivatives_batch(&model, &mut workspace, dynamics, &mut matrices))
            });
            group.bench_function(id("aba_derivatives"), |b| {
                b.iter(|| aba_derivatives_batch(&model, &mut workspace, forward, &mut matrices))
            });
        }
    }
    group.finish();
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

criterion_group!(benches, benchmarks, lanes, rollout);
criterion_main!(benches);
