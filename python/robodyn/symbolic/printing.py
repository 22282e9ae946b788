"""The equations as the notes print them: ``c₁₂ = cos(q₁ + q₂)``, ``s₂ = sin q₂``, q̇ as a dot.

:func:`abbreviate` replaces every sine or cosine of a sum of distinct joint coordinates by the
symbol ``s_{12…}`` / ``c_{12…}``; :func:`latex` and :func:`text` print the equations of motion
with it, as matrices (the ECE 470 notes, "Dynamic Equation") or joint by joint (the TUM notes, eq. 6.58).
"""

from __future__ import annotations

import sympy as sp

__all__ = ["abbreviate", "latex", "text"]


def _label(argument: sp.Expr, coordinates: tuple) -> str | None:
    """"12" for q₁ + q₂ (indices joined by commas past 9 joints), None for anything else."""
    terms = sp.Add.make_args(argument)
    indices = []
    for term in terms:
        if term not in coordinates:
            return None
        indices.append(coordinates.index(term) + 1)
    if len(set(indices)) != len(indices):
        return None
    separator = "," if len(coordinates) > 9 else ""
    return separator.join(str(i) for i in sorted(indices))


def abbreviate(expr, coordinates) -> sp.Expr:
    """``expr`` with sin/cos of sums of coordinates as the symbols ``s_{…}``/``c_{…}``, and each
    coefficient's common factors pulled out (``g l₁ (m₁ + m₂) c₁``)."""
    coordinates = tuple(coordinates)

    def short(function):
        label = _label(function.args[0], coordinates)
        if label is None:
            return function
        return sp.Symbol(("c" if isinstance(function, sp.cos) else "s") + f"_{{{label}}}", real=True)

    def one(e):
        e = sp.sympify(e).replace(lambda x: isinstance(x, (sp.cos, sp.sin)), short)
        return sp.factor_terms(e)

    if isinstance(expr, (sp.MatrixBase, sp.NDimArray)):
        return expr.applyfunc(one)
    return one(expr)


def _matrix_latex(matrix: sp.Matrix) -> str:
    return sp.latex(matrix, mat_delim="[", mat_str="bmatrix").replace(r"\left[", "").replace(r"\right]", "")


def latex(equations, form: str = "matrices") -> str:
    """LaTeX of ``τ = M(q) q̈ + V(q, q̇) + G(q) [+ F(q̇)]``: ``form="matrices"`` gives M, V, G (and
    F) as matrices, ``form="torques"`` the equation of every joint."""
    q = equations.coordinates[0]
    name = sp.latex(q[0]).split("_")[0]
    lines = []
    if form == "torques":
        for i, tau in enumerate(equations.tau, start=1):
            lines.append(rf"\tau_{{{i}}} &= {sp.latex(abbreviate(tau, q))}")
    elif form == "matrices":
        state = rf"{name}, \dot{{{name}}}"
        has_f = any(f != 0 for f in equations.F)
        lines.append(rf"\tau &= M({name})\,\ddot{{{name}}} + V({state}) + G({name})" + (rf" + F(\dot{{{name}}})" if has_f else ""))
        lines.append(rf"M({name}) &= {_matrix_latex(abbreviate(equations.M, q))}")
        lines.append(rf"V({state}) &= {_matrix_latex(abbreviate(equations.V, q))}")
        lines.append(rf"G({name}) &= {_matrix_latex(abbreviate(equations.G, q))}")
        if has_f:
            lines.append(rf"F(\dot{{{name}}}) &= {_matrix_latex(abbreviate(equations.F, q))}")
    else:
        raise ValueError(f"argument 'form': expected \"matrices\" or \"torques\", got {form!r}")
    return "\\begin{aligned}\n" + " \\\\\n".join(lines) + "\n\\end{aligned}"


def text(equations) -> str:
    """Plain text of M, V, G (and F), entry by entry, with the abbreviations."""
    q = equations.coordinates[0]
    n = equations.n
    out = [f"{equations.chain.name}: tau = M(q) qdd + V(q, qd) + G(q) + F(qd)",
           "c_{12} = cos(q_1 + q_2), s_{1} = sin(q_1), qdot_i = dq_i/dt", ""]
    parts = [("M", abbreviate(equations.M, q)), ("V", abbreviate(equations.V, q)),
             ("G", abbreviate(equations.G, q)), ("F", abbreviate(equations.F, q))]
    for label, matrix in parts:
        if label == "F" and all(x == 0 for x in matrix):
            continue
        for i in range(n):
            if label == "M":
                for j in range(i, n):
                    out.append(f"M[{i + 1},{j + 1}] = {matrix[i, j]}")
            else:
                out.append(f"{label}[{i + 1}] = {matrix[i]}")
        out.append("")
    return "\n".join(out).rstrip() + "\n"
