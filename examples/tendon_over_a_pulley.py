"""# A tendon over a pulley: a path that wraps around a cylinder

A `<tendon><spatial>` may pass a `<geom>` between two of its sites: where the straight path would
cut through the geom (a sphere or a cylinder), it runs to a tangent point instead, over the
surface, and off at a second tangent point. Here a cord runs from an anchor on the ceiling over a
fixed pulley (a cylinder of radius 5 cm) to the tip of a swinging arm; a `sidesite` above the
pulley keeps it over the top, even where the straight line would pass beneath. Its length is the
two straight pieces plus the arc, the pulley's radius times the angle of wrap: the closed form
checked below. A motor pulls on the cord ([Tendons](../guide/contacts.md#tendons)).

    python examples/tendon_over_a_pulley.py
"""

import matplotlib.pyplot as plt
import numpy as np
import robodyn
from _compare import show

RADIUS, H = 0.05, 0.002
SCENE = f"""<mujoco>
  <option timestep="{H}" integrator="implicitfast"/>
  <default><geom contype="0" conaffinity="0"/></default>
  <worldbody>
    <site name="anchor" pos="-0.3 0 0.9"/>
    <geom name="pulley" type="cylinder" size="{RADIUS} 0.02" pos="0 0 1" euler="90 0 0"/>
    <site name="over" pos="0 0 1.2"/>
    <body name="arm" pos="0.3 0 1"><joint name="swing" axis="0 1 0" damping="0.5"/>
      <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.02" mass="0.5"/>
      <site name="tip" pos="0.4 0 0"/></body>
  </worldbody>
  <tendon><spatial name="cord"><site site="anchor"/><geom geom="pulley" sidesite="over"/>
    <site site="tip"/></spatial></tendon>
  <actuator><motor name="winch" tendon="cord" gear="-1"/></actuator>
</mujoco>"""

m = robodyn.load_mjcf_string(SCENE)

# %%
# ## The cord's length: straight pieces and the arc
#
# Seen along the pulley's axis, each end p sees the circle's tangent point at an angle
# acos(r/|p|) from its own direction, the straight piece being √(|p|² − r²) long; the arc between
# the two tangent points is r times the angle between them. The cord over a range of the arm's
# angle, against that closed form:
angles = np.linspace(-0.8, 0.6, 8)
q = np.array([[a] for a in angles])
length = m.tendon_lengths(q)[:, 0]
anchor = np.array([-0.3, -0.1])
tips = np.stack([0.3 + 0.4 * np.cos(angles), -0.4 * np.sin(angles)], axis=1)  # (x, z) about the pulley


def reach(e: np.ndarray) -> float:
    """The angle between an end's direction and its tangent point: acos(r/|e|)."""
    return float(np.arccos(RADIUS / np.linalg.norm(e)))


def tangent_angles(p: np.ndarray, q: np.ndarray) -> tuple[float, float]:
    """The angles of the tangent points of a cord from p over the top of the circle to q."""
    # the ends' directions: p's in [0, 2π) (left of the pulley), q's in (−π, π] (right of it)
    from_p = float(np.mod(np.arctan2(p[1], p[0]), 2 * np.pi)) - reach(p)
    return from_p, float(np.arctan2(q[1], q[0])) + reach(q)


def over_the_top(p: np.ndarray, q: np.ndarray) -> float:
    """Straight pieces and arc of a cord from p over the top of the circle to q (both outside)."""
    from_p, to_q = tangent_angles(p, q)
    pieces = float(np.sqrt(p @ p - RADIUS**2) + np.sqrt(q @ q - RADIUS**2))
    return pieces + RADIUS * (from_p - to_q)


show("cord length L(θ): robodyn vs straight pieces + r · wrap angle", [over_the_top(anchor, tip) for tip in tips], length, 1e-12)

# %%
# ## Holding the arm
#
# The motor pulls the cord in with a force f: the torque on the arm is Jᵀ f, J = ∂L/∂θ the
# cord's moment arm, which changes as the arm swings. Let go level under a steady pull of 2 N,
# the arm swings down until the cord's moment balances its weight.
run = robodyn.simulate(m, m.neutral(), t_end=3.0, dt=H, integrator="mujoco", ctrl=[2.0])
lengths = m.tendon_lengths(run.q)[:, 0]
print(f"the arm settles at θ = {run.q[-1, 0]:.3f} rad, the cord {lengths[-1]:.3f} m long")
assert abs(run.v[-1, 0]) < 0.05 and np.pi / 2 < run.q[-1, 0] < np.pi

figure, (shape, over_time) = plt.subplots(1, 2, figsize=(10, 4))
turn = np.linspace(0, 2 * np.pi, 100)
shape.fill(RADIUS * np.cos(turn), 1 + RADIUS * np.sin(turn), color="0.7", label="pulley")
for k, color in [(0, "C0"), (len(run.t) - 1, "C1")]:
    theta = run.q[k, 0]
    tip = np.array([0.3 + 0.4 * np.cos(theta), 1 - 0.4 * np.sin(theta)])
    shape.plot([0.3, tip[0]], [1, tip[1]], color=color, linewidth=3, label=f"arm at t = {run.t[k]:.1f} s")
    # the cord: anchor, the arc between the tangent points, the tip (about the pulley's centre)
    arc = np.linspace(*tangent_angles(anchor, tip - [0, 1]), 30)
    cord = np.vstack([anchor, RADIUS * np.stack([np.cos(arc), np.sin(arc)], axis=1), tip - [0, 1]])
    shape.plot(cord[:, 0], 1 + cord[:, 1], color=color, linestyle=":", label="cord")
shape.set_aspect("equal")
shape.set_xlabel("x [m]")
shape.set_ylabel("z [m]")
shape.legend(loc="lower left", fontsize="small")
over_time.plot(run.t, lengths)
over_time.set_xlabel("time [s]")
over_time.set_ylabel("cord length L [m]")
figure.tight_layout()
figure.savefig("tendon_over_a_pulley.png", dpi=96)
