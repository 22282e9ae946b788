"""# A die thrown on a table: mesh contacts

An eight-sided die written as its six corners only (`<mesh vertex=...>` without faces: the mesh
is their convex hull, an octahedron, as in MuJoCo) is let go spinning above a table, lands,
tumbles and comes to rest on one of its triangular faces. Its contacts are found on its hull as MuJoCo finds them
([Meshes](../guide/contacts.md#meshes)): against the floor, the deepest corner and the corners
of the face there that lie below the floor. The scene is stepped as `mj_step` steps it
([Scenes stepped as MuJoCo](../guide/scene-simulation.md)).

    python examples/mesh_die.py
"""

import matplotlib.pyplot as plt
import numpy as np
import robodyn
from _compare import show

R, MASS, H = 0.02, 0.01, 0.002
CORNERS = " ".join(f"{x:g}" for axis in np.eye(3) for sign in (1, -1) for x in sign * R * axis)
SCENE = f"""<mujoco>
  <option timestep="{H}" integrator="implicitfast"/>
  <asset><mesh name="octahedron" vertex="{CORNERS}"/></asset>
  <worldbody>
    <geom name="table" type="plane" size="0 0 1"/>
    <body name="die" pos="0 0 0.05" euler="20 35 10">
      <freejoint name="die"/>
      <geom name="die" type="mesh" mesh="octahedron" mass="{MASS}"/>
    </body>
  </worldbody>
</mujoco>"""

m = robodyn.load_mjcf_string(SCENE)
v0 = np.array([0.0, 0.0, 0.0, 0.0, 30.0, 8.0])  # let go spinning: (linear; angular), body axes
run = robodyn.simulate(m, m.neutral(), v0, t_end=0.6, dt=H, integrator="mujoco")
height = run.q[:, 2]
touching = np.array([len(m.collide(q)) for q in run.q])
print(f"the die touches the table after {run.t[np.argmax(touching > 0)]:.3f} s")

# %%
# ## In the air
#
# Until it touches, only gravity acts: MuJoCo's step (v, then q with the new v) lowers the die by
# g h² n (n + 1) / 2 after n steps, the textbook's sum.
n = np.array([1, 10, 20, 30])
assert np.all(touching[n] == 0)
show("z(n h) − z(0) in the air, n = 1, 10, 20, 30", -9.81 * H**2 * n * (n + 1) / 2, height[n] - height[0], 1e-12)

# %%
# ## At rest on a face
#
# An octahedron rests on a triangle: three contacts, the face's corners, and their normal forces
# carry its weight m g. Its centre then lies above the face's centre, R/√3 over the table (the
# inradius of the regular octahedron of circumradius R), less the few tenths of a millimetre the
# soft contacts give.
q_end, v_end = run.q[-1], run.v[-1]
rest = m.contact_forward_dynamics(q_end, v_end)
normal = sum(contact["force"][0] for contact in rest["contacts"])
print(f"at rest: {len(rest['contacts'])} contacts, speed {np.linalg.norm(v_end):.1e}")
assert len(rest["contacts"]) == 3 and np.linalg.norm(v_end) < 1e-3
show("the table's push on the die, Σ normal forces = m g [N]", MASS * 9.81, normal, 1e-6)
show("its centre's height R/√3 [m] (to 0.5 mm)", R / np.sqrt(3), height[-1], 5e-4)

figure, (path, contacts) = plt.subplots(1, 2, figsize=(10, 4))
path.plot(run.t, 1000 * height)
path.axhline(1000 * R / np.sqrt(3), color="k", linestyle=":", label="resting on a face: R/√3")
path.axhline(1000 * R, color="k", linestyle="--", label="standing on a corner: R")
path.set_xlabel("time [s]")
path.set_ylabel("height of the centre [mm]")
path.legend(fontsize="small")
contacts.step(run.t, touching, where="post")
contacts.set_xlabel("time [s]")
contacts.set_ylabel("contacts with the table")
contacts.set_yticks(range(5))
figure.tight_layout()
figure.savefig("mesh_die.png", dpi=96)
