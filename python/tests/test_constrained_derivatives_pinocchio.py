"""Derivatives of constrained forward dynamics and of impulses against Pinocchio 4.1, field by field,
and against central differences where Pinocchio cannot say (a masked sole, Cassie's loops).

Pinocchio's side: `constraintDynamics` (one exact solve, as in test_constrained_pinocchio.py, whose
cases, anchors and coordinate maps this module reuses), then `computeConstraintDynamicsDerivatives`,
which returns (∂q̈/∂q, ∂q̈/∂v, ∂q̈/∂τ, ∂λ/∂q, ∂λ/∂v, ∂λ/∂τ) with q moved as q ⊕ δ like ours; and
`impulseDynamics`, then `computeImpulseDynamicsDerivatives`, which writes ∂v⁺/∂q to `data.ddq_dq`,
∂v⁺/∂v − 1 to `data.ddq_dv` (the identity left out, as its own finite-difference test states) and
the impulses' derivatives to `data.dlambda_dq` and `data.dlambda_dv`. On these cases all of them
equal central differences of Pinocchio's own solves (to the differences' accuracy).

Which velocities: two dynamics have the same derivatives at a state only where they agree in a
whole neighbourhood of it. Pinocchio's drift of a 3-D row is the classical acceleration of the
point, as ours, at any velocity; its drift of a 6-D row (a spatial acceleration in
LOCAL_WORLD_ALIGNED, the rate of the local rows in LOCAL) differs from ours (the classical
accelerations turned into the rows' axes) by products of the frame's velocities, for a frame held
to the world quadratic in J v. Where J v = 0 these and their first derivatives vanish, so the
derivatives agree there too. The
3-D cases (Solo12's feet, a point loop) therefore run at random velocities and at allowed ones
(J v = 0), the 6-D ones (Talos's soles) at allowed ones only, in both axes.

Two cases are not compared. The masked sole: Pinocchio has no row masks (its derivatives are
checked against central differences here). The hands' weld between two moving bodies: Pinocchio's
linear rows take the second body's velocity at the first frame's origin, ours at the second
frame's own origin; the two agree where the frames coincide, at the state, but not around it (off
it Pinocchio's rows are ours plus [c₁ − c₂]× ω₂), so q̈ agrees and its derivatives do not.
Impulses have no drift: every world-anchored case runs at random velocities; two-body impulses are
not compared, Pinocchio's `impulseDynamics` reading only `joint1`'s velocity.

Cassie's four rods (point rows between moving bodies, through ball joints) are checked against
central differences at random configurations, where their twelve rows are independent: on the
configurations where the loops close, two rows (the plantar rods' y rows) depend on the others,
and a step off them in q makes them independent again, so ∂q̈/∂q exists there only along the
closed configurations.
"""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest
from conftest import CROSS_CHECK_TOLERANCE, REPOSITORY, assert_close
from test_constrained_pinocchio import (  # noqa: F401 (solo12 and talos are fixtures)
    CASES,
    REFERENCES,
    WORLD_ANCHORED,
    case_states,
    exact_settings,
    impact_states,
    pinocchio_problem,
    solo12,
    talos,
)

import robodyn

CASSIE = REPOSITORY / "testdata" / "mjcf" / "cassie_nomesh.xml"
#: Cases whose rows Pinocchio states as we do near the state, not only at it (see the header).
PINOCCHIO_CASES = sorted(case for case in CASES if case not in ("talos_masked_sole", "talos_hands_loop"))
FORWARD_FIELDS = ("dqdd_dq", "dqdd_dv", "dqdd_dtau")
FORCE_FIELDS = ("dforces_dq", "dforces_dv", "dforces_dtau")


def pinocchio_forward_derivatives(robot, anchors, reference, q, v, tau):
    """Pinocchio's q̈, λ and their derivatives, in robodyn's coordinate order, keyed as robodyn's."""
    layout, pin_model = robot.layout, robot.pin_model
    data, models, datas = pinocchio_problem(robot, anchors, reference)
    qdd = pin.constraintDynamics(pin_model, data, layout.q_to_pinocchio(q), layout.v_to_pinocchio(v), layout.v_to_pinocchio(tau), models, datas, exact_settings()).copy()
    derivatives = pin.computeConstraintDynamicsDerivatives(pin_model, data, models, datas, exact_settings())
    result = {"qdd": layout.v_from_pinocchio(qdd), "forces": data.lambda_c.copy()}
    for name, matrix in zip(FORWARD_FIELDS, derivatives[:3]):
        result[name] = layout.matrix_from_pinocchio(matrix)
    for name, matrix in zip(FORCE_FIELDS, derivatives[3:]):
        result[name] = layout.jacobian_from_pinocchio(matrix)
    return result


@pytest.mark.parametrize("reference", sorted(REFERENCES))
@pytest.mark.parametrize("case", PINOCCHIO_CASES)
def test_constrained_forward_dynamics_derivatives_agree_with_pinocchio(request, case, reference):
    for robot, anchors, q, v, tau, label in case_states(request, case, reference, seed=800):
        expected = pinocchio_forward_derivatives(robot, anchors, reference, q, v, tau)
        ours = robot.model.constrained_forward_dynamics_derivatives(q, v, tau, [anchor.robodyn(reference) for anchor in anchors])
        for name, value in expected.items():
            assert_close(ours[name], value, CROSS_CHECK_TOLERANCE, f"{label} {name}")


def pinocchio_impulse_derivatives(robot, anchors, reference, q, v, restitution):
    """Pinocchio's v⁺, impulses and their derivatives, in robodyn's coordinate order, keyed as robodyn's."""
    layout, pin_model = robot.layout, robot.pin_model
    data, models, datas = pinocchio_problem(robot, anchors, reference)
    after = pin.impulseDynamics(pin_model, data, layout.q_to_pinocchio(q), layout.v_to_pinocchio(v), models, datas, restitution, exact_settings()).copy()
    pin.computeImpulseDynamicsDerivatives(pin_model, data, models, datas, restitution, exact_settings())
    return {
        "v": layout.v_from_pinocchio(after),
        "impulses": data.impulse_c.copy(),
        "dv_dq": layout.matrix_from_pinocchio(data.ddq_dq),
        # Pinocchio's ddq_dv is ∂v⁺/∂v − 1
        "dv_dv": layout.matrix_from_pinocchio(data.ddq_dv + np.eye(pin_model.nv)),
        "dimpulses_dq": layout.jacobian_from_pinocchio(data.dlambda_dq),
        "dimpulses_dv": layout.jacobian_from_pinocchio(data.dlambda_dv),
    }


@pytest.mark.parametrize("restitution", [0.0, 0.5])
@pytest.mark.parametrize("reference", sorted(REFERENCES))
@pytest.mark.parametrize("case", WORLD_ANCHORED)
def test_impulse_dynamics_derivatives_agree_with_pinocchio(request, case, reference, restitution):
    for robot, anchors, q, v, k in impact_states(request, case, seed=900):
        expected = pinocchio_impulse_derivatives(robot, anchors, reference, q, v, restitution)
        ours = robot.model.impulse_dynamics_derivatives(q, v, [anchor.robodyn(reference) for anchor in anchors], restitution=restitution)
        for name, value in expected.items():
            assert_close(ours[name], value, CROSS_CHECK_TOLERANCE, f"{case} {reference} e={restitution} state {k} {name}")


#: Central differences with this step: truncation h² |f‴| and round-off ε |f| / h, f carrying the
#: solve's own accuracy (~1e-12 |f| with damping); the worst measured, 1.6e-8 |f|, is on Cassie.
DIFFERENCE_STEP = 1e-5
#: Their tolerance, relative to the largest value differenced (q̈, or λ) or 1.
DIFFERENCE_TOLERANCE = 1e-7


def assert_derivatives_are_differences(model, q, v, tau, constraints, label, damping=0.0):
    """Every column of the six derivatives against central differences of the dynamics (q moved as
    q ⊕ h e_k); the errors in q̈'s and in λ's derivatives each relative to that value's size."""
    ours = model.constrained_forward_dynamics_derivatives(q, v, tau, constraints, damping=damping)

    def solve(q, v, tau):
        result = model.constrained_forward_dynamics(q, v, tau, constraints, damping=damping)
        return {"qdd": result["qdd"], "forces": result["forces"]}

    value = solve(q, v, tau)
    for name, moved in [("q", lambda step: (model.integrate(q, step), v, tau)), ("v", lambda step: (q, v + step, tau)), ("tau", lambda step: (q, v, tau + step))]:
        ends = [(solve(*moved(DIFFERENCE_STEP * e)), solve(*moved(-DIFFERENCE_STEP * e))) for e in np.eye(model.nv)]
        for field in ("qdd", "forces"):
            numeric = np.column_stack([(plus[field] - minus[field]) / (2 * DIFFERENCE_STEP) for plus, minus in ends])
            error = float(np.max(np.abs(ours[f"d{field}_d{name}"] - numeric)))
            bound = DIFFERENCE_TOLERANCE * max(1.0, float(np.max(np.abs(value[field]))))
            assert error <= bound, f"{label} d{field}_d{name}: max error {error:.3e} > {bound:.3e}"


@pytest.mark.parametrize("reference", sorted(REFERENCES))
@pytest.mark.parametrize("case", ["talos_hands_loop", "talos_masked_sole"])
def test_derivatives_pinocchio_does_not_state_equal_central_differences(request, case, reference):
    for robot, anchors, q, v, tau, label in case_states(request, case, reference, seed=1000, count=1):
        assert_derivatives_are_differences(robot.model, q, v, tau, [anchor.robodyn(reference) for anchor in anchors], label)


@pytest.fixture(scope="module")
def cassie():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", robodyn.ModelWarning)
        return robodyn.load(CASSIE)


@pytest.mark.parametrize("damping", [0.0, 1e-8])
def test_derivatives_on_cassies_loops_equal_central_differences(cassie, damping):
    """Cassie's four rods (12 point rows between moving bodies, through ball joints) at random
    configurations, where the rods' rows are independent; `damping` takes the proximal mode."""
    rng = np.random.default_rng(12)
    for seed in range(3):
        q = cassie.random_configuration(seed=seed)
        # τ = M u: accelerations of order one on every coordinate (a rod's spin has an inertia of 4e-6)
        v, tau = rng.uniform(-1, 1, cassie.nv), cassie.mass_matrix(q) @ rng.uniform(-1, 1, cassie.nv)
        assert_derivatives_are_differences(cassie, q, v, tau, cassie.constraints, f"Cassie state {seed} damping {damping}", damping)


#: Singular values of J below this (relative to the largest) count as dependent rows.
RANK_CUTOFF = 1e-10
#: The loops count as closed when their points are this close (m); qpos0's are 2e-17 apart.
CLOSURE_TOLERANCE = 1e-14
CLOSING_STEPS = 20
#: The step of the extrapolated differences along Cassie's closed configurations: their error
#: falls as h⁴ to 1e-8 of the values at 1e-4, below which the proximal solves' rounding grows.
CLOSED_STEP = 1e-4


def loop_gaps(model, q):
    """Each rod's attachment point minus the point it is held to, in world axes."""
    gaps = [model.frame_pose(q, c.frame) @ np.append(c.offset, 1.0) - model.frame_pose(q, c.frame2) @ np.append(c.offset2, 1.0) for c in model.constraints]
    return np.concatenate([gap[:3] for gap in gaps])


def closed(model, q):
    """q moved back onto the closed configurations by Newton's least-norm steps."""
    for _ in range(CLOSING_STEPS):
        gaps = loop_gaps(model, q)
        if np.max(np.abs(gaps)) <= CLOSURE_TOLERANCE:
            return q
        q = model.integrate(q, -np.linalg.lstsq(model.constraint_jacobian(q, model.constraints), gaps, rcond=RANK_CUTOFF)[0])
    raise AssertionError(f"the loops did not close: {np.max(np.abs(loop_gaps(model, q))):.1e} m")


def test_derivatives_on_cassies_closed_loops_equal_central_differences_along_them(cassie):
    """At qpos0, where the loops close and two of their rows depend on the others: q̈'s derivatives
    along the closed configurations (q moved in J's null space, then closed again) and along the
    velocities the loops allow; the forces through Jᵀ (what reaches the robot; λ is not unique)."""
    model, loops = cassie, cassie.constraints
    q = model.neutral()
    jacobian = model.constraint_jacobian(q, loops)
    _, singular, rows = np.linalg.svd(jacobian)
    tangent = rows[int(np.sum(singular > RANK_CUTOFF * singular[0])) :].T
    assert tangent.shape[1] == model.nv - 10, "two of the twelve rows depend on the others at qpos0"
    rng = np.random.default_rng(13)
    v, tau = tangent @ rng.uniform(-1, 1, tangent.shape[1]), model.mass_matrix(q) @ rng.uniform(-1, 1, model.nv)
    ours = model.constrained_forward_dynamics_derivatives(q, v, tau, loops, damping=1e-8)

    def solve(q, v, tau):
        result = model.constrained_forward_dynamics(q, v, tau, loops, damping=1e-8)
        return {"qdd": result["qdd"], "forces": jacobian.T @ result["forces"]}

    value = solve(q, v, tau)

    def central(moved, d, h, field):
        return (solve(*moved(h * d))[field] - solve(*moved(-h * d))[field]) / (2 * h)

    for name, moved, directions in [
        ("q", lambda step: (closed(model, model.integrate(q, step)), v, tau), tangent),
        ("v", lambda step: (q, v + step, tau), tangent),
        ("tau", lambda step: (q, v, tau + step), np.eye(model.nv)),
    ]:
        for field, analytic in [("qdd", ours[f"dqdd_d{name}"]), ("forces", jacobian.T @ ours[f"dforces_d{name}"])]:
            # Richardson's extrapolation (4 D(h/2) − D(h)) / 3 removes the h² term: along some
            # closed directions q̈'s third derivative is large (central differences at h = 1e-5
            # miss by 2.6e-4, falling as h²), and rounding forbids a smaller step
            numeric = np.column_stack([
                (4 * central(moved, d, CLOSED_STEP / 2, field) - central(moved, d, CLOSED_STEP, field)) / 3 for d in directions.T
            ])
            error = float(np.max(np.abs(analytic @ directions - numeric)))
            bound = DIFFERENCE_TOLERANCE * max(1.0, float(np.max(np.abs(value[field]))))
            assert error <= bound, f"Cassie at qpos0 d{field}/d{name}: max error {error:.3e} > {bound:.3e}"
