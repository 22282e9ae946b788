"""A free-floating rigid body, as the UR5 dynamics notes ("Free Floating Body (free joint)") writes its motion.

Translation, in world axes: m v̇ = m g, ṗ = v. Rotation, in body axes (Euler's equations):

    I_b ω̇_b + ω_b × (I_b ω_b) = M_b      so   ω̇_b = I_b⁻¹ [M_b − ω_b × (I_b ω_b)]

with the orientation carried either by a unit quaternion, q̇ = ½ q ⊗ (ω_b, 0), or by 1-2-3 Euler
angles (R = R_x(φ) R_y(θ) R_z(ψ)), whose rates

    [φ̇, θ̇, ψ̇]ᵀ = (1 / cos θ) [[cos ψ, −sin ψ, 0],
                              [cos θ sin ψ, cos θ cos ψ, 0],
                              [−sin θ cos ψ, sin θ sin ψ, cos θ]] ω_b

are singular at θ = ±90° (gimbal lock): there :func:`euler123_rates` raises ``GimbalLockError``.
The world-frame inertia is I = R I_b Rᵀ (the UR5 dynamics notes, "Relation between I and I_b").

Quaternions are ``[qx, qy, qz, qw]``, robodyn's order. :func:`simulate` integrates these equations
with RK4; the same body as a robodyn model (a free joint, ABA) gives the same ω̇_b (tested).
"""

from __future__ import annotations

import numpy as np

from robodyn._arguments import array, positive, real

__all__ = [
    "GimbalLockError",
    "angular_acceleration",
    "quaternion_rate",
    "euler123_rates",
    "euler123_rotation",
    "quaternion_rotation",
    "simulate",
    "precession_rate",
]

#: |cos θ| below this is gimbal lock for the 1-2-3 Euler-angle rates.
GIMBAL_LOCK_TOLERANCE = 1e-6


class GimbalLockError(ValueError):
    """The 1-2-3 Euler-angle rates are singular: θ = ±90°."""


def _vector(name, value, size=3, batch=False) -> np.ndarray:
    """`size` finite numbers; with ``batch``, also a stack of them, shape (N, size)."""
    return array(name, value, (size,), (None, size)) if batch else array(name, value, (size,))


def angular_acceleration(inertia_body, omega_body, moment_body=(0.0, 0.0, 0.0)) -> np.ndarray:
    """Euler's equations: ω̇_b = I_b⁻¹ [M_b − ω_b × (I_b ω_b)]. ``omega_body`` and
    ``moment_body`` may be stacks (N, 3)."""
    inertia_body = array("inertia_body", inertia_body, (3, 3))
    omega = _vector("omega_body", omega_body, batch=True)
    moment = _vector("moment_body", moment_body, batch=True)
    rhs = moment - np.cross(omega, omega @ inertia_body.T)
    return np.linalg.solve(inertia_body, rhs.T).T


def quaternion_rate(quaternion, omega_body) -> np.ndarray:
    """q̇ = ½ q ⊗ (ω_b, 0) for q = [qx, qy, qz, qw]; both may be stacks (N, 4) and (N, 3)."""
    quaternion = _vector("quaternion", quaternion, 4, batch=True)
    omega = _vector("omega_body", omega_body, batch=True)
    vector, w = quaternion[..., :3], quaternion[..., 3:]
    scalar = -np.sum(vector * omega, axis=-1, keepdims=True)
    return 0.5 * np.concatenate([w * omega + np.cross(vector, omega), scalar], axis=-1)


def quaternion_rotation(quaternion) -> np.ndarray:
    """The rotation matrix of a unit quaternion [qx, qy, qz, qw]."""
    x, y, z, w = _vector("quaternion", quaternion, 4) / np.linalg.norm(quaternion)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def euler123_rotation(angles) -> np.ndarray:
    """R = R_x(φ) R_y(θ) R_z(ψ) for angles = (φ, θ, ψ)."""
    phi, theta, psi = _vector("angles", angles)
    c, s = np.cos, np.sin
    rx = np.array([[1, 0, 0], [0, c(phi), -s(phi)], [0, s(phi), c(phi)]])
    ry = np.array([[c(theta), 0, s(theta)], [0, 1, 0], [-s(theta), 0, c(theta)]])
    rz = np.array([[c(psi), -s(psi), 0], [s(psi), c(psi), 0], [0, 0, 1]])
    return rx @ ry @ rz


def euler123_rates(angles, omega_body) -> np.ndarray:
    """(φ̇, θ̇, ψ̇) from ω_b (see the module's docstring); GimbalLockError where cos θ ≈ 0."""
    phi, theta, psi = _vector("angles", angles)
    omega = _vector("omega_body", omega_body)
    cos_theta = np.cos(theta)
    if abs(cos_theta) < GIMBAL_LOCK_TOLERANCE:
        raise GimbalLockError(f"1-2-3 Euler angles at gimbal lock: θ = {np.degrees(theta):.6f}°, cos θ = {cos_theta:.3e}")
    sin_theta, cos_psi, sin_psi = np.sin(theta), np.cos(psi), np.sin(psi)
    rates = np.array(
        [
            [cos_psi, -sin_psi, 0.0],
            [cos_theta * sin_psi, cos_theta * cos_psi, 0.0],
            [-sin_theta * cos_psi, sin_theta * sin_psi, cos_theta],
        ]
    )
    return rates @ omega / cos_theta


def precession_rate(inertia_transverse: float, inertia_axial: float, omega_axial: float) -> float:
    """A symmetric body (I₁ = I₂ = I_t, I₃ = I_a) spinning at ω₃: its transverse angular velocity
    turns about the body's symmetry axis at Ω = (I_a − I_t) / I_t · ω₃ (body frame)."""
    transverse, axial = positive("inertia_transverse", inertia_transverse), positive("inertia_axial", inertia_axial)
    return (axial - transverse) / transverse * real("omega_axial", omega_axial)


def simulate(inertia_body, omega_body, t_end: float, dt: float, orientation="quaternion", initial=None, moment_body=(0.0, 0.0, 0.0)) -> dict:
    """Torque-free (or constant body-moment) rotation by RK4 from ω_b(0) = ``omega_body``.

    ``orientation``: "quaternion" (``initial`` a quaternion, default identity) or "euler123"
    (``initial`` the angles, default zeros; GimbalLockError if the motion reaches θ = ±90°).
    Returns a dict with ``t``, ``omega_body`` (N×3), ``orientation`` (N×4 or N×3), ``rotation``
    (N×3×3), ``angular_momentum`` (world axes, R I_b ω_b) and ``kinetic_energy`` (½ ω_bᵀ I_b ω_b).
    """
    inertia_body = array("inertia_body", inertia_body, (3, 3))
    t_end, dt = positive("t_end", t_end), positive("dt", dt)
    if orientation == "quaternion":
        state_orientation = _vector("initial", [0.0, 0.0, 0.0, 1.0] if initial is None else initial, 4)
        rate, rotation = quaternion_rate, quaternion_rotation
    elif orientation == "euler123":
        state_orientation = _vector("initial", [0.0, 0.0, 0.0] if initial is None else initial)
        rate, rotation = euler123_rates, euler123_rotation
    else:
        raise ValueError(f"argument 'orientation': expected 'quaternion' or 'euler123', got {orientation!r}")

    def derivative(state):
        omega, attitude = state[:3], state[3:]
        return np.concatenate([angular_acceleration(inertia_body, omega, moment_body), rate(attitude, omega)])

    steps = int(round(t_end / dt))
    state = np.concatenate([_vector("omega_body", omega_body), state_orientation])
    states = [state]
    for _ in range(steps):
        k1 = derivative(state)
        k2 = derivative(state + dt / 2 * k1)
        k3 = derivative(state + dt / 2 * k2)
        k4 = derivative(state + dt * k3)
        previous, state = state, state + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        # a step may jump over θ = ±90°: cos θ changing sign is gimbal lock too
        if orientation == "euler123" and np.cos(previous[4]) * np.cos(state[4]) <= 0.0:
            raise GimbalLockError(f"1-2-3 Euler angles pass gimbal lock (θ = ±90°) at t = {len(states) * dt:.6g} s")
        states.append(state)
    states = np.array(states)
    omegas, attitudes = states[:, :3], states[:, 3:]
    rotations = np.array([rotation(a) for a in attitudes])
    momentum = np.einsum("nij,jk,nk->ni", rotations, inertia_body, omegas)
    energy = 0.5 * np.einsum("ni,ij,nj->n", omegas, inertia_body, omegas)
    return {
        "t": np.arange(steps + 1) * dt,
        "omega_body": omegas,
        "orientation": attitudes,
        "rotation": rotations,
        "angular_momentum": momentum,
        "kinetic_energy": energy,
    }
