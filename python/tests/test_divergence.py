"""Simulations never return garbage quietly: a rollout that leaves sensible bounds (non-finite
state, a speed beyond 1e6, energy growth beyond what the controller explains, a fixed step far too
large) stops with robodyn.SimulationError (a ValueError) saying when, what, which joint and the
step that keeps it stable."""

from __future__ import annotations

import re

import numpy as np
import pytest

import robodyn

#: A 1 kg slider on a spring of 100 N/m (ω = 10 rad/s): explicit Euler at dt = 0.05 s multiplies
#: its energy by 1 + (ω dt)² = 1.25 every step while its speed stays far below the speed bound.
SPRING = """<mujoco><compiler angle="radian"/><worldbody><body name="mass">
  <joint name="slide" type="slide" axis="1 0 0" stiffness="100"/>
  <inertial pos="0 0 0" mass="1" diaginertia="0.1 0.1 0.1"/></body></worldbody>
  <option gravity="0 0 0"/></mujoco>"""


def suggested_step(message: str) -> float:
    return float(re.search(r"a step of about (\S+) s \(dt\) or less keeps it stable", message).group(1))


def test_a_too_large_step_on_the_ur5_raises_with_time_joint_and_a_stable_step():
    m = robodyn.load("ur5")
    with pytest.raises(robodyn.SimulationError) as error:
        robodyn.simulate(m, m.neutral() + 0.3, t_end=2.0, dt=0.1)
    message = str(error.value)
    assert isinstance(error.value, ValueError)
    assert re.match(r"simulation diverged at t = \d+\.\d+ s: ", message)
    assert "joint '" in message and "bound 1e6" in message
    dt = suggested_step(message)
    # the suggestion really is stable
    robodyn.simulate(m, m.neutral() + 0.3, t_end=0.5, dt=dt)


def test_a_stiff_damping_gain_reports_the_step_it_needs():
    """docs/guide/simulation.md's example: kd = 5 on the UR5's light wrist needs a step below a millisecond."""
    m = robodyn.load("ur5")
    pd = robodyn.PD(kp=100.0, kd=5.0, q_ref=m.neutral())
    with pytest.raises(robodyn.SimulationError) as error:
        robodyn.simulate(m, m.neutral() + 0.3, t_end=1.0, dt=1e-3, controller=pd)
    dt = suggested_step(str(error.value))
    assert dt < 1e-3
    trajectory = robodyn.simulate(m, m.neutral() + 0.3, t_end=0.2, dt=dt, controller=pd)
    assert np.all(np.isfinite(trajectory.q))


def test_energy_growth_beyond_the_bound_raises_while_speeds_stay_small():
    m = robodyn.load_mjcf_string(SPRING)
    with pytest.raises(robodyn.SimulationError, match=r"the energy rose from 5\.0+e1 J to .* more than 1e6 times") as error:
        robodyn.simulate(m, [1.0], t_end=10.0, dt=0.05, integrator="euler")
    assert "speed" not in str(error.value)
    # the same spring with a smaller step stays within the guard's bounds, and semi-implicit Euler
    # at the large one too; both are far from accurate, which the accuracy check says
    with pytest.warns(robodyn.AccuracyWarning, match="euler: .* the energy drifted by"):
        robodyn.simulate(m, [1.0], t_end=10.0, dt=1e-3, integrator="euler")
    with pytest.warns(robodyn.AccuracyWarning, match="semi_implicit_euler: "):
        robodyn.simulate(m, [1.0], t_end=10.0, dt=0.05, integrator="semi_implicit_euler")


def test_a_step_far_too_large_is_refused_at_the_first_step():
    """ω dt = 20: one step and two half steps disagree by far more than the state's size."""
    m = robodyn.load_mjcf_string(SPRING.replace('stiffness="100"', 'stiffness="40000"'))
    with pytest.raises(robodyn.SimulationError, match=r"at t = 0\.000000 s: dt = 1e-1 s is far too large here"):
        robodyn.simulate(m, [1.0], t_end=1.0, dt=0.1, integrator="rk4")


def test_adaptive_runs_stop_at_the_speed_bound_and_suggest_tolerances():
    """A controller that pumps energy in (negative damping): RK45 follows the growth faithfully
    until the speed bound stops it."""
    m = robodyn.load("pendulum")
    with pytest.raises(robodyn.SimulationError, match=r"the speed of joint 'hinge' is .* above the bound 1e6; if the motion should stay bounded, tighter rtol"):
        robodyn.simulate(m, [0.1], t_end=100.0, dt=0.01, integrator="rk45", controller=lambda t, q, v: 5.0 * v)


def test_a_nan_from_the_controller_names_the_controller():
    m = robodyn.load("planar2")
    with pytest.raises(robodyn.SimulationError, match="controller torque") as error:
        robodyn.simulate(m, [0.1, 0.2], t_end=0.1, controller=lambda t, q, v: np.array([np.nan, 0.0]))
    assert "'dt'" not in str(error.value)
