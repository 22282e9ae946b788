"""MJCF scenes in robodyn's viewer beside MuJoCo's own offscreen render, from the same camera.

usage: python scripts/render_beside_mujoco.py PATH [PATH ...] --out DIR [--width W] [--height H] [--picture-width P]

For each MJCF scene PATH, both renderers show the model at its neutral configuration (MuJoCo's
qpos0: free bodies at their pose in the file) from the camera of robodyn's first view (the robot
framed, planes left out) with robodyn's field of view: MuJoCo's ``mujoco.Renderer`` with
``MUJOCO_GL=osmesa`` (Debian's ``libosmesa6``) and robodyn's offline page (``Model.to_html``)
screenshotted in headless Chromium (``robodyn.viewer.offscreen``; its pop-up notes hidden).
DIR/NAME.png holds MuJoCo's picture on the left and robodyn's on the right (NAME: the scene's
folder, or its file name), each W x H (default 640 x 480), the whole downscaled to P pixels wide
when given. docs/scenes.md shows four Menagerie scenes made so.

One line per scene gives two measures of agreement over the robot's pixels, those showing any
geom but a plane (the floor), as robodyn's first view frames it:

- IoU: the intersection over union of the robot's silhouettes, MuJoCo's from its segmentation
  render and robodyn's from a second page that draws only the robot, in black on white: a pixel
  is the robot's where some channel differs by more than 24 from a third page that draws nothing
  (what the page shows besides the robot, its control button, cancels).
  1 when pose, framing, field of view and shapes agree; lighting and colours do not enter.
- colour: the mean over the pixels in both silhouettes of the largest channel difference between
  the two pictures (0-255): what lighting, reflectance and colours make of the same surfaces.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np
from PIL import Image

import robodyn
from robodyn.viewer.offscreen import mujoco_render, robot_camera, robot_html, screenshot, without_notifications
from robodyn.viewer.scene import CAMERA_FOV

#: A pixel of the robot-only page is the robot's where some channel differs from the empty page
#: by more than this.
BACKGROUND_TOLERANCE = 24
#: Gap between the two pictures, pixels, and its colour.
GAP, GAP_RGB = 8, (255, 255, 255)


def silhouette(robot: np.ndarray, empty: np.ndarray) -> np.ndarray:
    """The robot's pixels on the robot-only page: those unlike the empty page's."""
    return np.abs(robot.astype(int) - empty.astype(int)).max(axis=-1) > BACKGROUND_TOLERANCE


def measures(theirs: np.ndarray, their_robot: np.ndarray, ours: np.ndarray, our_robot: np.ndarray) -> tuple[float, float]:
    """The silhouettes' intersection over union, and the mean largest channel difference over
    the pixels in both."""
    both = their_robot & our_robot
    union = their_robot | our_robot
    iou = float(both.sum() / union.sum()) if union.any() else 0.0
    difference = np.abs(theirs.astype(int) - ours.astype(int)).max(axis=-1)
    colour = float(difference[both].mean()) if both.any() else float("nan")
    return iou, colour


def name_of(path: Path) -> str:
    """The picture's name: the scene's folder, and the file's stem unless it is 'scene'."""
    return path.parent.name + ("" if path.stem == "scene" else f"-{path.stem}")


def render(path: Path, out: Path, width: int, height: int, work: Path, picture_width: int | None = None) -> tuple[float, float]:
    """Writes ``out`` (MuJoCo | robodyn) for the scene at ``path``; returns its measures."""
    with warnings.catch_warnings():
        # what the page cannot draw it draws in its material's colour: said once, by to_html
        warnings.simplefilter("ignore", robodyn.ModelWarning)
        model = robodyn.load(path)
        camera = robot_camera(model)
        robot_html(model, work / "robot-full.html", camera=camera)
        robot_html(model, work / "empty-full.html", camera=camera, empty=True)
    model.to_html(work / "scene-full.html", camera=camera)
    theirs, their_robot = mujoco_render(path, work / "mujoco.npy", width, height, camera, float(np.degrees(CAMERA_FOV)))
    shots = {}
    for name in ["scene", "robot", "empty"]:
        page = without_notifications(work / f"{name}-full.html", work / f"{name}.html")
        shots[name], _ = screenshot(page.resolve().as_uri(), work, name, width=width, height=height)
    ours = shots["scene"]
    side_by_side = np.full((height, 2 * width + GAP, 3), GAP_RGB, dtype=np.uint8)
    side_by_side[:, :width] = theirs
    side_by_side[:, width + GAP:] = ours
    picture = Image.fromarray(side_by_side)
    if picture_width is not None and picture_width < picture.width:
        picture = picture.resize((picture_width, round(picture.height * picture_width / picture.width)), Image.Resampling.LANCZOS)
    picture.save(out, optimize=True)
    return measures(theirs, their_robot, ours, silhouette(shots["robot"], shots["empty"]))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("paths", nargs="+", type=Path, metavar="PATH", help="MJCF scene files")
    parser.add_argument("--out", type=Path, required=True, help="folder for the side-by-side PNGs")
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=480)
    parser.add_argument("--picture-width", type=int, help="downscale each side-by-side PNG to this width")
    arguments = parser.parse_args(argv)
    arguments.out.mkdir(parents=True, exist_ok=True)
    failed = 0
    for path in arguments.paths:
        out = arguments.out / f"{name_of(path)}.png"
        try:
            with tempfile.TemporaryDirectory() as work:
                iou, colour = render(path, out, arguments.width, arguments.height, Path(work), arguments.picture_width)
        except Exception as error:  # one scene's failure is reported, the others still drawn
            failed += 1
            print(f"{path}: FAILED: {type(error).__name__}: {error}", flush=True)
            continue
        print(f"{path}: IoU {iou:.3f}, colour {colour:.1f} -> {out}", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
