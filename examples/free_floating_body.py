"""# A free-floating body: Euler's equations

The UR5 dynamics notes, "Free Floating Body": Euler's equations against the engine (a free joint and ABA), the
precession of a symmetric body, and the Dzhanibekov flip of the intermediate axis.

    python examples/free_floating_body.py
"""

import numpy as np
from _compare import show

import robodyn
from robodyn import free_body

urdf = """<robot name="box"><link name="b"><inertial><mass value="2"/>
  <inertia ixx="0.02" iyy="0.05" izz="0.06" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>"""
body = robodyn.load_urdf_string(urdf, floating_base=True)
body.gravity = [0.0, 0.0, 0.0]
inertia_body, omega = np.diag([0.02, 0.05, 0.06]), np.array([0.4, -1.2, 2.0])
qdd = body.forward_dynamics(body.neutral(), np.concatenate([[0, 0, 0], omega]), np.zeros(6))
show("ω̇_b = I_b⁻¹ [M_b − ω_b × (I_b ω_b)] vs ABA", free_body.angular_acceleration(inertia_body, omega), qdd[3:])

motion = free_body.simulate(np.diag([1.0, 1.0, 2.0]), [0.3, 0.0, 2.0], t_end=1.0, dt=1e-3)
rate = free_body.precession_rate(1.0, 2.0, 2.0)
angle = np.unwrap(np.angle(motion["omega_body"][:, 0] + 1j * motion["omega_body"][:, 1]))[-1]
show("precession Ω = (I3 − I1)/I1 ω3 (rad/s)", rate, angle / motion["t"][-1], 1e-8)

flip = free_body.simulate(np.diag([1.0, 2.0, 3.0]), [1e-3, 5.0, 1e-3], t_end=10.0, dt=1e-2)
print(f"Dzhanibekov: spin about the intermediate axis, ω2 from {flip['omega_body'][0, 1]:.3f} to {flip['omega_body'][:, 1].min():.3f} rad/s")
L = flip["angular_momentum"]
show("angular momentum (world) at the start and the end", L[0], L[-1], 1e-6)
