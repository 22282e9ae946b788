"""Joint springs and dampers with MuJoCo's polynomial terms (`stiffness="k k₁ k₂"`,
`damping="b b₁ b₂"`) and `springdamper` (a time constant and damping ratio turned into k and b),
against MuJoCo 4.0: the compiled values, q̈ at random states (`mj_forward`) and 100 `mj_step`
steps for each integrator; robodyn's own integrators' step derivatives with the polynomial terms.

MuJoCo's spring force is −(k + k₁ s + k₂ s²) d with s the signed displacement on a hinge or slide
and the rotation angle or the distance on a ball or a free joint's halves; its damper is per
degree of freedom −(b + b₁ |ν| + b₂ ν²) ν, on a free joint along the world's axes."""

import mujoco
import numpy as np
import pytest
import robodyn
from conftest import assert_close, assert_refused_as_in_mujoco, load_quietly
from test_contact_dynamics import assert_matches_mujoco, load_both
from test_derivatives import STEP_FD_TOLERANCE, step_differences
from test_scene_stepping import INTEGRATORS, assert_steps_from_a_turned_state

# A free body with springs and dampers on both halves, under it a hinge (springref, an actuator's
# polynomial damping through a gear), a slide and a ball; a second free body on the floor.
SPRINGS = """<mujoco><option timestep="0.002" cone="{cone}"/>
  <worldbody>
    <geom name="floor" type="plane" size="3 3 .1"/>
    <body name="base" pos="0 0 1">
      <joint name="root" type="free" stiffness="3 1.5 4" damping="0.4 0.3 0.2" armature="0.01"/>
      <geom name="base" type="box" size=".2 .1 .05" mass="4"/>
      <body name="upper" pos=".2 0 0">
        <joint name="shoulder" axis="0 1 0" stiffness="2 -1 3" springref="15" damping="0.1 0.5 0.3"/>
        <geom name="upper" type="capsule" fromto="0 0 0 .3 0 0" size=".03"/>
        <body name="lower" pos=".3 0 0">
          <joint name="reach" type="slide" axis="1 0 0" stiffness="20 0 50" damping="0.2 0 1"/>
          <geom name="lower" type="capsule" fromto="0 0 0 .2 0 0" size=".025"/>
          <body name="hand" pos=".2 0 0">
            <joint name="wrist" type="ball" stiffness="1 0.5 2" damping="0.0005 0.001 0.0002"/>
            <geom name="hand" type="box" size=".04 .03 .02"/></body></body></body></body>
    <body name="puck" pos="1 0 .2">
      <joint type="free" damping="0.1 0.6 0.4"/><geom name="puck" type="cylinder" size=".1 .03"/></body>
  </worldbody>
  <actuator><motor joint="shoulder" gear="1.5" damping="0.2 0.3 0.1"/></actuator>
</mujoco>"""

# The same without the terms past the linear ones.
LINEAR = (SPRINGS.replace('stiffness="3 1.5 4" damping="0.4 0.3 0.2"', 'stiffness="3" damping="0.4"')
          .replace('stiffness="2 -1 3"', 'stiffness="2"').replace('damping="0.1 0.5 0.3"', 'damping="0.1"')
          .replace('stiffness="20 0 50" damping="0.2 0 1"', 'stiffness="20" damping="0.2"')
          .replace('stiffness="1 0.5 2" damping="0.0005 0.001 0.0002"', 'stiffness="1" damping="0.0005"')
          .replace('damping="0.1 0.6 0.4"', 'damping="0.1"').replace('damping="0.2 0.3 0.1"', 'damping="0.2"'))


def test_polynomial_terms_are_read_as_mujoco_compiles_them():
    model = load_quietly(None, SPRINGS.replace("{cone}", "pyramidal"))
    mj_model = mujoco.MjModel.from_xml_string(SPRINGS.replace("{cone}", "pyramidal"))
    assert not [w for w in model.warnings if "polynomial" in w], model.warnings
    # MuJoCo's per joint stiffness on each of the joint's coordinates; its dampers per dof, the
    # actuator's terms joining its joint's times gear² (MuJoCo adds them when it runs)
    stiffness_poly = np.repeat(mj_model.jnt_stiffnesspoly, [6, 1, 1, 3, 6], axis=0)
    damping_poly = mj_model.dof_dampingpoly.copy()
    damping_poly[6] += 1.5**2 * mj_model.actuator_dampingpoly[0]
    assert_close(model.stiffness_poly, stiffness_poly, 0.0, "stiffness_poly")
    assert_close(model.damping_poly, damping_poly, 1e-15, "damping_poly")
    assert model.stiffness_poly.shape == (model.nv, 2)


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_polynomial_springs_and_dampers_as_in_mujoco(cone):
    """q̈ (through the passive forces, the rows' a_ref and the solution) at random states, against
    mj_forward; the terms move the accelerations."""
    model, mj_model, layout = load_both(SPRINGS.replace("{cone}", cone))
    linear = load_quietly(None, LINEAR.replace("{cone}", cone))
    rng = np.random.default_rng(11)
    for case in range(10):
        qpos = mj_model.qpos0.copy()
        # turned and moved both ways, and the free bodies lifted off the floor
        mujoco.mj_integratePos(mj_model, qpos, rng.normal(size=mj_model.nv) * 0.5, 1.0)
        qpos[2] += 0.5
        qvel = rng.normal(size=mj_model.nv) * 1.5
        ours, _ = assert_matches_mujoco(model, mj_model, layout, qpos, qvel, ctrl=[0.3], label=f"{cone} case {case}")
        q = layout.q_from_mujoco(qpos)
        without = linear.contact_forward_dynamics(q, layout.v_from_mujoco(q, qvel), ctrl=[0.3])["qdd"]
        assert np.max(np.abs(ours["qdd"] - without)) > 1e-2


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_polynomial_springs_and_dampers_step_as_in_mujoco(integrator):
    """100 steps: Euler's implicit damping and implicitfast's K take each damper's slope
    −(b + 2 b₁ |ν| + 3 b₂ ν²) at the step's ν (MuJoCo 4.0's), a free joint's along the world."""
    assert_steps_from_a_turned_state(SPRINGS, integrator, 4, ctrl=[0.3])


def test_polynomial_terms_mujoco_refuses_are_refused():
    text = SPRINGS.replace("{cone}", "pyramidal").replace('stiffness="2 -1 3"', 'stiffness="2 -1 3 1"')
    assert_refused_as_in_mujoco(text, r"<joint name='shoulder'>.*attribute 'stiffness': expected at most 3 numbers")


def test_polynomial_terms_are_settable_and_checked():
    model = load_quietly(None, SPRINGS.replace("{cone}", "pyramidal"))
    terms = np.asarray(model.stiffness_poly).copy()
    terms[6] = [0.5, 0.25]
    model.stiffness_poly = terms
    assert_close(model.stiffness_poly[6], [0.5, 0.25], 0.0, "set")
    # a ball's three coordinates stretch together: one pair
    uneven = terms.copy()
    uneven[9] = [7.0, 0.0]
    with pytest.raises(ValueError, match=r"stiffness_poly.*joint 'wrist': expected the same \(k₁, k₂\) on coordinates 8..11"):
        model.stiffness_poly = uneven
    with pytest.raises(ValueError, match=r"damping_poly.*expected finite values"):
        model.damping_poly = np.full((model.nv, 2), np.nan)
    with pytest.raises(ValueError, match="damping_poly"):
        model.damping_poly = np.zeros((model.nv, 3))
    restored = __import__("pickle").loads(__import__("pickle").dumps(model))
    assert_close(restored.stiffness_poly, model.stiffness_poly, 0.0, "pickled")


def test_own_integrators_feel_the_terms_and_their_derivatives():
    """robodyn's own integrators: a step's Jacobians with polynomial springs and dampers are its
    finite differences; without dampers, on the arm fixed to the world (hinge, slide and ball,
    whose springs are conservative: a ball's log map keeps its own direction), the springs'
    energy Σ (k d²/2 + k₁ s³/3 + k₂ s⁴/4) keeps the total."""
    model = robodyn.load_mjcf_string(SPRINGS.replace("{cone}", "pyramidal"))
    rng = np.random.default_rng(12)
    q = model.random_configuration(seed=5)
    v, tau = rng.uniform(-1, 1, model.nv), rng.uniform(-1, 1, model.nv)
    for integrator in ["euler", "rk4"]:
        _, a, b = robodyn.step(model, q, v, tau, 1e-3, integrator, derivatives=True)
        fd = step_differences(model, q, v, tau, 1e-3, integrator)
        assert_close(a, fd[:, : 2 * model.nv], STEP_FD_TOLERANCE, f"{integrator} A")
        assert_close(b, fd[:, 2 * model.nv:], STEP_FD_TOLERANCE, f"{integrator} B")
    fixed = SPRINGS.replace('<joint name="root" type="free" stiffness="3 1.5 4" damping="0.4 0.3 0.2" armature="0.01"/>', "")
    arm = robodyn.load_mjcf_string(fixed.replace("{cone}", "pyramidal"))
    arm.damping, arm.damping_poly, arm.gravity = np.zeros(arm.nv), np.zeros((arm.nv, 2)), [0.0, 0.0, 0.0]
    q = arm.neutral()
    q[:6] = [0.4, 0.05, 0.6 * np.sin(0.3), 0.8 * np.sin(0.3), 0.0, np.cos(0.3)]
    run = robodyn.simulate(arm, q, np.zeros(arm.nv), t_end=0.2, dt=1e-4, integrator="rk4")
    assert np.ptp(run.energy) < ENERGY_DRIFT * np.ptp(run.spring_energy)
    assert np.ptp(run.spring_energy) > 0.5 * np.max(run.spring_energy)


def test_the_spring_energy_is_the_potential_of_the_springs():
    """m.spring_energy(q): Σ (k d²/2 + k₁ s³/3 + k₂ s⁴/4) written out joint by joint here (s the
    signed displacement of the hinge and the slide, the length of the ball's and of either half of
    the free joint's), one state and a batch."""
    model = load_quietly(None, SPRINGS.replace("{cone}", "pyramidal"))
    q = model.random_configuration(8, seed=3)
    displacement = np.asarray(model.difference(np.broadcast_to(model.spring_reference, q.shape), q))
    expected = 0.5 * np.sum(model.stiffness * displacement**2, axis=1)
    blocks = {"revolute": [(0, 1)], "prismatic": [(0, 1)], "spherical": [(0, 3)], "free": [(0, 3), (3, 3)]}
    for kind, first in zip(model.joint_types, model.joint_idx_v):
        for offset, size in blocks[kind]:
            block = displacement[:, first + offset : first + offset + size]
            s = block[:, 0] if size == 1 else np.linalg.norm(block, axis=1)
            k1, k2 = model.stiffness_poly[first + offset]
            expected += k1 * s**3 / 3 + k2 * s**4 / 4
    assert_close(model.spring_energy(q), expected, 1e-13, "a batch")
    assert_close(model.spring_energy(q[3]), expected[3], 1e-13, "one state")
    assert model.spring_energy(model.spring_reference) == 0.0


#: RK4's energy drift over 0.2 s at 1e-4 s, relative to the energy that moves between the springs
#: and the bodies (measured 6e-10; leaving the polynomial terms out of the energy: 0.35).
ENERGY_DRIFT = 1e-7


# springdamper on each kind of joint (a class's, an actuator's damping and armature added to a
# hinge's), against the stiffness and damping MuJoCo's compiler sets.
SPRING_DAMPERS = """<mujoco>
  <default><default class="soft"><joint springdamper="0.2 0.7"/></default></default>
  <worldbody>
    <body name="base" pos="0 0 1">
      <joint name="root" type="free" springdamper="0.5 1"/>
      <geom type="box" size=".2 .1 .05" mass="4"/>
      <body name="upper" pos=".2 0 0">
        <joint name="shoulder" class="soft" axis="0 1 0" damping="3" stiffness="5 1 1" armature="0.02"/>
        <geom type="capsule" fromto="0 0 0 .3 0 0" size=".03"/>
        <body name="lower" pos=".3 0 0">
          <joint name="reach" type="slide" axis="1 0 0" springdamper="0.05 0.3"/>
          <geom type="capsule" fromto="0 0 0 .2 0 0" size=".025"/>
          <body name="hand" pos=".2 0 0">
            <joint name="wrist" type="ball" springdamper="0.1 2"/>
            <geom type="box" size=".04 .03 .02"/></body></body></body></body>
  </worldbody>
  <actuator><motor joint="shoulder" gear="2" damping="0.5" armature="0.1"/></actuator>
</mujoco>"""


def test_spring_dampers_set_stiffness_and_damping_as_mujoco():
    model = load_quietly(None, SPRING_DAMPERS)
    mj_model = mujoco.MjModel.from_xml_string(SPRING_DAMPERS)
    stiffness = np.repeat(mj_model.jnt_stiffness, [6, 1, 1, 3])
    # MuJoCo keeps the actuator's damping apart (it adds gear² b when it runs)
    damping = mj_model.dof_damping.copy()
    damping[6] += 2.0**2 * 0.5
    assert_close(model.stiffness, stiffness, 1e-12 * np.max(stiffness), "stiffness")
    assert_close(model.damping, damping, 1e-12 * np.max(damping), "damping")
    # the higher terms stay
    assert_close(model.stiffness_poly[6], [1.0, 1.0], 0.0, "higher terms")


def test_spring_dampers_mujoco_refuses_are_refused():
    for value in ["0.1 0", "-0.1 1", "0 1"]:
        text = SPRING_DAMPERS.replace('springdamper="0.05 0.3"', f'springdamper="{value}"')
        assert_refused_as_in_mujoco(text, rf"<joint name='reach'>.*attribute 'springdamper': expected a positive "
                                          rf"time constant and damping ratio, got {value}")


@pytest.mark.parametrize("damping", ["-0.5", "0 0.3", "-0.5 0.3", "0 -0.3"])
def test_euler_takes_the_dampers_implicit_as_mujoco_decides(damping):
    """MuJoCo 4.0's Euler takes the joint dampers implicitly when one has a positive linear term or
    any higher term (measured): a negative linear damping alone stays explicit."""
    text = ('<mujoco><option gravity="0 0 -9.81"/><worldbody><body><joint name="swing" axis="0 1 0" '
            f'damping="{damping}"/><geom name="bob" size=".1" pos="0 0 -1"/></body></worldbody></mujoco>')
    assert_steps_from_a_turned_state(text, "Euler", 8)


def test_euler_solves_dampers_that_leave_its_matrix_indefinite():
    """A damper whose slope outweighs the inertia (b₁ < 0 at speed) leaves M − h ∂f/∂ν
    indefinite: Cholesky fails there (MuJoCo 4.0's factorisation too: it warns and its step
    diverges, measured 4e15 rad/s) and robodyn solves the implicit step by LU; v₁ by hand."""
    b, b1, h, v = 1.0, -50.0, 0.01, 3.0
    text = (f'<mujoco><option timestep="{h}" gravity="0 0 0"/><worldbody><body><joint name="j" axis="0 1 0" '
            f'damping="{b} {b1}"/><geom name="bob" size="0.01" pos="0.1 0 0" mass="0.01" contype="0" '
            'conaffinity="0"/></body></worldbody></mujoco>')
    model = load_quietly(None, text)
    inertia = model.mass_matrix(np.zeros(1))[0, 0]
    force, slope = -(b + b1 * v) * v, -(b + 2 * b1 * v)
    assert inertia - h * slope < 0, "the case must leave the matrix indefinite"
    # (M − h K) u = M a with M a the damper's force, v₁ = v + h u
    expected = v + h * force / (inertia - h * slope)
    stepped = robodyn.step(model, np.zeros(1), np.array([v]), np.zeros(1), h, integrator="mujoco")
    assert_close(stepped[model.nq:], [expected], 1e-12, "v₁")
