"""# Cartesian dynamics of the 2-link arm

The TUM notes, "Cartesian state space equation": the 2-link arm's tool (x, y) task, F = M_x ẍ + V_x + G_x
with M_x = J⁻ᵀ M J⁻¹, V_x = J⁻ᵀ (V − M J⁻¹ J̇ q̇), G_x = J⁻ᵀ G, next to robodyn's Λ, μ, p.

    python examples/cartesian_dynamics.py
"""

import numpy as np
from _compare import show

import robodyn

arm = robodyn.load("planar2")
q, v = np.array([0.4, 1.1]), np.array([0.7, -1.3])
rows = [0, 1]  # the tool's x and y
j = arm.jacobian(q, "tool")[rows]
j_dot = arm.jacobian_time_variation(q, v, "tool")[rows]
j_inv = np.linalg.inv(j)
m, g = arm.mass_matrix(q), arm.generalized_gravity(q)
velocity_terms = arm.bias_forces(q, v) - g
cartesian = arm.operational_space(q, v, "tool", task=rows)
show("M_x = J⁻ᵀ M J⁻¹", j_inv.T @ m @ j_inv, cartesian["Lambda"], 1e-9)
show("V_x = J⁻ᵀ (V − M J⁻¹ J̇ q̇)", j_inv.T @ (velocity_terms - m @ j_inv @ j_dot @ v), cartesian["mu"], 1e-9)
show("G_x = J⁻ᵀ G", j_inv.T @ g, cartesian["p"], 1e-9)
