"""# A spring that stays bent: plastic springs

A joint spring with a `springyield` y is ideally elasto-plastic (MuJoCo 4.0's plasticity): bent
past y, its reference follows the joint so the stretch stays y, and the spring's torque never
exceeds k y. Here two hinges, one elastic and one plastic (k = 10 N·m/rad, y = 0.2 rad, damping
1 N·m·s/rad, no gravity), pushed by a motor with 5 N·m for half a second and then let go. The
elastic one swings back to 0; the plastic one comes to rest where its reference was left, bent
for good. Both are stepped as `mj_step` steps them ([plastic
springs](../guide/scene-simulation.md#plastic-springs)).

    python examples/plastic_spring.py
"""

import matplotlib.pyplot as plt
import numpy as np
import robodyn
from _compare import show

SCENE = """<mujoco>
  <compiler angle="radian"/>
  <option timestep="0.002" gravity="0 0 0"/>
  <worldbody>
    <body name="arm"><joint name="hinge" axis="0 0 1" stiffness="10" damping="1"{yield_}/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="1"/></body>
  </worldbody>
  <actuator><motor name="push" joint="hinge"/></actuator>
</mujoco>"""
K, Y = 10.0, 0.2

elastic = robodyn.load_mjcf_string(SCENE.format(yield_=""))
# (a ModelWarning says that robodyn's other integrators keep the spring elastic)
plastic = robodyn.load_mjcf_string(SCENE.format(yield_=f' springyield="{Y}"'))
print(f"plastic state: {elastic.nplastic} values elastic, {plastic.nplastic} plastic (the hinge's reference)")


def push(t: float, q: np.ndarray, v: np.ndarray) -> list[float]:
    """5 N·m for half a second, then nothing."""
    return [5.0 if t < 0.5 else 0.0]


# %%
# ## Bent for good
#
# Six seconds, sampled every 10 ms. While pushed, the plastic hinge's stretch q − r never exceeds
# y, so its spring's torque never exceeds k y = 2 N·m; once let go, the damper brings it to rest
# at its moved reference, where the spring is relaxed.
runs = {
    name: robodyn.simulate(model, model.neutral(), t_end=6.0, dt=0.01, integrator="mujoco", ctrl=push)
    for name, model in (("elastic", elastic), ("plastic", plastic))
}
bent = runs["plastic"]
stretch = bent.q[:, 0] - bent.plastic[:, 0]
print(f"largest stretch {np.max(np.abs(stretch)):.6f} rad (yield {Y} rad)")
assert np.max(np.abs(stretch)) <= Y + 1e-12
show("at rest: the angle is the moved reference", bent.plastic[-1], bent.q[-1], 1e-4)
show("the elastic hinge is back at 0", [0.0], runs["elastic"].q[-1], 1e-3)

# %%
# ## The figure
#
# The angle of each hinge, the plastic one's reference dashed, and the spring torques −k (q − r)
# (r = 0 for the elastic one): the plastic spring's is capped at ±k y.
figure, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7, 5))
for name, run in runs.items():
    top.plot(run.t, run.q[:, 0], label=f"{name} hinge")
    reference = run.plastic[:, 0] if run.plastic.shape[1] else 0.0
    bottom.plot(run.t, -K * (run.q[:, 0] - reference), label=name)
top.plot(bent.t, bent.plastic[:, 0], "k--", label="its spring's reference")
top.set_ylabel("angle [rad]")
top.legend()
bottom.axhline(K * Y, color="gray", lw=0.5)
bottom.axhline(-K * Y, color="gray", lw=0.5)
bottom.set_xlabel("time [s]")
bottom.set_ylabel("spring torque [N·m]")
bottom.legend()
figure.tight_layout()
figure.savefig("plastic_spring.png", dpi=96)
print(f"rest angle: {bent.q[-1, 0]:.4f} rad plastic, {runs['elastic'].q[-1, 0]:.4f} rad elastic")
