//! Jacobians of q ⊕ v and q₁ ⊖ q₀ against central finite differences on the Lie group, on every
//! test model (free and spherical joints included), at small and ordinary angles.

mod common;

use common::*;
use nalgebra::{DMatrix, DVector};
use robodyn::integrate::lie_group::{difference_jacobians, integrate_jacobians};
use robodyn::Model;

/// Central differences with step FD_STEP: truncation h² and round-off ε/h, both near 1e-10 here.
const LIE_FD_TOLERANCE: f64 = 1e-7;

/// (f(q ⊕ h e_k) ⊖ f(q ⊕ −h e_k)) / 2h for every k, with ⊖ taken at f(q): an nv × nv Jacobian.
fn tangent_jacobian(
    model: &Model,
    q: &DVector<f64>,
    f: impl Fn(&DVector<f64>) -> DVector<f64>,
) -> DMatrix<f64> {
    let centre = f(q);
    let mut jacobian = DMatrix::zeros(model.nv, model.nv);
    for k in 0..model.nv {
        let mut column = DVector::zeros(model.nv);
        for (sign, h) in [(1.0, FD_STEP), (-1.0, -FD_STEP)] {
            let moved = f(&displaced(model, q, &unit_step(model.nv, k, h)));
            let mut delta = DVector::zeros(model.nv);
            model
                .difference(centre.as_slice(), moved.as_slice(), delta.as_mut_slice())
                .unwrap();
            column += delta * (sign / (2.0 * FD_STEP));
        }
        jacobian.set_column(k, &column);
    }
    jacobian
}

#[test]
fn integrate_and_difference_jacobians_are_finite_differences() {
    let mut rng = rng();
    for (name, model) in test_models() {
        let nv = model.nv;
        for scale in [1e-3, 0.02, 1.0] {
            let q = model.random_configuration(&mut rng);
            let v = random_vector(&mut rng, nv) * scale;
            let q1 = displaced(&model, &q, &v);
            let integrate = |q: &DVector<f64>, v: &DVector<f64>| displaced(&model, q, v);
            let (mut d_q, mut d_v) = (DMatrix::zeros(nv, nv), DMatrix::zeros(nv, nv));
            integrate_jacobians(&model, q.as_slice(), v.as_slice(), &mut d_q, &mut d_v).unwrap();
            let fd_q = tangent_jacobian(&model, &q, |q| integrate(q, &v));
            // v moves in a vector space: perturb it directly
            let mut fd_v = DMatrix::zeros(nv, nv);
            for k in 0..nv {
                let step = unit_step(nv, k, FD_STEP);
                let (plus, minus) = (integrate(&q, &(&v + &step)), integrate(&q, &(&v - &step)));
                let (mut up, mut down) = (DVector::zeros(nv), DVector::zeros(nv));
                model
                    .difference(q1.as_slice(), plus.as_slice(), up.as_mut_slice())
                    .unwrap();
                model
                    .difference(q1.as_slice(), minus.as_slice(), down.as_mut_slice())
                    .unwrap();
                fd_v.set_column(k, &((up - down) / (2.0 * FD_STEP)));
            }
            let label = |what: &str| format!("{name} (|v| ~ {scale}): {what}");
            assert_close(
                &label("d(q+v)/dq"),
                d_q.as_slice(),
                fd_q.as_slice(),
                LIE_FD_TOLERANCE,
            );
            assert_close(
                &label("d(q+v)/dv"),
                d_v.as_slice(),
                fd_v.as_slice(),
                LIE_FD_TOLERANCE,
            );

            let difference = |q0: &DVector<f64>, q1: &DVector<f64>| {
                let mut out = DVector::zeros(nv);
                model
                    .difference(q0.as_slice(), q1.as_slice(), out.as_mut_slice())
                    .unwrap();
                out
            };
            let (mut d_q0, mut d_q1) = (DMatrix::zeros(nv, nv), DMatrix::zeros(nv, nv));
            difference_jacobians(&model, q.as_slice(), q1.as_slice(), &mut d_q0, &mut d_q1)
                .unwrap();
            // the difference is a vector: plain central differences of it along each tangent
            let fd_difference = |moving_first: bool| {
                let mut jacobian = DMatrix::zeros(nv, nv);
                for k in 0..nv {
                    let at = |h: f64| {
                        let step = unit_step(nv, k, h);
                        if moving_first {
                            difference(&displaced(&model, &q, &step), &q1)
                        } else {
                            difference(&q, &displaced(&model, &q1, &step))
                        }
                    };
                    jacobian.set_column(k, &((at(FD_STEP) - at(-FD_STEP)) / (2.0 * FD_STEP)));
                }
                jacobian
            };
            assert_close(
                &label("d(q1-q0)/dq0"),
                d_q0.as_slice(),
                fd_difference(true).as_slice(),
                LIE_FD_TOLERANCE,
            );
            assert_close(
                &label("d(q1-q0)/dq1"),
                d_q1.as_slice(),
                fd_difference(false).as_slice(),
                LIE_FD_TOLERANCE,
            );
        }
    }
}
