//! Derivatives of constrained forward dynamics and of impulses: every column equals central
//! differences of the dynamics themselves, on every constraint kind in both references, with
//! external forces, on a closed four-bar, and on a closure stated twice (proximal mode).

mod common;

use common::constraints::*;
use common::*;
use nalgebra::{DMatrix, DVector};
use robodyn::algo::{
    constrained_forward_dynamics, constrained_forward_dynamics_derivatives, impulse_dynamics,
    impulse_dynamics_derivatives, ConstrainedDerivatives, ConstrainedOptions, ConstraintData,
};
use robodyn::constraint::ConstraintSet;
use robodyn::spatial::Force;
use robodyn::{Data, Model};

/// The step of the central differences in the proximal case, whose solutions are exact only to
/// the proximal accuracy (1e-12 of the terms): a larger step keeps that noise below the
/// truncation error O(h²) = 1e-8.
const PROXIMAL_STEP: f64 = 1e-4;
/// Their tolerance: the proximal noise over the step (1e-12 / 1e-4) and the truncation.
const PROXIMAL_TOLERANCE: f64 = 1e-6;

/// (q̈, λ) as one vector.
fn stacked(c: &ConstraintData) -> DVector<f64> {
    let mut out = DVector::zeros(c.qdd.len() + c.forces.len());
    out.rows_mut(0, c.qdd.len()).copy_from(&c.qdd);
    out.rows_mut(c.qdd.len(), c.forces.len())
        .copy_from(&c.forces);
    out
}

/// `[∂q̈/∂x; ∂λ/∂x]` against central differences of `f` along each unit step of x, moved by
/// `moved(x, step)`.
fn check_columns(
    label: &str,
    analytic: (&DMatrix<f64>, &DMatrix<f64>),
    mut f: impl FnMut(&DVector<f64>) -> DVector<f64>,
    moved: impl Fn(&DVector<f64>) -> DVector<f64>,
    (n, h, tolerance): (usize, f64, f64),
) {
    // central differences round to ε |f| / h (times the conditioning of M and of the Delassus
    // matrix): the tolerance is relative to the size of the values differenced too
    let size = f(&moved(&DVector::zeros(n))).amax();
    for k in 0..n {
        let step = unit_step(n, k, h);
        let difference = (f(&moved(&step)) - f(&moved(&(-&step)))) / (2.0 * h);
        let mut column = analytic.0.column(k).into_owned().as_slice().to_vec();
        column.extend(analytic.1.column(k).iter());
        let scale = size.max(difference.amax()).max(1.0);
        for (i, (a, b)) in column.iter().zip(difference.iter()).enumerate() {
            assert!(
                (a - b).abs() <= tolerance * scale,
                "{label}, column {k}, entry {i}: {a} vs {b} (tolerance {:e})",
                tolerance * scale
            );
        }
    }
}

/// q̈ and λ (or q̇⁺ and Λ) of two routes to them agree to this, relative to the largest of them.
const SAME_DYNAMICS: f64 = 1e-9;

fn assert_same_dynamics(label: &str, ours: &DVector<f64>, other: &DVector<f64>) {
    let scale = other.amax().max(1.0);
    let difference = (ours - other).amax();
    assert!(
        difference <= SAME_DYNAMICS * scale,
        "{label}: the derivatives' dynamics differ from the dynamics' own by {difference:e} \
         (scale {scale:e})"
    );
}

/// The derivatives at (q, q̇, τ) with their workspaces, and the options of the dynamics they
/// differentiate.
fn derivatives_at(
    model: &Model,
    set: &ConstraintSet,
    (q, v, tau): (&DVector<f64>, &DVector<f64>, &DVector<f64>),
    f_ext: Option<&[Force]>,
    damping: f64,
) -> (
    Data,
    ConstraintData,
    ConstrainedDerivatives,
    ConstrainedOptions,
) {
    let mut data = Data::new(model);
    let (mut c, mut d) = (
        ConstraintData::new(model, set),
        ConstrainedDerivatives::new(model, set),
    );
    let args = (q.as_slice(), v.as_slice(), tau.as_slice());
    constrained_forward_dynamics_derivatives(
        model, &mut data, &mut c, &mut d, set, args, f_ext, damping,
    )
    .unwrap();
    let options = ConstrainedOptions {
        baumgarte: None,
        damping,
    };
    (data, c, d, options)
}

/// The forward-dynamics derivatives at (q, q̇, τ) against differences in q, q̇ and τ.
fn check_forward(
    label: &str,
    model: &Model,
    set: &ConstraintSet,
    (q, v, tau): (&DVector<f64>, &DVector<f64>, &DVector<f64>),
    f_ext: Option<&[Force]>,
    (damping, h, tolerance): (f64, f64, f64),
) {
    let (mut data, c, d, options) = derivatives_at(model, set, (q, v, tau), f_ext, damping);
    let mut dynamics = |q: &DVector<f64>, v: &DVector<f64>, tau: &DVector<f64>| {
        let mut other = ConstraintData::new(model, set);
        let args = (q.as_slice(), v.as_slice(), tau.as_slice());
        constrained_forward_dynamics(model, &mut data, &mut other, set, args, f_ext, &options)
            .unwrap();
        stacked(&other)
    };
    // the derivatives solve q̈ and λ with M's factor, forward dynamics with ABA's terms
    assert_same_dynamics(label, &stacked(&c), &dynamics(q, v, tau));
    let nv = model.nv;
    let size = (nv, h, tolerance);
    check_columns(
        &format!("{label}: d/dq"),
        (&d.dqdd_dq, &d.dforces_dq),
        |x| dynamics(x, v, tau),
        |step| displaced(model, q, step),
        size,
    );
    check_columns(
        &format!("{label}: d/dv"),
        (&d.dqdd_dv, &d.dforces_dv),
        |x| dynamics(q, x, tau),
        |step| v + step,
        size,
    );
    check_columns(
        &format!("{label}: d/dtau"),
        (&d.dqdd_dtau, &d.dforces_dtau),
        |x| dynamics(q, v, x),
        |step| tau + step,
        size,
    );
}

/// Random forces on every moving body.
fn random_forces(model: &Model, rng: &mut rand::rngs::StdRng) -> Vec<Force> {
    (1..model.nbodies())
        .map(|_| {
            let f = random_vector(rng, 6);
            Force::new(f.fixed_rows::<3>(0).into(), f.fixed_rows::<3>(3).into())
        })
        .collect()
}

#[test]
fn forward_dynamics_derivatives_equal_finite_differences() {
    let mut rng = rng();
    for (name, model, constraints) in cases() {
        let set = ConstraintSet::new(&model, constraints).unwrap();
        for _ in 0..2 {
            let (q, v, tau) = state(&model, &mut rng);
            let exact = (0.0, FD_STEP, FD_TOLERANCE);
            check_forward(name, &model, &set, (&q, &v, &tau), None, exact);
            let forces = random_forces(&model, &mut rng);
            let label = format!("{name} with f_ext");
            check_forward(&label, &model, &set, (&q, &v, &tau), Some(&forces), exact);
        }
    }
}

#[test]
fn derivatives_on_a_closed_four_bar_and_on_its_closure_stated_twice() {
    let (model, set, q) = four_bar();
    let mut rng = rng();
    // a velocity the loop allows: the crank's, the others from J q̇ = 0
    let mut data = Data::new(&model);
    let mut c = ConstraintData::new(&model, &set);
    robodyn::algo::constraint_jacobian(&model, &mut data, &mut c, &set, q.as_slice()).unwrap();
    let free = c.jacobian.columns(1, 2).into_owned();
    let rest = free.lu().solve(&(-c.jacobian.column(0) * 2.0)).unwrap();
    let v = DVector::from_vec(vec![2.0, rest[0], rest[1]]);
    let tau = random_vector(&mut rng, model.nv);
    let exact = (0.0, FD_STEP, FD_TOLERANCE);
    check_forward("four-bar", &model, &set, (&q, &v, &tau), None, exact);

    let twice = [set.constraints(), set.constraints()].concat();
    let twice = ConstraintSet::new(&model, twice).unwrap();
    let proximal = (1e-6, PROXIMAL_STEP, PROXIMAL_TOLERANCE);
    check_forward_accelerations("four-bar twice", &model, &twice, (&q, &v, &tau), proximal);
}

/// With a redundant set only q̈ is unique: its derivatives against differences, and the
/// forces' derivatives through what reaches the robot, Jᵀ dλ.
fn check_forward_accelerations(
    label: &str,
    model: &Model,
    set: &ConstraintSet,
    (q, v, tau): (&DVector<f64>, &DVector<f64>, &DVector<f64>),
    (damping, h, tolerance): (f64, f64, f64),
) {
    let (mut data, c, d, options) = derivatives_at(model, set, (q, v, tau), None, damping);
    let jacobian = c.jacobian.clone();
    let mut generalized = |q: &DVector<f64>, v: &DVector<f64>| {
        let mut other = ConstraintData::new(model, set);
        let args = (q.as_slice(), v.as_slice(), tau.as_slice());
        constrained_forward_dynamics(model, &mut data, &mut other, set, args, None, &options)
            .unwrap();
        // q̈ and Jᵀλ with J held at the point of differentiation (its own change is not dλ's)
        let mut out = DVector::zeros(2 * model.nv);
        out.rows_mut(0, model.nv).copy_from(&other.qdd);
        out.rows_mut(model.nv, model.nv)
            .copy_from(&(jacobian.transpose() * &other.forces));
        out
    };
    let nv = model.nv;
    let by_v = jacobian.transpose() * &d.dforces_dv;
    check_columns(
        &format!("{label}: d/dv"),
        (&d.dqdd_dv, &by_v),
        |x| generalized(q, x),
        |step| v + step,
        (nv, h, tolerance),
    );
    let by_q = jacobian.transpose() * &d.dforces_dq;
    check_columns(
        &format!("{label}: d/dq"),
        (&d.dqdd_dq, &by_q),
        |x| generalized(x, v),
        |step| displaced(model, q, step),
        (nv, h, tolerance),
    );
}

#[test]
fn impulse_derivatives_equal_finite_differences() {
    let mut rng = rng();
    for (name, model, constraints) in cases() {
        let set = ConstraintSet::new(&model, constraints).unwrap();
        let (q, v, _) = state(&model, &mut rng);
        for restitution in [0.0, 0.4] {
            let mut data = Data::new(&model);
            let (mut c, mut d) = (
                ConstraintData::new(&model, &set),
                ConstrainedDerivatives::new(&model, &set),
            );
            let args = (q.as_slice(), v.as_slice());
            impulse_dynamics_derivatives(
                &model,
                &mut data,
                &mut c,
                &mut d,
                &set,
                args,
                restitution,
                0.0,
            )
            .unwrap();
            let mut impulses = |q: &DVector<f64>, v: &DVector<f64>| {
                let mut other = ConstraintData::new(&model, &set);
                let args = (q.as_slice(), v.as_slice());
                impulse_dynamics(&model, &mut data, &mut other, &set, args, restitution, 0.0)
                    .unwrap();
                stacked(&other)
            };
            let label = format!("{name} impulses, e = {restitution}");
            assert_same_dynamics(&label, &stacked(&c), &impulses(&q, &v));
            let size = (model.nv, FD_STEP, FD_TOLERANCE);
            check_columns(
                &format!("{label}: d/dq"),
                (&d.dqdd_dq, &d.dforces_dq),
                |x| impulses(x, &v),
                |step| displaced(&model, &q, step),
                size,
            );
            check_columns(
                &format!("{label}: d/dv"),
                (&d.dqdd_dv, &d.dforces_dv),
                |x| impulses(&q, x),
                |step| &v + step,
                size,
            );
        }
    }
}

#[test]
fn a_workspace_for_another_set_is_refused() {
    let model = test_model("tree");
    let set = ConstraintSet::new(&model, tree_constraints(&model)).unwrap();
    let one = ConstraintSet::new(&model, tree_constraints(&model)[..1].to_vec()).unwrap();
    let mut data = Data::new(&model);
    let (mut c, mut d) = (
        ConstraintData::new(&model, &set),
        ConstrainedDerivatives::new(&model, &one),
    );
    let (q, v, tau) = state(&model, &mut rng());
    let args = (q.as_slice(), v.as_slice(), tau.as_slice());
    let error = constrained_forward_dynamics_derivatives(
        &model, &mut data, &mut c, &mut d, &set, args, None, 0.0,
    )
    .unwrap_err()
    .to_string();
    assert!(error.contains("derivatives"), "{error}");
}
