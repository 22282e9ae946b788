"""Exact trigonometric polynomials: the algebra every symbolic derivation here runs in.

A robot's kinematic and dynamic terms are polynomials in the sines and cosines of its joint angles
and in everything else (masses, lengths, velocities, prismatic coordinates). Products of sines and
cosines turn into sines and cosines of sums by the product-to-sum identities

    cos A cos B = ½ [cos(A − B) + cos(A + B)]
    sin A sin B = ½ [cos(A − B) − cos(A + B)]
    sin A cos B = ½ [sin(A + B) + sin(A − B)]

so each such expression has one canonical form ``Σ_k a_k cos(k·q) + b_k sin(k·q)`` over integer
vectors k whose first non-zero entry is positive, with coefficients a_k, b_k polynomials in the
other symbols. That form is the notes' closed form: c₁₂ = cos(q₁ + q₂) stands where c₁c₂ − s₁s₂
stood, s₁² + c₁² is 1, and an expression that is identically zero is 0, which makes it the test of
symbolic equality as well.

:class:`TrigPoly` keeps every intermediate in that form, with exact rational coefficients held as
SymPy sparse polynomials (``sympy.polys.rings``), so sums cancel as they are formed and nothing
ever needs SymPy's general ``simplify`` (which takes minutes on a 6-DoF arm where this takes
seconds). A constant angle φ in a sine or cosine (a URDF rpy of 0.5 rad) is one more angle of the
series, so that cos²φ + sin²φ is 1 there too; anything else in the coefficients (a square root,
1/m) enters as an opaque generator of the polynomial ring.
"""

from __future__ import annotations

from fractions import Fraction

import sympy as sp
from sympy.polys.rings import ring as polynomial_ring

__all__ = ["TrigRing", "TrigPoly", "trig_canonical", "is_identically_zero"]


def _linear_form(argument: sp.Expr, angles: tuple) -> tuple[tuple, sp.Expr] | None:
    """``argument = k·angles + phase`` with integer k and a phase free of angles, or None."""
    argument = sp.expand(argument)
    k = []
    for angle in angles:
        coefficient = argument.coeff(angle)
        if coefficient != 0 and not coefficient.is_Integer:
            return None
        k.append(int(coefficient))
    phase = sp.expand(argument - sum(c * a for c, a in zip(k, angles)))
    if phase.free_symbols & set(angles):
        return None
    return tuple(k), phase


def _normal(k: tuple, kind: str) -> tuple[tuple, str, int]:
    """cos(−x) = cos x and sin(−x) = −sin x: the frequency with its first non-zero entry positive,
    the kind, and the sign the flip costs."""
    for entry in k:
        if entry > 0:
            return k, kind, 1
        if entry < 0:
            return tuple(-e for e in k), kind, (-1 if kind == "sin" else 1)
    return k, kind, 1


def _product_to_sum(k1: tuple, kind1: str, k2: tuple, kind2: str) -> list[tuple[tuple, str, Fraction]]:
    """trig1(k1·q) trig2(k2·q) as a sum of (k, kind, weight)."""
    plus = tuple(a + b for a, b in zip(k1, k2))
    minus = tuple(a - b for a, b in zip(k1, k2))
    half = Fraction(1, 2)
    if kind1 == "cos" and kind2 == "cos":
        return [(minus, "cos", half), (plus, "cos", half)]
    if kind1 == "sin" and kind2 == "sin":
        return [(minus, "cos", half), (plus, "cos", -half)]
    if kind1 == "sin":
        return [(plus, "sin", half), (minus, "sin", half)]
    # cos A sin B = ½ [sin(A + B) − sin(A − B)]
    return [(plus, "sin", half), (minus, "sin", -half)]


class TrigRing:
    """The trigonometric polynomials in ``angles`` with polynomial coefficients in ``generators``.

    Expressions converted into the ring may hold other functions of non-angle quantities; each
    such subexpression becomes one more generator (kept as a dummy symbol and restored on output).
    """

    def __init__(self, angles, generators=(), expressions=()):
        self.joint_angles = tuple(angles)
        self.angles = self.joint_angles
        # constant angles φ inside sin/cos become angles of their own
        split = [self._split_phases(e) for e in expressions]
        constants = sorted({f.args[0] for e in split for f in e.atoms(sp.cos, sp.sin) if f.args[0].is_number},
                           key=sp.default_sort_key)
        self.constant_angles = {phi: sp.Dummy(f"phi{k}", real=True) for k, phi in enumerate(constants)}
        self.angles = self.joint_angles + tuple(self.constant_angles.values())
        self.zero_frequency = (0,) * len(self.angles)
        opaque: dict = {}
        symbols = set(generators)
        for expression in split:
            for value in _leaves(self.prepare(expression), self.angles):
                if isinstance(value, sp.Symbol):
                    symbols.add(value)
                elif value not in opaque:
                    opaque[value] = sp.Dummy(f"c{len(opaque)}")
        symbols -= set(self.angles)
        self.opaque = opaque
        self.restore = {dummy: value for value, dummy in opaque.items()}
        names = sorted(symbols, key=lambda s: s.name) + list(opaque.values())
        if names:
            self.ring, *gens = polynomial_ring(names, sp.QQ)
        else:
            self.ring, *gens = polynomial_ring("unused", sp.QQ)
            names = []
        self.generators = dict(zip(names, gens))
        self.index = {symbol: k for k, symbol in enumerate(names)}

    def _split_phases(self, expr) -> sp.Expr:
        """Floats as the exact decimals they print as; sin/cos of ``k·q + φ`` split into sin/cos of
        ``k·q`` times sin/cos φ."""
        expr = sp.sympify(expr)
        if expr.has(sp.Float):
            expr = expr.xreplace({f: sp.Rational(str(f)) for f in expr.atoms(sp.Float)})
        return expr.replace(
            lambda e: isinstance(e, (sp.cos, sp.sin)) and _has_phase(e.args[0], self.joint_angles),
            lambda e: _split_phase(e, self.joint_angles),
        )

    def prepare(self, expr) -> sp.Expr:
        """:meth:`_split_phases`, then every constant angle replaced by its own angle symbol."""
        expr = self._split_phases(expr)
        if not self.constant_angles:
            return expr
        return expr.xreplace({f: type(f)(self.constant_angles[f.args[0]])
                              for f in expr.atoms(sp.cos, sp.sin) if f.args[0] in self.constant_angles})

    def coefficient(self, expr: sp.Expr):
        """An angle-free expression as a ring element."""
        expr = self.prepare(expr)
        return self.ring.from_expr(expr.xreplace(self.opaque)) if expr != 0 else self.ring.zero

    def __call__(self, expr) -> "TrigPoly":
        """An expression (free of angles except inside sin/cos of integer combinations) as a TrigPoly."""
        expr = self.prepare(expr)
        angle_set = set(self.angles)
        terms: dict = {}
        for term in sp.Add.make_args(sp.expand(expr)):
            coefficient = []
            factors = []
            for factor in sp.Mul.make_args(term):
                base, exponent = factor.as_base_exp()
                if not base.free_symbols & angle_set:
                    coefficient.append(factor)
                    continue
                form = None
                if isinstance(base, (sp.cos, sp.sin)) and exponent.is_Integer and exponent > 0:
                    form = _linear_form(base.args[0], self.angles)
                if form is None:
                    raise ValueError(
                        f"expected a polynomial in sin and cos of integer combinations of "
                        f"{self.angles}, got the factor {factor}"
                    )
                kind = "cos" if isinstance(base, sp.cos) else "sin"
                factors += [(form[0], kind)] * int(exponent)
            product = [(self.zero_frequency, "cos", Fraction(1))]
            for k2, kind2 in factors:
                product = [
                    item
                    for k1, kind1, weight in product
                    for item in ((k, kind, weight * w) for k, kind, w in _product_to_sum(k1, kind1, k2, kind2))
                ]
            c = self.coefficient(sp.Mul(*coefficient))
            for k, kind, weight in product:
                _accumulate(terms, k, kind, c * sp.QQ(weight.numerator, weight.denominator))
        return TrigPoly(self, terms)

    def constant(self, value) -> "TrigPoly":
        return TrigPoly(self, _accumulate({}, self.zero_frequency, "cos", self.coefficient(value)))

    def matrix(self, matrix) -> list[list["TrigPoly"]]:
        """A SymPy matrix as nested lists of TrigPoly."""
        matrix = sp.Matrix(matrix)
        return [[self(matrix[i, j]) for j in range(matrix.cols)] for i in range(matrix.rows)]

    def vector(self, column) -> list["TrigPoly"]:
        """A SymPy column as a list of TrigPoly."""
        return [self(x) for x in sp.Matrix(column)]


def _accumulate(terms: dict, k: tuple, kind: str, coefficient) -> dict:
    k, kind, sign = _normal(k, kind)
    if kind == "sin" and not any(k):
        return terms
    key = (k, kind)
    total = terms.get(key)
    total = coefficient * sign if total is None else total + coefficient * sign
    if total:
        terms[key] = total
    else:
        terms.pop(key, None)
    return terms


class TrigPoly:
    """``Σ coefficient · trig(k·q)``: a dict ``{(k, "cos" | "sin"): ring element}``."""

    __slots__ = ("ring", "terms")

    def __init__(self, ring: TrigRing, terms: dict):
        self.ring = ring
        self.terms = terms

    def _lift(self, other) -> "TrigPoly":
        return other if isinstance(other, TrigPoly) else self.ring.constant(other)

    def __add__(self, other):
        other = self._lift(other)
        terms = dict(self.terms)
        for (k, kind), c in other.terms.items():
            _accumulate(terms, k, kind, c)
        return TrigPoly(self.ring, terms)

    __radd__ = __add__

    def __neg__(self):
        return TrigPoly(self.ring, {key: -c for key, c in self.terms.items()})

    def __sub__(self, other):
        return self + (-self._lift(other))

    def __rsub__(self, other):
        return self._lift(other) - self

    def __mul__(self, other):
        if not isinstance(other, TrigPoly):
            c = other if hasattr(other, "ring") and other.ring == self.ring.ring else self.ring.coefficient(other)
            return TrigPoly(self.ring, {key: value * c for key, value in self.terms.items() if value * c})
        terms: dict = {}
        for (k1, kind1), c1 in self.terms.items():
            for (k2, kind2), c2 in other.terms.items():
                c = c1 * c2
                for k, kind, w in _product_to_sum(k1, kind1, k2, kind2):
                    _accumulate(terms, k, kind, c * sp.QQ(w.numerator, w.denominator))
        return TrigPoly(self.ring, terms)

    __rmul__ = __mul__

    def diff(self, symbol: sp.Symbol) -> "TrigPoly":
        """∂/∂symbol: an angle (d cos(k·q)/dq_j = −k_j sin(k·q)) or a generator."""
        terms: dict = {}
        if symbol in self.ring.angles:
            j = self.ring.angles.index(symbol)
            for (k, kind), c in self.terms.items():
                if k[j]:
                    if kind == "cos":
                        _accumulate(terms, k, "sin", c * (-k[j]))
                    else:
                        _accumulate(terms, k, "cos", c * k[j])
            return TrigPoly(self.ring, terms)
        generator = self.ring.generators.get(symbol)
        if generator is None:
            return TrigPoly(self.ring, {})
        for (k, kind), c in self.terms.items():
            _accumulate(terms, k, kind, c.diff(generator))
        return TrigPoly(self.ring, terms)

    def select(self, keep) -> "TrigPoly":
        """The monomials whose generator exponents satisfy ``keep(exponents)`` (e.g. to set q̇ = 0)."""
        terms: dict = {}
        for key, c in self.terms.items():
            part = self.ring.ring.from_dict({m: v for m, v in c.terms() if keep(m)})
            if part:
                terms[key] = part
        return TrigPoly(self.ring, terms)

    def as_expr(self) -> sp.Expr:
        """The canonical SymPy expression; a constant angle's multiples are written out in
        powers of its sine and cosine (cos 2φ = cos²φ − sin²φ), so that the expression reads
        back into a ring with the same constant angles."""
        out = []
        ring = self.ring
        joints = len(ring.joint_angles)
        restore_constants = {d: phi for phi, d in ring.constant_angles.items()}
        for (k, kind), c in self.terms.items():
            coefficient = c.as_expr().xreplace(ring.restore)
            if not any(k):
                out.append(coefficient)
                continue
            joint = sp.Add(*[e * a for e, a in zip(k[:joints], ring.joint_angles) if e])
            constant = sp.Add(*[e * a for e, a in zip(k[joints:], ring.angles[joints:]) if e])
            if constant == 0:
                out.append(coefficient * (sp.cos(joint) if kind == "cos" else sp.sin(joint)))
                continue
            # trig(A + B) with B the constant part, expanded in sin/cos of the constant angles
            cos_b = sp.expand_trig(sp.cos(constant)).xreplace(restore_constants)
            sin_b = sp.expand_trig(sp.sin(constant)).xreplace(restore_constants)
            if kind == "cos":
                out.append(coefficient * (sp.cos(joint) * cos_b - sp.sin(joint) * sin_b))
            else:
                out.append(coefficient * (sp.sin(joint) * cos_b + sp.cos(joint) * sin_b))
        return sp.Add(*out)


def _leaves(expr: sp.Expr, angles: tuple) -> set:
    """Symbols and non-polynomial subexpressions free of angles (the ring's generators)."""
    if expr.is_Rational:
        return set()
    if isinstance(expr, sp.Symbol):
        return {expr}
    if isinstance(expr, (sp.Add, sp.Mul)):
        return set().union(*(_leaves(a, angles) for a in expr.args))
    if isinstance(expr, sp.Pow) and expr.exp.is_Integer and expr.exp > 0:
        return _leaves(expr.base, angles)
    if expr.free_symbols & set(angles):
        # sin/cos of k·q (phases were split off) or something the conversion will refuse
        return set()
    return {expr}


def _has_phase(argument: sp.Expr, angles: tuple) -> bool:
    form = _linear_form(argument, angles)
    return form is not None and form[1] != 0 and any(form[0])


def _split_phase(trig: sp.Expr, angles: tuple) -> sp.Expr:
    """cos(kq + φ) = cos φ cos kq − sin φ sin kq and sin(kq + φ) = sin φ cos kq + cos φ sin kq."""
    k, phase = _linear_form(trig.args[0], angles)
    kq = sp.Add(*[c * a for c, a in zip(k, angles)])
    if isinstance(trig, sp.cos):
        return sp.cos(phase) * sp.cos(kq) - sp.sin(phase) * sp.sin(kq)
    return sp.sin(phase) * sp.cos(kq) + sp.cos(phase) * sp.sin(kq)


def trig_canonical(expr, angles) -> sp.Expr:
    """``expr`` in the canonical form of the module docstring (floats read as exact decimals)."""
    return TrigRing(angles, expressions=[expr])(expr).as_expr()


def is_identically_zero(expr, angles) -> bool:
    """Whether ``expr`` (a scalar or a matrix) is zero for every value of its symbols."""
    entries = list(expr) if isinstance(expr, sp.MatrixBase) else [expr]
    return all(trig_canonical(e, angles) == 0 for e in entries)
