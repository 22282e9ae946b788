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
    # a polynomial damping (MuJoCo's actuator_dampingpoly) joins its joint's, times gear²
    polynomial = ACTUATED.replace('<motor name="push" joint="slide" gear="2"/>',
                                  '<motor name="push" joint="slide" gear="2" damping="0.5 0.2"/>')
    assert mujoco.MjModel.from_xml_string(polynomial).actuator_dampingpoly[0, 0] == 0.2
    damped = robodyn.load_mjcf_string(polynomial)
    assert not [w for w in damped.warnings if "polynomial" in w], damped.warnings
    slide = damped.joint_idx_v[damped.joint_names.index("slide")]
    assert damped.damping_poly[slide].tolist() == [4 * 0.2, 0.0]
    # more than b b₁ b₂: refused, as MuJoCo refuses it
    four = polynomial.replace('damping="0.5 0.2"', 'damping="0.5 0.2 0.1 0.3"')
    with pytest.raises(ValueError, match=r"attribute 'damping': expected at most 3 numbers \(c c₁ c₂\), got 4"):
        robodyn.load_mjcf_string(four)
    with pytest.raises(ValueError, match="too much data"):
        mujoco.MjModel.from_xml_string(four)
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


#: Two hinges under gravity (one limited, with armature), a fixed tendon across both; `{defaults}`
#: and `{actuator}` filled in by each case of ACTUATOR_DEFAULTS.
DEFAULTS_ARM = """<mujoco><compiler angle="radian"/>
  <default>{defaults}</default>
  <worldbody>
    <body name="upper">
      <joint name="j" axis="0 1 0" range="-1 2" armature="0.1"/>
      <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.03"/>
      <body name="fore" pos="0.4 0 0">
        <joint name="j2" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.025"/>
      </body>
    </body>
  </worldbody>
  <tendon><fixed name="t"><joint joint="j" coef="1"/><joint joint="j2" coef="0.5"/></fixed></tendon>
  <actuator>{actuator}</actuator>
</mujoco>"""

#: (a class's actuator defaults, an actuator): what MuJoCo's rule passes on (pairs found by a
#: randomised search against MuJoCo 4.0.0 among them). A class has one
#: actuator default; a shortcut takes its parameters only from a default written with the same
#: shortcut or a `general` of its gain type (nearest class first), mechanical ones (ranges, gear)
#: from any; a `general` takes the raw parameters whatever wrote them; damping ratios.
ACTUATOR_DEFAULTS = [
    ('<position kp="10"/>', '<velocity joint="j"/>'),
    ('<position kp="10"/>', '<motor joint="j"/>'),
    ('<position kp="10" kv="2"/>', '<general joint="j"/>'),
    ('<position kp="3" timeconst="0.2"/>', '<general joint="j"/>'),
    ('<position kp="3"/><velocity kv="5"/>', '<position joint="j"/>'),
    ('<velocity kv="5"/><position kp="3"/>', '<position joint="j"/>'),
    ('<position kp="3"/><default class="c"><velocity kv="5"/></default>', '<position joint="j" class="c"/>'),
    ('<position kp="3" kv="2"/><default class="c"><position timeconst="0.5"/></default>',
     '<position joint="j" class="c"/>'),
    ('<position kp="3"/><general dyntype="filter"/>', '<velocity joint="j"/>'),
    ('<general gaintype="affine"/><default class="c"><general gainprm="5"/></default>',
     '<position joint="j" class="c"/>'),
    ('<position kp="3"/><default class="c"><general gaintype="affine" gainprm="5"/></default>',
     '<position joint="j" class="c"/>'),
    ('<general gainprm="400" biastype="affine" biasprm="0 -400 -10"/>', '<position joint="j"/>'),
    ('<general gainprm="400" biastype="affine" biasprm="0 -400 -10"/>', '<velocity joint="j"/>'),
    ('<general gainprm="40" dyntype="integrator" biastype="affine" biasprm="0 -40 -2"/>', '<position joint="j"/>'),
    ('<general dyntype="filterexact" dynprm="0.3" gainprm="5"/>', '<position joint="j"/>'),
    ('<general dyntype="filter" dynprm="0.3"/>', '<cylinder joint="j"/>'),
    ('<general gainprm="4" biastype="affine" biasprm="1 2 3" dynprm="0.4"/>', '<cylinder joint="j"/>'),
    ('<general gaintype="affine" gainprm="7 2 3" dyntype="filter" dynprm="0.3"/>', '<cylinder joint="j"/>'),
    ('<cylinder area="3" timeconst="0.4" bias="1 2 3"/>', '<cylinder joint="j" area="2"/>'),
    ('<general gaintype="affine" gainprm="0 0 -3"/>', '<damper joint="j" ctrlrange="0 1"/>'),
    ('<damper kv="3" ctrlrange="0 1"/>', '<position joint="j"/>'),
    ('<damper kv="3" ctrlrange="0 1"/>', '<general joint="j"/>'),
    ('<position kp="3" ctrlrange="-1 1" gear="2" forcerange="-4 4"/>', '<motor joint="j"/>'),
    ('<position kp="3" inheritrange="0.5"/>', '<general joint="j"/>'),
    ('<position kp="3" inheritrange="0.5"/>', '<intvelocity joint="j"/>'),
    ('<position kp="3" inheritrange="0.5"/>', '<position joint="j" ctrlrange="-3 3"/>'),
    ('<position kp="3" ctrlrange="-3 3"/>', '<position joint="j" inheritrange="0.5"/>'),
    ('<general gainprm="40" dyntype="integrator" biastype="affine" biasprm="0 -40 0" inheritrange="0.5"/>',
     '<general joint="j"/>'),
    ('<intvelocity kp="3" actrange="-1 1"/>', '<intvelocity joint="j"/>'),
    ('<position kp="3" dampratio="1"/>', '<position joint="j" kv="1"/>'),
    ('<position kp="3" dampratio="0.7"/>', '<general joint="j" armature="0.05" gear="1.5"/>'),
    ('<position kp="30" dampratio="1.2"/>', '<position tendon="t" gear="2"/>'),
    ('', '<position joint="j2" kp="8" dampratio="1" timeconst="0.05"/>'),
    # a shortcut sets its activation layout without a general's actearly
    ('<general actearly="true"/>', '<intvelocity joint="j"/>'),
    ('<general actearly="true"/>', '<position joint="j" kp="3" timeconst="0.1"/>'),
    ('<general actearly="true" dyntype="filter"/>', '<general joint="j"/>'),
    # a damper default limits the control whatever ctrllimited said before it
    ('<general ctrllimited="false"/><damper kv="2" ctrlrange="0.5 1"/>', '<motor joint="j"/>'),
    ('<general ctrllimited="false"/><damper kv="2" ctrlrange="0.5 1"/>', '<general joint="j"/>'),
    ('<motor ctrllimited="false"/>', '<damper joint="j" kv="2" ctrlrange="0.5 1"/>'),
    # a shortcut's own range and inheritrange clear each other; a general's inheritrange wins
    ('<motor ctrlrange="-2 -1"/><position inheritrange="0.5"/>', '<motor joint="j"/>'),
    ('<general inheritrange="0.5"/><default class="k"><position ctrlrange="-1 1"/></default>',
     '<position joint="j" class="k"/>'),
    ('<position kp="1" inheritrange="0.5"/>', '<general joint="j" ctrlrange="-1 1"/>'),
    ('<position timeconst="0.49"/><default class="k"><general/><intvelocity/></default>',
     '<general joint="j" class="k" dyntype="filter"/>'),
]


@pytest.mark.parametrize("defaults, actuator", ACTUATOR_DEFAULTS)
def test_actuator_defaults_pass_on_as_in_mujoco(defaults, actuator):
    """Forces, activation rates, control and activation ranges as MuJoCo compiles the case."""
    text = DEFAULTS_ARM.format(defaults=defaults, actuator=actuator)
    model, compiled = robodyn.load_mjcf_string(text), mujoco.MjModel.from_xml_string(text)
    assert model.warnings == []
    assert (model.nu, model.na) == (compiled.nu, compiled.na) == (1, compiled.na)
    limited = bool(compiled.actuator_ctrllimited[0])
    expected_range = compiled.actuator_ctrlrange[0] if limited else [-np.inf, np.inf]
    np.testing.assert_array_equal(model.ctrl_range[0], expected_range)
    layout, data = MujocoLayout(model, compiled), mujoco.MjData(compiled)
    rng = np.random.default_rng(5)
    for _ in range(5):
        q = rng.uniform(-1, 1, model.nq)
        v, ctrl, act = rng.normal(size=model.nv), rng.uniform(-4, 4, 1), rng.uniform(-2, 2, model.na)
        data.qpos[:], data.qvel[:], data.ctrl[:], data.act[:] = q, v, ctrl, act
        mujoco.mj_forward(compiled, data)
        tau = layout.force_from_mujoco(q, data.qfrc_actuator)
        scale = max(1.0, np.max(np.abs(tau)))
        np.testing.assert_allclose(model.actuator_forces(q, v, ctrl, act if model.na else None), tau,
                                   rtol=0, atol=FORCE_TOLERANCE * scale)
        if model.na:
            np.testing.assert_allclose(model.activation_rates(ctrl, act), data.act_dot, rtol=0, atol=1e-12)


def test_actuator_defaults_mujoco_refuses_are_refused():
    for defaults, actuator, message in [
        ("", '<position joint="j" kv="1" dampratio="1"/>', "'kv' and 'dampratio'"),
        ("", '<position joint="j" ctrlrange="-1 1" inheritrange="1"/>', "'ctrlrange' and 'inheritrange'"),
        ("", '<intvelocity joint="j" actrange="-1 1" inheritrange="1"/>', "'actrange' and 'inheritrange'"),
        ("", '<cylinder joint="j" bias="1"/>', "attribute 'bias': expected 3 numbers"),
        ('<position kv="-1"/>', '<position joint="j"/>', "attribute 'kv': expected a value ≥ 0"),
        ("", '<general joint="j" dyntype="filter" biastype="affine" biasprm="0 -1 0" inheritrange="1"/>',
         "attribute 'inheritrange': only for position and intvelocity"),
        ('<position kp="1" inheritrange="0.5"/>', '<general joint="j" ctrlrange="-1 1" dyntype="filter"/>',
         "attribute 'inheritrange': only for position and intvelocity"),
        ('<position kp="2"/><position kv="1"/>', '<position joint="j"/>', "holds one <position>, this is a second"),
        ('<general actrange="-1 1"/>', '<velocity joint="j"/>', "'actrange': an actuator without activation"),
        ("", '<general joint="j" actrange="-1 1"/>', "'actrange': an actuator without activation"),
        ("<damper/>", '<velocity joint="j"/>', "a limited range needs lower < upper"),
        ('<damper ctrlrange="-1 1"/>', '<motor joint="j"/>', "a damper's range cannot be negative"),
        ('<general gaintype="affine" gainprm="0 0 2"/>', '<damper joint="j" ctrlrange="0 1"/>',
         "a damper's kv must be ≥ 0"),
        ('<intvelocity actrange="-1 1" inheritrange="1"/>', '<intvelocity joint="j"/>',
         "'actrange' and 'inheritrange'"),
    ]:
        text = DEFAULTS_ARM.format(defaults=defaults, actuator=actuator)
        with pytest.raises(ValueError, match=message):
            robodyn.load_mjcf_string(text)
        with pytest.raises(ValueError):
            mujoco.MjModel.from_xml_string(text)
