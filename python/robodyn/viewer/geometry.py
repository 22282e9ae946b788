"""The robot's visuals as triangle meshes in the frames of the bodies they move with.

Each visual of ``Model.visuals`` becomes one or more :class:`Piece`: primitives are tessellated by
trimesh, MuJoCo's mesh formats (STL, OBJ, .msh) are read by robodyn's own readers (the ones the
mesh inertias use), and the formats ROS robots ship (Collada ``.dae``, glTF, PLY, ...) by trimesh,
keeping the colours of their materials unless the model gives the visual a colour of its own.
MJCF textures (``robodyn.viewer.textures``) are laid on planes by MuJoCo's texture coordinates and
on meshes by their files'; the skybox is a panorama on a sphere around the scene.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from robodyn import _core
from robodyn.viewer.textures import plane_uv, skybox_panorama, texture_image, undrawn

__all__ = ["DEFAULT_RGBA", "MUJOCO_VISIBLE_GROUPS", "Piece", "skybox_piece", "stick_pieces", "visual_pieces"]

#: MuJoCo's geom colour when nothing gives one; a visual of this colour keeps its mesh's own.
DEFAULT_RGBA = (0.5, 0.5, 0.5, 1.0)
#: The geom groups MuJoCo's viewer shows unless told otherwise.
MUJOCO_VISIBLE_GROUPS = (0, 1, 2)
#: Tessellation of spheres, ellipsoids and capsule ends (icosphere subdivisions) and of round
#: sections (segments).
SPHERE_SUBDIVISIONS = 3
ROUND_SEGMENTS = 32
#: Half-side drawn for an unbounded MJCF plane (size 0), in metres.
UNBOUNDED_PLANE_HALF_SIDE = 5.0
#: Thickness of a drawn plane, in metres.
PLANE_THICKNESS = 1e-3
#: The stick figure drawn for a model without visuals: rod and joint radii as fractions of the
#: robot's size, and colours.
STICK_RADIUS_FRACTION = 0.012
JOINT_RADIUS_FRACTION = 0.025
STICK_RGBA = (0.35, 0.45, 0.6, 1.0)
JOINT_RGBA = (0.9, 0.5, 0.1, 1.0)
#: The formats robodyn reads itself, triangulated as MuJoCo triangulates them.
OWN_FORMATS = {".stl", ".obj", ".msh"}
#: The skybox sphere: its radius as a multiple of the scene's size (at least
#: :data:`SKYBOX_MIN_RADIUS` metres), inside the camera's far plane, and its tessellation.
SKYBOX_RADIUS_FACTOR = 20.0
SKYBOX_MIN_RADIUS = 50.0
SKYBOX_SEGMENTS = (64, 32)


@dataclass
class Piece:
    """A triangle mesh fixed to body ``body`` (index into ``["world"] + body_names``), its
    vertices in that body's frame, drawn in ``rgba``."""

    name: str
    body: int
    vertices: np.ndarray
    faces: np.ndarray
    rgba: tuple[float, float, float, float]
    #: When textured: texture coordinates (n, 2) in trimesh's convention (v from the image's
    #: bottom) and the image (PIL), drawn times ``rgba``.
    uv: np.ndarray | None = None
    image: Any = None
    #: Left out of the first view's framing: planes (often unbounded floors) and the skybox.
    backdrop: bool = False
    #: Drawn in its own colours whatever the light (the skybox).
    unlit: bool = False


def _primitive(kind: str, size: list[float]):
    """A trimesh of an MJCF-sized primitive in its own frame (z: the axis of round shapes)."""
    import trimesh

    if kind == "box":
        return trimesh.creation.box(extents=2 * np.asarray(size))
    if kind == "sphere":
        return trimesh.creation.icosphere(subdivisions=SPHERE_SUBDIVISIONS, radius=size[0])
    if kind == "ellipsoid":
        sphere = trimesh.creation.icosphere(subdivisions=SPHERE_SUBDIVISIONS, radius=1.0)
        sphere.vertices *= np.asarray(size)
        return sphere
    if kind == "cylinder":
        return trimesh.creation.cylinder(radius=size[0], height=2 * size[1], sections=ROUND_SEGMENTS)
    if kind == "capsule":
        return trimesh.creation.capsule(height=2 * size[1], radius=size[0], count=[ROUND_SEGMENTS, ROUND_SEGMENTS])
    if kind == "plane":
        half = [s if s > 0 else UNBOUNDED_PLANE_HALF_SIDE for s in size[:2]]
        plane = trimesh.creation.box(extents=[2 * half[0], 2 * half[1], PLANE_THICKNESS])
        plane.vertices[:, 2] -= PLANE_THICKNESS / 2
        return plane
    raise ValueError(f"unknown visual kind '{kind}'")


def _mesh_file_parts(visual: dict) -> list[tuple[np.ndarray, np.ndarray, tuple[float, ...] | None]]:
    """The (vertices, faces, own colour or None) of a visual's mesh, in the file's coordinates."""
    if visual.get("mesh_vertices") is not None:
        return [(np.asarray(visual["mesh_vertices"]), np.asarray(visual["mesh_faces"]), None)]
    if visual["mesh_missing"] is not None:
        raise FileNotFoundError(visual["mesh_missing"])
    path = visual["mesh_file"]
    suffix = os.path.splitext(path)[1].lower()
    if suffix in OWN_FORMATS:
        try:
            vertices, faces = _core.read_mesh_file(path)
        except ValueError as error:
            raise ValueError(f"{visual['element']}: {error}") from None
        return [(vertices, faces, None)]
    import trimesh

    try:
        loaded = trimesh.load(path)
    except Exception as error:  # trimesh raises many kinds; name the file and element
        raise ValueError(f"{visual['element']}: cannot read the mesh file '{path}' ({type(error).__name__}: {error})") from None
    meshes = loaded.dump() if isinstance(loaded, trimesh.Scene) else [loaded]
    parts = []
    for mesh in meshes:
        if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
            continue
        color = None
        try:
            color = tuple(float(c) / 255 for c in mesh.visual.main_color)
        except (AttributeError, TypeError, ValueError):
            color = None
        parts.append((np.asarray(mesh.vertices), np.asarray(mesh.faces), color))
    if not parts:
        raise ValueError(f"{visual['element']}: the mesh file '{path}' holds no triangles")
    return parts


def _textured_mesh(visual: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """(vertices, faces, uv) of a mesh file that has texture coordinates, else None."""
    import trimesh

    path = visual.get("mesh_file")
    if path is None:
        return None
    try:
        mesh = trimesh.load(path, process=False, force="mesh")
    except Exception as error:  # trimesh raises many kinds; name the file and element
        raise ValueError(f"{visual['element']}: cannot read the mesh file '{path}' ({type(error).__name__}: {error})") from None
    uv = getattr(mesh.visual, "uv", None)
    if uv is None or len(uv) != len(mesh.vertices):
        return None
    return np.asarray(mesh.vertices), np.asarray(mesh.faces, dtype=np.int64), np.asarray(uv, dtype=float)


class _TextureImages:
    """Each 2-D texture's image, made once; a texture that cannot be drawn warns once."""

    def __init__(self) -> None:
        self.images: dict[str, Any] = {}
        self.warned: set[str] = set()

    def image(self, texture: dict[str, Any]):
        key = texture["element"]
        if key not in self.images:
            self.images[key] = texture_image(texture)
        return self.images[key]

    def undrawn(self, texture: dict[str, Any], why: str) -> None:
        if texture["element"] not in self.warned:
            self.warned.add(texture["element"])
            undrawn(texture, why)


def _affine(matrix: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Points mapped by a 4x4 homogeneous matrix."""
    return points @ matrix[:3, :3].T + matrix[:3, 3]


def visual_pieces(model, groups: tuple[int, ...] | None = MUJOCO_VISIBLE_GROUPS) -> list[Piece]:
    """Every visual of ``model`` whose group is in ``groups`` (None: all) as pieces in their
    bodies' frames. A mesh file that is missing raises ``FileNotFoundError``, one that cannot be
    read ``ValueError``, both naming the file and the element that names it."""
    pieces = []
    # a file named by several visuals (a hand's fingers) is read once
    files: dict[str, list[tuple[np.ndarray, np.ndarray, tuple[float, ...] | None]]] = {}
    textures = _TextureImages()
    for visual in model.visuals:
        if groups is not None and visual["group"] not in groups:
            continue
        placement = np.asarray(visual["placement"])
        rgba = tuple(float(np.clip(c, 0.0, 1.0)) for c in visual["rgba"])
        texture = visual.get("texture")
        image = None
        if texture is not None and texture["kind"] != "2d":
            textures.undrawn(texture, f"a {texture['kind']} texture on a {visual['kind']} geom is not drawn")
        elif texture is not None:
            image = textures.image(texture)
        if visual["kind"] == "hfield":
            if image is not None:
                textures.undrawn(texture, "robodyn lays 2-D textures on planes and meshes, not on a height field")
            pieces.append(Piece(visual["name"], visual["body"], _affine(placement, np.asarray(visual["mesh_vertices"], dtype=float)),
                                np.asarray(visual["mesh_faces"], dtype=np.int64), rgba, backdrop=True))
            continue
        if visual["kind"] == "mesh":
            to_body = placement @ np.asarray(visual["file_to_visual"])
            # a mirroring scale turns the faces inside out: turn them back
            flip = np.linalg.det(to_body[:3, :3]) < 0
            textured = _textured_mesh(visual) if image is not None else None
            if image is not None and textured is None:
                textures.undrawn(texture, "the mesh has no texture coordinates")
            if textured is not None:
                vertices, faces, uv = textured
                pieces.append(Piece(visual["name"], visual["body"], _affine(to_body, vertices), faces[:, ::-1] if flip else faces,
                                    rgba, uv=uv, image=image))
                continue
            key = visual.get("mesh_file") or f"inline:{visual['element']}"
            if key not in files:
                files[key] = _mesh_file_parts(visual)
            for k, (vertices, faces, own) in enumerate(files[key]):
                faces = np.asarray(faces, dtype=np.int64)
                color = own if (own is not None and rgba == DEFAULT_RGBA) else rgba
                pieces.append(Piece(f"{visual['name']}/{k}", visual["body"], _affine(to_body, np.asarray(vertices, dtype=float)),
                                    faces[:, ::-1] if flip else faces, color))
            continue
        mesh = _primitive(visual["kind"], visual["size"])
        vertices = np.asarray(mesh.vertices)
        piece = Piece(visual["name"], visual["body"], _affine(placement, vertices), np.asarray(mesh.faces, dtype=np.int64), rgba,
                      backdrop=visual["kind"] == "plane")
        if image is not None and visual["kind"] == "plane":
            # trimesh's v runs from the image's bottom, MuJoCo's t from its top row
            st = plane_uv(vertices, visual["size"], texture)
            piece.uv, piece.image = np.stack([st[:, 0], 1 - st[:, 1]], axis=1), image
        elif image is not None:
            textures.undrawn(texture, f"robodyn lays 2-D textures on planes and meshes, not on a {visual['kind']}")
        pieces.append(piece)
    return pieces


def skybox_piece(texture: dict[str, Any] | None, centre: np.ndarray, size: float) -> Piece | None:
    """A skybox texture (``Model.skybox``) as an unlit sphere around ``centre``, larger than the
    scene's ``size``, painted with its panorama; None when there is none, or with a warning when
    it cannot be drawn."""
    from PIL import Image

    if texture is None:
        return None
    if texture["builtin"] is None:
        undrawn(texture, texture["undrawable"] or "a skybox from image files is not drawn")
        return None
    columns, rows = SKYBOX_SEGMENTS
    longitude = np.linspace(-np.pi, np.pi, columns + 1)
    latitude = np.linspace(np.pi / 2, -np.pi / 2, rows + 1)
    lon, lat = np.meshgrid(longitude, latitude)
    radius = max(SKYBOX_RADIUS_FACTOR * size, SKYBOX_MIN_RADIUS)
    vertices = radius * np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], axis=-1).reshape(-1, 3)
    uv = np.stack([(lon + np.pi) / (2 * np.pi), (lat + np.pi / 2) / np.pi], axis=-1).reshape(-1, 2)
    index = np.arange((rows + 1) * (columns + 1)).reshape(rows + 1, columns + 1)
    a, b, c, d = index[:-1, :-1], index[:-1, 1:], index[1:, :-1], index[1:, 1:]
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([b, d, c], -1).reshape(-1, 3)])
    return Piece("skybox", 0, vertices + centre, faces, (1.0, 1.0, 1.0, 1.0), uv=uv,
                 image=Image.fromarray(skybox_panorama(texture["builtin"])), backdrop=True, unlit=True)


def _rod(start: np.ndarray, end: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray] | None:
    """A cylinder from ``start`` to ``end`` as (vertices, faces), or None when they coincide."""
    import trimesh

    if np.linalg.norm(end - start) < radius:
        return None
    mesh = trimesh.creation.cylinder(radius=radius, segment=np.array([start, end]), sections=ROUND_SEGMENTS)
    return np.asarray(mesh.vertices), np.asarray(mesh.faces, dtype=np.int64)


def stick_pieces(model) -> list[Piece]:
    """A model without visuals (a DH table, a URDF without <visual>) as a stick figure: a rod from
    each body's origin to its children's joints and to its frames, and a ball at each joint, fixed
    in the bodies as they are at the neutral configuration (a prismatic joint's rod keeps its
    neutral length)."""
    import trimesh

    q = np.asarray(model.neutral(), dtype=float)
    poses = np.asarray(model.body_poses(q))
    frame_origins = np.array([np.asarray(model.frame_pose(q, name))[:3, 3] for name in model.frame_names]).reshape(-1, 3)
    every = np.concatenate([poses[:, :3, 3], frame_origins])
    size = max(float(np.linalg.norm(every.max(axis=0) - every.min(axis=0))), 0.1)
    rod_radius, joint_radius = STICK_RADIUS_FRACTION * size, JOINT_RADIUS_FRACTION * size
    # ends of rods fixed in each body: its children's origins and its frames' origins, world = 0
    ends = [(parent + 1, poses[body + 1, :3, 3]) for body, parent in enumerate(model.body_parents)]
    ends += [(body + 1, origin) for body, origin in zip(model.frame_bodies, frame_origins)]
    pieces = []
    for k, (body, end) in enumerate(ends):
        inverse = np.linalg.inv(poses[body])
        rod = _rod(np.zeros(3), inverse[:3, :3] @ end + inverse[:3, 3], rod_radius)
        if rod is not None:
            pieces.append(Piece(f"stick{k}", body, rod[0], rod[1], STICK_RGBA))
    ball = trimesh.creation.icosphere(subdivisions=2, radius=joint_radius)
    for body in range(1, len(poses)):
        pieces.append(Piece(f"joint{body}", body, np.asarray(ball.vertices), np.asarray(ball.faces, dtype=np.int64), JOINT_RGBA))
    return pieces
