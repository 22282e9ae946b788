"""Derivatives: the Jacobians of integrate and difference on the joints' Lie groups, against
Pinocchio's `dIntegrate` and `dDifference` on example-robot-data robots (free joints included) and
against central finite differences, batched like every call."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from conftest import CROSS_CHECK_TOLERANCE, assert_close

import robodyn

#: Central differences with step FD_STEP: truncation h² and round-off ε/h.
FD_STEP = 1e-6
FD_TOLERANCE = 1e-7


def test_lie_group_jacobians_agree_with_pinocchio(pinocchio_robot):
    name, model, pin_model, mapping = pinocchio_robot
    rng = np.random.default_rng(4)
    for seed in range(3):
        q = model.random_configuration(seed=seed)
        v = rng.uniform(-1.5, 1.5, model.nv)
        q1 = model.integrate(q, v)
        pq, pv, pq1 = mapping.q_to_pinocchio(q), mapping.v_to_pinocchio(v), mapping.q_to_pinocchio(q1)
        ours = model.integrate_jacobians(q, v)
        for key, argument in [("dq", pin.ArgumentPosition.ARG0), ("dv", pin.ArgumentPosition.ARG1)]:
            theirs = mapping.matrix_from_pinocchio(pin.dIntegrate(pin_model, pq, pv, argument))
            assert_close(ours[key], theirs, CROSS_CHECK_TOLERANCE, f"{name} integrate {key}")
        ours = model.difference_jacobians(q, q1)
        for key, argument in [("dq0", pin.ArgumentPosition.ARG0), ("dq1", pin.ArgumentPosition.ARG1)]:
            theirs = mapping.matrix_from_pinocchio(pin.dDifference(pin_model, pq, pq1, argument))
            assert_close(ours[key], theirs, CROSS_CHECK_TOLERANCE, f"{name} difference {key}")


def test_integrate_jacobians_are_finite_differences_and_batched():
    model = robodyn.load("ur5", floating_base=True)
    rng = np.random.default_rng(2)
    q = np.array([model.random_configuration(seed=s) for s in range(3)])
    v = rng.uniform(-1, 1, (3, model.nv))
    batch = model.integrate_jacobians(q, v)
    assert batch["dq"].shape == batch["dv"].shape == (3, model.nv, model.nv)
    eye = np.eye(model.nv)
    for k in range(3):
        single = model.integrate_jacobians(q[k], v[k])
        np.testing.assert_array_equal(batch["dv"][k], single["dv"])
        q1 = model.integrate(q[k], v[k])
        # ∂(q ⊕ v)/∂v column j: (q ⊕ (v + h e_j)) ⊖ q1, centrally
        fd = np.column_stack([
            (model.difference(q1, model.integrate(q[k], v[k] + FD_STEP * e)) - model.difference(q1, model.integrate(q[k], v[k] - FD_STEP * e))) / (2 * FD_STEP)
            for e in eye
        ])
        assert_close(single["dv"], fd, FD_TOLERANCE, "dv")
    pair = model.difference_jacobians(q[0], model.integrate(q[0], v[0]))
    # ⊖ undoes ⊕: ∂(q1 ⊖ q0)/∂q1 is the inverse of ∂(q0 ⊕ v)/∂v
    assert_close(pair["dq1"] @ model.integrate_jacobians(q[0], v[0])["dv"], eye, 1e-12, "J_r⁻¹ J_r")
