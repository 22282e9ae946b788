"""Derivatives: of inverse and forward dynamics, and the Jacobians of integrate and difference on
the joints' Lie groups, against Pinocchio (`computeRNEADerivatives`, `computeABADerivatives`,
`dIntegrate`, `dDifference`) on example-robot-data robots (free joints included) and against
central finite differences on the Lie group, batched like every call."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from conftest import CROSS_CHECK_TOLERANCE, REPOSITORY, assert_close, pinocchio_forces

import robodyn

#: Central differences with step FD_STEP: truncation h² and round-off ε/h.
FD_STEP = 1e-6
FD_TOLERANCE = 1e-7
#: Central differences of τ or q̈ (magnitudes up to ~1e3 on Talos): round-off ε |f| / h dominates.
DYNAMICS_FD_TOLERANCE = 1e-6


def test_dynamics_derivatives_agree_with_pinocchio(pinocchio_robot):
    name, model, pin_model, mapping = pinocchio_robot
    data = pin_model.createData()
    rng = np.random.default_rng(6)
    for seed in range(2):
        q = model.random_configuration(seed=seed)
        v, a = rng.uniform(-1, 1, model.nv), rng.uniform(-1, 1, model.nv)
        f_ext = rng.uniform(-5, 5, (len(model.body_names), 6))
        pq, pv, pa = mapping.q_to_pinocchio(q), mapping.v_to_pinocchio(v), mapping.v_to_pinocchio(a)
        theirs = pin.computeRNEADerivatives(pin_model, data, pq, pv, pa, pinocchio_forces(model, pin_model, f_ext))
        ours = model.inverse_dynamics_derivatives(q, v, a, f_ext=f_ext)
        for key, expected in zip(["dtau_dq", "dtau_dv", "dtau_da"], theirs):
            expected = np.triu(expected) + np.triu(expected, 1).T if key == "dtau_da" else expected
            assert_close(ours[key], mapping.matrix_from_pinocchio(expected), CROSS_CHECK_TOLERANCE, f"{name} {key}")

        tau = model.inverse_dynamics(q, v, a)
        theirs = pin.computeABADerivatives(pin_model, data, pq, pv, mapping.v_to_pinocchio(tau))
        ours = model.forward_dynamics_derivatives(q, v, tau)
        for key, expected in zip(["dqdd_dq", "dqdd_dv", "dqdd_dtau"], theirs):
            expected = np.triu(expected) + np.triu(expected, 1).T if key == "dqdd_dtau" else expected
            assert_close(ours[key], mapping.matrix_from_pinocchio(expected), CROSS_CHECK_TOLERANCE, f"{name} {key}")


def tangent_differences(model, q, f):
    """Columns (f(q ⊕ h e_k) − f(q ⊕ −h e_k)) / 2h: ∂f/∂q in the tangent space, centrally."""
    return np.column_stack([
        (f(model.integrate(q, FD_STEP * e)) - f(model.integrate(q, -FD_STEP * e))) / (2 * FD_STEP) for e in np.eye(model.nv)
    ])


def test_dynamics_derivatives_are_finite_differences_on_example_robot_data(pinocchio_robot):
    name, model, _, _ = pinocchio_robot
    rng = np.random.default_rng(10)
    q = model.random_configuration(seed=8)
    v, a = rng.uniform(-1, 1, model.nv), rng.uniform(-1, 1, model.nv)
    ours = model.inverse_dynamics_derivatives(q, v, a)
    assert_close(ours["dtau_dq"], tangent_differences(model, q, lambda q: model.inverse_dynamics(q, v, a)), DYNAMICS_FD_TOLERANCE, f"{name} dtau_dq")
    tau = model.inverse_dynamics(q, v, a)
    ours = model.forward_dynamics_derivatives(q, v, tau)
    assert_close(ours["dqdd_dq"], tangent_differences(model, q, lambda q: model.forward_dynamics(q, v, tau)), DYNAMICS_FD_TOLERANCE, f"{name} dqdd_dq")
    fd_v = np.column_stack([(model.forward_dynamics(q, v + FD_STEP * e, tau) - model.forward_dynamics(q, v - FD_STEP * e, tau)) / (2 * FD_STEP) for e in np.eye(model.nv)])
    assert_close(ours["dqdd_dv"], fd_v, DYNAMICS_FD_TOLERANCE, f"{name} dqdd_dv")


def test_dynamics_derivatives_are_finite_differences_on_the_bundled_models():
    rng = np.random.default_rng(9)
    free_armature = REPOSITORY / "testdata" / "mjcf" / "free_armature.xml"
    for name in ["pendulum", "planar2", "ur5", free_armature]:
        model = robodyn.load(name)
        q = model.random_configuration(seed=3)
        v, a = rng.uniform(-1, 1, model.nv), rng.uniform(-1, 1, model.nv)
        ours = model.inverse_dynamics_derivatives(q, v, a)
        fd = tangent_differences(model, q, lambda q: model.inverse_dynamics(q, v, a))
        assert_close(ours["dtau_dq"], fd, DYNAMICS_FD_TOLERANCE, f"{name} dtau_dq")
        assert_close(ours["dtau_da"], model.mass_matrix(q), 1e-12, f"{name} dtau_da = M")
        tau = model.inverse_dynamics(q, v, a)
        ours = model.forward_dynamics_derivatives(q, v, tau)
        fd = tangent_differences(model, q, lambda q: model.forward_dynamics(q, v, tau))
        assert_close(ours["dqdd_dq"], fd, DYNAMICS_FD_TOLERANCE, f"{name} dqdd_dq")
        assert_close(ours["dqdd_dtau"], model.inverse_mass_matrix(q), 1e-12, f"{name} dqdd_dtau = M⁻¹")


def test_dynamics_derivatives_are_batched():
    model = robodyn.load("ur5")
    rng = np.random.default_rng(3)
    q = np.array([model.random_configuration(seed=s) for s in range(4)])
    v, a = rng.uniform(-1, 1, (4, model.nv)), rng.uniform(-1, 1, (4, model.nv))
    batch = model.inverse_dynamics_derivatives(q, v, a)
    assert batch["dtau_dq"].shape == (4, model.nv, model.nv)
    single = model.inverse_dynamics_derivatives(q[1], v[1], a[1])
    for key in single:
        np.testing.assert_array_equal(batch[key][1], single[key])
    forward = model.forward_dynamics_derivatives(q, v, a)
    assert forward["dqdd_dv"].shape == (4, model.nv, model.nv)


def test_large_batches_equal_single_calls():
    """A result over 2 MiB (3000 UR5 states) takes the path that asks for huge pages."""
    model, n = robodyn.load("ur5"), 3000
    rng = np.random.default_rng(5)
    q = model.random_configuration(n=n, seed=6)
    v, a = rng.uniform(-1, 1, (n, model.nv)), rng.uniform(-1, 1, (n, model.nv))
    for call in (model.inverse_dynamics_derivatives, model.forward_dynamics_derivatives):
        batch = call(q, v, a)
        for k in (0, 1, 1499, n - 1):
            single = call(q[k], v[k], a[k])
            for key in single:
                np.testing.assert_array_equal(batch[key][k], single[key], f"{call.__name__} {key} [{k}]")


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


#: Central differences of one step (smooth in x and tau): round-off ε |x| / h dominates.
STEP_FD_TOLERANCE = 1e-6
#: With derivatives a stage's q̈ comes from M's factors (M⁻¹ (τ − b)), without them from ABA: the
#: two round differently, by up to cond(M) ε relative (3e4 ε on the UR5 below, whose wrist is light).
STEP_PATHS_TOLERANCE = 1e-11


def step_differences(model, q, v, tau, dt, integrator):
    """Columns of ∂x1/∂(q, v, tau) by central differences of `robodyn.step`, q on the Lie group."""
    nq, nv = model.nq, model.nv
    q1 = robodyn.step(model, q, v, tau, dt, integrator)[:nq]

    def moved(k, h):
        e = np.eye(nv)[k % nv] * h
        inputs = [model.integrate(q, e) if k < nv else q, v + e if nv <= k < 2 * nv else v, tau + e if k >= 2 * nv else tau]
        x = robodyn.step(model, *inputs, dt, integrator)
        return np.concatenate([model.difference(q1, x[:nq]), x[nq:]])

    return np.column_stack([(moved(k, FD_STEP) - moved(k, -FD_STEP)) / (2 * FD_STEP) for k in range(3 * nv)])


def test_step_jacobians_are_finite_differences_of_the_step():
    model = robodyn.load(REPOSITORY / "testdata" / "mjcf" / "free_armature.xml")
    model.damping = np.full(model.nv, 0.3)
    rng = np.random.default_rng(12)
    q = model.random_configuration(seed=5)
    v, tau = rng.uniform(-1, 1, model.nv), rng.uniform(-1, 1, model.nv)
    for integrator in ["euler", "semi_implicit_euler", "rk4"]:
        x1, a, b = robodyn.step(model, q, v, tau, 0.01, integrator, derivatives=True)
        assert_close(x1, robodyn.step(model, q, v, tau, 0.01, integrator), STEP_PATHS_TOLERANCE, f"{integrator} x1")
        fd = step_differences(model, q, v, tau, 0.01, integrator)
        assert_close(a, fd[:, : 2 * model.nv], STEP_FD_TOLERANCE, f"{integrator} A")
        assert_close(b, fd[:, 2 * model.nv :], STEP_FD_TOLERANCE, f"{integrator} B")


def test_step_is_one_step_of_simulate_and_is_batched():
    model = robodyn.load("ur5")
    q = model.random_configuration(2, seed=1)
    v = np.zeros((2, model.nv))
    tau = np.ones((2, model.nv))
    x1, a, b = robodyn.step(model, q, v, tau, 1e-3, derivatives=True)
    assert x1.shape == (2, model.nq + model.nv) and a.shape == (2, 12, 12) and b.shape == (2, 12, 6)
    run = robodyn.simulate(model, q[1], v[1], t_end=1e-3, dt=1e-3, controller=tau[1])
    assert_close(x1[1], np.concatenate([run.q[-1], run.v[-1]]), STEP_PATHS_TOLERANCE, "step = simulate")


def test_step_refuses_bad_arguments():
    model = robodyn.load("pendulum")
    for kwargs, words in [
        ({"integrator": "rk45"}, ["integrator", "rk45"]),
        ({"dt": -1.0}, ["dt", "-1"]),
        ({"limits": "hard"}, ["limits", "hard"]),
        ({"friction_velocity": 0.0}, ["friction_velocity"]),
    ]:
        arguments = {"dt": 0.01, **kwargs}
        try:
            robodyn.step(model, [0.1], [0.0], [0.0], **arguments)
        except ValueError as error:
            assert all(word in str(error) for word in words), str(error)
        else:
            raise AssertionError(f"{kwargs} accepted")


def skew(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def test_frame_and_center_of_mass_derivatives_agree_with_pinocchio(pinocchio_robot):
    """Pinocchio's frame accelerations are spatial; the classical one adds ω × v (local axes),
    whose derivatives follow from the velocity's. "world" (Pinocchio's LOCAL_WORLD_ALIGNED) is
    checked against finite differences instead: there Pinocchio's `getFrameVelocityDerivatives`
    (4.1) differs from central differences of its own `getFrameVelocity` (by 0.34 on the Panda's
    link 4; the kind of discrepancy stack-of-tasks/pinocchio#2702 reports for joints)."""
    name, model, pin_model, mapping = pinocchio_robot
    data = pin_model.createData()
    rng = np.random.default_rng(15)
    q = model.random_configuration(seed=4)
    v, a = rng.uniform(-1, 1, model.nv), rng.uniform(-1, 1, model.nv)
    pq, pv, pa = mapping.q_to_pinocchio(q), mapping.v_to_pinocchio(v), mapping.v_to_pinocchio(a)
    pin.computeForwardKinematicsDerivatives(pin_model, data, pq, pv, pa)
    pin.updateFramePlacements(pin_model, data)
    convert = mapping.jacobian_from_pinocchio
    for frame in model.frame_names[:: max(1, len(model.frame_names) // 6)]:
        frame_id = pin_model.getFrameId(frame)
        world = model.frame_acceleration_derivatives(q, v, a, frame, "world")
        for key, f in [("dv_dq", lambda q: model.frame_velocity(q, v, frame)), ("da_dq", lambda q: model.frame_acceleration(q, v, a, frame))]:
            assert_close(world[key], tangent_differences(model, q, f), DYNAMICS_FD_TOLERANCE, f"{name} {frame} world {key}")
        for reference, pin_reference in [("local", pin.LOCAL), ("spatial", pin.WORLD)]:
            velocity = model.frame_velocity_derivatives(q, v, frame, reference)
            theirs = pin.getFrameVelocityDerivatives(pin_model, data, frame_id, pin_reference)
            label = f"{name} {frame} {reference}"
            assert_close(velocity["dv_dq"], convert(theirs[0]), CROSS_CHECK_TOLERANCE, f"{label} dv_dq")
            assert_close(velocity["dv_dv"], convert(theirs[1]), CROSS_CHECK_TOLERANCE, f"{label} dv_dv")
            ours = model.frame_acceleration_derivatives(q, v, a, frame, reference)
            _, a_dq, a_dv, a_da = (convert(m) for m in pin.getFrameAccelerationDerivatives(pin_model, data, frame_id, pin_reference))
            if reference == "local":
                # + d(ω × v) = [ω×] dv − [v×] dω, from the velocity and its derivatives
                linear, angular = np.split(model.frame_velocity(q, v, frame, reference), 2)
                a_dq[:3] += skew(angular) @ velocity["dv_dq"][:3] - skew(linear) @ velocity["dv_dq"][3:]
                a_dv[:3] += skew(angular) @ velocity["dv_dv"][:3] - skew(linear) @ velocity["dv_dv"][3:]
            for key, expected in [("da_dq", a_dq), ("da_dv", a_dv), ("da_da", a_da)]:
                assert_close(ours[key], expected, CROSS_CHECK_TOLERANCE, f"{label} {key}")
    pin.centerOfMass(pin_model, data, pq, pv)
    theirs = mapping.jacobian_from_pinocchio(pin.getCenterOfMassVelocityDerivatives(pin_model, data))
    ours = model.center_of_mass_velocity_derivatives(q, v)
    assert_close(ours["dv_dq"], theirs, CROSS_CHECK_TOLERANCE, f"{name} dvcom_dq")
    assert_close(ours["dv_dv"], model.center_of_mass_jacobian(q), 1e-12, f"{name} dvcom_dv = J_com")
