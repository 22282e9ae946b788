"""# A crate on an incline, stepped as MuJoCo steps it

A crate of friction μ = 0.5 on slopes of 0.5 to 1.5 times the friction angle atan μ (26.6°):
below it the crate sticks, above it it slides with Coulomb's a = g (sin θ − μ cos θ).
`robodyn.simulate(..., integrator="mujoco")` steps the scene as MuJoCo's `mj_step` does
([Scenes stepped as MuJoCo](../guide/scene-simulation.md)): MuJoCo's soft contacts, its
elliptic friction cone and its Euler integrator at the file's 2 ms step. The slope is the floor
with gravity turned by θ (the same physics in the slope's axes). Where MuJoCo is installed, the
runs are checked against `mj_step`'s, step by step.

    python examples/crate_on_incline.py
"""

import matplotlib.pyplot as plt
import numpy as np
from _compare import show

import robodyn

MU, G = 0.5, 9.81
FRICTION_ANGLE = float(np.arctan(MU))
FRACTIONS = (0.5, 0.9, 1.1, 1.3, 1.5)


def scene(theta: float) -> str:
    """A flat crate (0.2 × 0.2 × 0.04 m, 1.6 kg) resting on the floor, gravity turned by θ."""
    gravity = f"{float(G * np.sin(theta))!r} 0 {float(-G * np.cos(theta))!r}"
    return f"""<mujoco><option gravity="{gravity}" cone="elliptic"/>
      <worldbody><geom name="slope" type="plane" size="0 0 1" friction="{MU} 0.005 0.0001"/>
        <body name="crate" pos="0 0 0.0199"><freejoint name="crate"/>
          <geom name="crate" type="box" size="0.1 0.1 0.02" friction="{MU} 0.005 0.0001"/></body>
      </worldbody></mujoco>"""


# %%
# ## One second on each slope
#
# A run starts at rest (`v0` zeros), records every 10 ms, and holds `ctrl` (none here). The crate
# stays level, so its speed down the slope is its body-axes x velocity.
runs = {}
for fraction in FRACTIONS:
    theta = fraction * FRICTION_ANGLE
    model = robodyn.load_mjcf_string(scene(theta))
    run = robodyn.simulate(model, model.neutral(), t_end=1.0, dt=0.01, integrator="mujoco")
    runs[fraction] = (theta, run)
    late = run.t >= 0.5
    slope = np.polyfit(run.t[late], run.v[late, 0], 1)[0]
    coulomb = max(0.0, G * (np.sin(theta) - MU * np.cos(theta)))
    print(f"θ = {np.degrees(theta):4.1f}°: a = {slope:6.3f} m/s², Coulomb {coulomb:6.3f} m/s²")

# %%
# ## Coulomb's law, as soft friction follows it
#
# Below the friction angle the crate does not move (soft friction lets it creep by less than a
# micrometre per second); above it, the acceleration is Coulomb's to within 4 %: MuJoCo's friction
# is a stiff spring-damper, not a rigid law (the tests measure the same in MuJoCo).
for fraction in (1.1, 1.5):
    theta, run = runs[fraction]
    late = run.t >= 0.5
    slope = np.polyfit(run.t[late], run.v[late, 0], 1)[0]
    show(f"a at {fraction} atan μ (m/s²)", G * (np.sin(theta) - MU * np.cos(theta)), slope, 0.05)

fig, axis = plt.subplots(figsize=(7, 3.8))
for fraction, (theta, run) in runs.items():
    line, = axis.plot(run.t, run.v[:, 0], lw=2, label=f"θ = {fraction} atan μ ({np.degrees(theta):.1f}°)")
    coulomb = max(0.0, G * (np.sin(theta) - MU * np.cos(theta)))
    axis.plot(run.t, coulomb * run.t, ls=":", color=line.get_color())
axis.set_xlabel("t (s)")
axis.set_ylabel("speed down the slope (m/s)")
axis.set_title("A crate on an incline (μ = 0.5) stepped as mj_step; dotted: Coulomb")
axis.legend(fontsize=8)
fig.tight_layout()

# %%
# ## The same steps as MuJoCo's
#
# `mj_step` from the same state, MuJoCo's solver run to convergence: the crate's state after
# each of the 500 steps (recorded every 10 ms), the largest difference over all of them shown
# with the last one. They agree to round-off here; with elliptic cones MuJoCo's Newton may stop a
# step short of the optimum, which the tests bound at 1e-6 over 100 steps (measured 6e-9).
try:
    import mujoco  # type: ignore[import-untyped]
except ImportError:
    mujoco = None
if mujoco is not None:
    theta, run = runs[1.3]
    compiled = mujoco.MjModel.from_xml_string(scene(theta))
    compiled.opt.tolerance, compiled.opt.iterations, compiled.opt.ls_iterations = 1e-15, 1000, 100
    data = mujoco.MjData(compiled)
    states = []
    for step in range(500):
        mujoco.mj_step(compiled, data)
        if (step + 1) % 5 == 0:
            states.append(data.qpos[:3].copy())
    largest = float(np.max(np.abs(np.array(states) - run.q[1:, :3])))
    print(f"largest difference over the 100 samples: {largest:.1e} m")
    show("crate's position at t = 1 s (m)", states[-1], run.q[-1, :3], 1e-6)
