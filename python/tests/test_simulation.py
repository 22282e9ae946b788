"""robodyn.simulate: energy, free-body motion, the pendulum's period, tracking, MuJoCo's RK4,
passive forces, callbacks, batches, files and errors. (Convergence orders and RK45's tolerance are
checked in crates/robodyn/tests/simulation.rs.)"""

from __future__ import annotations

import re

import mujoco
import numpy as np
import pytest
from conftest import REPOSITORY

import robodyn
from robodyn.crosscheck import rigid_body_only

#: Relative drift of total energy over 10 s allowed to RK45 at tight tolerance.
ENERGY_DRIFT_TOLERANCE = 1e-6
#: Tolerances RK45 runs at when energy must be conserved.
TIGHT = dict(integrator="rk45", rtol=1e-11, atol=1e-11)
#: Relative error of the small-amplitude pendulum period against 2π√(l/g).
PERIOD_TOLERANCE = 1e-6
#: Computed-torque tracking error (rad).
TRACKING_TOLERANCE = 1e-6
#: Agreement with MuJoCo's RK4 over 1 s (rad, rad/s).
MUJOCO_TOLERANCE = 1e-6
#: Relative change of a free body's angular momentum over its run.
MOMENTUM_TOLERANCE = 1e-9

BOX_URDF = """<robot name="box"><link name="box"><inertial><mass value="2"/>
  <inertia ixx="0.0217" iyy="0.0167" izz="0.0083" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>"""


def free_box():
    """A 2 kg box with distinct principal moments (x major, y intermediate, z minor), no gravity."""
    model = robodyn.load_urdf_string(BOX_URDF, floating_base=True)
    model.gravity = [0.0, 0.0, 0.0]
    return model


def relative_drift(trajectory):
    energy = trajectory.energy
    return float(np.max(np.abs(energy - energy[0])) / max(abs(energy[0]), np.max(np.abs(trajectory.kinetic_energy))))


@pytest.mark.parametrize("name", ["planar2", "ur5"])
def test_rk45_conserves_energy_over_ten_seconds(name):
    m = robodyn.load(name)
    q0 = m.neutral() + 0.8
    trajectory = robodyn.simulate(m, q0, t_end=10.0, dt=0.01, **TIGHT)
    assert trajectory.kinetic_energy.max() > 1.0, "the robot should swing"
    assert relative_drift(trajectory) < ENERGY_DRIFT_TOLERANCE


def test_semi_implicit_euler_energy_stays_bounded_where_explicit_euler_drifts():
    m = robodyn.load("pendulum")
    # first-order schemes at a coarse step, on purpose: the accuracy check would warn
    run = {name: robodyn.simulate(m, [1.0], t_end=100.0, dt=0.01, integrator=name, accuracy="ignore")
           for name in ("semi_implicit_euler", "euler")}
    error = {name: np.abs(t.energy - t.energy[0]) for name, t in run.items()}
    halves = {name: (e[: len(e) // 2].max(), e[len(e) // 2:].max()) for name, e in error.items()}
    first, second = halves["semi_implicit_euler"]
    # bounded: the second 50 s are no worse than the first, and the error is O(dt)
    assert second < 1.1 * first and second < 0.05 * run["euler"].energy[0] + 0.5
    # explicit Euler gains energy steadily
    first, second = halves["euler"]
    assert second > 1.5 * first and run["euler"].energy[-1] > run["euler"].energy[0] + 1.0


def test_free_body_keeps_its_angular_momentum_and_flips_about_the_intermediate_axis():
    m = free_box()
    identity = [0, 0, 0, 0, 0, 0, 1.0]
    flips = {}
    for axis in range(3):
        v0 = np.zeros(6)
        v0[3 + axis] = 5.0
        v0[3 + (axis + 1) % 3] = 0.01  # a small perturbation
        trajectory = robodyn.simulate(m, identity, v0, t_end=10.0, dt=0.01, **TIGHT)
        momentum = np.asarray(m.centroidal_momentum(trajectory.q, trajectory.v))[:, 3:]
        change = np.max(np.linalg.norm(momentum - momentum[0], axis=1)) / np.linalg.norm(momentum[0])
        assert change < MOMENTUM_TOLERANCE, f"axis {axis}"
        # the body axis that started along the spin: its world direction, against the start
        poses = np.asarray(m.frame_pose(trajectory.q, "box"))
        flips[axis] = float(np.min(poses[:, axis, axis]))
        quaternion_norms = np.linalg.norm(trajectory.q[:, 3:], axis=1)
        assert np.max(np.abs(quaternion_norms - 1)) < 1e-12
    # Dzhanibekov: the intermediate axis (y) turns over; the major (x) and minor (z) stay
    assert flips[1] < -0.9
    assert flips[0] > 0.9 and flips[2] > 0.9


def test_small_swings_of_the_pendulum_take_two_pi_root_l_over_g():
    m = robodyn.load("pendulum")  # point mass, l = 1 m
    trajectory = robodyn.simulate(m, [1e-3], t_end=10.0, dt=1e-3, **TIGHT)
    q, t = trajectory.q[:, 0], trajectory.t
    # upward zero crossings, linearly interpolated
    k = np.flatnonzero((q[:-1] < 0) & (q[1:] >= 0))
    crossings = t[k] - q[k] * (t[k + 1] - t[k]) / (q[k + 1] - q[k])
    period = np.mean(np.diff(crossings))
    expected = 2 * np.pi * np.sqrt(1.0 / 9.81)
    assert len(crossings) >= 4
    assert abs(period - expected) / expected < PERIOD_TOLERANCE


def sinusoid_reference(m, duration=2.0, knots=81):
    times = np.linspace(0.0, duration, knots)
    w = 1.0 + 0.3 * np.arange(m.nv)
    q = 0.5 * np.sin(np.outer(times, w))
    v = 0.5 * w * np.cos(np.outer(times, w))
    return times, q, v


def test_computed_torque_tracks_a_reference_motion():
    m = robodyn.load("ur5")
    m.damping = np.full(m.nv, 0.5)  # cancelled by the controller
    times, q, v = sinusoid_reference(m)
    controller = robodyn.ComputedTorque(kp=100.0, kd=20.0, reference=(times, q, v))
    trajectory = robodyn.simulate(m, q[0], v[0], t_end=2.0, dt=1e-3, controller=controller)
    at_knots = np.searchsorted(trajectory.t, times - 1e-12)
    assert np.max(np.abs(trajectory.q[at_knots] - q)) < TRACKING_TOLERANCE
    # PD with gravity compensation on the same reference lags behind by far more (undamped: the
    # wrist's damping over its small inertia, 0.5 / 1.3e-4 s⁻¹, would need a step below 0.7 ms)
    m.damping = np.zeros(m.nv)
    inertia = np.diag(m.mass_matrix(q[0]))
    pd = robodyn.PD(kp=100.0 * inertia, kd=20.0 * inertia, reference=(times, q, v), gravity_compensation=True)
    lagging = robodyn.simulate(m, q[0], v[0], t_end=2.0, dt=1e-3, controller=pd)
    assert np.max(np.abs(lagging.q[at_knots] - q)) > 1e3 * TRACKING_TOLERANCE


def test_ur5_agrees_with_mujoco_rk4_over_one_second():
    urdf = (REPOSITORY / "models" / "ur5.urdf").read_text()
    mj = rigid_body_only(mujoco.MjModel.from_xml_string(re.sub(r"<(visual|collision)\b.*?</\1>", "", urdf, flags=re.S)))
    m = robodyn.load("ur5")
    armature, damping = np.linspace(0.05, 0.01, m.nv), np.linspace(0.5, 0.1, m.nv)
    stiffness, spring_reference = np.linspace(2.0, 0.5, m.nv), np.linspace(-0.3, 0.3, m.nv)
    m.armature, m.damping, m.stiffness, m.spring_reference = armature, damping, stiffness, spring_reference
    mj.dof_armature[:], mj.dof_damping[:], mj.jnt_stiffness[:], mj.qpos_spring[:] = armature, damping, stiffness, spring_reference
    mj.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    mj.opt.timestep = 1e-4
    tau = np.linspace(3.0, -1.0, m.nv)
    q0, v0 = np.linspace(0.2, -0.4, m.nv), np.linspace(-0.5, 0.5, m.nv)
    data = mujoco.MjData(mj)
    data.qpos[:], data.qvel[:], data.qfrc_applied[:] = q0, v0, tau
    steps = 10_000
    for _ in range(steps):
        mujoco.mj_step(mj, data)
    trajectory = robodyn.simulate(m, q0, v0, t_end=steps * 1e-4, dt=1e-4, controller=tau)
    assert np.max(np.abs(trajectory.q[-1] - data.qpos)) < MUJOCO_TOLERANCE
    assert np.max(np.abs(trajectory.v[-1] - data.qvel)) < MUJOCO_TOLERANCE
    assert np.max(np.abs(trajectory.q[-1] - q0)) > 0.1, "the arm should have moved"


def test_damping_dissipates_and_friction_stops_the_pendulum():
    m = robodyn.load("pendulum")
    m.damping = [0.3]
    damped = robodyn.simulate(m, [1.0], t_end=5.0, dt=1e-3)
    # dE/dt = −d v² ≤ 0, and the lost energy is the damper's work
    assert np.all(np.diff(damped.energy) <= 1e-12)
    work = np.sum(0.5 * (damped.tau_passive[1:, 0] * damped.v[1:, 0] + damped.tau_passive[:-1, 0] * damped.v[:-1, 0]) * np.diff(damped.t))
    assert abs(damped.energy[-1] - damped.energy[0] - work) < 1e-6
    m.damping, m.friction = [0.0], [0.5]
    rubbing = robodyn.simulate(m, [1.0], t_end=10.0, dt=1e-3, friction_velocity=1e-3)
    assert abs(rubbing.v[-1, 0]) < 1e-2 and abs(rubbing.q[-1, 0]) < 0.06
    assert np.max(np.abs(rubbing.tau_passive)) <= 0.5


def test_joint_limits_are_reported_and_optionally_enforced():
    m = robodyn.load("planar2")
    # the bundled arm has no limits: none reported
    assert robodyn.simulate(m, [0.5, 0.0], t_end=1.0, dt=1e-3).limit_violations == []
    m2 = robodyn.load_urdf_string((REPOSITORY / "models" / "planar2.urdf").read_text().replace(
        'type="continuous"', 'type="revolute"').replace("<axis", '<limit lower="-0.5" upper="0.5" effort="1" velocity="1"/><axis'))
    m2.gravity = m.gravity
    free = robodyn.simulate(m2, [0.4, 0.0], t_end=1.0, dt=1e-3)
    joints = {v["joint"] for v in free.limit_violations}
    assert joints and all(v["worst_excess"] > 0.1 for v in free.limit_violations)
    held = robodyn.simulate(m2, [0.4, 0.0], t_end=1.0, dt=1e-4, limits="penalty")
    assert all(v["worst_excess"] < 0.05 for v in held.limit_violations)


def test_wrenches_as_functions_of_time():
    m = robodyn.load("pendulum")

    def hold_up(t, q, v):
        # m g upwards at the bob, (0, 0, −1) in the body frame, expressed in body axes
        c, s = np.cos(q[0]), np.sin(q[0])
        force = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]).T @ [0.0, 0.0, 9.81]
        moment = np.cross([0.0, 0.0, -1.0], force)
        return np.concatenate([force, moment])[None, :]

    held = robodyn.simulate(m, [0.5], t_end=2.0, dt=1e-3, wrenches=hold_up)
    assert np.max(np.abs(held.q[:, 0] - 0.5)) < 1e-12
    # a constant wrench array acts the same as a callable returning it
    push = np.array([[0.0, 0, 0, 0, 1.0, 0]])  # a moment about the hinge
    constant = robodyn.simulate(m, [0.0], t_end=1.0, dt=1e-3, wrenches=push)
    called = robodyn.simulate(m, [0.0], t_end=1.0, dt=1e-3, wrenches=lambda t, q, v: push)
    np.testing.assert_allclose(constant.q, called.q, atol=1e-14)
    assert np.max(np.abs(constant.q)) > 0.01


def test_a_python_controller_matches_the_native_one():
    m = robodyn.load("ur5")
    q_ref = np.full(m.nv, 0.3)
    kp, kd = np.array([100, 100, 50, 5, 5, 1.0]), np.array([10, 10, 5, 0.5, 0.5, 0.1])
    native = robodyn.simulate(m, m.neutral(), t_end=0.5, dt=1e-3,
                              controller=robodyn.PD(kp, kd, q_ref=q_ref, gravity_compensation=True))
    calls = []

    def pd(t, q, v):
        calls.append(t)
        return kp * (q_ref - q) - kd * v + m.generalized_gravity(q)

    python = robodyn.simulate(m, m.neutral(), t_end=0.5, dt=1e-3, controller=pd)
    np.testing.assert_allclose(python.q, native.q, atol=1e-12)
    np.testing.assert_allclose(python.tau, native.tau, atol=1e-9)
    # 4 per RK4 step and one at the start, plus 7 for each step-doubling check of the divergence
    # guard (two half steps of 3 new stages, and q̈ halfway), at steps 1, 50, 100, ..., 500
    checks = 1 + 500 // 50
    assert len(calls) == python.evaluations == 4 * 500 + 1 + 7 * checks
    gravity = robodyn.simulate(m, m.neutral(), t_end=0.2, dt=1e-3, controller=robodyn.GravityCompensation())
    assert np.max(np.abs(gravity.q - m.neutral())) < 1e-12


def test_batched_rollouts_match_single_runs():
    m = robodyn.load("ur5")
    q0 = m.random_configuration(n=4, seed=3)
    v0 = np.linspace(-1, 1, 4 * m.nv).reshape(4, m.nv)
    for controller in (None, lambda t, q, v: -0.01 * v):
        runs = robodyn.simulate(m, q0, v0, t_end=0.3, dt=1e-3, controller=controller)
        assert len(runs) == 4
        for k, run in enumerate(runs):
            single = robodyn.simulate(m, q0[k], v0[k], t_end=0.3, dt=1e-3, controller=controller)
            np.testing.assert_array_equal(run.q, single.q)
            assert run.steps == single.steps == 300


@pytest.mark.parametrize("integrator", ["euler", "semi_implicit_euler", "rk4", "rk45"])
def test_rollouts_in_lockstep_equal_single_runs_bit_for_bit(integrator):
    # native controllers without wrenches: the rollouts of a batch advance in lockstep, their
    # forward dynamics in lanes; 11 rollouts make full lane groups and leftovers on each thread
    m = robodyn.load("ur5")
    m.damping = [0.01] * m.nv
    n = 11
    q0 = m.random_configuration(n=n, seed=4)
    v0 = np.linspace(-1, 1, n * m.nv).reshape(n, m.nv)
    inertia = np.diag(m.mass_matrix(m.neutral()))
    controller = robodyn.PD(100 * inertia, 20 * inertia, q_ref=m.neutral(), gravity_compensation=True)
    # 120 steps: the guard's step-doubling checks at steps 1, 50 and 100 run too
    options = dict(t_end=0.024, dt=2e-4, integrator=integrator, controller=controller)
    runs = robodyn.simulate(m, q0, v0, **options)
    for k, run in enumerate(runs):
        single = robodyn.simulate(m, q0[k], v0[k], **options)
        for field in ("t", "q", "v", "a", "tau", "tau_passive"):
            np.testing.assert_array_equal(getattr(run, field), getattr(single, field), err_msg=field)
        assert (run.steps, run.evaluations) == (single.steps, single.evaluations)


def test_a_diverging_rollout_in_lockstep_is_named():
    m = robodyn.load("ur5")
    m.gravity = [0.0, 0.0, 0.0]
    q0 = np.stack([m.neutral()] * 5)
    q0[3, 1] = 1.0  # only rollout 3 moves (the others rest exactly), under far too stiff a PD
    controller = robodyn.PD([1e7] * m.nv, [0.0] * m.nv, q_ref=m.neutral())
    with pytest.raises(robodyn.SimulationError, match="rollout 3: .*dt = 5e-2 s is far too large"):
        robodyn.simulate(m, q0, np.zeros((5, m.nv)), t_end=1.0, dt=0.05, controller=controller)


def test_files_plots_and_animation(tmp_path):
    from PIL import Image

    m = robodyn.load("planar2")
    trajectory = robodyn.simulate(m, [1.0, 0.5], t_end=0.5, dt=0.01)
    trajectory.to_csv(tmp_path / "run.csv")
    table = np.genfromtxt(tmp_path / "run.csv", delimiter=",", names=True)
    np.testing.assert_allclose(table["energy"], trajectory.energy)
    assert len(table) == 51
    trajectory.to_npz(tmp_path / "run.npz")
    with np.load(tmp_path / "run.npz") as saved:
        np.testing.assert_array_equal(saved["q"], trajectory.q)
        assert list(saved["q_names"]) == m.joint_names
    trajectory.plot(tmp_path / "run.png")
    with Image.open(tmp_path / "run.png") as image:
        assert image.format == "PNG" and image.size[0] > 500
    trajectory.animate(tmp_path / "run.gif", fps=20)
    with Image.open(tmp_path / "run.gif") as image:
        assert image.format == "GIF" and image.n_frames == 11
    with pytest.raises(ValueError, match="'path'"):
        trajectory.animate(tmp_path / "run.avi")
    from matplotlib import animation

    if animation.writers.is_available("ffmpeg"):
        trajectory.animate(tmp_path / "run.mp4")
        assert (tmp_path / "run.mp4").stat().st_size > 1000
    else:
        with pytest.raises(ValueError, match="needs ffmpeg"):
            trajectory.animate(tmp_path / "run.mp4")


@pytest.mark.parametrize(
    "arguments, message",
    [
        (dict(integrator="rk5"), "'integrator'"),
        (dict(dt=0.0), "'dt'"),
        (dict(t_end=-1.0), "'t_end'"),
        (dict(q0=[np.nan, 0.0]), "'q0'"),
        (dict(v0=np.zeros(3)), "'v0'"),
        (dict(controller="pd"), "'controller'"),
        (dict(controller=robodyn.PD(1.0, 1.0)), "'q_ref'"),
        (dict(controller=robodyn.PD(1.0, 1.0, reference=([0.0, 0.5], np.zeros((2, 2)), np.zeros((2, 2))))), "'reference times'"),
        (dict(controller=lambda t, q, v: np.zeros(3)), "controller"),
        (dict(controller=lambda t, q, v: np.full(2, np.nan)), "'controller torque'"),
        (dict(limits="hard"), "'limits'"),
        (dict(integrator="rk45", rtol=0.0), "'rtol'"),
        (dict(wrenches=np.zeros((3, 6))), "'wrenches'"),
    ],
)
def test_bad_arguments_name_themselves(arguments, message):
    m = robodyn.load("planar2")
    call = dict(q0=[0.1, 0.2], t_end=1.0, dt=1e-3) | arguments
    with pytest.raises(ValueError, match=message):
        robodyn.simulate(m, **call)


def test_callback_exceptions_propagate_and_divergence_is_reported():
    m = robodyn.load("planar2")

    def broken(t, q, v):
        raise KeyError("from the controller")

    with pytest.raises(KeyError, match="from the controller"):
        robodyn.simulate(m, [0.1, 0.2], t_end=1.0, dt=1e-3, controller=broken)
    with pytest.raises(robodyn.SimulationError, match="simulation diverged at t = "):
        robodyn.simulate(m, [0.1, 0.2], t_end=1.0, dt=0.1, integrator="euler", controller=robodyn.PD(1e6, 1e3, q_ref=[0, 0]))


def test_progress_is_reported():
    m = robodyn.load("pendulum")
    fractions = []
    robodyn.simulate(m, [0.5], t_end=1.0, dt=1e-3, progress=fractions.append)
    assert fractions[0] == 0.0 and fractions[-1] == 1.0 and 50 <= len(fractions) <= 200
    assert fractions == sorted(fractions)


def test_the_simulate_command_reports_plots_and_shows_progress(tmp_path, capsys):
    from PIL import Image

    from robodyn.cli import main

    plot = tmp_path / "out.png"
    assert main(["simulate", "ur5", "--t", "1", "--integrator", "rk45", "--dt", "0.01", "--plot", str(plot), "--progress"]) == 0
    output = capsys.readouterr()
    assert "ur5: 1 s with rk45" in output.out and "energy:" in output.out
    assert output.err.rstrip().endswith("100.0 %") and "[####" in output.err
    with Image.open(plot) as image:
        assert image.format == "PNG"
    assert main(["simulate", "missing.urdf"]) == 2
    assert "robodyn simulate: model file not found" in capsys.readouterr().err
