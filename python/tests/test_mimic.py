"""Mimic joints in reduced coordinates (``robodyn.load(path, mimic=True)``): field by field against
Pinocchio 4.1's ``buildModelFromUrdf(path, mimic=True)`` on every example-robot-data file it builds
with mimic joints, against the full model holding the relations as constraints (an independent
algorithm: the KKT system) where Pinocchio refuses the file (a leader later in the tree), and by
finite differences."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import sympy as sp
from conftest import CROSS_CHECK_TOLERANCE, IDENTITY_TOLERANCE, assert_close

import robodyn



def pinocchio_mimic_files() -> list[str]:
    """Every example-robot-data URDF with mimic joints that Pinocchio 4.1 builds with mimic=True
    (path under robots/): Panda's two, Baxter, PR2 and TIAGo Pro at the time of writing."""
    import pinocchio as pin

    robots = robodyn._example_robot_data_dir()
    found = []
    for path in sorted(robots.rglob("*.urdf")) if robots else []:
        if "<mimic" not in path.read_text(errors="replace"):
            continue
        try:
            model = pin.buildModelFromUrdf(str(path), mimic=True)
        except Exception:  # Pinocchio refuses a leader that comes after its follower
            continue
        if model.nvExtended > model.nv:
            found.append(path.relative_to(robots).as_posix())
    return found


PINOCCHIO_MIMIC_FILES = pinocchio_mimic_files()
#: Files where a leader's joint comes after its follower's (Pinocchio refuses them).
LEADER_LATER_FILES = ["talos_data/robots/talos_full_v2.urdf", "romeo_description/urdf/romeo.urdf"]
#: Central differences with this step are exact to about its square times the third derivative.
FINITE_DIFFERENCE_STEP = 1e-6
FINITE_DIFFERENCE_TOLERANCE = 1e-6
#: The full model holding the relations (a proximal KKT solve) against the reduced equations.
KKT_TOLERANCE = 1e-8


def load(path, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", robodyn.ModelWarning)
        return robodyn.load(path, **options)


class PinocchioMimicLayout:
    """q_red and v_red in Pinocchio's mimic model, through the kept joints' names."""

    def __init__(self, model, pin_model):
        self.model, self.pin_model = model, pin_model
        self.joints, self.v_index = [], np.zeros(model.nv, dtype=int)
        for name, kind, iq, iv in zip(model.joint_names, model.joint_types, model.joint_idx_q, model.joint_idx_v):
            if name in model.followers:
                continue
            joint = pin_model.joints[pin_model.getJointId(name)]
            self.joints.append((iq, joint.idx_q, joint.nq, joint.nq == 2 and joint.nv == 1))
            self.v_index[iv : iv + joint.nv] = np.arange(joint.idx_v, joint.idx_v + joint.nv)

    def q(self, q):
        out = np.zeros(self.pin_model.nq)
        for iq, pin_iq, pin_nq, continuous in self.joints:
            out[pin_iq : pin_iq + pin_nq] = [np.cos(q[iq]), np.sin(q[iq])] if continuous else q[iq : iq + pin_nq]
        return out

    def v(self, v):
        out = np.zeros(self.pin_model.nv)
        out[self.v_index] = v
        return out


def random_state(model, seed):
    rng = np.random.default_rng(seed)
    return model.random_configuration(seed=seed), rng.standard_normal(model.nv), rng.standard_normal(model.nv)


def test_pinocchio_builds_the_expected_files():
    assert {"panda_description/urdf/panda.urdf", "pr2_description/urdf/pr2.urdf",
            "tiago_pro_description/robots/tiago_pro.urdf"} <= set(PINOCCHIO_MIMIC_FILES)


@pytest.mark.parametrize("path", PINOCCHIO_MIMIC_FILES)
def test_reduced_dynamics_agree_with_pinocchio(path, robots_dir):
    import pinocchio as pin

    model = load(robots_dir / path, mimic=True)
    pin_model = pin.buildModelFromUrdf(str(robots_dir / path), mimic=True)
    data = pin_model.createData()
    layout = PinocchioMimicLayout(model, pin_model)
    assert (model.nv, len(model.followers)) == (pin_model.nv, pin_model.nvExtended - pin_model.nv)
    v_index = layout.v_index
    for seed in range(3):
        q, v, a = random_state(model, seed)
        pq, pv, pa = layout.q(q), layout.v(v), layout.v(a)
        tau = model.inverse_dynamics(q, v, a)
        assert_close(tau, pin.rnea(pin_model, data, pq, pv, pa)[v_index], CROSS_CHECK_TOLERANCE, "rnea")
        mass = pin.crba(pin_model, data, pq)
        mass = np.triu(mass) + np.triu(mass, 1).T
        assert_close(model.mass_matrix(q), mass[np.ix_(v_index, v_index)], CROSS_CHECK_TOLERANCE, "crba")
        bias = pin.nonLinearEffects(pin_model, data, pq, pv)[v_index]
        assert_close(model.bias_forces(q, v), bias, CROSS_CHECK_TOLERANCE, "bias")
        gravity = pin.computeGeneralizedGravity(pin_model, data, pq)[v_index]
        assert_close(model.generalized_gravity(q), gravity, CROSS_CHECK_TOLERANCE, "gravity")
        # Pinocchio's ABA refuses mimic joints: its M and h, solved
        expected = np.linalg.solve(mass[np.ix_(v_index, v_index)], tau - bias)
        assert_close(model.forward_dynamics(q, v, tau), expected, 1e-7, "forward dynamics")
        pin.computeJointJacobians(pin_model, data, pq)
        pin.updateFramePlacements(pin_model, data)
        for frame in model.frame_names[1:]:
            jacobian = pin.getFrameJacobian(pin_model, data, pin_model.getFrameId(frame), pin.LOCAL_WORLD_ALIGNED)
            assert_close(model.jacobian(q, frame), jacobian[:, v_index], CROSS_CHECK_TOLERANCE, frame)
        assert_close(model.center_of_mass(q), pin.centerOfMass(pin_model, data, pq), CROSS_CHECK_TOLERANCE, "com")
        # Pinocchio's kinetic energy refuses mimic joints: ½ vᵀ M v
        energy = 0.5 * v @ mass[np.ix_(v_index, v_index)] @ v
        assert model.kinetic_energy(q, v) == pytest.approx(energy, rel=CROSS_CHECK_TOLERANCE)


@pytest.mark.parametrize("path", LEADER_LATER_FILES)
def test_leaders_later_in_the_tree_against_the_held_relations(path, robots_dir):
    """Files where a leader's joint comes after its follower's in the file (Pinocchio refuses them):
    the reduced equations (M_red solved) against the full model holding each relation as a
    JointCoupling (its KKT system)."""
    import pinocchio as pin

    with pytest.raises(Exception, match="not in the kinematic tree"):
        pin.buildModelFromUrdf(str(robots_dir / path), mimic=True)
    model = load(robots_dir / path, mimic=True)
    full = model.full
    names = full.joint_names
    # Romeo's fingers have massless links (M is singular): a rotor inertia on every joint
    full.armature = np.full(full.nv, 0.01)
    for seed in range(2):
        q, v, tau = random_state(model, seed)
        qdd = model.forward_dynamics(q, v, tau)
        held = full.constrained_forward_dynamics(model.expand(q), model.expand_velocity(v), model._actuation(tau),
                                                 model._couplings())
        assert_close(model.expand_velocity(qdd), held["qdd"], KKT_TOLERANCE, "forward dynamics")
        assert_close(model.inverse_dynamics(q, v, qdd), tau, IDENTITY_TOLERANCE, "aba ∘ rnea")
        # each follower moves with its leader
        expanded = model.expand(q)
        for follower, (leader, ratio, offset) in model.followers.items():
            iq = full.joint_idx_q
            assert expanded[iq[names.index(follower)]] == pytest.approx(ratio * expanded[iq[names.index(leader)]] + offset)


def link(name, mass=0.3):
    return (f'<link name="{name}"><inertial><origin xyz="0.02 0.01 0.05"/><mass value="{mass}"/>'
            f'<inertia ixx="0.002" ixy="0.0001" ixz="0" iyy="0.003" iyz="0" izz="0.002"/></inertial></link>')


def joint(name, kind, parent, child, axis, mimic="", xyz="0 0 0.1"):
    limit = '<limit lower="-1" upper="1" effort="10" velocity="2"/>'
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}" rpy="0.1 0 0.2"/><axis xyz="{axis}"/>{limit}{mimic}</joint>')


#: An arm with a gripper: 'right' mirrors 'left' (with an offset), 'thumb' follows 'wrist' and 'tip'
#: follows 'thumb' (a chain); 'thumb' comes before its leader's joint in the file.
GRIPPER = ('<robot name="gripper"><link name="base"/>' + "".join(link(n) for n in ("arm", "hand", "lf", "rf", "th", "tp"))
           + joint("shoulder", "revolute", "base", "arm", "0 0 1")
           + joint("thumb", "revolute", "hand", "th", "1 0 0", '<mimic joint="wrist" multiplier="0.5" offset="0.1"/>')
           + joint("tip", "revolute", "th", "tp", "1 0 0", '<mimic joint="thumb" multiplier="2" offset="-0.2"/>')
           + joint("wrist", "revolute", "arm", "hand", "0 1 0")
           + joint("left", "prismatic", "hand", "lf", "0 1 0")
           + joint("right", "prismatic", "hand", "rf", "0 1 0", '<mimic joint="left" multiplier="-1" offset="0.01"/>')
           + "</robot>")


@pytest.fixture
def gripper(tmp_path):
    path = tmp_path / "gripper.urdf"
    path.write_text(GRIPPER)
    return load(path, mimic=True)


def central_difference(f, x, step=FINITE_DIFFERENCE_STEP):
    columns = []
    for k in range(len(x)):
        dx = np.zeros(len(x))
        dx[k] = step
        columns.append((np.asarray(f(x + dx)) - np.asarray(f(x - dx))) / (2 * step))
    return np.stack(columns, axis=-1)


def test_the_reduced_coordinates_and_the_chain_of_relations(gripper):
    m = gripper
    assert (m.full.nq, m.nq, m.nv) == (6, 3, 3)
    assert m.followers == {"thumb": ("wrist", 0.5, 0.1), "tip": ("wrist", 1.0, 0.0), "right": ("left", -1.0, 0.01)}
    q = np.array([0.3, -0.4, 0.02])
    names = m.full.joint_names
    full = dict(zip(names, m.expand(q)))
    assert full == pytest.approx({"shoulder": 0.3, "wrist": -0.4, "thumb": -0.1, "tip": 2 * -0.1 - 0.2,
                                  "left": 0.02, "right": -0.01})
    assert m.joint_idx_q == [0, 1, 1, 1, 2, 2]
    assert_close(m.reduce(m.expand(q)), q, 0.0, "reduce ∘ expand")
    # the follower's armature reaches its leader through the transmission squared
    m.full.armature = np.arange(1.0, 7.0)
    assert m.full.joint_names == ["shoulder", "wrist", "thumb", "tip", "left", "right"]
    assert_close(m.armature, [1.0, 2 + 0.25 * 3 + 1.0 * 4, 5 + 6], 1e-15, "armature")
    # the reduced limits keep every joint of a group in range: right = 0.01 - left ≤ 1
    assert_close(m.lower_position_limit, [-1, -1, -0.99], 1e-15, "lower")
    assert_close(m.upper_position_limit, [1, 1, 1], 1e-15, "upper")


def test_derivatives_are_the_finite_differences_of_the_reduced_dynamics(gripper):
    m = gripper
    q, v, a = random_state(m, 4)
    derivatives = m.inverse_dynamics_derivatives(q, v, a)
    for key, f, x in (("dtau_dq", lambda x: m.inverse_dynamics(x, v, a), q),
                      ("dtau_dv", lambda x: m.inverse_dynamics(q, x, a), v)):
        assert_close(derivatives[key], central_difference(f, x), FINITE_DIFFERENCE_TOLERANCE, key)
    assert_close(derivatives["dtau_da"], m.mass_matrix(q), IDENTITY_TOLERANCE, "dtau_da")
    tau = m.inverse_dynamics(q, v, a)
    forward = m.forward_dynamics_derivatives(q, v, tau)
    for key, f, x in (("dqdd_dq", lambda x: m.forward_dynamics(x, v, tau), q),
                      ("dqdd_dv", lambda x: m.forward_dynamics(q, x, tau), v),
                      ("dqdd_dtau", lambda x: m.forward_dynamics(q, v, x), tau)):
        assert_close(forward[key], central_difference(f, x), FINITE_DIFFERENCE_TOLERANCE, key)
    for frame in ("tp", "rf"):
        position = central_difference(lambda x, frame=frame: m.frame_pose(x, frame)[:3, 3], q)
        assert_close(m.jacobian(q, frame)[:3], position, FINITE_DIFFERENCE_TOLERANCE, frame)


def test_the_lagrangian_identities_hold_in_reduced_coordinates(gripper):
    m = gripper
    q, v, _ = random_state(m, 5)
    # Ṁ − 2C is skew-symmetric
    mass_rate = central_difference(lambda t: m.mass_matrix(q + t[0] * v), np.zeros(1))[..., 0]
    skew = mass_rate - 2 * m.coriolis_matrix(q, v)
    assert_close(skew + skew.T, np.zeros((3, 3)), FINITE_DIFFERENCE_TOLERANCE, "Ṁ − 2C")
    # C_ij = Σ_k Γ_ijk v_k, and the velocity terms split into squares and products
    christoffel = m.christoffel(q)
    assert_close(christoffel @ v, m.coriolis_matrix(q, v), IDENTITY_TOLERANCE, "Γ v")
    j, k = np.triu_indices(3, 1)
    velocity_terms = m.centrifugal_matrix(q) @ v**2 + m.coriolis_pairs_matrix(q) @ (v[j] * v[k])
    assert_close(velocity_terms, m.bias_forces(q, v) - m.generalized_gravity(q), IDENTITY_TOLERANCE, "C v")
    assert m.kinetic_energy(q, v) == pytest.approx(0.5 * v @ m.mass_matrix(q) @ v, rel=IDENTITY_TOLERANCE)


def test_simulation_integrates_the_reduced_equations(gripper):
    """simulate (the full model holding the relations) against RK4 on the reduced forward dynamics
    (M_red solved), and energy kept without damping."""
    m = gripper
    q0, v0 = np.array([0.2, -0.3, 0.01]), np.array([1.0, -0.5, 0.1])
    dt, steps = 1e-3, 100
    run = robodyn.simulate(m, q0, v0, t_end=dt * steps, dt=dt)
    x = np.concatenate([q0, v0])

    def f(x):
        return np.concatenate([x[3:], m.forward_dynamics(x[:3], x[3:], np.zeros(3))])

    for _ in range(steps):
        k1 = f(x)
        k2 = f(x + dt / 2 * k1)
        k3 = f(x + dt / 2 * k2)
        k4 = f(x + dt * k3)
        x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    assert_close(run.q[-1], x[:3], KKT_TOLERANCE, "q")
    assert_close(run.v[-1], x[3:], KKT_TOLERANCE, "v")
    assert np.ptp(run.energy) < 1e-9 * np.max(run.kinetic_energy)
    assert run.q.shape == (steps + 1, 3) and run.tau.shape == (steps + 1, 3)


def test_controllers_act_on_the_reduced_coordinates(gripper):
    m = gripper
    q_ref = np.array([0.3, 0.2, 0.02])
    pd = robodyn.simulate(m, m.neutral(), t_end=0.05, controller=robodyn.PD(kp=[20, 30, 40], kd=2, q_ref=q_ref))

    def by_hand(t, q, v):
        return np.array([20, 30, 40]) * (q_ref - q) - 2 * v

    callable_run = robodyn.simulate(m, m.neutral(), t_end=0.05, controller=by_hand)
    assert_close(pd.q, callable_run.q, 1e-12, "PD")
    assert_close(pd.tau, callable_run.tau, 1e-9, "PD τ")
    # computed torque from the reference's start tracks it exactly
    times = np.array([0.0, 0.1])
    knots = np.array([[0.0, 0.0, 0.0], [0.2, -0.1, 0.01]])
    rates = np.array([[0.0, 0.0, 0.0], [1.0, -0.5, 0.05]])
    run = robodyn.simulate(m, knots[0], rates[0], t_end=0.1, controller=robodyn.ComputedTorque(
        kp=100, kd=20, reference=(times, knots, rates)))
    assert_close(run.q[-1], knots[-1], 1e-8, "computed torque")


def test_one_step_and_its_jacobians(gripper):
    m = gripper
    q, v, tau = random_state(m, 6)
    x1, a, b = robodyn.step(m, q, v, tau, 1e-3, derivatives=True)
    assert_close(x1, robodyn.step(m, q, v, tau, 1e-3), 0.0, "x1")

    def stepped(x):
        return robodyn.step(m, x[:3], x[3:], tau, 1e-3)

    assert_close(a, central_difference(stepped, np.concatenate([q, v])), FINITE_DIFFERENCE_TOLERANCE, "A")
    assert_close(b, central_difference(lambda t: robodyn.step(m, q, v, t, 1e-3), tau),
                 FINITE_DIFFERENCE_TOLERANCE, "B")


def test_constraints_on_the_reduced_model(gripper):
    """A point of the right finger held: the reduced KKT residuals, and those of the inverse problem."""
    m = gripper
    anchor = robodyn.PointAnchor("rf")
    q, v, tau = random_state(m, 7)
    result = m.constrained_forward_dynamics(q, v, tau, [anchor])
    qdd, forces = result["qdd"], result["forces"]
    jacobian = m.constraint_jacobian(q, [anchor])
    assert jacobian.shape == (3, 3) and forces.shape == (3,)
    residual = m.mass_matrix(q) @ qdd + m.bias_forces(q, v) - tau - jacobian.T @ forces
    assert_close(residual, np.zeros(3), KKT_TOLERANCE, "dynamics")
    drift = m.jacobian_time_variation(q, v, "rf")[:3] @ v
    assert_close(jacobian @ qdd + drift, np.zeros(3), KKT_TOLERANCE, "J q̈ + J̇ v")
    assert_close(m.delassus(q, [anchor]), jacobian @ np.linalg.solve(m.mass_matrix(q), jacobian.T),
                 IDENTITY_TOLERANCE, "delassus")
    inverse = m.constrained_inverse_dynamics(q, v, qdd, [anchor], actuated=["wrist", "left"])
    assert inverse["tau"][0] == 0.0
    residual = m.inverse_dynamics(q, v, qdd) - inverse["tau"] - jacobian.T @ inverse["forces"]
    assert_close(residual, np.zeros(3), KKT_TOLERANCE, "inverse")
    with pytest.raises(ValueError, match=r"the leaders of \['right'\] are not"):
        m.constrained_inverse_dynamics(q, v, qdd, [anchor], actuated=["wrist", "shoulder"])
    derivatives = m.constrained_forward_dynamics_derivatives(q, v, tau, [anchor])
    for key, f, x in (("dqdd_dq", lambda x: m.constrained_forward_dynamics(x, v, tau, [anchor])["qdd"], q),
                      ("dforces_dv", lambda x: m.constrained_forward_dynamics(q, x, tau, [anchor])["forces"], v),
                      ("dqdd_dtau", lambda x: m.constrained_forward_dynamics(q, v, x, [anchor])["qdd"], tau)):
        assert_close(derivatives[key], central_difference(f, x), FINITE_DIFFERENCE_TOLERANCE, key)
    impulse = m.impulse_dynamics_derivatives(q, v, [anchor])
    assert_close(impulse["dv_dv"], central_difference(lambda x: m.impulse_dynamics(q, x, [anchor])["v"], v),
                 FINITE_DIFFERENCE_TOLERANCE, "dv_dv")
    assert_close(jacobian @ impulse["v"], np.zeros(3), KKT_TOLERANCE, "J v⁺")
    # the point held where it is at q: from elsewhere, closing brings it back in reduced coordinates
    held = robodyn.PointAnchor("rf", offset2=m.frame_pose(q, "rf")[:3, 3])
    moved = q + np.array([0.05, -0.04, 0.03])
    assert_close(m.constraint_error(moved, held), m.frame_pose(moved, "rf")[:3, 3] - m.frame_pose(q, "rf")[:3, 3],
                 IDENTITY_TOLERANCE, "φ")
    closed = m.close_constraints(moved, held)
    assert closed["success"] and closed["q"].shape == (3,)
    assert np.max(np.abs(m.frame_pose(closed["q"], "rf")[:3, 3] - m.frame_pose(q, "rf")[:3, 3])) <= 1e-12


def test_every_method_of_a_model_is_reduced(gripper):
    public = {name for name in dir(robodyn.Model) if not name.startswith("_")}
    missing = sorted(name for name in public if not hasattr(gripper, name))
    assert missing == []
    # what is not a coordinate is the full model's; the rest is computed for q_red
    assert gripper.frame_names == gripper.full.frame_names and gripper.nv == 3
    for name in ("armature", "damping", "friction", "stiffness", "spring_reference", "velocity_limit",
                 "effort_limit", "lower_position_limit", "upper_position_limit", "neutral"):
        value = getattr(gripper, name)
        assert np.shape(value() if callable(value) else value) in ((3,),), name
    with pytest.raises(ValueError, match="m.full"):
        gripper.armature = [1.0, 1.0, 1.0]
    restored = __import__("pickle").loads(__import__("pickle").dumps(gripper))
    assert_close(restored.mass_matrix([0.1, 0.2, 0.0]), gripper.mass_matrix([0.1, 0.2, 0.0]), 0.0, "pickle")


def test_bad_relations_and_arguments_are_refused(tmp_path, gripper):
    path = tmp_path / "bad.urdf"
    wrist = joint("wrist", "revolute", "arm", "hand", "0 1 0")
    path.write_text(GRIPPER.replace(wrist, joint("wrist", "revolute", "arm", "hand", "0 1 0",
                                                 '<mimic joint="tip" multiplier="1" offset="0"/>')))
    with pytest.raises(ValueError, match="the mimic relations form a cycle: .* → .* → "):
        load(path, mimic=True)
    right = joint("right", "prismatic", "hand", "rf", "0 1 0", '<mimic joint="left" multiplier="-1" offset="0.01"/>')
    path.write_text(GRIPPER.replace(right, right.replace('joint="left"', 'joint="wrist"')))
    with pytest.raises(ValueError, match=r"joint 'right' \(prismatic\) mimics 'wrist' \(revolute\)"):
        load(path, mimic=True)
    with pytest.raises(ValueError, match=r"argument 'q': expected shape \(3,\) or \(N, 3\), got \(6,\)"):
        gripper.inverse_dynamics(np.zeros(6), np.zeros(3), np.zeros(3))
    path.write_text(GRIPPER)
    with pytest.raises(ValueError, match="argument 'mimic': expected True or False"):
        robodyn.load(path, mimic="yes")
    # by default the followers are joints of their own, and a warning says how to enforce them
    with pytest.warns(robodyn.ModelWarning, match=r"3 mimic joint\(s\) .* mimic=True\) enforces them"):
        full = robodyn.load(path)
    assert full.nq == 6 and len(full.constraints) == 3


def test_follower_limits_that_contradict_the_relation_are_reported(robots_dir):
    """PR2's mirrored gripper joints have the same limits as their leader, whose relation flips the
    sign: no common range, so q_red keeps the leader's limits and says so."""
    model = load(robots_dir / "pr2_description/urdf/pr2.urdf", mimic=True)
    notes = [w for w in model.warnings if "contradict" in w]
    assert len(notes) == 2 and any("r_gripper_r_parallel_root_joint" in note for note in notes)
    j = model.joint_idx_q[model.joint_names.index("r_gripper_l_finger_joint")]
    assert (model.lower_position_limit[j], model.upper_position_limit[j]) == (0.0, 0.548)


def test_batches_inverse_kinematics_and_the_workspace(gripper):
    m = gripper
    q = m.random_configuration(5, seed=3)
    v = np.random.default_rng(3).standard_normal((5, 3))
    batch = m.inverse_dynamics(q, v, v)
    assert batch.shape == (5, 3)
    assert_close(batch[2], m.inverse_dynamics(q[2], v[2], v[2]), 1e-14, "batch")
    assert m.mass_matrix(q).shape == (5, 3, 3) and m.jacobian(q, "rf").shape == (5, 6, 3)
    target = m.frame_pose(q[0], "rf")
    solution = m.inverse_kinematics("rf", target, q0=m.neutral())
    assert solution["success"] and solution["residual"] < 1e-10
    assert_close(m.frame_pose(solution["q"], "rf"), target, 1e-9, "pose")
    lower, upper = m.lower_position_limit, m.upper_position_limit
    assert np.all((solution["q"] >= lower) & (solution["q"] <= upper))
    points = m.workspace("rf", n=50, seed=1)
    assert points.shape == (50, 3)
    space = m.operational_space(q[0], v[0], "rf", task="position")
    assert_close(space["J"], m.jacobian(q[0], "rf")[:3], 0.0, "task Jacobian")


def planar_link(name):
    return (f'<link name="{name}"><inertial><origin xyz="0.1 0 0"/><mass value="0.5"/>'
            '<inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.002"/></inertial></link>')


def planar_fingers(ratio="-1"):
    """A planar hand: 'j2' turns against 'j1' (with an offset), 'j4' slides twice as far as 'j3'."""
    def joint_(name, kind, parent, child, axis, mimic="", xyz="0.2 0 0"):
        return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
                f'<origin xyz="{xyz}" rpy="0 0.3 0"/><axis xyz="{axis}"/>'
                f'<limit lower="-1" upper="1" effort="10" velocity="2"/>{mimic}</joint>')
    return ('<robot name="fingers"><link name="base"/>' + "".join(planar_link(n) for n in "abcd")
            + joint_("j1", "revolute", "base", "a", "0 0 1", xyz="0 0 0")
            + joint_("j2", "revolute", "a", "b", "0 0 1", f'<mimic joint="j1" multiplier="{ratio}" offset="0.25"/>')
            + joint_("j3", "prismatic", "a", "c", "0 1 0")
            + joint_("j4", "prismatic", "a", "d", "0 1 0", '<mimic joint="j3" multiplier="2" offset="0"/>')
            + "</robot>")


@pytest.mark.parametrize("ratio", ["-1", "0.5"])
def test_symbolic_equations_in_reduced_coordinates(tmp_path, ratio):
    """Lagrange's and Newton–Euler's equations of the chain with its relations, against the
    numeric reduced model; Ṁ − 2C skew exactly (a whole ratio; a half one keeps its own angle)."""
    from robodyn import symbolic as sym

    path = tmp_path / "fingers.urdf"
    path.write_text(planar_fingers(ratio))
    with pytest.raises(ValueError, match="pass mimic=True"):
        sym.from_urdf(path)
    chain = sym.from_urdf(path, mimic=True)
    assert chain.mimics == {1: (0, sp.Rational(ratio), sp.Rational("0.25")), 3: (2, 2, 0)}
    equations = sym.lagrange(chain)
    assert equations.n == 2 and list(equations.q) == [chain.q[0], chain.q[2]]
    numeric, model = equations.lambdify(), load(path, mimic=True)
    for seed in range(3):
        q, v, a = random_state(model, seed)
        assert_close(numeric.tau(q, v, a), model.inverse_dynamics(q, v, a), IDENTITY_TOLERANCE, "τ")
        assert_close(numeric.M(q), model.mass_matrix(q), IDENTITY_TOLERANCE, "M")
        assert_close(numeric.C(q, v), model.coriolis_matrix(q, v), IDENTITY_TOLERANCE, "C")
        assert_close(numeric.G(q), model.generalized_gravity(q), IDENTITY_TOLERANCE, "G")
    if ratio == "-1":
        assert equations.skew_residual() == sp.zeros(2)
        assert sym.newton_euler(chain).difference(equations) == sp.zeros(2, 1)



def test_polynomial_springs_and_dampers_through_the_transmission(gripper):
    """A reduced coordinate's dampers are its group's, each −(b + b₁ |r q̇| + b₂ r² q̇²) r q̇ pulled
    through r: Gᵀ τ_full equals the reduced polynomial with (Σ r² b, Σ |r|³ b₁, Σ r⁴ b₂), exactly; so
    do the springs of groups with one spring each, (r² k, r³ k₁, r⁴ k₂) about the reduced reference.
    Two springs with higher terms in one group have no such polynomial: refused by name."""
    full, rng = gripper.full, np.random.default_rng(4)
    full.damping = rng.uniform(0.1, 0.6, full.nv)
    full.damping_poly = rng.uniform(0.1, 1.0, (full.nv, 2))
    v = rng.normal(size=gripper.nv)
    rate = gripper.coupling @ v
    tau = gripper.coupling.T @ (-(full.damping + full.damping_poly[:, 0] * np.abs(rate) + full.damping_poly[:, 1] * rate**2) * rate)
    b, (b1, b2) = gripper.damping, gripper.damping_poly.T
    assert_close(tau, -(b + b1 * np.abs(v) + b2 * v**2) * v, IDENTITY_TOLERANCE, "dampers")
    # one spring per group: the shoulder, the thumb (the wrist's group), the right finger (the left's)
    springs = np.zeros(full.nv)
    terms = np.zeros((full.nv, 2))
    for name, k, k1, k2 in [("shoulder", 2.0, 0.5, 3.0), ("thumb", 1.5, -0.4, 2.0), ("right", 30.0, 4.0, 80.0)]:
        dof = full.joint_idx_v[full.joint_names.index(name)]
        springs[dof], terms[dof] = k, (k1, k2)
    full.stiffness, full.stiffness_poly = springs, terms
    full.spring_reference = full.neutral() + 0.05
    q = gripper.neutral() + rng.uniform(-0.3, 0.3, gripper.nq)
    x = gripper.expand(q) - full.spring_reference
    tau = gripper.coupling.T @ (-(springs + terms[:, 0] * x + terms[:, 1] * x**2) * x)
    s = q - gripper.spring_reference
    k, (k1, k2) = gripper.stiffness, gripper.stiffness_poly.T
    assert_close(tau, -(k + k1 * s + k2 * s**2) * s, IDENTITY_TOLERANCE, "springs")
    both = terms.copy()
    both[full.joint_idx_v[full.joint_names.index("wrist")]] = (0.1, 0.0)
    full.stiffness_poly = both
    with pytest.raises(ValueError, match=r"stiffness_poly.*reduced coordinate \d moves 2 springs .*(wrist|thumb).*m.full"):
        gripper.stiffness_poly
