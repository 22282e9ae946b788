"""# A Panda picks up a cube: a gripper's contacts and a coupling equality

Menagerie's Franka Panda in its MJX scene: box and capsule colliders, the two fingers coupled by a
joint equality (MuJoCo's soft equality rows), position actuators on the arm and one on the
fingers. From the scene's `pickup1` keyframe (the open fingers about the cube on the floor) the
gripper closes, then the shoulder and elbow turn to raise the hand 30 cm. `robodyn.simulate(...,
integrator="mujoco")` steps the scene as `mj_step` does ([Scenes stepped as
MuJoCo](../guide/scene-simulation.md)); the cube rises held by the finger pads' friction alone.

    python examples/panda_pick.py
"""

from typing import Any

import matplotlib.pyplot as plt
import numpy as np
import robodyn
from _compare import PANDA_CUBE, quietly_loaded, show

panda = quietly_loaded(PANDA_CUBE)
start = np.array(panda.keyframe("pickup1").ctrl)


def pick(t: float, q: Any, v: Any) -> Any:
    """The controls: the fingers' target 0 (closed) after 0.1 s; from 0.6 s the shoulder (joint 2)
    and the elbow (joint 4) turned by −0.35 and +0.2 rad along a half cosine over 0.8 s (no jerk
    at either end)."""
    closing = 0.0 if t > 0.1 else 0.04
    raised = 0.5 * (1.0 - np.cos(np.pi * np.clip((t - 0.6) / 0.8, 0.0, 1.0)))
    return start + np.array([0.0, -0.35 * raised, 0.0, 0.2 * raised, 0.0, 0.0, 0.0, closing - start[7]])


# %%
# ## The pick
#
# Two seconds of 5 ms steps (the scene's implicitfast integrator), sampled every 50 ms.
run = robodyn.simulate(
    panda, "pickup1", t_end=2.0, dt=0.05, integrator="mujoco", ctrl=pick
)
height = np.array([panda.frame_pose(q, "box")[2, 3] for q in run.q])
print(f"cube height: {height[0]:.3f} m at the start, {height[-1]:.3f} m at the end")
fingers = [
    panda.joint_idx_q[panda.joint_names.index(f"finger_joint{k}")] for k in (1, 2)
]
print(
    f"finger openings at the end: {run.q[-1, fingers].round(4).tolist()} m (coupled, softly)"
)

# %%
# ## The pads carry the cube
#
# At the top the floor no longer touches the cube; the two finger pads push up on it with its
# weight in all (their grip squeezes it sideways, in opposite directions).
pads = (
    run.contact_force("left_finger_pad")[-1] + run.contact_force("right_finger_pad")[-1]
)
weight = panda.body_masses[panda.body_names.index("box")] * float(
    np.linalg.norm(panda.gravity)
)
show("the pads' push on the cube at 2 s, up (N)", [weight], [-pads[2]], 0.05)

# %%
# ## Over time
#
# The figure: the cube's height, and who carries it: the floor until the hand rises at 0.7 s
# (closing, the pads press the cube down a little and the floor pushes back the more), then the
# two pads alone (the vertical parts of their pushes on the cube; its weight dotted).
pads_up = -(
    run.contact_force("left_finger_pad") + run.contact_force("right_finger_pad")
)[:, 2]
floor_up = -run.contact_force("floor")[:, 2]
figure, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7, 5))
top.plot(run.t, height)
top.set_ylabel("cube height [m]")
bottom.plot(run.t, pads_up, label="finger pads")
bottom.plot(run.t, floor_up, label="floor")
bottom.axhline(weight, color="grey", linestyle=":", label="m g of the cube")
bottom.set_xlabel("time [s]")
bottom.set_ylabel("push up on the cube [N]")
bottom.legend()
figure.tight_layout()
figure.savefig("panda_pick.png", dpi=96)
