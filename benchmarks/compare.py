"""robodyn against Pinocchio from Python, in one run: per-call time of each algorithm and a
10 000-state batch against a Pinocchio loop, printed as ratios (< 1 means robodyn is faster).

Run: .venv/bin/python benchmarks/compare.py [--batch 10000] [--robots ur5 panda talos]
Needs the bench extras (pip install '.[bench]'). Times are the best of several repeats.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import timeit
from pathlib import Path

import numpy as np
import pinocchio as pin

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python" / "tests"))
import robodyn  # noqa: E402
from conventions import PinocchioMap  # noqa: E402

ROBOTS = {
    "ur5": ("ur_description/urdf/ur5_robot.urdf", False),
    "panda": ("panda_description/urdf/panda.urdf", False),
    "talos": ("talos_data/robots/talos_full_v2.urdf", True),
}


def best_time(function, number: int) -> float:
    """Best per-call time in seconds over 5 repeats of `number` calls."""
    return min(timeit.repeat(function, number=number, repeat=5)) / number


def compare_robot(name: str, batch: int) -> list[tuple[str, float, float]]:
    path, floating = ROBOTS[name]
    urdf = robodyn._example_robot_data_dir() / path
    m = robodyn.load(urdf, floating_base=floating)
    pm = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer()) if floating else pin.buildModelFromUrdf(str(urdf))
    pd = pm.createData()
    mapping = PinocchioMap(m, pm)
    rng = np.random.default_rng(0)
    q = m.random_configuration(seed=1)
    v, a = rng.uniform(-1, 1, m.nv), rng.uniform(-1, 1, m.nv)
    pq, pv, pa = mapping.q(q), mapping.v(v), mapping.v(a)
    frame = m.frame_names[-1]
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
    }
    rows = []
    for algorithm, (ours, theirs) in single.items():
        rows.append((f"{name} {algorithm} (one call)", best_time(ours, 2000), best_time(theirs, 2000)))

    states = m.random_configuration(n=batch, seed=2)
    pin_states = [mapping.q(x) for x in states]
    velocities = rng.uniform(-1, 1, (batch, m.nv))
    pin_velocities = [mapping.v(x) for x in velocities]

    def pin_gravity_loop():
        for x in pin_states:
            pin.computeGeneralizedGravity(pm, pd, x)

    def pin_rnea_loop():
        for x, w in zip(pin_states, pin_velocities):
            pin.rnea(pm, pd, x, w, w)

    def pin_crba_loop():
        for x in pin_states:
            pin.crba(pm, pd, x)

    batches = {
        "gravity": (lambda: m.generalized_gravity(states), pin_gravity_loop),
        "rnea": (lambda: m.inverse_dynamics(states, velocities, velocities), pin_rnea_loop),
        "crba": (lambda: m.mass_matrix(states), pin_crba_loop),
    }
    for algorithm, (ours, theirs) in batches.items():
        rows.append((f"{name} {algorithm} ({batch} states)", best_time(ours, 1), best_time(theirs, 1)))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--batch", type=int, default=10_000)
    parser.add_argument("--robots", nargs="+", default=list(ROBOTS), choices=list(ROBOTS))
    args = parser.parse_args()
    print(f"robodyn {robodyn.__version__} vs Pinocchio {pin.__version__}; Python {platform.python_version()}, "
          f"{platform.machine()}, {os.cpu_count()} cores ({platform.processor() or 'unknown CPU'})")
    print(f"{'case':<36}{'robodyn':>14}{'pinocchio':>14}{'ratio':>9}")
    for name in args.robots:
        for case, ours, theirs in compare_robot(name, args.batch):
            unit, scale = ("us", 1e6) if theirs < 1e-3 else ("ms", 1e3)
            print(f"{case:<36}{ours * scale:>11.2f} {unit}{theirs * scale:>11.2f} {unit}{ours / theirs:>9.3f}")


if __name__ == "__main__":
    main()
