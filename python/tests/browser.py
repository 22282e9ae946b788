"""Headless Chromium for the viewer tests: screenshots of a page and the URLs it requested
(``robodyn.viewer.offscreen``), and where a world point falls in them.

Chromium comes from the Debian package `chromium` (the test command installs it); everything it
opens is a file or a server on the loopback address.
"""

from __future__ import annotations


import numpy as np

# Chromium and its screenshots live in robodyn.viewer.offscreen, which
# scripts/render_beside_mujoco.py shares; the tests' window is its default size
from robodyn.viewer.offscreen import HEIGHT, WIDTH, chromium, requested_urls, screenshot

__all__ = ["HEIGHT", "WIDTH", "chromium", "colour_fraction", "project", "requested_urls", "screenshot"]


def project(points: np.ndarray, camera: tuple[np.ndarray, np.ndarray], fov: float) -> np.ndarray:
    """Pixel coordinates (column, row) of world points seen by a pinhole camera at ``camera[0]``
    looking at ``camera[1]`` with +z up and vertical field of view ``fov``, in the screenshot."""
    position, target = (np.asarray(c, dtype=float) for c in camera)
    forward = (target - position) / np.linalg.norm(target - position)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    relative = np.atleast_2d(points) - position
    depth = relative @ forward
    scale = np.tan(fov / 2)
    x = (relative @ right) / (depth * scale * WIDTH / HEIGHT)
    y = (relative @ up) / (depth * scale)
    return np.stack([(x + 1) / 2 * WIDTH, (1 - y) / 2 * HEIGHT], axis=1)


def colour_fraction(pixels: np.ndarray, centre: np.ndarray, radius: int, rgb: tuple[int, int, int], tolerance: int) -> float:
    """The fraction of pixels within ``radius`` of ``centre`` (column, row) whose colour is
    within ``tolerance`` (per channel) of a hue like ``rgb``: the dominant channels must lead."""
    column, row = (int(round(c)) for c in centre)
    window = pixels[max(row - radius, 0):row + radius + 1, max(column - radius, 0):column + radius + 1].reshape(-1, 3)
    if len(window) == 0:
        return 0.0
    target = np.asarray(rgb, dtype=np.int16)
    # compare chromaticity: shading changes brightness, not which channel leads
    order = np.argsort(target)[::-1]
    leads = (window[:, order[0]] - window[:, order[2]]) > tolerance
    same_leader = np.argmax(window, axis=1) == order[0]
    return float(np.mean(leads & same_leader))
