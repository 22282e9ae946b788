//! Inverse kinematics: round trips to reachable poses.

mod common;

use robodyn::algo::{frame_pose, inverse_kinematics, IkOptions};
use robodyn::io::bundled_model;
use robodyn::Data;

/// Share of reachable targets that must be solved.
const REQUIRED_SUCCESS_RATE: f64 = 0.99;
/// Pose agreement of a solution with its target.
const POSE_TOLERANCE: f64 = 1e-8;

#[test]
fn ur5_reaches_random_reachable_poses() {
    let model = bundled_model("ur5", false).unwrap();
    let mut data = Data::new(&model);
    let tool = model.frame_index("tool0").unwrap();
    let mut rng = common::rng();
    let targets = 100;
    for position_only in [false, true] {
        let options = IkOptions {
            position_only,
            ..IkOptions::default()
        };
        let mut solved = 0;
        for _ in 0..targets {
            let goal = model.random_configuration(&mut rng);
            let target = frame_pose(&model, &mut data, goal.as_slice(), tool).unwrap();
            let solution = inverse_kinematics(
                &model,
                &mut data,
                tool,
                &target,
                model.neutral().as_slice(),
                &options,
                &mut rng,
            )
            .unwrap();
            if !solution.success {
                continue;
            }
            solved += 1;
            let reached = frame_pose(&model, &mut data, solution.q.as_slice(), tool).unwrap();
            let position_error = (reached.translation - target.translation).norm();
            assert!(
                position_error < POSE_TOLERANCE,
                "position error {position_error:e}"
            );
            if !position_only {
                let rotation_error = (reached.rotation - target.rotation).norm();
                assert!(
                    rotation_error < POSE_TOLERANCE,
                    "rotation error {rotation_error:e}"
                );
            }
            // within the limits
            for (k, value) in solution.q.iter().enumerate() {
                assert!(
                    *value >= model.lower_position_limit[k]
                        && *value <= model.upper_position_limit[k]
                );
            }
        }
        let rate = solved as f64 / targets as f64;
        assert!(
            rate >= REQUIRED_SUCCESS_RATE,
            "position_only={position_only}: solved {rate}"
        );
    }
}

#[test]
fn unreachable_target_reports_failure_with_its_residual() {
    let model = bundled_model("planar2", false).unwrap();
    let mut data = Data::new(&model);
    let tool = model.frame_index("tool").unwrap();
    // 3 m away: the arm reaches 1.5 m
    let target =
        robodyn::spatial::Transform::from_translation(&nalgebra::Vector3::new(3.0, 0.0, 0.0));
    let options = IkOptions {
        position_only: true,
        restarts: 3,
        ..IkOptions::default()
    };
    let solution = inverse_kinematics(
        &model,
        &mut data,
        tool,
        &target,
        &[0.1, 0.1],
        &options,
        &mut common::rng(),
    )
    .unwrap();
    assert!(!solution.success);
    assert!(
        (solution.residual - 1.5).abs() < 1e-6,
        "residual {}",
        solution.residual
    );
    assert_eq!(solution.iterations, 4 * options.max_iterations);
}
