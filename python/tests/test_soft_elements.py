"""MuJoCo's soft model beyond contacts and joints (`m.contact_forward_dynamics` against `mj_forward`,
as in test_contact_dynamics.py): equality constraints of every kind robodyn reads, fixed tendons
(limits, friction, springs and dampers with polynomial terms, equalities, actuators), spatial tendons through sites and pulleys and around spheres and cylinders (and actuators on them,
their forces bounded together by a tendon's actuatorfrcrange), tendons' inertias (armature),
rows' ids past what robodyn does not read,
MuJoCo's simple bodies, and a URDF's mimic joints as joint equalities.

MuJoCo solves to convergence here (`converged`: Newton, tolerance 1e-15)."""

import mujoco
import numpy as np
import pytest
from conftest import assert_close, assert_refused_as_in_mujoco, load_quietly
from test_contact_dynamics import ROW_AGREEMENT, assert_entries_close, assert_matches_mujoco, load_both, mujoco_solution

# --- 6. equality constraints ------------------------------------------------------------------

# Every kind of MuJoCo equality robodyn reads: a weld between an arm and a free box (torquescale 2,
# its own solref), a free ball's point connected to the world, two sites connected (their own
# solimp), a site welded to a world site, a ball joint welded to the world at a relpose, a slide
# following a hinge by a polynomial, a hinge held, and an inactive connect; the ball rests on the
# floor.
EQUALITIES = """<mujoco><option timestep="0.002" cone="{cone}"/>
  <worldbody>
    <geom name="floor" type="plane" size="0 0 1"/>
    <site name="post" pos="0.5 -1 1.5"/>
    <body name="arm" pos="0 0 1"><joint name="shoulder" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 .5 0 0" size=".05"/>
      <body name="fore" pos=".5 0 0" euler="10 20 30">
        <joint name="elbow" axis="0 0 1"/><joint name="slide" type="slide" axis="1 0 0"/>
        <geom type="box" size=".2 .05 .05" pos=".2 0 0"/></body></body>
    <body name="box" pos="1 .3 1.2" euler="5 -10 40"><freejoint/>
      <geom name="box" type="box" size=".1 .2 .3" mass="2"/>
      <site name="corner" pos=".1 .2 .3"/></body>
    <body name="ball" pos="-1 0 0.09"><freejoint/><geom name="ball" type="sphere" size=".1"/>
      <site name="top" pos="0 0 .1"/></body>
    <body name="pendulum" pos="0.5 -1 2"><joint name="swing" axis="1 0 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 -.5" size=".03"/>
      <body name="bob" pos="0 0 -.5"><joint name="twist" axis="0 0 1"/><geom type="sphere" size=".06"/>
        <site name="tip" pos="0 0 0" euler="0 0 15"/></body></body>
    <body name="lever" pos="-1 1 1"><joint name="lever" type="ball"/><geom type="box" size=".3 .02 .02" pos=".3 0 0"/></body>
  </worldbody>
  <equality>
    <weld body1="fore" body2="box" torquescale="2" solref="0.03 0.8"/>
    <connect body1="ball" anchor="0 0 .1"/>
    <connect site1="top" site2="corner" solimp="0.8 0.95 0.01 0.4 3"/>
    <weld site1="tip" site2="post"/>
    <weld body1="lever" anchor="-1 1 1" relpose="0 0 0 0.9 0.1 0 0"/>
    <joint joint1="slide" joint2="shoulder" polycoef="0.1 0.5 0.2 0 0"/>
    <joint joint1="elbow" polycoef="0.2 0 0 0 0"/>
    <connect body1="arm" body2="lever" anchor="0 0 0" active="false"/>
  </equality></mujoco>"""
EQUALITY_ROWS = 6 + 3 + 3 + 6 + 6 + 1 + 1


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_equality_constraints_as_in_mujoco(cone):
    """The equality rows (MuJoCo's first block: per equality, its rows' Jacobian, R from the bodies'
    or joints' weights and the impedance of the norm of its error, a_ref with the weld's and
    connect's J̇ q̇) and the solution with them, at random states away from qpos0."""
    model, mj_model, layout = load_both(EQUALITIES.replace("{cone}", cone))
    rng = np.random.default_rng(6)
    ball_height = mj_model.jnt_qposadr[mj_model.body("ball").jntadr[0]] + 2
    for case in range(4):
        qpos = mj_model.qpos0.copy()
        mujoco.mj_integratePos(mj_model, qpos, rng.normal(size=mj_model.nv) * 0.1, 1.0)
        qpos[ball_height] = 0.08
        ours, _ = assert_matches_mujoco(model, mj_model, layout, qpos, rng.normal(size=mj_model.nv),
                                        tau=rng.normal(size=mj_model.nv), label=f"{cone} case {case}")
        kinds = list(ours["row_types"])
        assert kinds[:EQUALITY_ROWS] == ["equality"] * EQUALITY_ROWS and "equality" not in kinds[EQUALITY_ROWS:]
        assert 7 not in list(ours["row_ids"])[:EQUALITY_ROWS], "the inactive connect has no rows"
        assert any(kind.startswith("contact") for kind in kinds), "the ball touches the floor"


def test_a_disabled_equality_flag_drops_the_rows():
    """<flag equality="disable">: no equality rows, as in MuJoCo."""
    text = EQUALITIES.replace('cone="{cone}"/>', 'cone="pyramidal"><flag equality="disable"/></option>')
    model, mj_model, layout = load_both(text)
    ours, _ = assert_matches_mujoco(model, mj_model, layout, mj_model.qpos0, np.ones(mj_model.nv))
    assert "equality" not in list(ours["row_types"])


# --- 7. fixed tendons -------------------------------------------------------------------------

# An arm whose fixed tendons carry every part robodyn reads: limits (one with a margin, one from a
# class), dry friction with its own solreffriction, dampers, a spring with a dead band and one at
# the joints' springref, two tendon equalities (one coupling two tendons by a polynomial) after an
# inactive joint equality, and motor, position (inheritrange) and general (affine, forcerange,
# damping) actuators on tendons.
TENDONS = """<mujoco><option timestep="0.002" cone="{cone}"/>
  <default><tendon solreflimit="0.03 0.9"/><default class="stiff"><tendon stiffness="40" springlength="0.1 0.3"/></default></default>
  <worldbody>
    <body name="upper" pos="0 0 1"><joint name="shoulder" axis="0 1 0" springref="20" damping="0.1"/>
      <geom name="upper" type="capsule" fromto="0 0 0 .4 0 0" size=".04"/>
      <body name="lower" pos=".4 0 0"><joint name="elbow" axis="0 1 0" ref="10"/>
        <joint name="reach" type="slide" axis="1 0 0" range="-.1 .2"/>
        <geom name="lower" type="capsule" fromto="0 0 0 .3 0 0" size=".03"/>
        <body name="hand" pos=".3 0 0"><joint name="wrist" axis="0 0 1" springref="25"/>
          <geom name="hand" type="box" size=".05 .03 .02"/></body></body></body>
  </worldbody>
  <tendon>
    <fixed name="flex" range="-0.4 0.5" margin="0.05" frictionloss="0.3" damping="0.7" solreffriction="0.05 1">
      <joint joint="shoulder" coef="1"/><joint joint="elbow" coef="-0.5"/></fixed>
    <fixed name="span" class="stiff" limited="true" range="-0.05 0.25">
      <joint joint="elbow" coef="0.3"/><joint joint="reach" coef="2"/></fixed>
    <fixed name="twist" damping="0.2"><joint joint="wrist" coef="1"/><joint joint="shoulder" coef="0.2"/></fixed>
    <fixed name="rest" stiffness="5"><joint joint="wrist" coef="-1"/></fixed>
  </tendon>
  <equality>
    <joint joint1="wrist" joint2="shoulder" polycoef="0 0.1 0 0 0" active="false"/>
    <tendon name="pair" tendon1="twist" tendon2="flex" polycoef="0.05 0.4 -0.3 0 0" solref="0.02 0.7"/>
    <tendon tendon1="rest" polycoef="0.1 0 0 0 0"/>
  </equality>
  <actuator>
    <motor tendon="flex" gear="2" ctrlrange="-1 1"/>
    <position tendon="span" kp="30" kv="2" inheritrange="1"/>
    <general tendon="twist" gainprm="3 0.5 0.2" gaintype="affine" biasprm="0.1 -1 -0.5" biastype="affine" forcerange="-2 2" damping="0.3"/>
    <velocity joint="shoulder" kv="0.5"/>
  </actuator>
</mujoco>"""


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_fixed_tendons_as_in_mujoco(cone):
    """Tendon friction and limit rows (after the dofs' and the joints'), tendon equality rows (ids in
    the file's order), tendon springs and dampers in q̈₀, tendon actuators, against MuJoCo."""
    model, mj_model, layout = load_both(TENDONS.replace("{cone}", cone))
    assert model.tendon_names == ["flex", "span", "twist", "rest"]
    rng, kinds = np.random.default_rng(3), set()
    for case in range(12):
        qpos = mj_model.qpos0 + rng.normal(size=mj_model.nq) * 0.4
        qvel, tau = rng.normal(size=mj_model.nv), rng.normal(size=mj_model.nv)
        ours, _ = assert_matches_mujoco(model, mj_model, layout, qpos, qvel, tau, rng.uniform(-1.5, 1.5, size=mj_model.nu),
                                        label=f"{cone} case {case}")
        kinds |= {(kind, int(i)) for kind, i in zip(ours["row_types"], ours["row_ids"])}
    assert {("equality", 1), ("equality", 2), ("friction_tendon", 0), ("limit_tendon", 0), ("limit_tendon", 1)} <= kinds


# The tendons above with polynomial springs and dampers (MuJoCo's tendon_stiffnesspoly and
# tendon_dampingpoly): −x (k + k₁ x + k₂ x²) and −L̇ (b + b₁ |L̇| + b₂ L̇²), and an actuator's
# polynomial damping joining its tendon's times gear².
TENDON_POLYNOMIALS = (TENDONS.replace('stiffness="40"', 'stiffness="40 -30 25"')
                      .replace('frictionloss="0.3" damping="0.7"', 'frictionloss="0.3" damping="0.7 0.4 0.3"')
                      .replace('<fixed name="rest" stiffness="5">', '<fixed name="rest" stiffness="5 2 1">')
                      .replace('forcerange="-2 2" damping="0.3"/>', 'forcerange="-2 2" damping="0.3 0.05 0.02" gear="1.2"/>'))


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_tendon_polynomial_springs_and_dampers_as_in_mujoco(cone):
    """The polynomial terms in q̈₀ (through the rows' a_ref and the solution), against mj_forward at
    random states; they move the accelerations."""
    model, mj_model, layout = load_both(TENDON_POLYNOMIALS.replace("{cone}", cone))
    assert not [w for w in model.warnings if "not modelled" in w], model.warnings
    assert mj_model.tendon_stiffnesspoly[1].tolist() == [-30, 25] and mj_model.actuator_dampingpoly[2].tolist() == [0.05, 0.02]
    linear, _, _ = load_both(TENDONS.replace("{cone}", cone))
    rng = np.random.default_rng(3)
    for case in range(10):
        qpos = mj_model.qpos0 + rng.normal(size=mj_model.nq) * 0.4
        qvel, ctrl = rng.normal(size=mj_model.nv), rng.uniform(-1.5, 1.5, size=mj_model.nu)
        ours, _ = assert_matches_mujoco(model, mj_model, layout, qpos, qvel, ctrl=ctrl, label=f"{cone} case {case}")
        q = layout.q_from_mujoco(qpos)
        without = linear.contact_forward_dynamics(q, layout.v_from_mujoco(q, qvel), ctrl=ctrl)["qdd"]
        assert np.max(np.abs(ours["qdd"] - without)) > 1e-3


def test_tendon_polynomials_mujoco_refuses_are_refused():
    text = TENDONS.replace("{cone}", "pyramidal").replace('<fixed name="rest" stiffness="5">', '<fixed name="rest" stiffness="5 1 1 1">')
    assert_refused_as_in_mujoco(text, r"attribute 'stiffness': expected at most 3 numbers \(c c₁ c₂\), got 4")


def test_tendon_lengths_as_in_mujoco():
    """m.tendon_lengths(q) is MuJoCo's ten_length, one state and a batch."""
    model, mj_model, layout = load_both(TENDONS.replace("{cone}", "pyramidal"))
    rng, d = np.random.default_rng(8), mujoco.MjData(mj_model)
    states = [mj_model.qpos0 + rng.normal(size=mj_model.nq) for _ in range(3)]
    expected = []
    for qpos in states:
        d.qpos[:] = qpos
        mujoco.mj_fwdPosition(mj_model, d)
        expected.append(d.ten_length.copy())
    batch = model.tendon_lengths(np.array([layout.q_from_mujoco(qpos) for qpos in states]))
    assert_close(batch, np.array(expected), ROW_AGREEMENT, "batch")
    assert_close(model.tendon_lengths(layout.q_from_mujoco(states[0])), expected[0], ROW_AGREEMENT, "one")


MIXED_ELEMENTS = """<mujoco><option timestep="0.002"/>
  <worldbody>
    <site name="s0" pos="0 0 1.5"/>
    <geom name="pin" type="cylinder" size=".02 .05" pos=".15 0 1.3" contype="0" conaffinity="0"/>
    <body name="a" pos="0 0 1"><joint name="j1" axis="0 1 0" range="-1 1"/>
      <geom type="capsule" fromto="0 0 0 .3 0 0" size=".03"/>
      <body name="b" pos=".3 0 0"><joint name="j2" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 .3 0 0" size=".03"/><site name="s2" pos=".3 0 0"/></body></body>
  </worldbody>
  <tendon>
    <spatial name="rope"><site site="s0"/><geom geom="pin"/><site site="s2"/></spatial>
    <fixed name="idle" frictionloss="0.5" range="-0.1 0.1" margin="0.5"><joint joint="j1" coef="0"/></fixed>
    <fixed name="pair" frictionloss="0.2" range="-0.1 0.1"><joint joint="j1" coef="1"/><joint joint="j2" coef="0.5"/></fixed>
  </tendon>
  <equality>
    <tendon tendon1="rope" active="false"/>
    <joint joint1="j2" joint2="j1" polycoef="0 0.5 0 0 0"/>
  </equality>
</mujoco>"""


def test_rows_carry_mujocos_ids_in_the_files_order():
    """A spatial tendon wrapping a geom before the fixed ones, and its (inactive) equality before a joint
    equality: the rows' ids are MuJoCo's (tendon 2, equality 1); a tendon whose Jacobian is zero has no
    rows, as in MuJoCo (its friction and its limit within the margin)."""
    model, mj_model, layout = load_both(MIXED_ELEMENTS)
    _, expected = assert_matches_mujoco(model, mj_model, layout, np.array([0.3, -0.2]), np.array([0.4, -1.0]))
    assert expected["row_types"] == ["equality", "friction_tendon", "limit_joint", "limit_tendon"]
    assert list(expected["row_ids"]) == [1, 2, 0, 2]


# --- 7b. spatial tendons ----------------------------------------------------------------------

# Sites on an arm, on the world and on a free-floating box (whose velocities robodyn measures in
# its own axes): a cord through three bodies with a limit, friction, a spring's dead band and a
# damper; a block and tackle (a pulley halves the second branch); two sites on one body; a
# tendon equality between spatial tendons. No contacts: the tendons alone.
SPATIAL = """<mujoco><option timestep="0.002" cone="{cone}"/>
  <default><geom contype="0" conaffinity="0"/></default>
  <worldbody>
    <site name="anchor" pos="0 0.2 1.6"/><site name="hook" pos="0.5 0 1.8"/>
    <body name="upper" pos="0 0 1"><joint name="shoulder" axis="0 1 0" damping="0.05"/>
      <geom type="capsule" fromto="0 0 0 .4 0 0" size=".04"/><site name="elbow_in" pos=".2 0 .05"/>
      <body name="lower" pos=".4 0 0"><joint name="elbow" axis="0 1 0"/>
        <joint name="reach" type="slide" axis="1 0 0" range="-.1 .2"/>
        <geom type="capsule" fromto="0 0 0 .3 0 0" size=".03"/>
        <site name="mid" pos=".1 0 .03"/><site name="tip" pos=".3 0 0"/></body></body>
    <body name="float" pos="0.6 0.1 1.2" euler="0.3 0.2 0.1"><joint type="free" stiffness="3" damping="0.02"/><geom type="box" size=".05 .04 .03"/>
      <site name="eye" pos="0 0 .03"/><site name="eye2" pos=".05 0 0"/></body>
  </worldbody>
  <tendon>
    <spatial name="cord" range="0.2 0.95" margin="0.05" frictionloss="0.2" damping="0.4" stiffness="30"
             springlength="0.5 0.6"><site site="anchor"/><site site="elbow_in"/><site site="tip"/><site site="eye"/></spatial>
    <spatial name="tackle" damping="0.3" stiffness="10"><site site="hook"/><site site="eye2"/>
      <pulley divisor="2"/><site site="eye2"/><site site="mid"/></spatial>
    <spatial name="inner" limited="true" range="0 0.5"><site site="mid"/><site site="tip"/><site site="eye"/></spatial>
  </tendon>
  <equality><tendon tendon1="inner" tendon2="tackle" polycoef="0 0.3 0 0 0" solref="0.05 1"/></equality>
</mujoco>"""


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_spatial_tendons_as_in_mujoco(cone):
    """Spatial tendons' limit, friction and equality rows, springs and dampers, against mj_forward
    at random states; their lengths (one state and a batch) as MuJoCo's ten_length."""
    model, mj_model, layout = load_both(SPATIAL.replace("{cone}", cone))
    assert not [w for w in model.warnings if "not read" in w or "not modelled" in w], model.warnings
    assert model.tendon_names == ["cord", "tackle", "inner"]
    rng, kinds, d = np.random.default_rng(6), set(), mujoco.MjData(mj_model)
    for case in range(12):
        qpos = mj_model.qpos0.copy()
        mujoco.mj_integratePos(mj_model, qpos, rng.normal(size=mj_model.nv) * 0.4, 1.0)
        qvel, tau = rng.normal(size=mj_model.nv), rng.normal(size=mj_model.nv)
        ours, _ = assert_matches_mujoco(model, mj_model, layout, qpos, qvel, tau, label=f"{cone} case {case}")
        kinds |= {(kind, int(i)) for kind, i in zip(ours["row_types"], ours["row_ids"])}
        d.qpos[:] = qpos
        mujoco.mj_fwdPosition(mj_model, d)
        assert_close(model.tendon_lengths(layout.q_from_mujoco(qpos)), d.ten_length, ROW_AGREEMENT, f"case {case}")
    assert {("equality", 0), ("friction_tendon", 0), ("limit_tendon", 0), ("limit_tendon", 2)} <= kinds


def test_spatial_tendon_paths_mujoco_refuses_are_refused():
    sites = '<site site="anchor"/>', '<site site="tip"/>'
    for path, message in [
        (sites[0], "two stops or more"),
        (f'{sites[0]}{sites[1]}<pulley divisor="2"/><pulley divisor="2"/>{sites[1]}{sites[0]}', "consecutive pulleys"),
        (f'{sites[0]}{sites[1]}<pulley divisor="2"/>', "ends with a pulley"),
        (f'{sites[0]}<pulley divisor="2"/>{sites[1]}', "needs a neighbour that is not a pulley"),
        (f'{sites[0]}{sites[0]}{sites[1]}', "repeated next to itself"),
        ('<site site="nowhere"/><site site="tip"/>', "no site named 'nowhere'"),
        (f'{sites[0]}<pulley divisor="0"/>{sites[1]}{sites[0]}', "'divisor': expected > 0"),
    ]:
        text = SPATIAL.replace("{cone}", "pyramidal").replace("</tendon>", f'<spatial name="bad">{path}</spatial></tendon>')
        with pytest.raises(ValueError, match=message):
            load_quietly(None, text)
        with pytest.raises(ValueError):
            mujoco.MjModel.from_xml_string(text)
    text = SPATIAL.replace("{cone}", "pyramidal").replace("</tendon>", f'<spatial width="0">{sites[0]}{sites[1]}</spatial></tendon>')
    with pytest.raises(ValueError, match="'width': expected a positive width"):
        load_quietly(None, text)
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_string(text)


# Actuators on the spatial tendons above: a motor (gear 2), a position servo (kp, kv), a velocity
# servo, a general one with a filtered activation and affine gain and bias, and a position servo
# whose kv MuJoCo's compiler derives from a damping ratio and the inertia the tendon sees at qpos0.
SPATIAL_ACTUATORS = SPATIAL.replace("</mujoco>", """<actuator>
    <motor name="reel" tendon="cord" gear="2" ctrlrange="-1 1"/>
    <position name="winch" tendon="tackle" kp="40" kv="3"/>
    <velocity name="brake" tendon="inner" kv="5"/>
    <general name="filtered" tendon="cord" gear="1.5" dyntype="filter" dynprm="0.05"
             gainprm="3 -1 0.5" biasprm="1 -2 -0.3"/>
    <position name="ratio" tendon="inner" kp="20" dampratio="0.7"/>
  </actuator></mujoco>""")


def actuated_states_as_in_mujoco(loaded, rng, cases, cone):
    """(q, v, ctrl, act, τ) at `cases` random states and controls of a model with actuators, τ its
    m.actuator_forces, each checked against qfrc_actuator and its solution against mj_forward."""
    model, mj_model, layout = loaded
    d = mujoco.MjData(mj_model)
    for case in range(cases):
        qpos = mj_model.qpos0.copy()
        mujoco.mj_integratePos(mj_model, qpos, rng.normal(size=mj_model.nv) * 0.4, 1.0)
        qvel, ctrl, act = rng.normal(size=mj_model.nv), rng.uniform(-2, 2, size=mj_model.nu), rng.normal(size=mj_model.na)
        d.qpos[:], d.qvel[:], d.ctrl[:], d.act[:] = qpos, qvel, ctrl, act
        mujoco.mj_forward(mj_model, d)
        q = layout.q_from_mujoco(qpos)
        v = layout.v_from_mujoco(q, qvel)
        tau = model.actuator_forces(q, v, ctrl, act)
        assert_close(tau, layout.force_from_mujoco(q, d.qfrc_actuator), ROW_AGREEMENT, f"{cone} case {case}")
        assert_matches_mujoco(model, mj_model, layout, qpos, qvel, ctrl=ctrl, label=f"{cone} case {case}")
        yield q, v, ctrl, act, tau


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_actuators_on_spatial_tendons_as_in_mujoco(cone):
    """Their forces gear Jᵀ f, with l = gear L and l̇ = gear J v moving with the state (the arms on
    the free box in its own axes), against qfrc_actuator; the solution with them, against
    mj_forward."""
    model, _, _ = loaded = load_both(SPATIAL_ACTUATORS.replace("{cone}", cone))
    assert not [w for w in model.warnings if "not modelled" in w], model.warnings
    states = list(actuated_states_as_in_mujoco(loaded, np.random.default_rng(11), 8, cone))
    # a batch is each state's
    batch = model.actuator_forces(*(np.array([s[k] for s in states]) for k in range(4)))
    assert_close(batch, np.array([s[4] for s in states]), 0.0, "batch")


# The actuators above with their tendons' forces bounded together: the cord's two (the motor, whose
# own forcerange then clamps it, and the filtered one) and the inner tendon's two (the velocity
# servo and the damping-ratio servo) scaled into each tendon's actuatorfrcrange.
TENDON_FORCE_RANGES = (SPATIAL_ACTUATORS.replace('<spatial name="cord"', '<spatial name="cord" actuatorfrcrange="-1.5 2"')
                       .replace('<spatial name="inner"', '<spatial name="inner" actuatorfrcrange="-3 0.8"')
                       .replace('ctrlrange="-1 1"/>', 'ctrlrange="-1 1" forcerange="-0.6 0.6"/>'))


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_tendon_actuator_force_ranges_as_in_mujoco(cone):
    """Where the sum F of a tendon's actuator forces leaves its actuatorfrcrange [f₋, f₊], each
    force f becomes f f₊/F (f f₋/F), before its own forcerange (MuJoCo's order): qfrc_actuator
    and mj_forward at random states, the bounds reached in most of them."""
    model, _, _ = loaded = load_both(TENDON_FORCE_RANGES.replace("{cone}", cone))
    unbounded, _, _ = load_both(SPATIAL_ACTUATORS.replace("{cone}", cone))
    assert not [w for w in model.warnings if "not modelled" in w], model.warnings
    bounded = sum(not np.allclose(tau, unbounded.actuator_forces(q, v, ctrl, act))
                  for q, v, ctrl, act, tau in actuated_states_as_in_mujoco(loaded, np.random.default_rng(12), 10, cone))
    assert bounded >= 5, bounded


def test_tendon_actuator_force_ranges_mujoco_refuses_are_refused():
    for attributes, message in [
        ('actuatorfrcrange="0.5 1"', r"'actuatorfrcrange': expected low ≤ 0 ≤ high, got '0.5 1'"),
        ('actuatorfrcrange="-1 -0.5"', r"expected low ≤ 0 ≤ high"),
        ('actuatorfrclimited="true"', r"'actuatorfrcrange': a limited tendon needs low < high"),
        ('actuatorfrclimited="true" actuatorfrcrange="1 -1"', r"a limited tendon needs low < high"),
        ('actuatorfrclimited="yes" actuatorfrcrange="-1 1"', r"'actuatorfrclimited': expected true, false or auto, got 'yes'"),
    ]:
        text = TENDON_FORCE_RANGES.replace("{cone}", "pyramidal").replace('<spatial name="tackle"', f'<spatial name="tackle" {attributes}')
        with pytest.raises(ValueError, match=r"line \d+.*" + message):
            load_quietly(None, text)
        with pytest.raises(ValueError):
            mujoco.MjModel.from_xml_string(text)
    # MuJoCo's auto: a range without low < high is no limit
    text = TENDON_FORCE_RANGES.replace("{cone}", "pyramidal").replace('<spatial name="tackle"', '<spatial name="tackle" actuatorfrcrange="1 -1"')
    assert not mujoco.MjModel.from_xml_string(text).tendon_actfrclimited[1]
    load_quietly(None, text)


# The actuators above with inertias on their tendons (MuJoCo's tendon armature): the cord's own
# (from the world through the arm to the free box: two trees, so MuJoCo's M keeps only each
# branch's terms), the tackle's from its position actuator (g² armature), a fixed tendon across the
# arm, and one across both slides of a body MuJoCo would call simple (which then no longer is).
TENDON_INERTIAS = (SPATIAL_ACTUATORS.replace('<spatial name="cord"', '<spatial name="cord" armature="0.2"')
                   .replace('<position name="winch" tendon="tackle"', '<position name="winch" tendon="tackle" armature="0.3" gear="1.5"')
                   .replace("</tendon>", """<fixed name="bend" armature="0.5"><joint joint="shoulder" coef="1"/><joint joint="elbow" coef="-0.5"/></fixed>
    <fixed name="glide" armature="0.8"><joint joint="sx" coef="1"/><joint joint="sy" coef="-2"/></fixed></tendon>""")
                   .replace("</worldbody>", """<body name="slider" pos="1 1 1"><joint name="sx" type="slide" axis="1 0 0" damping="0.5" frictionloss="0.3"/>
      <joint name="sy" type="slide" axis="0 1 0"/><geom size=".05" mass="2"/></body></worldbody>"""))


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_tendon_inertias_as_in_mujoco(cone):
    """M + a JᵀJ (on M's tree pattern, as MuJoCo's) and the bias a J (J̇ ν) in q̈₀, the weights and a
    damping ratio at qpos0 with them, the simple body demoted: mj_forward at random states."""
    model, _, _ = loaded = load_both(TENDON_INERTIAS.replace("{cone}", cone))
    assert not [w for w in model.warnings if "not modelled" in w], model.warnings
    apart = [w for w in model.warnings if "armature couples" in w]
    assert len(apart) == 2 and "tendon 'cord'" in apart[0] and "tendon 'tackle'" in apart[1], apart
    plain, _, _ = load_both(SPATIAL_ACTUATORS.replace("{cone}", cone))
    for q, v, ctrl, act, tau in actuated_states_as_in_mujoco(loaded, np.random.default_rng(13), 8, cone):
        # the inertias move the accelerations
        with_inertia = model.contact_forward_dynamics(q, v, ctrl=ctrl, act=act)["qdd"][:plain.nv]
        without = plain.contact_forward_dynamics(q[:plain.nq], v[:plain.nv], ctrl=ctrl, act=act)["qdd"]
        assert np.max(np.abs(with_inertia - without)) > 1e-3


def test_tendon_inertias_mujoco_refuses_are_refused():
    """A negative armature, and a tendon's or its actuator's on a path around a geom (MuJoCo's J̇
    does not follow a wrap: its compiler fails there)."""
    wraps = WRAPS.replace("{cone}", "pyramidal")
    for text, message in [
        (TENDON_INERTIAS.replace('armature="0.2"', 'armature="-0.2"'), r"attribute 'armature': expected a value ≥ 0, got -0.2"),
        (wraps.replace('<spatial name="over"', '<spatial name="over" armature="0.1"'),
         r"attribute 'armature': a tendon that wraps around a geom has none"),
        (wraps.replace('<position tendon="over"', '<position tendon="over" armature="0.1"'),
         r"attribute 'armature': tendon 'over' wraps around a geom, and has none"),
    ]:
        with pytest.raises(ValueError, match=message):
            load_quietly(None, text)
        with pytest.raises(ValueError):
            mujoco.MjModel.from_xml_string(text)


# Spatial tendons wrapping around spheres and cylinders: a cylinder in the world (a side site
# outside it) then a sphere on the arm (a side site above it); the same sphere without a side
# site, on to a free box; a sphere on the free box, then a pulley's branch around the arm's
# sphere; and (INSIDE, tested on its own) the sphere with a side site inside it, the path
# pressed against it from within. Each has dry friction, so that its row carries its J.
WRAPS = """<mujoco><option timestep="0.002" cone="{cone}"/>
  <default><geom contype="0" conaffinity="0"/><tendon frictionloss="0.1"/></default>
  <worldbody>
    <site name="anchor" pos="0 0 1.8"/>
    <geom name="pin" type="cylinder" size="0.06 0.1" pos="0.05 0 1.55" euler="90 0 0"/>
    <site name="pin_side" pos="0.2 0 1.55"/>
    <body name="upper" pos="0 0 1"><joint name="shoulder" axis="0 1 0" damping="0.05"/>
      <geom type="capsule" fromto="0 0 0 .4 0 0" size=".04"/>
      <geom name="knob" type="sphere" size="0.07" pos="0.4 0 0"/>
      <site name="knob_side" pos="0.4 0 0.2"/><site name="knob_in" pos="0.4 0 0.01"/>
      <site name="s1" pos="0.2 0 0.05"/>
      <body name="lower" pos=".4 0 0"><joint name="elbow" axis="0 1 0"/>
        <joint name="reach" type="slide" axis="1 0 0" range="-.1 .2"/>
        <geom type="capsule" fromto="0 0 0 .3 0 0" size=".03"/>
        <site name="tip" pos=".3 0 -0.02"/></body></body>
    <body name="float" pos="0.6 0.1 1.2" euler="0.3 0.2 0.1"><freejoint/><geom type="box" size=".05 .04 .03"/>
      <geom name="ball" type="sphere" size="0.04" pos="0 0.02 0"/><site name="eye" pos="0 0 -.06"/></body>
  </worldbody>
  <tendon>
    <spatial name="over" range="0.3 1.2" stiffness="20" damping="0.2"><site site="anchor"/>
      <geom geom="pin" sidesite="pin_side"/><site site="s1"/><geom geom="knob" sidesite="knob_side"/><site site="tip"/></spatial>
    <spatial name="plain" limited="true" range="0 0.9"><site site="s1"/><geom geom="knob"/><site site="tip"/><site site="eye"/></spatial>
    <spatial name="tackle"><site site="anchor"/><geom geom="ball"/><site site="eye"/><pulley divisor="2"/>
      <site site="eye"/><geom geom="knob"/><site site="tip"/></spatial>
  </tendon>
  <actuator><position tendon="over" kp="30" kv="1"/><motor tendon="tackle" gear="2"/></actuator>
</mujoco>"""
INSIDE = '<spatial name="inside"><site site="s1"/><geom geom="knob" sidesite="knob_in"/><site site="tip"/></spatial>'
# A path pressed against a sphere from within touches it at the root of an equation robodyn
# solves to round-off and MuJoCo to |f| <= 1e-6 (its Newton iteration's stop): measured over 400
# states of WRAPS with INSIDE, J of that tendon differs by up to 6.2e-8 (every other row's by
# 8e-15); the length, stationary there, by 2e-14.
INSIDE_WRAP_AGREEMENT = 1e-7


def mujoco_wraps(mj_model, d):
    """The geoms (names) each tendon's path wraps around in MuJoCo's d after mj_fwdPosition."""
    wraps = []
    for t in range(mj_model.ntendon):
        start, count = d.ten_wrapadr[t], d.ten_wrapnum[t]
        wraps.append({mj_model.geom(int(g)).name for g in d.wrap_obj.ravel()[start:start + count] if g >= 0})
    return wraps


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_tendons_wrapping_geoms_as_in_mujoco(cone):
    """Lengths against ten_length, and the friction rows (J), limits, springs, dampers and
    actuators against mj_forward, at random states where the paths wrap around each geom, the
    other way round and not at all."""
    model, mj_model, layout = load_both(WRAPS.replace("{cone}", cone))
    assert not [w for w in model.warnings if "not read" in w or "not modelled" in w], model.warnings
    rng, d = np.random.default_rng(12), mujoco.MjData(mj_model)
    seen = [set() for _ in range(mj_model.ntendon)]
    for case in range(16):
        qpos = mj_model.qpos0.copy()
        mujoco.mj_integratePos(mj_model, qpos, rng.normal(size=mj_model.nv) * 0.5, 1.0)
        qvel, ctrl = rng.normal(size=mj_model.nv), rng.uniform(-1, 1, size=mj_model.nu)
        d.qpos[:] = qpos
        mujoco.mj_fwdPosition(mj_model, d)
        for t, wrapped in enumerate(mujoco_wraps(mj_model, d)):
            seen[t].add(frozenset(wrapped))
        assert_close(model.tendon_lengths(layout.q_from_mujoco(qpos)), d.ten_length, ROW_AGREEMENT, f"case {case}")
        assert_matches_mujoco(model, mj_model, layout, qpos, qvel, ctrl=ctrl, label=f"{cone} case {case}")
    # each path wrapped and went straight
    assert seen[0] >= {frozenset({"pin", "knob"})}, seen[0]
    for t in range(1, 3):
        assert len(seen[t]) >= 2, (t, seen[t])


def test_a_side_site_inside_the_geom_presses_the_path_against_it():
    """The path from within: its length as ten_length (round-off), its friction row's J to
    INSIDE_WRAP_AGREEMENT, at states where it touches and where it passes straight through."""
    model, mj_model, layout = load_both(WRAPS.replace("{cone}", "pyramidal").replace("</tendon>", INSIDE + "</tendon>"))
    rng, d, touched = np.random.default_rng(12), mujoco.MjData(mj_model), set()
    for case in range(24):
        qpos = mj_model.qpos0.copy()
        mujoco.mj_integratePos(mj_model, qpos, rng.normal(size=mj_model.nv) * 0.5, 1.0)
        d.qpos[:] = qpos
        mujoco.mj_fwdPosition(mj_model, d)
        touched.add(bool(mujoco_wraps(mj_model, d)[3]))
        assert_close(model.tendon_lengths(layout.q_from_mujoco(qpos)), d.ten_length, ROW_AGREEMENT, f"case {case}")
        q, v, expected = mujoco_solution(mj_model, layout, qpos, np.zeros(mj_model.nv))
        ours = model.contact_forward_dynamics(q, v)
        assert list(ours["row_types"]) == expected["row_types"] and list(ours["row_ids"]) == list(expected["row_ids"])
        rows = [i for i, (kind, t) in enumerate(zip(ours["row_types"], ours["row_ids"])) if kind == "friction_tendon" and t == 3]
        others = [i for i in range(len(ours["row_types"])) if i not in rows]
        jacobian = np.asarray(ours["jacobian"])
        assert_entries_close(jacobian[rows], expected["jacobian"][rows], INSIDE_WRAP_AGREEMENT, f"case {case}")
        assert_entries_close(jacobian[others], expected["jacobian"][others], ROW_AGREEMENT, f"case {case}")
    assert touched == {True, False}


def test_wrapping_paths_mujoco_refuses_are_refused():
    for path, message in [
        ('<geom geom="pin"/><site site="anchor"/><site site="tip"/>', "a site on either side"),
        ('<site site="anchor"/><geom geom="pin"/><geom geom="knob"/><site site="tip"/>', "a site on either side"),
        ('<site site="anchor"/><geom geom="nowhere"/><site site="tip"/>', "no geom named 'nowhere'"),
        ('<site site="anchor"/><geom geom="pin" sidesite="nowhere"/><site site="tip"/>', "no site named 'nowhere'"),
        ('<site site="anchor"/><geom geom="box"/><site site="tip"/>', "neither"),
    ]:
        text = WRAPS.replace("{cone}", "pyramidal").replace('<geom type="box"', '<geom name="box" type="box"')
        text = text.replace("</tendon>", f'<spatial name="bad">{path}</spatial></tendon>')
        with pytest.raises(ValueError, match=message):
            load_quietly(None, text)
        with pytest.raises(ValueError):
            mujoco.MjModel.from_xml_string(text)
    text = WRAPS.replace("{cone}", "pyramidal").replace('<spatial name="plain"', '<spatial name="plain" armature="0.1"')
    with pytest.raises(ValueError, match="'armature'"):
        load_quietly(None, text)
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_string(text)


# --- 8. MuJoCo's simple bodies -------------------------------------------------------------------

# Bodies MuJoCo calls simple (body_simple 2: only axis-aligned slides at their origin, their inertia
# frame their own, no child, under the world or a jointless child of it) weigh 1/m in R, for their
# contacts and their slides' limits (with armature: not M⁻¹'s diagonal); and four that are not (a
# box turned in its body, a slide off the origin, a parent, the fixed stand).
SIMPLE_BODIES = """<mujoco><option cone="{cone}"/>
  <worldbody>
    <geom name="floor" type="plane" size="0 0 1"/>
    <body name="puck" pos="0 0 0.049"><joint name="px" type="slide" axis="1 0 0" armature="0.3" range="-0.1 0.1" margin="0.2"/>
      <joint name="py" type="slide" axis="0 1 0"/><geom name="puck" type="cylinder" size="0.1 0.05"/></body>
    <body name="stand" pos="1 0 0"><geom type="box" size=".05 .05 .05" pos="0 0 .5"/>
      <body name="slider" pos="0 0 0.039"><joint name="sz" type="slide" axis="0 0 1" range="-0.05 0.1" margin="0.2" armature="0.1"/>
        <geom name="slider" type="box" size="0.04 0.04 0.04"/></body></body>
    <body name="tilted" pos="2 0 0.039"><joint name="tx" type="slide" axis="1 0 0"/><joint name="ty" type="slide" axis="0 1 0"/>
      <geom name="tilted" type="box" size="0.04 0.05 0.04" euler="0 0 30"/></body>
    <body name="offset" pos="3 0 0.039"><joint name="ox" type="slide" axis="1 0 0" pos="0.1 0 0"/>
      <geom name="offset" type="sphere" size="0.04"/></body>
    <body name="parent" pos="4 0 0.039"><joint name="qx" type="slide" axis="1 0 0"/><geom name="parent" type="sphere" size="0.04"/>
      <body name="child" pos="0 0.2 0"><geom name="child" type="sphere" size="0.04"/></body></body>
    <body name="turned" pos="5 0 0.5"><joint name="u" type="slide" axis="1 0 0" range="-0.1 0.1" margin="0.2" armature="0.1"/>
      <geom type="box" size="0.04 0.05 0.04" euler="0 0 90"/></body>
    <body name="rod" pos="6 0 0.5"><joint name="r" type="slide" axis="1 0 0" range="-0.1 0.1" margin="0.2" armature="0.1"/>
      <geom type="capsule" fromto="-0.05 0 0 0.05 0 0" size="0.02"/></body>
    <body name="decreasing" pos="7 0 0.5"><joint name="d" type="slide" axis="1 0 0" range="-0.1 0.1" margin="0.2" armature="0.1"/>
      <geom type="box" size="0.02 0.04 0.06"/><geom type="box" size="0.02 0.04 0.03"/></body>
    <body name="increasing" pos="8 0 0.5"><joint name="i" type="slide" axis="1 0 0" range="-0.1 0.1" margin="0.2" armature="0.1"/>
      <geom type="box" size="0.06 0.04 0.02"/><geom type="box" size="0.03 0.04 0.02"/></body>
    <body name="given" pos="9 0 0.5"><joint name="g" type="slide" axis="1 0 0" range="-0.1 0.1" margin="0.2" armature="0.1"/>
      <inertial pos="0 0 0" mass="1" diaginertia="0.2 0.2 0.3" quat="0.7071068 0 0 0.7071068"/></body>
    <body name="full" pos="10 0 0.5"><joint name="f" type="slide" axis="1 0 0" range="-0.1 0.1" margin="0.2" armature="0.1"/>
      <inertial pos="0 0 0" mass="1" fullinertia="0.3 0.2 0.15 0 0 0"/></body>
    <body name="nudged" pos="11 0 0.5"><joint name="n" type="slide" axis="1 0 0" range="-0.1 0.1" margin="0.2" armature="0.1"/>
      <geom type="box" size="0.04 0.05 0.03" pos="5e-7 0 0" quat="1 5e-7 0 0"/></body>
    <body name="opted" pos="12 0 0.5" simple="false"><joint name="o" type="slide" axis="1 0 0" range="-0.1 0.1" margin="0.2" armature="0.1"/>
      <geom type="sphere" size="0.04"/></body>
  </worldbody></mujoco>"""


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_simple_bodies_weigh_one_over_their_mass_as_in_mujoco(cone):
    """MuJoCo's simple bodies need their principal axes of inertia to be their own, where its
    compiler puts them: a single geom's axes (a box turned a quarter, a capsule along x: not simple
    though diagonal), or by eigen-decomposition with the moments in decreasing order (two geoms,
    `fullinertia`), or an `<inertial>`'s `quat`; each to MuJoCo's 1e-6 (a geom 5e-7 off and turned by
    1e-6 rad still is); `simple="false"` turns it off."""
    model, mj_model, layout = load_both(SIMPLE_BODIES.replace("{cone}", cone))
    simple = {mj_model.body(i).name for i in range(1, mj_model.nbody) if mj_model.body_simple[i] == 2}
    assert simple == {"puck", "slider", "decreasing", "full", "nudged"}
    rng = np.random.default_rng(2)
    for case in range(3):
        qpos = mj_model.qpos0 + rng.normal(size=mj_model.nq) * 0.05
        _, expected = assert_matches_mujoco(model, mj_model, layout, qpos, rng.normal(size=mj_model.nv), label=f"case {case}")
        # each new slide has a limit row at least (its weight 1/m when simple, else 1/(m + armature))
        assert expected["row_types"].count("limit_joint") >= 4 + 8


# --- 8b. URDF mimic joints --------------------------------------------------------------------


def test_urdf_mimic_joints_are_soft_joint_equalities(tmp_path):
    """A URDF's mimic relations (held by m.constraints) are MuJoCo joint equalities in the soft model,
    with MuJoCo's default solref and solimp: one equality row each, J = e_follower − multiplier
    e_leader, its position the relation's violation; no file bodies are needed."""
    from test_mimic import GRIPPER

    path = tmp_path / "gripper.urdf"
    path.write_text(GRIPPER)
    model = load_quietly(path)
    couplings = list(model.constraints)
    assert len(couplings) >= 2
    rng = np.random.default_rng(9)
    q, v = rng.normal(size=model.nq), rng.normal(size=model.nv)
    result = model.contact_forward_dynamics(q, v)
    equality = [k for k, kind in enumerate(result["row_types"]) if kind == "equality"]
    assert len(equality) == len(couplings)
    jacobian = np.asarray(result["jacobian"])[equality]
    names = model.joint_names
    thumb, wrist = (model.joint_idx_v[names.index(n)] for n in ("thumb", "wrist"))
    row = jacobian[0]
    assert row[thumb] == 1.0 and row[wrist] == -0.5 and np.count_nonzero(row) == 2
    # the relation's violation is the row's position: its force pulls it back (f = −(J q̈ − a_ref)/R)
    assert np.all(np.isfinite(result["forces"])) and np.all(np.asarray(result["R"])[equality] > 0)
