"""# A ball on a string: a spatial tendon that only pulls

A `<tendon><spatial>` is the length of its path through sites; with `limited="true"` and a range
it becomes a string, which holds the length below its upper end and lets it shorten freely. Here
a ball on two slides (x, z) hangs from a fixed anchor by a 0.5 m string, let go 0.3 m beside the
anchor and level with it: it falls freely, slack string and all, until the string is taut, then
swings on it as a pendulum. The scene is stepped as `mj_step` steps it ([Scenes stepped as
MuJoCo](../guide/scene-simulation.md)); the string is MuJoCo's soft limit row on the tendon
([Tendons](../guide/contacts.md#tendons)).

    python examples/ball_on_a_string.py
"""

import matplotlib.pyplot as plt
import numpy as np
import robodyn
from _compare import show

LENGTH, H = 0.5, 0.002
SCENE = f"""<mujoco>
  <option timestep="{H}" integrator="implicitfast"/>
  <worldbody>
    <site name="anchor" pos="0 0 1"/>
    <body name="ball" pos="0.3 0 1">
      <joint name="x" type="slide" axis="1 0 0"/><joint name="z" type="slide" axis="0 0 1"/>
      <geom type="sphere" size="0.03" mass="0.2" contype="0" conaffinity="0"/><site name="knot"/>
    </body>
  </worldbody>
  <tendon><spatial name="string" limited="true" range="0 {LENGTH}" solreflimit="0.004 1">
    <site site="anchor"/><site site="knot"/></spatial></tendon>
</mujoco>"""

m = robodyn.load_mjcf_string(SCENE)
run = robodyn.simulate(m, m.neutral(), t_end=1.5, dt=H, integrator="mujoco")
length = m.tendon_lengths(run.q)[:, 0]
print(f"the string: {m.tendon_names[0]!r}, {length[0]:.3f} m from the anchor at the start")

# %%
# ## Slack: free fall
#
# While the string is slack nothing but gravity acts. MuJoCo's Euler-type step (v then q) drops
# the ball by g h² n (n + 1) / 2 after n steps: the textbook's sum, step for step.
n = np.array([1, 10, 50, 100, 140])
assert np.all(length[n] < LENGTH)
show("z(n h) − z(0) while slack, n = 1, 10, 50, 100, 140", -9.81 * H**2 * n * (n + 1) / 2, run.q[n, 1], 1e-12)

# %%
# ## Taut: a pendulum
#
# Once taut the limit row holds the string at its length (a soft constraint: it gives by its
# `solreflimit`'s spring, 4 ms here: a few millimetres at the jerk), and the ball swings on
# a circle about the anchor. The figure: the ball's path with the string's reach, and the string's
# length over time.
taut = np.flatnonzero(length > LENGTH - 0.005)
print(f"taut after {run.t[taut[0]]:.3f} s (free fall from rest: {np.sqrt(2 * 0.4 / 9.81):.3f} s)")
stretch = np.max(length) - LENGTH
print(f"the string's largest stretch: {1000 * stretch:.1f} mm")
assert 0 < stretch < 0.005

figure, (path, over_time) = plt.subplots(1, 2, figsize=(10, 4))
turn = np.linspace(-np.pi, 0, 100)
path.plot(LENGTH * np.cos(turn), 1 + LENGTH * np.sin(turn), "k:", label="the string's reach")
path.plot(0.3 + run.q[:, 0], 1 + run.q[:, 1], label="the ball")  # the slides move it from (0.3, 1)
path.plot([0], [1], "ko", label="anchor")
path.set_aspect("equal")
path.set_xlabel("x [m]")
path.set_ylabel("z [m]")
path.legend(loc="upper left", fontsize="small")
over_time.plot(run.t, length)
over_time.axhline(LENGTH, color="k", linestyle=":")
over_time.set_xlabel("time [s]")
over_time.set_ylabel("string length L [m]")
figure.tight_layout()
figure.savefig("ball_on_a_string.png", dpi=96)
