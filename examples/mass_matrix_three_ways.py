"""# The mass matrix three ways

The TU Berlin and UR5 dynamics notes: the 2-link arm's mass matrix by CRBA, by n RNEA calls and by Σ m Jᵀ J, and its
gravity vector by RNEA and by -Σ J_cᵀ m g, next to the closed forms.

    python examples/mass_matrix_three_ways.py
"""

import numpy as np
from _compare import show

import robodyn

arm = robodyn.load("planar2")
m1, m2, l1, l2, g = 2.0, 1.0, 1.0, 0.5, 9.81
q = np.array([0.4, 1.1])
c1, c2, c12 = np.cos(q[0]), np.cos(q[1]), np.cos(q[0] + q[1])
mass_matrix = [
    [l2**2 * m2 + 2 * l1 * l2 * m2 * c2 + l1**2 * (m1 + m2), l2**2 * m2 + l1 * l2 * m2 * c2],
    [l2**2 * m2 + l1 * l2 * m2 * c2, l2**2 * m2],
]
for method in ("crba", "rnea", "jacobians"):
    show(f"M(q), method={method!r}", mass_matrix, arm.mass_matrix(q, method=method))
gravity = [m2 * l2 * g * c12 + (m1 + m2) * l1 * g * c1, m2 * l2 * g * c12]
for method in ("rnea", "jacobians"):
    show(f"G(q), method={method!r}", gravity, arm.generalized_gravity(q, method=method))
