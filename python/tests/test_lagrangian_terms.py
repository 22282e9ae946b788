"""The lecture notes' dynamics terms (issue 4, parts 1 and 2): the Coriolis matrix and Christoffel
symbols, Craig's centrifugal/Coriolis split, the mass matrix three ways and gravity two ways;
identities, closed forms of the 2-link arm (the TU Berlin and TUM notes), and Pinocchio's computeCoriolisMatrix."""

from __future__ import annotations

import itertools

import numpy as np
import pinocchio as pin
import pytest
from conftest import CROSS_CHECK_TOLERANCE, IDENTITY_TOLERANCE, ROBOTS, assert_close

import robodyn
from robodyn.convert import PinocchioLayout

#: The three mass matrices and the two gravity vectors agree to this (relative).
METHOD_TOLERANCE = 1e-12
#: Central finite differences of M with step FD_STEP are good to about this.
FD_TOLERANCE = 1e-6
FD_STEP = 1e-6


@pytest.fixture(scope="module", params=sorted(ROBOTS))
def robot(request, robots_dir):
    path, floating_base = ROBOTS[request.param]
    return request.param, robodyn.load(robots_dir / path, floating_base=floating_base), robots_dir / path, floating_base


def test_coriolis_matrix_identities(robot):
    """C v = bias − g, and Ṁ − 2C skew-symmetric with Ṁ a central difference along v."""
    name, model, _, _ = robot
    rng = np.random.default_rng(3)
    q, v = model.random_configuration(seed=3), rng.uniform(-1, 1, model.nv)
    c = model.coriolis_matrix(q, v)
    assert_close(c @ v, model.bias_forces(q, v) - model.generalized_gravity(q), IDENTITY_TOLERANCE, f"{name} C v")
    m_dot = (model.mass_matrix(model.integrate(q, v, FD_STEP)) - model.mass_matrix(model.integrate(q, v, -FD_STEP))) / (2 * FD_STEP)
    skew = m_dot - 2 * c
    assert_close(skew + skew.T, np.zeros_like(skew), FD_TOLERANCE * max(1.0, np.abs(m_dot).max()), f"{name} Ṁ − 2C")


def test_coriolis_matrix_agrees_with_pinocchio(robot):
    name, model, path, floating_base = robot
    pin_model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer()) if floating_base else pin.buildModelFromUrdf(str(path))
    layout, data = PinocchioLayout(model, pin_model), pin_model.createData()
    rng = np.random.default_rng(4)
    for seed in range(3):
        q, v = model.random_configuration(seed=seed), rng.uniform(-2, 2, model.nv)
        expected = pin.computeCoriolisMatrix(pin_model, data, layout.q_to_pinocchio(q), layout.v_to_pinocchio(v))
        assert_close(model.coriolis_matrix(q, v), layout.matrix_from_pinocchio(expected), CROSS_CHECK_TOLERANCE, f"{name} C")


def test_mass_matrix_three_ways_and_gravity_two_ways(robot):
    name, model, _, _ = robot
    q = model.random_configuration(seed=5)
    crba = model.mass_matrix(q)
    for method in ("rnea", "jacobians"):
        assert_close(model.mass_matrix(q, method=method), crba, METHOD_TOLERANCE, f"{name} M by {method}")
    assert_close(model.generalized_gravity(q, method="jacobians"), model.generalized_gravity(q), METHOD_TOLERANCE, f"{name} g")


def test_christoffel_symbols_and_craigs_split():
    """Γ against finite differences of M; C(q) [q̇²] + B(q) [q̇ q̇] = C(q, q̇) q̇ (Panda: revolute
    joints only, so q̇ are coordinate rates)."""
    model = robodyn.load("ur5")
    n, q = model.nv, model.random_configuration(seed=6)
    gamma = model.christoffel(q)
    assert gamma.shape == (n, n, n)
    steps = np.eye(n) * FD_STEP
    dm = np.stack([(model.mass_matrix(q + s) - model.mass_matrix(q - s)) / (2 * FD_STEP) for s in steps], axis=2)
    # Γ_ijk = ½ (∂_k M_ij + ∂_j M_ik − ∂_i M_jk), with dm[i, j, k] = ∂M_ij/∂q_k
    expected = 0.5 * (dm + dm.transpose(0, 2, 1) - dm.transpose(2, 0, 1))
    assert_close(gamma, expected, FD_TOLERANCE, "Γ")
    v = np.random.default_rng(6).uniform(-1, 1, n)
    pairs = np.array([v[j] * v[k] for j, k in itertools.combinations(range(n), 2)])
    craig = model.centrifugal_matrix(q) @ v**2 + model.coriolis_pairs_matrix(q) @ pairs
    assert model.coriolis_pairs_matrix(q).shape == (n, n * (n - 1) // 2)
    assert_close(craig, model.coriolis_matrix(q, v) @ v, IDENTITY_TOLERANCE, "C(q) q̇² + B(q) q̇q̇")


def test_two_link_arm_closed_forms():
    """The TU Berlin notes' 2-link arm: C(q) = [[0, −m₂l₁l₂s₂], [m₂l₁l₂s₂, 0]], B(q) = [−2m₂l₁l₂s₂, 0]ᵀ;
    C(q, q̇) = [[h q̇₂, h(q̇₁ + q̇₂)], [−h q̇₁, 0]] with h = −m₂l₁l₂s₂ (the TUM notes)."""
    model = robodyn.load("planar2")
    m2, l1, l2 = 1.0, 1.0, 0.5
    q, v = np.array([0.4, 1.1]), np.array([0.7, -1.3])
    h = -m2 * l1 * l2 * np.sin(q[1])
    assert_close(model.centrifugal_matrix(q), [[0, h], [-h, 0]], IDENTITY_TOLERANCE, "C(q)")
    assert_close(model.coriolis_pairs_matrix(q), [[2 * h], [0]], IDENTITY_TOLERANCE, "B(q)")
    assert_close(model.coriolis_matrix(q, v), [[h * v[1], h * (v[0] + v[1])], [-h * v[0], 0]], IDENTITY_TOLERANCE, "C(q, q̇)")


def test_batches_and_bad_methods():
    model = robodyn.load("ur5")
    q = model.random_configuration(4, seed=1)
    v = np.ones((4, model.nv))
    assert model.coriolis_matrix(q, v).shape == (4, 6, 6)
    assert model.christoffel(q).shape == (4, 6, 6, 6)
    np.testing.assert_array_equal(model.mass_matrix(q, method="jacobians")[2], model.mass_matrix(q[2], method="jacobians"))
    with pytest.raises(ValueError, match="argument 'method': expected crba, rnea or jacobians, got 'lagrange'"):
        model.mass_matrix(q, method="lagrange")
    with pytest.raises(ValueError, match="argument 'method': expected rnea or jacobians, got 'crba'"):
        model.generalized_gravity(q, method="crba")
    with pytest.raises(ValueError, match="argument 'method': expected a string, got 3"):
        model.mass_matrix(q, method=3)
    with pytest.raises(ValueError, match="argument 'v'"):
        model.coriolis_matrix(q[0], [0.0] * 5)
