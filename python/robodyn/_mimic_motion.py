"""What a model in reduced coordinates (:class:`robodyn.mimic.MimicModel`) does through the full
model's iterations: inverse kinematics (the core's damped least squares on q_red), simulation and
one step (the full model holding each mimic relation as a :class:`robodyn.JointCoupling`: the same
equations, since the relations are linear in q; its record mapped to q_red)."""

from __future__ import annotations

from typing import Any

import numpy as np


#: Below this quaternion vector norm (half the angle, rad) log(R) takes its first-order form 2 xyz.
SMALL_ROTATION = 1e-12


def _rotation_log(rotation: np.ndarray) -> np.ndarray:
    """log(R) as a rotation vector, through the unit quaternion (accurate near 0 and π)."""
    trace = np.trace(rotation)
    candidates = [trace, rotation[0, 0], rotation[1, 1], rotation[2, 2]]
    k = int(np.argmax(candidates))
    if k == 0:
        w = 0.5 * np.sqrt(1.0 + trace)
        xyz = np.array([rotation[2, 1] - rotation[1, 2], rotation[0, 2] - rotation[2, 0],
                        rotation[1, 0] - rotation[0, 1]]) / (4.0 * w)
    else:
        i, j, l = k - 1, k % 3, (k + 1) % 3
        xyz = np.zeros(3)
        xyz[i] = 0.5 * np.sqrt(max(1.0 + rotation[i, i] - rotation[j, j] - rotation[l, l], 0.0))
        xyz[j] = (rotation[j, i] + rotation[i, j]) / (4.0 * xyz[i])
        xyz[l] = (rotation[l, i] + rotation[i, l]) / (4.0 * xyz[i])
        w = (rotation[l, j] - rotation[j, l]) / (4.0 * xyz[i])
    if w < 0:
        w, xyz = -w, -xyz
    norm = np.linalg.norm(xyz)
    return xyz * (2.0 * np.arctan2(norm, w) / norm) if norm > SMALL_ROTATION else 2.0 * xyz


def _pose_error(model, q: np.ndarray, frame: Any, target: np.ndarray, position_only: bool) -> np.ndarray:
    """The core's task error: p* − p in world axes, or [Rᵀ(p* − p); log(Rᵀ R*)] in the frame's."""
    pose = np.asarray(model.frame_pose(q, frame))
    if position_only:
        return target[:3, 3] - pose[:3, 3]
    rotation = pose[:3, :3]
    return np.concatenate([rotation.T @ (target[:3, 3] - pose[:3, 3]), _rotation_log(rotation.T @ target[:3, :3])])


def solve_pose(model, frame: Any, target: np.ndarray, q0: np.ndarray, position_only: bool,
                tolerance: float, max_iterations: int, restarts: int, damping: float,
                rng: np.random.Generator) -> dict[str, Any]:
    """Damped least squares from q0, then from random configurations: Δq = Jᵀ (J Jᵀ + (½|e|² + λ²) 1)⁻¹ e,
    q ← clamp(q ⊕ Δq) (Sugihara 2011, as the core)."""
    lower, upper = model._limits()
    rows = 3 if position_only else 6
    best = {"q": q0, "success": False, "iterations": 0, "residual": np.inf}
    iterations = 0
    for attempt in range(restarts + 1):
        q = q0 if attempt == 0 else model.random_configuration(seed=int(rng.integers(2**31)))
        for _ in range(max_iterations):
            error = _pose_error(model, q, frame, target, position_only)
            if np.linalg.norm(error) < tolerance:
                break
            jacobian = model.jacobian(q, frame, "world" if position_only else "local")[:rows]
            system = jacobian @ jacobian.T + (0.5 * error @ error + damping**2) * np.eye(rows)
            q = np.clip(model.integrate(q, jacobian.T @ np.linalg.solve(system, error)), lower, upper)
            iterations += 1
        residual = float(np.linalg.norm(_pose_error(model, q, frame, target, position_only)))
        if residual < best["residual"]:
            best.update(q=q, residual=residual)
        if best["residual"] < tolerance:
            break
    best.update(success=bool(best["residual"] < tolerance), iterations=iterations)
    return best


def full_controller(model, controller: Any) -> Any:
    """A controller of q_red as one of the full model giving the same reduced torque: τ = E τ_red
    (Gᵀ E = 1), so a constant, a callable, and PD's gains sit on the kept coordinates; computed
    torque's gains are copied to the followers (its τ = M (G ë_red) + h then maps to
    M_red ë_red + h_red)."""
    from robodyn import simulation

    selection, coupling = model._selection, model.coupling
    if controller is None:
        return None
    if isinstance(controller, (simulation.PD, simulation.ComputedTorque)):
        kp, kd = (np.broadcast_to(simulation.numbers(name, value), (model.nv,))
                  for name, value in (("kp", controller.kp), ("kd", controller.kd)))
        spread = selection if isinstance(controller, simulation.PD) else (coupling != 0).astype(float)
        q_ref = None if controller.q_ref is None else model._expand(controller.q_ref, "q_ref")
        changes = {"kp": spread @ kp, "kd": spread @ kd, "q_ref": q_ref, "reference": _full_reference(model, controller.reference)}
        return type(controller)(**{**controller.__dict__, **changes})
    if isinstance(controller, simulation.GravityCompensation):
        return controller
    if callable(controller):
        def torque(t, q, v):
            reduced = controller(t, q[model.independent_q], v[model.independent_v])
            return selection @ model._vector("controller", reduced, model.nv)
        return torque
    return model._actuation(controller)


def _full_reference(model, reference: Any) -> Any:
    """A reference motion (knots or a reduced Trajectory) in the full model's coordinates."""
    if reference is None:
        return None
    if hasattr(reference, "t") and hasattr(reference, "q"):
        return (reference.t, model.expand(reference.q), model.expand_velocity(reference.v))
    times, q, v = reference
    return (times, model._expand(q, "reference"), model._expand_velocity(v, "reference"))


def held(model, constraints: Any) -> list:
    """The constraints a run of the full model holds: the user's (the reduced model's own for
    ``"model"``), then the mimic relations."""
    if isinstance(constraints, str):
        given = model.constraints
    elif constraints is None:
        given = []
    else:
        given = list(constraints) if isinstance(constraints, (list, tuple)) else [constraints]
    return given + model._couplings()


def reduced_trajectory(model, run: Any) -> Any:
    """A full model's run in reduced coordinates (its spring energy kept: the full model's, whose
    springs may balance elsewhere than the reduced coordinate's quadratic)."""
    from robodyn.simulation import Trajectory

    reduced = Trajectory(
        model, run.t, q=run.q[:, model.independent_q], v=run.v[:, model.independent_v],
        a=run.a[:, model.independent_v], tau=run.tau @ model.coupling, tau_passive=run.tau_passive @ model.coupling,
        integrator=run.integrator, steps=run.steps, rejected_steps=run.rejected_steps, evaluations=run.evaluations,
        error_times=run.error_times, error_estimate=run.error_estimate, energy_drift=run.energy_drift,
        accuracy_issue=run.accuracy_issue)
    reduced.spring_energy = run.spring_energy
    return reduced


def simulate_reduced(arguments: dict[str, Any]) -> Any:
    """``robodyn.simulate`` of a reduced model: the full model's run, holding the relations."""
    from robodyn.simulation import simulate

    model = arguments.pop("model")
    q0 = model._expand(arguments.pop("q0"), "q0")
    v0 = arguments.pop("v0")
    v0 = np.zeros(q0.shape[:-1] + (model.full.nv,)) if v0 is None else model._expand_velocity(v0, "v0")
    arguments["controller"] = full_controller(model, arguments["controller"])
    arguments["constraints"] = held(model, arguments["constraints"])
    runs = simulate(model.full, q0, v0, **arguments)
    if isinstance(runs, list):
        return [reduced_trajectory(model, run) for run in runs]
    return reduced_trajectory(model, runs)


def step_reduced(arguments: dict[str, Any]) -> Any:
    """``robodyn.step`` of a reduced model: the full model's step holding the relations, x1 and its
    Jacobians reduced (rows kept, columns through G for the state and E for τ)."""
    from robodyn.simulation import step

    model = arguments.pop("model")
    q, v = model.expand(arguments.pop("q")), model.expand_velocity(arguments.pop("v"))
    tau = model._actuation(arguments.pop("tau"))
    arguments["constraints"] = held(model, arguments["constraints"])
    result = step(model.full, q, v, tau, **arguments)
    x1, *jacobians = result if isinstance(result, tuple) else (result,)
    nq, nv = model.full.nq, model.full.nv
    reduced = np.concatenate([x1[..., model.independent_q], x1[..., nq + model.independent_v]], axis=-1)
    if not jacobians:
        return reduced
    rows = np.concatenate([model.independent_v, nv + model.independent_v])
    state = np.kron(np.eye(2), model.coupling)
    a, b = jacobians
    return reduced, a[..., rows, :] @ state, b[..., rows, :] @ model._selection
