//! Derivatives of RNEA and ABA against central finite differences (q perturbed on the Lie group,
//! q ⊕ h e_k), on every test model, with and without external forces and armature on a free joint.

mod common;

use common::*;
use nalgebra::{DMatrix, DVector};
use robodyn::algo::{
    aba, aba_derivatives, center_of_mass_jacobian, center_of_mass_velocity_derivatives,
    frame_acceleration, frame_motion_derivatives, frame_velocity, inverse_mass_matrix, rnea,
    rnea_derivatives, DerivativesInto, Reference,
};
use robodyn::spatial::{Force, Vec3};
use robodyn::{Data, Model};

/// Central differences of τ or q̈ with step FD_STEP: truncation h² |f'''| and round-off ε |f| / h
/// are both below 1e-8 for these models' magnitudes.
const DYNAMICS_FD_TOLERANCE: f64 = 1e-6;

/// Column k of the result: (f(x + h e_k) − f(x − h e_k)) / 2h, with `moved(k, h)` the input moved.
fn central_differences(nv: usize, mut f: impl FnMut(usize, f64) -> DVector<f64>) -> DMatrix<f64> {
    let mut jacobian = DMatrix::zeros(nv, nv);
    for k in 0..nv {
        let column = (f(k, FD_STEP) - f(k, -FD_STEP)) / (2.0 * FD_STEP);
        jacobian.set_column(k, &column);
    }
    jacobian
}

/// The test models, plus the tree with armature on its free joint (the rotor's velocity term).
fn models() -> Vec<(&'static str, Model)> {
    let mut models = test_models();
    let (_, tree) = models.iter().find(|(name, _)| *name == "tree").unwrap();
    let mut free_rotor = tree.clone();
    free_rotor.armature.as_mut_slice()[..3].fill(0.3);
    free_rotor.armature.as_mut_slice()[3..6].fill(0.1);
    models.push(("tree with free-joint armature", free_rotor));
    models
}

fn random_forces(model: &Model, rng: &mut rand::rngs::StdRng) -> Vec<Force> {
    (1..model.nbodies())
        .map(|_| {
            let w = random_vector(rng, 6);
            Force::new(Vec3::new(w[0], w[1], w[2]), Vec3::new(w[3], w[4], w[5]))
        })
        .collect()
}

/// The dynamics function under test: its value and its three derivatives (∂/∂q, ∂/∂v, ∂/∂x) as
/// computed at (q, v, x), and a plain evaluation f(q, v, x).
struct Linearised {
    value: DVector<f64>,
    derivatives: [DMatrix<f64>; 3],
}

/// A dynamics function (q, v, x, f_ext) of a model in its workspace.
type DynamicsFunction<T> = fn(&Model, &mut Data, &[f64], &[f64], &[f64], Option<&[Force]>) -> T;

/// Checks `linearise(q, v, x)` against `f` at random states, with and without external forces.
fn check_against_differences(
    what: [&str; 4],
    linearise: DynamicsFunction<Linearised>,
    f: DynamicsFunction<DVector<f64>>,
) {
    let mut rng = rng();
    for (name, model) in models() {
        let mut data = Data::new(&model);
        let nv = model.nv;
        for with_forces in [false, true] {
            let (q, v, x) = state(&model, &mut rng);
            let forces = random_forces(&model, &mut rng);
            let f_ext = with_forces.then_some(&forces[..]);
            let linearised = linearise(
                &model,
                &mut data,
                q.as_slice(),
                v.as_slice(),
                x.as_slice(),
                f_ext,
            );
            let mut f_at = |q: &DVector<f64>, v: &DVector<f64>, x: &DVector<f64>| {
                f(
                    &model,
                    &mut data,
                    q.as_slice(),
                    v.as_slice(),
                    x.as_slice(),
                    f_ext,
                )
            };
            let label = |what: &str| format!("{name} (f_ext: {with_forces}): {what}");
            let value = f_at(&q, &v, &x);
            assert_close(
                &label(what[0]),
                linearised.value.as_slice(),
                value.as_slice(),
                1e-12,
            );
            let differences = [
                central_differences(nv, |k, h| {
                    f_at(&displaced(&model, &q, &unit_step(nv, k, h)), &v, &x)
                }),
                central_differences(nv, |k, h| f_at(&q, &(&v + unit_step(nv, k, h)), &x)),
                central_differences(nv, |k, h| f_at(&q, &v, &(&x + unit_step(nv, k, h)))),
            ];
            for ((what, ours), differences) in what[1..]
                .iter()
                .zip(&linearised.derivatives)
                .zip(&differences)
            {
                assert_close(
                    &label(what),
                    ours.as_slice(),
                    differences.as_slice(),
                    DYNAMICS_FD_TOLERANCE,
                );
            }
        }
    }
}

#[test]
fn rnea_derivatives_are_finite_differences() {
    check_against_differences(
        ["tau", "dtau/dq", "dtau/dv", "dtau/da"],
        |model, data, q, v, a, f_ext| {
            rnea_derivatives(model, data, q, v, a, f_ext, DerivativesInto::Data).unwrap();
            Linearised {
                value: data.tau.clone(),
                derivatives: [
                    data.dtau_dq.clone(),
                    data.dtau_dv.clone(),
                    data.mass_matrix.clone(),
                ],
            }
        },
        |model, data, q, v, a, f_ext| rnea(model, data, q, v, a, f_ext).unwrap().clone(),
    );
}

/// Every destination of the derivatives against `Data`'s matrices: the same operations into
/// another layout, so equal bit for bit; a buffer of the wrong length is refused, naming it.
#[test]
fn every_destination_holds_the_matrices() {
    let mut rng = rng();
    for (name, model) in models() {
        let (mut data, nv) = (Data::new(&model), model.nv);
        let (q, v, x) = state(&model, &mut rng);
        let forces = random_forces(&model, &mut rng);
        let (q, v, x, f_ext) = (q.as_slice(), v.as_slice(), x.as_slice(), Some(&forces[..]));
        let row_major = |m: &DMatrix<f64>| m.transpose().as_slice().to_vec();
        type Run<'r> = &'r dyn Fn(&mut Data, DerivativesInto) -> robodyn::Result<()>;
        let rnea: Run = &|data, into| rnea_derivatives(&model, data, q, v, x, f_ext, into);
        let aba: Run = &|data, into| aba_derivatives(&model, data, q, v, x, f_ext, into);
        for (algorithm, run, names) in [
            ("rnea", rnea, ["dtau_dq", "dtau_dv"]),
            ("aba", aba, ["dqdd_dq", "dqdd_dv"]),
        ] {
            run(&mut data, DerivativesInto::Data).unwrap();
            let matrices = match algorithm {
                "rnea" => [&data.dtau_dq, &data.dtau_dv, &data.mass_matrix],
                _ => [&data.dqdd_dq, &data.dqdd_dv, &data.mass_matrix_inverse],
            }
            .map(row_major);
            let (tau, qdd) = (data.tau.clone(), data.qdd.clone());

            let (mut by_q, mut by_v) = (vec![f64::NAN; nv * nv], vec![f64::NAN; nv * nv]);
            let into = DerivativesInto::RowMajor {
                by_q: &mut by_q,
                by_v: &mut by_v,
            };
            run(&mut data, into).unwrap();
            assert_eq!(by_q, matrices[0], "{name} {algorithm}: by q");
            assert_eq!(by_v, matrices[1], "{name} {algorithm}: by v");

            let mut stacked = vec![f64::NAN; 3 * nv * nv];
            run(&mut data, DerivativesInto::Stacked(&mut stacked)).unwrap();
            assert_eq!(stacked, matrices.concat(), "{name} {algorithm}: stacked");
            assert_eq!((&tau, &qdd), (&data.tau, &data.qdd), "{name} {algorithm}");

            let into = DerivativesInto::RowMajor {
                by_q: &mut by_q,
                by_v: &mut [],
            };
            let error = run(&mut data, into).unwrap_err().to_string();
            assert!(
                error.contains(names[1]) && error.contains("length 0"),
                "{error}"
            );
            let error = run(&mut data, DerivativesInto::Stacked(&mut [0.0]))
                .unwrap_err()
                .to_string();
            assert!(
                error.contains("out") && error.contains("length 1"),
                "{error}"
            );
        }
    }
}

#[test]
fn aba_derivatives_are_finite_differences() {
    check_against_differences(
        ["qdd", "dqdd/dq", "dqdd/dv", "dqdd/dtau"],
        |model, data, q, v, tau, f_ext| {
            aba_derivatives(model, data, q, v, tau, f_ext, DerivativesInto::Data).unwrap();
            let linearised = Linearised {
                value: data.qdd.clone(),
                derivatives: [
                    data.dqdd_dq.clone(),
                    data.dqdd_dv.clone(),
                    data.mass_matrix_inverse.clone(),
                ],
            };
            // ∂q̈/∂τ is M⁻¹ exactly
            let minv = inverse_mass_matrix(model, data, q).unwrap();
            assert_close(
                "M⁻¹",
                linearised.derivatives[2].as_slice(),
                minv.as_slice(),
                IDENTITY_TOLERANCE,
            );
            linearised
        },
        |model, data, q, v, tau, f_ext| aba(model, data, q, v, tau, f_ext).unwrap().clone(),
    );
}

#[test]
fn frame_motion_derivatives_are_finite_differences() {
    let mut rng = rng();
    for (name, model) in models() {
        let mut data = Data::new(&model);
        let nv = model.nv;
        let (q, v, a) = state(&model, &mut rng);
        for frame in [model.frames.len() - 1, model.frames.len() / 2] {
            for reference in [Reference::World, Reference::Local, Reference::Spatial] {
                frame_motion_derivatives(
                    &model,
                    &mut data,
                    q.as_slice(),
                    v.as_slice(),
                    a.as_slice(),
                    frame,
                    reference,
                )
                .unwrap();
                let ours = [
                    data.frame_velocity_dq.clone(),
                    data.jacobian.clone(),
                    data.frame_acceleration_dq.clone(),
                    data.frame_acceleration_dv.clone(),
                    data.jacobian.clone(),
                ];
                let mut motion = |q: &DVector<f64>, v: &DVector<f64>, a: &DVector<f64>| {
                    let (q, v, a) = (q.as_slice(), v.as_slice(), a.as_slice());
                    let velocity =
                        frame_velocity(&model, &mut data, q, v, frame, reference).unwrap();
                    let acceleration =
                        frame_acceleration(&model, &mut data, q, v, a, frame, reference).unwrap();
                    (
                        DVector::from_row_slice(&velocity),
                        DVector::from_row_slice(&acceleration),
                    )
                };
                let mut differences = |moved: &dyn Fn(usize, f64) -> [DVector<f64>; 3]| {
                    let mut jacobians = (DMatrix::zeros(6, nv), DMatrix::zeros(6, nv));
                    for k in 0..nv {
                        let [q1, v1, a1] = moved(k, FD_STEP);
                        let [q0, v0, a0] = moved(k, -FD_STEP);
                        let (plus, minus) = (motion(&q1, &v1, &a1), motion(&q0, &v0, &a0));
                        jacobians
                            .0
                            .set_column(k, &((plus.0 - minus.0) / (2.0 * FD_STEP)));
                        jacobians
                            .1
                            .set_column(k, &((plus.1 - minus.1) / (2.0 * FD_STEP)));
                    }
                    jacobians
                };
                let by_q = differences(&|k, h| {
                    [
                        displaced(&model, &q, &unit_step(nv, k, h)),
                        v.clone(),
                        a.clone(),
                    ]
                });
                let by_v = differences(&|k, h| [q.clone(), &v + unit_step(nv, k, h), a.clone()]);
                let by_a = differences(&|k, h| [q.clone(), v.clone(), &a + unit_step(nv, k, h)]);
                let expected = [by_q.0, by_v.0, by_q.1, by_v.1, by_a.1];
                let what = ["dv/dq", "dv/dv", "da/dq", "da/dv", "da/da"];
                for ((what, ours), expected) in what.iter().zip(&ours).zip(&expected) {
                    assert_close(
                        &format!("{name} frame {frame} {reference:?}: {what}"),
                        ours.as_slice(),
                        expected.as_slice(),
                        DYNAMICS_FD_TOLERANCE,
                    );
                }
            }
        }
    }
}

#[test]
fn center_of_mass_velocity_derivatives_are_finite_differences() {
    let mut rng = rng();
    for (name, model) in models() {
        let mut data = Data::new(&model);
        let nv = model.nv;
        let (q, v, _) = state(&model, &mut rng);
        center_of_mass_velocity_derivatives(&model, &mut data, q.as_slice(), v.as_slice()).unwrap();
        let (ours_q, ours_v) = (
            data.com_velocity_dq.clone(),
            data.jacobian.rows(0, 3).into_owned(),
        );
        let mut com_velocity = |q: &DVector<f64>, v: &DVector<f64>| {
            center_of_mass_jacobian(&model, &mut data, q.as_slice())
                .unwrap()
                .rows(0, 3)
                * v
        };
        let mut by_q = DMatrix::zeros(3, nv);
        let mut by_v = DMatrix::zeros(3, nv);
        for k in 0..nv {
            let step = unit_step(nv, k, FD_STEP);
            let (plus, minus) = (displaced(&model, &q, &step), displaced(&model, &q, &-&step));
            by_q.set_column(
                k,
                &((com_velocity(&plus, &v) - com_velocity(&minus, &v)) / (2.0 * FD_STEP)),
            );
            by_v.set_column(
                k,
                &((com_velocity(&q, &(&v + &step)) - com_velocity(&q, &(&v - &step)))
                    / (2.0 * FD_STEP)),
            );
        }
        assert_close(
            &format!("{name}: dcom/dq"),
            ours_q.as_slice(),
            by_q.as_slice(),
            DYNAMICS_FD_TOLERANCE,
        );
        assert_close(
            &format!("{name}: dcom/dv"),
            ours_v.as_slice(),
            by_v.as_slice(),
            DYNAMICS_FD_TOLERANCE,
        );
    }
}
