"""# iLQR with the derivatives of a simulation step

Trajectory optimisation with the derivatives of a simulation step: iLQR (Li & Todorov, 2004;
the regularisation and line search of Tassa, Erez & Todorov, 2012) swings the pendulum up and
moves the UR5 to a pose.

Each iteration linearises the whole trajectory in one batched call,
``robodyn.step(m, Q, V, U, dt, "rk4", derivatives=True)`` (A = ∂x⁺/∂x, B = ∂x⁺/∂u of every RK4
step, exact, on all cores), solves the Riccati recursion backwards for feedback gains, and rolls
the improved controls out. States are compared on the configuration's Lie group (q ⊖ q_goal), so
the same code serves floating robots. The cost printed per iteration decreases monotonically.

    python examples/ilqr_swing_up.py
"""

from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from _compare import show

import robodyn

Array = np.ndarray[Any, np.dtype[np.float64]]


def rollout(m: robodyn.Model, q0: Any, controls: Array, dt: float, feedback: tuple[Array, Array, Array, float, Array] | None = None) -> tuple[Array, Array, Array]:
    """States (q, v) from q0 at rest under `controls`; with `feedback` = (Q, V, K, alpha, k) the
    controls become U + α k + K (x ⊖ x̄) along the way."""
    q, v = [np.asarray(q0, dtype=float)], [np.zeros(m.nv)]
    applied = controls.copy()
    for t in range(len(controls)):
        if feedback is not None:
            Q, V, K, alpha, k = feedback
            deviation = np.concatenate([m.difference(Q[t], q[t]), v[t] - V[t]])
            applied[t] = controls[t] + alpha * k[t] + K[t] @ deviation
        x = robodyn.step(m, q[t], v[t], applied[t], dt, "rk4")
        q.append(x[: m.nq])
        v.append(x[m.nq :])
    return np.array(q), np.array(v), applied


def cost(m: robodyn.Model, states: tuple[Array, Array, Array], goal: Array, weights: tuple[Array, Array], dt: float) -> float:
    """½ Σ uᵀ R u dt + ½ eᵀ W e with e = [q_N ⊖ q_goal; v_N]."""
    Q, V, U = states
    control_weight, final_weight = weights
    error = np.concatenate([m.difference(goal, Q[-1]), V[-1]])
    return float(0.5 * dt * np.einsum("ti,ij,tj->", U, control_weight, U) + 0.5 * error @ final_weight @ error)


def ilqr(m: robodyn.Model, q0: Any, goal: Array, controls: Array, dt: float, weights: tuple[Array, Array], iterations: int = 100, label: str = "") -> tuple[Array, Array, Array, Array]:
    """Optimises `controls` (T, nv) from q0 at rest towards `goal` at rest; returns the states, the
    controls and the cost of every iteration."""
    control_weight, final_weight = weights
    nv = m.nv
    Q, V, U = rollout(m, q0, controls, dt)
    costs = [cost(m, (Q, V, U), goal, weights, dt)]
    mu = 1e-6
    print(f"{label}: iteration 0, cost {costs[-1]:.6g}")
    for iteration in range(1, iterations + 1):
        # linearise every step at once: A_t (2nv × 2nv), B_t (2nv × nv)
        _, A, B = robodyn.step(m, Q[:-1], V[:-1], U, dt, "rk4", derivatives=True)
        # the final cost's gradient and Hessian in the tangent space (Gauss-Newton)
        error = np.concatenate([m.difference(goal, Q[-1]), V[-1]])
        d_error = np.eye(2 * nv)
        d_error[:nv, :nv] = m.difference_jacobians(goal, Q[-1])["dq1"]
        value_gradient = d_error.T @ final_weight @ error
        value_hessian = d_error.T @ final_weight @ d_error
        # backward pass: the Riccati recursion for feedforward k_t and feedback K_t
        k, K = np.zeros_like(U), np.zeros((len(U), nv, 2 * nv))
        for t in reversed(range(len(U))):
            q_u = dt * control_weight @ U[t] + B[t].T @ value_gradient
            q_x = A[t].T @ value_gradient
            q_uu = dt * control_weight + B[t].T @ value_hessian @ B[t] + mu * np.eye(nv)
            q_ux = B[t].T @ value_hessian @ A[t]
            q_xx = A[t].T @ value_hessian @ A[t]
            k[t] = -np.linalg.solve(q_uu, q_u)
            K[t] = -np.linalg.solve(q_uu, q_ux)
            value_gradient = q_x + K[t].T @ q_uu @ k[t] + K[t].T @ q_u + q_ux.T @ k[t]
            value_hessian = q_xx + K[t].T @ q_uu @ K[t] + K[t].T @ q_ux + q_ux.T @ K[t]
            value_hessian = 0.5 * (value_hessian + value_hessian.T)
        # forward pass: the largest step along the new controls that lowers the cost
        for alpha in 0.5 ** np.arange(10):
            try:
                candidate = rollout(m, q0, U, dt, feedback=(Q, V, K, alpha, k))
            except ValueError:
                continue  # the step blew up (robodyn refuses non-finite states): shorten it
            new_cost = cost(m, candidate, goal, weights, dt)
            if new_cost < costs[-1]:
                break
        else:
            mu *= 10.0
            if mu > 1e6:
                break
            continue
        Q, V, U = candidate
        mu = max(mu / 10.0, 1e-9)
        improvement = (costs[-1] - new_cost) / costs[-1]
        costs.append(new_cost)
        print(f"{label}: iteration {iteration}, cost {new_cost:.6g} (step α = {alpha:g})")
        if improvement < 1e-7:
            break
    return Q, V, U, np.array(costs)


# the pendulum linearised at the top: θ̈ = −(g/l) sin θ + τ/(m l²) has ∂θ̈/∂θ = g/l there
pendulum = robodyn.load("pendulum")
top = np.array([np.pi])
linear = pendulum.forward_dynamics_derivatives(top, [0.0], [0.0])
show("∂θ̈/∂θ of the inverted pendulum, g/l (1/s²)", [[9.81]], linear["dqdd_dq"], 1e-12)

# swing the pendulum up from hanging at rest, in 2 s
dt = 0.02
weights = (np.eye(1) * 1e-2, np.diag([1e3, 1e2]))
Q, V, U, costs = ilqr(pendulum, [0.0], top, np.zeros((100, 1)), dt, weights, label="pendulum")
assert np.all(np.diff(costs) < 0), "the cost must decrease at every accepted iteration"
show("pendulum at the top after 2 s: θ (rad), θ̇ (rad/s)", [np.pi, 0.0], [Q[-1, 0], V[-1, 0]], 2e-2)
print(f"pendulum: cost {costs[0]:.4g} -> {costs[-1]:.4g} in {len(costs) - 1} iterations, peak torque {np.max(np.abs(U)):.2f} N·m")
pendulum_costs = costs

# move the UR5 from one pose to another in 1 s, starting from gravity compensation
ur5 = robodyn.load("ur5")
start = np.array([0.0, -1.2, 1.2, -0.5, 0.3, 0.0])
goal = np.array([0.9, -1.6, 1.0, -1.2, 1.0, 0.5])
hold = np.tile(ur5.generalized_gravity(start), (50, 1))
# control cost R_ii = 0.01 / M_ii (about the squared acceleration each torque buys): a uniform R
# would make the light wrist's torques nearly free and its motion violent
weights = (np.diag(1e-2 / np.diag(ur5.mass_matrix(start))), np.diag([1e3] * 6 + [1e1] * 6))
Q, V, U, costs = ilqr(ur5, start, goal, hold, dt, weights, label="ur5")
assert np.all(np.diff(costs) < 0), "the cost must decrease at every accepted iteration"
show("UR5 pose after 1 s (rad)", goal, Q[-1], 2e-2)
print(f"ur5: cost {costs[0]:.4g} -> {costs[-1]:.4g} in {len(costs) - 1} iterations")

# the cost of each accepted iteration, relative to the first
figure, axis = plt.subplots(figsize=(8, 3.5))
for label, run in (("pendulum swing-up", pendulum_costs), ("UR5 to a pose", costs)):
    axis.semilogy(run / run[0], marker="o", markersize=3, label=label)
axis.set_xlabel("iteration")
axis.set_ylabel("cost / initial cost")
axis.set_title("iLQR: the cost decreases at every accepted iteration")
axis.grid(True, alpha=0.3)
axis.legend()
