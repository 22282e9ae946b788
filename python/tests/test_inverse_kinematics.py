"""Inverse kinematics round trips on reachable poses (issue 3: ≥ 99% solved to 1e-8)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROBOTS

import robodyn

REQUIRED_SUCCESS_RATE = 0.99
POSE_TOLERANCE = 1e-8


@pytest.mark.parametrize(("name", "frame"), [("ur5", "tool0"), ("panda", "panda_hand_tcp")])
@pytest.mark.parametrize("position_only", [False, True])
def test_round_trip_on_reachable_poses(robots_dir, name, frame, position_only):
    path, _ = ROBOTS[name]
    model = robodyn.load(robots_dir / path)
    goals = model.random_configuration(n=300, seed=11)
    targets = model.frame_pose(goals, frame)
    result = model.inverse_kinematics(frame, targets, position_only=position_only)
    assert result["q"].shape == (300, model.nq)
    assert result["success"].mean() >= REQUIRED_SUCCESS_RATE
    reached = model.frame_pose(result["q"], frame)
    solved = result["success"]
    position_error = np.linalg.norm(reached[solved, :3, 3] - targets[solved, :3, 3], axis=1)
    assert position_error.max() < POSE_TOLERANCE
    if not position_only:
        assert np.abs(reached[solved, :3, :3] - targets[solved, :3, :3]).max() < POSE_TOLERANCE
    assert np.all(result["q"] >= model.lower_position_limit) and np.all(result["q"] <= model.upper_position_limit)


def test_batch_equals_loop_and_reports_failure():
    model = robodyn.load("planar2")
    reachable = model.frame_pose([0.3, 0.9], "tool")
    unreachable = np.eye(4)
    unreachable[0, 3] = 3.0  # the arm reaches 1.5 m
    targets = np.stack([reachable, unreachable])
    batch = model.inverse_kinematics("tool", targets, position_only=True, restarts=2)
    for k in range(2):
        single = model.inverse_kinematics("tool", targets[k], position_only=True, restarts=2)
        np.testing.assert_array_equal(batch["q"][k], single["q"])
        assert batch["success"][k] == single["success"]
    assert list(batch["success"]) == [True, False]
    assert abs(batch["residual"][1] - 1.5) < 1e-3


def test_bad_targets():
    model = robodyn.load("ur5")
    with pytest.raises(ValueError, match="argument 'target': expected a 4x4 homogeneous pose"):
        model.inverse_kinematics("tool0", 2 * np.eye(4))
    with pytest.raises(ValueError, match=r"argument 'target': expected shape \(4, 4\)"):
        model.inverse_kinematics("tool0", np.zeros(3))
    target = np.eye(4)
    target[0, 3] = np.nan
    with pytest.raises(ValueError, match="argument 'target': expected finite values"):
        model.inverse_kinematics("tool0", target)
    with pytest.raises(ValueError, match="argument 'options'"):
        model.inverse_kinematics("tool0", np.eye(4), tolerance=0.0)
