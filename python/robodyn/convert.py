"""Convention converters between robodyn and Pinocchio or MuJoCo.

Mixing the three libraries' layouts is the classic source of wrong numbers; these maps do it in
one place. Joints are matched by name.

robodyn vs Pinocchio (:class:`PinocchioLayout`):
- a continuous joint is one angle θ in robodyn, ``(cos θ, sin θ)`` in Pinocchio (nq = 2, nv = 1);
- joint order may differ (Pinocchio sorts a link's children, robodyn keeps file order);
- free joints agree: ``q = [x, y, z, qx, qy, qz, qw]``, ``v = [v_body, ω_body]``; Jacobian rows
  are ``[linear; angular]`` in both.

robodyn vs MuJoCo (:class:`MujocoLayout`):
- quaternions are ``[qw, qx, qy, qz]`` (scalar first) in MuJoCo, ``[qx, qy, qz, qw]`` in robodyn;
- a free joint's linear velocity is in world axes in MuJoCo (``qvel = [R v_body, ω_body]``), in
  body axes in robodyn; so velocities, accelerations, generalized forces, M and Jacobians convert
  with the joint's rotation R: for ``v_mj = T v`` (``T = diag(R, 1)`` on free joints),
  ``τ_mj = T τ``, ``M_mj = T M Tᵀ``, ``J_mj = J Tᵀ`` and ``a_mj = T (a + w)`` with
  ``w = [ω × v_body; 0]``; the bias forces differ by more than a rotation, because the two
  accelerations differ by w: ``b = Tᵀ b_mj + M w`` (:meth:`MujocoLayout.bias_from_mujoco`);
- joints are matched by name (MuJoCo's ``model.joint(j).name``).

Every method takes one state (1-D) and returns a new array.
"""

from __future__ import annotations

import numpy as np

from robodyn._joints import JOINT_KINDS

__all__ = ["PinocchioLayout", "MujocoLayout"]


def _rotation(quaternion_xyzw: np.ndarray) -> np.ndarray:
    """Rotation matrix of a unit quaternion [qx, qy, qz, qw]."""
    x, y, z, w = quaternion_xyzw / np.linalg.norm(quaternion_xyzw)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


class PinocchioLayout:
    """Index maps between a robodyn model and the Pinocchio model of the same robot."""

    def __init__(self, model, pin_model):
        self.model, self.pin_model = model, pin_model
        self.nq, self.nv = pin_model.nq, pin_model.nv
        # v_index[k]: Pinocchio's index of robodyn's velocity coordinate k
        self.v_index = np.zeros(model.nv, dtype=int)
        self._joints = []
        for name, iq, iv in zip(model.joint_names, model.joint_idx_q, model.joint_idx_v):
            if not pin_model.existJointName(name):
                raise ValueError(f"argument 'pin_model': expected a joint named '{name}', found none")
            joint = pin_model.joints[pin_model.getJointId(name)]
            continuous = joint.nq == 2 and joint.nv == 1
            self._joints.append((iq, joint.idx_q, joint.nq, continuous))
            self.v_index[iv : iv + joint.nv] = np.arange(joint.idx_v, joint.idx_v + joint.nv)
        # joint_ids[k]: Pinocchio's joint id of robodyn's moving body k (the joint's child)
        self.joint_ids = np.array([pin_model.getJointId(name) for name in model.joint_names], dtype=int)

    def q_to_pinocchio(self, q) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        out = np.zeros(self.nq)
        for iq, pin_iq, pin_nq, continuous in self._joints:
            if continuous:
                out[pin_iq : pin_iq + 2] = [np.cos(q[iq]), np.sin(q[iq])]
            else:
                out[pin_iq : pin_iq + pin_nq] = q[iq : iq + pin_nq]
        return out

    def q_from_pinocchio(self, q) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        out = np.zeros(self.model.nq)
        for iq, pin_iq, pin_nq, continuous in self._joints:
            if continuous:
                out[iq] = np.arctan2(q[pin_iq + 1], q[pin_iq])
            else:
                out[iq : iq + pin_nq] = q[pin_iq : pin_iq + pin_nq]
        return out

    def v_to_pinocchio(self, v) -> np.ndarray:
        """Velocities, accelerations or generalized forces."""
        out = np.zeros(self.nv)
        out[self.v_index] = v
        return out

    def v_from_pinocchio(self, v) -> np.ndarray:
        return np.asarray(v, dtype=float)[self.v_index]

    def matrix_from_pinocchio(self, matrix) -> np.ndarray:
        """An nv x nv matrix (M, M⁻¹, C)."""
        return np.asarray(matrix, dtype=float)[np.ix_(self.v_index, self.v_index)]

    def matrix_to_pinocchio(self, matrix) -> np.ndarray:
        out = np.zeros((self.nv, self.nv))
        out[np.ix_(self.v_index, self.v_index)] = matrix
        return out

    def inertial_parameters_from_pinocchio(self) -> np.ndarray:
        """Pinocchio's `inertias[j].toDynamicParameters()` as robodyn's `inertial_parameters`
        (nbodies, 10): the same ten parameters in the same order, rows in robodyn's body order."""
        return np.array([self.pin_model.inertias[int(j)].toDynamicParameters() for j in self.joint_ids])

    def regressor_from_pinocchio(self, regressor) -> np.ndarray:
        """Pinocchio's joint-torque regressor (nv × 10 njoints) as robodyn's `torque_regressor`:
        rows in robodyn's v order, column blocks in its body order."""
        regressor = np.asarray(regressor, dtype=float)[self.v_index]
        columns = np.concatenate([np.arange(10 * (j - 1), 10 * j) for j in self.joint_ids])
        return regressor[:, columns]

    def jacobian_from_pinocchio(self, jacobian) -> np.ndarray:
        """A k x nv matrix (Jacobian); Pinocchio returns a one-column Jacobian as a vector."""
        jacobian = np.asarray(jacobian, dtype=float)
        return jacobian.reshape(len(jacobian), -1)[:, self.v_index]


class MujocoLayout:
    """Maps between a robodyn model and the MuJoCo model of the same robot (joints by name; an
    unnamed MuJoCo joint by the name robodyn gives it, ``<body>_joint<k>``, k its index in its
    body)."""

    def __init__(self, model, mj_model):
        self.model, self.mj_model = model, mj_model
        names = []
        for j in range(mj_model.njnt):
            body = int(mj_model.jnt_bodyid[j])
            index_in_body = j - int(mj_model.body_jntadr[body])
            names.append(mj_model.joint(j).name or f"{mj_model.body(body).name}_joint{index_in_body}")
        self.v_index = np.zeros(model.nv, dtype=int)
        # mujoco_joints[k]: MuJoCo's index of robodyn's joint k (the one that moves body_names[k])
        self.mujoco_joints: list[int] = []
        self._joints = []
        for name, kind, iq, iv in zip(model.joint_names, model.joint_types, model.joint_idx_q, model.joint_idx_v):
            if name not in names:
                raise ValueError(f"argument 'mj_model': expected a joint named '{name}', found none")
            j = names.index(name)
            self.mujoco_joints.append(j)
            mj_iq, mj_iv = int(mj_model.jnt_qposadr[j]), int(mj_model.jnt_dofadr[j])
            self._joints.append((kind, iq, iv, mj_iq))
            nv = JOINT_KINDS[kind].nv
            self.v_index[iv : iv + nv] = np.arange(mj_iv, mj_iv + nv)
        if mj_model.nv != model.nv:
            raise ValueError(f"argument 'mj_model': expected {model.nv} velocity coordinates as the robodyn model has, got {mj_model.nv}")

    def _transform(self, q) -> np.ndarray:
        """T with v_mujoco (in robodyn order) = T v: diag(R, 1) on free joints, 1 elsewhere."""
        t = np.eye(self.model.nv)
        for kind, iq, iv, _ in self._joints:
            if kind == "free":
                t[iv : iv + 3, iv : iv + 3] = _rotation(np.asarray(q[iq + 3 : iq + 7], dtype=float))
        return t

    def _to_mujoco_order(self, vector) -> np.ndarray:
        out = np.zeros(self.mj_model.nv)
        out[self.v_index] = vector
        return out

    def q_to_mujoco(self, q) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        out = np.zeros(self.mj_model.nq)
        for kind, iq, _, mj_iq in self._joints:
            if kind == "free":
                out[mj_iq : mj_iq + 3] = q[iq : iq + 3]
                out[mj_iq + 3 : mj_iq + 7] = np.roll(q[iq + 3 : iq + 7], 1)
            elif kind == "spherical":
                out[mj_iq : mj_iq + 4] = np.roll(q[iq : iq + 4], 1)
            else:
                out[mj_iq] = q[iq]
        return out

    def q_from_mujoco(self, q) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        out = np.zeros(self.model.nq)
        for kind, iq, _, mj_iq in self._joints:
            if kind == "free":
                out[iq : iq + 3] = q[mj_iq : mj_iq + 3]
                out[iq + 3 : iq + 7] = np.roll(q[mj_iq + 3 : mj_iq + 7], -1)
            elif kind == "spherical":
                out[iq : iq + 4] = np.roll(q[mj_iq : mj_iq + 4], -1)
            else:
                out[iq] = q[mj_iq]
        return out

    def _plastic_entries(self) -> list[tuple[int, int, int]]:
        """(robodyn's index, MuJoCo's, size) of each plastic spring's references: the joints with a
        yield (a ball's quaternion: size 4), then the tendons (their dead band: size 2), by name."""
        mj, entries, start = self.mj_model, [], 0
        for k, (kind, y) in enumerate(zip(self.model.joint_types, self.model.spring_yield)):
            if y > 0:
                size = 4 if kind == "spherical" else 1
                entries.append((start, int(mj.jnt_plasticadr[self.mujoco_joints[k]]), size))
                start += size
        for name, y in zip(self.model.tendon_names, self.model.tendon_spring_yield):
            if y > 0:
                entries.append((start, int(mj.tendon_plasticadr[mj.tendon(name).id]), 2))
                start += 2
        return entries

    def plastic_to_mujoco(self, plastic) -> np.ndarray:
        """The plastic springs' references (robodyn's ``plastic``) as MuJoCo's ``plastic``: a ball's
        quaternion scalar first."""
        plastic, out = np.asarray(plastic, dtype=float), np.zeros(self.mj_model.nplastic)
        for ours, theirs, size in self._plastic_entries():
            out[theirs : theirs + size] = np.roll(plastic[ours : ours + size], 1 if size == 4 else 0)
        return out

    def plastic_from_mujoco(self, plastic) -> np.ndarray:
        """MuJoCo's ``plastic`` in robodyn's layout: a ball's quaternion scalar last."""
        plastic, out = np.asarray(plastic, dtype=float), np.zeros(self.model.nplastic)
        for ours, theirs, size in self._plastic_entries():
            out[ours : ours + size] = np.roll(plastic[theirs : theirs + size], -1 if size == 4 else 0)
        return out

    def v_to_mujoco(self, q, v) -> np.ndarray:
        """Velocities: v_mj = T v."""
        return self._to_mujoco_order(self._transform(q) @ np.asarray(v, dtype=float))

    def v_from_mujoco(self, q, v) -> np.ndarray:
        return self._transform(q).T @ np.asarray(v, dtype=float)[self.v_index]

    def _velocity_product(self, v) -> np.ndarray:
        """w = [ω × v_body; 0] on free joints, 0 elsewhere: a_mj = T (a + w)."""
        v = np.asarray(v, dtype=float)
        w = np.zeros(self.model.nv)
        for kind, _, iv, _ in self._joints:
            if kind == "free":
                w[iv : iv + 3] = np.cross(v[iv + 3 : iv + 6], v[iv : iv + 3])
        return w

    def a_to_mujoco(self, q, v, a) -> np.ndarray:
        """Accelerations: a_mj = T (a + w) (the body-frame linear velocity turns with the body)."""
        return self._to_mujoco_order(self._transform(q) @ (np.asarray(a, dtype=float) + self._velocity_product(v)))

    def a_from_mujoco(self, q, v, a) -> np.ndarray:
        return self._transform(q).T @ np.asarray(a, dtype=float)[self.v_index] - self._velocity_product(v)

    def bias_from_mujoco(self, q, v, bias, mass_matrix) -> np.ndarray:
        """robodyn's C(q, v) v + g(q) from MuJoCo's qfrc_bias and its full M (``mj_fullM``):
        b = Tᵀ b_mj + M w."""
        return self.force_from_mujoco(q, bias) + self.matrix_from_mujoco(q, mass_matrix) @ self._velocity_product(v)

    def force_to_mujoco(self, q, tau) -> np.ndarray:
        """Generalized forces (τ, bias, gravity): τ_mj = T τ (power is invariant)."""
        return self.v_to_mujoco(q, tau)

    def force_from_mujoco(self, q, tau) -> np.ndarray:
        return self.v_from_mujoco(q, tau)

    def matrix_from_mujoco(self, q, matrix) -> np.ndarray:
        """M (nv x nv): M = Tᵀ M_mj T."""
        t = self._transform(q)
        return t.T @ np.asarray(matrix, dtype=float)[np.ix_(self.v_index, self.v_index)] @ t

    def jacobian_from_mujoco(self, q, jacobian) -> np.ndarray:
        """A k x nv Jacobian: J = J_mj T."""
        return np.asarray(jacobian, dtype=float)[:, self.v_index] @ self._transform(q)
