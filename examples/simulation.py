"""The UR5 dynamics notes, "Simulate": q̈ = −M⁻¹(C + G), integrated with Euler's method, Runge–Kutta of fixed
order 4 and an adaptive Runge–Kutta ("odeint"), on the notes' pendulum and the 2-link arm; then
an animation of q.

    python examples/simulation.py [--animate swing.gif]
"""

import argparse

import numpy as np
from _compare import show

import robodyn

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--animate", help="write the 2-link arm's swing as a GIF (or MP4 with ffmpeg)")
args, _ = parser.parse_known_args()

# the pendulum of the UR5 dynamics notes: m l² θ̈ + m g l sin θ = 0, small swings take 2π√(l/g)
pendulum = robodyn.load("pendulum")
swing = robodyn.simulate(pendulum, [1e-3], t_end=5.0, dt=1e-3, integrator="rk45", rtol=1e-11, atol=1e-11)
theta, t = swing.q[:, 0], swing.t
k = np.flatnonzero((theta[:-1] < 0) & (theta[1:] >= 0))
crossings = t[k] - theta[k] * (t[k + 1] - t[k]) / (theta[k + 1] - theta[k])
show("period of small swings 2π√(l/g) (s)", 2 * np.pi * np.sqrt(1.0 / 9.81), np.mean(np.diff(crossings)), 1e-6)

# Euler's method against RK4 and the adaptive scheme: the error of θ(2 s) from 1 rad
reference = robodyn.simulate(pendulum, [1.0], t_end=2.0, dt=1e-2, integrator="rk45", rtol=1e-13, atol=1e-13)
print("θ(2 s) error, swinging from 1 rad:")
for integrator, dt in (("euler", 1e-3), ("euler", 5e-4), ("rk4", 1e-2), ("rk4", 5e-3)):
    run = robodyn.simulate(pendulum, [1.0], t_end=2.0, dt=dt, integrator=integrator)
    print(f"  {integrator:<5} dt = {dt:<7g} {abs(run.q[-1, 0] - reference.q[-1, 0]):.2e} rad")
print("  halving dt halves Euler's error and divides RK4's by 16")

# the 2-link arm of the ECE 470 and TUM notes falling from rest, no torque: energy is conserved
arm = robodyn.load("planar2")
fall = robodyn.simulate(arm, [0.3, 0.5], t_end=5.0, dt=1e-2, integrator="rk45", rtol=1e-11, atol=1e-11)
show("total energy T + V at t = 0 and at t = 5 s (J)", fall.energy[0], fall.energy[-1], 1e-8)
if args.animate:
    fall.animate(args.animate)
    print(f"wrote {args.animate}")
