"""# A ball on a height field: terrain contacts

A height field (`<hfield>`) is a terrain sampled on a grid: each cell two triangles, each the
top of a prism down to the field's base, and a geom touches the prisms under it as MuJoCo finds
them ([Height fields](../guide/contacts.md#height-fields)). Two fields here: a slope written as
a grid, down which a ball rolls nearly as the textbook says it rolls down a plane, and a row of
bumps, between which it rolls to and fro. The scenes are stepped as `mj_step` steps them
([Scenes stepped as MuJoCo](../guide/scene-simulation.md)).

    python examples/terrain_ball.py
"""

import matplotlib.pyplot as plt
import numpy as np
import robodyn
from _compare import show

G, R, H = 9.81, 0.1, 0.002
THETA = np.radians(10.0)
HALF, ROWS, COLUMNS = 2.0, 5, 41


def scene(heights: np.ndarray, top: float, start: tuple[float, float]) -> str:
    """A ball of radius R at `start` over a field of `heights` along x (every row the same)."""
    grid = np.tile(heights, (ROWS, 1))
    elevation = " ".join(f"{h:.9g}" for h in grid.ravel())
    return f"""<mujoco>
  <option timestep="{H}" integrator="implicitfast"/>
  <asset><hfield name="terrain" nrow="{ROWS}" ncol="{COLUMNS}" size="{HALF} 0.5 {top} 0.1" elevation="{elevation}"/></asset>
  <worldbody>
    <geom name="terrain" type="hfield" hfield="terrain" rgba="0.45 0.55 0.4 1"/>
    <body name="ball" pos="{start[0]} 0 {start[1]}"><freejoint/>
      <geom name="ball" type="sphere" size="{R}" friction="1 0.005 0.0001" rgba="0.8 0.3 0.2 1"/></body>
  </worldbody>
</mujoco>"""


# %%
# ## Down a slope
#
# Elevations rising evenly along x make a plane of slope tan θ = s₂ / (2 s₀). A solid ball rolls
# down a plane without slipping at a = 5/7 g sin θ. Down the grid of prisms it is 1.7 % slower:
# where it crosses from one triangle to the next it touches the next prism too, by that prism's
# edge, and the push of the edge leans against the motion. MuJoCo's `mj_step` gives the same
# (0.9834 of 5/7 g sin θ on this field; 0.995 with 11 samples along x, 0.971 with 161; 0.999 on
# a plane).
x = np.linspace(-HALF, HALF, COLUMNS)
top = 2 * HALF * np.tan(THETA)
start = 1.5
surface = (start + HALF) / (2 * HALF) * top  # the slope's height under the ball
slope = robodyn.load_mjcf_string(scene(x, top, (start, surface + R / np.cos(THETA) - 1e-4)))
run = robodyn.simulate(slope, slope.neutral(), t_end=1.0, dt=H, integrator="mujoco")
along = np.array([-np.cos(THETA), 0.0, -np.sin(THETA)])  # down the slope
travelled = (run.q[:, :3] - run.q[0, :3]) @ along
late = run.t > 0.2
acceleration = 2 * np.polyfit(run.t[late], travelled[late], 2)[0]
show("acceleration down a 10° slope of prisms, 5/7 g sin θ [m/s²] (to 2 %)", 5 / 7 * G * np.sin(THETA), acceleration,
     2e-2 * 5 / 7 * G * np.sin(THETA))
print(f"  robodyn / textbook: {acceleration / (5 / 7 * G * np.sin(THETA)):.4f}")

# %%
# ## Between bumps
#
# Let go on a bump's flank, the ball rolls down into the valley, up the next bump nearly as high
# as it started, and back: its centre stays one radius from the surface of triangles. It rolls
# along a row of samples (y = 0), so it touches one or two prisms at a time, and up to six where
# it passes over a sample, the corner of six triangles.
bumps = 0.5 + 0.5 * np.cos(2 * np.pi * x / 1.0)
bumpy = robodyn.load_mjcf_string(scene(bumps, 0.15, (0.3, 0.15 * bumps[np.searchsorted(x, 0.3)] + R + 0.02)))
ride = robodyn.simulate(bumpy, bumpy.neutral(), t_end=3.0, dt=H, integrator="mujoco")
touching = np.array([len(bumpy.collide(q)) for q in ride.q])
print(f"between the bumps: from x = {ride.q[0, 0]:.2f} m, between {ride.q[:, 0].min():.2f} and {ride.q[:, 0].max():.2f} m")
# the valley's bottom is at x = 0.5: the ball turns back short of the mirror point 0.7
assert 0.29 < ride.q[:, 0].min() and 0.6 < ride.q[:, 0].max() < 0.7
landed = touching[ride.t > 0.2]
print(f"prisms touched once landed: {landed.min()} to {landed.max()}")
assert 1 <= landed.min() and landed.max() <= 6

figure, (path, count) = plt.subplots(1, 2, figsize=(10, 4))
path.plot(x, 0.15 * bumps, color="0.4", label="the field's surface (samples)")
path.plot(ride.q[:, 0], ride.q[:, 2] - R, label="the ball's centre, less its radius")
path.set(xlim=(0.0, 1.0), xlabel="x [m]", ylabel="height [m]")
path.legend(fontsize="small")
count.step(ride.t, touching, where="post")
count.set(xlabel="time [s]", ylabel="prisms touched", yticks=range(7))
figure.tight_layout()
figure.savefig("terrain_ball.png", dpi=96)
