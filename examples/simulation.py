"""# Integrators: Euler, RK4 and adaptive Runge–Kutta

The UR5 dynamics notes, "Simulate": q̈ = −M⁻¹(C + G), integrated with Euler's method, Runge–Kutta
of fixed order 4 and an adaptive Runge–Kutta ("odeint"), on the notes' pendulum and the 2-link
arm. Writes a figure of the errors and `planar2_fall.html`, the arm's fall in the offline 3-D
viewer.

    python examples/simulation.py
"""

import matplotlib.pyplot as plt
import numpy as np
from _compare import show

import robodyn

# %%
# The pendulum of the UR5 dynamics notes: m l² θ̈ + m g l sin θ = 0, small swings take 2π√(l/g).
pendulum = robodyn.load("pendulum")
swing = robodyn.simulate(pendulum, [1e-3], t_end=5.0, dt=1e-3, integrator="rk45", rtol=1e-11, atol=1e-11)
theta, t = swing.q[:, 0], swing.t
k = np.flatnonzero((theta[:-1] < 0) & (theta[1:] >= 0))
crossings = t[k] - theta[k] * (t[k + 1] - t[k]) / (theta[k + 1] - theta[k])
show("period of small swings 2π√(l/g) (s)", 2 * np.pi * np.sqrt(1.0 / 9.81), np.mean(np.diff(crossings)), 1e-6)

# %%
# Euler's method against RK4 and the adaptive scheme: the error of θ(t) swinging from 1 rad.
# Halving dt halves Euler's error and divides RK4's by 16. (Euler's error is the point here:
# `accuracy="ignore"` silences the warning simulate gives when a fixed step misses its rtol.)
# The reference is sampled every 0.5 ms, at every step time of the runs below.
reference = robodyn.simulate(pendulum, [1.0], t_end=2.0, dt=5e-4, integrator="rk45", rtol=1e-13, atol=1e-13)
figure, axis = plt.subplots(figsize=(8, 4))
print("θ(2 s) error, swinging from 1 rad:")
for integrator, dt in (("euler", 1e-3), ("euler", 5e-4), ("rk4", 1e-2), ("rk4", 5e-3)):
    run = robodyn.simulate(pendulum, [1.0], t_end=2.0, dt=dt, integrator=integrator, accuracy="ignore")
    error = np.abs(run.q[:, 0] - np.interp(run.t, reference.t, reference.q[:, 0]))
    axis.semilogy(run.t[1:], error[1:], label=f"{integrator}, dt = {dt:g} s")
    print(f"  {integrator:<5} dt = {dt:<7g} {abs(run.q[-1, 0] - reference.q[-1, 0]):.2e} rad")
axis.set_xlabel("time [s]")
axis.set_ylabel("|θ − θ_reference| [rad]")
axis.set_title("The pendulum from 1 rad: error of each integrator")
axis.legend()
axis.grid(True, alpha=0.3)

# %%
# The 2-link arm of the ECE 470 and TUM notes falling from rest with no torque: the total energy
# is conserved. `to_html` writes the fall as one self-contained page that plays offline.
arm = robodyn.load("planar2")
fall = robodyn.simulate(arm, [0.3, 0.5], t_end=5.0, dt=1e-2, integrator="rk45", rtol=1e-11, atol=1e-11)
show("total energy T + V at t = 0 and at t = 5 s (J)", fall.energy[0], fall.energy[-1], 1e-8)
print(f"wrote {fall.to_html('planar2_fall.html')}")
