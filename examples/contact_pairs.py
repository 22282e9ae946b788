"""# A MuJoCo scene: which geoms may touch, and how

A legged robot on a floor, written in MJCF as a MuJoCo user writes a scene: a `<default>` class
for the feet, an explicit `<pair>` for one foot, an `<exclude>`, and `<option>`s (the
[Loading models](../guide/loading-models.md) guide, "Scenes"). robodyn reads every geom as a
collision shape with its contact parameters, the options, and which pairs of geoms MuJoCo checks
for contact; the picture shows them. Where MuJoCo is installed, the pairs are checked against
the ones its collision driver finds when every margin is 100 m (so that each pair it checks is
in contact).

    python examples/contact_pairs.py
"""

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import ListedColormap
from _compare import show

import robodyn

SCENE = """<mujoco model="walker">
  <option timestep="0.001" cone="elliptic" impratio="10"/>
  <default>
    <geom contype="1" conaffinity="1"/>
    <default class="foot"><geom friction="1.2" condim="6" solref="0.01 1" priority="1"/></default>
    <default class="visual"><geom contype="0" conaffinity="0"/></default>
  </default>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1"/>
    <body name="torso" pos="0 0 0.45">
      <freejoint/>
      <geom name="torso" type="box" size="0.25 0.1 0.05"/>
      <geom name="head" type="sphere" size="0.06" pos="0.3 0 0.05" class="visual"/>
      <body name="front_thigh" pos="0.2 0 0">
        <joint name="front_hip" axis="0 1 0"/>
        <geom name="front_thigh" type="capsule" fromto="0 0 0 0 0 -0.2" size="0.025"/>
        <body name="front_shin" pos="0 0 -0.2">
          <joint name="front_knee" axis="0 1 0"/>
          <geom name="front_shin" type="capsule" fromto="0 0 0 0 0 -0.2" size="0.02"/>
          <geom name="front_foot" type="sphere" size="0.03" pos="0 0 -0.2" class="foot"/>
        </body>
      </body>
      <body name="hind_thigh" pos="-0.2 0 0">
        <joint name="hind_hip" axis="0 1 0"/>
        <geom name="hind_thigh" type="capsule" fromto="0 0 0 0 0 -0.2" size="0.025"/>
        <body name="hind_shin" pos="0 0 -0.2">
          <joint name="hind_knee" axis="0 1 0"/>
          <geom name="hind_shin" type="capsule" fromto="0 0 0 0 0 -0.2" size="0.02"/>
          <geom name="hind_foot" type="sphere" size="0.03" pos="0 0 -0.2" class="foot"/>
        </body>
      </body>
    </body>
  </worldbody>
  <contact>
    <pair geom1="floor" geom2="hind_foot" condim="3" friction="0.5 0.5"/>
    <exclude body1="front_shin" body2="hind_shin"/>
  </contact>
</mujoco>"""

scene = robodyn.load_mjcf_string(SCENE)

# %%
# ## What the file says
#
# The options, and each geom's filter bits and contact parameters: the feet take their class's
# friction, `condim` and `solref`; the head is only drawn (its bits are zero).
print(scene.options)
for geom in scene.geoms:
    print(f"{geom['name']:>12}: contype {geom['contype']} conaffinity {geom['conaffinity']} "
          f"condim {geom['condim']} friction {geom['friction']} solref {geom['solref']}")
print("explicit pair:", scene.contact_pairs[0]["geom1"], scene.contact_pairs[0]["geom2"],
      "friction", scene.contact_pairs[0]["friction"])

# %%
# ## Which pairs MuJoCo checks
#
# Besides the explicit pair, MuJoCo checks every pair of geoms on different moving bodies that
# are not parent and child, not excluded, and whose bits match. A thigh never touches its own
# shin or the torso (parent and child), the two shins are excluded, the head touches nothing.
names = [geom["name"] for geom in scene.geoms]
index = {name: k for k, name in enumerate(names)}
checked = np.zeros((len(names), len(names)))
for one, other in scene.contact_candidates:
    checked[index[one], index[other]] = checked[index[other], index[one]] = 1
for pair in scene.contact_pairs:
    checked[index[pair["geom1"]], index[pair["geom2"]]] = checked[index[pair["geom2"]], index[pair["geom1"]]] = 2
print(len(scene.contact_candidates), "dynamic pairs,", len(scene.contact_pairs), "explicit")

# the rules, written out: different moving bodies (each geom's `body`), neither the other's
# parent (the world aside), the bodies not excluded, not an explicit pair, the bits matching
parents = [0, *(p + 1 for p in scene.body_parents)]  # into ["world"] + body_names
excluded = {frozenset(pair) for pair in scene.contact_excludes}
explicit = {frozenset((p["geom1"], p["geom2"])) for p in scene.contact_pairs}
by_rules = np.zeros_like(checked)
for i, first in enumerate(scene.geoms):
    for j, second in enumerate(scene.geoms):
        family = first["body"] != 0 and second["body"] != 0 and (
            parents[first["body"]] == second["body"] or parents[second["body"]] == first["body"])
        bits = first["contype"] & second["conaffinity"] or second["contype"] & first["conaffinity"]
        if (first["body"] != second["body"] and not family and bits
                and frozenset((first["source_body"], second["source_body"])) not in excluded
                and frozenset((first["name"], second["name"])) not in explicit):
            by_rules[i, j] = 1
show("pairs checked (the rules written out vs robodyn)", by_rules, np.where(checked == 1, 1, 0), 0.0)

fig, ax = plt.subplots(figsize=(6.5, 5.5))
ax.imshow(checked, cmap=ListedColormap(["white", "tab:blue", "tab:orange"]), vmin=0, vmax=2)
ax.set_xticks(range(len(names)), names, rotation=60, ha="right")
ax.set_yticks(range(len(names)), names)
ax.set_title("geom pairs checked for contact\nblue: MuJoCo's filters pass them, orange: explicit <pair>")
fig.tight_layout()

# %%
# ## The same pairs as MuJoCo's collision driver
#
# With every margin overridden to 100 m, each pair MuJoCo checks is found in contact.
try:
    import mujoco  # type: ignore[import-untyped]
except ImportError:
    mujoco = None
if mujoco is not None:
    compiled = mujoco.MjModel.from_xml_string(SCENE)
    compiled.opt.enableflags |= int(mujoco.mjtEnableBit.mjENBL_OVERRIDE)
    compiled.opt.o_margin = 100.0
    data = mujoco.MjData(compiled)
    mujoco.mj_forward(compiled, data)
    found = {tuple(sorted((int(c.geom1), int(c.geom2)))) for c in data.contact[: data.ncon]}
    ours = {tuple(sorted((index[a], index[b]))) for a, b in scene.contact_candidates}
    ours |= {tuple(sorted((index[p["geom1"]], index[p["geom2"]]))) for p in scene.contact_pairs}
    print("MuJoCo checks the same pairs:", found == ours)
    assert found == ours
