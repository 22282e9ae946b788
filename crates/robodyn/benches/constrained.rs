//! Criterion benchmarks of forward dynamics under contact constraints, the cases of
//! `benchmarks/compare.py`'s constrained section: example-robot-data's Solo12 on its four feet
//! (a point each, 12 rows) and Talos on its two soles (a frame each, 12 rows), held to the world
//! where they are, in world axes (Pinocchio's LOCAL_WORLD_ALIGNED), at a velocity the contacts
//! allow, and an impact there. Besides the whole calls, their parts: ABA (the free acceleration
//! and the articulated inertias the constrained algorithms build on), the constraint Jacobian,
//! and `delassus` on its own (CRBA, M's factor, the Jacobian and one sweep per row); and the
//! forward dynamics of a batch of `BATCH` states at each lane width this CPU runs. Skipped when
//! the URDFs are not found (see `cases`).

#[allow(dead_code)]
mod cases;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use nalgebra::DVector;
use rand::{rngs::StdRng, SeedableRng};
use robodyn::algo::{
    aba, constrained_forward_dynamics, constrained_forward_dynamics_batch,
    constrained_forward_dynamics_derivatives, constraint_jacobian, delassus, impulse_dynamics,
    ConstrainedBatchWorkspace, ConstrainedDerivatives, ConstrainedOptions, ConstraintData,
    LaneWidth, States,
};
use robodyn::constraint::{
    Attachment, Constraint, ConstraintKind, ConstraintReference, ConstraintSet,
};
use robodyn::io::{load_urdf_file, LoadOptions};
use robodyn::{Data, Model};
use std::hint::black_box;

/// The contacts: (name, URDF under example-robot-data's robots, rows per contact, frames).
const CONTACTS: [(&str, &str, usize, &[&str]); 2] = [
    (
        "solo12",
        "solo_description/robots/solo12.urdf",
        3,
        &["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"],
    ),
    (
        "talos",
        "talos_data/robots/talos_full_v2.urdf",
        6,
        &["left_sole_link", "right_sole_link"],
    ),
];

/// States in one benchmarked batch: enough groups of eight that the leftovers do not count.
const BATCH: usize = 256;

/// Each frame held to the world where it is: a point (3 rows) or the whole frame (6 rows).
fn contact_set(model: &Model, rows: usize, frames: &[&str]) -> ConstraintSet {
    let constraints = frames
        .iter()
        .map(|name| {
            let first = Attachment::at_frame(model.frame_index(name).expect("contact frame"));
            let kind = if rows == 3 {
                ConstraintKind::Point {
                    first,
                    second: None,
                }
            } else {
                ConstraintKind::Frame {
                    first,
                    second: None,
                    mask: [true; 6],
                }
            };
            Constraint {
                kind,
                reference: ConstraintReference::World,
            }
        })
        .collect();
    ConstraintSet::new(model, constraints).expect("contact set")
}

/// The state timed: a random configuration q, a velocity v the contacts allow (`u − Jᵀ (J Jᵀ)⁻¹
/// J u` of a velocity u of entries in ±0.6), torques of entries in ±5, and u itself, the velocity
/// at an impact.
struct Stance {
    q: Vec<f64>,
    v: Vec<f64>,
    tau: Vec<f64>,
    impact: Vec<f64>,
}

fn stance(model: &Model, set: &ConstraintSet) -> Stance {
    let q = model
        .random_configuration(&mut StdRng::seed_from_u64(7))
        .as_slice()
        .to_vec();
    let (mut data, mut constraints) = (Data::new(model), ConstraintData::new(model, set));
    let j = constraint_jacobian(model, &mut data, &mut constraints, set, &q)
        .expect("constraint Jacobian")
        .clone();
    let u = DVector::from_fn(model.nv, |k, _| (k % 7) as f64 * 0.2 - 0.6);
    let gram = (&j * j.transpose())
        .cholesky()
        .expect("independent contacts");
    let v = &u - j.transpose() * gram.solve(&(&j * &u));
    Stance {
        q,
        v: v.as_slice().to_vec(),
        tau: (0..model.nv).map(|k| (k % 11) as f64 - 5.0).collect(),
        impact: u.as_slice().to_vec(),
    }
}

fn benchmarks(c: &mut Criterion) {
    let Some(dir) = cases::robots_dir() else {
        return;
    };
    for (name, path, rows, frames) in CONTACTS {
        let model = load_urdf_file(&dir.join(path), LoadOptions::floating(true)).expect(path);
        let set = contact_set(&model, rows, frames);
        let Stance { q, v, tau, impact } = stance(&model, &set);
        let (mut data, mut constraints) = (Data::new(&model), ConstraintData::new(&model, &set));
        let options = ConstrainedOptions::default();
        let mut group = c.benchmark_group(format!("constrained/{name}"));
        group.bench_function("forward_dynamics", |b| {
            b.iter(|| {
                let state = (black_box(&q[..]), &v[..], &tau[..]);
                constrained_forward_dynamics(
                    &model,
                    &mut data,
                    &mut constraints,
                    &set,
                    state,
                    None,
                    &options,
                )
                .map(|()| constraints.qdd[0])
            })
        });
        group.bench_function("impulse_dynamics", |b| {
            b.iter(|| {
                let state = (black_box(&q[..]), &impact[..]);
                impulse_dynamics(&model, &mut data, &mut constraints, &set, state, 0.0, 0.0)
                    .map(|()| constraints.qdd[0])
            })
        });
        let mut derivatives = ConstrainedDerivatives::new(&model, &set);
        group.bench_function("forward_dynamics_derivatives", |b| {
            b.iter(|| {
                let state = (black_box(&q[..]), &v[..], &tau[..]);
                constrained_forward_dynamics_derivatives(
                    &model,
                    &mut data,
                    &mut constraints,
                    &mut derivatives,
                    &set,
                    state,
                    None,
                    0.0,
                )
                .map(|()| derivatives.dqdd_dq[0])
            })
        });
        // the parts: ABA (a_f and the articulated inertias), then J and γ
        group.bench_function("part_aba", |b| {
            b.iter(|| aba(&model, &mut data, black_box(&q), &v, &tau, None).map(|a| a[0]))
        });
        group.bench_function("part_constraint_jacobian", |b| {
            b.iter(|| {
                constraint_jacobian(&model, &mut data, &mut constraints, &set, black_box(&q))
                    .map(|j| j[0])
            })
        });
        group.bench_function("part_delassus", |b| {
            b.iter(|| {
                delassus(&model, &mut data, &mut constraints, &set, black_box(&q)).map(|d| d[0])
            })
        });
        group.finish();

        // a batch: the stance's configuration and velocity, the torques varied per state
        let mut group = c.benchmark_group(format!("constrained_batch/{name}"));
        group.throughput(Throughput::Elements(BATCH as u64));
        let (qs, vs) = (q.repeat(BATCH), v.repeat(BATCH));
        let taus: Vec<f64> = (0..BATCH * model.nv)
            .map(|k| (k % 13) as f64 - 6.0)
            .collect();
        let states = States {
            q: &qs,
            v: Some(&vs),
            a: None,
            tau: Some(&taus),
        };
        let mut out = vec![0.0; BATCH * (model.nv + set.rows())];
        for width in LaneWidth::ALL.into_iter().filter(|w| w.available()) {
            let mut workspace = ConstrainedBatchWorkspace::with_width(&model, &set, width)
                .expect("an available width");
            group.bench_function(format!("forward_dynamics/{width:?}"), |b| {
                b.iter(|| {
                    let (model, set) = (&model, &set);
                    constrained_forward_dynamics_batch(
                        model,
                        &mut workspace,
                        set,
                        black_box(states),
                        &options,
                        &mut out,
                    )
                    .map(|()| out[0])
                })
            });
        }
        group.finish();
    }
}

criterion_group!(benches, benchmarks);
criterion_main!(benches);
