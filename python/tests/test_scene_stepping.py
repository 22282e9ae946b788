"""Scenes stepped as MuJoCo's `mj_step` steps them (`robodyn.simulate` and `robodyn.step` with
`integrator="mujoco"`): the first 100 steps against `mj_step`'s, state by state, for the three
integrators robodyn follows (Euler with implicit joint damping, implicitfast, RK4), both cones, on a
box on a plane, a spinning free body, an arm with limits, dry friction and actuators, Menagerie's Go2
at home and dm_control's suite; then how a run is started and driven, and what is refused.

MuJoCo solves to convergence here (`converged`: Newton, tolerance 1e-15)."""

import mujoco
import numpy as np
import pytest
import robodyn
from conftest import REPOSITORY, load_quietly
from robodyn.convert import MujocoLayout
from test_contact_dynamics import (
    ARM,
    FLAGGED,
    SUITE,
    box_scene,
    converged,
    load_both,
    random_suite_state,
    without_unmodelled,
)
from test_menagerie import MENAGERIE, mujoco_model
from test_soft_elements import EQUALITIES, SPATIAL, SPATIAL_ACTUATORS, TENDON_FORCE_RANGES, TENDON_INERTIAS, TENDON_POLYNOMIALS, TENDONS, WRAPS

STEPS = 100
# 100 steps without elliptic friction: the same arithmetic in another order; measured up to 1.1e-12
# (walker, moving freely), 1e-14 elsewhere.
STEP_AGREEMENT = 1e-10
# With elliptic cones MuJoCo's Newton stops a step before the optimum (test_contact_dynamics's
# FORCE_AGREEMENT: forces up to 1.7e-7 off); over 100 steps the states differ by up to 6e-9 (Go2 at
# home, box). The bound, 1e-6, holds them.
ELLIPTIC_STEP_AGREEMENT = 1e-6
# One state solved twice, from the last step's solution (a run's warm start) and from q̈₀: both end
# where Newton's steps fall below 1e-10 of the accelerations; measured 4e-13 of the largest force
# apart on a Go2 falling onto its floor.
WARM_START_AGREEMENT = 1e-10

INTEGRATORS = ["Euler", "implicitfast", "RK4"]


def with_integrator(text, integrator):
    """An MJCF string with `<option integrator>` set (its first <option>, or a new one)."""
    if "<option" in text:
        return text.replace("<option", f'<option integrator="{integrator}"', 1)
    return text.replace("<mujoco>", f'<mujoco><option integrator="{integrator}"/>', 1)


def mujoco_steps(mj_model, layout, qpos, qvel, ctrl=None, tau=None, steps=STEPS):
    """MuJoCo's states after each of `steps` steps from (qpos, qvel), in robodyn's coordinates."""
    d = mujoco.MjData(mj_model)
    d.qpos[:], d.qvel[:] = qpos, qvel
    if ctrl is not None:
        d.ctrl[:] = ctrl
    states = []
    for _ in range(steps):
        if tau is not None:
            q = layout.q_from_mujoco(d.qpos)
            d.qfrc_applied[:] = layout.force_to_mujoco(q, tau)
        mujoco.mj_step(mj_model, d)
        states.append((d.qpos.copy(), d.qvel.copy()))
    return states


def assert_steps_like_mujoco(model, mj_model, layout, qpos, qvel, ctrl=None, tau=None, tolerance=STEP_AGREEMENT,
                             label=""):
    """robodyn.simulate's first STEPS steps from MuJoCo's (qpos, qvel) are mj_step's: qpos entry by entry,
    qvel relative to max(1, |qvel|)."""
    q0 = layout.q_from_mujoco(qpos)
    v0 = layout.v_from_mujoco(q0, qvel)
    h = model.options.timestep
    run = robodyn.simulate(model, q0, v0, t_end=STEPS * h, integrator="mujoco", ctrl=ctrl,
                           controller=tau)
    assert len(run.t) == STEPS + 1 and np.allclose(run.t, h * np.arange(STEPS + 1), rtol=0, atol=1e-12)
    worst = 0.0
    for k, (qpos_k, qvel_k) in enumerate(mujoco_steps(mj_model, layout, qpos, qvel, ctrl, tau), start=1):
        q, v = run.q[k], run.v[k]
        ours_qpos, ours_qvel = layout.q_to_mujoco(q), layout.v_to_mujoco(q, v)
        error = max(np.max(np.abs(ours_qpos - qpos_k)), np.max(np.abs(ours_qvel - qvel_k)) / max(1.0, np.max(np.abs(qvel_k))))
        assert error <= tolerance, f"{label}: step {k} off by {error:.3e}"
        worst = max(worst, error)
    return run, worst


# --- 1. a box on a plane, a spinning body ------------------------------------------------------


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_a_box_sliding_on_a_plane_steps_as_in_mujoco(integrator, cone):
    model, mj_model, layout = load_both(text=with_integrator(box_scene(3, cone), integrator))
    assert model.options.integrator == integrator
    tolerance = ELLIPTIC_STEP_AGREEMENT if cone == "elliptic" else STEP_AGREEMENT
    qvel = np.array([0.3, 0.1, 0.0, 0.2, 0.5, 1.0])
    assert_steps_like_mujoco(model, mj_model, layout, mj_model.qpos0, qvel, tolerance=tolerance, label=integrator)


SPINNER = """<mujoco><option gravity="0 0 0" integrator="{}"/>
  <worldbody><body name="spinner"><freejoint name="spinner"/>
    <geom name="spinner" type="box" size=".1 .2 .3" pos=".05 0 0"/>
  </body></worldbody></mujoco>"""


@pytest.mark.parametrize("spin", [1, 10])
@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_a_spinning_free_body_steps_as_in_mujoco(integrator, spin):
    """A box spinning about no principal axis, its origin off its centre of mass: implicitfast adds
    the gyroscopic forces' derivative of a free body alone in its tree, RK4 integrates the rotation on
    its group (Runge–Kutta–Munthe-Kaas); with the naive forms the states differ by 1e-4 and 6e-8. At
    ten times the spin (|ω| h = 0.17) dexp⁻¹ cut after θ⁴ is 4e-13 off in one step: it is exact."""
    model, mj_model, layout = load_both(text=SPINNER.format(integrator))
    qvel = np.array([0.1, 0.2, 0.3, 5.0, 7.0, 3.0]) * spin
    assert_steps_like_mujoco(model, mj_model, layout, mj_model.qpos0, qvel, label=integrator)


# --- 2. limits, dry friction, actuators, applied forces ---------------------------------------


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_an_arm_with_limits_friction_and_actuators_steps_as_in_mujoco(integrator):
    """The limits (one with a margin), dry friction, a motor and a position actuator of
    test_contact_dynamics's arm, driven by controls and applied forces, moving into its limits; a
    damped elbow, and the motor's own damping and armature (MuJoCo adds gear² times them to its
    joint's)."""
    text = with_integrator(ARM, integrator).replace('<joint name="elbow"', '<joint name="elbow" damping="0.4"')
    text = text.replace('gear="2"/>', 'gear="2" damping="0.3" armature="0.05"/>')
    model, mj_model, layout = load_both(text=text)
    slide = model.joint_idx_v[model.joint_names.index("slide")]
    assert model.damping[slide] == pytest.approx(4 * 0.3) and model.armature[slide] == pytest.approx(4 * 0.05)
    model, mj_model, layout = load_both(text=text)
    qpos = np.array([0.15, 0.8, -1.2, 1.5])
    qvel = np.array([0.5, 2.0, -3.0, 1.0])
    assert_steps_like_mujoco(model, mj_model, layout, qpos, qvel, ctrl=[0.7, -0.4], tau=[0.0, 0.3, -0.2, 0.1],
                             label=integrator)


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_equality_constraints_step_as_in_mujoco(integrator):
    """test_soft_elements's equalities of every kind (welds, connects, joint couplings; the ball on
    the floor), set moving: their rows' J̇ q̇ and softness through 100 steps."""
    model, mj_model, layout = load_both(text=with_integrator(EQUALITIES.replace("{cone}", "pyramidal"), integrator))
    qvel = np.random.default_rng(7).normal(size=mj_model.nv)
    assert_steps_like_mujoco(model, mj_model, layout, mj_model.qpos0, qvel, label=integrator)


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_fixed_tendons_step_as_in_mujoco(integrator):
    """test_soft_elements's tendon arm under steady controls: tendon dampers explicit in Euler (only
    the joints' are implicit there), in implicitfast's K with the tendon actuators' velocity gains."""
    model, mj_model, layout = load_both(text=with_integrator(TENDONS.replace("{cone}", "pyramidal"), integrator))
    qvel = np.random.default_rng(7).normal(size=mj_model.nv)
    assert_steps_like_mujoco(model, mj_model, layout, mj_model.qpos0, qvel, ctrl=[0.7, 0.1, -0.4, 0.3], label=integrator)


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_tendon_polynomials_step_as_in_mujoco(integrator):
    """test_soft_elements's polynomial tendon springs and dampers: implicitfast's K takes each
    damper's slope −(b + 2 b₁ |L̇| + 3 b₂ L̇²) JᵀJ at the step's L̇, as MuJoCo's qDeriv."""
    assert_steps_from_a_turned_state(TENDON_POLYNOMIALS, integrator, 5, ctrl=[0.7, 0.1, -0.4, 0.3])


def assert_steps_from_a_turned_state(text, integrator, seed, ctrl=None):
    """100 steps of the MJCF string `text` (pyramidal cone, the given integrator) like MuJoCo's,
    from qpos0 turned and a velocity drawn with `seed`."""
    model, mj_model, layout = load_both(text=with_integrator(text.replace("{cone}", "pyramidal"), integrator))
    rng = np.random.default_rng(seed)
    qpos = mj_model.qpos0.copy()
    mujoco.mj_integratePos(mj_model, qpos, rng.normal(size=mj_model.nv) * 0.3, 1.0)
    assert_steps_like_mujoco(model, mj_model, layout, qpos, rng.normal(size=mj_model.nv), ctrl=ctrl, label=integrator)


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_spatial_tendons_step_as_in_mujoco(integrator):
    """test_soft_elements's spatial tendons from a turned state: their rows, springs and dampers
    (implicitfast: in K, through the free body's turned velocities) through 100 steps."""
    assert_steps_from_a_turned_state(SPATIAL, integrator, 2)


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_actuators_on_spatial_tendons_step_as_in_mujoco(integrator):
    """test_soft_elements's actuators on spatial tendons under steady controls: their moment arms
    move with the state; implicitfast takes their velocity gains into K (gear² J_νᵀ J_ν)."""
    assert_steps_from_a_turned_state(SPATIAL_ACTUATORS, integrator, 5, ctrl=[0.4, 0.7, 0.2, 1.1, 0.3])


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_tendon_actuator_force_ranges_step_as_in_mujoco(integrator):
    """test_soft_elements's tendon actuators bounded by their tendons' actuatorfrcrange through 100
    steps; implicitfast leaves out of K an actuator whose force sits on its forcerange and those of
    a tendon whose forces are scaled into its range (as MuJoCo 4.0's qDeriv does)."""
    assert_steps_from_a_turned_state(TENDON_FORCE_RANGES, integrator, 6, ctrl=[0.9, 1.7, -1.2, 1.6, 0.9])


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_tendon_inertias_step_as_in_mujoco(integrator):
    """test_soft_elements's tendons with inertias (a cord across two trees, an actuator's armature,
    fixed tendons, a demoted simple body) through 100 steps: Euler's implicit damping and
    implicitfast's solve take M with them."""
    assert_steps_from_a_turned_state(TENDON_INERTIAS, integrator, 8, ctrl=[0.9, 1.7, -1.2, 1.6, 0.9])


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_tendons_wrapping_geoms_step_as_in_mujoco(integrator):
    """test_soft_elements's wrapping tendons (a cylinder and spheres, side sites, a pulley, two
    tendon actuators) through 100 steps from a turned state."""
    assert_steps_from_a_turned_state(WRAPS, integrator, 3, ctrl=[0.8, -0.5])


# --- 3. a Menagerie quadruped, dm_control's suite ----------------------------------------------


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_go2_at_home_steps_as_in_mujoco(integrator, tmp_path):
    """Menagerie's Go2 on its floor from `home` (elliptic cone, impratio 100, dry friction on every
    joint), its motors told the keyframe's controls; its own integrator is Euler, the others on a
    copy of its files."""
    folder = MENAGERIE / "unitree_go2"
    for name in ("go2.xml", "scene.xml"):
        text = (folder / name).read_text()
        if name == "go2.xml":
            text = text.replace("<option ", f'<option integrator="{integrator}" ', 1)
        (tmp_path / name).write_text(text)
    path = tmp_path / "scene.xml"
    model = load_quietly(path)
    mj_model = converged(mujoco_model(path, "unitree_go2/scene.xml"))
    assert model.options.integrator == integrator
    layout = MujocoLayout(model, mj_model)
    home = mj_model.key("home")
    assert_steps_like_mujoco(model, mj_model, layout, home.qpos, home.qvel, ctrl=home.ctrl,
                             tolerance=ELLIPTIC_STEP_AGREEMENT, label=integrator)


@pytest.mark.parametrize("name", SUITE + FLAGGED)
def test_dm_control_models_step_as_in_mujoco(name):
    """Each suite model with its own integrator (acrobot and cartpole RK4, the rest Euler, most with
    joint damping) from a random state near its floor, under random controls."""
    model, mj_model, layout = load_both(path=REPOSITORY / "testdata" / "dm_control" / f"{name}.xml")
    without_unmodelled(mj_model)
    rng = np.random.default_rng(8)
    qpos, qvel = random_suite_state(mj_model, rng)
    ctrl = rng.uniform(-1.0, 1.0, size=mj_model.nu)
    assert_steps_like_mujoco(model, mj_model, layout, qpos, qvel, ctrl=ctrl, label=name)


# --- 4. one step, starting and driving a run ----------------------------------------------------


def test_one_step_is_mj_step_and_batches_step_each_state():
    model, mj_model, layout = load_both(text=box_scene(3, "pyramidal"))
    rng = np.random.default_rng(2)
    q = np.array([layout.q_from_mujoco(mj_model.qpos0)] * 3)
    v = rng.normal(size=(3, 6))
    tau = rng.normal(size=(3, 6))
    x1 = robodyn.step(model, q, v, tau, model.options.timestep, integrator="mujoco")
    assert x1.shape == (3, model.nq + model.nv)
    for k in range(3):
        qpos, qvel = layout.q_to_mujoco(q[k]), layout.v_to_mujoco(q[k], v[k])
        (expected_qpos, expected_qvel), = mujoco_steps(mj_model, layout, qpos, qvel, tau=tau[k], steps=1)
        q1, v1 = x1[k, : model.nq], x1[k, model.nq :]
        assert np.allclose(layout.q_to_mujoco(q1), expected_qpos, rtol=0, atol=STEP_AGREEMENT)
        assert np.allclose(layout.v_to_mujoco(q1, v1), expected_qvel, rtol=0, atol=STEP_AGREEMENT)
        single = robodyn.step(model, q[k], v[k], tau[k], model.options.timestep, integrator="mujoco")
        assert np.array_equal(single, x1[k])


def test_a_property_set_between_steps_is_felt_by_the_next():
    """`step` keeps the scene's weights per model: a property set afterwards makes them anew (the
    armature changes M at qpos0, hence the contacts' regularisers), as a model loaded so would."""
    model, _, layout = load_both(text=box_scene(3, "pyramidal"))
    q = layout.q_from_mujoco(np.array([0.0, 0.0, 0.09, 1.0, 0.0, 0.0, 0.0]))
    v, tau, h = np.array([0.3, 0.0, -0.2, 0.0, 0.0, 0.0]), np.zeros(6), model.options.timestep
    before = robodyn.step(model, q, v, tau, h, integrator="mujoco")
    model.armature = np.full(6, 0.5)
    after = robodyn.step(model, q, v, tau, h, integrator="mujoco")
    fresh, _, _ = load_both(text=box_scene(3, "pyramidal"))
    fresh.armature = np.full(6, 0.5)
    assert not np.allclose(before, after)
    assert np.array_equal(after, robodyn.step(fresh, q, v, tau, h, integrator="mujoco"))


def test_a_run_starts_from_a_keyframe_with_its_controls():
    """`q0` may name a keyframe: its q, v and ctrl; controls given win, a callable is asked at each
    step's start and gives the same run as the array it returns."""
    model = load_quietly(MENAGERIE / "unitree_go2" / "scene.xml")
    home = model.keyframe("home")
    h = model.options.timestep
    run = robodyn.simulate(model, "home", t_end=10 * h, integrator="mujoco")
    assert np.array_equal(run.q[0], home.q) and np.array_equal(run.ctrl[0], home.ctrl)
    assert run.ctrl.shape == (11, model.nu) and run.tau_constraint.shape == (11, model.nv)
    # each sample's contacts and forces are the forward dynamics' at its state
    forward = model.contact_forward_dynamics(run.q[5], run.v[5], ctrl=home.ctrl)
    assert [c["geom2"] for c in run.contacts[5]] == [c["geom2"] for c in forward["contacts"]]
    scale = max(np.abs(c["force"]).max() for c in forward["contacts"])
    for recorded, found in zip(run.contacts[5], forward["contacts"]):
        np.testing.assert_allclose(recorded["force"], found["force"], rtol=0, atol=WARM_START_AGREEMENT * scale)
    np.testing.assert_allclose(run.tau_constraint[5], forward["tau_constraint"], rtol=0,
                               atol=WARM_START_AGREEMENT * scale)
    same = robodyn.simulate(model, home.q, home.v, t_end=10 * h, integrator="mujoco", ctrl=home.ctrl)
    assert np.array_equal(run.q, same.q)
    asked = []

    def ctrl(t, q, v):
        asked.append(t)
        return home.ctrl

    called = robodyn.simulate(model, "home", t_end=10 * h, integrator="mujoco", ctrl=ctrl)
    assert np.array_equal(called.q, run.q)
    assert np.allclose(asked, h * np.arange(11))
    # recorded every 5 steps
    sparse = robodyn.simulate(model, "home", t_end=10 * h, dt=5 * h, integrator="mujoco")
    assert np.array_equal(sparse.q, run.q[::5])


def test_a_run_from_a_keyframe_starts_at_its_time():
    """A keyframe's `time` is the run's first (MuJoCo's mj_resetDataKeyframe sets d.time): the samples,
    the callbacks' t and t_end count from it; a t_end before it is refused naming it."""
    text = SPINNER.format("Euler").replace("</mujoco>", '<keyframe><key name="late" time="0.3"/></keyframe></mujoco>')
    model = load_quietly(text=text)
    h, seen = model.options.timestep, []

    def push(t, q, v):
        seen.append(t)
        return np.zeros(model.nv)

    run = robodyn.simulate(model, "late", t_end=0.3 + 10 * h, integrator="mujoco", controller=push)
    assert len(run.t) == 11 and np.allclose(run.t, 0.3 + h * np.arange(11), rtol=0, atol=1e-12)
    assert seen[0] == 0.3 and np.allclose(seen, run.t[: len(seen)], rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match=r"argument 't_end': expected a time \(s\) not before the start, 0.3"):
        robodyn.simulate(model, "late", t_end=0.2, integrator="mujoco")


def test_rollouts_in_parallel_equal_their_own_runs():
    model = load_quietly(text=box_scene(3, "pyramidal"))
    rng = np.random.default_rng(3)
    q0 = np.array([model.neutral()] * 4)
    q0[:, 2] = 0.1 + rng.uniform(0.0, 0.05, 4)
    v0 = rng.normal(size=(4, 6))
    runs = robodyn.simulate(model, q0, v0, t_end=0.1, integrator="mujoco")
    assert len(runs) == 4
    for k in range(4):
        alone = robodyn.simulate(model, q0[k], v0[k], t_end=0.1, integrator="mujoco")
        assert np.array_equal(runs[k].q, alone.q)


# --- 5. what is refused --------------------------------------------------------------------------


def test_bad_input_is_refused_naming_it():
    model = load_quietly(MENAGERIE / "unitree_go2" / "scene.xml")
    h = model.options.timestep
    with pytest.raises(ValueError, match="ctrl"):
        robodyn.simulate(model, "home", t_end=h, integrator="mujoco", ctrl=np.zeros(3))
    with pytest.raises(ValueError, match="'crouch'"):
        robodyn.simulate(model, "crouch", t_end=h, integrator="mujoco")
    with pytest.raises(ValueError, match="dt"):
        robodyn.simulate(model, "home", t_end=h, dt=1.5 * h, integrator="mujoco")
    with pytest.raises(ValueError, match="wrenches"):
        robodyn.simulate(model, "home", t_end=h, integrator="mujoco", wrenches=np.zeros((len(model.body_names), 6)))
    with pytest.raises(ValueError, match="ctrl"):
        robodyn.simulate(model, "home", t_end=h, integrator="rk4", ctrl=np.zeros(model.nu))
    home = model.keyframe("home")
    with pytest.raises(ValueError, match="dt"):
        robodyn.step(model, home.q, home.v, np.zeros(model.nv), 2 * h, integrator="mujoco")
    with pytest.raises(ValueError, match="derivatives"):
        robodyn.step(model, home.q, home.v, np.zeros(model.nv), h, integrator="mujoco", derivatives=True)
    with pytest.raises(ValueError, match="returned at t = 0"):
        robodyn.simulate(model, "home", t_end=h, integrator="mujoco", ctrl=lambda t, q, v: np.zeros(2))
    implicit = load_quietly(text=with_integrator(box_scene(), "implicit"))
    with pytest.raises(ValueError, match="implicit"):
        robodyn.simulate(implicit, implicit.neutral(), t_end=0.01, integrator="mujoco")


def test_a_diverging_scene_stops_with_the_time():
    """A state past MuJoCo's 1e10 stops the run with SimulationError naming the time."""
    model = load_quietly(text=SPINNER.format("Euler"))
    with pytest.raises(robodyn.SimulationError, match="diverged"):
        robodyn.simulate(model, model.neutral(), np.full(6, 1e11), t_end=0.01, integrator="mujoco")
