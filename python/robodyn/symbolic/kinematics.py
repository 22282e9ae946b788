"""Forward kinematics and link Jacobians of a :class:`Chain`, exactly, in trigonometric-polynomial
form (see :mod:`robodyn.symbolic.trig`).

Frames are numbered 0 (the base) and 1..n (link i's joint frame). ``transform(j, i)`` is ʲTᵢ for
an ancestor frame j of i, the product of the links' ``ⁱ⁻¹Tᵢ(qᵢ) = origin_i · joint_i(qᵢ)``
(the ECE 470 notes, "Frames and transforms"). The Jacobians are the notes' geometric ones (the ECE 470 notes, "Recall
in Wk 04: Jacobian"): column j of link i's centre-of-mass Jacobian is ``Ẑⱼ × (p_c − pⱼ)`` for a
revolute joint j and ``Ẑⱼ`` for a prismatic one; of its angular Jacobian ``Ẑⱼ`` and 0. Both are
expressed in link i's own frame, where its inertia is constant, so that
``M = Σᵢ mᵢ J_vᵢᵀ J_vᵢ + J_ωᵢᵀ Iᵢ J_ωᵢ`` (the TU Berlin notes, "Mass Matrix") needs no rotated inertias.
"""

from __future__ import annotations

from functools import cached_property

import sympy as sp

from robodyn.symbolic.chain import Chain
from robodyn.symbolic.trig import TrigPoly, TrigRing

__all__ = ["ChainKinematics", "matmul", "matvec", "transpose", "cross", "dot"]


def matmul(a, b):
    return [[sum((a[i][k] * b[k][j] for k in range(len(b))), start=_zero(a)) for j in range(len(b[0]))]
            for i in range(len(a))]


def matvec(a, x):
    return [sum((a[i][k] * x[k] for k in range(len(x))), start=_zero(a)) for i in range(len(a))]


def transpose(a):
    return [list(row) for row in zip(*a)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _zero(a):
    first = a[0][0]
    return first.ring.constant(0)


class ChainKinematics:
    """Kinematics of ``chain`` in the trigonometric-polynomial ring of its revolute angles."""

    def __init__(self, chain: Chain):
        self.chain = chain
        self.revolute = tuple(q for q, link in zip(chain.q, chain.links) if link.joint == "revolute")
        prismatic = [q for q, link in zip(chain.q, chain.links) if link.joint == "prismatic"]
        expressions = [chain.gravity]
        for link in chain.links:
            expressions += [link.origin, link.axis, link.mass, link.com, link.inertia]
        self.ring = TrigRing(
            self.revolute,
            generators=list(chain.qd) + list(chain.qdd) + prismatic,
            expressions=[e for x in expressions for e in (x if isinstance(x, sp.MatrixBase) else [x])],
        )
        r = self.ring
        # per link: rotation and position of ⁱ⁻¹Tᵢ(qᵢ), axis, and mass properties in the ring
        self.rotation, self.position = [], []
        self.axis, self.mass, self.com, self.inertia = [], [], [], []
        for q, link in zip(chain.q, chain.links):
            t = link.origin * link.joint_transform(q)
            self.rotation.append(r.matrix(t[:3, :3]))
            self.position.append(r.vector(t[:3, 3]))
            self.axis.append(r.vector(link.axis))
            self.mass.append(r(link.mass))
            self.com.append(r.vector(link.com))
            self.inertia.append(r.matrix(link.inertia))
        self.gravity = r.vector(chain.gravity)

    def parent_frame(self, i: int) -> int:
        """Frame number of the parent of frame i (links are frames 1..n)."""
        return self.chain.links[i - 1].parent + 1

    def is_ancestor(self, j: int, i: int) -> bool:
        while i > j:
            i = self.parent_frame(i)
        return i == j

    @cached_property
    def _transforms(self) -> dict:
        # ʲTᵢ = ʲT_parent(i) · ᵖᵃʳᵉⁿᵗ⁽ⁱ⁾Tᵢ, for every ancestor j of i
        r = self.ring
        identity = [[r.constant(int(a == b)) for b in range(3)] for a in range(3)]
        origin = [r.constant(0) for _ in range(3)]
        transforms = {}
        for i in range(self.chain.n + 1):
            transforms[(i, i)] = (identity, origin)
            if i == 0:
                continue
            p = self.parent_frame(i)
            local_r, local_p = self.rotation[i - 1], self.position[i - 1]
            j = p
            while True:
                rot, pos = transforms[(j, p)]
                transforms[(j, i)] = (matmul(rot, local_r), [a + b for a, b in zip(matvec(rot, local_p), pos)])
                if j == 0:
                    break
                j = self.parent_frame(j)
        return transforms

    def transform(self, j: int, i: int) -> tuple:
        """(ʲRᵢ, ʲpᵢ) for an ancestor frame j of frame i."""
        return self._transforms[(j, i)]

    def point(self, i: int, point) -> list[TrigPoly]:
        """A point given in frame i, in the base frame."""
        rotation, position = self.transform(0, i)
        return [a + b for a, b in zip(matvec(rotation, point), position)]

    def com_position(self, i: int) -> list[TrigPoly]:
        """Centre of mass of link i (frame i) in the base frame."""
        return self.point(i, self.com[i - 1])

    def jacobians(self, i: int) -> tuple[list, list]:
        """(J_v, J_ω) of link i's centre of mass in frame i: 3 × n nested lists."""
        r = self.ring
        n = self.chain.n
        jv = [[r.constant(0) for _ in range(n)] for _ in range(3)]
        jw = [[r.constant(0) for _ in range(n)] for _ in range(3)]
        for j in range(1, i + 1):
            if not self.is_ancestor(j, i):
                continue
            rotation, position = self.transform(j, i)
            # Ẑⱼ in frame i: (ʲRᵢ)ᵀ axisⱼ
            z = matvec(transpose(rotation), self.axis[j - 1])
            if self.chain.links[j - 1].joint == "revolute":
                # Ẑⱼ × (p_c − pⱼ), with p_c − pⱼ = ʲRᵢ c_i + ʲpᵢ, rotated into frame i
                offset = [a + b for a, b in zip(matvec(rotation, self.com[i - 1]), position)]
                linear = matvec(transpose(rotation), cross(self.axis[j - 1], offset))
                angular = z
            else:
                linear, angular = z, [r.constant(0)] * 3
            for row in range(3):
                jv[row][j - 1] = linear[row]
                jw[row][j - 1] = angular[row]
        return jv, jw
