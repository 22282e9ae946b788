//! The hot algorithms allocate nothing after `Data::new`: a counting global allocator proves it.

mod common;

use nalgebra::DVector;
use robodyn::algo::*;
use robodyn::integrate::{
    simulate, ControlLaw, DesiredMotion, Integrator, NativeController, PassiveForces,
    SimulationOptions, StepWorkspace,
};
use robodyn::Data;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct CountingAllocator;

thread_local! {
    /// Allocations made on this thread: the test harness's own threads (its timers and output
    /// under a loaded machine) must not count.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn count_one() {
    // `try_with`: the thread's storage may already be gone while the thread ends
    let _ = ALLOCATIONS.try_with(|count| count.set(count.get() + 1));
}

unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count_one();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count_one();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

/// Allocations made by `f` on this thread.
fn allocations(f: impl FnOnce()) -> usize {
    let before = ALLOCATIONS.with(Cell::get);
    f();
    ALLOCATIONS.with(Cell::get) - before
}

// one test function, so that nothing else runs on this thread meanwhile
#[test]
fn algorithms_allocate_nothing_after_data_new() {
    // the counter sees allocations
    assert!(allocations(|| drop(std::hint::black_box(vec![1.0_f64; 8]))) > 0);
    let mut rng = common::rng();
    for (name, model) in common::test_models() {
        let mut data = Data::new(&model);
        let q = model.random_configuration(&mut rng);
        let v = common::random_vector(&mut rng, model.nv);
        let a = common::random_vector(&mut rng, model.nv);
        let f_ext = vec![robodyn::spatial::Force::ZERO; model.nbodies() - 1];
        let (q, v, a) = (q.as_slice(), v.as_slice(), a.as_slice());
        let frame = model.frames.len() - 1;
        let mut gamma = vec![0.0; model.nv.pow(3)];
        let (by_q, by_v) = (
            &mut vec![0.0; model.nv.pow(2)],
            &mut vec![0.0; model.nv.pow(2)],
        );
        let stacked = &mut vec![0.0; 3 * model.nv.pow(2)];
        let mut jacobians = (
            nalgebra::DMatrix::zeros(model.nv, model.nv),
            nalgebra::DMatrix::zeros(model.nv, model.nv),
        );
        let mut stepper = StepWorkspace::new(&model);
        let passive = PassiveForces::default();
        let counts = [
            (
                "step with derivatives (rk4)",
                allocations(|| {
                    stepper
                        .step(&model, q, v, a, 1e-3, Integrator::Rk4, &passive, true)
                        .unwrap();
                }),
            ),
            (
                "forward_kinematics",
                allocations(|| {
                    forward_kinematics(&model, &mut data, q).unwrap();
                }),
            ),
            (
                "jacobian",
                allocations(|| {
                    jacobian(&model, &mut data, q, frame, Reference::World).unwrap();
                }),
            ),
            (
                "rnea",
                allocations(|| {
                    rnea(&model, &mut data, q, v, a, Some(&f_ext)).unwrap();
                }),
            ),
            (
                "integrate_jacobians",
                allocations(|| {
                    robodyn::integrate::lie_group::integrate_jacobians(
                        &model,
                        q,
                        v,
                        &mut jacobians.0,
                        &mut jacobians.1,
                    )
                    .unwrap();
                }),
            ),
            (
                "torque_regressor",
                allocations(|| {
                    torque_regressor(&model, &mut data, q, v, a).unwrap();
                }),
            ),
            (
                "frame_motion_derivatives",
                allocations(|| {
                    frame_motion_derivatives(&model, &mut data, q, v, a, frame, Reference::Local)
                        .unwrap();
                }),
            ),
            (
                "center_of_mass_velocity_derivatives",
                allocations(|| {
                    center_of_mass_velocity_derivatives(&model, &mut data, q, v).unwrap();
                }),
            ),
            (
                "rnea_derivatives",
                allocations(|| {
                    rnea_derivatives(&model, &mut data, q, v, a, None, DerivativesInto::Data)
                        .unwrap();
                }),
            ),
            (
                "crba_into",
                allocations(|| {
                    crba_into(&model, &mut data, q, by_q).unwrap();
                }),
            ),
            (
                "rnea_derivatives into row-major buffers",
                allocations(|| {
                    let into = DerivativesInto::RowMajor { by_q, by_v };
                    rnea_derivatives(&model, &mut data, q, v, a, None, into).unwrap();
                }),
            ),
            (
                "aba_derivatives stacked",
                allocations(|| {
                    let into = DerivativesInto::Stacked(stacked);
                    aba_derivatives(&model, &mut data, q, v, a, None, into).unwrap();
                }),
            ),
            (
                "aba_derivatives",
                allocations(|| {
                    aba_derivatives(&model, &mut data, q, v, a, None, DerivativesInto::Data)
                        .unwrap();
                }),
            ),
            (
                "bias_forces",
                allocations(|| {
                    bias_forces(&model, &mut data, q, v).unwrap();
                }),
            ),
            (
                "generalized_gravity",
                allocations(|| {
                    generalized_gravity(&model, &mut data, q).unwrap();
                }),
            ),
            (
                "crba",
                allocations(|| {
                    crba(&model, &mut data, q).unwrap();
                }),
            ),
            (
                "aba",
                allocations(|| {
                    aba(&model, &mut data, q, v, a, Some(&f_ext)).unwrap();
                }),
            ),
            (
                "inverse_mass_matrix",
                allocations(|| {
                    inverse_mass_matrix(&model, &mut data, q).unwrap();
                }),
            ),
            (
                "kinetic_energy",
                allocations(|| {
                    kinetic_energy(&model, &mut data, q, v).unwrap();
                }),
            ),
            (
                "coriolis_matrix",
                allocations(|| {
                    coriolis_matrix(&model, &mut data, q, v).unwrap();
                }),
            ),
            (
                "christoffel_symbols",
                allocations(|| {
                    christoffel_symbols(&model, &mut data, q, &mut gamma).unwrap();
                }),
            ),
            (
                "mass_matrix_by_rnea",
                allocations(|| {
                    mass_matrix_by_rnea(&model, &mut data, q).unwrap();
                }),
            ),
            (
                "mass_matrix_by_jacobians",
                allocations(|| {
                    mass_matrix_by_jacobians(&model, &mut data, q).unwrap();
                }),
            ),
            (
                "generalized_gravity_by_jacobians",
                allocations(|| {
                    generalized_gravity_by_jacobians(&model, &mut data, q).unwrap();
                }),
            ),
            (
                "centroidal_momentum_matrix",
                allocations(|| {
                    centroidal_momentum_matrix(&model, &mut data, q).unwrap();
                }),
            ),
            (
                "center_of_mass",
                allocations(|| {
                    center_of_mass(&model, &mut data, q).unwrap();
                }),
            ),
        ];
        for (algorithm, count) in counts {
            assert_eq!(count, 0, "{name}: {algorithm} allocated {count} times");
        }
        if model.nv >= 6 {
            constrained_allocations(name, &model, &mut data, (q, v, a));
        }
        // a simulation allocates its buffers up front: ten times the steps, the same count
        for integrator in [
            Integrator::ExplicitEuler,
            Integrator::SemiImplicitEuler,
            Integrator::Rk4,
            Integrator::Rk45 {
                rtol: 1e-8,
                atol: 1e-8,
            },
        ] {
            let run = |t_end: f64| {
                let options = SimulationOptions::new(integrator, 1e-3, t_end);
                allocations(|| {
                    let mut pd = NativeController::new(
                        &model,
                        ControlLaw::Pd {
                            kp: DVector::from_element(model.nv, 0.1),
                            kd: DVector::from_element(model.nv, 0.01),
                            reference: DesiredMotion::Setpoint(model.neutral()),
                            gravity_compensation: true,
                        },
                        options.passive,
                        t_end,
                    )
                    .unwrap();
                    simulate(
                        &model,
                        q,
                        &vec![0.0; model.nv],
                        &options,
                        &mut pd,
                        None,
                        None,
                    )
                    .unwrap();
                })
            };
            let (short, long) = (run(0.01), run(0.1));
            assert_eq!(short, long, "{name}: {integrator:?} allocated per step");
        }
    }
}

/// Constrained forward dynamics and its derivatives allocate nothing after their workspaces are
/// made (the frame of the last body held: six independent rows on six or more coordinates, more
/// than the five below which nalgebra's products stay unblocked).
fn constrained_allocations(
    name: &str,
    model: &robodyn::Model,
    data: &mut Data,
    (q, v, tau): (&[f64], &[f64], &[f64]),
) {
    use robodyn::constraint::{Attachment, Constraint, ConstraintKind, ConstraintReference};
    let last = model.nbodies() - 1;
    let frame = model.frames.iter().position(|f| f.body == last).unwrap();
    let held = Constraint {
        kind: ConstraintKind::Frame {
            first: Attachment::at_frame(frame),
            second: None,
            mask: [true; 6],
        },
        reference: ConstraintReference::World,
    };
    let set = robodyn::constraint::ConstraintSet::new(model, vec![held]).unwrap();
    let mut c = ConstraintData::new(model, &set);
    let mut d = ConstrainedDerivatives::new(model, &set);
    let options = ConstrainedOptions::default();
    // a batch of two groups of the widest lanes and one state left over
    let n = 17;
    let (qs, vs, taus) = (q.repeat(n), v.repeat(n), tau.repeat(n));
    let states = States {
        q: &qs,
        v: Some(&vs),
        a: None,
        tau: Some(&taus),
    };
    let mut workspace = ConstrainedBatchWorkspace::new(model, &set);
    let mut out = vec![0.0; n * (model.nv + set.rows())];
    let counts = [
        (
            "constrained_forward_dynamics",
            allocations(|| {
                constrained_forward_dynamics(
                    model,
                    data,
                    &mut c,
                    &set,
                    (q, v, tau),
                    None,
                    &options,
                )
                .unwrap();
            }),
        ),
        (
            "constrained_forward_dynamics_derivatives",
            allocations(|| {
                let state = (q, v, tau);
                constrained_forward_dynamics_derivatives(
                    model, data, &mut c, &mut d, &set, state, None, 0.0,
                )
                .unwrap();
            }),
        ),
        (
            "constrained_forward_dynamics_batch",
            allocations(|| {
                let out = &mut out;
                constrained_forward_dynamics_batch(
                    model,
                    &mut workspace,
                    &set,
                    states,
                    &options,
                    out,
                )
                .unwrap();
            }),
        ),
    ];
    for (algorithm, count) in counts {
        assert_eq!(count, 0, "{name}: {algorithm} allocated {count} times");
    }
}
