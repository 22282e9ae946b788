"""robodyn.convert: layouts of Pinocchio and MuJoCo, checked on a floating robot with a ball joint
written both as URDF (robodyn) and MJCF (MuJoCo)."""

from __future__ import annotations

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from conftest import CROSS_CHECK_TOLERANCE, ROBOTS, assert_close

import robodyn
from robodyn.convert import MujocoLayout, PinocchioLayout

URDF = """<robot name="floating">
  <link name="base"><inertial><origin xyz="0.05 0 0.02"/><mass value="3"/>
    <inertia ixx="0.1" iyy="0.12" izz="0.08" ixy="0.01" ixz="0.0" iyz="0.005"/></inertial></link>
  <joint name="arm_joint" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0.1 0 0.2" rpy="0 0 0.5"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <link name="arm"><inertial><origin xyz="0 0 0.15"/><mass value="1"/>
    <inertia ixx="0.02" iyy="0.02" izz="0.004" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="ball_joint" type="spherical"><parent link="arm"/><child link="tip"/><origin xyz="0 0 0.3"/></joint>
  <link name="tip"><inertial><origin xyz="0.02 0 0.05"/><mass value="0.5"/>
    <inertia ixx="0.002" iyy="0.003" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
</robot>"""

MJCF = """<mujoco model="floating">
  <compiler angle="radian"/>
  <option gravity="0 0 -9.81"/>
  <worldbody>
    <body name="base">
      <freejoint name="root_joint"/>
      <inertial pos="0.05 0 0.02" mass="3" fullinertia="0.1 0.12 0.08 0.01 0.0 0.005"/>
      <body name="arm" pos="0.1 0 0.2" axisangle="0 0 1 0.5">
        <joint name="arm_joint" type="hinge" axis="0 1 0"/>
        <inertial pos="0 0 0.15" mass="1" diaginertia="0.02 0.02 0.004"/>
        <body name="tip" pos="0 0 0.3">
          <joint name="ball_joint" type="ball"/>
          <inertial pos="0.02 0 0.05" mass="0.5" diaginertia="0.002 0.003 0.001"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>"""


@pytest.fixture(scope="module")
def floating():
    model = robodyn.load_urdf_string(URDF, floating_base=True)
    mj = mujoco.MjModel.from_xml_string(MJCF)
    return model, mj, MujocoLayout(model, mj)


def test_mujoco_layout_round_trips(floating):
    model, _, layout = floating
    q = model.random_configuration(seed=1)
    v = np.linspace(-1, 1, model.nv)
    np.testing.assert_allclose(layout.q_from_mujoco(layout.q_to_mujoco(q)), q, atol=1e-15)
    np.testing.assert_allclose(layout.v_from_mujoco(q, layout.v_to_mujoco(q, v)), v, atol=1e-14)
    np.testing.assert_allclose(layout.a_from_mujoco(q, v, layout.a_to_mujoco(q, v, v)), v, atol=1e-14)


def test_floating_robot_agrees_with_mujoco_through_the_layout(floating):
    model, mj, layout = floating
    data = mujoco.MjData(mj)
    rng = np.random.default_rng(4)
    for seed in range(4):
        q = model.random_configuration(seed=seed)
        v, a, tau = (rng.uniform(-1, 1, model.nv) for _ in range(3))
        data.qpos[:], data.qvel[:] = layout.q_to_mujoco(q), layout.v_to_mujoco(q, v)
        data.qfrc_applied[:] = layout.force_to_mujoco(q, tau)
        mujoco.mj_forward(mj, data)
        mass = np.zeros((mj.nv, mj.nv))
        mujoco.mj_fullM(mj, data, mass)
        assert_close(model.mass_matrix(q), layout.matrix_from_mujoco(q, mass), CROSS_CHECK_TOLERANCE, "M")
        assert_close(model.bias_forces(q, v), layout.bias_from_mujoco(q, v, data.qfrc_bias, mass), CROSS_CHECK_TOLERANCE, "bias")
        assert_close(model.forward_dynamics(q, v, tau), layout.a_from_mujoco(q, v, data.qacc), CROSS_CHECK_TOLERANCE, "qacc")
        tip = mj.body("tip").id
        pose = model.frame_pose(q, "tip")
        assert_close(pose[:3, 3], data.xpos[tip], CROSS_CHECK_TOLERANCE, "tip position")
        assert_close(pose[:3, :3], data.xmat[tip].reshape(3, 3), CROSS_CHECK_TOLERANCE, "tip rotation")
        jacp, jacr = np.zeros((3, mj.nv)), np.zeros((3, mj.nv))
        mujoco.mj_jacBody(mj, data, jacp, jacr, tip)
        assert_close(model.jacobian(q, "tip"), layout.jacobian_from_mujoco(q, np.vstack([jacp, jacr])), CROSS_CHECK_TOLERANCE, "J")
        result = np.zeros(mj.nv)
        data.qacc[:] = layout.a_to_mujoco(q, v, a)
        mujoco.mj_rne(mj, data, 1, result)
        assert_close(model.inverse_dynamics(q, v, a), layout.force_from_mujoco(q, result), CROSS_CHECK_TOLERANCE, "rne")


def test_pinocchio_layout_round_trips(robots_dir):
    path, floating_base = ROBOTS["talos"]
    model = robodyn.load(robots_dir / path, floating_base=floating_base)
    pin_model = pin.buildModelFromUrdf(str(robots_dir / path), pin.JointModelFreeFlyer())
    layout = PinocchioLayout(model, pin_model)
    q = model.random_configuration(seed=2)
    v = np.linspace(-1, 1, model.nv)
    back = layout.q_from_pinocchio(layout.q_to_pinocchio(q))
    assert_close(model.difference(q, back), np.zeros(model.nv), 1e-12, "q")
    np.testing.assert_array_equal(layout.v_from_pinocchio(layout.v_to_pinocchio(v)), v)
    matrix = np.outer(v, v)
    np.testing.assert_array_equal(layout.matrix_from_pinocchio(layout.matrix_to_pinocchio(matrix)), matrix)


def test_layouts_reject_a_different_robot():
    model = robodyn.load("planar2")
    with pytest.raises(ValueError, match="expected a joint named 'joint1'"):
        MujocoLayout(model, mujoco.MjModel.from_xml_string(MJCF))


def test_mjcf_loader_reads_the_same_robot(floating):
    """robodyn's MJCF loader and its URDF loader give the same model of the floating robot."""
    model, _, _ = floating
    from_mjcf = robodyn.load_mjcf_string(MJCF)
    assert from_mjcf.joint_names == model.joint_names
    rng = np.random.default_rng(9)
    for seed in range(3):
        q = model.random_configuration(seed=seed)
        v = rng.uniform(-1, 1, model.nv)
        assert_close(from_mjcf.mass_matrix(q), model.mass_matrix(q), CROSS_CHECK_TOLERANCE, "M")
        assert_close(from_mjcf.bias_forces(q, v), model.bias_forces(q, v), CROSS_CHECK_TOLERANCE, "bias")
        assert_close(from_mjcf.frame_pose(q, "tip"), model.frame_pose(q, "tip"), CROSS_CHECK_TOLERANCE, "tip")


def test_mujoco_layout_rejects_a_model_with_more_joints():
    extra = MJCF.replace('<joint name="arm_joint" type="hinge" axis="0 1 0"/>', '<joint name="arm_joint" type="hinge" axis="0 1 0"/><joint name="extra"/>')
    with pytest.raises(ValueError, match="expected 10 velocity coordinates as the robodyn model has, got 11"):
        MujocoLayout(robodyn.load_mjcf_string(MJCF), mujoco.MjModel.from_xml_string(extra))
