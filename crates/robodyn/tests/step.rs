//! One simulation step and its Jacobians A = ∂x₁/∂x₀, B = ∂x₁/∂τ: the step is the simulator's, and
//! A, B are central finite differences of the step (q on the Lie group), for explicit Euler,
//! semi-implicit Euler and RK4, with springs, damping, friction and a joint-limit penalty acting.

mod common;

use common::*;
use nalgebra::{DMatrix, DVector};
use robodyn::integrate::lie_group::{tangent_rate, tangent_rate_jacobians};
use robodyn::integrate::{
    simulate, ControlLaw, Integrator, LimitModel, NativeController, PassiveForces,
    SimulationOptions, StepWorkspace,
};
use robodyn::Model;

/// Central differences of one step with step FD_STEP; the step's map is smooth and of order 1.
const STEP_FD_TOLERANCE: f64 = 1e-6;
const STEP: f64 = 0.01;

const INTEGRATORS: [Integrator; 3] = [
    Integrator::ExplicitEuler,
    Integrator::SemiImplicitEuler,
    Integrator::Rk4,
];

/// The test models with passive forces on every joint: springs pulling towards a reference,
/// damping and smoothed friction.
fn models_with_passive_forces() -> Vec<(&'static str, Model)> {
    let mut rng = rng();
    test_models()
        .into_iter()
        .map(|(name, mut model)| {
            model.stiffness.fill(3.0);
            model.damping.fill(0.4);
            model.friction.fill(0.2);
            model.spring_reference = model.random_configuration(&mut rng);
            (name, model)
        })
        .collect()
}

/// Puts every other limited revolute or prismatic joint 0.05 past its upper limit, where the
/// penalty −k δ − b q̇ pushes back for |q̇| < 1.25 (k = 50, b = 2).
fn push_past_upper_limits(model: &Model, q: &mut DVector<f64>) {
    for i in (1..model.nbodies()).step_by(2) {
        let index = model.idx_q()[i];
        let upper = model.upper_position_limit[index];
        if model.joints()[i].nq() == 1 && upper.is_finite() {
            q[index] = upper + 0.05;
        }
    }
}

/// x₁ = (q₁, v₁) of one step.
fn step(
    model: &Model,
    workspace: &mut StepWorkspace,
    (q, v, tau): (&DVector<f64>, &DVector<f64>, &DVector<f64>),
    (h, integrator): (f64, Integrator),
    passive: &PassiveForces,
) -> (DVector<f64>, DVector<f64>) {
    workspace
        .step(
            model,
            q.as_slice(),
            v.as_slice(),
            tau.as_slice(),
            h,
            integrator,
            passive,
            false,
        )
        .unwrap();
    (
        DVector::from_column_slice(&workspace.q_end),
        DVector::from_column_slice(&workspace.v_end),
    )
}

#[test]
fn step_jacobians_are_finite_differences() {
    let mut rng = rng();
    let passive = PassiveForces {
        limits: LimitModel::Penalty {
            stiffness: 50.0,
            damping: 2.0,
        },
        ..PassiveForces::default()
    };
    for (name, model) in models_with_passive_forces() {
        let nv = model.nv;
        let mut workspace = StepWorkspace::new(&model);
        for integrator in INTEGRATORS {
            let (mut q, v, tau) = state(&model, &mut rng);
            push_past_upper_limits(&model, &mut q);
            workspace
                .step(
                    &model,
                    q.as_slice(),
                    v.as_slice(),
                    tau.as_slice(),
                    STEP,
                    integrator,
                    &passive,
                    true,
                )
                .unwrap();
            let (a, b) = (workspace.a.clone(), workspace.b.clone());
            let (q1, _) = step(
                &model,
                &mut workspace,
                (&q, &v, &tau),
                (STEP, integrator),
                &passive,
            );
            // column k: (x₁(+h) ⊖ x₁(−h)) / 2h, q₁ differenced on the group at the central q₁
            let mut fd = DMatrix::zeros(2 * nv, 3 * nv);
            for k in 0..3 * nv {
                let moved = |h: f64| {
                    let mut inputs = (q.clone(), v.clone(), tau.clone());
                    match k / nv {
                        0 => inputs.0 = displaced(&model, &q, &unit_step(nv, k, h)),
                        1 => inputs.1 += unit_step(nv, k - nv, h),
                        _ => inputs.2 += unit_step(nv, k - 2 * nv, h),
                    }
                    inputs
                };
                let (plus, minus) = (moved(FD_STEP), moved(-FD_STEP));
                let (q_plus, v_plus) = step(
                    &model,
                    &mut workspace,
                    (&plus.0, &plus.1, &plus.2),
                    (STEP, integrator),
                    &passive,
                );
                let (q_minus, v_minus) = step(
                    &model,
                    &mut workspace,
                    (&minus.0, &minus.1, &minus.2),
                    (STEP, integrator),
                    &passive,
                );
                let (mut up, mut down) = (DVector::zeros(nv), DVector::zeros(nv));
                model
                    .difference(q1.as_slice(), q_plus.as_slice(), up.as_mut_slice())
                    .unwrap();
                model
                    .difference(q1.as_slice(), q_minus.as_slice(), down.as_mut_slice())
                    .unwrap();
                let column = DVector::from_iterator(
                    2 * nv,
                    (up - down).iter().chain((v_plus - v_minus).iter()).copied(),
                ) / (2.0 * FD_STEP);
                fd.set_column(k, &column);
            }
            let label = |what: &str| format!("{name} {integrator:?}: {what}");
            let (fd_a, fd_b) = (
                fd.columns(0, 2 * nv).into_owned(),
                fd.columns(2 * nv, nv).into_owned(),
            );
            assert_close(
                &label("A"),
                a.as_slice(),
                fd_a.as_slice(),
                STEP_FD_TOLERANCE,
            );
            assert_close(
                &label("B"),
                b.as_slice(),
                fd_b.as_slice(),
                STEP_FD_TOLERANCE,
            );
        }
    }
}

#[test]
fn a_step_is_the_simulators_step() {
    let mut rng = rng();
    for (name, model) in models_with_passive_forces() {
        let mut workspace = StepWorkspace::new(&model);
        for integrator in INTEGRATORS {
            let (q, v, tau) = state(&model, &mut rng);
            // a step small enough for the simulator's divergence check on the damped wrists
            let dt = 1e-5;
            let mut options = SimulationOptions::new(integrator, dt, dt);
            options.passive = PassiveForces::default();
            let mut controller = NativeController::new(
                &model,
                ControlLaw::Constant(tau.clone()),
                options.passive,
                options.t_end,
            )
            .unwrap();
            let run = simulate(
                &model,
                q.as_slice(),
                v.as_slice(),
                &options,
                &mut controller,
                None,
                None,
            )
            .unwrap();
            let (q1, v1) = step(
                &model,
                &mut workspace,
                (&q, &v, &tau),
                (dt, integrator),
                &options.passive,
            );
            let label = format!("{name} {integrator:?}");
            assert_close(&label, q1.as_slice(), &run.q[model.nq..2 * model.nq], 1e-14);
            assert_close(&label, v1.as_slice(), &run.v[model.nv..2 * model.nv], 1e-14);
        }
    }
}

#[test]
fn a_step_refuses_an_adaptive_scheme_and_a_bad_step() {
    let model = robodyn::io::bundled_model("pendulum", false).unwrap();
    let mut workspace = StepWorkspace::new(&model);
    let passive = PassiveForces::default();
    let adaptive = Integrator::Rk45 {
        rtol: 1e-6,
        atol: 1e-9,
    };
    let error = workspace
        .step(
            &model,
            &[0.1],
            &[0.0],
            &[0.0],
            0.01,
            adaptive,
            &passive,
            true,
        )
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("integrator") && error.contains("rk45"),
        "{error}"
    );
    let error = workspace
        .step(
            &model,
            &[0.1],
            &[0.0],
            &[0.0],
            -0.01,
            Integrator::Rk4,
            &passive,
            true,
        )
        .unwrap_err()
        .to_string();
    assert!(error.contains("dt") && error.contains("-0.01"), "{error}");
}

#[test]
fn tangent_rate_jacobians_are_finite_differences() {
    let mut rng = rng();
    for (name, model) in test_models() {
        let nv = model.nv;
        for scale in [1e-3, 0.3, 1.5] {
            let (xi, v) = (
                random_vector(&mut rng, nv) * scale,
                random_vector(&mut rng, nv),
            );
            let (mut d_xi, mut d_v) = (DMatrix::zeros(nv, nv), DMatrix::zeros(nv, nv));
            tangent_rate_jacobians(&model, xi.as_slice(), v.as_slice(), &mut d_xi, &mut d_v)
                .unwrap();
            let rate = |xi: &DVector<f64>, v: &DVector<f64>| {
                let mut out = DVector::zeros(nv);
                tangent_rate(&model, xi.as_slice(), v.as_slice(), out.as_mut_slice());
                out
            };
            let mut fd = (DMatrix::zeros(nv, nv), DMatrix::zeros(nv, nv));
            for k in 0..nv {
                let e = unit_step(nv, k, FD_STEP);
                fd.0.set_column(
                    k,
                    &((rate(&(&xi + &e), &v) - rate(&(&xi - &e), &v)) / (2.0 * FD_STEP)),
                );
                fd.1.set_column(
                    k,
                    &((rate(&xi, &(&v + &e)) - rate(&xi, &(&v - &e))) / (2.0 * FD_STEP)),
                );
            }
            let label = format!("{name} |xi| ~ {scale}");
            assert_close(&label, d_xi.as_slice(), fd.0.as_slice(), FD_TOLERANCE);
            assert_close(&label, d_v.as_slice(), fd.1.as_slice(), FD_TOLERANCE);
        }
    }
}
