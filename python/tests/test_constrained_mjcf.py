"""MJCF `<equality>` constraints: read as MuJoCo compiles them (anchors at qpos0, relpose, polycoef,
classes, active), compared with MuJoCo's compiled `eq_data`; and the loops they close held in
forward dynamics and in simulation (Cassie)."""

from __future__ import annotations


import mujoco
import numpy as np
import pytest
from conftest import REPOSITORY, assert_close
from conftest import load_quietly as load

import robodyn

CASSIE = REPOSITORY / "testdata" / "mjcf" / "cassie_nomesh.xml"
GRIPPER = REPOSITORY / "testdata" / "menagerie" / "robotiq_2f85" / "2f85.xml"
#: MuJoCo's compiler and robodyn both compute the anchors in double precision from the same poses.
COMPILER_TOLERANCE = 1e-12
#: Identities between exact computations (the constrained equations), relative.
IDENTITY_TOLERANCE = 1e-9
#: How far a simulated loop may come apart (m).
LOOP_DRIFT = 1e-8
#: How far above 1 RK4's amplification of a stable linear motion may come by rounding (its free
#: base's six zero eigenvalues come out at about 1e-9 / s).
STABLE_AMPLIFICATION = 1e-6

EQUALITIES = """<mujoco model="equalities">
  <compiler angle="radian"/>
  <default><equality solref="0.01 0.8"/><default class="stiff"><equality solimp="0.9 0.99 0.001 0.5 2"/></default></default>
  <worldbody>
    <body name="a" pos="0 0 1">
      <joint name="ja" type="hinge" axis="0 1 0" ref="0.2"/>
      <inertial pos="0.2 0 0" mass="1" diaginertia="0.01 0.02 0.02"/>
      <body name="b" pos="0.4 0 0" euler="0.1 0.2 0.3">
        <joint name="jb" type="hinge" axis="0 1 0"/>
        <inertial pos="0.2 0 0" mass="1" diaginertia="0.01 0.02 0.02"/>
        <site name="tip" pos="0.4 0 0"/>
      </body>
    </body>
    <body name="c" pos="0.5 0.3 1.2" euler="0.3 0 0.1">
      <joint name="jc" type="slide" axis="1 0 0"/>
      <joint name="jd" type="slide" axis="0 0 1"/>
      <inertial pos="0 0 0" mass="2" diaginertia="0.1 0.1 0.1"/>
      <site name="mark" pos="0.1 0 0"/>
    </body>
  </worldbody>
  <equality>
    <connect name="pin" body1="b" body2="c" anchor="0.4 0.1 0"/>
    <weld body1="a" body2="c" anchor="0.05 0 0.1" class="stiff"/>
    <weld body1="b" relpose="0.1 0.2 0.3 0.9 0.1 0.3 0.2" anchor="0.1 0 0" torquescale="2"/>
    <connect site1="tip" site2="mark"/>
    <joint joint1="jd" joint2="jc" polycoef="0.1 -0.5 0.3 0 0"/>
    <joint joint1="jb" polycoef="0.25 0 0 0 0" active="false"/>
  </equality>
</mujoco>"""


def pose(rotation, position):
    placement = np.eye(4)
    placement[:3, :3], placement[:3, 3] = rotation, position
    return placement


def mujoco_relpose(data):
    """A weld's compiled relpose as a 4x4 pose in body1: its position is where body2's anchor
    is held in body1, its w-first quaternion body2's orientation in body1."""
    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, data[6:10] / np.linalg.norm(data[6:10]))
    return pose(rotation.reshape(3, 3), data[3:6])


def test_connects_and_joint_equalities_are_those_mujoco_compiles():
    for path in (CASSIE, GRIPPER):
        model, compiled = load(path), mujoco.MjModel.from_xml_path(str(path))
        constraints = model.constraints
        assert len(constraints) == compiled.neq
        for k, constraint in enumerate(constraints):
            data = compiled.eq_data[k]
            if compiled.eq_type[k] == mujoco.mjtEq.mjEQ_CONNECT:
                assert constraint.frame == mujoco.mj_id2name(compiled, mujoco.mjtObj.mjOBJ_BODY, compiled.eq_obj1id[k])
                assert_close(constraint.offset, data[0:3], COMPILER_TOLERANCE, f"{path.name} {k} anchor")
                assert_close(constraint.offset2, data[3:6], COMPILER_TOLERANCE, f"{path.name} {k} anchor2")
            else:
                assert compiled.eq_type[k] == mujoco.mjtEq.mjEQ_JOINT
                # qpos0 of both driver joints is 0: the polynomial is MuJoCo's as written
                assert_close(constraint.polycoef, data[0:5], COMPILER_TOLERANCE, f"{path.name} {k} polycoef")


def test_welds_sites_classes_and_inactive_equalities():
    model, compiled = load(text=EQUALITIES), mujoco.MjModel.from_xml_string(EQUALITIES)
    constraints = model.constraints
    # the inactive joint equality is kept in the file's list but not held
    assert len(constraints) == compiled.neq - 1
    q = model.neutral()
    world = {name: model.frame_pose(q, name) for name in ("a", "b", "c", "tip", "mark")}
    # the connect's two points coincide at qpos0
    pin = constraints[0]
    first = world["b"] @ np.append(pin.offset, 1.0)
    second = world["c"] @ np.append(pin.offset2, 1.0)
    assert_close(first, second, COMPILER_TOLERANCE, "connect at qpos0")
    # the weld frames coincide at qpos0 (relpose from qpos0), and match MuJoCo's compiled relpose
    weld = constraints[1]
    assert_close(world["a"] @ np.array(weld.placement), world["c"] @ np.array(weld.placement2), COMPILER_TOLERANCE, "weld")
    assert_close(weld.placement, mujoco_relpose(compiled.eq_data[1]), COMPILER_TOLERANCE, "weld relpose")
    assert_close(weld.placement2, pose(np.eye(3), compiled.eq_data[1][0:3]), 0.0, "weld anchor")
    # a weld to the world with its relpose given
    given = constraints[2]
    assert given.frame == "b" and given.frame2 is None
    assert_close(given.placement, mujoco_relpose(compiled.eq_data[2]), COMPILER_TOLERANCE, "given relpose")
    assert constraints[3].frame == "tip" and constraints[3].frame2 == "mark"
    # jd − qpos0 = 0.1 − 0.5 (jc − qpos0) + 0.3 (jc − qpos0)²: both slides' qpos0 are 0
    assert constraints[4].joint == "jd" and constraints[4].leader == "jc"
    assert_close(constraints[4].polycoef, [0.1, -0.5, 0.3, 0, 0], 1e-15)
    # forward dynamics holds them all (the pin and the site connect are redundant with the weld)
    v = np.zeros(model.nv)
    result = model.constrained_forward_dynamics(q, v, np.zeros(model.nv), constraints, damping=1e-8)
    assert np.max(np.abs(model.constraint_jacobian(q, constraints) @ result["qdd"])) < 1e-8


RACK_AND_PINION = """<mujoco model="rack_and_pinion">
  <option gravity="0 0 0"/>
  <worldbody>
    <body name="pinion"><joint name="turn" type="hinge" axis="0 0 1"/>
      <inertial pos="0 0 0" mass="1" diaginertia="0.01 0.01 0.02"/></body>
    <body name="rack" pos="0 0.1 0"><joint name="slide" type="slide" axis="1 0 0"/>
      <inertial pos="0 0 0" mass="2" diaginertia="0.1 0.1 0.1"/></body>
  </worldbody>
  <equality><joint joint1="slide" joint2="turn" polycoef="0 0.05 0 0 0"/></equality>
</mujoco>"""


def test_a_hinge_drives_a_slide_as_a_rack_and_pinion():
    """A joint equality between a hinge and a slide (as MS-Human-700's knees hold them): with
    x = r θ, a torque τ on the pinion gives θ̈ = τ / (I + m r²) and ẍ = r θ̈."""
    model = load(text=RACK_AND_PINION)
    (coupling,) = model.constraints
    assert (coupling.joint, coupling.leader) == ("slide", "turn")
    radius, inertia, mass, torque = 0.05, 0.02, 2.0, 1.0
    q, v = model.neutral(), np.zeros(model.nv)
    result = model.constrained_forward_dynamics(q, v, np.array([torque, 0.0]), model.constraints)
    turn = torque / (inertia + mass * radius**2)
    assert_close(result["qdd"], [turn, radius * turn], IDENTITY_TOLERANCE, "rack and pinion")


def test_an_equality_naming_a_missing_body_or_joint_is_refused_by_line():
    broken = EQUALITIES.replace('body1="b" body2="c"', 'body1="b" body2="nowhere"')
    with pytest.raises(ValueError, match=r"line \d+.*'body2': no body or site is called 'nowhere'"):
        robodyn.load_mjcf_string(broken)
    broken = EQUALITIES.replace('joint1="jd" joint2="jc"', 'joint1="jd" joint2="jd"')
    with pytest.raises(ValueError, match=r"line \d+.*joint 'jd' is coupled to itself"):
        robodyn.load_mjcf_string(broken)


def loop_gap(model, loops, configurations):
    """The largest distance between the two points of a loop over the configurations (m)."""
    worst = 0.0
    for q in configurations:
        for loop in loops:
            one = model.frame_pose(q, loop.frame) @ np.append(loop.offset, 1.0)
            other = model.frame_pose(q, loop.frame2) @ np.append(loop.offset2, 1.0)
            worst = max(worst, float(np.max(np.abs(one - other))))
    return worst


def swinging(model):
    """Cassie's hips swinging its legs apart at 2 rad/s (a velocity its loops allow)."""
    swing = np.zeros(model.nv)
    velocity_index = dict(zip(model.joint_names, model.joint_idx_v))
    swing[velocity_index["left-hip-pitch"]], swing[velocity_index["right-hip-pitch"]] = 2.0, -2.0
    return swing


def test_cassie_keeps_its_loops_closed():
    model = load(CASSIE)
    loops = model.constraints
    assert len(loops) == 4
    q0 = model.neutral()
    # the loops close at qpos0; the pelvis falls freely, its legs held together by the rods
    # Cassie's legs are nearly planar: each rod's out-of-plane row depends on the others, so the
    # loops are solved in proximal mode
    with pytest.raises(ValueError, match=r"constraints\[0\] \(PointAnchor\('left-plantar-rod' to 'left-foot'\)\), row y"):
        model.constrained_forward_dynamics(q0, np.zeros(model.nv), np.zeros(model.nv), loops)
    # at Cassie's own time step (its <option timestep>): qpos0 puts the foot cranks outside their
    # ranges, where their damping is too fast for RK4 at 1 ms (see the tests below)
    run = robodyn.simulate(model, q0, t_end=1.0, dt=5e-4, integrator="rk4", constraints=loops, damping=1e-8)
    assert loop_gap(model, loops, run.q[::10]) < LOOP_DRIFT
    # the legs swinging apart at 2 rad/s: the loops open by rounding, so their out-of-plane rows
    # depend on the others only nearly, and the proximal iterations accept what that leaves
    run = robodyn.simulate(model, q0, swinging(model), t_end=0.5, dt=5e-4, integrator="rk4", constraints=loops, damping=1e-8)
    assert run.t[-1] == pytest.approx(0.5) and loop_gap(model, loops, run.q[::10]) < LOOP_DRIFT
    # with the pelvis held, the legs hang from it and the rods carry their weight
    held = [*loops, robodyn.FrameAnchor("cassie-pelvis")]
    forces = model.constrained_forward_dynamics(q0, np.zeros(model.nv), np.zeros(model.nv), held, damping=1e-8)["forces"]
    assert np.max(np.abs(forces[:12])) > 1.0


def test_cassie_standing_with_its_loops_and_both_feet_held():
    """Both loops of each leg and both feet welded to the ground: 24 rows, of which the feet's and
    the loops' overlap (the legs cannot move at all), solved in proximal mode; the constrained
    equations hold and the rows' accelerations vanish."""
    model = load(CASSIE)
    q, v = model.neutral(), np.zeros(model.nv)
    held = [*model.constraints, robodyn.FrameAnchor("left-foot"), robodyn.FrameAnchor("right-foot")]
    tau = np.random.default_rng(2).uniform(-10, 10, model.nv)
    with pytest.raises(ValueError, match="redundant"):
        model.constrained_forward_dynamics(q, v, tau, held)
    result = model.constrained_forward_dynamics(q, v, tau, held, damping=1e-8)
    jacobian = model.constraint_jacobian(q, held)
    residual = model.mass_matrix(q) @ result["qdd"] + model.bias_forces(q, v) - tau - jacobian.T @ result["forces"]
    assert np.max(np.abs(residual)) < IDENTITY_TOLERANCE * (1 + np.max(np.abs(tau)))
    assert np.max(np.abs(jacobian @ result["qdd"])) < IDENTITY_TOLERANCE * (1 + np.max(np.abs(result["qdd"])))


def test_simulate_holds_the_models_own_constraints_by_default():
    model = load(CASSIE)
    q0 = model.neutral()
    # Cassie's loops have dependent rows: without damping the run says so, naming the row
    with pytest.raises(ValueError, match=r"row y.*damping > 0"):
        robodyn.simulate(model, q0, t_end=0.01, dt=5e-4, integrator="rk4")
    options = {"t_end": 0.05, "dt": 5e-4, "integrator": "rk4", "damping": 1e-8}
    held = robodyn.simulate(model, q0, swinging(model), **options)
    explicit = robodyn.simulate(model, q0, swinging(model), constraints=model.constraints, **options)
    np.testing.assert_array_equal(held.q, explicit.q)
    assert loop_gap(model, model.constraints, held.q) < LOOP_DRIFT
    # None holds nothing: the open tree's rods come apart
    loose = robodyn.simulate(model, q0, swinging(model), constraints=None, **options)
    assert loop_gap(model, model.constraints, loose.q) > 1e3 * LOOP_DRIFT
    with pytest.raises(ValueError, match="constraints"):
        robodyn.simulate(model, q0, constraints="models", **options)


def cassie_home(model):
    """Cassie's `home` keyframe, its loops closed: MuJoCo's soft loops leave them 1.5 mm open
    there."""
    q = model.keyframe("home").q
    assert 1e-4 < np.max(np.abs(model.constraint_error(q, model.constraints))) < 1e-2
    closed = model.close_constraints(q, model.constraints)
    assert closed["success"] and closed["residual"] <= 1e-12
    return closed["q"]


def test_cassie_keeps_its_loops_closed_for_10_s_at_1_ms_with_rk4():
    """The issue's case, from Cassie's keyframe: RK4 at dt = 1 ms for 10 s. Measured: 6.6e-9 m
    without Baumgarte's terms (RK4's truncation: 180 times less at dt / 2), 2e-11 m with them."""
    model = load(CASSIE)
    loops, q0 = model.constraints, cassie_home(model)
    run = robodyn.simulate(model, q0, t_end=10.0, dt=1e-3, integrator="rk4", constraints=loops, damping=1e-8)
    assert run.t[-1] == pytest.approx(10.0) and loop_gap(model, loops, run.q[::10]) < LOOP_DRIFT
    assert np.ptp(run.q[:, model.joint_idx_q[model.joint_names.index("left-knee")]]) > 1e-3, "the legs move"
    pulled = robodyn.simulate(model, q0, t_end=10.0, dt=1e-3, integrator="rk4", constraints=loops, damping=1e-8,
                              baumgarte=(100.0, 20.0))
    assert loop_gap(model, loops, pulled.q[::10]) < LOOP_DRIFT / 100


def rk4_amplification(model, q, dt):
    """The largest |R(λ dt)|, R(z) = 1 + z + z²/2 + z³/6 + z⁴/24 (RK4 on ẋ = λ x), over the
    eigenvalues λ of Cassie's motion about rest at q with its loops held: M, the joint springs K
    and dampers D restricted to the null space of the loops' J."""
    jacobian = model.constraint_jacobian(q, model.constraints)
    _, singular, vt = np.linalg.svd(jacobian)
    free = vt[np.sum(singular > 1e-9 * singular[0]):].T
    mass, stiffness, damping = (free.T @ matrix @ free for matrix in (
        model.mass_matrix(q), np.diag(model.stiffness), np.diag(model.damping)))
    n = free.shape[1]
    motion = np.block([[np.zeros((n, n)), np.eye(n)],
                       [-np.linalg.solve(mass, stiffness), -np.linalg.solve(mass, damping)]])
    z = np.linalg.eigvals(motion) * dt
    return np.max(np.abs(1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24))


def test_why_cassie_starts_from_its_keyframe_at_1_ms():
    """At qpos0 the foot cranks and feet stand at 0 rad, outside their ranges (MuJoCo's soft joint
    limits push them back in at once); there the crank's damping (1 N m s/rad on a light crank)
    makes a mode of λ ≈ −5.3e3 / s, beyond RK4's bound |λ dt| < 2.79 at 1 ms. At the keyframe,
    the cranks inside their ranges, every mode is within it."""
    model = load(CASSIE)
    q = model.neutral()
    for name in ("left-foot-crank", "left-foot"):
        k = model.joint_idx_q[model.joint_names.index(name)]
        assert not model.lower_position_limit[k] <= q[k] <= model.upper_position_limit[k], name
    assert rk4_amplification(model, q, 1e-3) > 10.0
    assert rk4_amplification(model, q, 5e-4) < 1 + STABLE_AMPLIFICATION
    assert rk4_amplification(model, cassie_home(model), 1e-3) < 1 + STABLE_AMPLIFICATION
