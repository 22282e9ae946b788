"""# Coriolis and centrifugal terms, four ways

The TU Berlin and TUM notes: the 2-link arm's velocity terms, as the Coriolis matrix C(q, q̇), as Christoffel
symbols, and as Craig's centrifugal C(q) and Coriolis B(q) matrices.

    python examples/coriolis.py
"""

import numpy as np
from _compare import show

import robodyn

arm = robodyn.load("planar2")  # m1 = 2, m2 = 1, l1 = 1, l2 = 0.5 (point masses at the link ends)
m2, l1, l2 = 1.0, 1.0, 0.5
q, v = np.array([0.4, 1.1]), np.array([0.7, -1.3])
h = -m2 * l1 * l2 * np.sin(q[1])

show("C(q, q̇) = [[h q̇2, h (q̇1 + q̇2)], [-h q̇1, 0]], h = -m2 l1 l2 sin q2", [[h * v[1], h * (v[0] + v[1])], [-h * v[0], 0]], arm.coriolis_matrix(q, v))
show("V(q, q̇) = [-m2 l1 l2 s2 (q̇2² + 2 q̇1 q̇2), m2 l1 l2 s2 q̇1²]", [h * (v[1] ** 2 + 2 * v[0] * v[1]), -h * v[0] ** 2], arm.coriolis_matrix(q, v) @ v)
show("Craig's C(q) = [[0, -m2 l1 l2 s2], [m2 l1 l2 s2, 0]]", [[0, h], [-h, 0]], arm.centrifugal_matrix(q))
show("Craig's B(q) = [-2 m2 l1 l2 s2, 0]ᵀ", [[2 * h], [0]], arm.coriolis_pairs_matrix(q))
gamma = arm.christoffel(q)
show("Christoffel symbols Γ112 = Γ121 = Γ122 = h, Γ211 = -h", [h, h, h, -h], [gamma[0, 0, 1], gamma[0, 1, 0], gamma[0, 1, 1], gamma[1, 0, 0]])
