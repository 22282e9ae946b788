"""A 3-D viewer in the browser: the robot's meshes and primitives, posed by robodyn's forward
kinematics, with a trajectory player and overlays (body frames, centre of mass, ground grid).

Built on viser, whose web client ships inside its wheel as one HTML file: the live viewer is a
server on this machine (loopback unless told otherwise) that any browser opens, and
:func:`trajectory_html` writes one self-contained file that plays with no server and no network.

- ``Model.view(q)`` / :class:`Viewer`: one configuration, updated with ``viewer.show(q)``.
- ``Trajectory.view()`` / :class:`TrajectoryViewer`: play/pause, time slider, speed, overlays,
  at :data:`PLAYBACK_RATE` frames per second.
- ``Trajectory.to_html(path)`` / ``Model.to_html(path, q)``: the same as one offline file.
"""

from __future__ import annotations

import contextlib
import io
import os
import sys
import threading
import time
import webbrowser
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from robodyn import _arguments
from robodyn.viewer.geometry import MUJOCO_VISIBLE_GROUPS, stick_pieces, visual_pieces
from robodyn.viewer.scene import WEIGHT_ARROW_FRACTION, RobotScene, contact_arrows

__all__ = ["PLAYBACK_RATE", "TrajectoryViewer", "Viewer", "check_html_path", "model_html", "trajectory_html"]

#: Frames per second of the trajectory player and of the HTML export.
PLAYBACK_RATE = 60
#: Playback speeds offered by the player.
SPEEDS = ("0.1x", "0.25x", "0.5x", "1x", "2x", "4x")
#: How many of a trajectory's samples the first view frames (spread over it).
EXTENT_SAMPLES = 50
#: The address the viewer listens on unless told otherwise: this machine only.
LOOPBACK = "127.0.0.1"
#: viser's own port; the next free one is taken when it is busy.
DEFAULT_PORT = 8080


def _server(host: str, port: int):
    """A viser server without its banner."""
    try:
        import viser
    except ImportError as error:  # pragma: no cover - viser is a dependency
        raise ImportError("the viewer needs viser, a dependency of robodyn: pip install viser") from error
    with contextlib.redirect_stdout(io.StringIO()):
        return viser.ViserServer(host=host, port=port, verbose=False)


def _stop(server) -> None:
    """Stops a viser server without its farewell line."""
    with contextlib.redirect_stdout(io.StringIO()):
        server.stop()


def _pieces(model, groups: tuple[int, ...] | None):
    """What is drawn: the model's visuals, or its stick figure when it has none."""
    if groups is not None:
        try:
            groups = tuple(_arguments.count("groups", group, 0) for group in groups)
        except TypeError:
            raise _arguments.bad("groups", "None or a tuple of geom group numbers", repr(groups)) from None
    return visual_pieces(model, groups) if model.visuals else stick_pieces(model)


def _configuration(model, q, argument: str = "q") -> np.ndarray:
    """``q`` (default: the neutral configuration) as a checked configuration."""
    _arguments.robot_model("model", model)
    if q is None:
        return np.asarray(model.neutral(), dtype=float)
    q = _arguments.numbers(argument, q)
    if q.shape != (model.nq,):
        raise ValueError(f"argument '{argument}': expected one configuration of shape ({model.nq},), got shape {q.shape}")
    return q


def _options(frames: Any, com: Any, ground: Any, camera: Any) -> dict[str, Any]:
    """The overlays and the first view's camera, checked, as the scene takes them."""
    if camera is not None:
        try:
            position, look_at = camera
        except (TypeError, ValueError):
            raise _arguments.bad("camera", "None or (position, point looked at)", repr(camera)) from None
        camera = (_arguments.array("camera", position, (3,)), _arguments.array("camera", look_at, (3,)))
    return dict(frames=_arguments.flag("frames", frames), com_marker=_arguments.flag("com", com),
                ground=_arguments.flag("ground", ground), camera=camera)


def _browser_available() -> bool:
    """Whether a browser can likely be opened here (a desktop session)."""
    return sys.platform in ("darwin", "win32") or bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def check_html_path(path: str | os.PathLike[str], argument: str = "path") -> Path:
    """``path`` as a writable ``.html`` file path, or a ValueError naming the argument."""
    target = Path(_arguments.path(argument, path, "a file path ending in .html"))
    if target.suffix.lower() not in (".html", ".htm"):
        raise ValueError(f"argument '{argument}': expected a file name ending in .html, got '{target}'")
    return _arguments.writable_folder(argument, target)


class Viewer:
    """The robot in a browser page, served from this machine at :attr:`url`.

    ``q``: the configuration shown first (default: neutral). ``frames``, ``com`` and ``ground``
    show the body frames, the centre of mass and a ground grid. ``groups``: the MJCF geom groups
    drawn (MuJoCo's default 0, 1, 2; None for all). ``host`` is the loopback address unless you
    want other machines to connect; ``port`` is tried first, then the next free one.
    ``open_browser``: open the page (default: when a desktop session is there). ``camera``:
    (position, point looked at) of the first view, in world coordinates (default: the whole robot,
    planes left out, from the front right and above). MJCF textures and the skybox are drawn (see
    ``robodyn.viewer.textures``).
    Use :meth:`show` to pose the robot, :meth:`close` (or a ``with`` block) to stop the server.
    """

    def __init__(self, model: Any, q: ArrayLike | None = None, *, frames: bool = False, com: bool = False, ground: bool = True,
                 groups: tuple[int, ...] | None = MUJOCO_VISIBLE_GROUPS, host: str = LOOPBACK,
                 port: int = DEFAULT_PORT, open_browser: bool | None = None, camera: tuple[Any, Any] | None = None) -> None:
        q = _configuration(model, q)
        self._serve(model, np.asarray(model.body_poses(q)), np.asarray(model.center_of_mass(q)), None,
                    _options(frames, com, ground, camera), groups, host, port)
        self._open(open_browser)

    def _serve(self, model: Any, poses: np.ndarray, com: np.ndarray, extent_poses: np.ndarray | None,
               options: dict[str, Any], groups: tuple[int, ...] | None, host: str, port: int) -> None:
        """Starts the server with the robot at body poses ``poses`` (the pieces are read first,
        so that a missing mesh starts nothing)."""
        self.model = model
        pieces = _pieces(model, groups)
        self.server = _server(host, port)
        self.scene = RobotScene(self.server, pieces, poses, com, extent_poses=extent_poses, skybox=model.skybox, **options)
        self.url = f"http://{host}:{self.server.get_port()}"

    def _open(self, open_browser: bool | None) -> None:
        """Opens the page in a browser when asked, or by default when a desktop session is there."""
        if open_browser if open_browser is not None else _browser_available():
            webbrowser.open(self.url)

    def show(self, q: ArrayLike) -> None:
        """Poses the robot at configuration ``q`` in every open page."""
        q = _configuration(self.model, q)
        self.scene.show(np.asarray(self.model.body_poses(q)), np.asarray(self.model.center_of_mass(q)))

    def show_contacts(self, q: ArrayLike, v: ArrayLike | None = None, ctrl: ArrayLike | None = None) -> list[dict[str, Any]]:
        """Poses the robot at ``q`` and draws its scene's contacts there: a point at each and an
        arrow along the force pushing its second geom, of the soft model at (q, v) under controls
        ``ctrl`` (``m.contact_forward_dynamics``; v and ctrl default to zeros), the model's weight
        m g :data:`~robodyn.viewer.scene.WEIGHT_ARROW_FRACTION` of the robot's size long. Returns
        the contacts drawn (as ``contact_forward_dynamics`` lists them)."""
        q = _configuration(self.model, q)
        v = np.zeros(self.model.nv) if v is None else v
        contacts = self.model.contact_forward_dynamics(q, v, ctrl=ctrl)["contacts"]
        self.show(q)
        self.scene.show_contacts(*contact_arrows(contacts, _arrow_scale(self.model, self.scene.size, [contacts])))
        return contacts

    def hide_contacts(self) -> None:
        """Draws no contacts."""
        self.scene.show_contacts(np.zeros((0, 3)), np.zeros((0, 2, 3)))

    def close(self) -> None:
        """Stops the server; open pages stop updating."""
        _stop(self.server)

    def __enter__(self) -> Viewer:
        return self

    def __exit__(self, *exception: Any) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<robodyn Viewer of '{self.model.name}' at {self.url}>"


def _samples(trajectory) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times, body poses (T, nbodies, 4, 4) and centres of mass (T, 3) of a trajectory."""
    q = np.asarray(_arguments.trajectory("trajectory", trajectory).q, dtype=float)
    model = trajectory.model
    return np.asarray(trajectory.t, dtype=float), np.asarray(model.body_poses(q)).reshape(len(q), -1, 4, 4), \
        np.asarray(model.center_of_mass(q)).reshape(len(q), 3)


def _contact_samples(trajectory, size: float) -> list[tuple[np.ndarray, np.ndarray]] | None:
    """Each sample's contact points and force arrows (:func:`robodyn.viewer.scene.contact_arrows`),
    the model's weight m g drawn :data:`WEIGHT_ARROW_FRACTION` of the robot's size long (the
    largest force, without gravity); None when the run records no contacts (integrators other
    than ``"mujoco"``)."""
    if trajectory.integrator != "mujoco":
        return None
    scale = _arrow_scale(trajectory.model, size, trajectory.contacts)
    return [contact_arrows(sample, scale) for sample in trajectory.contacts]


def _arrow_scale(model: Any, size: float, samples: list[list[dict[str, Any]]]) -> float:
    """Metres per newton of the force arrows: the model's weight m g drawn
    :data:`WEIGHT_ARROW_FRACTION` of the robot's size long (the largest force of the samples'
    contacts, without gravity)."""
    weight = float(model.total_mass * np.linalg.norm(model.gravity))
    if weight == 0.0:
        largest = [np.linalg.norm(np.asarray(c["force"])[:3]) for sample in samples for c in sample]
        weight = max(largest, default=1.0) or 1.0
    return WEIGHT_ARROW_FRACTION * size / weight


def _spread(poses: np.ndarray) -> np.ndarray:
    """About :data:`EXTENT_SAMPLES` of a trajectory's poses, spread over it: what the first view
    frames."""
    return poses[::max(1, len(poses) // EXTENT_SAMPLES)]


def _sample_at(times: np.ndarray, t: float) -> int:
    """The last sample at or before time ``t``."""
    return int(np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 1))


class TrajectoryViewer(Viewer):
    """A trajectory played in the browser at :data:`PLAYBACK_RATE` frames per second: play/pause,
    a time slider, the playback speed and the overlays in the page's panel. Arguments as
    :class:`Viewer`; ``speed`` is the initial playback speed (one of :data:`SPEEDS`); ``contacts``
    draws a scene run's contact points and force arrows (``integrator="mujoco"``: each arrow the
    force on the contact's second geom, the model's weight half the robot's size long)."""

    def __init__(self, trajectory: Any, *, speed: str = "1x", frames: bool = False, com: bool = False, ground: bool = True,
                 groups: tuple[int, ...] | None = MUJOCO_VISIBLE_GROUPS, host: str = LOOPBACK,
                 port: int = DEFAULT_PORT, open_browser: bool | None = None, camera: tuple[Any, Any] | None = None,
                 contacts: bool = True) -> None:
        if speed not in SPEEDS:
            raise ValueError(f"argument 'speed': expected one of {', '.join(SPEEDS)}, got {speed!r}")
        self.times, self.poses, self.coms = _samples(trajectory)
        contacts = _arguments.flag("contacts", contacts)
        self._serve(trajectory.model, self.poses[0], self.coms[0], _spread(self.poses),
                    _options(frames, com, ground, camera), groups, host, port)
        self.contacts = _contact_samples(trajectory, self.scene.size)
        gui = self.server.gui
        duration = float(self.times[-1] - self.times[0])
        self.playing = gui.add_checkbox("Play", True)
        self.time = gui.add_slider("Time (s)", min=float(self.times[0]), max=float(self.times[-1]),
                                   step=max(duration / 1000, 1e-6), initial_value=float(self.times[0]))
        self.speed = gui.add_dropdown("Speed", SPEEDS, initial_value=speed)
        frames_box = gui.add_checkbox("Body frames", frames)
        com_box = gui.add_checkbox("Centre of mass", com)
        ground_box = gui.add_checkbox("Ground", ground)
        frames_box.on_update(lambda _: self.scene.overlays(frames=frames_box.value))
        com_box.on_update(lambda _: self.scene.overlays(com_marker=com_box.value))
        ground_box.on_update(lambda _: self.scene.overlays(ground=ground_box.value))
        self.contacts_box = gui.add_checkbox("Contacts", contacts, disabled=self.contacts is None)
        self.contacts_box.on_update(lambda _: self._draw(self.time.value))
        # the slider draws: moved in the page, or by the player below (viser calls back on both)
        self.time.on_update(lambda _: self._draw(self.time.value))
        self._stop = threading.Event()
        # one tick of the player, or a seek, at a time: a seek is never overwritten by a tick
        self._tick = threading.Lock()
        self._player = threading.Thread(target=self._play, name="robodyn-player", daemon=True)
        self._player.start()
        self._open(open_browser)

    def _draw(self, t: float) -> None:
        k = _sample_at(self.times, t)
        self.scene.show(self.poses[k], self.coms[k])
        if self.contacts is not None:
            self.scene.show_contacts(*self.contacts[k], visible=self.contacts_box.value)

    def _play(self) -> None:
        """Advances the time slider at the playback rate while playing, looping at the end."""
        period = 1.0 / PLAYBACK_RATE
        start, end = float(self.times[0]), float(self.times[-1])
        next_tick = time.perf_counter()
        while not self._stop.is_set():
            next_tick += period
            with self._tick:
                if self.playing.value and end > start:
                    t = self.time.value + period * float(self.speed.value.rstrip("x"))
                    self.time.value = start + (t - start) % (end - start) if t > end else t
            self._stop.wait(max(0.0, next_tick - time.perf_counter()))

    def seek(self, t: float) -> None:
        """Pauses the playback and shows the robot at time ``t`` (the sample at or before it)."""
        with self._tick:
            self.playing.value = False
            self.time.value = float(t)

    def close(self) -> None:
        """Stops the player and the server."""
        self._stop.set()
        self._player.join()
        super().close()


def _write_html(server, serializer_steps, path: Path) -> Path:
    """Runs ``serializer_steps(serializer)`` on a recording of ``server``'s scene and writes the
    self-contained page it makes."""
    try:
        serializer = server.get_scene_serializer()
        serializer_steps(serializer)
        path.write_text(serializer.as_html(), encoding="utf-8")
    finally:
        _stop(server)
    return path


def model_html(model, path: str | os.PathLike[str], q=None, *, frames: bool = False, com: bool = False,
               ground: bool = True, groups: tuple[int, ...] | None = MUJOCO_VISIBLE_GROUPS,
               camera: tuple[Any, Any] | None = None) -> Path:
    """Writes one self-contained HTML file showing ``model`` at ``q`` (default: neutral), which
    opens offline in any browser (no server, no network). Returns the path."""
    target = check_html_path(path)
    q = _configuration(model, q)
    options = _options(frames, com, ground, camera)
    pieces = _pieces(model, groups)
    server = _server(LOOPBACK, 0)
    RobotScene(server, pieces, np.asarray(model.body_poses(q)), np.asarray(model.center_of_mass(q)),
               skybox=model.skybox, **options)
    return _write_html(server, lambda serializer: None, target)


def trajectory_html(trajectory, path: str | os.PathLike[str], *, frames: bool = False, com: bool = False,
                    ground: bool = True, groups: tuple[int, ...] | None = MUJOCO_VISIBLE_GROUPS,
                    camera: tuple[Any, Any] | None = None, contacts: bool = True) -> Path:
    """Writes one self-contained HTML file that plays ``trajectory`` at :data:`PLAYBACK_RATE`
    frames per second (play/pause, time slider and speed in the page), offline in any browser;
    with a scene run's contact points and force arrows unless ``contacts`` is False (see
    :class:`TrajectoryViewer`). Returns the path."""
    target = check_html_path(path)
    contacts = _arguments.flag("contacts", contacts)
    times, poses, coms = _samples(trajectory)
    options = _options(frames, com, ground, camera)
    pieces = _pieces(trajectory.model, groups)
    server = _server(LOOPBACK, 0)
    scene = RobotScene(server, pieces, poses[0], coms[0], extent_poses=_spread(poses), skybox=trajectory.model.skybox,
                       **options)
    frame_times = np.arange(times[0], times[-1] + 0.5 / PLAYBACK_RATE, 1.0 / PLAYBACK_RATE)
    drawn = _contact_samples(trajectory, scene.size) if contacts else None

    def record(serializer) -> None:
        for k, t in enumerate(frame_times):
            sample = _sample_at(times, t)
            scene.show(poses[sample], coms[sample])
            if drawn is not None:
                scene.show_contacts(*drawn[sample])
            if k + 1 < len(frame_times):
                serializer.insert_sleep(1.0 / PLAYBACK_RATE)

    return _write_html(server, record, target)
