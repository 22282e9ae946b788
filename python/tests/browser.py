"""Headless Chromium for the viewer tests: screenshots of a page and the URLs it requested.

Chromium comes from the Debian package `chromium` (the test command installs it); everything it
opens is a file or a server on the loopback address.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np

#: Window size of the screenshots, pixels.
WIDTH, HEIGHT = 800, 600
#: Virtual time the page gets to load and draw before the screenshot, milliseconds.
VIRTUAL_TIME_MS = 15000
#: Wall-clock limit of one Chromium run, seconds.
CHROMIUM_TIMEOUT_S = 120


def chromium() -> str:
    """The Chromium executable, or a failure saying how to install it."""
    for name in (os.environ.get("ROBODYN_CHROMIUM", ""), "chromium", "chromium-browser", "google-chrome"):
        if name and shutil.which(name):
            return shutil.which(name)  # type: ignore[return-value]
    raise AssertionError("the viewer tests need Chromium: install the 'chromium' package (apt-get install chromium); "
                         "scripts/test installs it where it can")


def screenshot(url: str, folder: Path, name: str = "shot", net_log: bool = False) -> tuple[np.ndarray, list[str]]:
    """The page at ``url`` as an (H, W, 3) RGB array after it has loaded and drawn, and (with
    ``net_log``) every URL it requested."""
    from PIL import Image

    image = folder / f"{name}.png"
    log = folder / f"{name}-net.json"
    command = [chromium(), "--headless=new", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
               "--no-first-run", "--disable-extensions", "--disable-background-networking", "--disable-sync",
               "--disable-component-update", "--disable-default-apps", "--no-default-browser-check",
               f"--user-data-dir={folder / f'{name}-profile'}", f"--window-size={WIDTH},{HEIGHT}",
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
