"""Cartesian / operational-space dynamics (the TUM notes "Cartesian state space equation"): both forms
of Λ, μ, p, the equation F = Λ ẍ + μ + p itself, J̄, and the behaviour at singularities."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import IDENTITY_TOLERANCE, assert_close

import robodyn

#: Λ, μ, p through a matrix inverse: looser than the algorithms' identities.
CARTESIAN_TOLERANCE = 1e-9

UR5_Q = np.array([0.3, -1.1, 1.5, -0.4, 1.2, 0.5])


@pytest.mark.parametrize(("name", "q", "frame", "task"), [("ur5", UR5_Q, "tool0", "full"), ("planar2", np.array([0.4, 1.1]), "tool", [0, 1])])
def test_square_jacobian_gives_the_notes_forms(name, q, frame, task):
    """M_x = J⁻ᵀ M J⁻¹, V_x = J⁻ᵀ (V − M J⁻¹ J̇ q̇), G_x = J⁻ᵀ G."""
    model = robodyn.load(name)
    v = np.linspace(-0.8, 0.9, model.nv)
    result = model.operational_space(q, v, frame, task=task)
    rows = robodyn.operational_space.task_rows(task)
    j = model.jacobian(q, frame)[rows]
    j_dot = model.jacobian_time_variation(q, v, frame)[rows]
    j_inv = np.linalg.inv(j)
    m, g = model.mass_matrix(q), model.generalized_gravity(q)
    velocity_terms = model.bias_forces(q, v) - g
    assert result["damping"] == 0.0
    assert_close(result["Lambda"], j_inv.T @ m @ j_inv, CARTESIAN_TOLERANCE, "M_x")
    assert_close(result["mu"], j_inv.T @ (velocity_terms - m @ j_inv @ j_dot @ v), CARTESIAN_TOLERANCE, "V_x")
    assert_close(result["p"], j_inv.T @ g, CARTESIAN_TOLERANCE, "G_x")


@pytest.mark.parametrize("task", ["position", "full"])
def test_redundant_arm_obeys_f_equals_lambda_xdd_plus_mu_plus_p(task, robots_dir):
    """Panda (7 joints): for τ = Jᵀ F, the resulting ẍ = J q̈ + J̇ q̇ satisfies F = Λ ẍ + μ + p, and
    J J̄ = 1."""
    model = robodyn.load(robots_dir / "panda_description/urdf/panda.urdf")
    rng = np.random.default_rng(2)
    q, v = model.random_configuration(seed=2), rng.uniform(-1, 1, model.nv)
    result = model.operational_space(q, v, "panda_link8", task=task)
    force = rng.uniform(-5, 5, len(result["mu"]))
    qdd = model.forward_dynamics(q, v, result["J"].T @ force)
    rows = robodyn.operational_space.task_rows(task)
    xdd = result["J"] @ qdd + model.jacobian_time_variation(q, v, "panda_link8")[rows] @ v
    assert_close(result["Lambda"] @ xdd + result["mu"] + result["p"], force, CARTESIAN_TOLERANCE, "F")
    assert_close(result["J"] @ result["J_bar"], np.eye(len(rows)), IDENTITY_TOLERANCE, "J J̄")


def test_singular_pose_is_damped_and_reported():
    """UR5 with its wrist straight (q5 = 0): joints 4 and 6 align and the full task is singular."""
    model = robodyn.load("ur5")
    q = UR5_Q.copy()
    q[4] = 0.0
    v = np.full(6, 0.3)
    result = model.operational_space(q, v, "tool0")
    assert result["damping"] > 0.0
    assert all(np.all(np.isfinite(result[key])) for key in ("Lambda", "mu", "p", "J_bar"))
    with pytest.raises(ValueError, match="singular.*damping"):
        model.operational_space(q, v, "tool0", damping=0.0)
    # a chosen damping is used as given
    assert model.operational_space(q, v, "tool0", damping=1e-3)["damping"] == 1e-3


def test_batches_and_bad_arguments():
    model = robodyn.load("ur5")
    q = np.stack([UR5_Q, UR5_Q + 0.1])
    v = np.ones((2, 6))
    batch = model.operational_space(q, v, "tool0", task="position")
    single = model.operational_space(q[1], v[1], "tool0", task="position")
    assert batch["Lambda"].shape == (2, 3, 3) and batch["J_bar"].shape == (2, 6, 3)
    assert_close(batch["Lambda"][1], single["Lambda"], IDENTITY_TOLERANCE)
    with pytest.raises(ValueError, match="argument 'task'"):
        model.operational_space(UR5_Q, v[0], "tool0", task="linear")
    with pytest.raises(ValueError, match="argument 'damping'"):
        model.operational_space(UR5_Q, v[0], "tool0", damping=-1.0)
