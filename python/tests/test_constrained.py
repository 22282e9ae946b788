"""Constrained dynamics from Python: the constraint objects, batches, the identities each call must
satisfy, and bad input refused by name (the cross-checks against Pinocchio are in
test_constrained_pinocchio.py)."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from conftest import assert_close

import robodyn

#: Identities between exact computations (KKT residuals, inverse of forward), relative.
IDENTITY_TOLERANCE = 1e-9


@pytest.fixture(scope="module")
def ur5():
    return robodyn.load("ur5")


def loop(model):
    """The UR5's tool point held to a point of its upper arm, as if a rod joined them."""
    return [robodyn.PointAnchor("tool0", "forearm_link", offset2=[0.2, 0.0, 0.1])]


def test_forward_dynamics_satisfies_the_constrained_equations(ur5):
    rng = np.random.default_rng(3)
    q, v, tau = ur5.random_configuration(seed=1), rng.uniform(-1, 1, ur5.nv), rng.uniform(-5, 5, ur5.nv)
    constraints = [robodyn.PointAnchor("tool0", offset=[0.0, 0.0, 0.05]), robodyn.JointCoupling("wrist_3_joint", "wrist_1_joint", ratio=-2.0, offset=0.1)]
    result = ur5.constrained_forward_dynamics(q, v, tau, constraints)
    qdd, forces = result["qdd"], result["forces"]
    assert qdd.shape == (ur5.nv,) and forces.shape == (4,)
    jacobian = ur5.constraint_jacobian(q, constraints)
    residual = ur5.mass_matrix(q) @ qdd + ur5.bias_forces(q, v) - tau - jacobian.T @ forces
    assert np.max(np.abs(residual)) < IDENTITY_TOLERANCE * (1 + np.max(np.abs(forces)))
    # the coupling's row: q̈_w3 + 2 q̈_w1 = 0
    assert abs(qdd[5] + 2.0 * qdd[3]) < IDENTITY_TOLERANCE


def test_a_point_at_the_frame_origin_has_the_frames_world_jacobian(ur5):
    q = ur5.random_configuration(seed=4)
    jacobian = ur5.constraint_jacobian(q, robodyn.PointAnchor("tool0"))
    assert_close(jacobian, ur5.jacobian(q, "tool0")[:3], IDENTITY_TOLERANCE)
    local = ur5.constraint_jacobian(q, robodyn.PointAnchor("tool0", reference="local"))
    assert_close(local, ur5.jacobian(q, "tool0", reference="local")[:3], IDENTITY_TOLERANCE)
    frame = ur5.constraint_jacobian(q, robodyn.FrameAnchor("tool0", mask=[False, False, True, True, False, True]))
    assert_close(frame, ur5.jacobian(q, "tool0")[[2, 3, 5]], IDENTITY_TOLERANCE)


def test_batches_equal_one_state_at_a_time(ur5):
    # two groups of the widest lanes (eight states) and three left over: the forward dynamics
    # of a batch runs in lanes, each lane the one-state call's operations, so equal bit for bit
    rng = np.random.default_rng(5)
    n = 19
    q = ur5.random_configuration(n, seed=2)
    v, tau = rng.uniform(-1, 1, (n, ur5.nv)), rng.uniform(-5, 5, (n, ur5.nv))
    constraints = loop(ur5)
    assert ur5.delassus(q, constraints).shape == (n, 3, 3)
    for options in [{}, {"baumgarte": (40.0, 12.0)}, {"damping": 1e-6}]:
        batch = ur5.constrained_forward_dynamics(q, v, tau, constraints, **options)
        assert batch["qdd"].shape == (n, ur5.nv) and batch["forces"].shape == (n, 3)
        for k in range(n):
            one = ur5.constrained_forward_dynamics(q[k], v[k], tau[k], constraints, **options)
            np.testing.assert_array_equal(batch["qdd"][k], one["qdd"])
            np.testing.assert_array_equal(batch["forces"][k], one["forces"])
    # impulses in lanes too (with damping, one state at a time)
    for options in [{"restitution": 0.5}, {"restitution": 0.5, "damping": 1e-6}]:
        impulses = ur5.impulse_dynamics(q, v, constraints, **options)
        for k in range(n):
            one = ur5.impulse_dynamics(q[k], v[k], constraints, **options)
            np.testing.assert_array_equal(impulses["v"][k], one["v"])
            np.testing.assert_array_equal(impulses["impulses"][k], one["impulses"])


def test_an_empty_list_gives_the_free_dynamics(ur5):
    rng = np.random.default_rng(8)
    n = 11
    q = ur5.random_configuration(n, seed=3)
    v, tau = rng.uniform(-1, 1, (n, ur5.nv)), rng.uniform(-5, 5, (n, ur5.nv))
    free = ur5.forward_dynamics(q, v, tau)
    for options in [{}, {"baumgarte": (40.0, 12.0)}]:
        batch = ur5.constrained_forward_dynamics(q, v, tau, [], **options)
        assert batch["forces"].shape == (n, 0)
        assert_close(batch["qdd"], free, IDENTITY_TOLERANCE)
        one = ur5.constrained_forward_dynamics(q[0], v[0], tau[0], [], **options)
        assert_close(one["qdd"], free[0], IDENTITY_TOLERANCE)
    assert_close(ur5.impulse_dynamics(q, v, [])["v"], v, 0.0)
    derivatives = ur5.constrained_forward_dynamics_derivatives(q[0], v[0], tau[0], [])
    assert_close(derivatives["dqdd_dtau"], ur5.inverse_mass_matrix(q[0]), IDENTITY_TOLERANCE)
    assert ur5.constraint_jacobian(q[0], []).shape == (0, ur5.nv)


def test_a_list_passed_again_or_changed_gives_its_own_answer(ur5):
    # a call resolves the constraint objects it is given; the same objects again reuse that
    # set, other objects (a changed list, equal new objects) are resolved anew
    q = ur5.random_configuration(seed=6)
    tool, wrist = robodyn.PointAnchor("tool0"), robodyn.PointAnchor("wrist_1_link")
    constraints = [tool]
    first = ur5.constraint_jacobian(q, constraints)
    assert_close(ur5.constraint_jacobian(q, constraints), first, 0.0)
    constraints[0] = wrist
    assert_close(ur5.constraint_jacobian(q, constraints), ur5.jacobian(q, "wrist_1_link")[:3], IDENTITY_TOLERANCE)
    constraints.append(tool)
    assert ur5.constraint_jacobian(q, constraints).shape == (6, ur5.nv)
    assert_close(ur5.constraint_jacobian(q, [robodyn.PointAnchor("tool0")]), first, 0.0)
    with pytest.raises(ValueError, match="unknown"):
        ur5.constraint_jacobian(q, [tool, robodyn.PointAnchor("no_such_frame")])
    assert_close(ur5.constraint_jacobian(q, tool), first, 0.0)


def test_delassus_and_impulses(ur5):
    q, v = ur5.random_configuration(seed=6), np.linspace(-1, 1, ur5.nv)
    constraints = loop(ur5)
    jacobian = ur5.constraint_jacobian(q, constraints)
    expected = jacobian @ ur5.inverse_mass_matrix(q) @ jacobian.T
    assert_close(ur5.delassus(q, constraints), expected, IDENTITY_TOLERANCE)
    result = ur5.impulse_dynamics(q, v, constraints, restitution=0.3)
    assert_close(jacobian @ result["v"], -0.3 * jacobian @ v, IDENTITY_TOLERANCE)
    assert_close(ur5.mass_matrix(q) @ (result["v"] - v), jacobian.T @ result["impulses"], IDENTITY_TOLERANCE)


def test_external_forces_and_baumgarte_terms(ur5):
    rng = np.random.default_rng(8)
    q, v, tau = ur5.random_configuration(seed=3), rng.uniform(-1, 1, ur5.nv), rng.uniform(-5, 5, ur5.nv)
    f_ext = rng.uniform(-3, 3, (len(ur5.body_names), 6))
    constraints = [robodyn.PointAnchor("tool0", offset2=[0.3, 0.2, 0.4])]
    result = ur5.constrained_forward_dynamics(q, v, tau, constraints, f_ext=f_ext, baumgarte=(100.0, 20.0))
    jacobian = ur5.constraint_jacobian(q, constraints)
    # M q̈ + h − Σ Jᵀ f_ext = τ + Jᵀ λ: inverse dynamics with f_ext gives τ + Jᵀ λ
    generalized = ur5.inverse_dynamics(q, v, result["qdd"], f_ext=f_ext)
    assert_close(generalized, tau + jacobian.T @ result["forces"], IDENTITY_TOLERANCE)
    # J q̈ + J̇ v = −K_d J v − K_p (p − p*)
    error = ur5.frame_pose(q, "tool0")[:3, 3] - np.array([0.3, 0.2, 0.4])
    # without them J q̈ + J̇ v = 0 (for any τ), which gives J̇ v
    drift = ur5.constrained_forward_dynamics(q, v, np.zeros(ur5.nv), constraints)
    held = jacobian @ result["qdd"] - jacobian @ drift["qdd"]
    assert_close(held, -20.0 * jacobian @ v - 100.0 * error, IDENTITY_TOLERANCE)


def test_inverse_dynamics_inverts_forward_dynamics_on_a_fixed_base(ur5):
    q, v, tau = ur5.random_configuration(seed=9), np.full(ur5.nv, 0.3), np.linspace(-2, 2, ur5.nv)
    coupling = robodyn.JointCoupling("elbow_joint", "shoulder_lift_joint", ratio=0.5)
    qdd = ur5.constrained_forward_dynamics(q, v, tau, coupling)["qdd"]
    actuated = [name for name in ur5.joint_names if name != "elbow_joint"]
    result = ur5.constrained_inverse_dynamics(q, v, qdd, coupling, actuated=actuated)
    assert result["tau"][2] == 0.0
    residual = ur5.inverse_dynamics(q, v, qdd) - result["tau"] - ur5.constraint_jacobian(q, coupling).T @ result["forces"]
    assert np.max(np.abs(residual)) < IDENTITY_TOLERANCE * 10


def test_a_closure_stated_twice_needs_damping_and_then_shares_its_force(ur5):
    q, v, tau = ur5.random_configuration(seed=10), np.zeros(ur5.nv), np.ones(ur5.nv)
    twice = loop(ur5) * 2
    with pytest.raises(ValueError, match=r"constraints\[1\] \(PointAnchor\('tool0' to 'forearm_link'\)\), row x.*damping"):
        ur5.constrained_forward_dynamics(q, v, tau, twice)
    once = ur5.constrained_forward_dynamics(q, v, tau, loop(ur5))
    shared = ur5.constrained_forward_dynamics(q, v, tau, twice, damping=1e-6)
    assert_close(shared["qdd"], once["qdd"], 1e-8)
    assert_close(shared["forces"], np.concatenate([once["forces"] / 2] * 2), 1e-8)


def test_constraint_objects_pickle_and_print():
    constraints = [
        robodyn.PointAnchor("a", "b", offset=[1, 2, 3], offset2=[4, 5, 6], reference="local"),
        robodyn.FrameAnchor("a", placement=np.eye(4), mask=[True] * 5 + [False]),
        robodyn.JointCoupling("j1", "j2", polycoef=[0.1, 2.0, 0.3]),
        robodyn.Distance("a", "b", 0.4),
    ]
    for constraint in constraints:
        copy = pickle.loads(pickle.dumps(constraint))
        assert repr(copy) == repr(constraint)
    assert constraints[0].offset2 == [4.0, 5.0, 6.0] and constraints[0].reference == "local"
    assert constraints[1].mask == [True] * 5 + [False]
    assert constraints[2].polycoef == [0.1, 2.0, 0.3, 0.0, 0.0]


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: robodyn.PointAnchor("tool0", reference="body"), "argument 'reference': expected 'world' or 'local'"),
        (lambda: robodyn.PointAnchor("tool0", offset=[1, 2]), "argument 'offset': expected 3 finite numbers"),
        (lambda: robodyn.FrameAnchor("tool0", mask=[False] * 6), "argument 'mask'"),
        (lambda: robodyn.FrameAnchor("tool0", placement=np.ones((4, 4))), "argument 'placement': expected a rigid pose"),
        (lambda: robodyn.JointCoupling("a", "b", ratio=2.0, polycoef=[1, 2]), "either ratio and offset or polycoef"),
        (lambda: robodyn.Distance("a", "b", 0.0), "argument 'length'"),
        (lambda: robodyn.PointAnchor(3), "argument 'frame': expected a name"),
    ],
)
def test_malformed_constraints_are_refused_by_name(make, message):
    with pytest.raises(ValueError, match=message):
        make()


def test_unknown_names_and_wrong_kinds_are_refused_by_name(ur5):
    q, v, tau = ur5.neutral(), np.zeros(ur5.nv), np.zeros(ur5.nv)
    with pytest.raises(ValueError, match=r"constraints\[1\].*no_such_frame"):
        ur5.constraint_jacobian(q, [robodyn.PointAnchor("tool0"), robodyn.PointAnchor("no_such_frame")])
    with pytest.raises(ValueError, match=r"constraints\[0\].*unknown joint 'wrist'"):
        ur5.constraint_jacobian(q, robodyn.JointCoupling("wrist", "elbow_joint"))
    with pytest.raises(ValueError, match="argument 'constraints': expected a constraint"):
        ur5.constraint_jacobian(q, "tool0")
    with pytest.raises(ValueError, match="argument 'baumgarte'"):
        ur5.constrained_forward_dynamics(q, v, tau, loop(ur5), baumgarte=3.0)
    with pytest.raises(ValueError, match="argument 'damping'"):
        ur5.constrained_forward_dynamics(q, v, tau, loop(ur5), damping=-1.0)
    with pytest.raises(ValueError, match="argument 'restitution'"):
        ur5.impulse_dynamics(q, v, loop(ur5), restitution=1.5)
    with pytest.raises(ValueError, match="argument 'actuated': unknown joint 'hip'"):
        ur5.constrained_inverse_dynamics(q, v, tau, loop(ur5), actuated=["hip"])
    with pytest.raises(ValueError, match="argument 'tau'"):
        ur5.constrained_forward_dynamics(q, v, tau[:3], loop(ur5))


FOUR_BAR = """<robot name="four_bar">
  <link name="ground"/>
  <joint name="crank_joint" type="continuous"><parent link="ground"/><child link="crank"/><axis xyz="0 1 0"/></joint>
  <link name="crank"><inertial><origin xyz="0.1 0 0"/><mass value="0.5"/>
    <inertia ixx="1e-4" ixy="0" ixz="0" iyy="2e-3" iyz="0" izz="2e-3"/></inertial></link>
  <joint name="coupler_joint" type="continuous"><parent link="crank"/><child link="coupler"/>
    <origin xyz="0.2 0 0"/><axis xyz="0 1 0"/></joint>
  <link name="coupler"><inertial><origin xyz="0.3 0 0"/><mass value="1.0"/>
    <inertia ixx="1e-4" ixy="0" ixz="0" iyy="3e-2" iyz="0" izz="3e-2"/></inertial></link>
  <joint name="rocker_joint" type="continuous"><parent link="coupler"/><child link="rocker"/>
    <origin xyz="0.6 0 0"/><axis xyz="0 1 0"/></joint>
  <link name="rocker"><inertial><origin xyz="0.25 0 0"/><mass value="0.8"/>
    <inertia ixx="1e-4" ixy="0" ixz="0" iyy="1.7e-2" iyz="0" izz="1.7e-2"/></inertial></link>
  <joint name="tip_joint" type="fixed"><parent link="rocker"/><child link="tip"/><origin xyz="0.5 0 0"/></joint>
  <link name="tip"/>
</robot>"""
#: The ground pivot the rocker's tip is held to.
PIVOT = np.array([0.6, 0.0, 0.0])
#: How far the simulated loop may come apart (m) and its energy change (J).
LOOP_DRIFT = 1e-8
ENERGY_CHANGE = 1e-7


def four_bar():
    """The planar four-bar, its closure (x and z of the tip at the pivot) and a closed configuration
    (Newton's method on the coupler and rocker angles)."""
    model = robodyn.load_urdf_string(FOUR_BAR)
    placement = np.eye(4)
    placement[:3, 3] = PIVOT
    closure = robodyn.FrameAnchor("tip", placement2=placement, mask=[True, False, True, False, False, False])
    q = np.array([1.2, -1.6, -1.4])
    for _ in range(50):
        error = (model.frame_pose(q, "tip")[:3, 3] - PIVOT)[[0, 2]]
        q[1:] -= np.linalg.solve(model.constraint_jacobian(q, closure)[:, 1:], error)
    assert np.max(np.abs(model.frame_pose(q, "tip")[:3, 3] - PIVOT)) < 1e-14
    return model, closure, q


def test_a_simulated_four_bar_stays_closed_and_keeps_its_energy():
    model, closure, q0 = four_bar()
    # the case: 10 s at dt = 1e-3 with RK4 (measured: 3e-11 m apart, 1e-10 J)
    run = robodyn.simulate(model, q0, t_end=10.0, dt=1e-3, integrator="rk4", constraints=closure)
    tips = model.frame_pose(run.q, "tip")[:, :3, 3]
    assert np.max(np.abs(tips - PIVOT)) < LOOP_DRIFT
    energy = model.kinetic_energy(run.q, run.v) + model.potential_energy(run.q)
    assert np.max(np.abs(energy - energy[0])) < ENERGY_CHANGE
    assert np.ptp(run.q[:, 0]) > 0.3, "the linkage swings"
    # without the closure the chain falls apart from the pivot
    free = robodyn.simulate(model, q0, t_end=0.5, dt=1e-3, integrator="rk4")
    assert np.max(np.abs(model.frame_pose(free.q[-1], "tip")[:3, 3] - PIVOT)) > 1e-2
    # a batch of starts, each on its own
    runs = robodyn.simulate(model, np.stack([q0, q0]), np.stack([np.zeros(3), np.full(3, 0.0)]), t_end=0.2, constraints=[closure])
    np.testing.assert_array_equal(runs[0].q, runs[1].q)
    with pytest.raises(ValueError, match="argument 'baumgarte'"):
        robodyn.simulate(model, q0, t_end=0.1, constraints=closure, baumgarte="stiff")


def test_weighted_inverse_dynamics_moves_the_load_off_heavy_rows():
    """Solo12 standing: four feet leave one vertical mode free (one diagonal pair of feet against
    the other). With the FL-HR diagonal's rows weighted ten times, the other diagonal carries more
    (W/11 against W/2 on a symmetric stance); the weight is still carried, and W·forces lies in
    the base rows' column space."""
    solo = robodyn.load("solo12.urdf", floating_base=True)
    feet = [robodyn.PointAnchor(foot) for foot in ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")]
    q = solo.neutral()
    q[7:] = [0.0, 0.8, -1.6, 0.0, 0.8, -1.6, 0.0, -0.8, 1.6, 0.0, -0.8, 1.6]
    rest = np.zeros(solo.nv)
    plain = solo.constrained_inverse_dynamics(q, rest, rest, feet)["forces"].reshape(4, 3)
    weights = np.repeat([10.0, 1.0, 1.0, 10.0], 3)
    weighted = solo.constrained_inverse_dynamics(q, rest, rest, feet, weights=weights)["forces"]
    assert_close(weighted.reshape(4, 3).sum(axis=0), plain.sum(axis=0), IDENTITY_TOLERANCE)
    assert weighted.reshape(4, 3)[[0, 3], 2].sum() < 0.5 * plain[[0, 3], 2].sum()
    base = solo.constraint_jacobian(q, feet)[:, :6]
    null = np.linalg.svd(base.T)[2][6:]
    assert np.max(np.abs(null @ (weights * weighted))) < IDENTITY_TOLERANCE * np.max(np.abs(weights * weighted))
    with pytest.raises(ValueError, match="weights.*row 3"):
        solo.constrained_inverse_dynamics(q, rest, rest, feet, weights=np.array([1.0, 1, 1, -1, 1, 1, 1, 1, 1, 1, 1, 1]))
    with pytest.raises(ValueError, match="weights"):
        solo.constrained_inverse_dynamics(q, rest, rest, feet, weights=np.ones(5))


def test_an_opened_four_bar_is_closed_again_and_its_error_read():
    model, closure, closed = four_bar()
    assert np.max(np.abs(model.constraint_error(closed, closure))) < 1e-14
    opened = closed + np.array([0.05, -0.03, 0.04])
    # the rows' error is the tip's offset from the pivot along x and z
    tip = model.frame_pose(opened, "tip")[:3, 3]
    assert_close(model.constraint_error(opened, closure), (tip - PIVOT)[[0, 2]], 1e-15)
    result = model.close_constraints(opened, closure)
    assert result["success"] and result["residual"] <= 1e-12 and 0 < result["iterations"] <= 6
    assert np.max(np.abs(model.frame_pose(result["q"], "tip")[:3, 3] - PIVOT)) <= 1e-12
    # a batch: each configuration on its own, the closed one unchanged
    batch = model.close_constraints(np.stack([opened, closed]), [closure])
    np.testing.assert_array_equal(batch["q"][0], result["q"])
    np.testing.assert_array_equal(batch["q"][1], closed)
    assert batch["success"].tolist() == [True, True] and batch["iterations"][1] == 0
    assert model.constraint_error(np.stack([opened, closed]), closure).shape == (2, 2)
    # held at two places at once: not closed, and said so
    far = np.eye(4)
    far[:3, 3] = PIVOT + [10.0, 0.0, 0.0]
    impossible = [closure, robodyn.FrameAnchor("tip", placement2=far, mask=[True, False, True, False, False, False])]
    result = model.close_constraints(opened, impossible, max_iterations=10)
    assert not result["success"] and result["iterations"] == 10 and result["residual"] > 1.0
    for name, value in (("tolerance", 0.0), ("damping", -1.0), ("max_iterations", -1)):
        with pytest.raises(ValueError, match=f"argument '{name}'"):
            model.close_constraints(opened, closure, **{name: value})
