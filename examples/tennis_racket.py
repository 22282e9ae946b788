"""# The tennis-racket theorem, in 3-D

A rigid body spins stably about its axes of smallest and largest inertia, but not about the
intermediate one: the smallest disturbance grows and the body flips over and back again, the
Dzhanibekov effect (Ashbaugh, Chicone & Cushman, 1991). A free-floating book of 30 × 15 × 5 cm,
spun about its 15 cm axis, simulated by robodyn (a free joint, ABA, RK4) with no gravity. Energy
and angular momentum are conserved; the spin reverses. Writes `book.html`, the motion in the
offline 3-D viewer.

    python examples/tennis_racket.py
"""

import matplotlib.pyplot as plt
import numpy as np
from _compare import show

import robodyn

# %%
# A uniform box of mass m and sides (a, b, c) has I = m/12 diag(b² + c², a² + c², a² + b²):
# the y axis (the 15 cm side) is the intermediate one.
mass, (a, b, c) = 1.0, (0.30, 0.15, 0.05)
inertia = mass / 12 * np.array([b**2 + c**2, a**2 + c**2, a**2 + b**2])
urdf = f"""<robot name="book"><link name="book">
  <inertial><mass value="{mass}"/><inertia ixx="{inertia[0]}" iyy="{inertia[1]}" izz="{inertia[2]}" ixy="0" ixz="0" iyz="0"/></inertial>
  <visual><geometry><box size="{a} {b} {c}"/></geometry></visual></link></robot>"""
book = robodyn.load_urdf_string(urdf, floating_base=True)
book.gravity = [0.0, 0.0, 0.0]

# %%
# Spun at 6 rad/s about y, with a disturbance of 0.01 rad/s about x and z; v = [linear; angular],
# in the body's axes.
spin = np.array([0.0, 0.0, 0.0, 0.01, 6.0, 0.01])
motion = robodyn.simulate(book, book.neutral(), spin, t_end=8.0, dt=1e-3, integrator="rk4")
omega = motion.v[:, 3:]
momentum = book.centroidal_momentum(motion.q, motion.v)[:, 3:]  # [linear; angular], world axes
show("kinetic energy at t = 0 and at t = 8 s (J)", motion.energy[0], motion.energy[-1], 1e-9)
show("angular momentum (world) at t = 0 and at t = 8 s", momentum[0], momentum[-1], 1e-9)
print(f"ω_y went from {omega[0, 1]:.2f} to {omega[:, 1].min():.2f} rad/s and back to {omega[-1, 1]:.2f} rad/s")

figure, axis = plt.subplots(figsize=(8, 3.5))
for k, name in enumerate("xyz"):
    axis.plot(motion.t, omega[:, k], label=f"ω_{name}")
axis.set_xlabel("time [s]")
axis.set_ylabel("body angular velocity [rad/s]")
axis.set_title("Spin about the intermediate axis: it reverses, and again")
axis.grid(True, alpha=0.3)
axis.legend()

# %%
# The motion in the offline 3-D viewer (drag to turn, play and the time slider at the bottom).
print(f"wrote {motion.to_html('book.html')}")
