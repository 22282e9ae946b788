"""Equations of motion by Euler–Lagrange, the notes' recipe (the UR5 dynamics notes, "Euler-Lagrange method";
the TU Berlin notes, "Lagrange Formulation"; the TUM notes, "Lagrange Equation"):

1. kinetic energy through the link Jacobians (the TU Berlin notes, "Mass Matrix"; the UR5 dynamics notes step ②)
       K = ½ q̇ᵀ [Σᵢ mᵢ J_vᵢᵀ J_vᵢ + J_ωᵢᵀ Iᵢ J_ωᵢ] q̇ = ½ q̇ᵀ M(q) q̇
2. potential energy of gravity and springs (the TUM notes "u_i = −mᵢ gᵀ p_Cᵢ"; the UR5 dynamics notes "V")
       P = −Σᵢ mᵢ gᵀ p_cᵢ + Σ ½ k (q − q_ref)² + Σ ½ k (r − r₀)²
3. L = K − P and, for every coordinate,
       τⱼ = d/dt (∂L/∂q̇ⱼ) − ∂L/∂qⱼ − Qⱼ,   d/dt = Σₖ q̇ₖ ∂/∂qₖ + q̈ₖ ∂/∂q̇ₖ
   with the generalized forces of damping and friction Qⱼ = −bⱼ q̇ⱼ − f_cⱼ sign(q̇ⱼ), plus any
   others given as ``forces``.

K and the gravity part of P are exact trigonometric polynomials (:mod:`robodyn.symbolic.trig`);
springs and friction, whose terms are not, are differentiated by SymPy directly.
"""

from __future__ import annotations

import sympy as sp

from robodyn.symbolic.chain import Chain
from robodyn.symbolic.equations import EquationsOfMotion
from robodyn.symbolic.kinematics import ChainKinematics, dot, matvec, transpose
from robodyn.symbolic.mimic import ReducedEquations

__all__ = ["lagrange", "mass_matrix_by_jacobians", "passive_joint_forces"]


def mass_matrix_by_jacobians(kinematics: ChainKinematics) -> list[list]:
    """M = Σᵢ mᵢ J_vᵢᵀ J_vᵢ + J_ωᵢᵀ Iᵢ J_ωᵢ, every term in link i's frame (TrigPoly entries)."""
    n = kinematics.chain.n
    zero = kinematics.ring.constant(0)
    mass = [[zero for _ in range(n)] for _ in range(n)]
    for i in range(1, n + 1):
        jv, jw = kinematics.jacobians(i)
        jv_columns, jw_columns = transpose(jv), transpose(jw)
        # columns of Iᵢ J_ωᵢ
        i_jw = [matvec(kinematics.inertia[i - 1], column) for column in jw_columns]
        for a in range(n):
            for b in range(a, n):
                term = kinematics.mass[i - 1] * dot(jv_columns[a], jv_columns[b]) + dot(jw_columns[a], i_jw[b])
                mass[a][b] = mass[a][b] + term
    for a in range(n):
        for b in range(a):
            mass[a][b] = mass[b][a]
    return mass


def spring_potential(chain: Chain, kinematics: ChainKinematics) -> sp.Expr:
    """Joint springs ½ k (q − q_ref)² and point springs ½ k (r − r₀)², as a SymPy expression."""
    energy = sp.S.Zero
    for q, link in zip(chain.q, chain.links):
        energy += link.stiffness * (q - link.spring_reference) ** 2 / 2
    for spring in chain.springs:
        ends = []
        for link, point in ((spring.link_a, spring.point_a), (spring.link_b, spring.point_b)):
            ring_point = [kinematics.ring(x) for x in point]
            ends.append([p.as_expr() for p in kinematics.point(link + 1, ring_point)])
        length = sp.sqrt(sum((a - b) ** 2 for a, b in zip(*ends)))
        energy += spring.stiffness * (length - spring.rest_length) ** 2 / 2
    return energy


def passive_joint_forces(chain: Chain, kinematics: ChainKinematics) -> tuple[sp.Expr, list, list]:
    """(spring energy, spring forces ∂P_spring/∂q, dissipative forces b q̇ + f_c sign(q̇))."""
    springs = spring_potential(chain, kinematics)
    spring_forces = [sp.expand(sp.diff(springs, q)) for q in chain.q]
    dissipation = [link.damping * v + link.friction * sp.sign(v) for v, link in zip(chain.qd, chain.links)]
    return springs, spring_forces, dissipation


def lagrange(chain: Chain, forces=None) -> EquationsOfMotion:
    """The Euler–Lagrange equations of ``chain`` (see the module docstring). ``forces``: n more
    generalized forces Qⱼ acting on the joints besides the actuators (expressions in q and q̇),
    which enter F as −Q. A chain with mimic joints gives :class:`ReducedEquations`, in the
    coordinates the followers' relations leave (``forces`` still one per joint)."""
    if forces is not None:
        forces = [sp.sympify(f) for f in forces]
        if len(forces) != chain.n:
            raise ValueError(f"argument 'forces': expected {chain.n} generalized forces, got {len(forces)}")
    else:
        forces = [sp.S.Zero] * chain.n
    kinematics = ChainKinematics(chain)
    ring = kinematics.ring
    n = chain.n
    qd = [ring(s) for s in chain.qd]
    qdd = [ring(s) for s in chain.qdd]

    # K = ½ q̇ᵀ M q̇ with M from the Jacobians
    mass = mass_matrix_by_jacobians(kinematics)
    kinetic = sum((mass[a][b] * qd[a] * qd[b] for a in range(n) for b in range(n)), ring.constant(0)) * sp.Rational(1, 2)

    # P_gravity = −Σ mᵢ gᵀ p_cᵢ
    potential = ring.constant(0)
    for i in range(1, n + 1):
        potential = potential - kinematics.mass[i - 1] * dot(kinematics.gravity, kinematics.com_position(i))

    # τⱼ = d/dt ∂L/∂q̇ⱼ − ∂L/∂qⱼ, L = K − P_gravity (springs and friction added below)
    lagrangian = kinetic - potential
    tau = []
    for j in range(n):
        momentum = lagrangian.diff(chain.qd[j])
        rate = sum(
            (momentum.diff(chain.q[k]) * qd[k] + momentum.diff(chain.qd[k]) * qdd[k] for k in range(n)),
            ring.constant(0),
        )
        tau.append(rate - lagrangian.diff(chain.q[j]))

    springs, spring_forces, dissipation = passive_joint_forces(chain, kinematics)
    dissipation = [d - force for d, force in zip(dissipation, forces)]
    equations = EquationsOfMotion(
        chain=chain,
        kinematics=kinematics,
        rigid_tau=tau,
        kinetic=kinetic,
        gravity_potential=potential,
        spring_potential=springs,
        spring_forces=spring_forces,
        dissipation=dissipation,
    )
    # a chain with mimic joints: the same equations, in the kept coordinates
    return ReducedEquations(equations) if chain.mimics else equations
