"""The robot in a viser scene: one node per body, posed by robodyn's forward kinematics, the
visuals fixed under it, and the overlays (body frames, centre of mass, ground grid)."""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from robodyn.viewer.geometry import Piece, skybox_piece
from robodyn.viewer.textures import unlit_glb

__all__ = ["RobotScene", "camera_for", "contact_arrows", "poses_to_wxyz_position"]

#: Vertical field of view of the initial camera, radians.
CAMERA_FOV = np.radians(50.0)
#: Direction from the robot's centre to the initial camera (normalised when used).
CAMERA_DIRECTION = np.array([1.0, 0.8, 0.6])
#: Margin around the robot's bounding sphere in the initial view.
CAMERA_MARGIN = 1.15
#: Body-frame axes and the centre-of-mass marker, as fractions of the robot's size.
AXES_FRACTION = 0.08
COM_FRACTION = 0.02
COM_RGB = (230, 40, 40)
#: Contact points and their force arrows: colour, point size and arrow thickness as fractions of
#: the robot's size, and the length of an arrow carrying the model's weight m g, as one.
CONTACT_RGB = (20, 170, 60)
CONTACT_POINT_FRACTION = 0.02
CONTACT_ARROW_FRACTION = 0.004
WEIGHT_ARROW_FRACTION = 0.5
#: Side of the ground grid's cells, metres, and how far the grid reaches beyond the robot.
GRID_CELL = 0.1
GRID_REACH = 2.0


def poses_to_wxyz_position(poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Quaternions (w, x, y, z) and positions of 4x4 poses (..., 4, 4)."""
    from viser.transforms import SO3

    return SO3.from_matrix(poses[..., :3, :3]).wxyz, poses[..., :3, 3].copy()


def contact_arrows(contacts: list[dict[str, Any]], metres_per_newton: float) -> tuple[np.ndarray, np.ndarray]:
    """One sample's contacts (as ``Trajectory.contacts`` lists them): their points (K, 3) and force
    arrows (K, 2, 3), from each point along the force pushing its second geom (``frame``ᵀ
    ``force[:3]``, world axes), ``metres_per_newton`` long per newton."""
    points = np.array([contact["position"] for contact in contacts], dtype=float).reshape(-1, 3)
    forces = np.array([np.asarray(contact["frame"]).T @ np.asarray(contact["force"])[:3] for contact in contacts],
                      dtype=float).reshape(-1, 3)
    return points, np.stack([points, points + metres_per_newton * forces], axis=1)


def _bounds(pieces: list[Piece], poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The world bounding box of the pieces and the moving bodies' origins at body poses
    ``poses``, planes left out (a floor is unbounded, or drawn far larger than the robot) unless
    there is nothing else."""
    framed = [piece for piece in pieces if not piece.backdrop] or pieces
    points = [poses[1:, :3, 3] if len(poses) > 1 else poses[:, :3, 3]]
    for piece in framed:
        low, high = piece.vertices.min(axis=0), piece.vertices.max(axis=0)
        corners = np.array([[x, y, z] for x in (low[0], high[0]) for y in (low[1], high[1]) for z in (low[2], high[2])])
        pose = poses[piece.body]
        points.append(corners @ pose[:3, :3].T + pose[:3, 3])
    every = np.concatenate(points)
    return every.min(axis=0), every.max(axis=0)


def camera_for(low: np.ndarray, high: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A camera position and the point it looks at that show the box [low, high] whole."""
    centre = (low + high) / 2
    radius = max(np.linalg.norm(high - low) / 2, 1e-3)
    distance = CAMERA_MARGIN * radius / np.sin(CAMERA_FOV / 2)
    direction = CAMERA_DIRECTION / np.linalg.norm(CAMERA_DIRECTION)
    return centre + distance * direction, centre


def _textured_glb(piece: Piece) -> bytes:
    """A textured piece as a binary glTF: its image times its colour, seen from both sides."""
    import trimesh

    colour = np.round(255 * np.asarray(piece.rgba)).astype(np.uint8)
    material = trimesh.visual.material.PBRMaterial(baseColorTexture=piece.image, baseColorFactor=colour, doubleSided=True,
                                                   metallicFactor=0.0, roughnessFactor=1.0,
                                                   alphaMode="BLEND" if piece.rgba[3] < 1 else None)
    mesh = trimesh.Trimesh(piece.vertices, piece.faces, process=False,
                           visual=trimesh.visual.TextureVisuals(uv=piece.uv, material=material))
    glb = mesh.export(file_type="glb")
    return unlit_glb(glb) if piece.unlit else glb


def _node_name(text: str) -> str:
    """A scene-node name part: letters, digits, '_' and '-' only."""
    return re.sub(r"[^A-Za-z0-9_-]", "_", text)


class RobotScene:
    """The robot's nodes in ``server``'s scene, set up for body poses ``poses`` (nbodies, 4, 4)
    and centre of mass ``com``; ``frames``, ``com_marker`` and ``ground`` switch the overlays.
    The initial camera shows the robot whole (at every pose of ``extent_poses`` when given; planes
    left out), from the front right and above, unless ``camera`` gives its (position, point
    looked at). ``skybox``: the model's skybox texture (``Model.skybox``), drawn around the scene."""

    def __init__(self, server, pieces: list[Piece], poses: np.ndarray, com: np.ndarray, *,
                 frames: bool = False, com_marker: bool = False, ground: bool = True,
                 extent_poses: np.ndarray | None = None, camera: tuple[Any, Any] | None = None,
                 skybox: dict[str, Any] | None = None) -> None:
        self.server = server
        scene = server.scene
        scene.set_up_direction("+z")
        every_pose = poses[None] if extent_poses is None else extent_poses
        lows, highs = zip(*(_bounds(pieces, p) for p in every_pose))
        low, high = np.min(lows, axis=0), np.max(highs, axis=0)
        size = max(float(np.linalg.norm(high - low)), 1e-3)
        position, look_at = camera_for(low, high) if camera is None else (np.asarray(camera[0], float), np.asarray(camera[1], float))
        server.initial_camera.fov = float(CAMERA_FOV)
        server.initial_camera.up = (0.0, 0.0, 1.0)
        server.initial_camera.position = tuple(position)
        server.initial_camera.look_at = tuple(look_at)
        self.bounds = (low, high)
        self.camera = (position, look_at)
        self.size = size

        grid_side = 2 * GRID_REACH + float(max(high[0] - low[0], high[1] - low[1]))
        self.ground = scene.add_grid("/ground", width=grid_side, height=grid_side, cell_size=GRID_CELL,
                                     position=(float((low[0] + high[0]) / 2), float((low[1] + high[1]) / 2), min(0.0, float(low[2]))),
                                     visible=ground)
        self.bodies = []
        for body in range(len(poses)):
            self.bodies.append(scene.add_frame(f"/robot/body{body}", show_axes=frames, axes_length=AXES_FRACTION * size,
                                               axes_radius=AXES_FRACTION * size / 20))
        sky = skybox_piece(skybox, (low + high) / 2, size)
        for index, piece in enumerate(pieces + ([sky] if sky is not None else [])):
            name = f"/robot/body{piece.body}/{index}_{_node_name(piece.name)}"
            if piece.image is not None:
                scene.add_glb(name, _textured_glb(piece), cast_shadow=False, receive_shadow=False)
                continue
            rgb = tuple(int(round(255 * c)) for c in piece.rgba[:3])
            scene.add_mesh_simple(name, vertices=piece.vertices.astype(np.float32), faces=piece.faces.astype(np.uint32),
                                  color=rgb, opacity=piece.rgba[3] if piece.rgba[3] < 1 else None, side="double")
        self.com = scene.add_icosphere("/com", radius=COM_FRACTION * size, color=COM_RGB, visible=com_marker)
        self.contact_nodes: tuple[Any, Any] | None = None
        self.show(poses, com)

    def show(self, poses: np.ndarray, com: np.ndarray) -> None:
        """Moves every body to ``poses`` (nbodies, 4, 4) and the marker to ``com``."""
        wxyz, position = poses_to_wxyz_position(poses)
        with self.server.atomic():
            for node, w, p in zip(self.bodies, wxyz, position):
                node.wxyz = w
                node.position = p
            self.com.position = np.asarray(com, dtype=float)

    def show_contacts(self, points: np.ndarray, arrows: np.ndarray, visible: bool = True) -> None:
        """Draws contact points (K, 3) and force arrows (K, 2, 3) (:func:`contact_arrows`) in
        place of the last ones; none drawn when K is 0 or not ``visible``."""
        scene = self.server.scene
        shown = visible and len(points) > 0
        if not shown:
            # one hidden point stands for none (viser draws no empty cloud)
            points, arrows = np.zeros((1, 3)), np.zeros((1, 2, 3))
        with self.server.atomic():
            self.contact_nodes = (
                scene.add_point_cloud("/contacts/points", points.astype(np.float32), CONTACT_RGB,
                                      point_size=CONTACT_POINT_FRACTION * self.size, point_shape="circle",
                                      visible=shown),
                scene.add_line_segments("/contacts/forces", arrows.astype(np.float32), CONTACT_RGB,
                                        thickness=CONTACT_ARROW_FRACTION * self.size, visible=shown),
            )

    def overlays(self, *, frames: bool | None = None, com_marker: bool | None = None, ground: bool | None = None) -> None:
        """Switches the overlays given."""
        if frames is not None:
            for node in self.bodies:
                node.show_axes = frames
        if com_marker is not None:
            self.com.visible = com_marker
        if ground is not None:
            self.ground.visible = ground
