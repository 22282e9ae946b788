"""Actuators with activation dynamics (MJCF `dyntype` integrator, filter, filterexact; `position
timeconst`, `intvelocity`, `cylinder`, `actearly`, `actrange`): MuJoCo's `act` state, its rates
`act_dot` and the forces it drives, against `mj_forward`; 100 steps of each integrator against
`mj_step`, activations included; the closed forms of a filter's and an integrator's response; a
keyframe's `act`; what is refused.

MuJoCo solves to convergence here (`converged`: Newton, tolerance 1e-15)."""

import mujoco
import numpy as np
import pytest
import robodyn
from conftest import assert_close, load_quietly
from test_contact_dynamics import load_both
from test_scene_stepping import INTEGRATORS, STEP_AGREEMENT, STEPS, with_integrator

# act_dot, qfrc_actuator and qacc at one state: the same arithmetic in another order (measured
# 1e-15 relative).
FORWARD_AGREEMENT = 1e-12
# The closed forms against the stepped activation: the same formula (filterexact) or a sum of
# equal steps (integrator).
CLOSED_FORM = 1e-12

ACTIVATED = """<mujoco><compiler angle="radian"/><option timestep="0.005"/>
  <default><geom contype="0" conaffinity="0"/></default>
  <worldbody>
    <body name="cart" pos="0 0 1">
      <joint name="slide" type="slide" axis="1 0 0" range="-0.2 0.2"/>
      <geom name="cart" type="box" size="0.1 0.1 0.05"/>
      <body name="upper">
        <joint name="shoulder" axis="0 1 0" range="-1 1"/>
        <geom name="upper" type="capsule" fromto="0 0 0 0.4 0 0" size="0.03"/>
        <body name="fore" pos="0.4 0 0">
          <joint name="elbow" axis="0 1 0" damping="0.2"/>
          <geom name="fore" type="capsule" fromto="0 0 0 0.3 0 0" size="0.025"/>
          <body name="hand" pos="0.3 0 0">
            <joint name="wrist" axis="0 0 1"/>
            <geom name="hand" type="box" size="0.05 0.03 0.02" pos="0.05 0 0"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <tendon><fixed name="pair"><joint joint="shoulder" coef="1"/><joint joint="elbow" coef="0.5"/></fixed></tendon>
  <actuator>
    <general name="integrate" joint="slide" dyntype="integrator" gainprm="40" biastype="affine"
             biasprm="0 -40 -4" actrange="-0.15 0.15" ctrlrange="-1 1"/>
    <general name="filter" joint="shoulder" dyntype="filter" dynprm="0.05" gainprm="3" ctrlrange="-2 2"/>
    <position name="lag" joint="elbow" kp="20" kv="1" timeconst="0.03"/>
    <general name="early" tendon="pair" dyntype="filterexact" dynprm="0.02" actearly="true" gaintype="affine"
             gainprm="2 0 -0.5" actrange="-1 1"/>
    <intvelocity name="speed" joint="wrist" kp="1" kv="0.02" actrange="-1 1"/>
    <cylinder name="piston" joint="wrist" timeconst="0.1" area="0.02" bias="0 0 -0.01"/>
    <motor name="plain" joint="shoulder" gear="0.5"/>
    <damper name="brake" joint="elbow" kv="0.3" ctrlrange="0 1"/>
  </actuator>
  <keyframe>
    <key name="primed" qpos="0.05 0.2 -0.3 0.1" qvel="0.1 -0.5 0.8 2" act="0.1 -0.5 0.2 0.3 0.4 0.5"
         ctrl="0.5 3 0.1 -0.8 0.3 1 0.4 1.5"/>
  </keyframe>
</mujoco>"""


def mujoco_forward(mj_model, qpos, qvel, ctrl, act):
    """MuJoCo's mj_forward at (qpos, qvel, act) under ctrl."""
    d = mujoco.MjData(mj_model)
    d.qpos[:], d.qvel[:], d.ctrl[:], d.act[:] = qpos, qvel, ctrl, act
    mujoco.mj_forward(mj_model, d)
    return d


def random_forwards(model, mj_model, layout, seed, cases=5):
    """At `cases` random states, activations and controls (some outside their ranges, the
    activations too): (q, v, ctrl, act, MuJoCo's mj_forward, robodyn's contact_forward_dynamics)."""
    rng = np.random.default_rng(seed)
    for _ in range(cases):
        qpos = rng.uniform(-0.15, 0.15, size=4)
        qvel, act, ctrl = rng.normal(size=4), rng.uniform(-1.2, 1.2, size=6), rng.uniform(-2.5, 2.5, size=8)
        d = mujoco_forward(mj_model, qpos, qvel, ctrl, act)
        q = layout.q_from_mujoco(qpos)
        v = layout.v_from_mujoco(q, qvel)
        yield q, v, ctrl, act, d, model.contact_forward_dynamics(q, v, ctrl=ctrl, act=act)


def test_activation_dynamics_are_read_as_mujoco_compiles_them():
    model, mj_model, _ = load_both(ACTIVATED)
    assert model.warnings == []
    assert model.na == mj_model.na == 6
    key = model.keyframe("primed")
    assert np.array_equal(key.act, [0.1, -0.5, 0.2, 0.3, 0.4, 0.5])


def test_activations_drive_the_forces_as_in_mujoco():
    """At random states, activations and controls (some outside their ranges, the activations too:
    MuJoCo clamps w only as it integrates): act_dot, qfrc_actuator and qacc as mj_forward's."""
    model, mj_model, layout = load_both(ACTIVATED)
    for case, (q, v, ctrl, act, d, ours) in enumerate(random_forwards(model, mj_model, layout, 11)):
        scale = max(1.0, np.max(np.abs(d.act_dot)))
        assert np.max(np.abs(ours["act_dot"] - d.act_dot)) <= FORWARD_AGREEMENT * scale, f"case {case}"
        assert np.allclose(model.activation_rates(ctrl, act), d.act_dot, rtol=0, atol=FORWARD_AGREEMENT * scale)
        tau = layout.force_from_mujoco(q, d.qfrc_actuator)
        assert np.allclose(ours["tau_actuator"], tau, rtol=0, atol=FORWARD_AGREEMENT * max(1.0, np.max(np.abs(tau))))
        assert np.allclose(model.actuator_forces(q, v, ctrl, act), tau, rtol=0, atol=1e-12 * max(1.0, np.max(np.abs(tau))))
        qacc = layout.a_from_mujoco(q, v, d.qacc)
        assert np.allclose(ours["qdd"], qacc, rtol=0, atol=FORWARD_AGREEMENT * max(1.0, np.max(np.abs(qacc))))


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_activations_step_as_in_mujoco(integrator):
    """From the keyframe (its q, v, ctrl and act), 100 steps of each integrator: q, v and act as
    mj_step's, the activations clamped to their ranges as they go (the integrator's slide saturates);
    the filter's and the damper's controls past their ranges (implicitfast's K takes them clamped)."""
    text = with_integrator(ACTIVATED, integrator)
    model, mj_model, layout = load_both(text)
    h = model.options.timestep
    run = robodyn.simulate(model, "primed", t_end=STEPS * h, integrator="mujoco")
    d = mujoco.MjData(mj_model)
    mujoco.mj_resetDataKeyframe(mj_model, d, 0)
    saturated = False
    for k in range(1, STEPS + 1):
        mujoco.mj_step(mj_model, d)
        q, v = run.q[k], run.v[k]
        assert np.max(np.abs(layout.q_to_mujoco(q) - d.qpos)) <= STEP_AGREEMENT, f"step {k}"
        assert np.max(np.abs(layout.v_to_mujoco(q, v) - d.qvel)) <= STEP_AGREEMENT * max(1.0, np.max(np.abs(d.qvel)))
        assert np.max(np.abs(run.act[k] - d.act)) <= STEP_AGREEMENT, f"step {k}: {run.act[k]} vs {d.act}"
        saturated |= d.act[0] == 0.15
    assert saturated
    assert run.act.shape == (STEPS + 1, 6) and np.array_equal(run.act[0], model.keyframe("primed").act)
    # robodyn.step: one step of the same, [q1, v1, act1]
    key = model.keyframe("primed")
    x1 = robodyn.step(model, key.q, key.v, np.zeros(model.nv), h, integrator="mujoco", ctrl=key.ctrl, act=key.act)
    assert x1.shape == (model.nq + model.nv + model.na,)
    assert np.allclose(x1, np.concatenate([run.q[1], run.v[1], run.act[1]]), rtol=0, atol=1e-15)


def test_a_filter_and_an_integrator_follow_their_closed_forms():
    """On a fixed joint pair (no motion matters): filterexact's activation is u (1 − e^(−t/τ)) at
    every step, an integrator's u t until it meets its range, then held there."""
    text = """<mujoco><option timestep="0.01" gravity="0 0 0"/>
      <worldbody><body><joint name="j" type="slide"/><geom size=".1" mass="1"/></body></worldbody>
      <actuator>
        <general joint="j" dyntype="filterexact" dynprm="0.2" gainprm="0"/>
        <general joint="j" dyntype="integrator" gainprm="0" actrange="-1 0.5"/>
      </actuator></mujoco>"""
    model = load_quietly(None, text)
    run = robodyn.simulate(model, model.neutral(), t_end=1.0, integrator="mujoco", ctrl=[2.0, 0.75])
    t = run.t
    assert np.allclose(run.act[:, 0], 2.0 * (1 - np.exp(-t / 0.2)), rtol=0, atol=CLOSED_FORM)
    assert np.allclose(run.act[:, 1], np.minimum(0.75 * t, 0.5), rtol=0, atol=CLOSED_FORM)


def test_activations_robodyn_does_not_model_keep_their_places():
    """A PID's states (one per `ki`, `slewmax`), a user's `actdim`, a muscle's: counted as MuJoCo
    counts them, held (warned), so that a keyframe's `act` and the modelled ones line up."""
    text = ACTIVATED.replace("<actuator>", """<actuator>
    <pid name="pid" joint="slide" kp="1" ki="1" slewmax="2"/>
    <general name="user" joint="slide" dyntype="user" actdim="3"/>
    <muscle name="muscle" joint="shoulder"/>""").replace('act="0.1 ', 'act="0 0 0 0 0 0 0.1 ').replace(
        'ctrl="0.5 ', 'ctrl="0 0 0 0.5 ')
    model, mj_model, _ = load_both(text)
    assert model.na == mj_model.na == 12
    assert [w for w in model.warnings if "<pid" in w or "'user'" in w or "<muscle" in w]
    key, mj_key = model.keyframe("primed"), mj_model.key("primed")
    assert np.array_equal(key.act, mj_key.act)
    rates = model.activation_rates(key.ctrl, key.act)
    assert np.all(rates[:6] == 0.0) and rates[6] == 0.5  # the integrator: ẇ = u


def test_bad_activations_are_refused():
    model, _, _ = load_both(ACTIVATED)
    key = model.keyframe("primed")
    with pytest.raises(ValueError, match="'act'"):
        model.contact_forward_dynamics(key.q, key.v, act=np.zeros(5))
    with pytest.raises(ValueError, match="'act'"):
        robodyn.step(model, key.q, key.v, np.zeros(model.nv), 0.005, integrator="mujoco", act=np.zeros(2))
    with pytest.raises(ValueError, match="'act0'"):
        robodyn.simulate(model, key.q, t_end=0.01, integrator="mujoco", act0=np.zeros(7))
    with pytest.raises(ValueError, match="'act0'"):
        robodyn.simulate(model, key.q, t_end=0.01, act0=np.zeros(6))
    with pytest.raises(ValueError, match="'act'"):
        model.actuator_forces(key.q, key.v, key.ctrl, np.zeros(3))


@pytest.mark.parametrize("flag", ['actuation="disable"', 'clampctrl="disable"'])
def test_the_actuation_and_clampctrl_flags_as_in_mujoco(flag):
    """actuation disabled: the actuators exert nothing, every ẇ is 0 and an actuatorgravcomp joint's
    gravity compensation is lost; clampctrl disabled: controls past their ranges act as given. At
    random states against mj_forward, and 100 steps of each integrator from the keyframe."""
    text = ACTIVATED.replace('<option timestep="0.005"/>', f'<option timestep="0.005"><flag {flag}/></option>').replace(
        '<body name="fore" pos="0.4 0 0">', '<body name="fore" pos="0.4 0 0" gravcomp="1">').replace(
        '<joint name="elbow" axis="0 1 0" damping="0.2"/>', '<joint name="elbow" axis="0 1 0" damping="0.2" actuatorgravcomp="true"/>')
    model, mj_model, layout = load_both(text)
    assert not [w for w in model.warnings if "not followed" in w], model.warnings
    for case, (q, v, ctrl, act, d, ours) in enumerate(random_forwards(model, mj_model, layout, 13)):
        assert_close(ours["act_dot"], d.act_dot, FORWARD_AGREEMENT, f"{flag} case {case} act_dot")
        assert_close(model.activation_rates(ctrl, act), d.act_dot, FORWARD_AGREEMENT, "m.activation_rates")
        assert_close(ours["tau_actuator"], layout.force_from_mujoco(q, d.qfrc_actuator), FORWARD_AGREEMENT, "tau_actuator")
        assert_close(ours["qdd"], layout.a_from_mujoco(q, v, d.qacc), FORWARD_AGREEMENT, f"{flag} case {case} qdd")
    for integrator in INTEGRATORS:
        model, mj_model, layout = load_both(with_integrator(text, integrator))
        h = model.options.timestep
        run = robodyn.simulate(model, "primed", t_end=STEPS * h, integrator="mujoco")
        d = mujoco.MjData(mj_model)
        mujoco.mj_resetDataKeyframe(mj_model, d, 0)
        for k in range(1, STEPS + 1):
            mujoco.mj_step(mj_model, d)
            q, v = run.q[k], run.v[k]
            assert_close(layout.q_to_mujoco(q), d.qpos, STEP_AGREEMENT, f"{flag} {integrator} step {k} qpos")
            assert_close(layout.v_to_mujoco(q, v), d.qvel, STEP_AGREEMENT, f"{flag} {integrator} step {k} qvel")
            assert_close(run.act[k], d.act, STEP_AGREEMENT, f"{flag} {integrator} step {k} act")
