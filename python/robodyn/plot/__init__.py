"""Figures of a simulation: time series and a 3-D stick-figure animation (matplotlib).

Both work headless: figures are drawn on matplotlib's Agg canvas unless ``show=True`` asks for a
window. matplotlib is one of robodyn's dependencies.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Callable

import numpy as np

from robodyn import _arguments

__all__ = ["animate_trajectory", "check_animation_path", "check_figure_path", "plot_contact_forces", "plot_trajectory",
           "stick_figure_points"]

#: At most this many legend entries per panel; beyond it, the panel says how many it left out.
MAX_LEGEND_ENTRIES = 12
#: Lines of the animation's ground grid in each direction.
GROUND_GRID_LINES = 11


def _matplotlib() -> None:
    """Fails with the install command when matplotlib is missing."""
    try:
        import matplotlib  # noqa: F401
    except ImportError as error:  # pragma: no cover - matplotlib is a dependency
        raise ImportError("plots need matplotlib, a dependency of robodyn: pip install matplotlib") from error


def _units(model) -> tuple[str, str, str]:
    """Units of q, v and τ for the model's joint kinds."""
    kinds = set(model.joint_types)
    if kinds <= {"revolute"}:
        return "rad", "rad/s", "N·m"
    if kinds <= {"prismatic"}:
        return "m", "m/s", "N"
    return "rad, m", "rad/s, m/s", "N·m, N"


def _new_figure(rows: int, show: bool):
    """A figure on the Agg canvas, or a pyplot window when shown."""
    _matplotlib()
    size = (10, 2.6 * rows)
    if show:
        import matplotlib.pyplot as plt

        return plt.figure(figsize=size)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=size)
    FigureCanvasAgg(figure)
    return figure


def plot_trajectory(trajectory, path: str | os.PathLike[str] | None = None, show: bool | None = None):
    """q, v, τ (controller and passive) and the energies over time, one panel each, with units and
    the joints' names in the legends. Saves to ``path`` (PNG, PDF, SVG by its suffix) when given;
    ``show`` opens a window (default: only when no path is given and a display exists). Returns the
    matplotlib figure."""
    model = _arguments.trajectory("trajectory", trajectory).model
    if path is not None:
        check_figure_path(path)
    if show is None:
        show = path is None and bool(os.environ.get("DISPLAY"))
    show = _arguments.flag("show", show)
    figure = _new_figure(4, show)
    axes = figure.subplots(4, 1, sharex=True)
    q_unit, v_unit, tau_unit = _units(model)
    q_names, v_names = trajectory.coordinate_names
    t = trajectory.t
    panels = [
        (axes[0], trajectory.q, q_names, f"q [{q_unit}]"),
        (axes[1], trajectory.v, v_names, f"v [{v_unit}]"),
        (axes[2], trajectory.tau, v_names, f"τ [{tau_unit}]"),
    ]
    for axis, values, names, label in panels:
        for k, name in enumerate(names):
            axis.plot(t, values[:, k], label=name, linewidth=1.2)
        axis.set_ylabel(label)
    # one legend per set of names: colours follow the coordinate from panel to panel
    _legend(axes[0], len(q_names))
    if v_names != q_names:
        _legend(axes[1], len(v_names))
    if np.any(trajectory.tau_passive):
        axes[2].set_prop_cycle(None)
        for k in range(len(v_names)):
            axes[2].plot(t, trajectory.tau_passive[:, k], linestyle="--", linewidth=0.8)
        axes[2].set_title("solid: controller, dashed: passive (springs, damping, friction, limits)", fontsize=8)
    energy = axes[3]
    energy.plot(t, trajectory.energy, label="total", color="black", linewidth=1.5)
    energy.plot(t, trajectory.kinetic_energy, label="kinetic", linewidth=1.0)
    energy.plot(t, trajectory.potential_energy, label="potential (gravity)", linewidth=1.0)
    if np.any(trajectory.spring_energy):
        energy.plot(t, trajectory.spring_energy, label="springs", linewidth=1.0)
    energy.set_ylabel("energy [J]")
    energy.set_xlabel("time [s]")
    energy.legend(fontsize=8, loc="upper right")
    for axis in axes:
        axis.grid(True, alpha=0.3)
    figure.suptitle(
        f"{model.name}: {trajectory.integrator}, {len(t)} samples over {t[-1]:g} s, "
        f"{trajectory.steps} steps"
    )
    figure.tight_layout()
    if path is not None:
        figure.savefig(path, dpi=110)
    if show:
        import matplotlib.pyplot as plt

        plt.show()
    return figure


def plot_contact_forces(trajectory, geoms=None, path: str | os.PathLike[str] | None = None,
                        show: bool | None = None):
    """The contact force on each geom over time (a run with ``integrator="mujoco"``): its part along
    "up" (against gravity; world z without gravity) and the size of the rest, one panel each, with
    their sum over the geoms and, on the first panel, the model's weight m g. ``geoms``: names
    (default: every geom of a moving body that touched something). Saves to ``path`` as
    :func:`plot_trajectory` does; returns the matplotlib figure."""
    trajectory = _arguments.trajectory("trajectory", trajectory)
    model = trajectory.model
    if trajectory.integrator != "mujoco":
        raise _arguments.bad("trajectory", "a run with integrator='mujoco' (the others record no contacts)",
                             f"a run with integrator={trajectory.integrator!r}")
    names = [g["name"] for g in model.geoms]
    if geoms is None:
        touched = {name for sample in trajectory.contacts for contact in sample
                   for name in (contact["geom1"], contact["geom2"])}
        geoms = [g["name"] for g in model.geoms if g["name"] in touched and g["body"] != 0]
    elif isinstance(geoms, str):
        geoms = [geoms]
    elif not isinstance(geoms, (list, tuple)) or not all(isinstance(g, str) for g in geoms):
        raise _arguments.bad("geoms", "None, a geom's name or a list of them", repr(geoms))
    unknown = [g for g in geoms if g not in names]
    if unknown:
        raise _arguments.bad("geoms", f"names of the model's geoms ({len(names)})", repr(unknown))
    if path is not None:
        check_figure_path(path)
    if show is None:
        show = path is None and bool(os.environ.get("DISPLAY"))
    show = _arguments.flag("show", show)
    gravity = np.asarray(model.gravity, dtype=float)
    up = -gravity / np.linalg.norm(gravity) if np.any(gravity) else np.array([0.0, 0.0, 1.0])
    figure = _new_figure(2, show)
    along, across = figure.subplots(2, 1, sharex=True)
    t = trajectory.t
    total = np.zeros((len(t), 3))
    for name in geoms:
        force = trajectory.contact_force(name)
        total += force
        along.plot(t, force @ up, label=name, linewidth=1.2)
        across.plot(t, np.linalg.norm(force - np.outer(force @ up, up), axis=1), label=name, linewidth=1.2)
    if len(geoms) > 1:
        along.plot(t, total @ up, label="sum", color="black", linewidth=1.5)
        across.plot(t, np.linalg.norm(total - np.outer(total @ up, up), axis=1), label="sum", color="black",
                    linewidth=1.5)
    weight = float(model.total_mass * np.linalg.norm(gravity))
    along.axhline(weight, color="grey", linestyle=":", linewidth=1.0, label=f"m g = {weight:.4g} N")
    along.set_ylabel("up [N]")
    across.set_ylabel("across [N]")
    across.set_xlabel("time [s]")
    _legend(along, len(geoms) + 2)
    for axis in (along, across):
        axis.grid(True, alpha=0.3)
    figure.suptitle(f"{model.name}: contact forces on {len(geoms)} geoms (up: against gravity)")
    figure.tight_layout()
    if path is not None:
        figure.savefig(path, dpi=110)
    if show:
        import matplotlib.pyplot as plt

        plt.show()
    return figure


def _legend(axis, entries: int) -> None:
    handles, labels = axis.get_legend_handles_labels()
    if entries > MAX_LEGEND_ENTRIES:
        handles, labels = handles[:MAX_LEGEND_ENTRIES], labels[:MAX_LEGEND_ENTRIES]
        labels[-1] += f" (+{entries - MAX_LEGEND_ENTRIES} more)"
    axis.legend(handles, labels, fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)


def stick_figure_points(model, q) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """The robot as points and segments: the origins of the world, every body and every frame for
    configurations ``q`` (T, nq), shape (T, P, 3), and the index pairs joined by a segment (body to
    parent body, frame to its body)."""
    _arguments.robot_model("model", model)
    q = np.atleast_2d(_arguments.array("q", q, (model.nq,), (None, model.nq)))
    frames = model.frame_names
    # point 0 is the world origin, then one per frame
    points = np.zeros((len(q), len(frames) + 1, 3))
    for k, name in enumerate(frames):
        points[:, k + 1] = np.asarray(model.frame_pose(q, name)).reshape(len(q), 4, 4)[:, :3, 3]
    body_point = {}
    for k, name in enumerate(frames):
        body = model.frame_bodies[k]
        if body >= 0 and model.body_names[body] == name:
            body_point[body] = k + 1
    segments = []
    for body, parent in enumerate(model.body_parents):
        if body in body_point:
            segments.append((body_point.get(parent, 0), body_point[body]))
    for k, body in enumerate(model.frame_bodies):
        if body_point.get(body) != k + 1:
            segments.append((body_point.get(body, 0), k + 1))
    return points, segments


def check_figure_path(path: str | os.PathLike[str], argument: str = "path") -> Path:
    """``path`` if a figure can be saved there (a format matplotlib writes, a writable folder), else a
    ValueError naming ``argument``."""
    _matplotlib()
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    path = Path(_arguments.path(argument, path))
    formats = FigureCanvasAgg.get_supported_filetypes()
    if path.suffix.lower().lstrip(".") not in formats:
        raise ValueError(f"argument '{argument}': expected a file ending in one of "
                         f"{', '.join('.' + f for f in sorted(formats))}, got '{path}'")
    _arguments.writable_folder(argument, path)
    return path


def check_animation_path(path: str | os.PathLike[str], argument: str = "path") -> Path:
    """``path`` if an animation can be written there (.gif, or .mp4 with ffmpeg installed, in a
    writable folder), else a ValueError naming ``argument``."""
    _matplotlib()
    from matplotlib import animation

    path = Path(_arguments.path(argument, path))
    suffix = path.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise ValueError(f"argument '{argument}': expected a .gif or .mp4 file, got '{path}'")
    if suffix == ".mp4" and not animation.writers.is_available("ffmpeg"):
        raise ValueError(f"argument '{argument}': writing {path.name} needs ffmpeg, which is not installed; "
                         "write a .gif instead")
    _arguments.writable_folder(argument, path)
    return path


def animate_trajectory(trajectory, path: str | os.PathLike[str], fps: int = 30, speed: float = 1.0,
                       progress: Callable[[float], Any] | None = None):
    """A 3-D stick figure of the robot moving along the trajectory, written to ``path``: a GIF
    (Pillow), or an MP4 when the suffix is ``.mp4`` and ffmpeg is installed. ``speed`` > 1 plays
    faster than real time. ``progress(fraction)`` is called after each frame is written. Returns
    the path."""
    from matplotlib import animation

    _arguments.trajectory("trajectory", trajectory)
    path = check_animation_path(path)
    fps, speed = _arguments.positive("fps", fps), _arguments.positive("speed", speed)
    _arguments.callback("progress", progress)
    writer = animation.FFMpegWriter(fps=fps) if path.suffix.lower() == ".mp4" else animation.PillowWriter(fps=fps)
    t = trajectory.t
    frame_times = np.arange(0.0, t[-1] + 1e-12, speed / fps)
    samples = np.minimum(np.searchsorted(t, frame_times), len(t) - 1)
    points, segments = stick_figure_points(trajectory.model, trajectory.q[samples])

    figure = _new_figure(2, show=False)
    figure.set_size_inches(6, 6)
    axis = figure.add_subplot(projection="3d")
    low, high = points.reshape(-1, 3).min(axis=0), points.reshape(-1, 3).max(axis=0)
    centre, half = (low + high) / 2, max(float(np.max(high - low)) / 2, 0.1) * 1.1
    for setter, c in zip((axis.set_xlim, axis.set_ylim, axis.set_zlim), centre):
        setter(c - half, c + half)
    # equal axes, and a ground grid at z = 0 (or under the robot, when it is all above or below)
    axis.set_box_aspect((1, 1, 1))
    ground = 0.0 if low[2] - 1e-9 <= 0.0 <= high[2] + 1e-9 else centre[2] - half
    ticks = np.linspace(-half, half, GROUND_GRID_LINES)
    for offset in ticks:
        axis.plot(centre[0] + ticks[[0, -1]], [centre[1] + offset] * 2, [ground] * 2, color="0.85", linewidth=0.6)
        axis.plot([centre[0] + offset] * 2, centre[1] + ticks[[0, -1]], [ground] * 2, color="0.85", linewidth=0.6)
    axis.set_xlabel("x [m]")
    axis.set_ylabel("y [m]")
    axis.set_zlabel("z [m]")
    lines = [axis.plot([], [], [], color="tab:blue", linewidth=3, marker="o", markersize=4)[0] for _ in segments]
    title = axis.set_title("")

    def draw(frame: int):
        for line, (a, b) in zip(lines, segments):
            ends = points[frame, [a, b]]
            line.set_data_3d(ends[:, 0], ends[:, 1], ends[:, 2])
        title.set_text(f"{trajectory.model.name}   t = {t[samples[frame]]:.2f} s")
        return [*lines, title]

    movie = animation.FuncAnimation(figure, draw, frames=len(samples), blit=False)
    report = None if progress is None else (lambda frame, frames: progress((frame + 1) / frames))
    movie.save(str(path), writer=writer, dpi=80, progress_callback=report)
    return path
