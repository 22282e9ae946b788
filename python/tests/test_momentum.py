"""Energy and momentum (issue 4, part 6): the Lagrangian, d(T + V)/dt = q̇ᵀτ, centroidal momentum
and its matrix against Pinocchio, the centre-of-mass velocity."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import CROSS_CHECK_TOLERANCE, IDENTITY_TOLERANCE, assert_close

import robodyn

#: A central difference in time with step TIME_STEP is good to about this (relative).
FD_TOLERANCE = 1e-6
TIME_STEP = 1e-6


def test_energy_rate_is_the_power_of_the_joint_forces(pinocchio_robot):
    """Along the motion q̈ = FD(q, q̇, τ): d(T + V)/dt = q̇ᵀ τ (no damping or friction applied)."""
    name, model, _, _ = pinocchio_robot
    rng = np.random.default_rng(1)
    q, v, tau = model.random_configuration(seed=1), rng.uniform(-1, 1, model.nv), rng.uniform(-5, 5, model.nv)
    qdd = model.forward_dynamics(q, v, tau)

    def energy(h):
        q_h, v_h = model.integrate(q, v, h), v + h * qdd
        return model.kinetic_energy(q_h, v_h) + model.potential_energy(q_h)

    rate = (energy(TIME_STEP) - energy(-TIME_STEP)) / (2 * TIME_STEP)
    assert_close(rate, v @ tau, FD_TOLERANCE, f"{name} dE/dt")
    assert_close(model.lagrangian(q, v), model.kinetic_energy(q, v) - model.potential_energy(q), IDENTITY_TOLERANCE, f"{name} L")


def test_centroidal_momentum_agrees_with_pinocchio(pinocchio_robot):
    name, model, pin_model, layout = pinocchio_robot
    data = pin_model.createData()
    rng = np.random.default_rng(2)
    for seed in range(3):
        q, v = model.random_configuration(seed=seed), rng.uniform(-1, 1, model.nv)
        pq, pv = layout.q_to_pinocchio(q), layout.v_to_pinocchio(v)
        matrix = pin.computeCentroidalMap(pin_model, data, pq)
        assert_close(model.centroidal_momentum_matrix(q), layout.jacobian_from_pinocchio(matrix), CROSS_CHECK_TOLERANCE, f"{name} A_G")
        momentum = pin.computeCentroidalMomentum(pin_model, data, pq, pv).vector
        assert_close(model.centroidal_momentum(q, v), momentum, CROSS_CHECK_TOLERANCE, f"{name} h_G")
        # linear momentum = m ċ
        mass = pin.computeTotalMass(pin_model)
        assert_close(model.center_of_mass_velocity(q, v) * mass, momentum[:3], CROSS_CHECK_TOLERANCE, f"{name} m ċ")
        assert_close(model.center_of_mass_velocity(q, v), model.center_of_mass_jacobian(q) @ v, IDENTITY_TOLERANCE, f"{name} ċ")


def test_momentum_of_a_free_body_is_conserved_without_gravity():
    """A lone tumbling body with no forces: A_G v stays constant along the motion."""
    urdf = """<robot name="brick"><link name="b"><inertial><origin xyz="0.1 0 0"/><mass value="2"/>
      <inertia ixx="0.02" iyy="0.05" izz="0.06" ixy="0.001" ixz="0" iyz="0"/></inertial></link></robot>"""
    model = robodyn.load_urdf_string(urdf, floating_base=True)
    model.gravity = [0.0, 0.0, 0.0]
    q, v = model.neutral(), np.array([0.3, -0.2, 0.1, 1.0, 2.0, -0.5])
    start = model.centroidal_momentum(q, v)
    dt = 1e-4
    for _ in range(200):
        # midpoint step: enough to see drift if the momentum were wrong
        a = model.forward_dynamics(q, v, np.zeros(6))
        q_mid, v_mid = model.integrate(q, v, dt / 2), v + dt / 2 * a
        a_mid = model.forward_dynamics(q_mid, v_mid, np.zeros(6))
        q, v = model.integrate(q, v_mid, dt), v + dt * a_mid
    assert_close(model.centroidal_momentum(q, v), start, 1e-6, "h_G conserved")
