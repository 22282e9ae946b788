"""Time the symbolic layer: derivation of the closed forms (Euler–Lagrange with M, V, G, C and the
Christoffel symbols in canonical form; Newton–Euler; LaTeX; C code) per model, best of 3 runs.

    .venv/bin/python benchmarks/symbolic.py
"""

from __future__ import annotations

import time
from pathlib import Path

from robodyn import symbolic as sym

ROOT = Path(__file__).resolve().parents[1]
MODELS = {
    "pendulum": sym.pendulum,
    "2-link planar, point masses (symbolic)": lambda: sym.planar_chain(2),
    "3-link planar, rods (symbolic)": lambda: sym.planar_chain(3, point_masses=False),
    "3-DoF RRP arm (DH)": lambda: sym.from_dh(ROOT / "testdata" / "dh" / "rpp_arm.toml"),
    "UR5, 6-DoF (DH)": lambda: sym.from_dh(ROOT / "models" / "ur5_dh.toml"),
    "UR5, 6-DoF (URDF)": lambda: sym.from_urdf(ROOT / "models" / "ur5.urdf"),
    "UR5, 6-DoF (URDF, symbolic masses)": lambda: sym.from_urdf(ROOT / "models" / "ur5.urdf", symbolic_params={"mass"}),
}


def lagrange_terms(chain):
    eom = sym.lagrange(chain)
    return eom.M, eom.V, eom.G, eom.C, eom.christoffel


def best(task, rounds=3) -> float:
    times = []
    for _ in range(rounds):
        start = time.perf_counter()
        task()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    print(f"{'model':40} {'Lagrange: M V G C Γ':>20} {'Newton–Euler τ':>15} {'LaTeX':>8} {'C code':>8}")
    for name, make in MODELS.items():
        chain = make()
        derive = best(lambda: lagrange_terms(chain))
        newton = best(lambda: sym.newton_euler(chain).tau)
        eom = sym.lagrange(chain)
        lagrange_terms(chain)
        latex = best(lambda: eom.latex(), rounds=1)
        code = best(lambda: eom.codegen("c"), rounds=1)
        print(f"{name:40} {derive:19.2f}s {newton:14.2f}s {latex:7.2f}s {code:7.2f}s")


if __name__ == "__main__":
    main()
