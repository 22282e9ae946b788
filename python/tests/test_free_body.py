"""The free-floating body of the UR5 dynamics notes: Euler's equations, quaternion and 1-2-3 Euler-angle
kinematics, conservation, precession, the Dzhanibekov effect, and agreement with the engine."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import IDENTITY_TOLERANCE, assert_close

import robodyn
from robodyn import free_body, inertia

#: RK4 at the steps used here keeps invariants to this (relative).
INTEGRATION_TOLERANCE = 1e-9

ASYMMETRIC = np.diag([1.0, 2.0, 3.0])


def test_engine_gives_eulers_angular_acceleration():
    """A body on a free joint (ABA, no gravity) has the ω̇_b of Euler's equations."""
    rotation = free_body.euler123_rotation([0.3, -0.5, 1.1])
    tensor = inertia.rotate(np.diag([0.02, 0.05, 0.06]), rotation)
    urdf = f"""<robot name="body"><link name="b"><inertial><mass value="2"/>
      <inertia ixx="{tensor[0, 0]}" iyy="{tensor[1, 1]}" izz="{tensor[2, 2]}" ixy="{tensor[0, 1]}" ixz="{tensor[0, 2]}" iyz="{tensor[1, 2]}"/>
      </inertial></link></robot>"""
    model = robodyn.load_urdf_string(urdf, floating_base=True)
    model.gravity = [0.0, 0.0, 0.0]
    omega = np.array([0.4, -1.2, 2.0])
    moment = np.array([0.01, 0.0, -0.02])
    qdd = model.forward_dynamics(model.random_configuration(seed=1), np.concatenate([[0.1, 0.2, 0.3], omega]), np.concatenate([[0, 0, 0], moment]))
    assert_close(qdd[3:], free_body.angular_acceleration(tensor, omega, moment), IDENTITY_TOLERANCE, "ω̇_b")


def test_euler_rates_invert_the_angular_velocity_map():
    """ω_b = E(θ, ψ) [φ̇, θ̇, ψ̇] with E = [[cψcθ, sψ, 0], [−sψcθ, cψ, 0], [sθ, 0, 1]]."""
    phi, theta, psi = 0.2, 0.7, -1.3
    rates = np.array([0.5, -0.3, 0.9])
    c, s = np.cos, np.sin
    e = np.array([[c(psi) * c(theta), s(psi), 0], [-s(psi) * c(theta), c(psi), 0], [s(theta), 0, 1]])
    assert_close(free_body.euler123_rates([phi, theta, psi], e @ rates), rates, IDENTITY_TOLERANCE, "rates")
    with pytest.raises(free_body.GimbalLockError, match="gimbal lock"):
        free_body.euler123_rates([0.1, np.pi / 2, 0.0], [1.0, 0.0, 0.0])


def test_torque_free_motion_conserves_momentum_and_energy_both_ways():
    omega = np.array([0.5, 1.0, -0.3])
    by_quaternion = free_body.simulate(ASYMMETRIC, omega, t_end=2.0, dt=1e-3)
    by_angles = free_body.simulate(ASYMMETRIC, omega, t_end=2.0, dt=1e-3, orientation="euler123")
    for result in (by_quaternion, by_angles):
        momentum, energy = result["angular_momentum"], result["kinetic_energy"]
        assert_close(momentum, np.broadcast_to(momentum[0], momentum.shape), INTEGRATION_TOLERANCE, "L world")
        assert_close(energy, np.full_like(energy, energy[0]), INTEGRATION_TOLERANCE, "T")
    # the two orientation descriptions describe the same motion
    assert_close(by_quaternion["rotation"], by_angles["rotation"], 1e-8, "R")


def test_symmetric_body_precesses_at_the_analytic_rate():
    """I₁ = I₂ = 1, I₃ = 2: ω₁ + iω₂ turns at Ω = (I₃ − I₁)/I₁ ω₃."""
    omega = np.array([0.3, 0.0, 2.0])
    result = free_body.simulate(np.diag([1.0, 1.0, 2.0]), omega, t_end=3.0, dt=1e-3)
    rate = free_body.precession_rate(1.0, 2.0, 2.0)
    expected = 0.3 * np.exp(1j * rate * result["t"])
    transverse = result["omega_body"][:, 0] + 1j * result["omega_body"][:, 1]
    assert np.abs(transverse - expected).max() < 1e-9
    assert np.allclose(result["omega_body"][:, 2], 2.0, atol=1e-12)


def test_intermediate_axis_is_unstable():
    """Dzhanibekov: a spin about the intermediate axis flips; about the largest and smallest it stays."""
    perturbation = 1e-3
    intermediate = free_body.simulate(ASYMMETRIC, [perturbation, 5.0, perturbation], t_end=10.0, dt=1e-2)
    assert intermediate["omega_body"][:, 1].min() < -4.9
    for axis in (0, 2):
        omega = np.full(3, perturbation)
        omega[axis] = 5.0
        stable = free_body.simulate(ASYMMETRIC, omega, t_end=10.0, dt=1e-2)
        assert stable["omega_body"][:, axis].min() > 4.9


def test_euler_angles_report_gimbal_lock_during_a_simulation():
    # spinning about body y from θ = 0 drives θ through 90°
    with pytest.raises(free_body.GimbalLockError, match="gimbal lock.*at t = 1.57"):
        free_body.simulate(np.eye(3), [0.0, 1.0, 0.0], t_end=3.0, dt=1e-3, orientation="euler123")
    with pytest.raises(ValueError, match="argument 'orientation'"):
        free_body.simulate(np.eye(3), [0.0, 1.0, 0.0], t_end=1.0, dt=1e-3, orientation="rpy")


def test_rates_take_stacks_of_states():
    omegas = np.array([[0.4, -1.2, 2.0], [1.0, 0.0, 0.5]])
    batch = free_body.angular_acceleration(ASYMMETRIC, omegas)
    assert_close(batch[1], free_body.angular_acceleration(ASYMMETRIC, omegas[1]), IDENTITY_TOLERANCE, "ω̇ batch")
    quaternions = np.array([[0.0, 0.0, 0.0, 1.0], [0.1, 0.2, 0.3, np.sqrt(0.86)]])
    rates = free_body.quaternion_rate(quaternions, omegas)
    assert_close(rates[1], free_body.quaternion_rate(quaternions[1], omegas[1]), IDENTITY_TOLERANCE, "q̇ batch")
