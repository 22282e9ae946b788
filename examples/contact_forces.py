"""# Where a quadruped's weight goes: contact forces as MuJoCo computes them

Menagerie's Unitree Go2 stands on its scene's floor at its `home` keyframe, its motors driven by
the keyframe's controls. `m.contact_forward_dynamics(q, v, ctrl=...)` finds the contacts, builds
MuJoCo's constraint rows (the joints' dry friction, their limits, the contacts in the file's
elliptic cone) and solves MuJoCo's soft model ([Contacts](../guide/contacts.md), "Contact
forces"). The picture shows each foot's normal and friction force; where MuJoCo is installed,
every row's force and the accelerations are checked against `mj_forward` run to convergence.

    python examples/contact_forces.py
"""


import matplotlib.pyplot as plt
import numpy as np
from _compare import GO2_SCENE, go2_scene, show

import robodyn
from robodyn.plot import stick_figure_points

go2 = go2_scene()
home = go2.keyframe("home")
q, ctrl = np.asarray(home.q), np.asarray(home.ctrl)
v = np.zeros(go2.nv)

# %%
# ## The rows and their forces
#
# One row per joint for its dry friction (`frictionloss` 0.2 N·m), then per contact: the feet
# have condim 6 (the normal, two tangents, spin and two rolls), the elliptic cone's rows. A
# contact's normal force is its first row's; its friction the tangent rows'.
result = go2.contact_forward_dynamics(q, v, ctrl=ctrl)
forces, types = result["forces"], result["row_types"]
print("rows:", {kind: types.count(kind) for kind in dict.fromkeys(types)})
feet = [c for c in result["contacts"] if c["geom2"] in ("FL", "FR", "RL", "RR")]
for contact in feet:
    first = contact["first_row"]
    normal, friction = forces[first], forces[first + 1 : first + 3]
    print(f"{contact['geom2']}: normal {normal:6.2f} N, friction {np.round(friction, 2)} N, "
          f"{contact['distance'] * 1e3:+.2f} mm")

# %%
# ## Newton's second law for the whole robot
#
# The floor is flat, so only the normal rows push up: Σ fₙ = m (g + c̈_z), c the centre of mass,
# whose acceleration at rest is c̈ = J_c q̈. The keyframe sets the feet 18 mm into the floor,
# and the feet's soft contacts (`solimp` 0.015 1 0.022: weak at first) do not yet carry the
# robot: it sinks further before they do.
mass, g = go2.total_mass, -go2.gravity[2]
normals = sum(forces[c["first_row"]] for c in result["contacts"] if c["first_row"] >= 0)
com_acceleration = go2.center_of_mass_jacobian(q) @ result["qdd"]
print(f"Σ fₙ = {normals:.3f} N, m (g + c̈_z) = {mass * (g + com_acceleration[2]):.3f} N")
show("Σ fₙ = m (g + c̈_z)", np.array([mass * (g + com_acceleration[2])]), np.array([normals]), 1e-9)

# %%
# ## The picture
#
# The robot's links (a stick figure) and each foot's contact force, to scale, from the side
# (x forward) and from the front (y to the left).
points, segments = stick_figure_points(go2, q[None, :])
# each foot's body (the calf; `body` counts the world, `body_names` does not)
knees = {geom["name"]: go2.body_names[geom["body"] - 1] for geom in go2.geoms if geom["body"] > 0}
fig, axes = plt.subplots(1, 2, figsize=(9, 3.6), width_ratios=(3, 2))
for axis, (across, label) in zip(axes, ((0, "x (m)"), (1, "y (m)"))):
    for a, b in segments:
        if a > 0:  # not the segment from the world's origin to the base
            axis.plot(points[0, [a, b], across], points[0, [a, b], 2], color="0.35", lw=1.5)
    for contact in feet:
        # the shin, from the knee (its body's origin) to the foot
        knee = go2.frame_pose(q, knees[contact["geom2"]])[:3, 3]
        axis.plot([knee[across], contact["position"][across]], [knee[2], contact["position"][2]], color="0.35", lw=1.5)
        first, frame = contact["first_row"], contact["frame"]
        force = forces[first] * frame[0] + forces[first + 1] * frame[1] + forces[first + 2] * frame[2]
        start = contact["position"]
        axis.annotate("", (start[across] + force[across] * 4e-3, start[2] + force[2] * 4e-3),
                      (start[across], start[2]), arrowprops={"arrowstyle": "->", "color": "tab:red", "lw": 2})
        axis.plot(start[across], start[2], "o", color="black", ms=4)
    axis.axhline(0, color="0.5", lw=2)
    axis.set_aspect("equal")
    axis.set_xlabel(label)
    axis.set_ylabel("z (m)")
axes[0].set_title("side")
axes[1].set_title("front")
fig.suptitle(f"Go2 at home: the feet's contact forces (4 mm per N), Σ fₙ = {normals:.1f} N")
fig.tight_layout()


# %%
# ## The same as MuJoCo's
#
# MuJoCo's `mj_forward` at the same state, its Newton solver run to tolerance 1e-15: the same
# rows in the same order, the same forces and accelerations (MuJoCo stops a step short of the
# optimum on elliptic cones: 1e-7 covers it, measured in the tests).
try:
    import mujoco  # type: ignore[import-untyped]
except ImportError:
    mujoco = None
if mujoco is not None:
    spec = mujoco.MjSpec.from_file(str(GO2_SCENE))
    for geom in [geom for geom in spec.geoms if geom.type == mujoco.mjtGeom.mjGEOM_MESH]:
        spec.delete(geom)
    for mesh in list(spec.meshes):
        spec.delete(mesh)
    compiled = spec.compile()
    compiled.opt.tolerance, compiled.opt.iterations, compiled.opt.ls_iterations = 1e-15, 1000, 100
    data = mujoco.MjData(compiled)
    mujoco.mj_resetDataKeyframe(compiled, data, compiled.key("home").id)
    mujoco.mj_forward(compiled, data)
    show("row forces", data.efc_force.copy(), forces, 1e-7)
    # at rest and upright, MuJoCo's free-joint accelerations (world axes) are robodyn's (body axes)
    show("accelerations", data.qacc.copy(), result["qdd"], 1e-7)
