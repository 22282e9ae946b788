"""Equations of motion of a chain with mimic joints, in reduced coordinates.

A mimic relation q_f = r q_l + o (``from_urdf(path, mimic=True)`` reads them) leaves the follower
without a coordinate of its own. The equations are the chain's, derived as if every joint moved on
its own, at q_f = r q_l + o, q̇_f = r q̇_l, q̈_f = r q̈_l, and mapped by the constant matrix G that
gives every joint's rate from the kept ones (q̇ = G q̇_red; virtual work maps forces by Gᵀ):

    τ_red = Gᵀ τ,   M_red = Gᵀ M G,   V_red = Gᵀ V,   G_red = Gᵀ G(q),   F_red = Gᵀ F,
    C_red = Gᵀ C G,   Γ_red[i, j, k] = Σ G_ai G_bj G_ck Γ[a, b, c]

(C_red and Γ_red are those of M_red, as G is constant). Each entry is put back in the canonical
trigonometric form; with a ratio that is not a whole number, the follower's angle r q_l stays a
sine or cosine of its own.
"""

from __future__ import annotations

from functools import cached_property

import sympy as sp

from robodyn._mimic_relations import resolve_mimics
from robodyn.symbolic.equations import EquationsOfMotion, as_given
from robodyn.symbolic.trig import trig_canonical

__all__ = ["MimicMap", "ReducedEquations"]


class MimicMap:
    """A chain's mimic relations as maps: ``coupling`` G (n × kept), the substitution of every
    follower's symbols, and :meth:`reduce` for expressions."""

    def __init__(self, chain):
        self.chain = chain
        self.followers = resolve_mimics(dict(chain.mimics), lambda k: chain.links[k].name)
        self.kept = [i for i in range(chain.n) if i not in self.followers]
        column = {i: j for j, i in enumerate(self.kept)}
        self.coupling = sp.zeros(chain.n, len(self.kept))
        self.substitution = {}
        for i in self.kept:
            self.coupling[i, column[i]] = 1
        self.whole_ratios = all(ratio.is_Integer for _, ratio, _ in self.followers.values())
        for follower, (leader, ratio, offset) in self.followers.items():
            self.coupling[follower, column[leader]] = ratio
            self.substitution.update({
                chain.q[follower]: ratio * chain.q[leader] + offset,
                chain.qd[follower]: ratio * chain.qd[leader],
                chain.qdd[follower]: ratio * chain.qdd[leader],
            })

    @property
    def coordinates(self) -> tuple[tuple, tuple, tuple]:
        """The kept coordinate, velocity and acceleration symbols."""
        chain = self.chain
        return tuple(tuple(symbols[i] for i in self.kept) for symbols in (chain.q, chain.qd, chain.qdd))

    @property
    def angles(self) -> tuple:
        """The kept revolute joints' angles."""
        return tuple(self.chain.q[i] for i in self.kept if self.chain.links[i].joint == "revolute")

    def reduce(self, expr) -> sp.Expr:
        """An exact expression of the full chain at the relations, in canonical form where every
        ratio is a whole number (else expanded: r q_l is then an angle of its own)."""
        expr = sp.expand(sp.sympify(expr).xreplace(self.substitution))
        if not self.whole_ratios:
            return expr
        return trig_canonical(expr, self.angles)

    def forces(self, entries) -> list:
        """Gᵀ f at the relations, exact: generalized forces of every joint as the kept ones'."""
        return [self.reduce(x) for x in self.coupling.T * sp.Matrix(entries)]


class ReducedEquations(EquationsOfMotion):
    """τ_red = M_red q̈_red + V_red + G_red + F_red of a chain with mimic joints (see the module
    docstring): the attributes and methods of :class:`EquationsOfMotion`, over the kept
    coordinates. ``full`` holds the equations with every joint free."""

    def __init__(self, full: EquationsOfMotion):
        super().__init__(full.chain, full.kinematics, full._rigid_tau, full._kinetic, full._gravity_potential,
                         full._spring_potential, full._spring_forces, full._dissipation)
        self.full = full
        self.map = MimicMap(full.chain)
        self.coupling = self.map.coupling

    @property
    def n(self) -> int:
        """Number of kept coordinates."""
        return len(self.map.kept)

    @property
    def coordinates(self) -> tuple[tuple, tuple, tuple]:
        """The kept coordinate, velocity and acceleration symbols."""
        return self.map.coordinates

    q = property(lambda self: sp.Matrix(self.coordinates[0]))
    qd = property(lambda self: sp.Matrix(self.coordinates[1]))
    qdd = property(lambda self: sp.Matrix(self.coordinates[2]))

    def _reduced(self, expr) -> sp.Expr:
        return self.map.reduce(expr)

    def _reduced_out(self, matrix) -> sp.Matrix:
        return as_given(matrix.applyfunc(self._reduced), self.chain.decimals)

    def _exact(self, rows) -> sp.Matrix:
        return sp.Matrix([[entry.as_expr() for entry in row] for row in rows])

    @cached_property
    def _reduced_mass(self) -> sp.Matrix:
        return self.coupling.T * self._exact(self.full._mass) * self.coupling

    @cached_property
    def _reduced_coriolis(self) -> sp.Matrix:
        return (self.coupling.T * self._exact(self.full._coriolis) * self.coupling).applyfunc(self._reduced)

    @cached_property
    def M(self) -> sp.Matrix:
        """M_red = Gᵀ M G."""
        return self._reduced_out(self._reduced_mass)

    @cached_property
    def G(self) -> sp.Matrix:
        """G_red = Gᵀ G(q): gravity and springs."""
        gravity = [g.as_expr() + s for g, s in zip((g for g in self.full._gravity), self.full._spring_forces)]
        return self._reduced_out(self.coupling.T * sp.Matrix(gravity))

    @cached_property
    def V(self) -> sp.Matrix:
        """V_red = Gᵀ V."""
        return self._reduced_out(self.coupling.T * self._exact([[v] for v in self.full._velocity]))

    @cached_property
    def C(self) -> sp.Matrix:
        """C_red = Gᵀ C G: V_red = C_red q̇_red, Ṁ_red − 2 C_red skew."""
        return as_given(self._reduced_coriolis, self.chain.decimals)

    @cached_property
    def F(self) -> sp.Matrix:
        """F_red = Gᵀ F: damping and friction through the transmission."""
        return self._reduced_out(self.coupling.T * sp.Matrix(self.full._dissipation))

    def _exact_tau(self) -> list:
        return self.map.forces(self.full._exact_tau())

    @cached_property
    def tau(self) -> sp.Matrix:
        """τ_red = Gᵀ τ: the equations of motion."""
        return as_given(sp.Matrix(self._exact_tau()), self.chain.decimals)

    @cached_property
    def christoffel(self) -> sp.Array:
        """Γ_red[i, j, k] = Σ G_ai G_bj G_ck Γ[a, b, c] (those of M_red)."""
        gamma, g, n, m = self.full._christoffel, self.coupling, self.chain.n, self.n
        entries = [[[self._reduced(sum((g[a, i] * g[b, j] * g[c, k] * gamma[a][b][c].as_expr()
                                        for a in range(n) for b in range(n) for c in range(n)
                                        if g[a, i] != 0 and g[b, j] != 0 and g[c, k] != 0), sp.S.Zero))
                     for k in range(m)] for j in range(m)] for i in range(m)]
        return as_given(sp.Array(entries), self.chain.decimals)

    @cached_property
    def centrifugal(self) -> sp.Matrix:
        """Craig's C(q) of the kept coordinates: Γ_red[i, j, j]."""
        gamma = self.christoffel
        return sp.Matrix(self.n, self.n, lambda i, j: gamma[i, j, j])

    @cached_property
    def coriolis_pairs(self) -> sp.Matrix:
        """Craig's B(q) of the kept coordinates: 2 Γ_red[i, j, k] for j < k."""
        gamma = self.christoffel
        pairs = [(j, k) for j in range(self.n) for k in range(j + 1, self.n)]
        return sp.Matrix(self.n, len(pairs), lambda i, p: 2 * gamma[i, pairs[p][0], pairs[p][1]])

    @property
    def velocity_squares(self) -> sp.Matrix:
        return sp.Matrix([v**2 for v in self.coordinates[1]])

    @property
    def velocity_products(self) -> sp.Matrix:
        qd = self.coordinates[1]
        return sp.Matrix([qd[j] * qd[k] for j in range(self.n) for k in range(j + 1, self.n)])

    @cached_property
    def kinetic_energy(self) -> sp.Expr:
        """K = ½ q̇_redᵀ M_red q̇_red."""
        return as_given(self._reduced(self.full._kinetic.as_expr()), self.chain.decimals)

    @cached_property
    def potential_energy(self) -> sp.Expr:
        """P at the relations: gravity and springs."""
        full = self.full
        return as_given(self._reduced(full._gravity_potential.as_expr() + full._spring_potential), self.chain.decimals)

    @property
    def lagrangian(self) -> sp.Expr:
        return self.kinetic_energy - self.potential_energy

    @cached_property
    def _reduced_mass_rate(self) -> sp.Matrix:
        # Ṁ_red = Σₖ ∂M_red/∂q_k q̇_k
        q, qd = self.coordinates[:2]
        mass = self._reduced_mass.applyfunc(self._reduced)
        return mass.applyfunc(lambda m: self._reduced(sum(m.diff(a) * v for a, v in zip(q, qd))))

    @cached_property
    def M_dot(self) -> sp.Matrix:
        """Ṁ_red = Σₖ ∂M_red/∂q_k q̇_k."""
        return as_given(self._reduced_mass_rate, self.chain.decimals)

    def skew_residual(self) -> sp.Matrix:
        """(Ṁ_red − 2 C_red) + its transpose, in canonical form: zero when skew."""
        residual = self._reduced_mass_rate - 2 * self._reduced_coriolis
        return (residual + residual.T).applyfunc(self._reduced)

    def __repr__(self) -> str:
        return (f"<ReducedEquations of '{self.chain.name}': {self.n} coordinates, "
                f"{len(self.map.followers)} mimic joint(s)>")
