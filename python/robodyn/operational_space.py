"""Cartesian (operational-space) dynamics of a frame: the TUM notes, "Cartesian state space equation".

For a task x of k rows of a frame's motion (its Jacobian J, k × nv), the joint-space equation
M q̈ + C q̇ + g = τ with τ = Jᵀ F becomes

    F = Λ(q) ẍ + μ(q, q̇) + p(q)
    Λ = (J M⁻¹ Jᵀ)⁻¹,   μ = Λ (J M⁻¹ C q̇ − J̇ q̇),   p = Λ J M⁻¹ g,

and J̄ = M⁻¹ Jᵀ Λ is the dynamically consistent generalized inverse of J (J J̄ = 1). For a square,
invertible J these are the notes' M_x = J⁻ᵀ M J⁻¹, V_x = J⁻ᵀ (V − M J⁻¹ J̇ q̇), G_x = J⁻ᵀ G.

Near a singularity J M⁻¹ Jᵀ loses rank and Λ blows up. ``damping=None`` (the default) then
inverts J M⁻¹ Jᵀ + λ 1 with λ = DAMPING_RATIO times its largest eigenvalue, when its smallest
eigenvalue falls below SINGULARITY_RATIO times the largest; the λ used (0 away from singularities)
is returned as ``damping``. A number sets λ; ``damping=0`` refuses a singular task with a
ValueError. Nothing returns inf or NaN.

The function is also a method of every model: ``m.operational_space(q, v, frame, ...)``. It
composes the batched core calls (``jacobian``, ``jacobian_time_variation``,
``inverse_mass_matrix``, ``bias_forces``, ``generalized_gravity``) with NumPy, so q and v may be
batches too.
"""

from __future__ import annotations

import numpy as np

from robodyn._arguments import bad, choice, count, real, robot_model

__all__ = ["operational_space", "task_rows", "SINGULARITY_RATIO", "DAMPING_RATIO"]

#: J M⁻¹ Jᵀ counts as singular when its eigenvalues span more than this ratio.
SINGULARITY_RATIO = 1e-10
#: The automatic damping, relative to the largest eigenvalue of J M⁻¹ Jᵀ.
DAMPING_RATIO = 1e-6

_TASKS = {"full": [0, 1, 2, 3, 4, 5], "position": [0, 1, 2], "orientation": [3, 4, 5]}


def task_rows(task) -> list[int]:
    """The Jacobian rows of a task: "full", "position", "orientation" or a list of rows of
    [linear; angular]."""
    if isinstance(task, str):
        return _TASKS[choice("task", task, tuple(_TASKS), " or a list of rows 0-5")]
    try:
        rows = [count("task", row, 0) for row in task]
    except TypeError:
        raise bad("task", "'full', 'position', 'orientation' or a list of rows 0-5", repr(task)) from None
    if not rows or len(set(rows)) != len(rows) or any(r > 5 for r in rows):
        raise bad("task", "distinct rows among 0-5", repr(list(task)))
    return rows


def operational_space(model, q, v, frame, task="full", damping=None, reference="world") -> dict:
    """Λ, μ, p and J̄ of a frame's task (see the module's docstring). Returns a dict with
    ``"Lambda"`` (k × k), ``"mu"`` (k), ``"p"`` (k), ``"J_bar"`` (nv × k), ``"J"`` (k × nv) and
    ``"damping"`` (the λ used), each with a leading batch axis when q is a batch."""
    robot_model("model", model)
    rows = task_rows(task)
    jacobian = model.jacobian(q, frame, reference)[..., rows, :]
    jacobian_dot = model.jacobian_time_variation(q, v, frame, reference)[..., rows, :]
    m_inverse = model.inverse_mass_matrix(q)
    gravity = model.generalized_gravity(q)
    velocity_terms = model.bias_forces(q, v) - gravity
    j_t = np.swapaxes(jacobian, -1, -2)
    # Λ⁻¹ = J M⁻¹ Jᵀ
    lambda_inverse = jacobian @ m_inverse @ j_t
    eigenvalues = np.linalg.eigvalsh(lambda_inverse)
    largest, smallest = eigenvalues[..., -1], eigenvalues[..., 0]
    singular = smallest <= SINGULARITY_RATIO * largest
    if damping is None:
        used = np.where(singular, DAMPING_RATIO * largest, 0.0)
    else:
        if real("damping", damping) < 0:
            raise bad("damping", "None or a finite number >= 0", repr(damping))
        damping = float(damping)
        if damping == 0.0 and np.any(singular):
            raise ValueError(
                f"frame {frame!r}: the task is singular here (J M⁻¹ Jᵀ has eigenvalues down to {float(np.min(smallest)):.3e}); "
                "pass damping=None or a positive damping"
            )
        used = np.full(np.shape(largest), damping)
    k = len(rows)
    identity = np.eye(k)
    lambda_matrix = np.linalg.inv(lambda_inverse + np.asarray(used)[..., None, None] * identity)
    lambda_matrix = 0.5 * (lambda_matrix + np.swapaxes(lambda_matrix, -1, -2))
    j_m_inverse = jacobian @ m_inverse
    # μ = Λ (J M⁻¹ C q̇ − J̇ q̇),  p = Λ J M⁻¹ g
    mu = (lambda_matrix @ ((j_m_inverse @ velocity_terms[..., None]) - jacobian_dot @ np.asarray(v, dtype=float)[..., None]))[..., 0]
    p = (lambda_matrix @ (j_m_inverse @ gravity[..., None]))[..., 0]
    # J̄ = M⁻¹ Jᵀ Λ
    j_bar = m_inverse @ j_t @ lambda_matrix
    return {"Lambda": lambda_matrix, "mu": mu, "p": p, "J_bar": j_bar, "J": jacobian, "damping": used}
