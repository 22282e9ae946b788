"""Accuracy you can see: a fixed-step run less accurate than ``rtol`` says so once (an
AccuracyWarning with the time, the error and a step that meets the tolerance), raises with
``accuracy="raise"``, and keeps its error estimates in the Trajectory; accurate, damped and
controlled runs raise no false alarm."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

import robodyn
from robodyn.cli import main


def swing(m, dt: float, **options):
    """The issue's case: the UR5 from neutral + 0.3 at rest, no damping, RK4, 5 s."""
    return robodyn.simulate(m, m.neutral() + 0.3, t_end=5.0, dt=dt, integrator="rk4", **options)


def no_accuracy_warning(run, *args, **options):
    """``run(*args, **options)`` with an AccuracyWarning turned into an error."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", robodyn.AccuracyWarning)
        return run(*args, **options)


def suggested_step(message: str) -> float:
    return float(re.search(r"a step of about (\S+) s or less meets the tolerance", message).group(1))


def test_the_coarse_swing_warns_once_with_time_error_and_a_step_that_meets_the_tolerance():
    m = robodyn.load("ur5")
    with pytest.warns(robodyn.AccuracyWarning) as record:
        coarse = swing(m, 0.05)
    assert len(record) == 1
    message = str(record[0].message)
    assert re.match(r"rk4: dt = 5\.000e-2 s misses rtol = 1\.0e-3 from t = \d+\.\d+ s: ", message), message
    issue = coarse.accuracy_issue
    assert issue is not None and issue["message"] in message
    assert issue["error"] > 1e-3 and 0.0 <= issue["time"] <= 5.0
    # the drift (checked every 16 samples) is the trajectory's own: 5.4 J off E₀ = -7.0 J, against
    # a largest kinetic energy of 37 J
    drift = np.abs(coarse.energy - coarse.energy[0]).max() / coarse.kinetic_energy.max()
    assert drift > 0.1 and 0.5 * drift < coarse.energy_drift < 2.0 * drift
    assert len(coarse.error_estimate) == len(coarse.error_times) == 3  # steps 1, 50 and 100
    # the suggested step meets the tolerance
    dt = suggested_step(message)
    assert dt == pytest.approx(issue["largest_step"], rel=0.05) and dt < 0.05
    fine = no_accuracy_warning(swing, m, dt)
    assert fine.accuracy_issue is None


def test_the_same_swing_at_a_millisecond_is_quiet_and_records_its_estimates():
    m = robodyn.load("ur5")
    fine = no_accuracy_warning(swing, m, 1e-3)
    assert fine.accuracy_issue is None
    assert len(fine.error_times) == 101 and fine.error_times[0] == 0.0
    assert np.all(fine.error_estimate < 1e-6) and fine.energy_drift < 1e-6


def test_damped_and_controlled_runs_give_no_false_alarm():
    m = robodyn.load("ur5")
    gains = np.diag(m.mass_matrix(m.neutral()))
    controllers = [robodyn.PD(kp=100 * gains, kd=20 * gains, q_ref=m.neutral(), gravity_compensation=True),
                   robodyn.GravityCompensation(), robodyn.ComputedTorque(kp=100.0, kd=20.0, q_ref=m.neutral()),
                   lambda t, q, v: -0.01 * v]
    for controller in controllers:
        run = no_accuracy_warning(swing, m, 1e-3, controller=controller)
        # a controller puts energy in: no drift to track
        assert run.energy_drift is None and run.accuracy_issue is None
    m.damping = np.full(m.nv, 0.02)  # the light wrist's velocity decays at 150 s⁻¹
    damped = no_accuracy_warning(swing, m, 1e-3)
    assert damped.energy_drift is None and np.all(damped.error_estimate < 1e-3)
    m.damping = np.zeros(m.nv)
    # the wrist meets its limit: the penalty's 1e4 N·m/rad on its small inertia needs a short step
    penalty = no_accuracy_warning(robodyn.simulate, m, m.neutral() + 0.3, t_end=1.0, dt=1e-4, limits="penalty")
    assert penalty.energy_drift is None


def test_raise_and_ignore():
    m = robodyn.load("ur5")
    with pytest.raises(robodyn.AccuracyError, match=r"misses rtol = 1\.0e-3") as error:
        swing(m, 0.05, accuracy="raise")
    assert isinstance(error.value, robodyn.SimulationError) and isinstance(error.value, ValueError)
    quiet = no_accuracy_warning(swing, m, 0.05, accuracy="ignore")
    assert quiet.accuracy_issue is not None
    # a looser tolerance lets the coarse run through, a tighter one flags a finer run
    no_accuracy_warning(swing, m, 2e-3, rtol=1.0)
    with pytest.warns(robodyn.AccuracyWarning, match=r"rtol = 1\.0e-12"):
        swing(m, 1e-3, rtol=1e-12)


def test_rk45_controls_its_own_error_and_is_not_checked():
    m = robodyn.load("ur5")
    run = no_accuracy_warning(robodyn.simulate, m, m.neutral() + 0.3, t_end=5.0, dt=0.05, integrator="rk45")
    assert len(run.error_estimate) == 0 and run.energy_drift is None and run.accuracy_issue is None


def test_each_rollout_of_a_batch_warns_once_and_names_itself():
    m = robodyn.load("ur5")
    q0 = np.stack([m.neutral() + 0.3, m.neutral() + 0.2])
    with pytest.warns(robodyn.AccuracyWarning) as record:
        runs = robodyn.simulate(m, q0, np.zeros((2, m.nv)), t_end=5.0, dt=0.05)
    assert sorted(str(w.message)[:9] for w in record) == ["rollout 0", "rollout 1"]
    assert all(run.accuracy_issue is not None for run in runs)


@pytest.mark.parametrize(
    ("options", "expected"),
    [
        ({"accuracy": "loud"}, r"argument 'accuracy': expected one of \['warn', 'raise', 'ignore'\], got 'loud'"),
        ({"accuracy": None}, r"argument 'accuracy': expected one of .* got None"),
        ({"rtol": 0.0}, r"argument 'rtol': expected a finite number > 0, got 0"),
        ({"rtol": -1e-3}, r"argument 'rtol': expected a finite number > 0, got -0\.001"),
        ({"rtol": float("nan")}, r"argument 'rtol': expected finite numbers, got nan"),
        ({"rtol": "tight"}, r"argument 'rtol': expected numbers, got 'tight'"),
    ],
)
def test_bad_accuracy_options_name_the_argument(options, expected):
    m = robodyn.load("planar2")
    with pytest.raises(ValueError, match=expected):
        robodyn.simulate(m, [0.1, 0.2], t_end=0.1, **options)


def test_the_cli_reports_a_coarse_run_in_its_summary(capsys):
    q0 = [str(x + 0.3) for x in robodyn.load("ur5").neutral()]
    assert no_accuracy_warning(main, ["simulate", "ur5", "--t", "5", "--dt", "0.05", "--q0", *q0]) == 0
    out = capsys.readouterr().out
    assert re.search(r"^accuracy: dt = 5\.000e-2 s misses rtol = 1\.0e-3 from t = ", out, re.MULTILINE), out
    assert no_accuracy_warning(main, ["simulate", "ur5", "--t", "0.5", "--q0", *q0]) == 0
    assert "accuracy:" not in capsys.readouterr().out
