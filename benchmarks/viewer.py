"""How fast the viewer poses a robot: the time to send one frame of a 50-body robot to the page
(forward kinematics of every body, quaternions, one batched scene update), against the 16.7 ms a
60 Hz playback allows. Run: .venv/bin/python benchmarks/viewer.py
"""

from __future__ import annotations

import time

import numpy as np

import robodyn
from robodyn.viewer import Viewer

#: Bodies in the chain, frames sent, and the frame period of a 60 Hz playback.
BODIES = 50
FRAMES = 600
PERIOD_MS = 1000 / 60


def chain(bodies: int) -> robodyn.Model:
    """A chain of capsules on alternating hinge axes."""
    links = "".join(
        f'<body name="b{k}" pos="0 0 0.1"><joint name="j{k}" axis="{"0 1 0" if k % 2 else "1 0 0"}"/>'
        f'<geom type="capsule" fromto="0 0 0 0 0 0.1" size="0.02" rgba="0.2 0.4 0.9 1"/>'
        for k in range(bodies))
    text = f'<mujoco model="chain{bodies}"><worldbody>{links}{"</body>" * bodies}</worldbody></mujoco>'
    return robodyn.load_mjcf_string(text)


def main() -> None:
    model = chain(BODIES)
    q = np.random.default_rng(0).uniform(-0.3, 0.3, (FRAMES, model.nq))
    with Viewer(model, q[0], open_browser=False, port=0) as viewer:
        best = np.inf
        for _ in range(3):
            start = time.perf_counter()
            for configuration in q:
                viewer.show(configuration)
            best = min(best, (time.perf_counter() - start) / FRAMES * 1000)
    print(f"{BODIES}-body chain: {best:.3f} ms per frame sent to the page "
          f"({PERIOD_MS / best:.0f}x the 60 Hz budget of {PERIOD_MS:.1f} ms)")


if __name__ == "__main__":
    main()
