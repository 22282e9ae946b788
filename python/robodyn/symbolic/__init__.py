"""Symbolic equations of motion with SymPy, derived the way the lecture notes do it.

    from robodyn import symbolic as sym
    arm = sym.planar_chain(2, point_masses=True)     # or sym.from_dh(rows), sym.from_urdf(path)
    eom = sym.lagrange(arm)                          # Euler–Lagrange
    eom.M, eom.V, eom.G, eom.C, eom.christoffel      # SymPy matrices in the notes' closed forms
    sym.newton_euler(arm).tau                        # Craig's iterative Newton–Euler, symbolic
    eom.latex(); eom.lambdify(); eom.codegen("c")

Pure Python on SymPy: nothing here needs the Rust core.
"""

from robodyn.symbolic.chain import Chain, Link, PointSpring
from robodyn.symbolic.equations import EquationsOfMotion, extract_terms
from robodyn.symbolic.lagrange import lagrange
from robodyn.symbolic.newton_euler import NewtonEuler, newton_euler
from robodyn.symbolic.models import from_dh, from_urdf, pendulum, planar_chain
from robodyn.symbolic.trig import is_identically_zero, trig_canonical

__all__ = [
    "Chain",
    "Link",
    "PointSpring",
    "EquationsOfMotion",
    "extract_terms",
    "lagrange",
    "newton_euler",
    "NewtonEuler",
    "from_dh",
    "from_urdf",
    "pendulum",
    "planar_chain",
    "is_identically_zero",
    "trig_canonical",
]
