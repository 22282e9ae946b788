"""Cross-checks against MuJoCo on the example-robot-data URDFs, which MuJoCo imports itself
(fixed base; meshes removed: they do not enter the dynamics)."""

from __future__ import annotations

import re

import mujoco
import numpy as np
import pytest
from conftest import CROSS_CHECK_TOLERANCE, REPOSITORY, ROBOTS, assert_close

import robodyn


def rigid_body_only(mj):
    """No passive joint forces, limit constraints or actuators: MuJoCo's rigid-body dynamics
    (armature stays: robodyn models it too)."""
    mj.dof_damping[:] = 0.0
    mj.dof_frictionloss[:] = 0.0
    mj.jnt_stiffness[:] = 0.0
    mj.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT | mujoco.mjtDisableBit.mjDSBL_ACTUATION
    return mj


def mujoco_model(urdf):
    text = re.sub(r"<(visual|collision|gazebo|transmission)\b.*?</\1>", "", urdf.read_text(), flags=re.S)
    return rigid_body_only(mujoco.MjModel.from_xml_string(text))


def check_dynamics(model, mj, data, q, qpos, v, a, tau, label):
    """M, bias, q̈ and mj_rne at one state (v, a, τ mean the same in both: no free joints)."""
    data.qpos[:], data.qvel[:], data.qfrc_applied[:] = qpos, v, tau
    mujoco.mj_forward(mj, data)
    mass = np.zeros((mj.nv, mj.nv))
    mujoco.mj_fullM(mj, data, mass)
    assert_close(model.mass_matrix(q), mass, CROSS_CHECK_TOLERANCE, f"{label} M")
    assert_close(model.bias_forces(q, v), data.qfrc_bias, CROSS_CHECK_TOLERANCE, f"{label} bias")
    assert_close(model.forward_dynamics(q, v, tau), data.qacc, CROSS_CHECK_TOLERANCE, f"{label} qacc")
    result = np.zeros(mj.nv)
    data.qacc[:] = a
    mujoco.mj_rne(mj, data, 1, result)
    # mj_rne leaves armature out of M qacc
    assert_close(model.inverse_dynamics(q, v, a) - model.armature * a, result, CROSS_CHECK_TOLERANCE, f"{label} rne")


def check_frames(model, mj, data, q, qpos, label):
    """Every body's pose and Jacobian (mj_jacBody) and every site's pose."""
    data.qpos[:] = qpos
    mujoco.mj_forward(mj, data)
    jacp, jacr = np.zeros((3, mj.nv)), np.zeros((3, mj.nv))
    for body in range(1, mj.nbody):
        link = mj.body(body).name
        pose = model.frame_pose(q, link)
        assert_close(pose[:3, 3], data.xpos[body], CROSS_CHECK_TOLERANCE, f"{label} {link} position")
        assert_close(pose[:3, :3], data.xmat[body].reshape(3, 3), CROSS_CHECK_TOLERANCE, f"{label} {link} rotation")
        mujoco.mj_jacBody(mj, data, jacp, jacr, body)
        assert_close(model.jacobian(q, link), np.vstack([jacp, jacr]), CROSS_CHECK_TOLERANCE, f"{label} {link} J")
    for site in range(mj.nsite):
        name = mj.site(site).name
        pose = model.frame_pose(q, name)
        assert_close(pose[:3, 3], data.site_xpos[site], CROSS_CHECK_TOLERANCE, f"{label} {name}")
        assert_close(pose[:3, :3], data.site_xmat[site].reshape(3, 3), CROSS_CHECK_TOLERANCE, f"{label} {name}")


@pytest.fixture(scope="module", params=sorted(ROBOTS))
def robot(request, robots_dir):
    urdf = robots_dir / ROBOTS[request.param][0]
    model = robodyn.load(urdf)
    mj = mujoco_model(urdf)
    joint_names = [mj.joint(j).name for j in range(mj.njnt)]
    # MuJoCo keeps the URDF's file order too
    assert joint_names == model.joint_names
    return request.param, model, mj


def test_dynamics_agree_with_mujoco(robot):
    name, model, mj = robot
    data = mujoco.MjData(mj)
    rng = np.random.default_rng(5)
    for seed in range(3):
        q = model.random_configuration(seed=seed)
        v, a, tau = (rng.uniform(-1, 1, model.nv) for _ in range(3))
        check_dynamics(model, mj, data, q, q, v, a, tau, name)


def test_body_poses_and_jacobians_agree_with_mujoco(robot):
    name, model, mj = robot
    q = model.random_configuration(seed=9)
    check_frames(model, mj, mujoco.MjData(mj), q, q, name)


SHARED_MJCF = REPOSITORY.parent / "shared" / "mjcf"


@pytest.mark.parametrize("name", ["ur5e_nomesh.xml", "panda_nomesh.xml"])
def test_mjcf_models_agree_with_mujoco(name):
    """MuJoCo Menagerie's UR5e and Panda (meshes removed), loaded by robodyn's MJCF loader."""
    path = SHARED_MJCF / name
    assert path.exists(), f"{path}: the MJCF test models live in shared/mjcf beside the repository"
    with pytest.warns(robodyn.ModelWarning, match="not read"):
        model = robodyn.load(path)
    mj = rigid_body_only(mujoco.MjModel.from_xml_path(str(path)))
    assert model.joint_names == [mj.joint(j).name for j in range(mj.njnt)]
    np.testing.assert_array_equal(model.armature, mj.dof_armature)
    data = mujoco.MjData(mj)
    rng = np.random.default_rng(6)
    for seed in range(3):
        q = model.random_configuration(seed=seed)
        v, a, tau = (rng.uniform(-1, 1, model.nv) for _ in range(3))
        check_dynamics(model, mj, data, q, q, v, a, tau, name)
        check_frames(model, mj, data, q, q, name)


MJCF_FEATURES = """<mujoco model="features">
  <compiler angle="degree" eulerseq="zyx"/>
  <option gravity="0 -9.81 -3"/>
  <default>
    <joint armature="0.01" axis="1 0 0"/>
    <default class="heavy">
      <joint armature="0.2" damping="3"/>
    </default>
  </default>
  <worldbody>
    <site name="world_site" pos="0.1 0 0"/>
    <body name="a" pos="0 0 0.5" euler="10 20 30" childclass="heavy">
      <inertial pos="0.1 0 0" mass="2" diaginertia="0.1 0.2 0.3" axisangle="1 1 0 30"/>
      <joint name="a1" type="hinge" pos="0.1 0.2 0" axis="0 0 1"/>
      <joint name="a2" type="hinge" pos="-0.1 0 0.3" axis="0 1 0"/>
      <joint name="a3" type="slide" axis="1 0 1" range="-0.2 0.2"/>
      <body name="b" pos="0.3 0 0" xyaxes="0 1 0 -1 0 0">
        <inertial pos="0 0 0.1" mass="1" fullinertia="0.05 0.04 0.03 0.001 0.002 0.003"/>
        <joint name="b1" class="main"/>
        <site name="b_tip" pos="0 0 0.2" zaxis="1 1 1"/>
        <body name="c" pos="0 0.1 0.2">
          <inertial pos="0 0 0" mass="0.5" diaginertia="0.01 0.01 0.01"/>
          <joint name="c1" type="ball" pos="0 0 0.05"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>"""


def test_mjcf_orientations_defaults_and_joint_chains_agree_with_mujoco():
    """Every orientation form, degrees, eulerseq, classes and childclass, several joints in one
    body with their own pos, a ball joint off the body origin, sites."""
    model = robodyn.load_mjcf_string(MJCF_FEATURES)
    mj = rigid_body_only(mujoco.MjModel.from_xml_string(MJCF_FEATURES))
    assert model.joint_names == ["a1", "a2", "a3", "b1", "c1"]
    np.testing.assert_allclose(model.armature, mj.dof_armature)
    np.testing.assert_allclose(model.gravity, mj.opt.gravity)
    data = mujoco.MjData(mj)
    rng = np.random.default_rng(2)
    for seed in range(3):
        q = model.random_configuration(seed=seed)
        v, a, tau = (rng.uniform(-1, 1, model.nv) for _ in range(3))
        qpos = np.concatenate([q[:4], np.roll(q[4:8], 1)])  # the ball's quaternion, w first
        check_dynamics(model, mj, data, q, qpos, v, a, tau, "features")
        check_frames(model, mj, data, q, qpos, "features")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("<mujoco><worldbody><body name='x'><geom size='0.1'/><joint/></body></worldbody></mujoco>", "<body name='x'>.*inertia from geoms"),
        ("<mujoco><worldbody><body name='x'><inertial mass='1' diaginertia='1 1 1'/><joint type='screw'/></body></worldbody></mujoco>", "unknown joint type 'screw'"),
        ("<mujoco><default><default><joint/></default></default></mujoco>", "needs a 'class'"),
        ("<mujoco><worldbody><body name='x' quat='0 0 0 0'/></worldbody></mujoco>", "non-zero quaternion"),
        ("<mujoco><worldbody><body name='x' pos='1 2'/></worldbody></mujoco>", "attribute 'pos': expected 3 numbers"),
        ("<robot/>", "expected the root element <mujoco>"),
        ("<mujoco><worldbody><body name='x'><inertial mass='1' diaginertia='1 1 1'/><joint class='nope'/></body></worldbody></mujoco>", "unknown class 'nope'"),
    ],
)
def test_mjcf_errors_name_the_element(text, message):
    with pytest.raises(ValueError, match=message):
        robodyn.load_mjcf_string(text, source="bad.xml")
