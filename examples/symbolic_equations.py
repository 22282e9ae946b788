"""# Equations of motion, symbolically

The ECE 470, TUM and UR5 dynamics notes: the equations of motion derived symbolically, as the notes derive them by
hand: Euler–Lagrange for the 2-link arm (M, V, G), Newton–Euler giving the same τ, the pendulum,
and the closed forms evaluated next to the numeric core.

    python examples/symbolic_equations.py
"""

import numpy as np
import sympy as sp
from _compare import show

import robodyn
from robodyn import symbolic as sym

arm = sym.planar_chain(2)  # the notes' arm: point masses m_i at the ends of links l_i, gravity along -y
eom = sym.lagrange(arm)
print(eom.latex())  # M, V, G with c_12 = cos(q_1 + q_2) as the ECE 470 notes print them

# Newton–Euler (Craig's iteration) gives the same torques, symbolically
assert sym.newton_euler(arm).difference(eom) == sp.zeros(2, 1)
print("Newton–Euler τ − Euler–Lagrange τ = 0")
print(eom.latex("torques"))  # the TUM notes, eq. 6.58

# the pendulum of the UR5 dynamics notes
print(sym.lagrange(sym.pendulum()).latex("torques"))  # m l² θ̈ + m g l sin θ = τ

# the closed forms with the bundled planar2's numbers, next to the numeric core
numbers = {"m_1": 2.0, "m_2": 1.0, "l_1": 1.0, "l_2": 0.5, "g": 9.81}
f = eom.lambdify(params=numbers)
model = robodyn.load("planar2")
q, v, a = np.array([0.4, 1.1]), np.array([0.7, -1.3]), np.array([0.5, -0.2])
show("M(q) from the closed form", f.M(q), model.mass_matrix(q))
show("V(q, q̇) from the closed form", f.V(q, v), model.coriolis_matrix(q, v) @ v)
show("G(q) from the closed form", f.G(q), model.generalized_gravity(q))
show("τ from the closed form", f.tau(q, v, a), model.inverse_dynamics(q, v, a))
