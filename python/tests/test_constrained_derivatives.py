"""Derivatives of constrained dynamics from Python: finite differences of the dynamics themselves,
batches, one step's Jacobians with constraints, and bad input refused by name (the cross-checks
against Pinocchio are in test_constrained_derivatives_pinocchio.py)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import assert_close

import robodyn

#: Central differences with this step round to ε |f| / h ≈ 1e-10 |f| and truncate to h² |f'''|.
STEP = 1e-6
#: Their tolerance, relative to the size of the values differenced (amplified by M's conditioning).
DIFFERENCE_TOLERANCE = 1e-6
#: Identities between exact computations, relative.
IDENTITY_TOLERANCE = 1e-9
#: With derivatives a constrained stage's q̈ and λ are solved with M's factor, without them with
#: ABA's terms: the two round differently, by up to about cond(M) ε relative (as in free space).
STEP_PATHS_TOLERANCE = 1e-11


@pytest.fixture(scope="module")
def ur5():
    return robodyn.load("ur5")


def constraints():
    """The tool point held where it is and a wrist coupling: 4 rows on the UR5."""
    return [
        robodyn.PointAnchor("tool0", offset=[0.0, 0.0, 0.05]),
        robodyn.JointCoupling("wrist_3_joint", "wrist_1_joint", ratio=-2.0, offset=0.1),
    ]


def state(model, seed):
    rng = np.random.default_rng(seed)
    return model.random_configuration(seed=seed), rng.uniform(-1, 1, model.nv), rng.uniform(-5, 5, model.nv)


def differences(f, x, moved, n):
    """Central differences of f along each unit step of x (moved(x, step)), as columns."""
    columns = []
    for k in range(n):
        step = np.zeros(n)
        step[k] = STEP
        columns.append((f(moved(x, step)) - f(moved(x, -step))) / (2 * STEP))
    return np.stack(columns, axis=-1)


def assert_differences(label, analytic, numeric, size):
    scale = max(1.0, size, np.max(np.abs(numeric)))
    error = np.max(np.abs(analytic - numeric))
    assert error <= DIFFERENCE_TOLERANCE * scale, f"{label}: {error:.3e} (scale {scale:.3e})"


def test_forward_dynamics_derivatives_equal_finite_differences(ur5):
    q, v, tau = state(ur5, 3)
    held = constraints()
    result = ur5.constrained_forward_dynamics_derivatives(q, v, tau, held)
    plain = ur5.constrained_forward_dynamics(q, v, tau, held)
    assert_differences("qdd", result["qdd"], plain["qdd"], 0.0)
    assert result["dqdd_dq"].shape == (ur5.nv, ur5.nv) and result["dforces_dtau"].shape == (4, ur5.nv)

    def both(q, v, tau):
        out = ur5.constrained_forward_dynamics(q, v, tau, held)
        return np.concatenate([out["qdd"], out["forces"]])

    size = np.max(np.abs(both(q, v, tau)))
    for name, f, x, moved in [
        ("q", lambda x: both(x, v, tau), q, ur5.integrate),
        ("v", lambda x: both(q, x, tau), v, np.add),
        ("tau", lambda x: both(q, v, x), tau, np.add),
    ]:
        numeric = differences(f, x, moved, ur5.nv)
        analytic = np.vstack([result[f"dqdd_d{name}"], result[f"dforces_d{name}"]])
        assert_differences(f"d/d{name}", analytic, numeric, size)


def test_impulse_derivatives_equal_finite_differences(ur5):
    q, v, _ = state(ur5, 4)
    held = constraints()
    result = ur5.impulse_dynamics_derivatives(q, v, held, restitution=0.3)

    def both(q, v):
        out = ur5.impulse_dynamics(q, v, held, restitution=0.3)
        return np.concatenate([out["v"], out["impulses"]])

    size = np.max(np.abs(both(q, v)))
    for name, f, x, moved in [("q", lambda x: both(x, v), q, ur5.integrate), ("v", lambda x: both(q, x), v, np.add)]:
        numeric = differences(f, x, moved, ur5.nv)
        analytic = np.vstack([result[f"dv_d{name}"], result[f"dimpulses_d{name}"]])
        assert_differences(f"d/d{name}", analytic, numeric, size)


def test_batches_equal_one_state_at_a_time(ur5):
    rng = np.random.default_rng(5)
    n = 4
    q = ur5.random_configuration(n, seed=2)
    v, tau = rng.uniform(-1, 1, (n, ur5.nv)), rng.uniform(-5, 5, (n, ur5.nv))
    held = constraints()
    batch = ur5.constrained_forward_dynamics_derivatives(q, v, tau, held)
    impulses = ur5.impulse_dynamics_derivatives(q, v, held)
    assert batch["dforces_dq"].shape == (n, 4, ur5.nv)
    for k in range(n):
        one = ur5.constrained_forward_dynamics_derivatives(q[k], v[k], tau[k], held)
        for name, value in one.items():
            np.testing.assert_array_equal(batch[name][k], value)
        one = ur5.impulse_dynamics_derivatives(q[k], v[k], held)
        for name, value in one.items():
            np.testing.assert_array_equal(impulses[name][k], value)


def test_a_constrained_step_has_the_jacobians_of_its_finite_differences(ur5):
    q, v, tau = state(ur5, 6)
    held = constraints()
    dt = 1e-3
    x1, a, b = robodyn.step(ur5, q, v, tau, dt, derivatives=True, constraints=held)
    plain = robodyn.step(ur5, q, v, tau, dt, constraints=held)
    assert_close(x1, plain, STEP_PATHS_TOLERANCE, "x1 with and without derivatives")
    nq, nv = ur5.nq, ur5.nv
    # the step's result in the tangent space at q1: [difference(q1, q1'), v1']
    q1 = x1[:nq]

    def tangent(x):
        return np.concatenate([ur5.difference(q1, x[:nq]), x[nq:]])

    size = np.max(np.abs(x1))
    numeric_q = differences(lambda x: tangent(robodyn.step(ur5, x, v, tau, dt, constraints=held)), q, ur5.integrate, nv)
    numeric_v = differences(lambda x: tangent(robodyn.step(ur5, q, x, tau, dt, constraints=held)), v, np.add, nv)
    numeric_tau = differences(lambda x: tangent(robodyn.step(ur5, q, v, x, dt, constraints=held)), tau, np.add, nv)
    assert_differences("A", a, np.hstack([numeric_q, numeric_v]), size)
    assert_differences("B", b, numeric_tau, size)


def test_derivatives_refuse_what_they_do_not_hold(ur5):
    q, v, tau = state(ur5, 7)
    with pytest.raises(ValueError, match="baumgarte=None"):
        robodyn.step(ur5, q, v, tau, 1e-3, derivatives=True, constraints=constraints(), baumgarte=(10.0, 5.0))
    twice = constraints()[:1] * 2
    with pytest.raises(ValueError, match=r"constraints\[1\]"):
        ur5.constrained_forward_dynamics_derivatives(q, v, tau, twice)
    with pytest.raises(ValueError, match="damping"):
        ur5.constrained_forward_dynamics_derivatives(q, v, tau, constraints(), damping=-1.0)
    with pytest.raises(ValueError, match="restitution"):
        ur5.impulse_dynamics_derivatives(q, v, constraints(), restitution=2.0)
