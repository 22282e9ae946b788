"""# Constrained dynamics: feet on the ground, a four-bar, Cassie's legs

Three robots under constraints (the [Constrained dynamics](../guide/constraints.md) guide):
Solo12 standing on its four feet, where the feet's forces must carry its weight; a four-bar
linkage spinning with its loop held closed; and Cassie falling with the rods of its legs closing
four loops. Solo12 comes from example-robot-data (`pip install 'robodyn[robots]'`), Cassie from
the repository's `testdata/`.

    python examples/constrained_dynamics.py
"""

import warnings
from pathlib import Path

import _compare
import matplotlib.pyplot as plt
import numpy as np
from _compare import show

import robodyn
from robodyn.plot import stick_figure_points

# the repository's root: examples/ lies beside testdata/
REPOSITORY = Path(_compare.__file__).resolve().parents[1]

# %%
# ## Solo12 standing: the contact forces
#
# Each foot is a `PointAnchor` (3 rows, world axes): held where it stands. At rest (q̇ = 0, q̈ = 0)
# `constrained_inverse_dynamics` gives the torques of the twelve leg joints and the forces the
# ground exerts on the feet. Four feet give twelve forces for the six equations of the base, so
# they are not unique: robodyn returns those of least norm. Whichever they are, they carry the
# robot: their sum is m g, and their moment about the centre of mass is zero.
solo = robodyn.load("solo12.urdf", floating_base=True)
FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")
stance = solo.neutral()
stance[7:] = [0.0, 0.8, -1.6, 0.0, 0.8, -1.6, 0.0, -0.8, 1.6, 0.0, -0.8, 1.6]
stance[2] = -min(solo.frame_pose(stance, foot)[2, 3] for foot in FEET)  # the feet on z = 0
feet = [robodyn.PointAnchor(foot) for foot in FEET]
rest = np.zeros(solo.nv)
standing = solo.constrained_inverse_dynamics(stance, rest, rest, feet)
forces = standing["forces"].reshape(4, 3)
weight = solo.total_mass * -solo.gravity[2]
show("sum of the feet's forces = (0, 0, m g) (N)", [0.0, 0.0, weight], forces.sum(axis=0))
soles = np.array([solo.frame_pose(stance, foot)[:3, 3] for foot in FEET])
moment = np.cross(soles - solo.center_of_mass(stance), forces).sum(axis=0)
show("their moment about the centre of mass (N m)", np.zeros(3), moment)

# %%
# Forward dynamics under the torques inverse dynamics found: the robot stays still, held by the
# same forces.
held = solo.constrained_forward_dynamics(stance, rest, standing["tau"], feet)
show("q̈ under those torques (rad/s², m/s²)", np.zeros(solo.nv), held["qdd"], 1e-9)
show("the same forces (N)", standing["forces"], held["forces"], 1e-9)

# %%
# The body leaning forwards and back over feet that stay where they are (the legs found by
# Newton's method on the feet's positions): the front feet take more of the weight as the centre
# of mass moves over them. One call computes the forces of all the leans at once.
leans = np.linspace(-0.06, 0.06, 25)
postures = np.tile(stance, (len(leans), 1))
postures[:, 0] += leans
targets = [robodyn.PointAnchor(foot, offset2=sole) for foot, sole in zip(FEET, soles)]
for posture in postures:
    for _ in range(20):
        miss = np.concatenate([solo.frame_pose(posture, foot)[:3, 3] - sole for foot, sole in zip(FEET, soles)])
        posture[7:] -= np.linalg.solve(solo.constraint_jacobian(posture, targets)[:, 6:], miss)
misses = [solo.frame_pose(posture, foot)[:3, 3] - sole for posture in postures for foot, sole in zip(FEET, soles)]
show("every lean: the feet where they stood, largest miss along x, y, z (m)", np.zeros(3), np.abs(misses).max(axis=0), 1e-12)
still = np.zeros((len(leans), solo.nv))
leaning = solo.constrained_inverse_dynamics(postures, still, still, feet)["forces"].reshape(len(leans), 4, 3)
totals = leaning[:, :, 2].sum(axis=1)
show("every lean: the vertical forces' smallest and largest sum = m g (N)", [weight, weight], [totals.min(), totals.max()])

# %%
# The robot leaning 4 cm forwards, the ground's force on each foot drawn as an arrow (the cross:
# the centre of mass over the ground), and the vertical forces at every lean.
shown = int(np.argmin(np.abs(leans - 0.04)))
figure = plt.figure(figsize=(10, 4.2))
axis = figure.add_subplot(1, 2, 1, projection="3d")
points, segments = stick_figure_points(solo, postures[shown])
for a, b in segments:
    if a > 0:  # not the segment from the world's origin to the base
        axis.plot(*points[0, [a, b]].T, color="0.35", lw=1.5)
scale = 0.6 / weight  # m per N: a quarter of the weight is 15 cm long
axis.quiver(*soles.T, *(scale * leaning[shown]).T, color="tab:red", lw=2, arrow_length_ratio=0.2)
for name, sole, force in zip(FEET, soles, leaning[shown]):
    axis.text(*(sole + scale * force), f" {name[:2]} {force[2]:.2f} N", fontsize=8)
axis.plot(*solo.center_of_mass(postures[shown])[:2], 0.0, "kx", ms=8)
axis.plot(*soles[[0, 1, 3, 2, 0]].T, color="0.7", lw=0.8)
axis.set(xlabel="x [m]", ylabel="y [m]", zlabel="z [m]", xlim=(-0.25, 0.25), ylim=(-0.25, 0.25), zlim=(0, 0.3))
axis.set_box_aspect((1, 1, 0.6))
axis.view_init(elev=18, azim=-60)
axis.set_title(f"Solo12 leaning 4 cm forwards: the ground's forces\n(sum {totals[shown]:.3f} N = m g)")
axis = figure.add_subplot(1, 2, 2)
for k, name in enumerate(FEET):
    axis.plot(100 * leans, leaning[:, k, 2], label=name, ls="-" if k % 2 == 0 else "--")
axis.axhline(weight / 4, color="0.6", lw=0.8)
axis.set(xlabel="body's lean forwards [cm]", ylabel="vertical force on the foot [N]",
         title="Leaning over the feet: the forces move")
axis.legend()
axis.grid(True, alpha=0.3)
figure.tight_layout()


# %%
# ## A four-bar linkage
#
# A crank (0.15 m), a coupler (0.5 m) and a rocker (0.35 m) in a chain from a ground pivot, the
# rocker's tip held to a second pivot 0.45 m along the ground. The shortest link plus the longest
# is shorter than the other two together (Grashof's condition), so the crank turns all the way
# round while the rocker rocks. The closure keeps two rows of a `FrameAnchor` (x and z, a
# `mask`): the joints keep the linkage in its plane, so the rows along y and about x and z would
# be zero, and the rotation about y must stay free.
def bar(name: str, length: float, mass: float) -> str:
    """A URDF link: a slender bar of `length` along x, turning about y."""
    inertia = mass * length**2 / 12.0
    return (f'<link name="{name}"><inertial><origin xyz="{length / 2} 0 0"/><mass value="{mass}"/>'
            f'<inertia ixx="1e-5" ixy="0" ixz="0" iyy="{inertia}" iyz="0" izz="{inertia}"/></inertial></link>')


CRANK, COUPLER, ROCKER, GROUND = 0.15, 0.5, 0.35, 0.45
linkage = robodyn.load_urdf_string(f"""<robot name="four_bar"><link name="ground"/>
  <joint name="crank" type="continuous"><parent link="ground"/><child link="crank"/><axis xyz="0 1 0"/></joint>
  {bar("crank", CRANK, 0.3)}
  <joint name="coupler" type="continuous"><parent link="crank"/><child link="coupler"/>
    <origin xyz="{CRANK} 0 0"/><axis xyz="0 1 0"/></joint>
  {bar("coupler", COUPLER, 0.6)}
  <joint name="rocker" type="continuous"><parent link="coupler"/><child link="rocker"/>
    <origin xyz="{COUPLER} 0 0"/><axis xyz="0 1 0"/></joint>
  {bar("rocker", ROCKER, 0.5)}
  <joint name="tip" type="fixed"><parent link="rocker"/><child link="tip"/><origin xyz="{ROCKER} 0 0"/></joint>
  <link name="tip"/></robot>""")
pivot = np.eye(4)
pivot[0, 3] = GROUND
closure = robodyn.FrameAnchor("tip", placement2=pivot, mask=[True, False, True, False, False, False])


def gap(model: robodyn.Model, q: np.ndarray) -> float:
    """How far the rocker's tip is from its pivot (m)."""
    return float(np.linalg.norm(model.frame_pose(q, "tip")[:3, 3] - pivot[:3, 3]))


# %%
# The loop closed by Newton's method on the coupler's and rocker's angles, and a velocity the loop
# allows (J q̇ = 0: the crank at 6 rad/s). RK4's own error opens the loop by a fraction of a
# micrometre over 3 s; Baumgarte's terms (`baumgarte=(Kp, Kd)`) pull it back to under 1e-8 m
# without taking energy out.
q0 = np.array([-1.2, 0.8, 2.0])
for _ in range(20):
    miss = (linkage.frame_pose(q0, "tip")[:3, 3] - pivot[:3, 3])[[0, 2]]
    q0[1:] -= np.linalg.solve(linkage.constraint_jacobian(q0, closure)[:, 1:], miss)
allowed = np.linalg.svd(linkage.constraint_jacobian(q0, closure))[2][-1]
v0 = 6.0 * allowed / allowed[0]
plain = robodyn.simulate(linkage, q0, v0, t_end=3.0, dt=1e-3, integrator="rk4", constraints=closure)
spin = robodyn.simulate(linkage, q0, v0, t_end=3.0, dt=1e-3, integrator="rk4", constraints=closure, baumgarte=(100.0, 20.0))
plain_gaps, spin_gaps = (np.array([gap(linkage, q) for q in run.q]) for run in (plain, spin))
show("loop closure |tip − pivot| over 3 s, at most (m)", 0.0, spin_gaps.max(), 1e-8)
show("energy T + V, its largest change over 3 s (J)", 0.0, np.abs(spin.energy - spin.energy[0]).max(), 1e-7)
print(f"the crank turned {abs(spin.q[-1, 0] - q0[0]) / (2 * np.pi):.1f} times")
unlooped = robodyn.simulate(linkage, q0, v0, t_end=0.2, dt=1e-3, integrator="rk4")
print(f"without the closure the tip leaves its pivot by {gap(linkage, unlooped.q[-1]):.3f} m in 0.2 s")

figure = plt.figure(figsize=(10, 4.2))
axis = figure.add_subplot(1, 2, 1)
turn = spin.t[np.argmax(np.abs(spin.q[:, 0] - q0[0]) >= 2 * np.pi)]  # the crank's first turn
instants = np.searchsorted(spin.t, np.linspace(0.0, turn, 7)[:-1])
for k, colour in zip(instants, plt.cm.viridis(np.linspace(0, 0.9, len(instants)))):
    joints = np.array([linkage.frame_pose(spin.q[k], f)[:3, 3] for f in ("crank", "coupler", "rocker", "tip")])
    axis.plot(joints[:, 0], joints[:, 2], "o-", color=colour, lw=2, ms=4, label=f"t = {spin.t[k]:.2f} s")
crank_pins = np.array([linkage.frame_pose(q, "coupler")[:3, 3] for q in spin.q[::5]])
axis.plot(crank_pins[:, 0], crank_pins[:, 2], color="0.7", lw=0.8, zorder=0)
axis.plot([0.0, GROUND], [0.0, 0.0], "k^", ms=10)
axis.set(xlabel="x [m]", ylabel="z [m]", ylim=(-0.2, 0.62), aspect="equal",
         title=f"The four-bar over the crank's first turn ({turn:.2f} s)")
axis.legend(fontsize=7, loc="upper left", ncol=3)
axis = figure.add_subplot(2, 2, 2)
axis.semilogy(plain.t[1:], plain_gaps[1:], label="RK4", color="tab:gray")
axis.semilogy(spin.t[1:], spin_gaps[1:], label="RK4 + Baumgarte (100, 20)", color="tab:blue")
axis.axhline(1e-8, color="tab:red", lw=0.8, ls=":")
axis.set(ylabel="|tip − pivot| [m]", title="Loop closure error")
axis.legend(fontsize=7)
axis.grid(True, alpha=0.3)
axis = figure.add_subplot(2, 2, 4)
axis.plot(spin.t, spin.energy - spin.energy[0], color="tab:blue")
axis.set(xlabel="time [s]", ylabel="E − E₀ [J]", title="Energy")
axis.grid(True, alpha=0.3)
figure.tight_layout()

# %%
# ## Cassie's legs
#
# Each of Cassie's legs closes two loops with rods (plantar and Achilles); the MJCF file states
# them as `<equality><connect>`, which become `cassie.constraints`: four `PointAnchor`s between two
# moving bodies. The legs are planar, so the rows of a rod out of its leg's plane depend on the
# others: the loops are held in the proximal mode (`damping`). Cassie falls from where its file
# puts it, its hips swinging its legs apart at 2 rad/s (a leg's loops lie below its hip, which
# turns them as one piece: a velocity they allow); its knee and heel springs take up the motion. Without the
# constraints, the open tree's rods come apart from the feet and heels at once.
with warnings.catch_warnings():
    # its actuators and sensors are not read (robodyn models the rigid-body tree)
    warnings.simplefilter("ignore", robodyn.ModelWarning)
    cassie = robodyn.load(REPOSITORY / "testdata" / "mjcf" / "cassie_nomesh.xml")
loops = [loop for loop in cassie.constraints if isinstance(loop, robodyn.PointAnchor)]  # the connects
assert len(loops) == len(cassie.constraints) == 4
swing = np.zeros(cassie.nv)
velocity_index = dict(zip(cassie.joint_names, cassie.joint_idx_v))
swing[velocity_index["left-hip-pitch"]], swing[velocity_index["right-hip-pitch"]] = 2.0, -2.0
show("J q̇ of the hips' swing (m/s)", np.zeros(12), cassie.constraint_jacobian(cassie.neutral(), loops) @ swing)
# half the time step of Cassie's file: at this speed its stiff springs on light links need it
fall = robodyn.simulate(cassie, cassie.neutral(), swing, t_end=0.5, dt=2.5e-4, integrator="rk4", constraints=loops, damping=1e-8)
loose = robodyn.simulate(cassie, cassie.neutral(), swing, t_end=0.5, dt=1e-4, integrator="rk4", constraints=None)


def rod_ends(q: np.ndarray, loop: robodyn.PointAnchor) -> np.ndarray:
    """The two points a loop holds together (the rod's end, the point of the foot or heel), in
    world coordinates, shape (2, 3)."""
    assert loop.frame2 is not None and loop.offset2 is not None  # both on moving bodies
    one = cassie.frame_pose(q, loop.frame) @ [*loop.offset, 1.0]
    other = cassie.frame_pose(q, loop.frame2) @ [*loop.offset2, 1.0]
    return np.array([one[:3], other[:3]])


def loop_gaps(trajectory: robodyn.Trajectory) -> np.ndarray:
    """Each loop's gap, how far its two points are apart (m), per sample."""
    return np.array([[np.linalg.norm(np.subtract(*rod_ends(q, loop))) for loop in loops] for q in trajectory.q])


closed, opened = loop_gaps(fall), loop_gaps(loose)
show("Cassie's four loops over 0.5 s, the largest gap (m)", 0.0, closed.max(), 1e-8)
print(f"the open tree's largest gap: {1e3 * opened.max():.0f} mm")

# %%
# Cassie's file also names a standing pose, its keyframe `home` (MuJoCo's `<key>`, in robodyn's
# coordinates): MuJoCo's loops are soft, and its saved pose leaves the rods open by a little;
# `close_constraints` closes them before a simulation starts there.
home = cassie.keyframe("home")
standing = cassie.close_constraints(home.q, loops)
print(f"keyframe '{home.name}': loops open by {1e3 * np.abs(cassie.constraint_error(home.q, loops)).max():.1f} mm, "
      f"closed to {standing['residual']:.0e} m in {standing['iterations']} steps")

figure = plt.figure(figsize=(10, 4.2))
axis = figure.add_subplot(1, 2, 1)
snapshots = [0, len(fall.t) // 2, len(fall.t) - 1]
points, segments = stick_figure_points(cassie, fall.q[snapshots])
for sample, (k, colour) in enumerate(zip(snapshots, ("0.6", "tab:green", "tab:blue"))):
    # in the pelvis's axes: the legs, not the fall
    pelvis = cassie.frame_pose(fall.q[k], "cassie-pelvis")
    local = (points[sample] - pelvis[:3, 3]) @ pelvis[:3, :3]
    for a, b in segments:
        if a > 0:  # not the segment from the world's origin to the pelvis
            axis.plot(local[[a, b], 0], local[[a, b], 2], color=colour, lw=1.2)
    for loop in loops:
        # the rod, from its body's origin to its held end
        rod = np.array([cassie.frame_pose(fall.q[k], loop.frame)[:3, 3], rod_ends(fall.q[k], loop)[0]])
        rod = (rod - pelvis[:3, 3]) @ pelvis[:3, :3]
        axis.plot(rod[:, 0], rod[:, 2], color=colour, lw=3, solid_capstyle="round")
        axis.plot(rod[1, 0], rod[1, 2], "o", color="tab:red", ms=3)
    axis.plot([], [], color=colour, label=f"t = {fall.t[k]:.2f} s")
axis.set(xlabel="x in the pelvis's axes [m]", ylabel="z in the pelvis's axes [m]", aspect="equal",
         title="Cassie's legs (thick: the rods, red: their held ends)")
axis.legend(fontsize=8)
axis = figure.add_subplot(1, 2, 2)
for k, loop in enumerate(loops):
    axis.semilogy(fall.t[1:], np.maximum(closed[1:, k], 1e-17), color=f"C{k}", label=f"{loop.frame}, closed")
    axis.semilogy(loose.t[1:], opened[1:, k], color=f"C{k}", ls=":", label="open tree" if k == 3 else None)
axis.axhline(1e-8, color="tab:red", lw=0.8, ls=":")
axis.set(xlabel="time [s]", ylabel="gap between the rod's ends [m]", title="Falling: the loops stay closed")
axis.legend(fontsize=7)
axis.grid(True, alpha=0.3)
figure.tight_layout()
