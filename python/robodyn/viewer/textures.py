"""MJCF textures as the viewer draws them: the images (PNG files, MuJoCo's builtin checker,
gradient and flat patterns with their edge, cross and random marks, made pixel for pixel as
MuJoCo's compiler makes them, but for the random dots, see :func:`builtin_image`), the texture
coordinates MuJoCo gives a plane, and the skybox as a panorama on a sphere around the scene.

A texture that cannot be drawn (a cube texture on a geom, a 2-D texture on a geom without texture
coordinates, a file robodyn cannot read) leaves the geom in its material's colour, with a
:class:`robodyn.ModelWarning` naming the texture.
"""

from __future__ import annotations

import json
import struct
import warnings
from typing import Any

import numpy as np

__all__ = ["builtin_image", "cube_faces", "plane_uv", "skybox_panorama", "texture_image", "undrawn", "unlit_glb"]

#: The seed of the random dots (MuJoCo's own generator is not NumPy's: the dots fall elsewhere,
#: with the same probability per pixel).
RANDOM_DOT_SEED = 42
#: Pixels of the skybox's panorama: longitude by latitude.
PANORAMA_SIZE = (1024, 512)


def undrawn(texture: dict[str, Any], why: str) -> None:
    """Warns that ``texture`` is not drawn (its geom keeps the material's colour)."""
    from robodyn import ModelWarning

    warnings.warn(f"{texture['element']}: texture '{texture['name']}' is not drawn ({why}): the material's colour is drawn instead",
                  ModelWarning, stacklevel=3)


def _bytes(rgb: Any) -> np.ndarray:
    """Colours in [0, 1] as MuJoCo's compiler stores them: 255 x, truncated."""
    return (255 * np.asarray(rgb, dtype=float)).astype(np.uint8)


def _blend(rgb1: Any, rgb2: Any, position: np.ndarray) -> np.ndarray:
    """MuJoCo's sigmoid blend of two colours at ``position`` in [-1, 1] (rgb2 at -1, an even mix
    at 0, rgb1 at +1), as bytes: alpha = (1 + √2 p / √(1 + p²)) / 2, clipped to [0, 1]."""
    alpha = np.clip(0.5 * (1 + np.sqrt(2) * position / np.sqrt(1 + position**2)), 0.0, 1.0)[..., None]
    return (255 * (alpha * np.asarray(rgb1, dtype=float) + (1 - alpha) * np.asarray(rgb2, dtype=float))).astype(np.uint8)


def _checker(first: np.ndarray, second: np.ndarray, width: int, height: int) -> np.ndarray:
    """Two by two squares: ``first`` top left and bottom right, ``second`` elsewhere."""
    image = np.empty((height, width, 3), dtype=np.uint8)
    top, left = np.arange(height)[:, None] < height // 2, np.arange(width)[None, :] < width // 2
    image[:] = np.where((top == left)[..., None], first, second)
    return image


def _mark(images: list[np.ndarray], spec: dict[str, Any]) -> None:
    """Draws the mark of ``spec`` over each image (in place): its edge, or a cross through its
    middle row and column, or random dots (over the first width x height pixels of the images
    laid end to end, as MuJoCo lays them)."""
    colour = _bytes(spec["markrgb"])
    for image in images:
        height, width = image.shape[:2]
        if spec["mark"] == "edge":
            image[:, [0, width - 1]] = colour
            image[[0, height - 1], :] = colour
        elif spec["mark"] == "cross":
            image[:, width // 2] = colour
            image[height // 2, :] = colour
    if spec["mark"] == "random" and spec["random"] > 0:
        pixels = np.concatenate([image.reshape(-1, 3) for image in images])
        count = min(len(pixels), spec["width"] * spec["height"])
        dots = np.random.default_rng(RANDOM_DOT_SEED).random(count) < spec["random"]
        pixels[:count][dots] = colour
        start = 0
        for image in images:
            image.reshape(-1, 3)[:] = pixels[start:start + image.shape[0] * image.shape[1]]
            start += image.shape[0] * image.shape[1]


def builtin_image(spec: dict[str, Any]) -> np.ndarray:
    """A builtin 2-D texture (``visual['texture']['builtin']``) as an (height, width, 3) image:
    a radial gradient from rgb1 in the middle to rgb2 at the corners, a checker, or flat rgb1,
    then the mark."""
    width, height = spec["width"], spec["height"]
    if spec["pattern"] == "gradient":
        x = 2 * np.arange(width)[None, :] / max(width - 1, 1) - 1
        y = 1 - 2 * np.arange(height)[:, None] / max(height - 1, 1)
        image = _blend(spec["rgb2"], spec["rgb1"], 2 * np.sqrt(x**2 + y**2) - 1)
    elif spec["pattern"] == "checker":
        image = _checker(_bytes(spec["rgb1"]), _bytes(spec["rgb2"]), width, height)
    else:
        image = np.broadcast_to(_bytes(spec["rgb1"]), (height, width, 3)).copy()
    _mark([image], spec)
    return image


def cube_faces(spec: dict[str, Any]) -> list[np.ndarray]:
    """A builtin cube or skybox texture's six faces (right, left, up, down, front, back: +x, -x,
    +y, -y, +z, -z of the cube map), each (width, width, 3): a gradient by elevation from rgb1
    above to rgb2 below, a checker, or flat rgb1 with rgb2 below; then the mark."""
    w = spec["width"]
    rgb1, rgb2 = spec["rgb1"], spec["rgb2"]
    if spec["pattern"] == "gradient":
        x = 2 * np.arange(w)[None, :] / max(w - 1, 1) - 1
        y = 1 - 2 * np.arange(w)[:, None] / max(w - 1, 1)
        sides = _blend(rgb1, rgb2, np.arcsin(y / np.sqrt(1 + x**2 + y**2)) / (np.pi / 2))
        elevation = 1 - np.arccos(1 / np.sqrt(1 + x**2 + y**2)) / (np.pi / 2)
        faces = [sides, sides.copy(), _blend(rgb1, rgb2, elevation), _blend(rgb1, rgb2, -elevation), sides.copy(), sides.copy()]
    elif spec["pattern"] == "checker":
        first, second = _bytes(rgb1), _bytes(rgb2)
        faces = [_checker(first, second, w, w) for _ in range(4)] + [_checker(second, first, w, w) for _ in range(2)]
    else:
        faces = [np.broadcast_to(_bytes(rgb2 if k == 3 else rgb1), (w, w, 3)).copy() for k in range(6)]
    _mark(faces, spec)
    return faces


def _sample_cube(faces: list[np.ndarray], directions: np.ndarray) -> np.ndarray:
    """The cube map's colour in each direction (..., 3) of the cube's own axes, by OpenGL's rule:
    the face of the largest component, then (s, t) on it."""
    shape = directions.shape[:-1]
    d = directions.reshape(-1, 3)
    axis = np.argmax(np.abs(d), axis=1)
    major = d[np.arange(len(d)), axis]
    face = 2 * axis + (major < 0)
    rx, ry, rz = d.T
    # (sc, tc) of each face: OpenGL's cube-map table
    sc = np.select([face == 0, face == 1, face == 2, face == 3, face == 4], [-rz, rz, rx, rx, rx], -rx)
    tc = np.select([face == 2, face == 3], [rz, -rz], -ry)
    s, t = (sc / np.abs(major) + 1) / 2, (tc / np.abs(major) + 1) / 2
    size = faces[0].shape[0]
    column, row = np.clip((s * size).astype(int), 0, size - 1), np.clip((t * size).astype(int), 0, size - 1)
    stacked = np.stack(faces)
    return stacked[face, row, column].reshape(*shape, 3)


def skybox_panorama(spec: dict[str, Any]) -> np.ndarray:
    """A builtin skybox as an equirectangular image (:data:`PANORAMA_SIZE`; longitude from -π at
    the left, latitude from +π/2 at the top, in world axes with z up). MuJoCo lays the cube map
    with its up face along world +z: cube axes (x, y, z) are world (x, z, -y)."""
    columns, rows = PANORAMA_SIZE
    longitude = (np.arange(columns) + 0.5) / columns * 2 * np.pi - np.pi
    latitude = np.pi / 2 - (np.arange(rows) + 0.5) / rows * np.pi
    lon, lat = np.meshgrid(longitude, latitude)
    world = np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], axis=-1)
    cube = np.stack([world[..., 0], world[..., 2], -world[..., 1]], axis=-1)
    return _sample_cube(cube_faces(spec), cube)


def texture_image(texture: dict[str, Any]):
    """A 2-D texture's image as a PIL image (its PNG file, flipped as asked, or its builtin
    pattern), or None with a warning when it cannot be drawn."""
    from PIL import Image

    if texture["undrawable"] is not None:
        undrawn(texture, texture["undrawable"])
        return None
    if texture["builtin"] is not None:
        return Image.fromarray(builtin_image(texture["builtin"]))
    try:
        with Image.open(texture["file"]) as opened:
            image = opened.convert("RGBA" if opened.mode in ("RGBA", "LA", "P") else "RGB")
    except OSError as error:
        undrawn(texture, f"cannot read '{texture['file']}': {error}")
        return None
    if texture["hflip"]:
        image = image.transpose(Image.Transpose.FLIP_LEFT_RIGHT)
    if texture["vflip"]:
        image = image.transpose(Image.Transpose.FLIP_TOP_BOTTOM)
    return image


def plane_uv(vertices: np.ndarray, size: list[float], texture: dict[str, Any]) -> np.ndarray:
    """MuJoCo's texture coordinates (s, t) on a plane geom at ``vertices`` (its own frame), for
    ``texture``'s ``repeat`` and ``uniform``: over a bounded plane s runs 0 to 1 along x and t 1
    to 0 along y, each times the repeat (times the half-size where uniform); an unbounded plane
    has s = x/2, t = -y/2, times the repeat, less 1/2. Image row 0 is at t = 0."""
    scale = np.array([r if r > 0 else 1.0 for r in texture["repeat"]])
    half = np.asarray(size[:2], dtype=float)
    if texture["uniform"]:
        scale = np.where(half > 0, scale * half, scale)
    x, y = vertices[:, 0], vertices[:, 1]
    s = (x + half[0]) / (2 * half[0]) if half[0] > 0 else 0.5 * x
    t = 1 - (y + half[1]) / (2 * half[1]) if half[1] > 0 else -0.5 * y
    shift = 0.5 if (half <= 0).any() else 0.0
    return np.stack([scale[0] * s - shift, scale[1] * t - shift], axis=1)


def unlit_glb(glb: bytes) -> bytes:
    """A binary glTF with each material marked unlit (KHR_materials_unlit): drawn in its own
    colours whatever the lights, as MuJoCo draws its skybox."""
    magic, version, _ = struct.unpack_from("<4sII", glb, 0)
    json_length, json_type = struct.unpack_from("<I4s", glb, 12)
    if magic != b"glTF" or json_type != b"JSON":
        raise ValueError("expected a binary glTF whose first chunk is JSON")
    document = json.loads(glb[20:20 + json_length])
    for material in document.get("materials", []):
        material.setdefault("extensions", {})["KHR_materials_unlit"] = {}
    document["extensionsUsed"] = sorted(set(document.get("extensionsUsed", [])) | {"KHR_materials_unlit"})
    text = json.dumps(document, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    rest = glb[20 + json_length:]
    total = 12 + 8 + len(text) + len(rest)
    return struct.pack("<4sII", magic, version, total) + struct.pack("<I4s", len(text), b"JSON") + text + rest
