//! Criterion benchmarks of scenes stepped as MuJoCo's `mj_step` steps them, the cases of
//! `benchmarks/compare.py`'s scene section: Menagerie's Unitree Go2 on its floor from its `home`
//! keyframe (four feet in contact, elliptic cones, dry friction on every joint), its motors
//! told the keyframe's controls, with each of the three integrators; one step, its forward
//! dynamics alone, and a run of `RUN_STEPS` steps. A step and a run start their solver from q̈₀,
//! as `robodyn.step` and `robodyn.simulate` do (and `mj_step` after `mj_resetDataKeyframe`); the
//! forward dynamics alone starts from its last solution (the same state's: the warm case).

use criterion::{criterion_group, criterion_main, Criterion};
use robodyn::io::load_mjcf_file;
use robodyn::model::Integrator;
use robodyn::soft::step::SceneStep;
use robodyn::Model;
use std::hint::black_box;
use std::path::PathBuf;

/// Steps in the timed run (one second of the Go2's 2 ms steps).
const RUN_STEPS: usize = 500;

/// The Go2 scene with `integrator` in place of its own (Euler).
fn go2(integrator: Integrator) -> Model {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../testdata/menagerie/unitree_go2/scene.xml");
    let mut model = load_mjcf_file(&path).expect("the Go2 scene");
    model.options.integrator = integrator;
    model
}

fn scenes(c: &mut Criterion) {
    let mut group = c.benchmark_group("scene");
    for integrator in [Integrator::Euler, Integrator::ImplicitFast, Integrator::Rk4] {
        let model = go2(integrator);
        let home = model.keyframe("home").expect("home").clone();
        let tau = vec![0.0; model.nv];
        let ctrl = home.ctrl.as_slice();
        let mut stepper = SceneStep::new(&model).expect("a stepped integrator");
        let name = integrator.keyword();
        if integrator == Integrator::Euler {
            group.bench_function("go2/forward", |b| {
                b.iter(|| {
                    stepper
                        .forward_only(
                            &model,
                            (home.q.as_slice(), home.v.as_slice(), &[], &[]),
                            &tau,
                            ctrl,
                        )
                        .expect("forward");
                    black_box(&stepper.forward);
                })
            });
        }
        group.bench_function(format!("go2/step/{name}"), |b| {
            b.iter(|| {
                let (mut q, mut v) = (home.q.as_slice().to_vec(), home.v.as_slice().to_vec());
                stepper.forget_warm_start();
                stepper
                    .step(&model, 0.0, (&mut q, &mut v, &mut [], &mut []), &tau, ctrl)
                    .expect("step");
                black_box(&q);
            })
        });
        group.bench_function(format!("go2/run{RUN_STEPS}/{name}"), |b| {
            b.iter(|| {
                let (mut q, mut v) = (home.q.as_slice().to_vec(), home.v.as_slice().to_vec());
                stepper.forget_warm_start();
                for k in 0..RUN_STEPS {
                    let time = k as f64 * model.options.timestep;
                    stepper
                        .step(&model, time, (&mut q, &mut v, &mut [], &mut []), &tau, ctrl)
                        .expect("step");
                }
                black_box(&q);
            })
        });
    }
    group.finish();
}

criterion_group!(benches, scenes);
criterion_main!(benches);
