"""Iterative Newton–Euler, symbolic: Craig's equations 6.45–6.53 as the ECE 470 and TUM notes write them.

Every vector is expressed in the frame of its link (the joint frame i), ``ⁱ⁺¹ᵢR`` is the transpose
of the rotation of ``ⁱTᵢ₊₁`` and ``ⁱPᵢ₊₁`` its translation; Ẑ is the joint axis in its own frame.
Gravity enters as an acceleration of the base, ``⁰v̇₀ = −g`` (the TUM notes, "To include gravity").

Outward, i: 0 → n−1 (revolute joint i+1; for a prismatic one ω and ω̇ only rotate and v̇ gains
``2 ω × ḋ Ẑ + d̈ Ẑ``)::

    ⁱ⁺¹ωᵢ₊₁ = ⁱ⁺¹ᵢR ⁱωᵢ + θ̇ᵢ₊₁ Ẑ
    ⁱ⁺¹ω̇ᵢ₊₁ = ⁱ⁺¹ᵢR ⁱω̇ᵢ + ⁱ⁺¹ᵢR ⁱωᵢ × θ̇ᵢ₊₁ Ẑ + θ̈ᵢ₊₁ Ẑ
    ⁱ⁺¹v̇ᵢ₊₁ = ⁱ⁺¹ᵢR (ⁱω̇ᵢ × ⁱPᵢ₊₁ + ⁱωᵢ × (ⁱωᵢ × ⁱPᵢ₊₁) + ⁱv̇ᵢ)
    ⁱ⁺¹v̇_Cᵢ₊₁ = ω̇ × P_C + ω × (ω × P_C) + v̇       (all of link i+1)
    ⁱ⁺¹Fᵢ₊₁ = mᵢ₊₁ v̇_C,   ⁱ⁺¹Nᵢ₊₁ = ᶜI ω̇ + ω × ᶜI ω

Inward, i: n → 1 (a tree sums over the children instead of the one i+1)::

    ⁱfᵢ = ⁱᵢ₊₁R ⁱ⁺¹fᵢ₊₁ + ⁱFᵢ
    ⁱnᵢ = ⁱNᵢ + ⁱᵢ₊₁R ⁱ⁺¹nᵢ₊₁ + ⁱP_Cᵢ × ⁱFᵢ + ⁱPᵢ₊₁ × ⁱᵢ₊₁R ⁱ⁺¹fᵢ₊₁
    τᵢ = ⁱnᵢᵀ Ẑᵢ   (a prismatic joint: τᵢ = ⁱfᵢᵀ Ẑᵢ)

The joint's own spring, damper and friction add their forces to τᵢ (what the actuator must also
overcome), so that τ is the same as Euler–Lagrange's.
"""

from __future__ import annotations

from functools import cached_property

import sympy as sp

from robodyn.symbolic.chain import Chain
from robodyn.symbolic.equations import as_given
from robodyn.symbolic.kinematics import ChainKinematics, cross, dot, matvec, transpose
from robodyn.symbolic.lagrange import passive_joint_forces
from robodyn.symbolic.mimic import MimicMap
from robodyn.symbolic.trig import trig_canonical

__all__ = ["newton_euler", "NewtonEuler"]


def _add(a, b):
    return [x + y for x, y in zip(a, b)]


def _scale(a, s):
    return [x * s for x in a]


class NewtonEuler:
    """The iteration's results: ``tau`` and, per link (index 0 for link 1), ``omega``,
    ``omega_dot``, ``v_dot``, ``v_dot_c``, ``F``, ``N``, ``f``, ``n``: 3 × 1 SymPy matrices in the
    link's frame, as the notes tabulate them."""

    def __init__(self, chain: Chain, kinematics: ChainKinematics, vectors: dict, rigid_tau: list, passive: list):
        self.chain = chain
        self._vectors = vectors
        self._rigid_tau = rigid_tau
        self._passive = passive
        self.ring = kinematics.ring
        # with mimic joints: every result at the relations, τ in the kept coordinates
        self._mimics = MimicMap(chain) if chain.mimics else None

    def _column(self, vector) -> sp.Matrix:
        column = sp.Matrix([x.as_expr() for x in vector])
        if self._mimics is not None:
            column = column.applyfunc(self._mimics.reduce)
        return as_given(column, self.chain.decimals)

    def _per_link(self, name: str) -> list[sp.Matrix]:
        return [self._column(v) for v in self._vectors[name]]

    @cached_property
    def tau(self) -> sp.Matrix:
        """Joint torques (forces for prismatic joints), n × 1; with mimic joints, Gᵀ τ at the
        relations (one per kept coordinate)."""
        return as_given(sp.Matrix(self._exact_tau()), self.chain.decimals)

    omega = cached_property(lambda self: self._per_link("omega"))
    omega_dot = cached_property(lambda self: self._per_link("omega_dot"))
    v_dot = cached_property(lambda self: self._per_link("v_dot"))
    v_dot_c = cached_property(lambda self: self._per_link("v_dot_c"))
    F = cached_property(lambda self: self._per_link("F"))
    N = cached_property(lambda self: self._per_link("N"))
    f = cached_property(lambda self: self._per_link("f"))
    n = cached_property(lambda self: self._per_link("n"))

    def difference(self, equations) -> sp.Matrix:
        """τ_Newton–Euler − τ_Lagrange of the same chain, exactly, in canonical form: the zero
        vector when the two agree."""
        angles = self._mimics.angles if self._mimics is not None else self.ring.joint_angles
        return sp.Matrix([trig_canonical(a - b, angles) for a, b in zip(self._exact_tau(), equations._exact_tau())])

    def _exact_tau(self) -> list:
        tau = [t.as_expr() + p for t, p in zip(self._rigid_tau, self._passive)]
        return tau if self._mimics is None else self._mimics.forces(tau)

    def __repr__(self) -> str:
        return f"<NewtonEuler of '{self.chain.name}': {self.chain.n} joints>"


def newton_euler(chain: Chain) -> NewtonEuler:
    """Craig's iterative Newton–Euler on ``chain``, symbolic (see the module docstring)."""
    kinematics = ChainKinematics(chain)
    ring = kinematics.ring
    n = chain.n
    zero = [ring.constant(0)] * 3
    qd = [ring(s) for s in chain.qd]
    qdd = [ring(s) for s in chain.qdd]
    # frame 0: at rest, accelerating upwards against gravity
    omega = {0: zero}
    omega_dot = {0: zero}
    v_dot = {0: _scale(kinematics.gravity, -1)}
    v_dot_c, force, torque = {}, {}, {}

    # outward: velocities and accelerations, then each link's F = m v̇_C and N = I ω̇ + ω × I ω
    for i in range(1, n + 1):
        p = kinematics.parent_frame(i)
        to_child = transpose(kinematics.rotation[i - 1])
        position = kinematics.position[i - 1]
        z = kinematics.axis[i - 1]
        rotated_omega = matvec(to_child, omega[p])
        rotated_omega_dot = matvec(to_child, omega_dot[p])
        # ⁱ⁺¹ᵢR (ω̇ × P + ω × (ω × P) + v̇)
        transported = matvec(to_child, _add(_add(cross(omega_dot[p], position),
                                                 cross(omega[p], cross(omega[p], position))), v_dot[p]))
        if chain.links[i - 1].joint == "revolute":
            omega[i] = _add(rotated_omega, _scale(z, qd[i - 1]))
            omega_dot[i] = _add(_add(rotated_omega_dot, cross(rotated_omega, _scale(z, qd[i - 1]))),
                                _scale(z, qdd[i - 1]))
            v_dot[i] = transported
        else:
            omega[i] = rotated_omega
            omega_dot[i] = rotated_omega_dot
            # + 2 ω × ḋ Ẑ + d̈ Ẑ
            v_dot[i] = _add(_add(transported, _scale(cross(omega[i], _scale(z, qd[i - 1])), 2)),
                            _scale(z, qdd[i - 1]))
        com = kinematics.com[i - 1]
        v_dot_c[i] = _add(_add(cross(omega_dot[i], com), cross(omega[i], cross(omega[i], com))), v_dot[i])
        force[i] = _scale(v_dot_c[i], kinematics.mass[i - 1])
        inertia = kinematics.inertia[i - 1]
        torque[i] = _add(matvec(inertia, omega_dot[i]), cross(omega[i], matvec(inertia, omega[i])))

    # inward: forces and torques the parent exerts, summed over the children
    f = {i: list(force[i]) for i in range(1, n + 1)}
    moment = {i: _add(torque[i], cross(kinematics.com[i - 1], force[i])) for i in range(1, n + 1)}
    for i in range(n, 0, -1):
        p = kinematics.parent_frame(i)
        if p == 0:
            continue
        to_parent = kinematics.rotation[i - 1]
        rotated_f = matvec(to_parent, f[i])
        f[p] = _add(f[p], rotated_f)
        moment[p] = _add(_add(moment[p], matvec(to_parent, moment[i])), cross(kinematics.position[i - 1], rotated_f))
    tau = []
    for i in range(1, n + 1):
        projected = f[i] if chain.links[i - 1].joint == "prismatic" else moment[i]
        tau.append(dot(projected, kinematics.axis[i - 1]))

    _, spring_forces, dissipation = passive_joint_forces(chain, kinematics)
    passive = [s + d for s, d in zip(spring_forces, dissipation)]
    vectors = {
        "omega": [omega[i] for i in range(1, n + 1)],
        "omega_dot": [omega_dot[i] for i in range(1, n + 1)],
        "v_dot": [v_dot[i] for i in range(1, n + 1)],
        "v_dot_c": [v_dot_c[i] for i in range(1, n + 1)],
        "F": [force[i] for i in range(1, n + 1)],
        "N": [torque[i] for i in range(1, n + 1)],
        "f": [f[i] for i in range(1, n + 1)],
        "n": [moment[i] for i in range(1, n + 1)],
    }
    return NewtonEuler(chain, kinematics, vectors, tau, passive)
