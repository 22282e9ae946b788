"""DH tables from Python and TOML: the same robots as URDF, the ECE 470 notes' arm, errors."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest
from conftest import CROSS_CHECK_TOLERANCE, REPOSITORY, assert_close

import robodyn

UR5_DH = REPOSITORY / "models" / "ur5_dh.toml"


def test_ur5_dh_table_is_the_bundled_ur5_urdf():
    dh, urdf = robodyn.load(UR5_DH), robodyn.load("ur5")
    assert dh.joint_names == [n.removesuffix("_joint") for n in urdf.joint_names]
    rng = np.random.default_rng(1)
    for seed in range(5):
        q = urdf.random_configuration(seed=seed)
        v, a = rng.uniform(-1, 1, 6), rng.uniform(-1, 1, 6)
        assert_close(dh.frame_pose(q, "tool"), urdf.frame_pose(q, "tool0"), CROSS_CHECK_TOLERANCE, "tool")
        assert_close(dh.mass_matrix(q), urdf.mass_matrix(q), CROSS_CHECK_TOLERANCE, "M")
        assert_close(dh.inverse_dynamics(q, v, a), urdf.inverse_dynamics(q, v, a), CROSS_CHECK_TOLERANCE, "tau")


def test_ur5_dh_has_the_forward_kinematics_of_example_robot_data(robots_dir):
    """ROS's base_link is UR's base frame turned by π about z; tool0 is DH frame 6."""
    erd = robodyn.load(robots_dir / "ur_description/urdf/ur5_robot.urdf")
    rows = tomllib.loads(UR5_DH.read_text())["joint"]
    dh = robodyn.from_dh(rows, "standard", base={"rpy": [0.0, 0.0, math.pi]})
    for seed in range(5):
        q = erd.random_configuration(seed=seed)
        assert_close(dh.frame_pose(q, "tool"), erd.frame_pose(q, "tool0"), CROSS_CHECK_TOLERANCE, "tool0")


def test_seed_001_planar_arm_from_python_in_degrees():
    rows = [
        {"name": "joint1", "type": "revolute", "a": 0, "alpha": 0, "d": 0, "theta": 0, "mass": 2.0, "com": [1, 0, 0]},
        {"name": "joint2", "type": "revolute", "a": 1.0, "alpha": 0, "d": 0, "theta": 0, "mass": 1.0, "com": np.array([0.5, 0, 0])},
    ]
    arm = robodyn.from_dh(rows, "modified", tool={"xyz": [0.5, 0, 0]}, gravity=[0, -9.81, 0], angle_unit="degree")
    reference = robodyn.load("planar2")
    assert arm.frame_names == ["base", "joint1", "joint2", "tool"]
    for q in ([0.3, -0.7], [1.2, 2.1]):
        assert_close(arm.mass_matrix(q), reference.mass_matrix(q), CROSS_CHECK_TOLERANCE, "M")
        assert_close(arm.generalized_gravity(q), reference.generalized_gravity(q), CROSS_CHECK_TOLERANCE, "g")
        assert_close(arm.frame_pose(q, "tool"), reference.frame_pose(q, "tool"), CROSS_CHECK_TOLERANCE, "tool")


def test_prismatic_rows_and_limits():
    rows = [
        {"type": "prismatic", "a": 0, "alpha": 90, "d": 0.1, "theta": 0, "mass": 1, "lower": 0, "upper": 0.5},
        {"type": "revolute", "a": 0.2, "alpha": 0, "d": 0, "theta": 0, "mass": 1, "lower": -90, "upper": 90},
    ]
    m = robodyn.from_dh(rows, "modified", angle_unit="degree")
    assert m.joint_types == ["prismatic", "revolute"]
    np.testing.assert_allclose(m.lower_position_limit, [0.0, -math.pi / 2])
    np.testing.assert_allclose(m.upper_position_limit, [0.5, math.pi / 2])
    # the prismatic joint moves DH frame 1 along its z axis: d = 0.1 + q
    pose = m.frame_pose([0.3, 0.0], "joint1")
    np.testing.assert_allclose(pose[:3, 3], [0.0, -0.4, 0.0], atol=1e-12)


@pytest.mark.parametrize(
    ("rows", "convention", "message"),
    [
        ([{"type": "revolute", "a": 0}], "modified", r"\[\[joint\]\] 1: missing key 'alpha'"),
        ([{"type": "screw", "a": 0, "alpha": 0, "d": 0, "theta": 0}], "modified", "'type': expected"),
        ([{"type": "revolute", "a": 0, "alpha": 0, "d": 0, "theta": 0, "lenght": 1}], "modified", "unknown key 'lenght'"),
        ([{"type": "revolute", "a": 0, "alpha": 0, "d": 0, "theta": 0}], "sideways", "'convention'"),
        ([{"type": "revolute", "a": "x", "alpha": 0, "d": 0, "theta": 0}], "modified", "'a': expected a number"),
        ([{"type": "revolute", "a": object(), "alpha": 0, "d": 0, "theta": 0}], "modified", "'a': expected a number, a string"),
        ([], "modified", "expected at least one row"),
    ],
)
def test_bad_tables(rows, convention, message):
    with pytest.raises(ValueError, match=message):
        robodyn.from_dh(rows, convention)


def test_bad_toml_file(tmp_path):
    path = tmp_path / "robot.toml"
    path.write_text('convention = "modified"\n[[joint]\n')
    with pytest.raises(ValueError, match="robot.toml: malformed TOML"):
        robodyn.load(path)
    with pytest.raises(FileNotFoundError):
        robodyn.load(tmp_path / "missing.toml")
