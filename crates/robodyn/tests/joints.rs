//! Joints: the motion subspace against a finite difference of the joint transform, and the Lie
//! group integration against its difference.

mod common;

use common::{rng, FD_STEP, FD_TOLERANCE};
use rand::Rng;
use robodyn::spatial::{mat6_mul_motion, Force, Mat3, Transform, Turn, Vec3};
use robodyn::Joint;

const ROUND_TRIP_TOLERANCE: f64 = 1e-10;

fn joints() -> Vec<Joint> {
    vec![
        Joint::Revolute {
            axis: Vec3::new(0.6, 0.0, 0.8),
        },
        Joint::Prismatic {
            axis: Vec3::new(0.0, -0.8, 0.6),
        },
        Joint::Spherical,
        Joint::Free,
    ]
}

/// The body velocity `(ω, v)` in child axes of the motion X(t): from `Ẋ X⁻¹ = (v×)` on the pose.
fn body_velocity(before: &Transform, after: &Transform, dt: f64) -> [f64; 6] {
    // pose of the child in the joint frame: rotation R = Eᵀ, position p = r
    let (r0, r1) = (before.rotation.transpose(), after.rotation.transpose());
    let omega_hat = r0.transpose() * (r1 - r0) / dt;
    let omega = Vec3::new(omega_hat[(2, 1)], omega_hat[(0, 2)], omega_hat[(1, 0)]);
    let linear = r0.transpose() * (after.translation - before.translation) / dt;
    [omega.x, omega.y, omega.z, linear.x, linear.y, linear.z]
}

#[test]
fn subspace_is_the_derivative_of_the_joint_transform() {
    let mut rng = rng();
    for joint in joints() {
        let mut q = vec![0.0; joint.nq()];
        joint.random(
            &mut rng,
            &vec![-1.0; joint.nq()],
            &vec![1.0; joint.nq()],
            &mut q,
        );
        for k in 0..joint.nv() {
            // move along the k-th velocity coordinate for ±h
            let mut step = vec![0.0; joint.nv()];
            step[k] = FD_STEP;
            let (mut q_plus, mut q_minus) = (q.clone(), q.clone());
            joint.integrate(&q, &step, &mut q_plus);
            step[k] = -FD_STEP;
            joint.integrate(&q, &step, &mut q_minus);
            let velocity = body_velocity(
                &joint.transform(&q_minus),
                &joint.transform(&q_plus),
                2.0 * FD_STEP,
            );
            let s = joint.subspace_column(k);
            let expected = [
                s.angular.x,
                s.angular.y,
                s.angular.z,
                s.linear.x,
                s.linear.y,
                s.linear.z,
            ];
            for (a, b) in velocity.iter().zip(expected) {
                assert!(
                    (a - b).abs() < FD_TOLERANCE,
                    "{} column {k}: {velocity:?} vs {expected:?}",
                    joint.kind()
                );
            }
        }
    }
}

#[test]
fn difference_inverts_integrate() {
    let mut rng = rng();
    for joint in joints() {
        for _ in 0..20 {
            let mut q = vec![0.0; joint.nq()];
            joint.random(
                &mut rng,
                &vec![-1.0; joint.nq()],
                &vec![1.0; joint.nq()],
                &mut q,
            );
            let v: Vec<f64> = (0..joint.nv())
                .map(|i| 0.7 * (i as f64 + 1.0).sin())
                .collect();
            let mut q1 = vec![0.0; joint.nq()];
            joint.integrate(&q, &v, &mut q1);
            let mut back = vec![0.0; joint.nv()];
            joint.difference(&q, &q1, &mut back);
            for (a, b) in back.iter().zip(&v) {
                assert!(
                    (a - b).abs() < ROUND_TRIP_TOLERANCE,
                    "{}: {back:?} vs {v:?}",
                    joint.kind()
                );
            }
            if let Some(offset) = joint.quaternion_offset() {
                let norm: f64 = q1[offset..offset + 4].iter().map(|x| x * x).sum();
                assert!((norm - 1.0).abs() < ROUND_TRIP_TOLERANCE);
            }
        }
    }
}

#[test]
fn neutral_is_the_identity_transform() {
    for joint in joints() {
        let mut q = vec![0.0; joint.nq()];
        joint.neutral(&mut q);
        assert_eq!(
            joint.transform(&q).to_matrix(),
            Transform::IDENTITY.to_matrix(),
            "{}",
            joint.kind()
        );
    }
}

/// `transform_after` takes shortcuts for coordinate axes; each is `X_J(q) X_T` to rounding.
const COMPOSITION_TOLERANCE: f64 = 1e-14;

/// [`joints`], and revolute and prismatic joints along each coordinate axis (both ways) and the
/// fixed joint: the cases the joints' shortcuts tell apart.
fn joints_and_shortcuts() -> Vec<Joint> {
    let mut all = joints();
    for k in 0..3 {
        for sign in [1.0, -1.0] {
            all.push(Joint::Revolute {
                axis: Vec3::ith(k, sign),
            });
            all.push(Joint::Prismatic {
                axis: Vec3::ith(k, sign),
            });
        }
    }
    all.push(Joint::Fixed);
    all
}

#[test]
fn transform_after_is_the_joint_transform_times_the_tree_transform() {
    let mut rng = rng();
    for joint in joints_and_shortcuts() {
        for _ in 0..5 {
            let x_tree = Transform::from_pose(
                &random_rotation(&mut rng),
                &Vec3::new(rng.random(), rng.random(), rng.random()),
            );
            let mut q = vec![0.0; joint.nq()];
            let unlimited = vec![f64::INFINITY; joint.nq()];
            joint.random(&mut rng, &unlimited, &unlimited, &mut q);
            let expected = (joint.transform(&q) * x_tree).to_matrix();
            let composed = joint.transform_after(&q, &x_tree).to_matrix();
            assert!(
                (composed - expected).amax() < COMPOSITION_TOLERANCE,
                "{joint:?} at {q:?}: {composed} vs {expected}"
            );
        }
    }
}

#[test]
fn subspace_column_from_a_frame_is_the_inverse_transform_of_the_column() {
    let mut rng = rng();
    for joint in joints_and_shortcuts() {
        let x = random_transform(&mut rng);
        for k in 0..joint.nv() {
            let expected = x.inverse_apply_motion(&joint.subspace_column(k));
            let column = joint.subspace_column_from(k, &x);
            let difference = (column - expected)
                .to_array()
                .iter()
                .fold(0.0_f64, |m, d| m.max(d.abs()));
            assert!(
                difference < COMPOSITION_TOLERANCE,
                "{joint:?} column {k}: {column:?} vs {expected:?}"
            );
        }
    }
}

/// `subspace_column_at` moves the column's linear part from the origin to a point:
/// `v_p = v_O + ω × p`, the same angular part.
#[test]
fn subspace_column_at_a_point_is_the_velocity_of_that_point() {
    let mut rng = rng();
    for joint in joints_and_shortcuts() {
        let x = random_transform(&mut rng);
        let point = Vec3::new(rng.random(), rng.random(), rng.random());
        for k in 0..joint.nv() {
            let at_origin = joint.subspace_column_from(k, &x);
            let at_point = joint.subspace_column_at(k, &x, &point);
            let expected = at_origin.linear + at_origin.angular.cross(&point);
            assert_eq!(at_point.angular, at_origin.angular, "{joint:?} column {k}");
            assert!(
                (at_point.linear - expected).amax() < COMPOSITION_TOLERANCE,
                "{joint:?} column {k}: {at_point:?} vs {expected:?}"
            );
        }
    }
}

/// A transform of random rotation and translation (each coordinate in [0, 1)).
fn random_transform(rng: &mut impl Rng) -> Transform {
    Transform::from_pose(
        &random_rotation(rng),
        &Vec3::new(rng.random(), rng.random(), rng.random()),
    )
}

fn random_rotation(rng: &mut impl Rng) -> nalgebra::Matrix3<f64> {
    let axis = nalgebra::Unit::new_normalize(Vec3::new(
        rng.random::<f64>() - 0.5,
        rng.random::<f64>() - 0.5,
        rng.random::<f64>() - 0.5,
    ));
    *nalgebra::Rotation3::from_axis_angle(&axis, 6.0 * rng.random::<f64>()).matrix()
}

#[test]
fn inertia_times_subspace_is_the_product_with_the_subspace_column() {
    let mut rng = rng();
    for joint in joints_and_shortcuts() {
        let inertia = nalgebra::Matrix6::from_fn(|_, _| rng.random::<f64>() - 0.5);
        for k in 0..joint.nv() {
            let expected = mat6_mul_motion(&inertia, &joint.subspace_column(k));
            // the same products in the same order, less some + 0 terms: equal
            assert_eq!(
                joint.inertia_times_subspace(&inertia, k).to_vector(),
                expected.to_vector(),
                "{joint:?} column {k}"
            );
        }
    }
}

/// `Joint::subspace_component`: where a column of S is a coordinate axis (or its opposite), the
/// component it names is `S_kᵀ f` exactly; a general axis has none.
#[test]
fn subspace_components_are_the_projections() {
    let f = Force::new(Vec3::new(0.3, -1.7, 2.9), Vec3::new(-4.1, 0.6, 1.3));
    let axis = |x: f64, y: f64, z: f64| Vec3::new(x, y, z);
    let joints = [
        Joint::Revolute {
            axis: axis(1.0, 0.0, 0.0),
        },
        Joint::Revolute {
            axis: axis(0.0, -1.0, 0.0),
        },
        Joint::Revolute {
            axis: axis(0.0, 0.0, 1.0),
        },
        Joint::Prismatic {
            axis: axis(0.0, 1.0, 0.0),
        },
        Joint::Prismatic {
            axis: axis(-1.0, 0.0, 0.0),
        },
        Joint::Spherical,
        Joint::Free,
    ];
    for joint in joints {
        for k in 0..joint.nv() {
            let (index, negative) = joint.subspace_component(k).expect("a coordinate axis");
            let value = f.plucker()[index];
            let value = if negative { -value } else { value };
            assert_eq!(value, joint.project_force(k, &f), "{joint:?}, column {k}");
        }
    }
    let general = [
        Joint::Revolute {
            axis: axis(0.6, 0.8, 0.0),
        },
        Joint::Prismatic {
            axis: axis(0.0, 0.6, -0.8),
        },
    ];
    for joint in general {
        assert_eq!(joint.subspace_component(0), None, "{joint:?}");
    }
}

/// `Joint::turn`: a revolute joint about ±e_k or a prismatic joint after a tree transform whose
/// rotation keeps one axis exactly (none, quarter turns, a turn about e_k), reporting the column
/// of the rotation's row k; not after any other rotation, nor one that turns e_k into −e_k.
#[test]
fn turn_needs_a_coordinate_axis_and_a_tree_that_keeps_an_axis() {
    let translation = Vec3::new(0.1, -0.2, 0.3);
    let tree = |rotation: Mat3| Transform::from_pose(&rotation, &translation);
    let shifted = Transform::from_translation(&translation);
    let tilted = tree(robodyn::spatial::rotation_from_rpy(0.0, 0.3, 0.0));
    // a quarter turn about x, exactly: row z is −e_y, row y is e_z
    let quarter_about_x = tree(Mat3::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0));
    // a half turn about x: row z is −e_z
    let half_about_x = tree(Mat3::new(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0));
    let revolute = |x: f64, y: f64, z: f64| Joint::Revolute {
        axis: Vec3::new(x, y, z),
    };
    let turn = |axis, column, axis_negative, tree_rotates| {
        Some(Turn {
            axis,
            column,
            axis_negative,
            tree_rotates,
        })
    };
    assert_eq!(
        revolute(1.0, 0.0, 0.0).turn(&shifted),
        turn(0, 0, false, false)
    );
    assert_eq!(
        revolute(0.0, -1.0, 0.0).turn(&shifted),
        turn(1, 1, true, false)
    );
    assert_eq!(
        revolute(0.0, 0.0, 1.0).turn(&shifted),
        turn(2, 2, false, false)
    );
    assert_eq!(
        revolute(0.0, 0.0, 1.0).turn(&quarter_about_x),
        turn(2, 1, false, true)
    );
    assert_eq!(
        revolute(0.0, 1.0, 0.0).turn(&quarter_about_x),
        turn(1, 2, false, true)
    );
    assert_eq!(
        revolute(-1.0, 0.0, 0.0).turn(&quarter_about_x),
        turn(0, 0, true, true)
    );
    assert_eq!(
        revolute(1.0, 0.0, 0.0).turn(&half_about_x),
        turn(0, 0, false, true)
    );
    assert_eq!(revolute(0.0, 0.0, 1.0).turn(&half_about_x), None);
    assert_eq!(revolute(0.0, 0.0, 1.0).turn(&tilted), None);
    // a tree that turns about the joint's own axis keeps it
    assert_eq!(
        revolute(0.0, 1.0, 0.0).turn(&tilted),
        turn(1, 1, false, true)
    );
    assert_eq!(revolute(0.6, 0.8, 0.0).turn(&shifted), None);
    let prismatic = Joint::Prismatic {
        axis: Vec3::new(0.6, 0.8, 0.0),
    };
    assert_eq!(prismatic.turn(&shifted), turn(2, 2, false, false));
    assert_eq!(prismatic.turn(&quarter_about_x), turn(2, 1, false, true));
    assert_eq!(prismatic.turn(&tilted), None);
    assert_eq!(Joint::Spherical.turn(&shifted), None);
    assert_eq!(Joint::Free.turn(&shifted), None);
}
