"""MuJoCo's gravity compensation (`<body gravcomp="γ">`): a force −γ m g at each body's centre of
mass, in the scene's dynamics (`qfrc_passive`, or `qfrc_actuator` on an `actuatorgravcomp` joint),
against MuJoCo 4.0's `mj_forward` and `mj_step`;
an arm fully compensated holds still; gravity disabled takes it away, as in MuJoCo."""

import mujoco
import numpy as np
import pytest
from conftest import assert_close, load_quietly
from test_contact_dynamics import assert_matches_mujoco, load_both
from test_scene_stepping import INTEGRATORS, assert_steps_from_a_turned_state

# A free base, an arm (a jointless body welded to the upper arm with its own gravcomp, more than
# its weight on the hand), a floor under it.
HELD = """<mujoco><option timestep="0.002" cone="{cone}"/>
  <worldbody>
    <geom name="floor" type="plane" size="3 3 .1"/>
    <body name="base" pos="0 0 1" gravcomp="0.5">
      <freejoint/>
      <geom name="base" type="box" size=".2 .1 .05" mass="4"/>
      <body name="upper" pos=".2 0 0" gravcomp="1">
        <joint name="shoulder" axis="0 1 0" damping="0.1"/>
        <geom name="upper" type="capsule" fromto="0 0 0 .3 0 0" size=".03"/>
        <body name="pad" pos=".15 0 .04" gravcomp="0.8"><geom name="pad" type="box" size=".05 .02 .01" mass="0.3"/></body>
        <body name="lower" pos=".3 0 0">
          <joint name="elbow" axis="0 1 0" damping="0.1"/>
          <geom name="lower" type="capsule" fromto="0 0 0 .2 0 0" size=".025"/>
          <body name="hand" pos=".2 0 0" gravcomp="1.3">
            <joint name="wrist" type="ball" damping="0.01"/>
            <geom name="hand" type="box" size=".04 .03 .02" pos=".03 .01 0"/></body></body></body></body>
  </worldbody>
</mujoco>"""


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_gravity_compensation_as_in_mujoco(cone):
    """q̈ at random states (the base on the floor or above it) against mj_forward; the
    compensation moves the accelerations, and the model says other integrators leave it out."""
    model, mj_model, layout = load_both(HELD.replace("{cone}", cone))
    assert [w for w in model.warnings if "gravcomp" in w and "base, upper, pad, hand" in w
            and "other integrators and algorithms feel their full weight" in w], model.warnings
    plain = load_quietly(None, HELD.replace("{cone}", cone).replace("gravcomp", "user"))
    rng = np.random.default_rng(5)
    for case in range(10):
        qpos = mj_model.qpos0.copy()
        mujoco.mj_integratePos(mj_model, qpos, rng.normal(size=mj_model.nv) * 0.5, 1.0)
        qpos[2] = rng.uniform(0.0, 1.0)
        qvel = rng.normal(size=mj_model.nv)
        ours, _ = assert_matches_mujoco(model, mj_model, layout, qpos, qvel, label=f"{cone} case {case}")
        q = layout.q_from_mujoco(qpos)
        without = plain.contact_forward_dynamics(q, layout.v_from_mujoco(q, qvel))["qdd"]
        assert np.max(np.abs(ours["qdd"] - without)) > 0.1


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_gravity_compensation_steps_as_in_mujoco(integrator):
    assert_steps_from_a_turned_state(HELD, integrator, 3)


def test_an_arm_held_up_entirely_stays_still_and_without_gravity_nothing_is_held():
    """γ = 1 on every body of an arm fixed to the world (contacts off): at rest q̈ = 0 at any pose. With gravity
    disabled MuJoCo applies no compensation; neither does robodyn."""
    arm = HELD.replace('cone="{cone}"/>', '><flag contact="disable"/></option>').replace("<freejoint/>", "").replace(
        '<body name="lower" pos=".3 0 0">', '<body name="lower" pos=".3 0 0" gravcomp="1">').replace(
        'gravcomp="0.5"', 'gravcomp="1"').replace('gravcomp="0.8"', 'gravcomp="1"').replace('gravcomp="1.3"', 'gravcomp="1"')
    model = load_quietly(None, arm)
    q = model.random_configuration(seed=2)
    result = model.contact_forward_dynamics(q, np.zeros(model.nv))
    assert result["contacts"] == []
    assert_close(result["qdd"], np.zeros(model.nv), HELD_STILL, "q̈")
    weightless = arm.replace('<flag contact="disable"/>', '<flag contact="disable" gravity="disable"/>')
    model, mj_model, layout = load_both(weightless)
    mj_data = mujoco.MjData(mj_model)
    mujoco.mj_forward(mj_model, mj_data)
    assert_close(mj_data.qfrc_passive, np.zeros(mj_model.nv), 0.0, "MuJoCo without gravity")
    assert_matches_mujoco(model, mj_model, layout, mj_model.qpos0, np.zeros(mj_model.nv), label="no gravity")


# The shoulder's and the elbow's compensation counted as actuator forces (actuatorgravcomp), the
# shoulder's clamped with its motor's force to ±3 N·m.
ACTUATED = HELD.replace('<joint name="shoulder" axis="0 1 0" damping="0.1"/>',
                        '<joint name="shoulder" axis="0 1 0" damping="0.1" actuatorgravcomp="true" actuatorfrcrange="-3 3"/>').replace(
    '<joint name="elbow" axis="0 1 0" damping="0.1"/>', '<joint name="elbow" axis="0 1 0" damping="0.1" actuatorgravcomp="true"/>').replace(
    "</worldbody>", '</worldbody><actuator><motor joint="shoulder" gear="2"/></actuator>')


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_actuator_gravity_compensation_as_in_mujoco(cone):
    """actuatorgravcomp: the joint's compensation is in MuJoCo's qfrc_actuator, clamped with the
    actuators' forces by the joint's actuatorfrcrange (so a clamped shoulder holds less), and not in
    qfrc_passive: tau_actuator and q̈ at random states against mj_forward; no warning."""
    model, mj_model, layout = load_both(ACTUATED.replace("{cone}", cone))
    assert not [w for w in model.warnings if "actuatorgravcomp" in w], model.warnings
    rng = np.random.default_rng(7)
    clamped = 0
    for case in range(10):
        qpos = mj_model.qpos0.copy()
        mujoco.mj_integratePos(mj_model, qpos, rng.normal(size=mj_model.nv) * 0.5, 1.0)
        qvel, ctrl = rng.normal(size=mj_model.nv), rng.uniform(-2, 2, 1)
        ours, _ = assert_matches_mujoco(model, mj_model, layout, qpos, qvel, ctrl=ctrl, label=f"{cone} case {case}")
        shoulder = model.joint_idx_v[model.joint_names.index("shoulder")]
        clamped += abs(ours["tau_actuator"][shoulder]) == 3.0
    assert 0 < clamped < 10


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_actuator_gravity_compensation_steps_as_in_mujoco(integrator):
    assert_steps_from_a_turned_state(ACTUATED, integrator, 4, ctrl=[0.7])


#: q̈ of an arm held up entirely: the weights and their compensation cancel to round-off.
HELD_STILL = 1e-12
