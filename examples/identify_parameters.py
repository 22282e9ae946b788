"""# Identifying inertial parameters

Identifying a robot's inertial parameters from measured torques (Atkeson, An & Hollerbach, 1986).

The joint torques are linear in the ten standard parameters of every link, τ = Y(q, q̇, q̈) π
(`m.torque_regressor`, π = `m.inertial_parameters.ravel()`). Drive the UR5 along an exciting
trajectory (a Fourier series, tracked by a PD controller), "measure" τ with sensor noise, stack
the regressors and solve least squares. Not every parameter shows in the torques (a link's mass
above a joint that cannot feel it, combinations of parameters that always appear together): what
the data determine are the base parameters, the projection of π on the row space of the stacked
regressor. They are recovered to the noise level.

    python examples/identify_parameters.py
"""

import numpy as np
from _compare import show

import robodyn

NOISE = 0.05  # N·m, standard deviation of the torque sensors
rng = np.random.default_rng(7)
m = robodyn.load("ur5")
nv = m.nv

# the regressor reproduces inverse dynamics: τ = Y π
q, v, a = m.random_configuration(seed=1), rng.uniform(-1, 1, nv), rng.uniform(-1, 1, nv)
pi = m.inertial_parameters.ravel()
show("τ = Y(q, q̇, q̈) π (Atkeson–An–Hollerbach) against RNEA", m.inverse_dynamics(q, v, a), m.torque_regressor(q, v, a) @ pi, 1e-12)

# an exciting trajectory: q_ref(t) = q₀ + Σ_k c_k sin(k ω t), tracked with gravity compensation
t = np.linspace(0.0, 6.0, 601)
omega = 2 * np.pi / 6.0
harmonics = rng.uniform(-0.4, 0.4, (3, nv))
q_ref = m.neutral() + sum(c * np.sin((k + 1) * omega * t)[:, None] for k, c in enumerate(harmonics))
v_ref = sum(c * (k + 1) * omega * np.cos((k + 1) * omega * t)[:, None] for k, c in enumerate(harmonics))
inertia = np.diag(m.mass_matrix(m.neutral()))  # gains scaled by each joint's inertia: no stiff wrist
controller = robodyn.PD(kp=400.0 * inertia, kd=40.0 * inertia, reference=(t, q_ref, v_ref), gravity_compensation=True)
run = robodyn.simulate(m, q_ref[0], v_ref[0], t_end=6.0, dt=2e-3, controller=controller)

# measurements: every fifth sample, torques with sensor noise
samples = slice(0, None, 5)
Q, V, A = run.q[samples], run.v[samples], run.a[samples]
measured = run.tau[samples] + rng.normal(0.0, NOISE, run.tau[samples].shape)
W = m.torque_regressor(Q, V, A).reshape(-1, pi.size)  # (samples·nv, 10·nbodies)
print(f"{len(Q)} samples, {W.shape[0]} equations, {W.shape[1]} standard parameters")

# the base parameters: coordinates of π on the row space of W (its right singular vectors)
_, singular, rows = np.linalg.svd(W, full_matrices=False)
rank = int(np.sum(singular > singular[0] * 1e-9))
basis = rows[:rank]
estimate = np.linalg.lstsq(W, measured.ravel(), rcond=None)[0]
print(f"{rank} base parameters are identifiable (the other {pi.size - rank} combinations never move τ)")

# least squares: error covariance σ² (WᵀW)⁻¹ on the base parameters, so their error is about
# σ √(Σ 1/s_i²); the torques it predicts are off by about the noise
expected_error = NOISE * np.sqrt(np.sum(1.0 / singular[:rank] ** 2))
error = np.linalg.norm(basis @ (estimate - pi))
print(f"base-parameter error {error:.2e}, expected from the noise {expected_error:.2e}")
assert error < 3 * expected_error, "the base parameters are not recovered to the noise level"
residual = measured.ravel() - W @ estimate
show("torque residual RMS = the sensor noise σ (textbook least squares)", NOISE, np.sqrt(np.mean(residual**2)), 0.005)

# the identified parameters predict the torques of a motion they have not seen, through the regressor
q, v, a = m.random_configuration(seed=9), rng.uniform(-1, 1, nv), rng.uniform(-1, 1, nv)
show("τ of a new motion: Y π̂ against the true model (N·m)", m.inverse_dynamics(q, v, a), m.torque_regressor(q, v, a) @ estimate, 0.05)

# plain least squares does not know physics: completed with the nominal values where the data are
# silent, the estimate need not be a set of real bodies, and robodyn says which one it is not
completed = (pi + basis.T @ basis @ (estimate - pi)).reshape(-1, 10)
try:
    m.inertial_parameters = completed
    print("the completed estimate is physically consistent")
except ValueError as error:
    print(f"as a model: {error}")
