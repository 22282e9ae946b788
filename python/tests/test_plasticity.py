"""Plastic springs (MJCF `springyield` on joints and tendons, MuJoCo 4.0's ideal
elasto-plasticity) against MuJoCo: the compiled yields and the initial plastic state, the forces
at a moved reference (`mj_forward`), 100 `mj_step` steps per integrator with the references moving
as MuJoCo moves them, a slack tendon's rule, keyframes' `plastic`, and what MuJoCo refuses.

A spring stretched past its yield y drags its reference after it so the stretch stays y, after
each step at the new configuration: a hinge's or slide's value, a ball's quaternion (turned back
by y about the axis of the stretch), a tendon's dead band [low, high] (which moves whole, except
that a slack tendon's low end at 0 stays there when it is stretched)."""

import re

import mujoco
import numpy as np
import pytest
import robodyn
from conftest import assert_close, assert_refused_as_in_mujoco, load_quietly
from test_contact_dynamics import load_both
from test_scene_stepping import INTEGRATORS, STEP_AGREEMENT, with_integrator

# A hinge, a slide and a ball with plastic springs (yields in degrees, the compiler's default),
# a fixed tendon over the hinge and the slide with a plastic dead band, a spatial tendon (slack
# below 0.5) with a plastic spring, a box on a floor tethered to a post by a third.
PLASTIC = """<mujoco><option timestep="0.004"/>
  <worldbody>
    <geom name="floor" type="plane" size="3 3 .1"/>
    <site name="anchor" pos="0 0 1.5"/>
    <body name="arm" pos="0 0 1">
      <joint name="hinge" axis="0 1 0" stiffness="8" springref="5" springyield="6" damping="0.05"/>
      <geom type="capsule" fromto="0 0 0 .4 0 0" size=".03" mass="1"/>
      <body name="carriage" pos=".4 0 0">
        <joint name="slide" type="slide" axis="1 0 0" stiffness="30 0 40" springyield="0.02"/>
        <geom type="box" size=".05 .05 .05" mass=".5"/>
        <body name="hand" pos=".1 0 0">
          <joint name="wrist" type="ball" stiffness="2" springyield="10" damping="0.01"/>
          <geom type="box" size=".06 .03 .02" pos=".06 0 0" mass=".2"/>
          <site name="grip" pos=".1 0 0"/></body></body></body>
    <site name="post" pos="1.5 0 .3"/>
    <body name="box" pos="1 0 .1">
      <freejoint name="box"/><geom name="box" type="box" size=".1 .1 .1" mass="1"/>
      <site name="ring" pos=".1 0 .05"/></body>
  </worldbody>
  <tendon>
    <fixed name="link" stiffness="20" springlength="0.05 0.1" springyield="0.01">
      <joint joint="hinge" coef="0.5"/><joint joint="slide" coef="1"/></fixed>
    <spatial name="cord" stiffness="15" springlength="0 0.5" springyield="0.03">
      <site site="anchor"/><site site="grip"/></spatial>
    <spatial name="tether" stiffness="40" springlength="0.3" springyield="0.02">
      <site site="post"/><site site="ring"/></spatial>
  </tendon>
</mujoco>"""

#: A fast swing: every spring yields within the first steps.
VELOCITY = {"hinge": 4.0, "slide": 1.5, "wrist": (3.0, -2.0, 5.0), "box": (-1.0, 0.5, 0.0, 0.0, 0.0, 3.0)}


def start(model, mj_model, layout):
    """MuJoCo's qpos0 and a qvel swinging the plastic joints (VELOCITY), the box at rest."""
    qvel = np.zeros(mj_model.nv)
    for name, value in VELOCITY.items():
        j = mj_model.joint(name)
        qvel[j.dofadr[0] : j.dofadr[0] + np.size(value)] = value
    return mj_model.qpos0.copy(), qvel


def test_yields_and_the_initial_plastic_state_are_read_as_mujoco_compiles_them():
    model, mj_model, layout = load_both(text=PLASTIC)
    mj_yield = [mj_model.jnt_springyield[j] for j in layout.mujoco_joints]
    assert_close(model.spring_yield, mj_yield, 1e-15, "spring_yield")
    assert_close(model.tendon_spring_yield, mj_model.tendon_springyield, 0.0, "tendon_spring_yield")
    assert model.nplastic == mj_model.nplastic == 1 + 1 + 4 + 2 + 2 + 2
    d = mujoco.MjData(mj_model)
    assert_close(model.plastic0, layout.plastic_from_mujoco(d.plastic), 1e-15, "plastic0")
    assert_close(layout.plastic_to_mujoco(model.plastic0), d.plastic, 1e-15, "plastic0 in MuJoCo's layout")
    # a model without a yield has no plastic state
    plain = load_quietly(None, re.sub(r'springyield="[^"]*"', 'springyield="0"', PLASTIC))
    assert plain.nplastic == 0 and plain.plastic0.shape == (0,)


def test_a_load_warning_says_only_the_scene_dynamics_yields():
    warned = [w for w in load_quietly(None, PLASTIC).warnings if "springyield" in w]
    assert len(warned) == 1, warned
    assert re.search(r"springs of joint 'hinge', .* tendon 'tether' yield .* other integrators .* elastic", warned[0])


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_forces_at_moved_references_are_mujocos(cone):
    """mj_forward with mjData.plastic moved (a hinge and a slide off, the ball's reference turned,
    both tendons' dead bands shifted): q̈ and the constraint forces."""
    model, mj_model, layout = load_both(text=PLASTIC.replace("<option", f'<option cone="{cone}"'))
    rng = np.random.default_rng(3)
    qpos, qvel = start(model, mj_model, layout)
    mujoco.mj_integratePos(mj_model, qpos, rng.normal(size=mj_model.nv) * 0.2, 1.0)
    d = mujoco.MjData(mj_model)
    d.qpos[:], d.qvel[:] = qpos, qvel
    turned = np.zeros(4)
    mujoco.mju_axisAngle2Quat(turned, [0.3, 0.5, 0.8] / np.linalg.norm([0.3, 0.5, 0.8]), 0.7)
    d.plastic[:] = [0.3, -0.05, *turned, 0.2, 0.3, 0.1, 0.4, 0.35, 0.38]
    mujoco.mj_forward(mj_model, d)
    q = layout.q_from_mujoco(qpos)
    v = layout.v_from_mujoco(q, qvel)
    ours = model.contact_forward_dynamics(q, v, plastic=layout.plastic_from_mujoco(d.plastic))
    assert_close(ours["qdd"], layout.a_from_mujoco(q, v, d.qacc), 1e-8, "qdd")
    # the plastic state moves the springs: without it robodyn's q̈ is another
    elastic = model.contact_forward_dynamics(q, v)
    assert np.max(np.abs(elastic["qdd"] - ours["qdd"])) > 1.0


def mujoco_plastic_steps(mj_model, qpos, qvel, steps=100, kicks=None):
    """MuJoCo's (qpos, qvel, plastic) after each step; `kicks` {step: qvel} sets the velocity
    before that step."""
    d = mujoco.MjData(mj_model)
    d.qpos[:], d.qvel[:] = qpos, qvel
    states = []
    for k in range(steps):
        if kicks and k in kicks:
            d.qvel[:] = kicks[k]
        mujoco.mj_step(mj_model, d)
        states.append((d.qpos.copy(), d.qvel.copy(), d.plastic.copy()))
    return states


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_plastic_springs_step_as_in_mujoco(integrator):
    """100 steps of robodyn.simulate are mj_step's, the plastic state included: every spring
    yields (the swing is fast), the box rests on the floor."""
    model, mj_model, layout = load_both(text=with_integrator(PLASTIC, integrator))
    qpos, qvel = start(model, mj_model, layout)
    q0 = layout.q_from_mujoco(qpos)
    h = model.options.timestep
    run = robodyn.simulate(model, q0, layout.v_from_mujoco(q0, qvel), t_end=100 * h, integrator="mujoco")
    assert run.plastic.shape == (101, model.nplastic)
    assert_close(run.plastic[0], model.plastic0, 0.0, "plastic at the start")
    for k, (qpos_k, qvel_k, plastic_k) in enumerate(mujoco_plastic_steps(mj_model, qpos, qvel), start=1):
        q, v = run.q[k], run.v[k]
        assert_close(layout.q_to_mujoco(q), qpos_k, STEP_AGREEMENT, f"{integrator} qpos, step {k}")
        assert_close(layout.v_to_mujoco(q, v), qvel_k, STEP_AGREEMENT, f"{integrator} qvel, step {k}")
        assert_close(layout.plastic_to_mujoco(run.plastic[k]), plastic_k, STEP_AGREEMENT, f"{integrator} plastic, step {k}")
    # each spring yielded: its reference left where it started
    moved = np.abs(layout.plastic_to_mujoco(run.plastic[-1]) - layout.plastic_to_mujoco(model.plastic0))
    for name, adr in [("hinge", mj_model.jnt_plasticadr[mj_model.joint("hinge").id]),
                      ("slide", mj_model.jnt_plasticadr[mj_model.joint("slide").id]),
                      ("link", mj_model.tendon_plasticadr[0]), ("cord", mj_model.tendon_plasticadr[1] + 1),
                      ("tether", mj_model.tendon_plasticadr[2])]:
        assert moved[adr] > 1e-3, name
    assert np.max(moved[2:6]) > 1e-3, "wrist"


# A fixed tendon on a slide pushed out, back and out again, its dead band given here.
SLACK = """<mujoco><compiler angle="radian"/><worldbody>
  <body><joint name="s" type="slide" axis="1 0 0"/><geom size=".1" mass="1"/></body></worldbody>
  <tendon><fixed name="t" stiffness="{k}" springlength="{band}" springyield="0.1">
    <joint joint="s" coef="1"/></fixed></tendon></mujoco>"""


@pytest.mark.parametrize("band", ["0 0.3", "-0.2 0.3", "0.1 0.3", "0 0"])
@pytest.mark.parametrize("k", [0, 5])
def test_a_tendons_dead_band_moves_as_in_mujoco(band, k):
    """The band moves whole when pushed past either end; a slack tendon's low end at exactly 0
    stays when it is stretched (also where the band reaches 0 on its way, "-0.2 0.3"); a spring
    without stiffness yields all the same. Step by step with robodyn.step."""
    text = SLACK.format(k=k, band=band)
    model, mj_model, _ = load_both(text=text)
    kicks = {0: [10.0], 50: [-20.0], 100: [20.0]}
    expected = mujoco_plastic_steps(mj_model, np.zeros(1), np.zeros(1), steps=150, kicks=kicks)
    q, v, plastic = np.zeros(1), np.zeros(1), model.plastic0
    for k_step, (qpos_k, _, plastic_k) in enumerate(expected):
        v = np.asarray(kicks.get(k_step, v), dtype=float)
        x = robodyn.step(model, q, v, np.zeros(1), model.options.timestep, integrator="mujoco", plastic=plastic)
        q, v, plastic = x[:1], x[1:2], x[2:]
        assert_close(q, qpos_k, STEP_AGREEMENT, f"q, step {k_step}")
        assert_close(plastic, plastic_k, STEP_AGREEMENT, f"plastic, step {k_step}")


def test_disabled_springs_do_not_yield():
    """MuJoCo moves no reference with <flag spring="disable">: neither does robodyn."""
    text = SLACK.format(k=5, band="0.3").replace("<worldbody>", '<option><flag spring="disable"/></option><worldbody>', 1)
    model = load_quietly(None, text)
    x = robodyn.step(model, [0.0], [-300.0], [0.0], model.options.timestep, integrator="mujoco")
    assert_close(x[2:], model.plastic0, 0.0, "plastic")
    assert x[0] < -0.5


# Keyframes: one with plastic (the ball's quaternion unnormalised), one without, one short.
KEYS = """<mujoco><compiler angle="radian"/><worldbody><body>
  <joint name="h" stiffness="1" springref="0.2" springyield="0.3"/><geom size=".1" mass="1"/>
  <body pos=".3 0 0"><joint name="b" type="ball" stiffness="1" springyield="0.5"/>
  <geom type="box" size=".1 .05 .02" pos=".1 0 0" mass="1"/></body></body></worldbody>
  <keyframe><key name="given" qpos="1 1 0 0 0" plastic="0.7 0 2 0 0"/><key name="none" qpos="1 1 0 0 0"/>
    <key name="short" plastic="0.4"/></keyframe></mujoco>"""


def test_keyframes_carry_the_plastic_state_as_mujoco_reads_it():
    model, mj_model, layout = load_both(text=KEYS)
    for k, name in enumerate(["given", "none", "short"]):
        d = mujoco.MjData(mj_model)
        mujoco.mj_resetDataKeyframe(mj_model, d, k)
        assert_close(model.keyframe(name).plastic, layout.plastic_from_mujoco(d.plastic), 1e-15, name)
        # a run from the key starts at its plastic state and steps as MuJoCo steps
        run = robodyn.simulate(model, name, t_end=10 * model.options.timestep, integrator="mujoco")
        assert_close(run.plastic[0], model.keyframe(name).plastic, 0.0, f"{name} start")
        for _ in range(10):
            mujoco.mj_step(mj_model, d)
        assert_close(layout.plastic_to_mujoco(run.plastic[-1]), d.plastic, STEP_AGREEMENT, f"{name} after 10 steps")
    assert_close(model.keyframe("given").plastic, [0.7, 1, 0, 0, 0], 0.0, "a ball's reference scalar last")
    # a Keyframe made in Python carries it too, through pickling
    import pickle

    key = pickle.loads(pickle.dumps(model.keyframe("given")))
    assert_close(key.plastic, model.keyframe("given").plastic, 0.0, "pickled")
    assert_close(pickle.loads(pickle.dumps(model)).plastic0, model.plastic0, 0.0, "pickled model")


@pytest.mark.parametrize(("text", "match"), [
    (KEYS.replace('springyield="0.3"', 'springyield="-0.3"'), "springyield.*≥ 0"),
    ('<mujoco><worldbody><body><joint type="free" springyield="0.1"/><geom size=".1"/></body></worldbody></mujoco>',
     "springyield.*free joint"),
    (SLACK.format(k=1, band="0 0.3").replace('springyield="0.1"', 'springyield="-1"'), "springyield.*≥ 0"),
    (KEYS.replace('plastic="0.4"', 'plastic="0.4 1 0 0 0 1"'), "plastic.*at most 5"),
])
def test_what_mujoco_refuses_is_refused(text, match):
    assert_refused_as_in_mujoco(text, match)


def test_a_plastic_state_of_the_wrong_shape_or_not_unit_is_refused_naming_it():
    model = load_quietly(None, KEYS)
    h = model.options.timestep
    with pytest.raises(ValueError, match="plastic0"):
        robodyn.simulate(model, model.neutral(), t_end=h, integrator="mujoco", plastic0=[0.1])
    with pytest.raises(ValueError, match=r"plastic.*unit quaternion.*joint 'b'"):
        robodyn.step(model, model.neutral(), np.zeros(4), np.zeros(4), h, integrator="mujoco",
                     plastic=[0.1, 0, 0, 0, 2])
    with pytest.raises(ValueError, match="plastic"):
        model.contact_forward_dynamics(model.neutral(), np.zeros(4), plastic=[0.1, 0, 0])
    with pytest.raises(ValueError, match="plastic0.*integrator='mujoco'"):
        robodyn.simulate(model, model.neutral(), t_end=h, plastic0=model.plastic0)
