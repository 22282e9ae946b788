"""Fast numeric functions from the symbolic equations: ``eom.lambdify()``.

The closed forms go through ``sympy.lambdify`` with common subexpressions eliminated, into NumPy
functions of one state (``q`` of shape ``(n,)``) or a batch (``(N, n)``, evaluated state by state).
The model's parameters are fixed when the functions are made: a file's values by default, and
``params`` for symbols without one (``{m_1: 2.0, …}``).
"""

from __future__ import annotations

import numpy as np
import sympy as sp

__all__ = ["NumericEquations", "known_values", "parameter_values"]


def known_values(chain, params: dict | None) -> dict:
    """The chain's own parameter values overridden by ``params`` (keys: symbols or their names)."""
    values = dict(chain.values)
    for key, value in (params or {}).items():
        symbol = key if isinstance(key, sp.Symbol) else next(
            (s for s in chain.parameters if s.name == key), None)
        if symbol is None:
            raise ValueError(f"argument 'params': '{key}' is not a parameter of chain '{chain.name}' "
                             f"(its parameters: {[s.name for s in chain.parameters]})")
        values[symbol] = sp.sympify(value)
    return values


def parameter_values(chain, params: dict | None, expressions, coordinates) -> dict:
    """:func:`known_values`, raising ``ValueError`` that names any parameter of ``expressions``
    left without a value (``coordinates``: the symbols that are not parameters)."""
    values = known_values(chain, params)
    coordinates = set(coordinates)
    free = set().union(*(sp.sympify(e).free_symbols for e in expressions)) - coordinates
    missing = sorted(s.name for s in free if s not in values)
    if missing:
        raise ValueError(f"argument 'params': expected values for {missing}, got none")
    return values


class NumericEquations:
    """NumPy functions ``M(q)``, ``C(q, v)``, ``V(q, v)``, ``G(q)``, ``F(v)`` and
    ``tau(q, v, a)`` of one chain with fixed parameters."""

    def __init__(self, equations, params: dict | None = None):
        chain = equations.chain
        self.n = equations.n
        self.name = chain.name
        parts = {"M": equations.M, "C": equations.C, "V": equations.V, "G": equations.G,
                 "F": equations.F, "tau": equations.tau}
        arguments = [symbol for symbols in equations.coordinates for symbol in symbols]
        values = parameter_values(chain, params, parts.values(), arguments)
        self._functions = {
            name: sp.lambdify(arguments, expr.xreplace(values), modules="numpy", cse=True)
            for name, expr in parts.items()
        }

    def _state(self, value, name: str) -> np.ndarray:
        array = np.asarray(value, dtype=float)
        if array.ndim not in (1, 2) or array.shape[-1] != self.n:
            raise ValueError(f"argument '{name}': expected shape ({self.n},) or (N, {self.n}), got {array.shape}")
        if not np.all(np.isfinite(array)):
            raise ValueError(f"argument '{name}': expected finite values, got NaN or infinity")
        return array

    def _call(self, part: str, q=None, v=None, a=None) -> np.ndarray:
        given = {"q": q, "v": v, "a": a}
        arrays = {k: self._state(x, k) for k, x in given.items() if x is not None}
        shapes = {x.shape for x in arrays.values()}
        if len(shapes) > 1:
            raise ValueError(f"arguments {sorted(arrays)}: expected the same shape, got {sorted(shapes)}")
        first = next(iter(arrays.values()))
        batch = first.ndim == 2
        rows = first.shape[0] if batch else 1
        stacks = [arrays[k].reshape(rows, self.n) if k in arrays else np.zeros((rows, self.n)) for k in ("q", "v", "a")]
        function = self._functions[part]
        out = np.array([np.asarray(function(*row), dtype=float) for row in np.hstack(stacks)])
        if part not in ("M", "C"):
            # a constant column comes back as nested (n, 1) lists
            out = out.reshape(len(out), self.n)
        return out if batch else out[0]

    def M(self, q) -> np.ndarray:
        """Mass matrix, (n, n)."""
        return self._call("M", q=q)

    def C(self, q, v) -> np.ndarray:
        """Coriolis matrix (Christoffel form), (n, n)."""
        return self._call("C", q=q, v=v)

    def V(self, q, v) -> np.ndarray:
        """Coriolis and centrifugal forces C(q, v) v, (n,)."""
        return self._call("V", q=q, v=v)

    def G(self, q) -> np.ndarray:
        """Gravity and spring forces, (n,)."""
        return self._call("G", q=q)

    def F(self, v) -> np.ndarray:
        """Damping and friction forces, (n,)."""
        return self._call("F", v=v)

    def tau(self, q, v, a) -> np.ndarray:
        """Inverse dynamics τ = M a + V + G + F, (n,)."""
        return self._call("tau", q=q, v=v, a=a)

    def __repr__(self) -> str:
        return f"<NumericEquations of '{self.name}': M(q), C(q, v), V(q, v), G(q), F(v), tau(q, v, a)>"
