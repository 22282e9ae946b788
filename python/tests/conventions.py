"""Maps states and results between robodyn's layout and Pinocchio's, for the cross-checks.

Pinocchio stores a continuous joint as (cos θ, sin θ) (nq = 2, nv = 1) where robodyn stores θ, and
it may order joints differently (it sorts a link's child joints; robodyn keeps file order), so
coordinates are matched by joint name. Free joints share the layout [x, y, z, qx, qy, qz, qw] /
[v_local, ω_local].
"""

from __future__ import annotations

import numpy as np


class PinocchioMap:
    """Index maps between a robodyn model and the Pinocchio model of the same robot."""

    def __init__(self, model, pin_model):
        self.model, self.pin_model = model, pin_model
        self.nq, self.nv = pin_model.nq, pin_model.nv
        # v: robodyn index -> Pinocchio index
        self.v_index = np.zeros(model.nv, dtype=int)
        self.joints = []
        for name, iq, iv in zip(model.joint_names, model.joint_idx_q, model.joint_idx_v):
            joint = pin_model.joints[pin_model.getJointId(name)]
            continuous = joint.nq == 2 and joint.nv == 1
            self.joints.append((iq, joint.idx_q, joint.nq, continuous))
            self.v_index[iv : iv + joint.nv] = np.arange(joint.idx_v, joint.idx_v + joint.nv)

    def q(self, q: np.ndarray) -> np.ndarray:
        """robodyn q -> Pinocchio q."""
        out = np.zeros(self.nq)
        for iq, pin_iq, pin_nq, continuous in self.joints:
            if continuous:
                out[pin_iq : pin_iq + 2] = [np.cos(q[iq]), np.sin(q[iq])]
            else:
                out[pin_iq : pin_iq + pin_nq] = q[iq : iq + pin_nq]
        return out

    def v(self, v: np.ndarray) -> np.ndarray:
        """robodyn v (or a, τ) -> Pinocchio order."""
        out = np.zeros(self.nv)
        out[self.v_index] = v
        return out

    def v_back(self, v: np.ndarray) -> np.ndarray:
        """Pinocchio v (or a, τ) -> robodyn order."""
        return np.asarray(v)[self.v_index]

    def matrix_back(self, matrix: np.ndarray) -> np.ndarray:
        """Pinocchio nv x nv matrix -> robodyn order."""
        return np.asarray(matrix)[np.ix_(self.v_index, self.v_index)]

    def columns_back(self, matrix: np.ndarray) -> np.ndarray:
        """Pinocchio k x nv matrix (a Jacobian) -> robodyn column order."""
        matrix = np.asarray(matrix)
        # Pinocchio returns a one-column matrix as a vector
        return matrix.reshape(len(matrix), -1)[:, self.v_index]
