"""Bad input gives ValueError / FileNotFoundError naming the argument or file element, what was
expected and what came; never a crash or a Rust panic."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn


@pytest.fixture(scope="module")
def model():
    return robodyn.load("ur5", floating_base=True)


def test_missing_file():
    with pytest.raises(FileNotFoundError, match="no_such_robot.urdf"):
        robodyn.load("/tmp/no_such_robot.urdf")
    with pytest.raises(FileNotFoundError, match="not a bundled model"):
        robodyn.load("no_such_model")


def test_unsupported_file_type(tmp_path):
    path = tmp_path / "robot.sdf"
    path.write_text("<sdf/>")
    with pytest.raises(ValueError, match=r"expected a \.urdf, MJCF \.xml or \.toml \(DH table\) file"):
        robodyn.load(path)
    with pytest.raises(ValueError, match="name_or_path"):
        robodyn.load(42)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("<robot><link", "malformed XML"),
        ("<robot name='r'><link name='a'/><link name='b'/><joint name='j' type='screw'><parent link='a'/><child link='b'/></joint></robot>",
         r"<joint name='j'> \(line 1\): unknown joint type 'screw'"),
        ("<robot name='r'><link name='a'/><joint name='j' type='fixed'><parent link='a'/><child link='b'/></joint></robot>",
         "<child link='b'>: no link of that name"),
        ("<robot name='r'><link name='a'/><link name='b'/></robot>", "expected one root link"),
        ("<robot name='r'><link name='a'/><link name='b'/><joint name='j1' type='fixed'><parent link='a'/><child link='b'/></joint>"
         "<joint name='j2' type='fixed'><parent link='b'/><child link='a'/></joint></robot>", "cycle"),
        ("<robot name='r'><link name='a'><inertial><mass value='1'/><inertia ixx='1' iyy='1' izz='-1' ixy='0' ixz='0' iyz='0'/></inertial></link></robot>",
         r"<link name='a'>/<inertial> \(line 1\): expected a positive semi-definite inertia"),
    ],
)
def test_invalid_urdf(tmp_path, text, message):
    path = tmp_path / "bad.urdf"
    path.write_text(text)
    with pytest.raises(ValueError, match=message) as error:
        robodyn.load(path)
    assert "bad.urdf" in str(error.value)
    with pytest.raises(ValueError, match=message):
        robodyn.load_urdf_string(text)


def test_wrong_shapes(model):
    q, v = model.neutral(), np.zeros(model.nv)
    with pytest.raises(ValueError, match=r"argument 'q': expected shape \(13,\) or \(N, 13\), got \(6,\)"):
        model.mass_matrix(np.zeros(6))
    with pytest.raises(ValueError, match=r"argument 'v': expected shape \(12,\) or \(N, 12\), got \(2, 3\)"):
        model.bias_forces(q, np.zeros((2, 3)))
    with pytest.raises(ValueError, match="argument 'a': expected a single sample like argument 'q'"):
        model.inverse_dynamics(q, v, np.zeros((3, model.nv)))
    with pytest.raises(ValueError, match="argument 'v': expected a batch of 4 like argument 'q'"):
        model.bias_forces(np.stack([q] * 4), np.zeros((5, model.nv)))
    with pytest.raises(ValueError, match=r"argument 'f_ext': expected shape \(7, 6\)"):
        model.inverse_dynamics(q, v, v, f_ext=np.zeros(6))
    with pytest.raises(ValueError, match="argument 'q': expected an array of numbers"):
        model.mass_matrix("not a state")
    with pytest.raises(ValueError, match="argument 'q'"):
        model.mass_matrix([[1, 2], [3]])


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_input(model, bad):
    q, v = model.neutral(), np.zeros(model.nv)
    broken = v.copy()
    broken[4] = bad
    with pytest.raises(ValueError, match=r"argument 'tau': expected finite values, got .* at index 4"):
        model.forward_dynamics(q, v, broken)
    with pytest.raises(ValueError, match="argument 'v': expected finite values"):
        model.kinetic_energy(q, broken)
    bad_q = q.copy()
    bad_q[8] = bad
    with pytest.raises(ValueError, match="argument 'q': expected finite values"):
        model.generalized_gravity(bad_q)
    with pytest.raises(ValueError, match=r"batch element 2: argument 'q': expected finite values"):
        model.generalized_gravity(np.stack([q, q, bad_q]))
    # a large batch runs in runs of consecutive states: the element is still named by its index
    many = np.tile(q, (1000, 1))
    many[737] = bad_q
    with pytest.raises(ValueError, match=r"batch element 737: argument 'q': expected finite values"):
        model.generalized_gravity(many)
    with pytest.raises(ValueError, match="argument 'f_ext': expected finite values"):
        f_ext = np.zeros((7, 6))
        f_ext[1, 2] = bad
        model.inverse_dynamics(q, v, v, f_ext=f_ext)
    with pytest.raises(ValueError, match="argument 'gravity'"):
        model.gravity = [0, 0, bad]


def test_non_unit_quaternion(model):
    q = model.neutral()
    q[6] = 2.0
    with pytest.raises(ValueError, match="expected a unit quaternion"):
        model.mass_matrix(q)


def test_unknown_frame_and_reference(model):
    q = model.neutral()
    with pytest.raises(ValueError, match="unknown frame 'gripper'.*'tool0'"):
        model.frame_pose(q, "gripper")
    with pytest.raises(ValueError, match="argument 'frame': expected a frame name or an index below"):
        model.jacobian(q, 999)
    for wrong in (2.5, None, b"tool0"):
        with pytest.raises(ValueError, match="argument 'frame': expected a frame name or an index below"):
            model.jacobian(q, wrong)
    tool = model.frame_names.index("tool0")
    np.testing.assert_array_equal(model.jacobian(q, np.int64(tool)), model.jacobian(q, "tool0"))
    with pytest.raises(ValueError, match="argument 'reference': expected 'world', 'local' or 'spatial', got 'body'"):
        model.jacobian(q, "tool0", "body")
    for wrong in (3, None, b"world"):
        with pytest.raises(ValueError, match="argument 'reference': expected 'world', 'local' or 'spatial', got "):
            model.frame_velocity(q, q, "tool0", wrong)


def test_bad_properties(model):
    with pytest.raises(ValueError, match=r"argument 'armature': expected values >= 0"):
        model.armature = -np.ones(model.nv)
    with pytest.raises(ValueError, match=r"argument 'gravity': expected shape \(3,\)"):
        model.gravity = [0, 9.81]


def test_singular_dynamics_is_an_error_not_nan():
    """The UR5's base link is massless: floating, its base can spin without the arm moving."""
    model = robodyn.load("ur5", floating_base=True)
    q, v = model.neutral(), np.zeros(model.nv)
    with pytest.raises(ValueError, match="singular"):
        model.forward_dynamics(q, v, v)
    with pytest.raises(ValueError, match="mass matrix is singular"):
        model.inverse_mass_matrix(q)


def test_overflow_is_an_error_not_inf():
    model = robodyn.load("pendulum")
    with pytest.raises(ValueError, match="the result is not finite"):
        model.kinetic_energy([0.0], [1e200])
