"""# A quadruped lands: contact forces over time

Menagerie's Unitree Go2 is dropped from 5 cm above its `home` keyframe onto its scene's floor
and held there by a PD law through its twelve motors (k_p = 200 N·m/rad, k_d = 5 N·m·s/rad,
clipped to the motors' ranges). `robodyn.simulate(..., integrator="mujoco")` steps the scene as
MuJoCo's `mj_step` does ([Scenes stepped as MuJoCo](../guide/scene-simulation.md)); the
trajectory records each sample's contacts and their forces, and `run.plot_contact_forces()`
draws the force on each foot over time: the impact, then the feet sharing the robot's weight.

    python examples/go2_landing.py
"""

from typing import Any

import numpy as np
from _compare import go2_scene, show

import robodyn

go2 = go2_scene()
home = go2.keyframe("home")
JOINTS, SPEEDS = slice(7, go2.nq), slice(6, go2.nv)
KP, KD = 200.0, 5.0
low, high = np.asarray(go2.ctrl_range).T
target = np.asarray(home.q)[JOINTS]


def hold(t: float, q: Any, v: Any) -> Any:
    """The motors' torques: a PD law about `home`, clipped to their ranges."""
    return np.clip(KP * (target - q[JOINTS]) - KD * v[SPEEDS], low, high)


# %%
# ## The drop
#
# The run starts 5 cm above `home` at rest and lasts 1.5 s (750 steps of 2 ms); `ctrl` is asked
# at each step's start, as a MuJoCo user sets `d.ctrl` before each `mj_step`.
start = np.array(home.q)
start[2] += 0.05
run = robodyn.simulate(go2, start, t_end=1.5, integrator="mujoco", ctrl=hold)
print(f"base height: {run.q[0, 2]:.3f} m at the start, {run.q[-1, 2]:.3f} m at the end")

# %%
# ## The feet carry the robot's weight
#
# Once the landing has died out the floor pushes on the four feet with m g in all, up against
# gravity (the soft contacts settle to within a millinewton), and the sideways forces cancel.
feet = ["FL", "FR", "RL", "RR"]
forces = sum(run.contact_force(foot)[-1] for foot in feet)
weight = go2.total_mass * float(np.linalg.norm(go2.gravity))
show("the feet's push at 1.5 s, world axes (N)", [0.0, 0.0, weight], forces, 1e-4)

# %%
# ## Over time
#
# The figure: each foot's push up (against gravity) and across, their sum and m g. The impact
# peaks at five times the weight within 30 ms, the front feet pushing hardest; the PD law has
# the robot at rest on its feet after 0.4 s.
run.plot_contact_forces(feet, path="go2_landing_forces.png")
