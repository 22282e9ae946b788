//! Identities between the kinematics algorithms and the dynamics they feed, on every test model
//! (DESIGN.md, "How we know it is right" 4): Jacobians as derivatives of poses, J̇, frame
//! velocities and accelerations, the centre of mass, external forces through Jᵀ, integrate and
//! difference.

mod common;

use common::*;
use nalgebra::DVector;
use robodyn::algo::*;
use robodyn::Data;

#[test]
fn jacobian_is_the_derivative_of_forward_kinematics() {
    let mut rng = rng();
    for (name, model) in test_models() {
        let mut data = Data::new(&model);
        let q = model.random_configuration(&mut rng);
        for frame in 0..model.frames.len() {
            let world = jacobian(&model, &mut data, q.as_slice(), frame, Reference::World)
                .unwrap()
                .clone();
            let local = jacobian(&model, &mut data, q.as_slice(), frame, Reference::Local)
                .unwrap()
                .clone();
            let spatial = jacobian(&model, &mut data, q.as_slice(), frame, Reference::Spatial)
                .unwrap()
                .clone();
            forward_kinematics(&model, &mut data, q.as_slice()).unwrap();
            let pose = frame_placement(&model, &data, frame);
            // the support-only pose equals the one from full forward kinematics
            let direct = frame_pose(&model, &mut Data::new(&model), q.as_slice(), frame).unwrap();
            assert_close(
                &format!("{name}: frame_pose"),
                direct.to_homogeneous().as_slice(),
                pose.to_homogeneous().as_slice(),
                0.0,
            );
            let rotation = pose.rotation.transpose();
            for k in 0..model.nv {
                let pose_at = |h: f64, data: &mut Data| {
                    let moved = displaced(&model, &q, &unit_step(model.nv, k, h));
                    forward_kinematics(&model, data, moved.as_slice()).unwrap();
                    frame_placement(&model, data, frame)
                };
                let (plus, minus) = (pose_at(FD_STEP, &mut data), pose_at(-FD_STEP, &mut data));
                // linear: ṗ;  angular: from Ṙ Rᵀ = ω×
                let p_dot = (plus.translation - minus.translation) / (2.0 * FD_STEP);
                let r_dot =
                    (plus.rotation.transpose() - minus.rotation.transpose()) / (2.0 * FD_STEP);
                let omega_hat = r_dot * rotation.transpose();
                let omega =
                    nalgebra::Vector3::new(omega_hat[(2, 1)], omega_hat[(0, 2)], omega_hat[(1, 0)]);
                let label = format!("{name}: frame {} column {k}", model.frames[frame].name);
                let world_column = [p_dot.as_slice(), omega.as_slice()].concat();
                assert_close(
                    &label,
                    world.column(k).as_slice(),
                    &world_column,
                    FD_TOLERANCE,
                );
                let local_column = [
                    (rotation.transpose() * p_dot).as_slice(),
                    (rotation.transpose() * omega).as_slice(),
                ]
                .concat();
                assert_close(
                    &label,
                    local.column(k).as_slice(),
                    &local_column,
                    FD_TOLERANCE,
                );
                // spatial: velocity of the point at the world origin, v_O = ṗ - ω × p
                let v_origin = p_dot - omega.cross(&pose.translation);
                assert_close(
                    &label,
                    spatial.column(k).as_slice(),
                    &[v_origin.as_slice(), omega.as_slice()].concat(),
                    FD_TOLERANCE,
                );
            }
        }
    }
}

#[test]
fn external_force_maps_through_the_jacobian_transpose() {
    // a wrench on a body adds -Jᵀ f to τ (local Jacobian of the body's frame, f in body axes)
    let mut rng = rng();
    for (name, model) in test_models() {
        let mut data = Data::new(&model);
        let (q, v, a) = state(&model, &mut rng);
        let body = model.nbodies() - 1;
        let frame = model
            .frames
            .iter()
            .position(|f| f.body == body && f.placement == robodyn::spatial::Transform::IDENTITY)
            .unwrap();
        let wrench = [0.5, -1.0, 2.0, 0.3, 0.2, -0.4];
        let mut f_ext = vec![robodyn::spatial::Force::ZERO; model.nbodies() - 1];
        f_ext[body - 1] = robodyn::spatial::Force::from_array(&wrench);
        let free = rnea(
            &model,
            &mut data,
            q.as_slice(),
            v.as_slice(),
            a.as_slice(),
            None,
        )
        .unwrap()
        .clone();
        let pushed = rnea(
            &model,
            &mut data,
            q.as_slice(),
            v.as_slice(),
            a.as_slice(),
            Some(&f_ext),
        )
        .unwrap()
        .clone();
        let j = jacobian(&model, &mut data, q.as_slice(), frame, Reference::Local).unwrap();
        let expected = &free - j.transpose() * DVector::from_row_slice(&wrench);
        assert_close(
            &format!("{name}: f_ext"),
            pushed.as_slice(),
            expected.as_slice(),
            IDENTITY_TOLERANCE,
        );
    }
}

#[test]
fn center_of_mass_and_potential_energy_agree() {
    let mut rng = rng();
    for (name, model) in test_models() {
        let mut data = Data::new(&model);
        let q = model.random_configuration(&mut rng);
        let com = center_of_mass(&model, &mut data, q.as_slice()).unwrap();
        let energy = potential_energy(&model, &mut data, q.as_slice()).unwrap();
        assert_close(
            &format!("{name}: V = -M gᵀ c"),
            &[energy],
            &[-model.total_mass() * model.gravity.dot(&com)],
            IDENTITY_TOLERANCE,
        );
    }
}

#[test]
fn integrate_and_difference_round_trip_on_the_model() {
    let mut rng = rng();
    for (name, model) in test_models() {
        let (q, v, _) = state(&model, &mut rng);
        let mut q1 = DVector::zeros(model.nq);
        model
            .integrate(q.as_slice(), v.as_slice(), q1.as_mut_slice())
            .unwrap();
        let mut back = DVector::zeros(model.nv);
        model
            .difference(q.as_slice(), q1.as_slice(), back.as_mut_slice())
            .unwrap();
        assert_close(
            &format!("{name}: q1 ⊖ q"),
            back.as_slice(),
            v.as_slice(),
            IDENTITY_TOLERANCE,
        );
    }
}

#[test]
fn frame_velocity_and_acceleration_are_j_v_and_j_a_plus_jdot_v() {
    // J̇ q̇ by a central difference of J along q(t) = q ⊕ t q̇
    let mut rng = rng();
    for (name, model) in test_models() {
        let mut data = Data::new(&model);
        let (q, v, a) = state(&model, &mut rng);
        let frame = model.frames.len() - 1;
        for reference in [Reference::World, Reference::Spatial, Reference::Local] {
            let jacobian_at =
                |h: f64, data: &mut Data| jacobian_along(&model, data, &q, &v, h, frame, reference);
            let j = jacobian_at(0.0, &mut data);
            let velocity = frame_velocity(
                &model,
                &mut data,
                q.as_slice(),
                v.as_slice(),
                frame,
                reference,
            )
            .unwrap();
            assert_close(
                &format!("{name} {reference:?}: J v"),
                &velocity,
                (&j * &v).as_slice(),
                IDENTITY_TOLERANCE,
            );
            if reference == Reference::Local {
                // local: the world quantities in the frame's axes
                let world = frame_acceleration(
                    &model,
                    &mut data,
                    q.as_slice(),
                    v.as_slice(),
                    a.as_slice(),
                    frame,
                    Reference::World,
                )
                .unwrap();
                forward_kinematics(&model, &mut data, q.as_slice()).unwrap();
                let rotation = frame_placement(&model, &data, frame).rotation;
                let local = frame_acceleration(
                    &model,
                    &mut data,
                    q.as_slice(),
                    v.as_slice(),
                    a.as_slice(),
                    frame,
                    reference,
                )
                .unwrap();
                let expected: Vec<f64> = [&world[0..3], &world[3..6]]
                    .iter()
                    .flat_map(|part| {
                        (rotation * nalgebra::Vector3::from_row_slice(part))
                            .iter()
                            .copied()
                            .collect::<Vec<_>>()
                    })
                    .collect();
                assert_close(
                    &format!("{name}: local acceleration"),
                    &local,
                    &expected,
                    IDENTITY_TOLERANCE,
                );
                continue;
            }
            let j_dot_v = (jacobian_at(FD_STEP, &mut data) - jacobian_at(-FD_STEP, &mut data)) * &v
                / (2.0 * FD_STEP);
            let acceleration = frame_acceleration(
                &model,
                &mut data,
                q.as_slice(),
                v.as_slice(),
                a.as_slice(),
                frame,
                reference,
            )
            .unwrap();
            let expected = &j * &a + j_dot_v;
            assert_close(
                &format!("{name} {reference:?}: J a + J̇ v"),
                &acceleration,
                expected.as_slice(),
                FD_TOLERANCE,
            );
        }
    }
}

#[test]
fn center_of_mass_jacobian_is_the_derivative_of_the_center_of_mass() {
    let mut rng = rng();
    for (name, model) in test_models() {
        let mut data = Data::new(&model);
        let q = model.random_configuration(&mut rng);
        let j = center_of_mass_jacobian(&model, &mut data, q.as_slice())
            .unwrap()
            .clone();
        for k in 0..model.nv {
            let com_at = |h: f64, data: &mut Data| {
                let moved = displaced(&model, &q, &unit_step(model.nv, k, h));
                center_of_mass(&model, data, moved.as_slice()).unwrap()
            };
            let derivative =
                (com_at(FD_STEP, &mut data) - com_at(-FD_STEP, &mut data)) / (2.0 * FD_STEP);
            assert_close(
                &format!("{name}: J_com column {k}"),
                &j.column(k).as_slice()[..3],
                derivative.as_slice(),
                FD_TOLERANCE,
            );
        }
    }
}

#[test]
fn jacobian_time_variation_is_the_derivative_of_the_jacobian() {
    let mut rng = rng();
    for (name, model) in test_models() {
        let mut data = Data::new(&model);
        let (q, v, _) = state(&model, &mut rng);
        for frame in [0, model.frames.len() / 2, model.frames.len() - 1] {
            for reference in [Reference::World, Reference::Local, Reference::Spatial] {
                let jacobian_at = |h: f64, data: &mut Data| {
                    jacobian_along(&model, data, &q, &v, h, frame, reference)
                };
                let expected = (jacobian_at(FD_STEP, &mut data) - jacobian_at(-FD_STEP, &mut data))
                    / (2.0 * FD_STEP);
                let j_dot = jacobian_time_variation(
                    &model,
                    &mut data,
                    q.as_slice(),
                    v.as_slice(),
                    frame,
                    reference,
                )
                .unwrap();
                assert_close(
                    &format!("{name} frame {frame} {reference:?}: J̇"),
                    j_dot.as_slice(),
                    expected.as_slice(),
                    FD_TOLERANCE,
                );
            }
        }
    }
}
