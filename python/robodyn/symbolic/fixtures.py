"""Regenerates the closed-form reference values the Rust tests read:
``python -m robodyn.symbolic.fixtures`` run in the repository's root writes
``testdata/reference/symbolic_<model>.json`` (arguments: fixture names, default all).

For each model file, the Euler–Lagrange closed forms (exact rationals, no rounding in the
derivation) are evaluated at fixed states with 30 significant digits, then written as doubles:
M(q), C(q, v), G(q) and τ(q, v, a). Each file records its provenance (model path and SHA-256,
gravity, SymPy version, the command).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import sys
from pathlib import Path

import sympy as sp

from robodyn.symbolic.lagrange import lagrange
from robodyn.symbolic.models import STANDARD_GRAVITY, from_dh, from_urdf

__all__ = ["FIXTURES", "STATES", "fixture", "main"]

#: name -> (model file relative to the repository, gravity); planar2 with the notes' gravity along −y
FIXTURES = {
    "planar2": ("models/planar2.urdf", (0, -STANDARD_GRAVITY, 0)),
    "pendulum": ("models/pendulum.urdf", (0, 0, -STANDARD_GRAVITY)),
    "rpp_arm": ("testdata/dh/rpp_arm.toml", (0, 0, -STANDARD_GRAVITY)),
    "ur5_dh": ("models/ur5_dh.toml", (0, 0, -STANDARD_GRAVITY)),
    "ur5": ("models/ur5.urdf", (0, 0, -STANDARD_GRAVITY)),
}

#: (q, v, a) patterns, cycled over the joints; decimals, read exactly
STATES = [
    ("0.3 -0.7 1.1 -1.9 0.5 2.3", "0.5 1.5 -0.25 0.75 -1 2", "0.2 -0.4 1 -1.5 0.6 0.1"),
    ("1.2 2.1 -0.6 0.4 -2.8 0", "-2 0.3 1.25 -0.5 0.1 -1.1", "1 1 -2 0.5 0 3"),
    ("-2.5 0.4 0 3 1.7 -0.9", "0 -1 0.6 1.4 -2 0.2", "-0.5 2 0.3 -0.7 1.2 -1"),
]
DIGITS = 30


def _values(pattern: str, n: int) -> list:
    numbers = pattern.split()
    return [sp.Rational(numbers[k % len(numbers)]) for k in range(n)]


def _floats(matrix) -> list:
    rows = [[float(sp.N(x, DIGITS)) for x in matrix.row(i)] for i in range(matrix.rows)]
    return rows if matrix.cols > 1 else [row[0] for row in rows]


def fixture(name: str, repository: Path) -> dict:
    """The reference values of one model (see the module docstring)."""
    relative, gravity = FIXTURES[name]
    path = Path(repository) / relative
    chain = from_dh(path, gravity=gravity) if path.suffix == ".toml" else from_urdf(path, gravity=gravity)
    # exact rationals in the results (no decimal rounding before the evaluation)
    equations = lagrange(dataclasses.replace(chain, decimals=False))
    n = chain.n
    states = []
    for q_pattern, v_pattern, a_pattern in STATES:
        q, v, a = _values(q_pattern, n), _values(v_pattern, n), _values(a_pattern, n)
        at = dict(zip(chain.q, q)) | dict(zip(chain.qd, v)) | dict(zip(chain.qdd, a))
        states.append({
            "q": [float(x) for x in q], "v": [float(x) for x in v], "a": [float(x) for x in a],
            "mass_matrix": _floats(equations.M.xreplace(at)),
            "coriolis_matrix": _floats(equations.C.xreplace(at)),
            "gravity": _floats(equations.G.xreplace(at)),
            "tau": _floats(equations.tau.xreplace(at)),
        })
    return {
        "provenance": {
            "generator": "python -m robodyn.symbolic.fixtures (Euler-Lagrange closed forms, exact, "
                         f"evaluated to {DIGITS} digits)",
            "model": relative,
            "model_sha256": hashlib.sha256(path.read_bytes()).hexdigest(),
            "gravity": [float(x) for x in gravity],
            "sympy": sp.__version__,
        },
        "states": states,
    }


def main(argv: list[str] | None = None) -> int:
    names = (argv if argv is not None else sys.argv[1:]) or list(FIXTURES)
    repository = Path.cwd()
    if not (repository / "testdata" / "reference").is_dir():
        print(f"run in the repository's root: {repository} has no testdata/reference", file=sys.stderr)
        return 2
    unknown = [n for n in names if n not in FIXTURES]
    if unknown:
        print(f"unknown fixture(s) {unknown}: expected some of {list(FIXTURES)}", file=sys.stderr)
        return 2
    for name in names:
        target = repository / "testdata" / "reference" / f"symbolic_{name}.json"
        target.write_text(json.dumps(fixture(name, repository), indent=1) + "\n")
        print(f"wrote {target.relative_to(repository)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
