"""MJCF `<actuator>`: the generalised forces of a control vector (`m.actuator_forces`), field by
field against MuJoCo's `qfrc_actuator` after `mj_forward`, on Panda's file (general actuators
with classes, ranges) and on one file with every modelled kind; what is not modelled warns."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from conftest import REPOSITORY

import robodyn
from robodyn.convert import MujocoLayout

#: Both compute the same few products and sums in double precision; relative to the forces.
FORCE_TOLERANCE = 1e-12

PANDA = REPOSITORY / "testdata" / "mjcf" / "panda_nomesh.xml"

#: A slide and three hinges (one with a ref, one limited), each kind of modelled actuator, gears,
#: ranges given directly, by class and by `inheritrange`, and two joints whose total actuator
#: force is clamped (`actuatorfrcrange`).
ACTUATED = """<mujoco model="actuated">
  <compiler angle="radian"/>
  <default>
    <default class="strong"><motor gear="3" ctrlrange="-2 2" forcerange="-5 5"/></default>
  </default>
  <worldbody>
    <body name="cart" pos="0 0 1">
      <joint name="slide" type="slide" axis="1 0 0"/>
      <geom type="box" size="0.2 0.1 0.05"/>
      <body name="arm" pos="0 0 -0.1">
        <joint name="shoulder" axis="0 1 0" ref="0.3"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.4" size="0.04"/>
        <body name="forearm" pos="0 0 -0.4">
          <joint name="elbow" axis="0 1 0" range="-1 2" actuatorfrcrange="-6 4"/>
          <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03"/>
          <body name="hand" pos="0 0 -0.3">
            <joint name="wrist" axis="1 0 0" actuatorfrcrange="-2.5 2.5" actuatorfrclimited="true"/>
            <geom type="sphere" size="0.05"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="push" joint="slide" gear="2"/>
    <motor class="strong" joint="wrist"/>
    <position name="hold" joint="shoulder" kp="50" kv="4"/>
    <position joint="elbow" kp="20" inheritrange="0.5"/>
    <velocity joint="wrist" kv="3" forcerange="-1 1"/>
    <general joint="elbow" gaintype="affine" gainprm="2 0.5 0.1" biastype="affine" biasprm="1 -3 -0.2" ctrlrange="-1 1" ctrllimited="true"/>
    <general joint="shoulder" gainprm="7"/>
  </actuator>
</mujoco>"""


def mujoco_actuator_forces(model, compiled, q, v, ctrl):
    """MuJoCo's qfrc_actuator at (q, v) under ctrl, in robodyn's order."""
    layout, data = MujocoLayout(model, compiled), mujoco.MjData(compiled)
    data.qpos[:] = layout.q_to_mujoco(q)
    data.qvel[:] = layout.v_to_mujoco(q, v)
    data.ctrl[:] = ctrl
    mujoco.mj_forward(compiled, data)
    return layout.force_from_mujoco(q, data.qfrc_actuator)


def states(model, count, seed):
    """Random (q, v, ctrl): controls reaching past their ranges, so that clamping is tested."""
    rng = np.random.default_rng(seed)
    q = model.random_configuration(n=count, seed=seed)
    return q, rng.uniform(-3, 3, (count, model.nv)), rng.uniform(-4, 4, (count, model.nu))


@pytest.mark.parametrize("source", ["panda", "actuated"])
def test_actuator_forces_equal_mujocos(source):
    if source == "panda":
        model, compiled = robodyn.load(PANDA), mujoco.MjModel.from_xml_path(str(PANDA))
    else:
        model, compiled = robodyn.load_mjcf_string(ACTUATED), mujoco.MjModel.from_xml_string(ACTUATED)
    assert not [w for w in model.warnings if "actuator" in w], model.warnings
    assert model.nu == compiled.nu
    assert model.actuator_names == [compiled.actuator(k).name or f"actuator{k}" for k in range(compiled.nu)]
    limited = compiled.actuator_ctrllimited.astype(bool)
    np.testing.assert_array_equal(model.ctrl_range[limited], compiled.actuator_ctrlrange[limited])
    assert np.all(np.isinf(model.ctrl_range[~limited]))
    q, v, ctrl = states(model, 20, seed=3)
    batch = model.actuator_forces(q, v, ctrl)
    for k in range(len(q)):
        expected = mujoco_actuator_forces(model, compiled, q[k], v[k], ctrl[k])
        scale = max(1.0, np.max(np.abs(expected)))
        np.testing.assert_allclose(model.actuator_forces(q[k], v[k], ctrl[k]), expected, rtol=0, atol=FORCE_TOLERANCE * scale)
        np.testing.assert_array_equal(batch[k], model.actuator_forces(q[k], v[k], ctrl[k]))


def test_a_position_actuator_holds_its_target():
    """The textbook's PD law: τ = k_p (u − q) − k_v q̇ on the joint, with the gear."""
    model = robodyn.load_mjcf_string(ACTUATED)
    ctrl = np.zeros(model.nu)
    ctrl[model.actuator_names.index("hold")] = 0.7
    q, v = model.neutral(), np.zeros(model.nv)
    v[1] = 0.5
    shoulder = model.joint_idx_v[model.joint_names.index("shoulder")]
    tau = model.actuator_forces(q, v, ctrl)
    assert tau[shoulder] == pytest.approx(50 * (0.7 - q[shoulder]) - 4 * 0.5, rel=1e-15)


def test_what_is_not_modelled_warns_and_bad_input_is_refused():
    unmodelled = ACTUATED.replace('<velocity joint="wrist"', '<muscle joint="wrist"').replace(
        'kv="3" forcerange="-1 1"/>', '/>')
    model = robodyn.load_mjcf_string(unmodelled)
    assert [w for w in model.warnings if "<muscle" in w and "not read" in w and "no force" in w]
    assert model.nu == 7 and model.na == 1  # it keeps its place in the controls and the activations
    text = ACTUATED.replace('joint="slide" gear="2"', 'joint="slid" gear="2"')
    with pytest.raises(ValueError, match=r"<motor name='push'> \(line \d+\): attribute 'joint': no joint named 'slid'"):
        robodyn.load_mjcf_string(text)
    model = robodyn.load_mjcf_string(ACTUATED)
    q, v = model.neutral(), np.zeros(model.nv)
    with pytest.raises(ValueError, match=r"argument 'ctrl'.*7"):
        model.actuator_forces(q, v, np.zeros(3))
    with pytest.raises(ValueError, match=r"argument 'ctrl'"):
        model.actuator_forces(q, v, np.full(7, np.nan))
    # a clamped joint needs a range MuJoCo accepts
    text = ACTUATED.replace('actuatorfrcrange="-2.5 2.5"', 'actuatorfrcrange="2.5 -2.5"')
    with pytest.raises(ValueError, match=r"<joint name='wrist'> \(line \d+\): attribute 'actuatorfrclimited' is true"):
        robodyn.load_mjcf_string(text)
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_string(text)
    assert robodyn.load("ur5").nu == 0
