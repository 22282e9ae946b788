"""MuJoCo's own offscreen render of a model at its qpos0, from a free camera, as an (H, W, 3)
NumPy array in a .npy file. Run as a script in its own process, so that MuJoCo picks its OpenGL
back end (``MUJOCO_GL``, osmesa here) when it is imported:

    MUJOCO_GL=osmesa python mujoco_render.py MODEL OUT.npy WIDTH HEIGHT LOOKAT_X LOOKAT_Y LOOKAT_Z DISTANCE AZIMUTH ELEVATION
"""

from __future__ import annotations

import sys

import mujoco
import numpy as np


def render(model_path: str, width: int, height: int, lookat: list[float], distance: float, azimuth: float, elevation: float) -> np.ndarray:
    model = mujoco.MjModel.from_xml_path(model_path)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    camera = mujoco.MjvCamera()
    camera.type = mujoco.mjtCamera.mjCAMERA_FREE
    camera.lookat[:] = lookat
    camera.distance, camera.azimuth, camera.elevation = distance, azimuth, elevation
    with mujoco.Renderer(model, height=height, width=width) as renderer:
        renderer.update_scene(data, camera)
        return renderer.render().copy()


if __name__ == "__main__":
    path, out, width, height = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
    numbers = [float(x) for x in sys.argv[5:11]]
    np.save(out, render(path, width, height, numbers[:3], numbers[3], numbers[4], numbers[5]))
