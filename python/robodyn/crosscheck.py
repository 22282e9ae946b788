"""Compare a robodyn model with MuJoCo's model of the same robot, quantity by quantity.

``mujoco_discrepancies(model, mj_model)`` evaluates both at random states and returns, for each
quantity, the largest error relative to the quantity's size (``max|robodyn - mujoco| /
max(1, max|mujoco|)``), after converting MuJoCo's conventions with
:class:`robodyn.convert.MujocoLayout`. The quantities:

- ``"M"``: the joint-space inertia matrix (``mj_fullM``, armature included);
- ``"bias"``: C(q, v) v + g(q) (from ``qfrc_bias``);
- ``"forward_dynamics"``: q̈ for random τ (``qacc`` with ``qfrc_applied = τ``);
- ``"inverse_dynamics"``: τ for random q̈ (``mj_rne``, plus the armature times ``qacc`` it leaves out);
- ``"body_pose"``, ``"site_pose"``: every named body's and site's position and rotation (an unnamed one
  has no name to find it by in robodyn);
- ``"jacobian"``: every body's world-aligned Jacobian (``mj_jacBody``);
- ``"jacobian_dot_v"``: every body's J̇v, the classical acceleration at q̈ = 0 (``mj_jacDot``).

MuJoCo is made a rigid-body model first: damping, friction loss, springs, gravity compensation,
fluid forces, constraints and actuators are switched off on the ``mj_model`` passed in (its armature stays: robodyn models it too).
``mujoco`` is imported only when this is called.
"""

from __future__ import annotations

import numpy as np

from .convert import MujocoLayout

__all__ = ["mujoco_discrepancies", "rigid_body_only"]


def rigid_body_only(mj_model):
    """Switches off what robodyn's dynamics calls leave out: joint damping, friction loss and
    springs, tendon springs and dampers, gravity compensation (``gravcomp``), the medium's forces
    (density, viscosity, wind), constraints (limits, contacts, equalities) and actuators. Returns
    ``mj_model``."""
    import mujoco

    mj_model.opt.density = 0.0
    mj_model.opt.viscosity = 0.0
    mj_model.opt.wind[:] = 0.0
    mj_model.body_gravcomp[:] = 0.0
    mj_model.tendon_stiffness[:] = 0.0
    mj_model.tendon_damping[:] = 0.0
    mj_model.dof_damping[:] = 0.0
    mj_model.dof_frictionloss[:] = 0.0
    mj_model.jnt_stiffness[:] = 0.0
    mj_model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT | mujoco.mjtDisableBit.mjDSBL_ACTUATION
    return mj_model


def _relative_error(actual, expected) -> float:
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    if actual.shape != expected.shape:
        return float("inf")
    scale = max(1.0, float(np.max(np.abs(expected)))) if expected.size else 1.0
    return float(np.max(np.abs(actual - expected))) / scale if expected.size else 0.0


def mujoco_discrepancies(model, mj_model, seed: int = 0, states: int = 3) -> dict[str, float]:
    """The largest relative error of each quantity (see the module's docstring) over ``states``
    random states drawn with ``seed``."""
    import mujoco

    rigid_body_only(mj_model)
    layout = MujocoLayout(model, mj_model)
    data = mujoco.MjData(mj_model)
    errors: dict[str, float] = {}

    def record(name, actual, expected):
        errors[name] = max(errors.get(name, 0.0), _relative_error(actual, expected))

    rng = np.random.default_rng(seed)
    nv = mj_model.nv
    jacp, jacr = np.zeros((3, nv)), np.zeros((3, nv))
    jacp_dot, jacr_dot = np.zeros((3, nv)), np.zeros((3, nv))
    for k in range(states):
        q = model.random_configuration(seed=seed + k)
        v, a, tau = (rng.uniform(-1, 1, model.nv) for _ in range(3))
        v_mj = layout.v_to_mujoco(q, v)
        data.qpos[:], data.qvel[:] = layout.q_to_mujoco(q), v_mj
        data.qfrc_applied[:] = layout.force_to_mujoco(q, tau)
        mujoco.mj_forward(mj_model, data)
        # dynamics
        mass = np.zeros((nv, nv))
        mujoco.mj_fullM(mj_model, data, mass)
        record("M", model.mass_matrix(q), layout.matrix_from_mujoco(q, mass))
        record("bias", model.bias_forces(q, v), layout.bias_from_mujoco(q, v, data.qfrc_bias, mass))
        record("forward_dynamics", model.forward_dynamics(q, v, tau), layout.a_from_mujoco(q, v, data.qacc))
        # frames: the point's acceleration at robodyn q̈ = 0 is J_mj a_mj + J̇_mj v_mj
        a_mj = layout.a_to_mujoco(q, v, np.zeros(model.nv))
        # bodies and sites by name (an unnamed one has no name to find it by in robodyn)
        for body in range(1, mj_model.nbody):
            name = mj_model.body(body).name
            if not name:
                continue
            pose = model.frame_pose(q, name)
            record("body_pose", pose[:3, 3], data.xpos[body])
            record("body_pose", pose[:3, :3], data.xmat[body].reshape(3, 3))
            mujoco.mj_jacBody(mj_model, data, jacp, jacr, body)
            jacobian = np.vstack([jacp, jacr])
            record("jacobian", model.jacobian(q, name), layout.jacobian_from_mujoco(q, jacobian))
            mujoco.mj_jacDot(mj_model, data, jacp_dot, jacr_dot, data.xpos[body], body)
            expected = jacobian @ a_mj + np.vstack([jacp_dot, jacr_dot]) @ v_mj
            record("jacobian_dot_v", model.jacobian_time_variation(q, v, name) @ v, expected)
        for site in range(mj_model.nsite):
            if not mj_model.site(site).name:
                continue
            pose = model.frame_pose(q, mj_model.site(site).name)
            record("site_pose", pose[:3, 3], data.site_xpos[site])
            record("site_pose", pose[:3, :3], data.site_xmat[site].reshape(3, 3))
        # inverse dynamics last: it overwrites qacc; mj_rne leaves out the rotors' armature · qacc
        result = np.zeros(nv)
        data.qacc[:] = layout.a_to_mujoco(q, v, a)
        mujoco.mj_rne(mj_model, data, 1, result)
        result += mj_model.dof_armature * data.qacc
        record("inverse_dynamics", model.inverse_dynamics(q, v, a), layout.force_from_mujoco(q, result))
    return errors
