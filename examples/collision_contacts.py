"""# Where geoms touch: contacts as MuJoCo finds them

A ramp with a ball, a crate, a beam and a drum resting on it: `m.collide(q)` finds each contact (the two geoms, the point midway between their
surfaces, the frame whose first row is the normal, and the signed distance) as MuJoCo's
collision detection does ([Contacts](../guide/contacts.md)). The picture draws the points and
normals; where MuJoCo is installed, every contact is checked against `mj_collision`.

    python examples/collision_contacts.py
"""

import matplotlib.pyplot as plt
import numpy as np
from _compare import show

import robodyn

SCENE = """<mujoco model="contacts">
  <worldbody>
    <geom name="ramp" type="plane" size="1 1 0.1" euler="0 12 0"/>
    <!-- the bodies set on the ramp, each sunk a few millimetres into it -->
    <frame euler="0 12 0">
      <body name="ball" pos="-0.45 0 0.085">
        <freejoint/>
        <geom name="ball" type="sphere" size="0.09"/>
      </body>
      <body name="crate" pos="0 0 0.097">
        <freejoint/>
        <geom name="crate" type="box" size="0.15 0.1 0.1"/>
      </body>
      <body name="beam" pos="0.4 0 0.036" euler="90 0 0">
        <freejoint/>
        <geom name="beam" type="capsule" size="0.04 0.25"/>
      </body>
      <body name="drum" pos="0.75 0 0.058">
        <freejoint/>
        <geom name="drum" type="cylinder" size="0.1 0.06"/>
      </body>
    </frame>
  </worldbody>
</mujoco>"""

scene = robodyn.load_mjcf_string(SCENE)
q = scene.neutral()

# %%
# ## The contacts
#
# One line per contact: the two geoms (the one of lower MuJoCo type first: plane, sphere,
# capsule, ellipsoid, cylinder, box), the signed distance (negative: they overlap) and the
# normal, from the first geom to the second.
contacts = scene.collide(q)
for contact in contacts:
    print(f"{contact['geom1']:>5} - {contact['geom2']:<5} distance {contact['distance']:+.4f} m "
          f"at {np.round(contact['position'], 4)} normal {np.round(contact['normal'], 3)}")

# %%
# ## The picture
#
# Each contact point and its normal (scaled by 0.1 m), on the geoms' outlines in the x-z plane.
fig, ax = plt.subplots(figsize=(7, 4))
slope = np.tan(np.radians(12))
ax.plot([-0.7, 0.8], [0.7 * slope, -0.8 * slope], color="0.4", lw=2, label="ramp")
for contact in contacts:
    x, _, z = contact["position"]
    nx, _, nz = contact["normal"] * 0.1
    ax.annotate("", (x + nx, z + nz), (x, z), arrowprops={"arrowstyle": "->", "color": "tab:red"})
    ax.plot(x, z, "o", color="tab:red", ms=4)
ax.set_aspect("equal")
ax.set_xlabel("x (m)")
ax.set_ylabel("z (m)")
ax.set_title(f"{len(contacts)} contacts: points and normals (0.1 m)")
fig.tight_layout()

# %%
# ## The same contacts as MuJoCo's
#
# MuJoCo's contact list at the same configuration: the same geoms in the same order, and the
# same distances, points and frames.
try:
    import mujoco  # type: ignore[import-untyped]
except ImportError:
    mujoco = None
if mujoco is not None:
    # MuJoCo starts at its qpos0, robodyn's neutral configuration
    compiled = mujoco.MjModel.from_xml_string(SCENE)
    data = mujoco.MjData(compiled)
    mujoco.mj_kinematics(compiled, data)
    mujoco.mj_collision(compiled, data)
    found = data.contact[: data.ncon]
    print("MuJoCo's geoms:", [(compiled.geom(int(c.geom[0])).name, compiled.geom(int(c.geom[1])).name) for c in found])
    assert [(compiled.geom(int(c.geom[0])).name, compiled.geom(int(c.geom[1])).name) for c in found] == [
        (c["geom1"], c["geom2"]) for c in contacts]
    show("distances", np.array([c.dist for c in found]), np.array([c["distance"] for c in contacts]), 1e-12)
    show("points", np.array([c.pos for c in found]), np.array([c["position"] for c in contacts]), 1e-12)
    show("frames", np.array([c.frame.reshape(3, 3) for c in found]), np.array([c["frame"] for c in contacts]), 1e-12)
