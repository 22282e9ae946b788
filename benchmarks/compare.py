"""robodyn against Pinocchio and MuJoCo from Python, in one run: per-call time of each algorithm,
a 10 000-state batch against a Python loop, forward dynamics under contacts (Solo12 on its feet,
Talos on its soles) and impacts against Pinocchio's constraintDynamics and impulseDynamics, a 10 s
UR5 rollout (RK4, PD) against mj_step and 64 rollouts of 1 s against mujoco.rollout, and Menagerie's
Go2 scene stepped as mj_step steps it (one step, a run, 64 rollouts; against MuJoCo as the scene sets
it and run to convergence as robodyn's solver is), printed as ratios (< 1 means robodyn is faster).

Run: .venv/bin/python benchmarks/compare.py [--batch 10000] [--robots ur5 panda talos]
[--sections pinocchio constrained mujoco simulation scene] [--criterion target/criterion] [--json out.json]
(--json also writes the tables as JSON, which scripts/benchmarks_page.py turns into docs/benchmarks.md;
--criterion sets the Rust core's times of the constrained cases, from a `cargo bench -p robodyn
--bench constrained` run before, beside the same calls from Python).
Needs the bench extras (pip install '.[bench]'). Times are the best of several repeats; a batch
round repeats the batch for at least BATCH_ROUND_S (a Python loop takes that long once).

MuJoCo loads the same URDFs (visual and collision elements removed) with a fixed base, so its
table uses fixed-base robodyn models. MuJoCo has no separate RNEA/CRBA entry points that start
from q, so each MuJoCo case is the pipeline of mj_* calls a Python user would make for it.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import re
import timeit
from pathlib import Path

# numpy's OpenBLAS keeps a thread of its own spinning after each call, which on a 2-core machine
# takes a core from a batch's threads: set before numpy is imported (a user's setting stays)
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import mujoco
import numpy as np
import pinocchio as pin

import robodyn
from robodyn.convert import PinocchioLayout

# each robot's file, whether its base floats, and the frame whose pose and Jacobian are timed
# (its tool or fingertip, as in pinocchio_native.sh)
ROBOTS = {
    "ur5": ("ur_description/urdf/ur5_robot.urdf", False, "tool0"),
    "panda": ("panda_description/urdf/panda.urdf", False, "panda_hand_tcp"),
    "talos": ("talos_data/robots/talos_full_v2.urdf", True, "gripper_left_fingertip_1_link"),
}


def best_times(ours, theirs, number: int, repeat: int = 21) -> tuple[float, float]:
    """Best per-call times in seconds of two functions over `repeat` rounds of `number` calls,
    the rounds interleaved so that a drift in the machine's speed affects both alike (with 7
    rounds of a few milliseconds, a UR5 call's ratio moved by 0.1 between runs on a shared host;
    with 21, by 0.01-0.04)."""
    best_ours = best_theirs = float("inf")
    for _ in range(repeat):
        best_ours = min(best_ours, timeit.timeit(ours, number=number))
        best_theirs = min(best_theirs, timeit.timeit(theirs, number=number))
    return best_ours / number, best_theirs / number


#: A batch round lasts at least this long (s): a batch of a few milliseconds timed once is
#: mostly the machine's noise (a sleeping core waking, the first touch of the result).
BATCH_ROUND_S = 0.02


def batch_times(ours, theirs, repeat: int = 9) -> tuple[float, float]:
    """Best per-call times in seconds of a batch and of the loop it replaces: each side calls
    itself enough times per round for `BATCH_ROUND_S` (the loops take that long once), the rounds
    interleaved as in `best_times`. The count per round comes from the best of three calls: the
    first call after a Python loop can take 2-4x longer (the second core wakes), and a count set
    from it alone made a round of two calls, one of them slow (a Talos gravity batch timed at
    5.1 ms per call in one run, 2.1 ms in the next section of the same run)."""
    numbers = [
        max(1, round(BATCH_ROUND_S / min(timeit.repeat(f, number=1, repeat=3)))) for f in (ours, theirs)
    ]
    best = [float("inf"), float("inf")]
    for _ in range(repeat):
        for k, f in enumerate((ours, theirs)):
            best[k] = min(best[k], timeit.timeit(f, number=numbers[k]) / numbers[k])
    return best[0], best[1]


def compare_robot(name: str, batch: int) -> list[tuple[str, float, float]]:
    path, floating, frame = ROBOTS[name]
    urdf = robodyn._example_robot_data_dir() / path
    m = robodyn.load(urdf, floating_base=floating)
    pm = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer()) if floating else pin.buildModelFromUrdf(str(urdf))
    pd = pm.createData()
    mapping = PinocchioLayout(m, pm)
    rng = np.random.default_rng(0)
    q = m.random_configuration(seed=1)
    v, a = rng.uniform(-1, 1, m.nv), rng.uniform(-1, 1, m.nv)
    pq, pv, pa = mapping.q_to_pinocchio(q), mapping.v_to_pinocchio(v), mapping.v_to_pinocchio(a)
    frame_id = pm.getFrameId(frame)

    def pin_jacobian():
        pin.computeFrameJacobian(pm, pd, pq, frame_id, pin.LOCAL_WORLD_ALIGNED)

    def pin_frame_pose():
        pin.forwardKinematics(pm, pd, pq)
        return pin.updateFramePlacement(pm, pd, frame_id).homogeneous

    single = {
        "rnea": (lambda: m.inverse_dynamics(q, v, a), lambda: pin.rnea(pm, pd, pq, pv, pa)),
        "crba": (lambda: m.mass_matrix(q), lambda: pin.crba(pm, pd, pq)),
        "aba": (lambda: m.forward_dynamics(q, v, a), lambda: pin.aba(pm, pd, pq, pv, pa)),
        "gravity": (lambda: m.generalized_gravity(q), lambda: pin.computeGeneralizedGravity(pm, pd, pq)),
        "frame_pose": (lambda: m.frame_pose(q, frame), pin_frame_pose),
        "jacobian": (lambda: m.jacobian(q, frame), pin_jacobian),
        "rnea_derivatives": (lambda: m.inverse_dynamics_derivatives(q, v, a), lambda: pin.computeRNEADerivatives(pm, pd, pq, pv, pa)),
        "aba_derivatives": (lambda: m.forward_dynamics_derivatives(q, v, a), lambda: pin.computeABADerivatives(pm, pd, pq, pv, pa)),
    }
    rows = [(f"{name} {algorithm} (one call)", *best_times(ours, theirs, 2000)) for algorithm, (ours, theirs) in single.items()]

    states = m.random_configuration(n=batch, seed=2)
    pin_states = [mapping.q_to_pinocchio(x) for x in states]
    velocities = rng.uniform(-1, 1, (batch, m.nv))
    pin_velocities = [mapping.v_to_pinocchio(x) for x in velocities]

    def pin_gravity_loop():
        for x in pin_states:
            pin.computeGeneralizedGravity(pm, pd, x)

    def pin_rnea_loop():
        for x, w in zip(pin_states, pin_velocities):
            pin.rnea(pm, pd, x, w, w)

    def pin_crba_loop():
        for x in pin_states:
            pin.crba(pm, pd, x)

    def pin_aba_loop():
        for x, w in zip(pin_states, pin_velocities):
            pin.aba(pm, pd, x, w, w)

    def pin_rnea_derivatives_loop():
        for x, w in zip(pin_states, pin_velocities):
            pin.computeRNEADerivatives(pm, pd, x, w, w)

    def pin_frame_pose_loop():
        for x in pin_states:
            pin.forwardKinematics(pm, pd, x)
            pin.updateFramePlacement(pm, pd, frame_id)

    def pin_jacobian_loop():
        for x in pin_states:
            pin.computeFrameJacobian(pm, pd, x, frame_id, pin.LOCAL_WORLD_ALIGNED)

    def pin_aba_derivatives_loop():
        for x, w in zip(pin_states, pin_velocities):
            pin.computeABADerivatives(pm, pd, x, w, w)

    batches = {
        "gravity": (lambda: m.generalized_gravity(states), pin_gravity_loop),
        "rnea": (lambda: m.inverse_dynamics(states, velocities, velocities), pin_rnea_loop),
        "crba": (lambda: m.mass_matrix(states), pin_crba_loop),
        "aba": (lambda: m.forward_dynamics(states, velocities, velocities), pin_aba_loop),
        "rnea_derivatives": (lambda: m.inverse_dynamics_derivatives(states, velocities, velocities), pin_rnea_derivatives_loop),
        "aba_derivatives": (lambda: m.forward_dynamics_derivatives(states, velocities, velocities), pin_aba_derivatives_loop),
        "frame_pose": (lambda: m.frame_pose(states, frame), pin_frame_pose_loop),
        "jacobian": (lambda: m.jacobian(states, frame), pin_jacobian_loop),
    }
    rows += [(f"{name} {algorithm} ({batch} states)", *batch_times(ours, theirs)) for algorithm, (ours, theirs) in batches.items()]
    return rows


#: The constrained section's robots: name -> (file, rows per contact, the frames held). Each frame
#: is held to the world where it is, in world axes (Pinocchio's LOCAL_WORLD_ALIGNED): Solo12 on its
#: four feet (a point each), Talos (the file of ROBOTS) on its two soles (the whole frame each).
CONTACTS = {
    "solo12": ("solo_description/robots/solo12.urdf", 3, ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")),
    "talos": (ROBOTS["talos"][0], 6, ("left_sole_link", "right_sole_link")),
}
#: What the contacts are called in the rows.
CONTACT_NAMES = {3: "feet", 6: "soles"}
#: The constrained algorithms timed, as the rows name them -> their criterion benchmark in
#: `cargo bench -p robodyn --bench constrained` (group `constrained/ROBOT`, which criterion keeps in
#: its folder `constrained_ROBOT`).
CONSTRAINED_ALGORITHMS = {"forward dynamics": "forward_dynamics", "impulse dynamics": "impulse_dynamics",
                          "derivatives": "forward_dynamics_derivatives"}
#: The derivatives of constrained forward dynamics, in the order of Pinocchio's
#: `computeConstraintDynamicsDerivatives`.
DERIVATIVE_KEYS = ("dqdd_dq", "dqdd_dv", "dqdd_dtau", "dforces_dq", "dforces_dv", "dforces_dtau")
#: Before any timing, robodyn's results equal Pinocchio's to this, relative to each state's largest
#: entry (Pinocchio's tests agree to 1e-9): a benchmark never times a wrong answer.
AGREEMENT = 1e-8


def assert_agree(label: str, ours, theirs) -> None:
    """|ours - theirs| <= AGREEMENT * max(1, the largest |theirs| of the state), state by state
    (the last axis holds one state's entries)."""
    ours, theirs = np.asarray(ours), np.asarray(theirs)
    scale = np.maximum(1.0, np.max(np.abs(theirs), axis=-1))
    error = np.max(np.abs(ours - theirs), axis=-1)
    worst = np.unravel_index(np.argmax(error / scale), np.shape(scale))
    assert np.all(error <= AGREEMENT * scale), f"{label}: robodyn and Pinocchio differ by {error[worst]:.1e} (scale {scale[worst]:.1e})"


def pinocchio_contacts(pm, pd, size: int, frames):
    """Pinocchio's constraint models and datas of the contacts, prepared once as a user would
    before a loop: `initConstraintDynamics` sizes the contact Cholesky factor in `pd`. `size`: 3 (a
    point) or 6 (a frame) rows per contact."""
    kind = pin.ContactType.CONTACT_3D if size == 3 else pin.ContactType.CONTACT_6D
    models, datas = pin.StdVec_RigidConstraintModel(), pin.StdVec_RigidConstraintData()
    for name in frames:
        frame = pm.frames[pm.getFrameId(name)]
        models.append(pin.RigidConstraintModel(kind, pm, frame.parentJoint, frame.placement, pin.LOCAL_WORLD_ALIGNED))
        datas.append(models[-1].createData())
    pin.initConstraintDynamics(pm, pd, models, datas)
    return models, datas


def contact_states(m, contacts, count: int, seed: int):
    """`count` states at the contacts (each (count, n)): random configurations q, velocities v the
    contacts allow, random torques and the random velocities u that v comes from, moving the
    contacts (an impact's). v = u - J⁺ J u: there Pinocchio's drift of 6-D world rows (the
    contact's spatial acceleration) equals robodyn's J̇ v."""
    rng = np.random.default_rng(seed)
    q = m.random_configuration(n=count, seed=seed)
    jacobians = m.constraint_jacobian(q, contacts)
    u = rng.uniform(-1, 1, (count, m.nv))
    v = u - np.einsum("nij,nj->ni", np.linalg.pinv(jacobians), np.einsum("nij,nj->ni", jacobians, u))
    return q, v, rng.uniform(-5, 5, (count, m.nv)), u


def constrained_case(name: str, algorithm: str, states: int | None = None) -> str:
    """A constrained row's case: robot, contacts, algorithm, one call or `states` states."""
    count = "one call" if states is None else f"{states} states"
    return f"{name} {CONTACT_NAMES[CONTACTS[name][1]]}: {algorithm} ({count})"


def compare_constrained(name: str, batch: int) -> list[tuple[str, float, float]]:
    """Forward dynamics with the contacts of CONTACTS (and, for Solo12, an impact on them): one call
    and a batch against `pin.constraintDynamics` (`pin.impulseDynamics`) with its default settings
    (one exact solve), after checking that both give the same answers."""
    path, size, frames = CONTACTS[name]
    urdf = robodyn._example_robot_data_dir() / path
    m = robodyn.load(urdf, floating_base=True)
    pm = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
    pd = pm.createData()
    models, datas = pinocchio_contacts(pm, pd, size, frames)
    contacts = [robodyn.PointAnchor(frame) if size == 3 else robodyn.FrameAnchor(frame) for frame in frames]
    mapping = PinocchioLayout(m, pm)

    q, v, tau, impact = (x[0] for x in contact_states(m, contacts, 1, seed=4))
    states, velocities, torques, impacts = contact_states(m, contacts, batch, seed=5)
    pq, pv, ptau, pimpact = mapping.q_to_pinocchio(q), mapping.v_to_pinocchio(v), mapping.v_to_pinocchio(tau), mapping.v_to_pinocchio(impact)
    pin_states = [mapping.q_to_pinocchio(x) for x in states]
    pin_velocities = [mapping.v_to_pinocchio(x) for x in velocities]
    pin_torques = [mapping.v_to_pinocchio(x) for x in torques]
    pin_impacts = [mapping.v_to_pinocchio(x) for x in impacts]

    def pin_forward(x, w, t):
        return pin.constraintDynamics(pm, pd, x, w, t, models, datas)

    def pin_impulse(x, w):
        return pin.impulseDynamics(pm, pd, x, w, models, datas)

    def pin_forward_loop():
        for x, w, t in zip(pin_states, pin_velocities, pin_torques):
            pin_forward(x, w, t)

    def pin_impulse_loop():
        for x, w in zip(pin_states, pin_impacts):
            pin_impulse(x, w)

    def check(ours, keys, solve, arguments, forces: str) -> None:
        """robodyn's result (one state or a batch), its entries `keys`, against Pinocchio's `solve`
        at the same states: its return value (in robodyn's order) and `pd`'s field `forces`."""
        expected = [(mapping.v_from_pinocchio(solve(*state)), getattr(pd, forces).copy()) for state in arguments]
        for key, column in zip(keys, zip(*expected)):
            assert_agree(f"{name} {key}", np.reshape(ours[key], np.shape(column)), np.array(column))

    forward_keys = ("qdd", "forces")
    check(m.constrained_forward_dynamics(q, v, tau, contacts), forward_keys, pin_forward, [(pq, pv, ptau)], "lambda_c")
    check(m.constrained_forward_dynamics(states, velocities, torques, contacts), forward_keys, pin_forward,
          zip(pin_states, pin_velocities, pin_torques), "lambda_c")
    rows = [
        (constrained_case(name, "forward dynamics"),
         *best_times(lambda: m.constrained_forward_dynamics(q, v, tau, contacts), lambda: pin_forward(pq, pv, ptau), 2000)),
        (constrained_case(name, "forward dynamics", batch),
         *batch_times(lambda: m.constrained_forward_dynamics(states, velocities, torques, contacts), pin_forward_loop)),
    ]
    # the derivatives: one call, and a batch of a tenth of the states (each state's result is
    # six matrices)
    derivative_batch = batch // 10

    def pin_derivatives(x, w, t):
        pin_forward(x, w, t)
        return pin.computeConstraintDynamicsDerivatives(pm, pd, models, datas)

    def pin_derivatives_loop():
        for x, w, t in zip(pin_states[:derivative_batch], pin_velocities, pin_torques):
            pin_derivatives(x, w, t)

    ours = m.constrained_forward_dynamics_derivatives(q, v, tau, contacts)
    for key, theirs in zip(DERIVATIVE_KEYS, pin_derivatives(pq, pv, ptau)):
        expected = mapping.matrix_from_pinocchio(theirs) if key.startswith("dqdd") else mapping.jacobian_from_pinocchio(theirs)
        assert_agree(f"{name} {key}", ours[key].ravel(), expected.ravel())
    few = slice(0, derivative_batch)
    rows += [
        (constrained_case(name, "derivatives"),
         *best_times(lambda: m.constrained_forward_dynamics_derivatives(q, v, tau, contacts),
                     lambda: pin_derivatives(pq, pv, ptau), 200)),
        (constrained_case(name, "derivatives", derivative_batch),
         *batch_times(lambda: m.constrained_forward_dynamics_derivatives(states[few], velocities[few], torques[few], contacts),
                      pin_derivatives_loop)),
    ]
    if name == "solo12":
        impulse_keys = ("v", "impulses")
        check(m.impulse_dynamics(q, impact, contacts), impulse_keys, pin_impulse, [(pq, pimpact)], "impulse_c")
        check(m.impulse_dynamics(states, impacts, contacts), impulse_keys, pin_impulse, zip(pin_states, pin_impacts), "impulse_c")
        rows += [
            (constrained_case(name, "impulse dynamics"),
             *best_times(lambda: m.impulse_dynamics(q, impact, contacts), lambda: pin_impulse(pq, pimpact), 2000)),
            (constrained_case(name, "impulse dynamics", batch),
             *batch_times(lambda: m.impulse_dynamics(states, impacts, contacts), pin_impulse_loop)),
        ]
    return rows


def native_constrained(criterion: Path, timed) -> list[tuple[str, float, float]]:
    """The Rust core's time of each constrained one-call row (the fastest of criterion's samples,
    per iteration, from the last `cargo bench -p robodyn --bench constrained` whose results are in
    `criterion`: the best of several, as the calls from Python are timed), beside that row's time
    from Python in `timed` (the rows of `compare_constrained`). Criterion's headline figure is a
    mean, which on a shared machine sits above a best-of time by the machine's noise."""
    from_python = {case: ours for case, ours, _ in timed}
    rows = []
    for name in CONTACTS:
        for algorithm, bench in CONSTRAINED_ALGORITHMS.items():
            case = constrained_case(name, algorithm)
            samples = criterion / f"constrained_{name}" / bench / "new" / "sample.json"
            if case in from_python and samples.is_file():
                sample = json.loads(samples.read_text(encoding="utf-8"))
                # each sample: its total time (ns) over its iteration count
                nanoseconds = min(t / n for t, n in zip(sample["times"], sample["iters"]))
                rows.append((case, nanoseconds * 1e-9, from_python[case]))
    return rows


def mujoco_model(urdf: Path) -> mujoco.MjModel:
    """MuJoCo's import of a URDF without its meshes (they are not needed for dynamics)."""
    text = re.sub(r"<(visual|collision|gazebo|transmission)\b.*?</\1>", "", urdf.read_text(), flags=re.S)
    return mujoco.MjModel.from_xml_string(text)


def compare_mujoco(name: str, batch: int) -> list[tuple[str, float, float]]:
    path = ROBOTS[name][0]
    urdf = robodyn._example_robot_data_dir() / path
    m = robodyn.load(urdf)
    mj = mujoco_model(urdf)
    d = mujoco.MjData(mj)
    assert mj.nv == m.nv, f"{name}: MuJoCo has nv = {mj.nv}, robodyn {m.nv}"
    rng = np.random.default_rng(0)
    q = m.random_configuration(seed=1)
    v, a = rng.uniform(-1, 1, m.nv), rng.uniform(-1, 1, m.nv)
    tau = np.zeros(m.nv)
    dense = np.zeros((m.nv, m.nv))
    d.qpos[:], d.qvel[:], d.qacc[:] = q, v, a

    def mj_rnea():
        mujoco.mj_kinematics(mj, d)
        mujoco.mj_comPos(mj, d)
        mujoco.mj_comVel(mj, d)
        mujoco.mj_rne(mj, d, 1, tau)

    def mj_crba():
        mujoco.mj_kinematics(mj, d)
        mujoco.mj_comPos(mj, d)
        mujoco.mj_crb(mj, d)
        mujoco.mj_fullM(mj, d, dense)

    def mj_gravity():
        mujoco.mj_kinematics(mj, d)
        mujoco.mj_comPos(mj, d)
        mujoco.mj_rne(mj, d, 0, tau)

    single = {
        "rnea": (lambda: m.inverse_dynamics(q, v, a), mj_rnea),
        "crba": (lambda: m.mass_matrix(q), mj_crba),
        "forward dynamics": (lambda: m.forward_dynamics(q, v, a), lambda: mujoco.mj_forward(mj, d)),
        "gravity": (lambda: m.generalized_gravity(q), mj_gravity),
    }
    rows = [(f"{name} {k} (one call)", *best_times(ours, theirs, 2000)) for k, (ours, theirs) in single.items()]

    states = m.random_configuration(n=batch, seed=2)

    def mj_gravity_loop():
        d.qvel[:] = 0.0
        for x in states:
            d.qpos[:] = x
            mj_gravity()

    def mj_crba_loop():
        for x in states:
            d.qpos[:] = x
            mj_crba()

    rows.append((f"{name} gravity ({batch} states)", *batch_times(lambda: m.generalized_gravity(states), mj_gravity_loop)))
    rows.append((f"{name} crba ({batch} states)", *batch_times(lambda: m.mass_matrix(states), mj_crba_loop)))
    return rows


#: The rollout benchmark: duration (s) and step (s), RK4 in both libraries.
ROLLOUT_DURATION, ROLLOUT_STEP = 10.0, 1e-3


def mujoco_with_pd(urdf: Path, kp: np.ndarray, kd: np.ndarray) -> mujoco.MjModel:
    """MuJoCo's import of the URDF with the same controller as robodyn's native PD: a position
    actuator (gain kp) and a velocity actuator (gain kd) per joint, no clamp on the joints'
    actuator forces, and gravity compensation of every body (``gravcomp="1"``), all evaluated by
    MuJoCo inside its RK4 stages."""
    plain = mujoco_model(urdf)
    names = [plain.joint(j).name for j in range(plain.njnt)]
    spec = mujoco.MjSpec.from_string(re.sub(r"<(visual|collision|gazebo|transmission)\b.*?</\1>", "", urdf.read_text(), flags=re.S))
    for body in spec.bodies:
        body.gravcomp = 1.0
    # MuJoCo's URDF import turns <limit effort> into a clamp on each joint's actuator force;
    # robodyn's PD applies its torque as it is
    for joint in spec.joints:
        joint.actfrclimited = mujoco.mjtLimited.mjLIMITED_FALSE
    for name, p_gain, d_gain in zip(names, kp, kd):
        spec.add_actuator(target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT).set_to_position(kp=p_gain)
        spec.add_actuator(target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT).set_to_velocity(kv=d_gain)
    model = spec.compile()
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    model.opt.timestep = ROLLOUT_STEP
    return model


def compare_rollout(name: str) -> list[tuple[str, float, float]]:
    """A 10 s rollout at dt = 1 ms with RK4 and a PD controller with gravity compensation holding
    the neutral configuration from a displaced start: robodyn.simulate (recording every step, with
    energies) against one mj_step(nstep=10000) call."""
    path = ROBOTS[name][0]
    urdf = robodyn._example_robot_data_dir() / path
    m = robodyn.load(urdf)
    q0 = np.full(m.nv, 0.3)
    inertia = np.diag(m.mass_matrix(q0))
    kp, kd = 100.0 * inertia, 20.0 * inertia
    controller = robodyn.PD(kp, kd, q_ref=m.neutral(), gravity_compensation=True)
    mj = mujoco_with_pd(urdf, kp, kd)
    d = mujoco.MjData(mj)
    steps = int(round(ROLLOUT_DURATION / ROLLOUT_STEP))

    def ours():
        return robodyn.simulate(m, q0, t_end=ROLLOUT_DURATION, dt=ROLLOUT_STEP, integrator="rk4", controller=controller)

    def theirs():
        mujoco.mj_resetData(mj, d)
        d.qpos[:] = q0
        d.ctrl[:] = 0.0
        mujoco.mj_step(mj, d, nstep=steps)

    final = ours().q[-1]
    theirs()
    print(f"{name} rollout: final configurations differ by {np.max(np.abs(final - d.qpos)):.1e} rad")
    return [(f"{name} 10 s rollout, RK4 + PD", *best_times(ours, theirs, 1, 3))]


#: The batched-rollout benchmark: rollouts, each this long (s), RK4 at ROLLOUT_STEP.
BATCHED_ROLLOUTS, BATCHED_DURATION = 64, 1.0


def compare_batched_rollouts(name: str) -> list[tuple[str, float, float]]:
    """64 rollouts of 1 s from random starts, RK4 and the PD of `compare_rollout`, every step
    recorded: one batched robodyn.simulate call against mujoco.rollout with one MjData per core."""
    from mujoco import rollout

    path = ROBOTS[name][0]
    urdf = robodyn._example_robot_data_dir() / path
    m = robodyn.load(urdf)
    inertia = np.diag(m.mass_matrix(np.full(m.nv, 0.3)))
    kp, kd = 100.0 * inertia, 20.0 * inertia
    controller = robodyn.PD(kp, kd, q_ref=m.neutral(), gravity_compensation=True)
    mj = mujoco_with_pd(urdf, kp, kd)
    starts = m.random_configuration(n=BATCHED_ROLLOUTS, seed=3)
    steps = int(round(BATCHED_DURATION / ROLLOUT_STEP))
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    d = mujoco.MjData(mj)
    initial = np.empty((BATCHED_ROLLOUTS, mujoco.mj_stateSize(mj, spec)))
    for state, q0 in zip(initial, starts):
        mujoco.mj_resetData(mj, d)
        d.qpos[:] = q0
        mujoco.mj_getState(mj, d, state, spec)
    workers = [mujoco.MjData(mj) for _ in range(os.cpu_count() or 1)]
    control = np.zeros((BATCHED_ROLLOUTS, 1, mj.nu))

    def ours():
        return robodyn.simulate(m, starts, t_end=BATCHED_DURATION, dt=ROLLOUT_STEP, integrator="rk4", controller=controller)

    def theirs():
        return rollout.rollout(mj, workers, initial, control, nstep=steps)

    finals = np.array([trajectory.q[-1] for trajectory in ours()])
    states, _ = theirs()
    # the full-physics state starts with the time, then qpos
    print(f"{name} batched rollouts: final configurations differ by {np.max(np.abs(finals - states[:, -1, 1:1 + m.nq])):.1e} rad")
    return [(f"{name} {BATCHED_ROLLOUTS} rollouts of {BATCHED_DURATION:g} s, RK4 + PD", *best_times(ours, theirs, 1, 3))]


#: The scene section: Menagerie's Go2 on its floor (testdata; its meshes, which only draw, left out
#: of MuJoCo's copy as of robodyn's), from its `home` keyframe with the keyframe's controls: one step,
#: a run of SCENE_STEPS steps, and SCENE_ROLLOUTS rollouts of SCENE_ROLLOUT_STEPS steps, each
#: recording its last state.
GO2_SCENE = Path(__file__).resolve().parents[1] / "testdata" / "menagerie" / "unitree_go2" / "scene.xml"
SCENE_STEPS, SCENE_ROLLOUTS, SCENE_ROLLOUT_STEPS = 500, 64, 1000


def go2_mujoco() -> mujoco.MjModel:
    """MuJoCo's Go2 scene without its mesh geoms (their files are not in testdata)."""
    spec = mujoco.MjSpec.from_file(str(GO2_SCENE))
    for geom in [g for g in spec.geoms if g.type == mujoco.mjtGeom.mjGEOM_MESH]:
        spec.delete(geom)
    for mesh in list(spec.meshes):
        spec.delete(mesh)
    return spec.compile()


def compare_scene() -> list[tuple[str, float, float]]:
    """The Go2 scene stepped as mj_step steps it (its own integrator, Euler; contacts, dry friction
    and motors): robodyn.step against mj_step from the keyframe (MuJoCo's warm start cleared, as
    robodyn.step has none), robodyn.simulate against mujoco.rollout with one MjData, and a batch of
    rollouts against mujoco.rollout with one MjData per core; each against MuJoCo as the scene
    sets it (its solver stops at `tolerance` 1e-8) and against MuJoCo run to convergence
    (CONVERGED_TOLERANCE), as robodyn's solver runs: the same work on both sides."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", robodyn.ModelWarning)
        m = robodyn.load(GO2_SCENE)
    mj = go2_mujoco()
    converged = go2_mujoco()
    converged.opt.tolerance = CONVERGED_TOLERANCE
    rows = scene_rows(m, mj, "")
    rows += scene_rows(m, converged, ", MuJoCo converged")
    home = m.keyframe("home")
    h = m.options.timestep
    final = robodyn.simulate(m, "home", t_end=SCENE_STEPS * h, dt=SCENE_STEPS * h, integrator="mujoco").q[-1]
    for label, model in (("its tolerance", mj), ("converged", converged)):
        d = mujoco.MjData(model)
        mujoco.mj_resetDataKeyframe(model, d, 0)
        for _ in range(SCENE_STEPS):
            d.ctrl[:] = home.ctrl
            mujoco.mj_step(model, d)
        print(f"go2 scene: after {SCENE_STEPS} steps the base heights differ by {abs(final[2] - d.qpos[2]):.1e} m "
              f"(MuJoCo {label})")
    return rows


#: MuJoCo's `tolerance` where its solver is run to convergence, as robodyn's is (its tests' too).
CONVERGED_TOLERANCE = 1e-15


def scene_rows(m, mj: mujoco.MjModel, label: str) -> list[tuple[str, float, float]]:
    """The scene's three cases, robodyn's `m` against MuJoCo's `mj`, `label` after each case."""
    from mujoco import rollout

    home = m.keyframe("home")
    h = m.options.timestep
    q, v, tau = np.asarray(home.q), np.asarray(home.v), np.zeros(m.nv)
    d = mujoco.MjData(mj)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    mujoco.mj_resetDataKeyframe(mj, d, 0)
    start = np.empty(mujoco.mj_stateSize(mj, spec))
    mujoco.mj_getState(mj, d, start, spec)

    def our_step():
        return robodyn.step(m, q, v, tau, h, integrator="mujoco", ctrl=home.ctrl)

    def their_step():
        mujoco.mj_resetDataKeyframe(mj, d, 0)
        mujoco.mj_step(mj, d)

    def their_reset():
        mujoco.mj_resetDataKeyframe(mj, d, 0)

    ours, theirs = best_times(our_step, their_step, 200)
    reset, _ = best_times(their_reset, their_reset, 200)
    rows = [(f"go2 scene, one step (Euler){label}", ours, theirs - reset)]
    duration = SCENE_STEPS * h
    control = np.tile(np.asarray(home.ctrl), (1, SCENE_STEPS, 1))
    rows.append((f"go2 scene, {SCENE_STEPS} steps{label}", *best_times(
        lambda: robodyn.simulate(m, "home", t_end=duration, dt=duration, integrator="mujoco"),
        lambda: rollout.rollout(mj, d, start[None], control), 1, 5)))
    duration = SCENE_ROLLOUT_STEPS * h
    starts, speeds = np.tile(q, (SCENE_ROLLOUTS, 1)), np.zeros((SCENE_ROLLOUTS, m.nv))
    controls = np.tile(np.asarray(home.ctrl), (SCENE_ROLLOUTS, 1))
    workers = [mujoco.MjData(mj) for _ in range(os.cpu_count() or 1)]
    initial = np.tile(start, (SCENE_ROLLOUTS, 1))
    every_step = np.tile(np.asarray(home.ctrl), (SCENE_ROLLOUTS, SCENE_ROLLOUT_STEPS, 1))
    rows.append((f"go2 scene, {SCENE_ROLLOUTS} rollouts of {SCENE_ROLLOUT_STEPS} steps{label}", *best_times(
        lambda: robodyn.simulate(m, starts, speeds, t_end=duration, dt=duration, integrator="mujoco", ctrl=controls),
        lambda: rollout.rollout(mj, workers, initial, every_step), 1, 5)))
    return rows


def native_scene(criterion: Path, timed) -> list[tuple[str, float, float]]:
    """The Rust core's time of the scene's one step and run (`cargo bench -p robodyn --bench scenes`,
    its results in `criterion`; the fastest sample, as `native_constrained`), beside the call from
    Python."""
    from_python = {case: ours for case, ours, _ in timed}
    rows = []
    for case, bench, steps in (("go2 scene, one step (Euler)", "step_Euler", 1),
                               (f"go2 scene, {SCENE_STEPS} steps", f"run{SCENE_STEPS}_Euler", SCENE_STEPS)):
        samples = criterion / "scene" / f"go2_{bench}" / "new" / "sample.json"
        if case in from_python and samples.is_file():
            sample = json.loads(samples.read_text(encoding="utf-8"))
            nanoseconds = min(t / n for t, n in zip(sample["times"], sample["iters"]))
            rows.append((case, nanoseconds * 1e-9, from_python[case]))
    return rows


def print_table(title: str, other: str, rows) -> None:
    width = max(40, 2 + max((len(case) for case, _, _ in rows), default=0))
    print(f"\n{title}")
    print(f"{'case':<{width}}{'robodyn':>14}{other:>14}{'ratio':>9}")
    for case, ours, theirs in rows:
        unit, scale = ("us", 1e6) if theirs < 1e-3 else ("ms", 1e3)
        print(f"{case:<{width}}{ours * scale:>11.2f} {unit}{theirs * scale:>11.2f} {unit}{ours / theirs:>9.3f}")


#: The sections of a run, in order: robodyn against Pinocchio, the constrained cases, against
#: MuJoCo, the rollouts.
SECTIONS = ("pinocchio", "constrained", "mujoco", "simulation", "scene")
#: The table of the Rust core's constrained times (`--criterion`), after the constrained section.
NATIVE_TITLE = "Constrained dynamics, one call: the Rust core (criterion) beside the call from Python"
#: The table of the Rust core's scene times (`--criterion`), after the scene section.
NATIVE_SCENE_TITLE = "Go2 scene: the Rust core (criterion) beside the call from Python"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--batch", type=int, default=10_000)
    parser.add_argument("--robots", nargs="+", default=list(ROBOTS), choices=list(ROBOTS))
    parser.add_argument("--sections", nargs="+", default=list(SECTIONS), choices=list(SECTIONS), help="the sections run (default: all)")
    parser.add_argument("--criterion", type=Path, help="criterion's results (target/criterion) of `cargo bench -p robodyn --bench "
                        "constrained` and `--bench scenes`, set beside the constrained one-call rows and the scene rows in "
                        "tables of their own")
    parser.add_argument("--json", type=Path, help="also write the tables to this file (times in seconds)")
    args = parser.parse_args()
    versions = {"robodyn": robodyn.__version__, "pinocchio": pin.__version__, "mujoco": mujoco.__version__,
                "python": platform.python_version()}
    machine = {"machine": platform.machine(), "processor": _processor_name(), "cores": os.cpu_count(),
               "load_average": [os.getloadavg()[0]]}
    print(f"robodyn {versions['robodyn']}, Pinocchio {versions['pinocchio']}, MuJoCo {versions['mujoco']}; "
          f"Python {versions['python']}, {machine['machine']}, {machine['cores']} cores")
    sections = {
        "pinocchio": ("robodyn vs Pinocchio", "pinocchio", lambda: [row for name in args.robots for row in compare_robot(name, args.batch)]),
        "constrained": ("Constrained dynamics: robodyn vs Pinocchio (Solo12 on 4 feet, Talos on 2 soles)", "pinocchio",
                        lambda: [row for name in CONTACTS for row in compare_constrained(name, args.batch)]),
        "mujoco": ("robodyn vs MuJoCo (fixed base)", "mujoco", lambda: [row for name in args.robots for row in compare_mujoco(name, args.batch)]),
        "simulation": ("Simulation: robodyn.simulate vs mj_step and mujoco.rollout", "mujoco",
                       lambda: compare_rollout("ur5") + compare_batched_rollouts("ur5")),
        "scene": ("Scene (Go2 on its floor) stepped as mj_step: robodyn vs mj_step and mujoco.rollout", "mujoco",
                  compare_scene),
    }
    tables = []
    for key in args.sections:
        title, other, run = sections[key]
        rows = run()
        print_table(title, other, rows)
        tables.append({"title": title, "other": other, "rows": [list(row) for row in rows]})
        if key == "constrained" and args.criterion:
            native = native_constrained(args.criterion, rows)
            print_table(NATIVE_TITLE, "from Python", native)
            tables.append({"title": NATIVE_TITLE, "other": "from Python", "rows": [list(row) for row in native]})
        if key == "scene" and args.criterion:
            native = native_scene(args.criterion, rows)
            print_table(NATIVE_SCENE_TITLE, "from Python", native)
            tables.append({"title": NATIVE_SCENE_TITLE, "other": "from Python", "rows": [list(row) for row in native]})
    if args.json:
        # the one-minute load average at the start and at the end: other jobs sharing the machine
        machine["load_average"].append(os.getloadavg()[0])
        result = {"date": datetime.date.today().isoformat(), "versions": versions, "machine": machine, "batch": args.batch,
                  "tables": tables}
        args.json.write_text(json.dumps(result, indent=1) + "\n", encoding="utf-8")
        print(f"wrote {args.json}")


def _processor_name() -> str:
    """The CPU's model name (Linux's /proc/cpuinfo), else what `platform` knows."""
    cpuinfo = Path("/proc/cpuinfo")
    if cpuinfo.exists():
        found = re.search(r"^model name\s*:\s*(.+)$", cpuinfo.read_text(), re.MULTILINE)
        if found:
            return found.group(1).strip()
    return platform.processor() or platform.machine()


if __name__ == "__main__":
    main()
