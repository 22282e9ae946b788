"""The equations of motion ``τ = M(q) q̈ + V(q, q̇) + G(q) + F(q̇)`` and everything read off them.

The terms are read off τ the way the UR5 dynamics notes do ("E_OM ... M, C, G = ?"):
``M = ∂τ/∂q̈``, ``G = τ(q̇ = 0, q̈ = 0)`` (gravity and springs), ``V = τ − M q̈ − G − F`` (Coriolis
and centrifugal, Craig's V of the ECE 470 and TUM notes), and ``F`` the damping and friction forces (and −Q of
any other generalized forces given to ``lagrange``). From M come
the Christoffel symbols (the TU Berlin notes, "Christoffel Symbols")

    Γᵢⱼₖ = ½ (∂Mᵢⱼ/∂qₖ + ∂Mᵢₖ/∂qⱼ − ∂Mⱼₖ/∂qᵢ),    Cᵢⱼ = Σₖ Γᵢⱼₖ q̇ₖ,   V = C q̇,

with Ṁ − 2C skew-symmetric, and Craig's split ``V = C(q)[q̇²] + B(q)[q̇q̇]`` (the TU Berlin notes, "Centrifugal
and Coriolis Computation"): ``C(q)ᵢⱼ = Γᵢⱼⱼ`` and ``B(q)`` with columns ``2Γᵢⱼₖ`` for j < k in the
order q̇₁q̇₂, q̇₁q̇₃, …, q̇₁q̇ₙ, q̇₂q̇₃, ….
"""

from __future__ import annotations

from functools import cached_property

import sympy as sp

from robodyn.symbolic.trig import trig_canonical

__all__ = ["EquationsOfMotion", "extract_terms", "as_given"]


def as_given(expr, decimals: bool):
    """Exact rationals back as the decimals a file gave (when ``decimals``), integers kept."""
    if not decimals:
        return expr
    if isinstance(expr, (sp.MatrixBase, sp.NDimArray)):
        return expr.applyfunc(lambda e: as_given(e, True))
    expr = sp.sympify(expr)
    return expr.xreplace({r: sp.Float(r, 15) for r in expr.atoms(sp.Rational) if not r.is_Integer})


def extract_terms(tau, q, qd, qdd) -> tuple[sp.Matrix, sp.Matrix, sp.Matrix]:
    """The UR5 dynamics notes' reading of (M, V, G) off any expression for τ: ``M = ∂τ/∂q̈``,
    ``G = τ(q̇ = 0, q̈ = 0)``, ``V = τ(q̈ = 0) − G``; each entry in canonical trigonometric form."""
    tau = sp.Matrix(tau)
    at_rest = {v: 0 for v in qd} | {a: 0 for a in qdd}
    without_acceleration = {a: 0 for a in qdd}
    mass = tau.jacobian(sp.Matrix(qdd))
    gravity = tau.subs(at_rest)
    velocity = tau.subs(without_acceleration) - gravity

    def canonical(m):
        return m.applyfunc(lambda e: trig_canonical(e, q))

    return canonical(mass), canonical(velocity), canonical(gravity)


class EquationsOfMotion:
    """τ = M q̈ + V + G + F of a chain, with its parts as SymPy matrices in the notes' forms.

    Built by :func:`robodyn.symbolic.lagrange`; every attribute is computed on first use.
    """

    def __init__(self, chain, kinematics, rigid_tau, kinetic, gravity_potential, spring_potential,
                 spring_forces, dissipation):
        self.chain = chain
        self.kinematics = kinematics
        self._ring = kinematics.ring
        self._rigid_tau = rigid_tau
        self._kinetic = kinetic
        self._gravity_potential = gravity_potential
        self._spring_potential = spring_potential
        self._spring_forces = spring_forces
        self._dissipation = dissipation

    @property
    def n(self) -> int:
        return self.chain.n

    @property
    def coordinates(self) -> tuple[tuple, tuple, tuple]:
        """The coordinate, velocity and acceleration symbols the equations are written in."""
        return self.chain.q, self.chain.qd, self.chain.qdd

    @property
    def q(self):
        return sp.Matrix(self.chain.q)

    @property
    def qd(self):
        return sp.Matrix(self.chain.qd)

    @property
    def qdd(self):
        return sp.Matrix(self.chain.qdd)

    def _out(self, expr):
        return as_given(expr, self.chain.decimals)

    # the parts, in the ring
    @cached_property
    def _mass(self):
        # M = ∂τ/∂q̈
        return [[t.diff(a) for a in self.chain.qdd] for t in self._rigid_tau]

    @cached_property
    def _gravity(self):
        # G = τ(q̇ = 0, q̈ = 0): the monomials with no velocity or acceleration
        moving = [self._ring.index[s] for s in self.chain.qd + self.chain.qdd]
        return [t.select(lambda m: not any(m[k] for k in moving)) for t in self._rigid_tau]

    @cached_property
    def _christoffel(self):
        # Γᵢⱼₖ = ½ (∂Mᵢⱼ/∂qₖ + ∂Mᵢₖ/∂qⱼ − ∂Mⱼₖ/∂qᵢ)
        n, q, m = self.n, self.chain.q, self._mass
        dm = [[[m[i][j].diff(q[k]) for k in range(n)] for j in range(n)] for i in range(n)]
        return [[[(dm[i][j][k] + dm[i][k][j] - dm[j][k][i]) * sp.Rational(1, 2) for k in range(n)]
                 for j in range(n)] for i in range(n)]

    @cached_property
    def _coriolis(self):
        # Cᵢⱼ = Σₖ Γᵢⱼₖ q̇ₖ
        qd = [self._ring(v) for v in self.chain.qd]
        gamma = self._christoffel
        return [[sum((gamma[i][j][k] * qd[k] for k in range(self.n)), self._ring.constant(0))
                 for j in range(self.n)] for i in range(self.n)]

    @cached_property
    def _velocity(self):
        # V = τ − M q̈ − G
        qdd = [self._ring(a) for a in self.chain.qdd]
        return [self._rigid_tau[i] - sum((self._mass[i][j] * qdd[j] for j in range(self.n)), self._ring.constant(0))
                - self._gravity[i] for i in range(self.n)]

    def _matrix(self, rows) -> sp.Matrix:
        return self._out(sp.Matrix([[entry.as_expr() for entry in row] for row in rows]))

    # the parts, as SymPy
    @cached_property
    def M(self) -> sp.Matrix:
        """Mass matrix M(q), n × n."""
        return self._matrix(self._mass)

    @cached_property
    def G(self) -> sp.Matrix:
        """Gravity and spring forces G(q) = ∂P/∂q, n × 1."""
        gravity = [g.as_expr() for g in self._gravity]
        return self._out(sp.Matrix([g + s for g, s in zip(gravity, self._spring_forces)]))

    @cached_property
    def V(self) -> sp.Matrix:
        """Coriolis and centrifugal forces V(q, q̇) = C(q, q̇) q̇, n × 1 (Craig's V)."""
        return self._matrix([[v] for v in self._velocity])

    @cached_property
    def C(self) -> sp.Matrix:
        """Coriolis matrix C(q, q̇) from the Christoffel symbols: V = C q̇, Ṁ − 2C skew."""
        return self._matrix(self._coriolis)

    @cached_property
    def F(self) -> sp.Matrix:
        """Damping and friction forces F(q̇) = b q̇ + f_c sign(q̇) (minus any other generalized
        forces Q given to ``lagrange``), n × 1."""
        return self._out(sp.Matrix(self._dissipation))

    def _exact_tau(self) -> list:
        return [t.as_expr() + s + d for t, s, d in zip(self._rigid_tau, self._spring_forces, self._dissipation)]

    @cached_property
    def tau(self) -> sp.Matrix:
        """τ = M q̈ + V + G + F, n × 1: the equations of motion."""
        return self._out(sp.Matrix(self._exact_tau()))

    @cached_property
    def christoffel(self) -> sp.Array:
        """Christoffel symbols of the first kind Γ[i, j, k] (the TU Berlin notes' b_ijk), n × n × n."""
        gamma = self._christoffel
        return self._out(sp.Array([[[gamma[i][j][k].as_expr() for k in range(self.n)] for j in range(self.n)]
                                   for i in range(self.n)]))

    @cached_property
    def centrifugal(self) -> sp.Matrix:
        """Craig's C(q): ``C(q)[q̇²]`` is the centrifugal part of V; entry (i, j) = Γᵢⱼⱼ."""
        gamma = self._christoffel
        return self._matrix([[gamma[i][j][j] for j in range(self.n)] for i in range(self.n)])

    @cached_property
    def coriolis_pairs(self) -> sp.Matrix:
        """Craig's B(q): ``B(q)[q̇q̇]`` is the Coriolis part of V, n × n(n−1)/2, columns 2Γᵢⱼₖ for
        j < k in the order q̇₁q̇₂, q̇₁q̇₃, …, q̇₂q̇₃, …."""
        gamma = self._christoffel
        pairs = [(j, k) for j in range(self.n) for k in range(j + 1, self.n)]
        rows = [[gamma[i][j][k] * 2 for j, k in pairs] for i in range(self.n)]
        if not pairs:
            return sp.zeros(self.n, 0)
        return self._matrix(rows)

    @property
    def velocity_squares(self) -> sp.Matrix:
        """[q̇²] = [q̇₁², …, q̇ₙ²]ᵀ."""
        return sp.Matrix([v**2 for v in self.chain.qd])

    @property
    def velocity_products(self) -> sp.Matrix:
        """[q̇q̇] = [q̇₁q̇₂, q̇₁q̇₃, …, q̇ₙ₋₁q̇ₙ]ᵀ."""
        qd = self.chain.qd
        return sp.Matrix([qd[j] * qd[k] for j in range(self.n) for k in range(j + 1, self.n)])

    @cached_property
    def kinetic_energy(self) -> sp.Expr:
        """K = ½ q̇ᵀ M q̇."""
        return self._out(self._kinetic.as_expr())

    @cached_property
    def potential_energy(self) -> sp.Expr:
        """P: gravity −Σ mᵢ gᵀ p_cᵢ plus the springs' energy."""
        return self._out(self._gravity_potential.as_expr() + self._spring_potential)

    @property
    def lagrangian(self) -> sp.Expr:
        """L = K − P."""
        return self.kinetic_energy - self.potential_energy

    @cached_property
    def _mass_rate(self):
        # Ṁ = Σₖ ∂M/∂qₖ q̇ₖ
        qd = [self._ring(v) for v in self.chain.qd]
        return [[sum((m.diff(q) * v for q, v in zip(self.chain.q, qd)), self._ring.constant(0)) for m in row]
                for row in self._mass]

    @cached_property
    def M_dot(self) -> sp.Matrix:
        """Ṁ = Σₖ ∂M/∂qₖ q̇ₖ, n × n."""
        return self._matrix(self._mass_rate)

    def skew_residual(self) -> sp.Matrix:
        """(Ṁ − 2C) + (Ṁ − 2C)ᵀ, exactly: the zero matrix when Ṁ − 2C is skew-symmetric."""
        mdot, c, n = self._mass_rate, self._coriolis, self.n
        return self._matrix([[mdot[i][j] - c[i][j] * 2 + mdot[j][i] - c[j][i] * 2 for j in range(n)]
                             for i in range(n)])

    def lambdify(self, params: dict | None = None):
        """NumPy functions ``M(q)``, ``C(q, v)``, ``V(q, v)``, ``G(q)``, ``F(v)``, ``tau(q, v, a)``
        (see :mod:`robodyn.symbolic.numeric`); ``params`` gives values to symbolic parameters."""
        from robodyn.symbolic.numeric import NumericEquations

        return NumericEquations(self, params)

    def latex(self, form: str = "matrices") -> str:
        """The equations in LaTeX as the notes print them (see :mod:`robodyn.symbolic.printing`)."""
        from robodyn.symbolic.printing import latex

        return latex(self, form)

    def text(self) -> str:
        """M, V, G (and F) entry by entry, in plain text with the notes' abbreviations."""
        from robodyn.symbolic.printing import text

        return text(self)

    def codegen(self, language: str, params: dict | None = None, prefix: str | None = None) -> str:
        """Standalone C, Rust or NumPy source of M, C, G and τ (see :mod:`robodyn.symbolic.codegen`)."""
        from robodyn.symbolic.codegen import codegen

        return codegen(self, language, params, prefix)

    def __repr__(self) -> str:
        return f"<EquationsOfMotion of '{self.chain.name}': {self.n} joints>"
