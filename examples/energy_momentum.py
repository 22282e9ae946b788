"""# Energy, power and momentum

Energy and momentum: T = ½ q̇ᵀ M q̇, the power balance d(T + V)/dt = q̇ᵀ τ, and the centroidal
momentum, whose linear part is m ċ.

    python examples/energy_momentum.py
"""

import numpy as np
from _compare import show

import robodyn

ur5 = robodyn.load("ur5")
rng = np.random.default_rng(0)
q, v, tau = ur5.random_configuration(seed=0), rng.uniform(-1, 1, 6), rng.uniform(-5, 5, 6)
show("T = ½ q̇ᵀ M q̇", 0.5 * v @ ur5.mass_matrix(q) @ v, ur5.kinetic_energy(q, v))
qdd, h = ur5.forward_dynamics(q, v, tau), 1e-6


def energy(t: float) -> float:
    return float(ur5.kinetic_energy(q + t * v, v + t * qdd)) + float(ur5.potential_energy(q + t * v))


show("d(T + V)/dt = q̇ᵀ τ", v @ tau, (energy(h) - energy(-h)) / (2 * h), 1e-6)
mass = 3.7 + 8.393 + 2.275 + 1.219 + 1.219 + 0.1879  # UR5's published link masses
show("linear momentum = m ċ", mass * ur5.center_of_mass_velocity(q, v), ur5.centroidal_momentum(q, v)[:3])
