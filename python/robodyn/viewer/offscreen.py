"""Pictures of a scene to set side by side: MuJoCo's own offscreen render of an MJCF file and a
headless-Chromium screenshot of robodyn's offline page, from the same camera. The viewer tests and
``scripts/render_beside_mujoco.py`` use them; neither is needed to draw a robot.

MuJoCo renders in a subprocess (this module run as a script), so that it picks its OpenGL back end
(``MUJOCO_GL=osmesa``: Debian's ``libosmesa6``) when it is imported. Chromium comes from the Debian
package ``chromium``; everything it opens is a file or a server on the loopback address.

    MUJOCO_GL=osmesa python -m robodyn.viewer.offscreen MODEL OUT.npy WIDTH HEIGHT LOOKAT_X LOOKAT_Y LOOKAT_Z DISTANCE AZIMUTH ELEVATION [FOVY [Q ...]]

writes MuJoCo's picture (FOVY degrees, ``nan`` for the model's; at Q, default qpos0) as an
(H, W, 3) array and, beside it (``OUT`` with ``-robot.npy``), the mask of the pixels that show the
robot: every geom but planes (MuJoCo's segmentation render).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["chromium", "mujoco_camera", "mujoco_render", "requested_urls", "robot_camera", "robot_html", "screenshot",
           "without_notifications"]

#: Window size of the screenshots, pixels.
WIDTH, HEIGHT = 800, 600
#: Virtual time the page gets to load and draw before the screenshot, milliseconds.
VIRTUAL_TIME_MS = 15000
#: Wall-clock limit of one Chromium run, and of one MuJoCo render, seconds.
CHROMIUM_TIMEOUT_S = 120
MUJOCO_TIMEOUT_S = 300


def chromium() -> str:
    """The Chromium executable (``ROBODYN_CHROMIUM``, or one on the PATH), or a failure saying how
    to install it."""
    for name in (os.environ.get("ROBODYN_CHROMIUM", ""), "chromium", "chromium-browser", "google-chrome"):
        found = shutil.which(name) if name else None
        if found:
            return found
    raise AssertionError("screenshots of the viewer need Chromium: install the 'chromium' package (apt-get install chromium); "
                         "scripts/test installs it where it can")


def screenshot(url: str, folder: Path, name: str = "shot", net_log: bool = False, *, width: int = WIDTH,
               height: int = HEIGHT) -> tuple[np.ndarray, list[str]]:
    """The page at ``url`` in a ``width`` x ``height`` window as an (H, W, 3) RGB array after it
    has loaded and drawn, and (with ``net_log``) every URL it requested. Files go to ``folder``."""
    from PIL import Image

    image = folder / f"{name}.png"
    log = folder / f"{name}-net.json"
    command = [chromium(), "--headless=new", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
               "--no-first-run", "--disable-extensions", "--disable-background-networking", "--disable-sync",
               "--disable-component-update", "--disable-default-apps", "--no-default-browser-check",
               f"--user-data-dir={folder / f'{name}-profile'}", f"--window-size={width},{height}",
               f"--virtual-time-budget={VIRTUAL_TIME_MS}", "--hide-scrollbars", f"--screenshot={image}",
               # no name resolves but the loopback address: nothing leaves this machine, neither
               # the page's requests (the net log still shows them) nor the browser's own
               "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1, EXCLUDE localhost",
               "--disable-features=NetworkTimeServiceQuerying,OptimizationHints,Translate,MediaRouter",
               "--no-pings", "--disable-client-side-phishing-detection", "--disable-domain-reliability"]
    if net_log:
        command.append(f"--log-net-log={log}")
    run = subprocess.run(command + [url], capture_output=True, text=True, timeout=CHROMIUM_TIMEOUT_S)
    assert image.is_file(), f"Chromium made no screenshot of {url}: {run.stderr[-2000:]}"
    pixels = np.asarray(Image.open(image).convert("RGB"), dtype=np.int16)
    return pixels, (requested_urls(log) if net_log else [])


def requested_urls(log: Path) -> list[str]:
    """Every URL a Chromium net log shows the page requesting (the browser's own background
    requests have no origin as their initiator and are left out)."""
    text = log.read_text()
    # a log cut short by the browser's exit lacks its closing brackets
    try:
        events = json.loads(text)["events"]
    except json.JSONDecodeError:
        events = json.loads(text.rstrip().rstrip(",") + "]}")["events"]
    urls = []
    for event in events:
        params = event.get("params", {})
        url, initiator = params.get("url"), params.get("initiator")
        if isinstance(url, str) and initiator is not None and initiator != "not an origin" and url not in urls:
            urls.append(url)
    return urls


def mujoco_camera(position: Any, look_at: Any) -> tuple[np.ndarray, float, float, float]:
    """A camera at ``position`` looking at ``look_at`` as MuJoCo's free camera: look-at point,
    distance, azimuth and elevation (degrees)."""
    position, look_at = np.asarray(position, dtype=float), np.asarray(look_at, dtype=float)
    offset = look_at - position
    distance = float(np.linalg.norm(offset))
    azimuth = float(np.degrees(np.arctan2(offset[1], offset[0])))
    elevation = float(np.degrees(np.arcsin(offset[2] / distance)))
    return look_at, distance, azimuth, elevation


def mujoco_render(path: str | os.PathLike[str], out: Path, width: int, height: int, camera: tuple[Any, Any],
                  fovy: float | None = None, q: Any = None) -> tuple[np.ndarray, np.ndarray]:
    """MuJoCo's offscreen render (osmesa, in a subprocess) of the MJCF file ``path`` at ``q``
    (default: its qpos0) from ``camera`` (position, point looked at) with vertical field of view
    ``fovy`` degrees (default: the model's), and the mask of its robot's pixels (every geom but
    planes, as robodyn's first view frames it). ``out``: the .npy file the subprocess writes."""
    look_at, distance, azimuth, elevation = mujoco_camera(*camera)
    environment = dict(os.environ, MUJOCO_GL="osmesa", PYOPENGL_PLATFORM="osmesa")
    extra = ["nan" if fovy is None else repr(float(fovy))] + ([] if q is None else [repr(float(x)) for x in np.asarray(q, dtype=float)])
    run = subprocess.run([sys.executable, "-m", "robodyn.viewer.offscreen", str(path), str(out), str(width), str(height),
                          *(repr(float(x)) for x in look_at), repr(distance), repr(azimuth), repr(elevation), *extra],
                         capture_output=True, text=True, env=environment, timeout=MUJOCO_TIMEOUT_S)
    assert run.returncode == 0, f"MuJoCo's offscreen render failed (is Debian's libosmesa6 installed?): {run.stderr[-2000:]}"
    return np.load(out), np.load(out.with_name(out.stem + "-robot.npy"))


def _render(path: str, width: int, height: int, look_at: list[float], distance: float, azimuth: float, elevation: float,
            fovy: float | None, q: list[float]) -> tuple[np.ndarray, np.ndarray]:
    """In the subprocess: the picture and the robot's mask."""
    import mujoco

    model = mujoco.MjModel.from_xml_path(path)
    if fovy is not None:
        model.vis.global_.fovy = fovy
    model.vis.global_.offwidth = max(int(model.vis.global_.offwidth), width)
    model.vis.global_.offheight = max(int(model.vis.global_.offheight), height)
    data = mujoco.MjData(model)
    if q:
        data.qpos[:] = q
    mujoco.mj_forward(model, data)
    camera = mujoco.MjvCamera()
    camera.type = mujoco.mjtCamera.mjCAMERA_FREE
    camera.lookat[:] = look_at
    camera.distance, camera.azimuth, camera.elevation = distance, azimuth, elevation
    with mujoco.Renderer(model, height=height, width=width) as renderer:
        renderer.update_scene(data, camera)
        picture = renderer.render().copy()
        renderer.enable_segmentation_rendering()
        renderer.update_scene(data, camera)
        segments = renderer.render().copy()
    ids, types = segments[..., 0], segments[..., 1]
    geom = (types == int(mujoco.mjtObj.mjOBJ_GEOM)) & (ids >= 0)
    robot = np.zeros(ids.shape, dtype=bool)
    robot[geom] = model.geom_type[ids[geom]] != int(mujoco.mjtGeom.mjGEOM_PLANE)
    return picture, robot


def robot_camera(model, q: Any = None) -> tuple[np.ndarray, np.ndarray]:
    """The camera (position, point looked at) of robodyn's first view of ``model`` at ``q``
    (default: neutral): the robot whole, planes left out."""
    from robodyn.viewer import MUJOCO_VISIBLE_GROUPS, _configuration, _pieces
    from robodyn.viewer.scene import _bounds, camera_for

    poses = np.asarray(model.body_poses(_configuration(model, q)))
    return camera_for(*_bounds(_pieces(model, MUJOCO_VISIBLE_GROUPS), poses))


def robot_html(model, path: str | os.PathLike[str], q: Any = None, *, camera: tuple[Any, Any], empty: bool = False) -> Path:
    """Like ``model.to_html(path, q, camera=camera)`` but only the robot's silhouette: every visual
    but planes, in black, with no floor, ground grid or skybox, on the page's white background
    (with ``empty``, not even the robot: what the page shows besides it)."""
    from robodyn.viewer import MUJOCO_VISIBLE_GROUPS, LOOPBACK, _configuration, _pieces, _server, _write_html, check_html_path
    from robodyn.viewer.scene import RobotScene

    target = check_html_path(path)
    q = _configuration(model, q)
    pieces = [replace(piece, rgba=(0.0, 0.0, 0.0, 1.0), image=None, uv=None)
              for piece in _pieces(model, MUJOCO_VISIBLE_GROUPS) if not piece.backdrop and not empty]
    server = _server(LOOPBACK, 0)
    RobotScene(server, pieces, np.asarray(model.body_poses(q)), np.asarray(model.center_of_mass(q)), ground=False, camera=camera)
    return _write_html(server, lambda serializer: None, target)


#: Hides the page's pop-up notes (viser's "Software WebGL rendering detected" in headless Chromium).
NO_NOTIFICATIONS = '<style>[class*="mantine-Notification"] { display: none !important; }</style>'


def without_notifications(page: Path, out: Path) -> Path:
    """A copy of the offline page ``page`` at ``out`` that shows no pop-up notes."""
    text = page.read_text(encoding="utf-8")
    head = text.find("</head>")
    assert head >= 0, f"{page}: no </head>"
    out.write_text(text[:head] + NO_NOTIFICATIONS + text[head:], encoding="utf-8")
    return out


if __name__ == "__main__":
    model_path, out_path, w, h = sys.argv[1], Path(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
    numbers = [float(x) for x in sys.argv[5:]]
    fov = numbers[6] if len(numbers) > 6 and not np.isnan(numbers[6]) else None
    picture, robot = _render(model_path, w, h, numbers[:3], numbers[3], numbers[4], numbers[5], fov, numbers[7:])
    np.save(out_path, picture)
    np.save(out_path.with_name(out_path.stem + "-robot.npy"), robot)
