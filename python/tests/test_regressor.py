"""The joint-torque regressor and the inertial parameters: against Pinocchio's
`computeJointTorqueRegressor` and dynamic parameters on example-robot-data robots, τ = Y π against
inverse dynamics, settable parameters, and clear errors for unphysical ones."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import CROSS_CHECK_TOLERANCE, assert_close

import robodyn

#: τ = Y π and inverse dynamics are the same sums in another order.
REGRESSOR_TOLERANCE = 1e-12


def test_parameters_and_regressor_agree_with_pinocchio(pinocchio_robot):
    name, model, pin_model, mapping = pinocchio_robot
    data = pin_model.createData()
    assert_close(model.inertial_parameters, mapping.inertial_parameters_from_pinocchio(), CROSS_CHECK_TOLERANCE, f"{name} π")
    rng = np.random.default_rng(5)
    for seed in range(3):
        q = model.random_configuration(seed=seed)
        v, a = rng.uniform(-2, 2, model.nv), rng.uniform(-2, 2, model.nv)
        pq, pv, pa = mapping.q_to_pinocchio(q), mapping.v_to_pinocchio(v), mapping.v_to_pinocchio(a)
        theirs = pin.computeJointTorqueRegressor(pin_model, data, pq, pv, pa)
        ours = model.torque_regressor(q, v, a)
        assert ours.shape == (model.nv, 10 * len(model.body_names))
        assert_close(ours, mapping.regressor_from_pinocchio(theirs), CROSS_CHECK_TOLERANCE, f"{name} Y")
        # τ = Y π is inverse dynamics
        tau = ours @ model.inertial_parameters.ravel()
        assert_close(tau, model.inverse_dynamics(q, v, a), REGRESSOR_TOLERANCE, f"{name} Y π")


def test_regressor_is_batched():
    model = robodyn.load("ur5")
    rng = np.random.default_rng(1)
    q = np.array([model.random_configuration(seed=s) for s in range(4)])
    v, a = rng.uniform(-1, 1, (4, model.nv)), rng.uniform(-1, 1, (4, model.nv))
    batch = model.torque_regressor(q, v, a)
    assert batch.shape == (4, model.nv, 10 * len(model.body_names))
    for k in range(4):
        np.testing.assert_array_equal(batch[k], model.torque_regressor(q[k], v[k], a[k]))


def test_setting_parameters_changes_the_dynamics():
    model = robodyn.load("ur5")
    q, v, a = model.random_configuration(seed=2), np.full(model.nv, 0.3), np.full(model.nv, -0.2)
    y = model.torque_regressor(q, v, a)
    pi = model.inertial_parameters
    heavier = pi.copy()
    heavier[-1] *= 3.0  # the last link three times as heavy, its inertia with it
    model.inertial_parameters = heavier
    np.testing.assert_array_equal(model.inertial_parameters, heavier)
    assert model.body_masses[-1] == pytest.approx(3.0 * pi[-1, 0])
    tau = model.inverse_dynamics(q, v, a)
    assert_close(tau, y @ heavier.ravel() + model.armature * a, REGRESSOR_TOLERANCE, "Y π_new")
    assert_close(model.forward_dynamics(q, v, tau), a, 1e-10, "aba∘rnea")


@pytest.mark.parametrize(
    ("spoil", "message"),
    [
        (lambda p: p.__setitem__((2, 0), -1.0), r"row 2 \(body '.*'\): expected a mass >= 0, got -1"),
        (lambda p: p.__setitem__((1, 9), -1e3), r"row 1 \(body '.*'\): expected a positive semi-definite"),
        (lambda p: p.__setitem__((0, 4), np.nan), r"argument 'inertial_parameters'.*not finite|finite"),
    ],
    ids=["negative mass", "not positive semi-definite", "nan"],
)
def test_unphysical_parameters_are_refused(spoil, message):
    model = robodyn.load("ur5")
    before = model.inertial_parameters
    bad = before.copy()
    spoil(bad)
    with pytest.raises(ValueError, match=message):
        model.inertial_parameters = bad
    np.testing.assert_array_equal(model.inertial_parameters, before)
    with pytest.raises(ValueError, match=r"argument 'inertial_parameters': expected shape \(6, 10\)"):
        model.inertial_parameters = before[1:]
