"""# A servo with a lag: actuators with activation dynamics

An actuator whose `dyntype` is not none has a state of its own, its activation w (MuJoCo's `act`),
which its force takes in place of the control. Here one hinge, two scenes: a `position` servo
(k_p = 20, k_v = 2) told to go to 1 rad at once, and the same servo with `timeconst="0.1"`, whose
setpoint w follows the command through a first-order filter, ẇ = (u − w)/τ, integrated exactly
(MuJoCo's `filterexact`): w(t) = u (1 − e^(−t/τ)). Both are stepped as `mj_step` steps them
([Scenes stepped as MuJoCo](../guide/scene-simulation.md)); the lagged setpoint starts the arm
gently.

    python examples/actuator_activation.py
"""

import matplotlib.pyplot as plt
import numpy as np
import robodyn
from _compare import show

SCENE = """<mujoco>
  <compiler angle="radian"/>
  <option timestep="0.002" integrator="implicitfast" gravity="0 0 0"/>
  <worldbody>
    <body name="arm"><joint name="hinge" axis="0 0 1"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="1"/></body>
  </worldbody>
  <actuator><position name="servo" joint="hinge" kp="20" kv="2"{lag}/></actuator>
</mujoco>"""
TAU = 0.1

plain = robodyn.load_mjcf_string(SCENE.format(lag=""))
lagged = robodyn.load_mjcf_string(SCENE.format(lag=f' timeconst="{TAU}"'))
print(f"activations: {plain.na} without the lag, {lagged.na} with it")

# %%
# ## The filter's closed form
#
# One second of 2 ms steps under the command u = 1 rad, sampled every 10 ms: the stepped setpoint
# is the textbook's first-order response at every sample.
runs = {
    name: robodyn.simulate(model, model.neutral(), t_end=1.0, dt=0.01, integrator="mujoco", ctrl=[1.0])
    for name, model in (("servo", plain), ("servo with a 0.1 s lag", lagged))
}
lag = runs["servo with a 0.1 s lag"]
show("w(t) = u (1 − e^(−t/τ)) at 0.1, 0.2, 0.5 s", 1 - np.exp(-np.array([0.1, 0.2, 0.5]) / TAU),
     lag.act[[10, 20, 50], 0], 1e-12)

# %%
# ## The response
#
# The plain servo's torque jumps to k_p u = 20 N·m; the lagged one's rises with its setpoint, and
# the arm arrives later and gentler. The figure: the angle of each, the lagged setpoint dashed, and
# the torques.
figure, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7, 5))
for name, run in runs.items():
    top.plot(run.t, run.q[:, 0], label=name)
    bottom.plot(run.t, run.tau[:, 0], label=name)
top.plot(lag.t, lag.act[:, 0], "k--", label="the lagged setpoint w")
top.set_ylabel("angle [rad]")
top.legend()
bottom.set_xlabel("time [s]")
bottom.set_ylabel("actuator torque [N·m]")
figure.tight_layout()
figure.savefig("actuator_activation.png", dpi=96)
print(f"peak torque: {np.max(np.abs(runs['servo'].tau)):.1f} N·m plain, {np.max(np.abs(lag.tau)):.1f} N·m lagged")
