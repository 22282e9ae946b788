"""Constrained dynamics against Pinocchio 4.1, field by field: point contacts (Solo12's feet), sole
contacts (Talos), loops between two moving bodies, masked rows, impulses, the constraint Jacobian,
the Delassus matrix and constrained inverse dynamics.

Pinocchio's side: `RigidConstraintModel(type, model, joint1, placement1[, joint2, placement2],
reference)` with a frame's `parentJoint` and `placement` (times the constraint's own placement in the
frame), then `initConstraintDynamics` and `constraintDynamics` with `ProximalSettings(accuracy, mu=0,
max_iter=1)`, which is one exact solve; q̈ is returned, λ is `data.lambda_c`, in the convention
M q̈ + h = τ + Jᵀλ, and J is `getConstraintsJacobian`. What its rows are, checked on its own
identities (KKT residual, J q̈ + γ = 0, finite differences of J v):

- 3-D, LOCAL_WORLD_ALIGNED: v(c1) - v(c2) in world axes, each point moving with its own body;
  γ = J̇v, the classical acceleration of c1 minus that of c2.
- 3-D, LOCAL: the same rows in c1's axes; γ is the world one rotated into c1's axes, which is not the
  time derivative of those rows.
- 6-D, LOCAL: the twist of body 1 minus that of body 2, both at c1's origin in c1's axes; γ = J̇v.
- 6-D, LOCAL_WORLD_ALIGNED: the same twist in world axes (the linear rows at c1's origin for both
  bodies); γ is the spatial acceleration, not the classical one, so again not J̇v of the rows.

Where Pinocchio's drift is not J̇v of rows robodyn defines the same way, two definitions of the drift
only agree at velocities the constraints allow (J v = 0): those comparisons run there. Every case runs
at such velocities, and the ones where the definitions agree everywhere also run at random velocities.

Pinocchio 4.1's `computeDelassusMatrix` reads neither `joint2` nor LOCAL_WORLD_ALIGNED, and its
`impulseDynamics` reads only `joint1`'s velocity: the Delassus matrix is built here as J M⁻¹ Jᵀ from
Pinocchio's J and M, and two-body impulses are solved densely from the same pieces.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
import pytest
from conftest import CROSS_CHECK_TOLERANCE, assert_close, pinocchio_model

import robodyn
from robodyn.convert import PinocchioLayout

SOLO12 = "solo_description/robots/solo12.urdf"
TALOS = "talos_data/robots/talos_reduced.urdf"
FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")
SOLES = ("left_sole_link", "right_sole_link")
REFERENCES = {"world": pin.LOCAL_WORLD_ALIGNED, "local": pin.LOCAL}
#: Pinocchio's own answers satisfy M q̈ + h = τ + Jᵀλ to this, relative to the largest term.
PINOCCHIO_RESIDUAL_TOLERANCE = 1e-10
#: A constraint-frame placement in its body that is neither the identity nor axis-aligned.
TILTED = pin.SE3(pin.rpy.rpyToMatrix(0.3, -0.2, 0.5), np.array([0.01, -0.02, 0.03])).homogeneous
#: The points of FL_FOOT and HR_FOOT that the point loop holds together (in each foot's axes).
LOOP_OFFSETS = (np.array([0.01, -0.02, 0.03]), np.array([-0.02, 0.01, 0.015]))


@dataclass(frozen=True)
class Anchor:
    """One constraint stated once and built for both libraries: a point (3 rows) or a frame (6 rows)
    of `frame`, held to the world (`frame2` None) or to `frame2`. `local` is the constraint point's
    offset (3-vector) or frame's placement (4x4) in `frame`; `local2` the same in `frame2`."""

    rows: int
    frame: str
    local: np.ndarray
    frame2: str | None = None
    local2: np.ndarray | None = None
    mask: tuple[bool, ...] | None = None

    def robodyn(self, reference):
        if self.rows == 3:
            return robodyn.PointAnchor(self.frame, self.frame2, offset=self.local, offset2=self.local2, reference=reference)
        mask = None if self.mask is None else np.array(self.mask)
        return robodyn.FrameAnchor(self.frame, self.frame2, placement=self.local, placement2=self.local2, mask=mask, reference=reference)

    def pinocchio(self, pin_model, reference):
        """Pinocchio's model of the full 3 or 6 rows (Pinocchio has no masks)."""
        kind = pin.ContactType.CONTACT_3D if self.rows == 3 else pin.ContactType.CONTACT_6D
        joint1, placement1 = _joint_placement(pin_model, self.frame, self.local)
        if self.frame2 is None:
            return pin.RigidConstraintModel(kind, pin_model, joint1, placement1, REFERENCES[reference])
        joint2, placement2 = _joint_placement(pin_model, self.frame2, self.local2)
        return pin.RigidConstraintModel(kind, pin_model, joint1, placement1, joint2, placement2, REFERENCES[reference])

    def kept_rows(self):
        return np.ones(self.rows, dtype=bool) if self.mask is None else np.array(self.mask)

    def drift_agrees_at_any_velocity(self, reference):
        """Whether Pinocchio's drift equals robodyn's at any velocity, not only where J v = 0.
        robodyn's drift is the world one (the classical acceleration of the point, the angular
        acceleration) turned into the rows' axes; Pinocchio's is that for 3-D rows, and for 6-D
        rows a spatial acceleration, which differs from it by ω × v where J v ≠ 0."""
        return self.rows == 3


def _joint_placement(pin_model, frame, local):
    """A frame of Pinocchio's model and a point or placement in it, as (joint, placement in joint)."""
    parent = pin_model.frames[pin_model.getFrameId(frame)]
    inner = pin.SE3(np.eye(3), np.asarray(local, dtype=float)) if np.shape(local) == (3,) else pin.SE3(np.asarray(local, dtype=float))
    return parent.parentJoint, parent.placement * inner


@dataclass(frozen=True)
class Robot:
    model: object
    pin_model: object
    layout: PinocchioLayout


def _robot(path) -> Robot:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", robodyn.ModelWarning)
        model = robodyn.load(path, floating_base=True)
    pin_model = pinocchio_model(path, True)
    return Robot(model, pin_model, PinocchioLayout(model, pin_model))


@pytest.fixture(scope="module")
def solo12(robots_dir) -> Robot:
    return _robot(robots_dir / SOLO12)


@pytest.fixture(scope="module")
def talos(robots_dir) -> Robot:
    return _robot(robots_dir / TALOS)


def feet(robot, q):
    return [Anchor(3, frame, np.zeros(3)) for frame in FEET]


def tilted_feet(robot, q):
    """Points off the feet's origins, so that the offset and the local axes matter."""
    return [Anchor(3, frame, np.array([0.01 * k, -0.02, 0.005 * k])) for k, frame in enumerate(FEET, 1)]


def soles(robot, q):
    return [Anchor(6, SOLES[0], np.eye(4)), Anchor(6, SOLES[1], TILTED)]


def point_loop(robot, q):
    """FL_FOOT held to HR_FOOT by a point of each, two feet on the ground."""
    return [Anchor(3, "FL_FOOT", LOOP_OFFSETS[0], "HR_FOOT", LOOP_OFFSETS[1]), Anchor(3, "FR_FOOT", np.zeros(3)), Anchor(3, "HL_FOOT", np.zeros(3))]


def hands_loop(robot, q):
    """Talos on both soles, its two hands welded where they are (the two constraint frames coincide)."""
    left, right = "wrist_left_ft_tool_link", "wrist_right_ft_tool_link"
    placement2 = np.linalg.inv(robot.model.frame_pose(q, right)) @ robot.model.frame_pose(q, left) @ TILTED
    return soles(robot, q) + [Anchor(6, left, TILTED, right, placement2)]


def masked_sole(robot, q):
    """The left sole's constraint frame free to turn about one axis (the mask drops the last angular
    row, in the reference's axes: 5 rows), the right sole held."""
    return [Anchor(6, SOLES[0], TILTED, mask=(True, True, True, True, True, False)), Anchor(6, SOLES[1], np.eye(4))]


CASES = {
    "solo12_feet": ("solo12", feet),
    "solo12_tilted_feet": ("solo12", tilted_feet),
    "solo12_point_loop": ("solo12", point_loop),
    "talos_soles": ("talos", soles),
    "talos_hands_loop": ("talos", hands_loop),
    "talos_masked_sole": ("talos", masked_sole),
}
WORLD_ANCHORED = ["solo12_feet", "solo12_tilted_feet", "talos_soles"]


def pinocchio_models(robot, anchors, reference):
    models = pin.StdVec_RigidConstraintModel()
    for anchor in anchors:
        models.append(anchor.pinocchio(robot.pin_model, reference))
    return models


def pinocchio_problem(robot, anchors, reference):
    """Pinocchio's data, constraint models and constraint datas, initialised for its solvers."""
    data, models = robot.pin_model.createData(), pinocchio_models(robot, anchors, reference)
    datas = pin.StdVec_RigidConstraintData()
    for model in models:
        datas.append(model.createData())
    pin.initConstraintDynamics(robot.pin_model, data, models, datas)
    return data, models, datas


def pinocchio_mass_matrix(pin_model, pq):
    mass = pin.crba(pin_model, pin_model.createData(), pq)
    return np.triu(mass) + np.triu(mass, 1).T


def exact_settings():
    """One proximal step with mu = 0: Pinocchio's exact constrained solve."""
    return pin.ProximalSettings(1e-14, 0.0, 1)


def pinocchio_forward(robot, anchors, reference, pq, pv, ptau):
    """Pinocchio's (q̈, λ, J) of the full rows, in Pinocchio's coordinate order, checked on its KKT system."""
    pin_model = robot.pin_model
    data, models, datas = pinocchio_problem(robot, anchors, reference)
    qdd = pin.constraintDynamics(pin_model, data, pq, pv, ptau, models, datas, exact_settings()).copy()
    forces = data.lambda_c.copy()
    jacobian = pin.getConstraintsJacobian(pin_model, data, models, datas).copy()
    terms = [pinocchio_mass_matrix(pin_model, pq) @ qdd, pin.nle(pin_model, pin_model.createData(), pq, pv), ptau, jacobian.T @ forces]
    residual = terms[0] + terms[1] - terms[2] - terms[3]
    scale = max(1.0, max(float(np.max(np.abs(t))) for t in terms))
    assert float(np.max(np.abs(residual))) <= PINOCCHIO_RESIDUAL_TOLERANCE * scale, "Pinocchio's KKT residual"
    return qdd, forces, jacobian


def kept(anchors):
    """The rows the anchors keep, as a mask over Pinocchio's full rows."""
    return np.concatenate([anchor.kept_rows() for anchor in anchors])


def allowed_velocity(jacobian, pv):
    """pv projected onto the velocities the constraints allow (J v = 0)."""
    return pv - np.linalg.pinv(jacobian) @ (jacobian @ pv)


def random_states(robot, count, seed):
    """(q, v, tau) in robodyn's order: robodyn's random configurations, uniform v and tau."""
    rng = np.random.default_rng(seed)
    for k in range(count):
        q = robot.model.random_configuration(seed=seed + k)
        yield q, rng.uniform(-1, 1, robot.model.nv), rng.uniform(-5, 5, robot.model.nv)


def case_states(request, case, reference, seed, count=3):
    """Each state of the case once at an allowed velocity and, where the drifts agree everywhere,
    once at a random velocity: (robot, anchors, q, v, tau, label)."""
    robot_name, build = CASES[case]
    robot = request.getfixturevalue(robot_name)
    for k, (q, v, tau) in enumerate(random_states(robot, count, seed)):
        anchors = build(robot, q)
        pq, pv = robot.layout.q_to_pinocchio(q), robot.layout.v_to_pinocchio(v)
        jacobian = pinocchio_forward(robot, anchors, reference, pq, pv, robot.layout.v_to_pinocchio(tau))[2][kept(anchors)]
        yield robot, anchors, q, robot.layout.v_from_pinocchio(allowed_velocity(jacobian, pv)), tau, f"{case} {reference} state {k} allowed v"
        if all(anchor.drift_agrees_at_any_velocity(reference) for anchor in anchors):
            yield robot, anchors, q, v, tau, f"{case} {reference} state {k} random v"


def reference_forward(robot, anchors, reference, q, v, tau):
    """Pinocchio's q̈ and λ (robodyn's order) with the kept rows only: Pinocchio's own solve where every
    row is kept, else a dense KKT solve of Pinocchio's M, h, J and drift γ = -J q̈ on the kept rows."""
    layout = robot.layout
    pq, pv, ptau = layout.q_to_pinocchio(q), layout.v_to_pinocchio(v), layout.v_to_pinocchio(tau)
    qdd, forces, jacobian = pinocchio_forward(robot, anchors, reference, pq, pv, ptau)
    rows = kept(anchors)
    if not rows.all():
        drift = -(jacobian @ qdd)[rows]
        jacobian = jacobian[rows]
        mass, bias = pinocchio_mass_matrix(robot.pin_model, pq), pin.nle(robot.pin_model, robot.pin_model.createData(), pq, pv)
        m = len(drift)
        # [M -Jᵀ; J 0] [q̈; λ] = [τ - h; -γ]
        kkt = np.block([[mass, -jacobian.T], [jacobian, np.zeros((m, m))]])
        solution = np.linalg.solve(kkt, np.r_[ptau - bias, -drift])
        qdd, forces = solution[: robot.pin_model.nv], solution[robot.pin_model.nv :]
    return layout.v_from_pinocchio(qdd), forces, layout.jacobian_from_pinocchio(jacobian)


@pytest.mark.parametrize("reference", sorted(REFERENCES))
@pytest.mark.parametrize("case", sorted(CASES))
def test_constraint_jacobian_and_delassus_agree_with_pinocchio(request, case, reference):
    for robot, anchors, q, v, tau, label in case_states(request, case, reference, seed=100):
        constraints = [anchor.robodyn(reference) for anchor in anchors]
        pq = robot.layout.q_to_pinocchio(q)
        jacobian = pinocchio_forward(robot, anchors, reference, pq, robot.layout.v_to_pinocchio(v), np.zeros(robot.pin_model.nv))[2][kept(anchors)]
        assert_close(robot.model.constraint_jacobian(q, constraints), robot.layout.jacobian_from_pinocchio(jacobian), CROSS_CHECK_TOLERANCE, f"{label} J")
        delassus = jacobian @ np.linalg.solve(pinocchio_mass_matrix(robot.pin_model, pq), jacobian.T)
        assert_close(robot.model.delassus(q, constraints), delassus, CROSS_CHECK_TOLERANCE, f"{label} Delassus")


@pytest.mark.parametrize("reference", sorted(REFERENCES))
@pytest.mark.parametrize("case", sorted(CASES))
def test_constrained_forward_dynamics_agrees_with_pinocchio(request, case, reference):
    for robot, anchors, q, v, tau, label in case_states(request, case, reference, seed=200):
        constraints = [anchor.robodyn(reference) for anchor in anchors]
        qdd, forces, _ = reference_forward(robot, anchors, reference, q, v, tau)
        result = robot.model.constrained_forward_dynamics(q, v, tau, constraints)
        assert_close(result["qdd"], qdd, CROSS_CHECK_TOLERANCE, f"{label} qdd")
        assert_close(result["forces"], forces, CROSS_CHECK_TOLERANCE, f"{label} forces")


def pinocchio_impulse(robot, anchors, reference, pq, pv, restitution):
    """Pinocchio's velocity after an impact and its impulses, on world-anchored constraints."""
    pin_model = robot.pin_model
    data, models, datas = pinocchio_problem(robot, anchors, reference)
    after = pin.impulseDynamics(pin_model, data, pq, pv, models, datas, restitution, exact_settings()).copy()
    return after, data.impulse_c.copy()


def impact_states(request, case, seed, count=3):
    """The case's anchors at random states, for impulses (which have no drift): (robot, anchors, q, v, k)."""
    robot_name, build = CASES[case]
    robot = request.getfixturevalue(robot_name)
    for k, (q, v, _) in enumerate(random_states(robot, count, seed)):
        yield robot, build(robot, q), q, v, k


@pytest.mark.parametrize("restitution", [0.0, 0.5])
@pytest.mark.parametrize("reference", sorted(REFERENCES))
@pytest.mark.parametrize("case", WORLD_ANCHORED)
def test_impulse_dynamics_agrees_with_pinocchio(request, case, reference, restitution):
    for robot, anchors, q, v, k in impact_states(request, case, seed=300):
        after, impulses = pinocchio_impulse(robot, anchors, reference, robot.layout.q_to_pinocchio(q), robot.layout.v_to_pinocchio(v), restitution)
        result = robot.model.impulse_dynamics(q, v, [anchor.robodyn(reference) for anchor in anchors], restitution=restitution)
        label = f"{case} {reference} e={restitution} state {k}"
        assert_close(result["v"], robot.layout.v_from_pinocchio(after), CROSS_CHECK_TOLERANCE, f"{label} v after")
        assert_close(result["impulses"], impulses, CROSS_CHECK_TOLERANCE, f"{label} impulses")


@pytest.mark.parametrize("restitution", [0.0, 0.5])
@pytest.mark.parametrize("reference", sorted(REFERENCES))
@pytest.mark.parametrize("case", ["solo12_point_loop", "talos_hands_loop"])
def test_loop_impulses_agree_with_pinocchio_pieces(request, case, reference, restitution):
    """M (v⁺ - v) = Jᵀ P and J v⁺ = -e J v, solved densely with Pinocchio's M and J."""
    robot_name, build = CASES[case]
    robot = request.getfixturevalue(robot_name)
    for k, (q, v, _) in enumerate(random_states(robot, 3, seed=400)):
        anchors = build(robot, q)
        pq, pv = robot.layout.q_to_pinocchio(q), robot.layout.v_to_pinocchio(v)
        jacobian = pinocchio_forward(robot, anchors, reference, pq, pv, np.zeros(robot.pin_model.nv))[2]
        mass_inverse_jt = np.linalg.solve(pinocchio_mass_matrix(robot.pin_model, pq), jacobian.T)
        impulses = np.linalg.solve(jacobian @ mass_inverse_jt, -(1.0 + restitution) * jacobian @ pv)
        result = robot.model.impulse_dynamics(q, v, [anchor.robodyn(reference) for anchor in anchors], restitution=restitution)
        label = f"{case} {reference} e={restitution} state {k}"
        assert_close(result["v"], robot.layout.v_from_pinocchio(pv + mass_inverse_jt @ impulses), CROSS_CHECK_TOLERANCE, f"{label} v after")
        assert_close(result["impulses"], impulses, CROSS_CHECK_TOLERANCE, f"{label} impulses")


def base_rows(robot):
    """Pinocchio's velocity indices of the free joint (the coordinates nothing actuates)."""
    root = robot.pin_model.joints[1]
    return np.arange(root.idx_v, root.idx_v + root.nv)


def test_constrained_inverse_dynamics_recovers_pinocchio_torques(talos):
    """One sole held (6 rows, 6 unactuated coordinates): the forces are unique, so the torques and
    forces that produce Pinocchio's constrained q̈ are those Pinocchio was given and returned."""
    robot, anchors = talos, soles(talos, None)[:1]
    for k, (q, v, tau) in enumerate(random_states(robot, 3, seed=500)):
        ptau = robot.layout.v_to_pinocchio(tau)
        ptau[base_rows(robot)] = 0.0
        pq, pv = robot.layout.q_to_pinocchio(q), robot.layout.v_to_pinocchio(v)
        # a velocity the sole allows: where J v ≠ 0 the two 6-D drifts differ (see the header)
        pv = allowed_velocity(pinocchio_forward(robot, anchors, "local", pq, pv, ptau)[2], pv)
        v = robot.layout.v_from_pinocchio(pv)
        qdd, forces, _ = pinocchio_forward(robot, anchors, "local", pq, pv, ptau)
        result = robot.model.constrained_inverse_dynamics(q, v, robot.layout.v_from_pinocchio(qdd), [anchors[0].robodyn("local")])
        assert_close(result["tau"], robot.layout.v_from_pinocchio(ptau), CROSS_CHECK_TOLERANCE, f"talos state {k} tau")
        assert_close(result["forces"], forces, CROSS_CHECK_TOLERANCE, f"talos state {k} forces")


@pytest.mark.parametrize("reference", sorted(REFERENCES))
def test_constrained_inverse_dynamics_minimum_norm_forces(solo12, reference):
    """Four feet (12 rows) on six unactuated coordinates: of the forces that produce q̈, the smallest,
    λ = (J_baseᵀ)⁺ (M q̈ + h)_base with Pinocchio's rnea and J, and τ = M q̈ + h - Jᵀλ (zero on the base)."""
    robot, anchors = solo12, feet(solo12, None)
    base = base_rows(robot)
    for k, (q, v, tau) in enumerate(random_states(robot, 3, seed=600)):
        pq, pv = robot.layout.q_to_pinocchio(q), robot.layout.v_to_pinocchio(v)
        if reference == "local":
            pv = allowed_velocity(pinocchio_forward(robot, anchors, reference, pq, pv, np.zeros(robot.pin_model.nv))[2], pv)
        qdd, _, jacobian = pinocchio_forward(robot, anchors, reference, pq, pv, robot.layout.v_to_pinocchio(tau))
        generalized = pin.rnea(robot.pin_model, robot.pin_model.createData(), pq, pv, qdd)
        forces = np.linalg.lstsq(jacobian[:, base].T, generalized[base], rcond=None)[0]
        torques = generalized - jacobian.T @ forces
        v_robodyn = robot.layout.v_from_pinocchio(pv)
        constraints = [anchor.robodyn(reference) for anchor in anchors]
        result = robot.model.constrained_inverse_dynamics(q, v_robodyn, robot.layout.v_from_pinocchio(qdd), constraints)
        label = f"solo12 {reference} state {k}"
        assert_close(result["tau"], robot.layout.v_from_pinocchio(torques), CROSS_CHECK_TOLERANCE, f"{label} tau")
        assert_close(result["forces"], forces, CROSS_CHECK_TOLERANCE, f"{label} forces")


def test_constrained_inverse_dynamics_refuses_an_acceleration_the_feet_forbid(solo12):
    q, v, a = next(random_states(solo12, 1, seed=700))
    with pytest.raises(ValueError):
        solo12.model.constrained_inverse_dynamics(q, v, a, [anchor.robodyn("world") for anchor in feet(solo12, q)])
