"""Cross-checks against MuJoCo on the example-robot-data URDFs, which MuJoCo imports itself
(fixed base; meshes removed: they do not enter the dynamics)."""

from __future__ import annotations

import re

import mujoco
import numpy as np
import pytest
from conftest import CROSS_CHECK_TOLERANCE, ROBOTS, assert_close

import robodyn


def mujoco_model(urdf):
    text = re.sub(r"<(visual|collision|gazebo|transmission)\b.*?</\1>", "", urdf.read_text(), flags=re.S)
    model = mujoco.MjModel.from_xml_string(text)
    # rigid-body dynamics only: no passive joint forces, no limit constraints
    model.dof_damping[:] = 0.0
    model.dof_frictionloss[:] = 0.0
    model.jnt_stiffness[:] = 0.0
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    return model


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
        data.qpos[:], data.qvel[:], data.qfrc_applied[:] = q, v, tau
        mujoco.mj_forward(mj, data)
        mass = np.zeros((mj.nv, mj.nv))
        mujoco.mj_fullM(mj, data, mass)
        assert_close(model.mass_matrix(q), mass, CROSS_CHECK_TOLERANCE, f"{name} M")
        assert_close(model.bias_forces(q, v), data.qfrc_bias, CROSS_CHECK_TOLERANCE, f"{name} bias")
        assert_close(model.forward_dynamics(q, v, tau), data.qacc, CROSS_CHECK_TOLERANCE, f"{name} qacc")
        result = np.zeros(mj.nv)
        data.qacc[:] = a
        mujoco.mj_rne(mj, data, 1, result)
        assert_close(model.inverse_dynamics(q, v, a), result, CROSS_CHECK_TOLERANCE, f"{name} rne")


def test_body_poses_and_jacobians_agree_with_mujoco(robot):
    name, model, mj = robot
    data = mujoco.MjData(mj)
    q = model.random_configuration(seed=9)
    data.qpos[:] = q
    mujoco.mj_forward(mj, data)
    jacp, jacr = np.zeros((3, mj.nv)), np.zeros((3, mj.nv))
    for body in range(1, mj.nbody):
        link = mj.body(body).name
        pose = model.frame_pose(q, link)
        assert_close(pose[:3, 3], data.xpos[body], CROSS_CHECK_TOLERANCE, f"{name} {link} position")
        assert_close(pose[:3, :3], data.xmat[body].reshape(3, 3), CROSS_CHECK_TOLERANCE, f"{name} {link} rotation")
        mujoco.mj_jacBody(mj, data, jacp, jacr, body)
        assert_close(model.jacobian(q, link), np.vstack([jacp, jacr]), CROSS_CHECK_TOLERANCE, f"{name} {link} J")
