"""# Where geoms touch: contacts as MuJoCo finds them

A ramp with a ball, a crate (a tin standing on it), a beam, a drum and an egg resting on it: `m.collide(q)` finds each contact (the two geoms, the point midway between their
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
      <body name="tin" pos="0.02 0 0.245">
        <freejoint/>
        <geom name="tin" type="cylinder" size="0.05 0.05"/>
      </body>
      <body name="egg" pos="-0.75 0 0.058" euler="0 30 0">
        <freejoint/>
        <geom name="egg" type="ellipsoid" size="0.1 0.07 0.06"/>
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
# MuJoCo's contact list at the same configuration: the same geoms in the same order. Given the
# geoms where MuJoCo placed them (`collide_placed`), the same distances, points and frames to the
# last bit or two. Through `collide(q)` the placements come from robodyn's kinematics, which
# round differently (1e-16): all contacts but the tin's agree to 1e-12, and the tin's are
# another four corners of its base's 16-gon, whose largest quadrilaterals tie.
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
    names = [(compiled.geom(int(c.geom[0])).name, compiled.geom(int(c.geom[1])).name) for c in found]
    print("MuJoCo's geoms:", names)
    assert names == [(c["geom1"], c["geom2"]) for c in contacts]
    ids = [compiled.geom(geom["name"]).id for geom in scene.geoms]
    placed = scene.collide_placed(data.geom_xpos[ids], data.geom_xmat[ids])
    show("distances", np.array([c.dist for c in found]), np.array([c["distance"] for c in placed]), 1e-15)
    show("points", np.array([c.pos for c in found]), np.array([c["position"] for c in placed]), 1e-15)
    show("frames", np.array([c.frame.reshape(3, 3) for c in found]), np.array([c["frame"] for c in placed]), 1e-15)
    not_tin = [k for k, c in enumerate(contacts) if c["geom1"] != "tin"]
    show("points but the tin's, through q", np.array([found[k].pos for k in not_tin]),
         np.array([contacts[k]["position"] for k in not_tin]), 1e-12)
