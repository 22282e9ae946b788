"""Simulation: integrate M(q) q̈ + C(q, q̇) q̇ + g(q) = τ + τ_passive + Σ Jᵀ f_ext in time.

The UR5 dynamics notes end where this begins: "q̈ = −M⁻¹(C + G); simulate: integrate … Euler's method,
Runge–Kutta fixed order 4, odeint (adaptive) … once we obtain q we can do an animation"::

    m = robodyn.load("ur5")
    traj = robodyn.simulate(m, q0, v0, t_end=5.0, dt=1e-3, integrator="rk4",
                            controller=robodyn.PD(kp=50.0, kd=5.0, q_ref=q_ref))
    traj.t, traj.q, traj.v, traj.a, traj.tau, traj.energy
    traj.plot("swing.png"); traj.animate("swing.gif")

The loop runs in Rust (``robodyn._core.simulate``). Integrators: ``"euler"`` (explicit),
``"semi_implicit_euler"`` (symplectic), ``"rk4"`` and ``"rk45"`` (Dormand–Prince, adaptive, with
dense output at every ``dt``). Spherical and free joints are integrated on their Lie group
(Runge–Kutta–Munthe-Kaas), so quaternions stay unit without renormalisation.

Accuracy: fixed-step runs check themselves. Every 50th step (and the first) is compared with two
half steps, which estimates its local error; while nothing puts energy in or takes it out (no
damping, friction, limit penalty, controller torque or wrench), the energy drift is tracked too.
Past ``rtol`` (1e-3 of the state by default) :func:`simulate` warns once per run with an
:class:`AccuracyWarning` naming the time, the error and the largest step that meets the tolerance
(``accuracy="raise"`` raises :class:`AccuracyError` instead, ``"ignore"`` says nothing); the
estimates stay in :class:`Trajectory` (``error_times``, ``error_estimate``, ``energy_drift``,
``accuracy_issue``). RK45 controls its own error and is not checked.

Controllers: the native :class:`PD`, :class:`ComputedTorque`, :class:`GravityCompensation`, a
constant torque (an array of nv), or any Python callable ``controller(t, q, v) -> tau``. A callable is
the slow path: it is called from Rust at every stage of every step (four times per RK4 step) with the
GIL held, costing microseconds each; it must be a function of (t, q, v) only.
"""

from __future__ import annotations

import csv
import os
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Sequence, Union, overload

import numpy as np

if TYPE_CHECKING:
    from robodyn.viewer import TrajectoryViewer
from numpy.typing import ArrayLike

from robodyn import _core
from robodyn._arguments import bad, callback, choice, flag, numbers, real, robot_model
from robodyn._joints import coordinate_names
from robodyn._mimic_motion import simulate_reduced, step_reduced
from robodyn._scene_stepping import keyframe, simulate_scene, step_scene
from robodyn.mimic import MimicModel

__all__ = [
    "AccuracyError",
    "AccuracyWarning",
    "ACCURACY_MODES",
    "ComputedTorque",
    "GravityCompensation",
    "INTEGRATORS",
    "PD",
    "Trajectory",
    "simulate",
    "step",
]

#: The integrator names :func:`simulate` accepts (``"mujoco"``: the scene's own, as ``mj_step``).
INTEGRATORS = ("euler", "semi_implicit_euler", "rk4", "rk45", "mujoco")
#: The default recording interval of the integrators other than ``"mujoco"`` (s).
DEFAULT_DT = 1e-3
#: What :func:`simulate` does at a joint limit: report it, or also push back with a penalty.
LIMIT_MODELS = ("report", "penalty")
#: What :func:`simulate` does with a fixed-step run less accurate than ``rtol``.
ACCURACY_MODES = ("warn", "raise", "ignore")
#: The default ``rtol``: RK45's tolerance per step, and the fixed-step schemes' accuracy check.
RK45_RTOL = 1e-6
ACCURACY_RTOL = 1e-3


class AccuracyWarning(UserWarning):
    """A fixed-step simulation less accurate than its ``rtol``: the message says from when, how
    large the error is and the largest step that meets the tolerance (see :func:`simulate`)."""


class AccuracyError(_core.SimulationError):
    """``simulate(..., accuracy="raise")`` on a fixed-step run less accurate than its ``rtol``
    (a :class:`robodyn.SimulationError`, so a ``ValueError``); the message is the warning's."""


def _reference_spec(q_ref, reference) -> dict[str, Any]:
    """A set-point ``q_ref`` or a sampled ``reference`` (times, q, v), as the core reads them."""
    if reference is not None:
        if q_ref is not None:
            raise ValueError("give either 'q_ref' (a set-point) or 'reference' (a motion), not both")
        if hasattr(reference, "t") and hasattr(reference, "q") and hasattr(reference, "v"):
            times, q, v = reference.t, reference.q, reference.v
        else:
            try:
                times, q, v = reference
            except (TypeError, ValueError):
                raise ValueError(
                    f"argument 'reference': expected (times, q, v) or a Trajectory, got {reference!r}"
                ) from None
        return {"times": numbers("reference", times), "q": numbers("reference", q), "v": numbers("reference", v)}
    if q_ref is None:
        raise ValueError("argument 'q_ref': a PD or computed-torque controller needs q_ref or reference")
    return {"q_ref": numbers("q_ref", q_ref)}


def _gains(model, name: str, value: Any) -> np.ndarray:
    """A gain per velocity coordinate; a scalar applies to all."""
    gains = numbers(name, value)
    if gains.ndim == 0:
        gains = np.full(model.nv, float(gains))
    return gains


@dataclass(frozen=True)
class PD:
    """τ = K_p (q_ref ⊖ q) + K_d (v_ref − v), plus g(q) with ``gravity_compensation=True``.

    ``kp`` and ``kd`` are scalars or one gain per velocity coordinate. The target is a set-point
    ``q_ref`` (v_ref = 0) or a ``reference`` motion: ``(times, q, v)`` knots (shapes (K,), (K, nq),
    (K, nv)) joined by cubic Hermite segments, or a :class:`Trajectory`; it must cover [0, t_end].
    Runs natively.
    """

    kp: Any
    kd: Any
    q_ref: Any = None
    reference: Any = None
    gravity_compensation: bool = False

    def _spec(self, model) -> dict[str, Any]:
        return {"kind": "pd", "kp": _gains(model, "kp", self.kp), "kd": _gains(model, "kd", self.kd),
                "gravity_compensation": bool(self.gravity_compensation), **_reference_spec(self.q_ref, self.reference)}


@dataclass(frozen=True)
class ComputedTorque:
    """τ = M(q) (a_d + K_d (v_d − v) + K_p (q_d ⊖ q)) + C(q, v) v + g(q) − τ_passive(q, v).

    Feedback linearisation with the robot's own model (Spong, Hutchinson & Vidyasagar, §8.3): the
    error obeys ë + K_d ė + K_p e = 0, so the robot tracks the reference exactly when it starts on
    it. The reference is as for :class:`PD`; a_d comes from its Hermite segments. Runs natively.
    """

    kp: Any
    kd: Any
    q_ref: Any = None
    reference: Any = None

    def _spec(self, model) -> dict[str, Any]:
        return {"kind": "computed_torque", "kp": _gains(model, "kp", self.kp), "kd": _gains(model, "kd", self.kd),
                **_reference_spec(self.q_ref, self.reference)}


@dataclass(frozen=True)
class GravityCompensation:
    """τ = g(q): the robot floats where it is put (and drifts with its velocity). Runs natively."""

    def _spec(self, model) -> dict[str, Any]:
        return {"kind": "gravity_compensation"}


def _controller_argument(model, controller):
    if hasattr(controller, "_spec"):
        return controller._spec(model)
    if controller is None or callable(controller):
        return controller
    if isinstance(controller, (list, tuple, np.ndarray)):
        return {"kind": "constant", "tau": numbers("controller", controller)}
    raise ValueError(
        f"argument 'controller': expected None, a constant torque of {model.nv} values, robodyn.PD, "
        f"robodyn.ComputedTorque, robodyn.GravityCompensation or a callable (t, q, v) -> tau, got {controller!r}"
    )


def _wrenches_argument(wrenches: Any) -> Any:
    """None, a callable, or the wrenches as numbers."""
    return wrenches if wrenches is None or callable(wrenches) else numbers("wrenches", wrenches)


@dataclass
class Trajectory:
    """A recorded simulation: ``len(t)`` samples, every ``dt`` from 0 to ``t_end``.

    Arrays: ``t`` (T,), ``q`` (T, nq), ``v``, ``a``, ``tau`` and ``tau_passive`` (T, nv). ``tau`` is
    the controller's torque, ``tau_passive`` the joints' own (springs, damping, friction, limit
    penalty). A scene stepped with ``integrator="mujoco"`` also records ``ctrl`` (T, nu), ``act``
    (T, na: the actuators' activations, MuJoCo's ``act``), ``plastic`` (T, nplastic: the references
    of the springs with a ``springyield``, MuJoCo's ``plastic``),
    ``tau_constraint`` (T, nv: Jᵀ f of its contacts, limits and dry friction) and ``contacts`` (per
    sample, its contacts as :meth:`Model.collide` lists them, each with ``force``: normal, tangents,
    spin and rolls in its frame; :meth:`contact_force` sums them per geom), and its ``tau`` holds the
    actuators' forces too; other runs leave them (T, 0) and empty. Energies (J), per sample: ``kinetic_energy``, ``potential_energy`` (gravity),
    ``spring_energy`` and their sum ``energy``. ``limit_violations`` lists the joints that left their
    position range. ``steps``, ``rejected_steps`` and ``evaluations`` tell the work done.

    Accuracy (fixed-step schemes; empty or None for RK45): ``error_estimate`` holds the local error
    of the steps checked by step doubling, relative to the state's size, at the steps' start times
    ``error_times``; ``energy_drift`` the largest |E − E₀| relative to the largest kinetic energy while
    the system was conservative (None if it never was); ``accuracy_issue``, when a measure exceeded
    ``rtol``, a dict ``{"message", "measure"}`` (``"local_error"`` or ``"energy_drift"``), ``"time"``
    (first exceeded, s), ``"error"`` (largest, relative) and ``"largest_step"`` (s).
    """

    model: Any = field(repr=False)
    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    tau: np.ndarray
    tau_passive: np.ndarray
    integrator: str
    steps: int
    rejected_steps: int
    evaluations: int
    error_times: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)
    error_estimate: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)
    energy_drift: float | None = None
    accuracy_issue: dict[str, Any] | None = None
    ctrl: np.ndarray = field(default_factory=lambda: np.empty((0, 0)), repr=False)
    tau_constraint: np.ndarray = field(default_factory=lambda: np.empty((0, 0)), repr=False)
    act: np.ndarray = field(default_factory=lambda: np.empty((0, 0)), repr=False)
    plastic: np.ndarray = field(default_factory=lambda: np.empty((0, 0)), repr=False)
    contacts: list[list[dict[str, Any]]] = field(default_factory=list, repr=False)
    kinetic_energy: np.ndarray = field(init=False, repr=False)
    potential_energy: np.ndarray = field(init=False, repr=False)
    spring_energy: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        m = self.model
        # integrators other than "mujoco" record no controls and no constraint forces: (T, 0)
        if self.ctrl.size == 0:
            self.ctrl = np.empty((len(self.t), 0))
        if self.tau_constraint.size == 0:
            self.tau_constraint = np.empty((len(self.t), 0))
        if self.act.size == 0:
            self.act = np.empty((len(self.t), 0))
        if self.plastic.size == 0:
            self.plastic = np.empty((len(self.t), 0))
        self.kinetic_energy = np.asarray(m.kinetic_energy(self.q, self.v))
        self.potential_energy = np.asarray(m.potential_energy(self.q))
        self.spring_energy = np.asarray(m.spring_energy(self.q))

    def contact_force(self, geom: str) -> np.ndarray:
        """The contact force on the geom named ``geom`` per sample, (T, 3) in world axes (N): the sum
        over its contacts of their normal and friction forces (``frame``ᵀ ``force[:3]``), as pushing
        the contact's second geom and reversed on its first. Only runs with ``integrator="mujoco"``
        record contacts (the others give zeros)."""
        names = [g["name"] for g in self.model.geoms]
        if geom not in names:
            raise bad("geom", f"the name of one of the model's geoms ({len(names)})", repr(geom))
        total = np.zeros((len(self.t), 3))
        for k, sample in enumerate(self.contacts):
            for contact in sample:
                push = np.asarray(contact["frame"]).T @ np.asarray(contact["force"])[:3]
                total[k] += push * ((contact["geom2"] == geom) - (contact["geom1"] == geom))
        return total

    @property
    def energy(self) -> np.ndarray:
        """Total mechanical energy T + V_gravity + V_springs (J), per sample."""
        return self.kinetic_energy + self.potential_energy + self.spring_energy

    def __len__(self) -> int:
        return len(self.t)

    @property
    def coordinate_names(self) -> tuple[list[str], list[str]]:
        """Labels of the q and v columns: the joint name, with the coordinate for multi-DoF joints."""
        return coordinate_names(self.model)

    @property
    def limit_violations(self) -> list[dict[str, Any]]:
        """Each q coordinate that left [lower, upper]: ``{"joint", "coordinate", "first_time",
        "worst_excess"}`` (excess in rad or m, positive)."""
        m = self.model
        q_names, _ = self.coordinate_names
        excess = np.maximum(self.q - m.upper_position_limit, m.lower_position_limit - self.q)
        violations = []
        for k in np.flatnonzero(np.any(excess > 0, axis=0)):
            first = int(np.argmax(excess[:, k] > 0))
            violations.append({"joint": _joint_of_q(m, k), "coordinate": q_names[k],
                               "first_time": float(self.t[first]), "worst_excess": float(excess[:, k].max())})
        return violations

    def columns(self) -> dict[str, np.ndarray]:
        """Every recorded series as a named column (the CSV's header)."""
        q_names, v_names = self.coordinate_names
        table = {"t": self.t}
        for prefix, values, names in (("q", self.q, q_names), ("v", self.v, v_names), ("a", self.a, v_names),
                                      ("tau", self.tau, v_names), ("tau_passive", self.tau_passive, v_names)):
            for k, name in enumerate(names):
                table[f"{prefix}[{name}]"] = values[:, k]
        table.update(kinetic_energy=self.kinetic_energy, potential_energy=self.potential_energy,
                     spring_energy=self.spring_energy, energy=self.energy)
        return table

    def to_csv(self, path: str | os.PathLike[str]) -> None:
        """One row per sample, one column per series (``columns()``); SI units."""
        table = self.columns()
        with open(path, "w", newline="") as file:
            writer = csv.writer(file)
            writer.writerow(table)
            writer.writerows(np.column_stack(list(table.values())).tolist())

    def to_npz(self, path: str | os.PathLike[str]) -> None:
        """The arrays (t, q, v, a, tau, tau_passive and the energies) and the coordinate names."""
        q_names, v_names = self.coordinate_names
        np.savez(path, t=self.t, q=self.q, v=self.v, a=self.a, tau=self.tau, tau_passive=self.tau_passive,
                 kinetic_energy=self.kinetic_energy, potential_energy=self.potential_energy,
                 spring_energy=self.spring_energy, energy=self.energy,
                 q_names=np.array(q_names), v_names=np.array(v_names))

    def plot(self, path: str | os.PathLike[str] | None = None, show: bool | None = None):
        """q, v, τ and energy over time in one figure (see :func:`robodyn.plot.plot_trajectory`)."""
        from robodyn.plot import plot_trajectory

        return plot_trajectory(self, path, show)

    def plot_contact_forces(self, geoms: Any = None, path: str | os.PathLike[str] | None = None,
                            show: bool | None = None):
        """The contact force on each geom over time, up and across (see
        :func:`robodyn.plot.plot_contact_forces`)."""
        from robodyn.plot import plot_contact_forces

        return plot_contact_forces(self, geoms, path, show)

    def animate(self, path: str | os.PathLike[str], fps: int = 30, speed: float = 1.0,
                progress: Callable[[float], Any] | None = None):
        """A 3-D stick figure of the robot, as a GIF or (with ffmpeg) MP4 (see
        :func:`robodyn.plot.animate_trajectory`)."""
        from robodyn.plot import animate_trajectory

        return animate_trajectory(self, path, fps=fps, speed=speed, progress=progress)

    def view(self, **options: Any) -> TrajectoryViewer:
        """Plays the trajectory in a browser page served from this machine: play/pause, time
        slider, speed, and the overlays (body frames, centre of mass, ground, and a scene run's
        contact points and force arrows). Returns the :class:`robodyn.viewer.TrajectoryViewer`
        (``close()`` stops it). Options: ``speed``, ``frames``, ``com``, ``ground``, ``contacts``,
        ``groups``, ``host``, ``port``, ``open_browser``."""
        from robodyn.viewer import TrajectoryViewer

        return TrajectoryViewer(self, **options)

    def to_html(self, path: str | os.PathLike[str], **options: Any) -> Path:
        """Writes one self-contained HTML file that plays the trajectory offline, in any browser,
        at 60 frames per second. Options: ``frames``, ``com``, ``ground``, ``contacts``, ``groups``."""
        from robodyn.viewer import trajectory_html

        return trajectory_html(self, path, **options)


def _joint_of_q(model, k: int) -> str:
    """The joint holding configuration coordinate ``k``."""
    starts = np.asarray(model.joint_idx_q)
    return model.joint_names[int(np.searchsorted(starts, k, side="right")) - 1]


#: One configuration, (nq,), and a batch of them, (N, nq), as the type checker sees them.
Configuration = Union["np.ndarray[tuple[int], np.dtype[Any]]", Sequence[float]]
Configurations = Union["np.ndarray[tuple[int, int], np.dtype[Any]]", Sequence[Sequence[float]]]


@overload
def simulate(model: _core.Model | MimicModel, q0: Configuration | str, v0: ArrayLike | None = None, t_end: float = 1.0,
             dt: float | None = None, integrator: str = "rk4", controller: Any = None, wrenches: Any = None, *,
             rtol: float | None = None, atol: float = 1e-9, max_step: float | None = None,
             friction_velocity: float = 1e-2, limits: str = "report", limit_stiffness: float = 1e4,
             limit_damping: float = 1e2, progress: Callable[[float], Any] | None = None,
             accuracy: str = "warn", constraints: Any | None = "model", baumgarte: tuple[float, float] | None = None,
             damping: float = 0.0, ctrl: Any = None, act0: ArrayLike | None = None,
             plastic0: ArrayLike | None = None) -> Trajectory: ...


@overload
def simulate(model: _core.Model | MimicModel, q0: Configurations, v0: ArrayLike | None = None, t_end: float = 1.0,
             dt: float | None = None, integrator: str = "rk4", controller: Any = None, wrenches: Any = None, *,
             rtol: float | None = None, atol: float = 1e-9, max_step: float | None = None,
             friction_velocity: float = 1e-2, limits: str = "report", limit_stiffness: float = 1e4,
             limit_damping: float = 1e2, progress: Callable[[float], Any] | None = None,
             accuracy: str = "warn", constraints: Any | None = "model", baumgarte: tuple[float, float] | None = None,
             damping: float = 0.0, ctrl: Any = None, act0: ArrayLike | None = None,
             plastic0: ArrayLike | None = None) -> list[Trajectory]: ...


@overload
def simulate(model: _core.Model | MimicModel, q0: ArrayLike, v0: ArrayLike | None = None, t_end: float = 1.0,
             dt: float | None = None, integrator: str = "rk4", controller: Any = None, wrenches: Any = None, *,
             rtol: float | None = None, atol: float = 1e-9, max_step: float | None = None,
             friction_velocity: float = 1e-2, limits: str = "report", limit_stiffness: float = 1e4,
             limit_damping: float = 1e2, progress: Callable[[float], Any] | None = None,
             accuracy: str = "warn", constraints: Any | None = "model", baumgarte: tuple[float, float] | None = None,
             damping: float = 0.0, ctrl: Any = None, act0: ArrayLike | None = None,
             plastic0: ArrayLike | None = None) -> Trajectory | list[Trajectory]: ...


def simulate(
    model: _core.Model | MimicModel,
    q0: ArrayLike,
    v0: ArrayLike | None = None,
    t_end: float = 1.0,
    dt: float | None = None,
    integrator: str = "rk4",
    controller: Any = None,
    wrenches: Any = None,
    *,
    rtol: float | None = None,
    atol: float = 1e-9,
    max_step: float | None = None,
    friction_velocity: float = 1e-2,
    limits: str = "report",
    limit_stiffness: float = 1e4,
    limit_damping: float = 1e2,
    progress: Callable[[float], Any] | None = None,
    accuracy: str = "warn",
    constraints: Any | None = "model",
    baumgarte: tuple[float, float] | None = None,
    damping: float = 0.0,
    ctrl: Any = None,
    act0: ArrayLike | None = None,
    plastic0: ArrayLike | None = None,
) -> Trajectory | list[Trajectory]:
    """Simulate ``model`` from (``q0``, ``v0``) at t = 0 to ``t_end``, recording every ``dt``.

    For a type checker, a configuration typed as one vector (``m.neutral()``, a list of numbers)
    gives a :class:`Trajectory` and a batch (``m.random_configuration(n)``, a list of lists) a list;
    an array of unknown shape gives either.

    ``q0`` of shape (nq,) gives one :class:`Trajectory`; a batch (N, nq) with ``v0`` (N, nv) gives N
    of them, simulated in parallel on all cores when everything is native (no Python callable).
    ``v0`` defaults to zeros.

    ``integrator="mujoco"`` steps a scene as MuJoCo's ``mj_step`` does (the file's ``<option>``
    integrator and time step, its soft contacts, limits, dry friction and actuators; see the guide's
    "Scenes stepped as MuJoCo"): ``q0`` may name a keyframe (its q, v, ctrl, act and plastic; the run
    starts at its time, from which ``t_end`` counts), ``ctrl`` gives the
    actuators' controls (nu values, one row per rollout, or a callable ``(t, q, v) -> ctrl``),
    ``act0`` the activations of the actuators with activation dynamics at the start (na values, one
    row per rollout; default zeros, or the keyframe's), ``plastic0`` the references of the springs
    with a ``springyield`` (``m.nplastic`` values, one row per rollout; default ``m.plastic0``, or the
    keyframe's),
    ``controller`` forces on the joints, ``dt`` (default: the time step) a whole number of steps
    between samples; the accuracy, passive-force and limit options below are the other integrators'.

    ``integrator``: ``"euler"``, ``"semi_implicit_euler"`` or ``"rk4"`` step by ``dt`` (default 1 ms); ``"rk45"``
    chooses its steps to keep each one's error below ``atol + rtol·|x|`` (per component; ``max_step``
    bounds them; ``rtol`` defaults to 1e-6 there) and records every ``dt`` by dense output.

    Accuracy of the fixed-step schemes: the first step and every 50th are compared with two half
    steps (step doubling), which estimates their local error relative to the state's size (max(1,
    largest speed)); while the system is conservative (no damping, friction, limit penalty,
    controller torque or wrench) the energy drift, relative to the largest kinetic energy, is
    tracked too. When either exceeds ``rtol`` (default 1e-3), ``accuracy="warn"`` (the default)
    issues one :class:`AccuracyWarning` per run with the time, the error and the largest step that
    meets the tolerance; ``"raise"`` raises :class:`AccuracyError` (after the run) instead and
    ``"ignore"`` says nothing. The estimates are kept in the :class:`Trajectory`. RK45 keeps its own
    error below ``rtol`` and is not checked.

    ``controller``: ``None`` (no torque), a constant torque (nv values), :class:`PD`,
    :class:`ComputedTorque`, :class:`GravityCompensation`, or a callable ``(t, q, v) -> tau`` (slow
    path, see the module docstring). ``wrenches``: external wrenches on the moving bodies, an array
    (nbodies, 6) or a callable ``(t, q, v) -> (nbodies, 6)``; row k acts on ``body_names[k]``,
    ``[force; moment]`` in that body's frame (as ``f_ext`` in :meth:`Model.inverse_dynamics`).

    Passive forces come from the model: ``stiffness``/``spring_reference``, ``damping``, ``friction``
    (Coulomb, smoothed as F_c·tanh(v / ``friction_velocity``)), ``armature``. Joint limits are
    reported in ``Trajectory.limit_violations``; ``limits="penalty"`` also pushes back past a limit
    with τ = −``limit_stiffness``·δ − ``limit_damping``·v (only ever outwards of the violation).
    ``progress(fraction)`` is called about a hundred times per run (this runs the loop with the GIL
    held; Ctrl-C stops it).

    ``constraints``: ``"model"`` (the default) holds the model's own, :attr:`Model.constraints`
    (an MJCF file's ``<equality>``; none for a model without); ``None`` or ``[]`` holds none; or one
    or a list of :class:`robodyn.PointAnchor`, :class:`robodyn.FrameAnchor`,
    :class:`robodyn.JointCoupling`, :class:`robodyn.Distance` held through the run (closed loops,
    anchors), with ``baumgarte`` and ``damping`` as in :meth:`Model.constrained_forward_dynamics`;
    the accelerations are :meth:`Model.constrained_forward_dynamics`'s. Loops whose rows depend on
    each other (a planar linkage closed by 3-D connects, as Cassie's legs) need ``damping > 0``:
    without it the run stops at once with an error naming the row. Rollouts with constraints run
    in parallel, each on its own (not in SIMD lanes).

    Raises ``ValueError`` naming the argument for bad input, and when the simulation diverges (with
    the time it happened; :class:`robodyn.SimulationError`); an exception raised by a callback
    propagates unchanged.
    """
    if integrator == "mujoco":
        return simulate_scene(model, q0, v0, t_end, dt, controller, wrenches, progress, constraints, ctrl, act0,
                              plastic0)
    if ctrl is not None:
        raise bad("ctrl", "None: controls drive a scene's actuators with integrator='mujoco'", "controls")
    if act0 is not None:
        raise bad("act0", "None: activations are a scene's state with integrator='mujoco'", "activations")
    if plastic0 is not None:
        raise bad("plastic0", "None: plastic springs are a scene's state with integrator='mujoco'", "references")
    if isinstance(model, MimicModel):
        return simulate_reduced(dict(locals()))
    robot_model("model", model)
    dt = DEFAULT_DT if dt is None else dt
    if isinstance(q0, str):
        key = keyframe(model, q0)
        q0, v0 = key.q, key.v if v0 is None else v0
    q0 = numbers("q0", q0)
    v0 = np.zeros(q0.shape[:-1] + (model.nv,)) if v0 is None else numbers("v0", v0)
    choice("integrator", integrator, INTEGRATORS)
    choice("limits", limits, LIMIT_MODELS)
    choice("accuracy", accuracy, ACCURACY_MODES)
    _check_gains(baumgarte)
    # one rtol: RK45's step control, or the fixed-step schemes' accuracy check
    adaptive = integrator == "rk45"
    rk45_rtol = real("rtol", rtol) if rtol is not None and adaptive else RK45_RTOL
    accuracy_rtol = real("rtol", rtol) if rtol is not None and not adaptive else ACCURACY_RTOL
    result = _core.simulate(
        model, q0, v0, real("t_end", t_end), real("dt", dt), integrator, rk45_rtol, real("atol", atol),
        float("inf") if max_step is None else real("max_step", max_step), _controller_argument(model, controller),
        _wrenches_argument(wrenches), real("friction_velocity", friction_velocity), limits,
        real("limit_stiffness", limit_stiffness), real("limit_damping", limit_damping), callback("progress", progress),
        accuracy_rtol, constraints=_held(model, constraints), baumgarte=baumgarte, damping=damping,
    )
    series = ("q", "v", "a", "tau", "tau_passive")
    statistics = ("steps", "rejected_steps", "evaluations")
    records = ("error_times", "error_estimate", "energy_drift", "accuracy_issue")
    batch = result["q"].ndim == 3
    runs = [
        Trajectory(model, result["t"], integrator=integrator,
                   **{key: result[key][k] if batch else result[key] for key in series},
                   **{key: result[key][k] for key in statistics + records})
        for k in range(len(result["steps"]))
    ]
    _report_accuracy(runs, accuracy, batch)
    return runs if batch else runs[0]


def _report_accuracy(runs: list[Trajectory], accuracy: str, batch: bool) -> None:
    """One :class:`AccuracyWarning` per run that missed its tolerance, or :class:`AccuracyError`
    for the first of them (``accuracy="raise"``)."""
    if accuracy == "ignore":
        return
    for k, run in enumerate(runs):
        if run.accuracy_issue is None:
            continue
        message = f"{run.integrator}: {run.accuracy_issue['message']}"
        if batch:
            message = f"rollout {k}: {message}"
        if accuracy == "raise":
            raise AccuracyError(message)
        warnings.warn(message, AccuracyWarning, stacklevel=3)


def _held(model: _core.Model, constraints: Any) -> Any:
    """The constraints a run holds: the model's own for ``"model"``, else those given."""
    if isinstance(constraints, str):
        choice("constraints", constraints, ("model",), " or constraint objects")
        return model.constraints or None
    return constraints


def _check_gains(baumgarte: Any) -> None:
    """Baumgarte's gains are None or a pair (kp, kd)."""
    if baumgarte is not None and numbers("baumgarte", baumgarte).shape != (2,):
        raise bad("baumgarte", "None or a pair (kp, kd) of gains (1/s², 1/s)", repr(baumgarte))


def step(
    model: _core.Model | MimicModel,
    q: ArrayLike,
    v: ArrayLike,
    tau: ArrayLike,
    dt: float,
    integrator: str = "rk4",
    derivatives: bool = False,
    *,
    friction_velocity: float = 1e-2,
    limits: str = "report",
    limit_stiffness: float = 1e4,
    limit_damping: float = 1e2,
    constraints: Any | None = "model",
    baumgarte: tuple[float, float] | None = None,
    damping: float = 0.0,
    ctrl: Any = None,
    act: ArrayLike | None = None,
    plastic: ArrayLike | None = None,
) -> Any:
    """One step of size ``dt`` from (``q``, ``v``) with the torque ``tau`` held over it (with
    ``integrator="mujoco"``: one ``mj_step`` of the scene, ``dt`` its time step, ``ctrl`` the controls): the step
    :func:`simulate` takes (``integrator`` ``"euler"``, ``"semi_implicit_euler"`` or ``"rk4"``, on the
    joints' Lie groups, with the model's passive forces and the same ``friction_velocity`` and
    ``limits`` options).

    Returns ``x1`` = [q1, v1] (nq + nv values; with ``integrator="mujoco"`` [q1, v1, act1, plastic1],
    ``act`` the activations of the actuators with activation dynamics at the start, na values,
    default zeros, and ``plastic`` the references of the springs with a ``springyield``,
    ``m.nplastic`` values, default ``m.plastic0``), and with ``derivatives=True`` the tuple
    ``(x1, A, B)``: A = ∂x1/∂x0 (2nv × 2nv) and B = ∂x1/∂tau (2nv × nv), the exact Jacobians of this
    discrete step (chain rule through its stages, from the analytical derivatives of forward
    dynamics and of the passive forces). Rows and columns are [q; v] with q in the tangent space:
    a change δ of q means ``m.integrate(q, δ)``, and x1's change is read as
    ``m.difference(q1, q1')`` (as for every derivative in robodyn). Batched: (N, nq), (N, nv),
    (N, nv) give (N, ...) results computed on all cores.

    ``constraints``, ``baumgarte`` and ``damping`` as in :func:`simulate`: the step integrates
    :meth:`Model.constrained_forward_dynamics`, and its Jacobians come from
    :meth:`Model.constrained_forward_dynamics_derivatives` (those of the exact constraint
    equations, so ``derivatives=True`` takes ``baumgarte=None``).
    """
    if integrator == "mujoco":
        return step_scene(model, q, v, tau, dt, derivatives, constraints, ctrl, act, plastic)
    if ctrl is not None:
        raise bad("ctrl", "None: controls drive a scene's actuators with integrator='mujoco'", "controls")
    if act is not None:
        raise bad("act", "None: activations are a scene's state with integrator='mujoco'", "activations")
    if plastic is not None:
        raise bad("plastic", "None: plastic springs are a scene's state with integrator='mujoco'", "references")
    if isinstance(model, MimicModel):
        return step_reduced(dict(locals()))
    robot_model("model", model)
    choice("integrator", integrator, INTEGRATORS[:3] + ("mujoco",), " (a single fixed step)")
    _check_gains(baumgarte)
    choice("limits", limits, LIMIT_MODELS)
    derivatives = flag("derivatives", derivatives)
    flat = _core.step(
        model, q, v, tau, real("dt", dt), integrator, derivatives, real("friction_velocity", friction_velocity),
        limits, real("limit_stiffness", limit_stiffness), real("limit_damping", limit_damping),
        constraints=_held(model, constraints), baumgarte=baumgarte, damping=real("damping", damping),
    )
    nx, nv = model.nq + model.nv, model.nv
    if not derivatives:
        return flat
    batch = flat.shape[:-1]
    x1 = flat[..., :nx]
    a = flat[..., nx : nx + 4 * nv * nv].reshape(batch + (2 * nv, 2 * nv))
    b = flat[..., nx + 4 * nv * nv :].reshape(batch + (2 * nv, nv))
    return x1, a, b
