"""# Mimic joints: Panda's fingers in reduced coordinates

Panda's second finger joint mimics the first (`<mimic joint="panda_finger_joint1"/>`). Loaded
with `mimic=True` (the [Mimic joints](../guide/mimic.md) guide), the model has one coordinate for
both fingers, and every method works in those reduced coordinates. Panda comes from
example-robot-data (`pip install 'robodyn[robots]'`).

    python examples/mimic_joints.py
"""

import warnings

import matplotlib.pyplot as plt
import numpy as np
from _compare import show

import robodyn

with warnings.catch_warnings():
    warnings.simplefilter("ignore", robodyn.ModelWarning)  # Panda's file has Gazebo attributes
    panda = robodyn.load("panda.urdf", mimic=True)
    free = robodyn.load("panda.urdf")
print(panda)
show("nq: reduced, and the full model's", [8, 9], [panda.nq, panda.full.nq], 0)

# %%
# ## The map G
#
# q̇ = G q̇_red: G copies each kept coordinate and gives the follower its leader's rate. Every
# quantity is the full model's mapped by G; the mass matrix is M_red = Gᵀ M G, the finger's entry
# the sum of both fingers' inertias.
q = panda.random_configuration(seed=2)
full_q = panda.expand(q)
show("the two finger joints (m)", [full_q[7], full_q[7]], full_q[7:9], 0)
G = panda.coupling
M = panda.full.mass_matrix(full_q)
show("largest |M_red − Gᵀ M G|", 0.0, np.abs(panda.mass_matrix(q) - G.T @ M @ G).max(), 1e-12)
show("the finger's M_red = M₇₇ + 2 M₇₈ + M₈₈ (kg): both fingers' mass", M[7, 7] + 2 * M[7, 8] + M[8, 8],
     panda.mass_matrix(q)[7, 7], 1e-12)

# %%
# The reduced forward dynamics (M_red solved) against the full model holding the relation as a
# constraint (its KKT system): the same accelerations.
rng = np.random.default_rng(0)
v, tau = rng.standard_normal(panda.nv), rng.standard_normal(panda.nv)
relation = robodyn.JointCoupling("panda_finger_joint2", "panda_finger_joint1")
held = panda.full.constrained_forward_dynamics(full_q, G @ v, np.append(tau, 0.0), [relation])
show("q̈: reduced, and the full model's held", held["qdd"], G @ panda.forward_dynamics(q, v, tau), 1e-9)

# %%
# ## Closing the hand
#
# A PD on every reduced coordinate with gravity compensation drives the fingers from closed to
# 3 cm open. In reduced coordinates both fingers move as one; the full model driven the same way
# with its relation dropped (`constraints=None`: the first finger driven, the second free) leaves
# the second finger where it was.
start = panda.neutral()
target = start.copy()
target[7] = 0.03
control = robodyn.PD(kp=np.r_[np.full(7, 50.0), 200.0], kd=np.r_[np.full(7, 5.0), 5.0], q_ref=target,
                     gravity_compensation=True)
run = robodyn.simulate(panda, start, t_end=0.6, dt=1e-3, controller=control)
fingers = panda.expand(run.q)[:, 7:9]
loose = robodyn.simulate(free, panda.expand(start), t_end=0.6, dt=1e-3, constraints=None,
                         controller=robodyn.PD(kp=np.r_[np.full(7, 50.0), 200.0, 0.0],
                                               kd=np.r_[np.full(7, 5.0), 5.0, 0.0],
                                               q_ref=panda.expand(target), gravity_compensation=True))
show("reduced: the fingers apart at most (m)", 0.0, np.abs(fingers[:, 0] - fingers[:, 1]).max(), 1e-15)
show("reduced: the first finger after 0.6 s (m)", 0.03, fingers[-1, 0], 1e-3)

figure, axes = plt.subplots(1, 2, figsize=(10, 3.8))
axes[0].plot(run.t, 100 * fingers[:, 0], lw=3, color="tab:blue", label="finger 1, mimic=True")
axes[0].plot(run.t, 100 * fingers[:, 1], lw=1.2, color="black", ls="--", label="finger 2, mimic=True")
axes[0].plot(loose.t, 100 * loose.q[:, 7], color="tab:orange", label="finger 1, relation dropped")
axes[0].plot(loose.t, 100 * loose.q[:, 8], color="tab:red", ls=":", label="finger 2, relation dropped")
axes[0].set(xlabel="time [s]", ylabel="finger joint [cm]", title="Panda's fingers opening under a PD")
axes[0].legend(fontsize=8)
axes[1].plot(run.t, run.tau[:, 7], color="tab:blue", label="mimic=True: both fingers (30 g)")
axes[1].plot(loose.t, loose.tau[:, 7], color="tab:orange", label="relation dropped: one finger (15 g)")
axes[1].set(xlabel="time [s]", ylabel="PD force on finger 1's coordinate [N]",
            title="One coordinate drives both fingers", xlim=(0, 0.15))
axes[1].legend(fontsize=8)
figure.tight_layout()
