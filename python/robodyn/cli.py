"""The ``robodyn`` command: ``demo``, ``info``, ``models``, ``derive`` and ``simulate``.

Every command takes a bundled model's name or a model file (URDF, MJCF ``.xml``, DH ``.toml``).
A bad argument is one line on standard error naming it, and exit status 2; never a traceback.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import threading
import time
import warnings
from pathlib import Path
from typing import Any, Callable, NoReturn, Sequence, TextIO

import numpy as np

import robodyn
from robodyn import _arguments
from robodyn._joints import JOINT_KINDS, coordinate_names
from robodyn.simulation import INTEGRATORS

#: forward_dynamics(inverse_dynamics(a)) must return a to this relative accuracy.
ROUND_TRIP_TOLERANCE = 1e-9
#: Runs with more recorded samples than this show a progress bar on a terminal.
PROGRESS_BAR_SAMPLES = 2_000
#: A derivation shows its elapsed time on a terminal once it has taken this long (s).
DERIVE_STATUS_AFTER_S = 1.0
#: Exit status of a command given a bad argument (argparse's own).
USAGE_ERROR = 2


class UsageError(Exception):
    """A bad argument: printed as one line, exit status 2."""


class _Parser(argparse.ArgumentParser):
    """argparse, with its errors as one line naming the command and the argument."""

    def error(self, message: str) -> NoReturn:
        raise UsageError(message)


# ---------------------------------------------------------------------------------------------------
# argument types: each names what it expected and what came


def _option(check: Callable[[str, Any], Any]) -> Callable[[str], Any]:
    """An option's type from a check of ``robodyn._arguments``: the text read as a number (1e6
    is a whole number), then checked."""

    def convert(text: str) -> Any:
        try:
            number = float(text)
            value: Any = int(number) if number.is_integer() else number
        except ValueError:
            value = text
        try:
            return check("option", value)
        except ValueError as error:
            # argparse puts the option's name before the message
            raise argparse.ArgumentTypeError(str(error).removeprefix("argument 'option': ")) from None

    return convert


_positive_int = _option(_arguments.count)
_positive_float = _option(_arguments.positive)


def _load(model: str, show_warnings: bool = True) -> robodyn.Model:
    """A bundled model or a model file, as the commands take them; its warnings one line each."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", robodyn.ModelWarning)
        m = robodyn.load(model)
    if show_warnings:
        for message in m.warnings:
            print(f"warning: {message}", file=sys.stderr)
    return m


def _configuration(m: robodyn.Model, values: Sequence[float] | None, option: str, default: np.ndarray) -> np.ndarray:
    """A configuration given on the command line (nq numbers), checked against the model."""
    if values is None:
        return default
    if len(values) != m.nq:
        raise UsageError(f"argument {option}: expected {m.nq} numbers (nq of {m.name}), got {len(values)}")
    q = np.asarray(values, dtype=float)
    try:
        m.difference(q, q)
    except ValueError as error:
        raise UsageError(f"argument {option}: {error}") from None
    return q


def _is_terminal(stream: TextIO) -> bool:
    return hasattr(stream, "isatty") and stream.isatty()


def _progress_bar(label: str, width: int = 40) -> Callable[[float], None]:
    """A text progress bar on standard error, redrawn in place: ``label [#####.....]  50.0 %``."""
    stream = sys.stderr

    def draw(fraction: float) -> None:
        filled = int(round(fraction * width))
        stream.write(f"\r{label} [{'#' * filled}{'.' * (width - filled)}] {fraction * 100:5.1f} %")
        if fraction >= 1.0:
            stream.write("\n")
        stream.flush()

    return draw


# ---------------------------------------------------------------------------------------------------
# robodyn demo


def _table(columns: dict[str, np.ndarray], names: list[str], heading: str) -> str:
    width = max(len(n) for n in [*names, heading])
    lines = [f"  {heading:<{width}}" + "".join(f"{c:>14}" for c in columns)]
    for k, name in enumerate(names):
        lines.append(f"  {name:<{width}}" + "".join(f"{values[k]:14.6f}" for values in columns.values()))
    return "\n".join(lines)


def _matrix(rows: np.ndarray, names: list[str]) -> str:
    width = max(len(n) for n in names)
    column = max(10, width + 2)
    lines = [" " * (width + 2) + "".join(f"{n:>{column}}" for n in names)]
    for name, row in zip(names, np.atleast_2d(rows)):
        lines.append(f"  {name:<{width}}" + "".join(f"{x:{column}.4f}" for x in row))
    return "\n".join(lines)


def demo(model: str = "ur5", batch: int = 10_000) -> int:
    """Print the dynamics of a robot at a sample state and time a batch."""
    m = _load(model)
    q_names, v_names = coordinate_names(m)
    q = m.random_configuration(seed=1)
    v = np.linspace(-1.0, 1.0, m.nv)
    a = np.linspace(0.5, -0.5, m.nv)

    mass = m.mass_matrix(q)
    gravity = m.generalized_gravity(q)
    coriolis = m.bias_forces(q, v) - gravity
    tau = m.inverse_dynamics(q, v, a)
    print(f"robodyn {robodyn.__version__}: {m!r}\n")
    print("Configuration q:")
    print(_table({"q": q}, q_names, "coordinate"))
    print("\nThe terms of  tau = M(q) a + C(q, v) v + g(q)  (SI units: rad or m, N·m or N):")
    print(_table({"v": v, "a": a, "g(q)": gravity, "C(q,v)v": coriolis, "tau": tau}, v_names, "coordinate"))
    print("\nMass matrix M(q):")
    print(_matrix(mass, v_names))

    qdd = m.forward_dynamics(q, v, tau)
    error = float(np.max(np.abs(qdd - a)) / max(1.0, float(np.max(np.abs(a)))))
    ok = error < ROUND_TRIP_TOLERANCE
    print(f"\nforward_dynamics(inverse_dynamics(a)) == a: {'yes' if ok else 'NO'} (max error {error:.1e})")

    states = m.random_configuration(n=batch, seed=2)
    start = time.perf_counter()
    m.generalized_gravity(states)
    elapsed = time.perf_counter() - start
    print(f"generalized_gravity on a batch of {batch} states: {elapsed * 1e3:.2f} ms "
          f"({elapsed / batch * 1e9:.0f} ns per state, {os.cpu_count()} cores)")
    return 0 if ok else 1


# ---------------------------------------------------------------------------------------------------
# robodyn info


def info(model: str) -> int:
    """Print what a model holds: sizes, joints, bodies, frames, warnings."""
    m = _load(model, show_warnings=False)
    print(f"{m.name}: nq = {m.nq}, nv = {m.nv}, {len(m.joint_names)} joints, {len(m.body_names)} bodies, "
          f"{len(m.frame_names)} frames, total mass {m.total_mass:.6g} kg, gravity [{', '.join(f'{g:g}' for g in m.gravity)}] m/s²")
    print("\nJoints (limits in rad for revolute, m for prismatic joints):")
    width = max(len(n) for n in m.joint_names)
    print(f"  {'joint':<{width}}  {'type':<10} {'q index':>7} {'v index':>7} {'lower':>12} {'upper':>12}")
    for name, kind, iq, iv in zip(m.joint_names, m.joint_types, m.joint_idx_q, m.joint_idx_v):
        unit = JOINT_KINDS[kind].unit
        lower = f"{m.lower_position_limit[iq]:.6g} {unit}" if unit else "-"
        upper = f"{m.upper_position_limit[iq]:.6g} {unit}" if unit else "-"
        print(f"  {name:<{width}}  {kind:<10} {iq:>7} {iv:>7} {lower:>12} {upper:>12}")
    print("\nBodies (mass in kg; parent body):")
    width = max(len(n) for n in m.body_names)
    for name, mass, parent in zip(m.body_names, m.body_masses, m.body_parents):
        print(f"  {name:<{width}}  {mass:10.6g}   {'world' if parent < 0 else m.body_names[parent]}")
    print("\nFrames (body they move with):")
    for name, body in zip(m.frame_names, m.frame_bodies):
        print(f"  {name}  ({'world' if body < 0 else m.body_names[body]})")
    for relation in m.mimic_joints:
        print(f"mimic: q[{relation[0]}] = {relation[2]:g} q[{relation[1]}] + {relation[3]:g} (a JointCoupling in m.constraints where both joints are revolute or prismatic; load(..., mimic=True) enforces it in reduced coordinates)")
    print(f"\nWarnings: {len(m.warnings)}")
    for message in m.warnings:
        print(f"  {message}")
    return 0


# ---------------------------------------------------------------------------------------------------
# robodyn derive


def _elapsed_status(label: str) -> Callable[[], None]:
    """Shows ``label ... 3.2 s`` on a terminal while a long step runs; returns the function that stops it."""
    stream = sys.stderr
    done = threading.Event()
    start = time.perf_counter()

    def tick() -> None:
        if done.wait(DERIVE_STATUS_AFTER_S):
            return
        while not done.wait(0.2):
            stream.write(f"\r{label} ... {time.perf_counter() - start:.1f} s")
            stream.flush()
        stream.write(f"\r{label} ... done in {time.perf_counter() - start:.1f} s\n")
        stream.flush()

    thread = threading.Thread(target=tick, daemon=True)
    if _is_terminal(stream):
        thread.start()

    def stop() -> None:
        done.set()
        if thread.is_alive():
            thread.join()

    return stop


def _symbolic_chain(model: str, rods: bool, symbolic_params: bool) -> Any:
    """The symbolic chain of a planar arm, the pendulum, a bundled model, a DH table or a URDF."""
    from robodyn import symbolic as sym

    planar = model.removeprefix("planar")
    if model.startswith("planar") and planar.isdigit() and int(planar) > 0:
        return sym.planar_chain(int(planar), point_masses=not rods)
    if model == "pendulum":
        return sym.pendulum()
    if model in robodyn.models():
        text, gravity = robodyn._core.bundled_urdf(model)
        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / f"{model}.urdf"
            path.write_text(text)
            return sym.from_urdf(path, symbolic_params=symbolic_params, gravity=list(gravity))
    suffix = Path(model).suffix.lower()
    if suffix in (".toml", ".urdf") and not Path(model).is_file():
        raise FileNotFoundError(f"model file not found: '{model}'")
    if suffix == ".toml":
        return sym.from_dh(model, symbolic_params=symbolic_params)
    if suffix == ".urdf":
        return sym.from_urdf(model, symbolic_params=symbolic_params)
    if suffix == ".xml":
        raise UsageError(f"argument model: the symbolic layer reads URDF files and DH tables, not MJCF, got '{model}'")
    raise UsageError(f"argument model: expected planar<n>, pendulum, a bundled model ({', '.join(robodyn.models())}), "
                     f"a DH table .toml or a .urdf file, got '{model}'")


def derive(model: str, rods: bool, latex: str | None, codegen: str | None, symbolic_params: bool,
           newton_euler: bool, output: str | None) -> int:
    """Print the closed-form equations of motion of a model."""
    from robodyn import symbolic as sym

    if output:
        _arguments.writable_folder("-o/--output", output)
    chain = _symbolic_chain(model, rods, symbolic_params)
    start = time.perf_counter()
    stop = _elapsed_status(f"Euler–Lagrange equations of {model}")
    try:
        equations = sym.lagrange(chain)
    finally:
        stop()
    if newton_euler:
        stop = _elapsed_status("Newton–Euler, and the difference")
        try:
            difference = sym.newton_euler(chain).difference(equations)
        finally:
            stop()
        agree = all(d == 0 for d in difference)
        print(f"Newton–Euler and Euler–Lagrange agree: {'yes' if agree else 'NO'}", file=sys.stderr)
    if codegen:
        text = equations.codegen(codegen)
    elif latex:
        text = equations.latex(latex) + "\n"
    else:
        text = equations.text()
    elapsed = time.perf_counter() - start
    if output:
        Path(output).write_text(text)
        print(f"wrote {output}", file=sys.stderr)
    else:
        print(text, end="")
    print(f"derived in {elapsed:.2f} s", file=sys.stderr)
    return 0


# ---------------------------------------------------------------------------------------------------
# robodyn simulate


def _check_outputs(plot: str | None, animate: str | None, csv: str | None, npz: str | None,
                   html: str | None = None) -> None:
    """Everything the outputs need, checked before simulating rather than after."""
    from robodyn.plot import check_animation_path, check_figure_path
    from robodyn.viewer import check_html_path

    try:
        if plot:
            check_figure_path(plot, "--plot")
        if animate:
            check_animation_path(animate, "--animate")
        if html:
            check_html_path(html, "--html")
    except ImportError as error:
        raise UsageError(str(error)) from None
    except ValueError as error:
        raise UsageError(str(error)) from None
    for path, option in ((csv, "--csv"), (npz, "--npz")):
        if path:
            _arguments.writable_folder(option, path)


def simulate(model: str, t_end: float, dt: float | None, integrator: str, q0: Sequence[float] | None, controller: str,
             target: Sequence[float] | None, plot: str | None, animate: str | None, csv: str | None,
             npz: str | None, show_progress: bool | None = None, html: str | None = None) -> int:
    """Simulate a model from rest and report the run; optionally save a plot, an animation, a page
    that plays it and data."""
    _check_outputs(plot, animate, csv, npz, html)
    m = _load(model)
    start_q = _configuration(m, q0, "--q0", m.neutral())
    if target is not None and controller != "pd":
        raise UsageError("argument --target: only the pd controller takes a target (--controller pd)")
    goal = _configuration(m, target, "--target", start_q)
    gains = np.diag(m.mass_matrix(start_q))
    controllers: dict[str, Any] = {
        "none": None,
        "gravity": robodyn.GravityCompensation(),
        "pd": robodyn.PD(kp=100.0 * gains, kd=20.0 * gains, q_ref=goal, gravity_compensation=True),
    }
    terminal = _is_terminal(sys.stderr)
    if dt is None:
        dt = m.options.timestep if integrator == "mujoco" else 1e-3
    if show_progress is None:
        show_progress = t_end / dt > PROGRESS_BAR_SAMPLES and terminal
    begin = time.perf_counter()
    trajectory = robodyn.simulate(m, start_q, t_end=t_end, dt=dt, integrator=integrator,
                                  controller=controllers[controller], accuracy="ignore",
                                  progress=_progress_bar("simulating") if show_progress else None)
    elapsed = time.perf_counter() - begin
    drift = float(np.max(np.abs(trajectory.energy - trajectory.energy[0])))
    print(f"{m.name}: {t_end:g} s with {integrator} in {elapsed:.3f} s ({trajectory.steps} steps, "
          f"{trajectory.rejected_steps} rejected, {trajectory.evaluations} evaluations of the dynamics)")
    print(f"energy: {trajectory.energy[0]:.6g} J at the start, {trajectory.energy[-1]:.6g} J at the end, "
          f"largest change {drift:.3g} J")
    if trajectory.accuracy_issue is not None:
        print(f"accuracy: {trajectory.accuracy_issue['message']}")
    kinds = dict(zip(m.joint_names, m.joint_types))
    for violation in trajectory.limit_violations:
        unit = JOINT_KINDS[kinds[violation["joint"]]].unit
        print(f"limit: {violation['coordinate']} left its range at t = {violation['first_time']:.3f} s, "
              f"by up to {violation['worst_excess']:.3g} {unit}".rstrip())
    if plot:
        trajectory.plot(plot)
        print(f"wrote {plot}")
    if animate:
        trajectory.animate(animate, progress=_progress_bar("writing frames") if terminal else None)
        print(f"wrote {animate}")
    if html:
        trajectory.to_html(html)
        print(f"wrote {html} (opens offline in any browser)")
    if csv:
        trajectory.to_csv(csv)
        print(f"wrote {csv}")
    if npz:
        trajectory.to_npz(npz)
        print(f"wrote {npz}")
    return 0


# ---------------------------------------------------------------------------------------------------
# robodyn view


def view(model: str, q: Sequence[float] | None, html: str | None, port: int, frames: bool, com: bool,
         open_browser: bool | None) -> int:
    """Shows a model in the browser until interrupted, or writes it to one offline HTML file."""
    from robodyn.viewer import check_html_path

    if html:
        check_html_path(html, "--html")
    m = _load(model)
    configuration = _configuration(m, q, "--q", m.neutral())
    if html:
        m.to_html(html, configuration, frames=frames, com=com)
        print(f"wrote {html} (opens offline in any browser)")
        return 0
    with m.view(configuration, port=port, frames=frames, com=com, open_browser=open_browser) as viewer:
        print(f"{m.name}: {viewer.url} (Ctrl-C stops)", flush=True)
        try:
            while True:
                time.sleep(1.0)
        except KeyboardInterrupt:
            print()
    return 0


# ---------------------------------------------------------------------------------------------------
# the parser


MODEL_HELP = "a bundled model (robodyn models) or a model file: .urdf, MJCF .xml or DH table .toml"


def _parser() -> _Parser:
    parser = _Parser(prog="robodyn", description="Rigid-body dynamics for robots.")
    parser.add_argument("--version", action="version", version=f"robodyn {robodyn.__version__}")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    demo_parser = commands.add_parser("demo", help="dynamics of a robot at a sample state, and a timed batch")
    demo_parser.add_argument("model", nargs="?", default="ur5", help=MODEL_HELP + " (default ur5)")
    demo_parser.add_argument("--batch", type=_positive_int, default=10_000, help="batch size to time (default 10000)")

    info_parser = commands.add_parser("info", help="what a model holds: joints, limits, bodies, frames, warnings")
    info_parser.add_argument("model", help=MODEL_HELP)

    commands.add_parser("models", help="list the bundled models")

    derive_parser = commands.add_parser("derive", help="closed-form equations of motion (SymPy)")
    derive_parser.add_argument("model", help="planar<n> (e.g. planar2), pendulum, a bundled model, a DH table .toml or a .urdf")
    derive_parser.add_argument("--rods", action="store_true", help="planar links as uniform rods, not point masses")
    derive_parser.add_argument("--latex", nargs="?", const="matrices", choices=["matrices", "torques"],
                               help="print LaTeX: M, V, G as matrices (default) or each joint's torque")
    derive_parser.add_argument("--codegen", choices=["c", "rust", "numpy"], help="print source code of M, C, G, tau")
    derive_parser.add_argument("--symbolic-params", action="store_true",
                               help="masses, lengths, inertias and g of a file as symbols")
    derive_parser.add_argument("--newton-euler", action="store_true",
                               help="also derive by Newton–Euler and report whether the two agree")
    derive_parser.add_argument("-o", "--output", help="write to this file instead of standard output")

    simulate_parser = commands.add_parser("simulate", help="simulate a model and plot or animate the motion")
    simulate_parser.add_argument("model", help=MODEL_HELP)
    simulate_parser.add_argument("--t", type=_positive_float, default=5.0, dest="t_end", help="duration in s (default 5)")
    simulate_parser.add_argument("--dt", type=_positive_float, default=None,
                                 help="step (recording interval for rk45 and mujoco) in s (default 1e-3; "
                                      "mujoco: the scene's time step)")
    simulate_parser.add_argument("--integrator", default="rk4", choices=INTEGRATORS)
    simulate_parser.add_argument("--q0", type=float, nargs="+", help="initial configuration, nq numbers (default: neutral)")
    simulate_parser.add_argument("--controller", default="none", choices=["none", "gravity", "pd"],
                                 help="no torque, gravity compensation, or PD to --target with gravity compensation")
    simulate_parser.add_argument("--target", type=float, nargs="+",
                                 help="the configuration the pd controller drives to, nq numbers (default: q0)")
    simulate_parser.add_argument("--plot", help="save q, v, τ and energy over time (PNG, PDF or SVG)")
    simulate_parser.add_argument("--animate", help="save a stick-figure animation (.gif, or .mp4 with ffmpeg)")
    simulate_parser.add_argument("--html", help="save a page that plays the motion with the robot's meshes, offline")
    simulate_parser.add_argument("--csv", help="save the trajectory as CSV")
    simulate_parser.add_argument("--npz", help="save the trajectory as NumPy .npz")
    simulate_parser.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                                 help="show a progress bar (default: for long runs on a terminal)")
    view_parser = commands.add_parser("view", help="show a model in the browser, or save it as an offline page")
    view_parser.add_argument("model", help=MODEL_HELP)
    view_parser.add_argument("--q", type=float, nargs="+", help="the configuration, nq numbers (default: neutral)")
    view_parser.add_argument("--html", help="write one self-contained page instead of serving")
    view_parser.add_argument("--port", type=_positive_int, default=8080, help="port tried first (default 8080)")
    view_parser.add_argument("--frames", action="store_true", help="draw every body's frame")
    view_parser.add_argument("--com", action="store_true", help="mark the centre of mass")
    view_parser.add_argument("--browser", action=argparse.BooleanOptionalAction, default=None,
                             help="open the page in a browser (default: when a desktop session is there)")
    dataset_parser = commands.add_parser("dataset", help="sample states and write their dynamics to a Zarr store or Parquet files")
    dataset_parser.add_argument("model", help=MODEL_HELP)
    dataset_parser.add_argument("--n", type=_positive_int, required=True, help="number of states, e.g. 1e6")
    dataset_parser.add_argument("--out", required=True, help="the Zarr store to write (a folder), or, ending in .parquet, a folder of Parquet files "
                                "(vector quantities)")
    dataset_parser.add_argument("--quantities", nargs="+", default=["tau"], choices=["tau", "M", "g", "qdd"],
                                help="what to evaluate at each state (default tau)")
    dataset_parser.add_argument("--seed", type=int, default=0, help="the seed (default 0)")
    dataset_parser.add_argument("--chunk", type=_positive_int, default=65_536,
                                help="states per task and Zarr chunk (default 65536)")
    dataset_parser.add_argument("--sampler", choices=["uniform", "gaussian"], default="uniform",
                                help="q uniform within the limits, or Gaussian around the neutral pose")
    dataset_parser.add_argument("--scheduler", help="a Dask scheduler's address (default: this machine, no Dask)")
    dataset_parser.add_argument("--resume", action="store_true", help="complete a store an interrupted run left")
    dataset_parser.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                                help="show a progress bar (default: on a terminal)")
    return parser


# ---------------------------------------------------------------------------------------------------
# robodyn dataset


def dataset(model: str, n: int, out: str, quantities: list[str], seed: int, chunk: int, sampler: str,
            scheduler: str | None, resume: bool, progress: bool | None) -> int:
    """Samples n states of a model and writes them with their dynamics to a Zarr store or Parquet
    files."""
    m = _load(model)
    _arguments.writable_folder("--out", out)
    client = None
    if scheduler is not None:
        from dask.distributed import Client

        client = Client(scheduler)
    show = _is_terminal(sys.stderr) if progress is None else progress
    started = time.perf_counter()
    try:
        robodyn.dataset(m, n, quantities, sampler=sampler, seed=seed, chunk=chunk, out=out,
                                client=client, resume=resume, progress=_progress_bar("dataset") if show else None)
    finally:
        if client is not None:
            client.close()
    seconds = time.perf_counter() - started
    print(f"{out}: {n} states of {m.name} ({', '.join(['q', 'v', 'a', 'tau_applied', *quantities])}), "
          f"{-(-n // chunk)} chunks, {seconds:.1f} s, {n / seconds:,.0f} states/s")
    return 0


def _run(args: argparse.Namespace) -> int:
    if args.command == "demo":
        return demo(args.model, args.batch)
    if args.command == "info":
        return info(args.model)
    if args.command == "models":
        print("\n".join(robodyn.models()))
        return 0
    if args.command == "derive":
        return derive(args.model, args.rods, args.latex, args.codegen, args.symbolic_params, args.newton_euler,
                      args.output)
    if args.command == "dataset":
        return dataset(args.model, args.n, args.out, args.quantities, args.seed, args.chunk, args.sampler,
                       args.scheduler, args.resume, args.progress)
    if args.command == "view":
        return view(args.model, args.q, args.html, args.port, args.frames, args.com, args.browser)
    return simulate(args.model, args.t_end, args.dt, args.integrator, args.q0, args.controller, args.target,
                    args.plot, args.animate, args.csv, args.npz, args.progress, args.html)


def main(argv: list[str] | None = None) -> int:
    arguments = sys.argv[1:] if argv is None else argv
    command = next((a for a in arguments if not a.startswith("-")), "")
    commands = ("demo", "info", "models", "derive", "simulate", "view", "dataset")
    prefix = f"robodyn {command}".strip() if command in commands else "robodyn"
    try:
        return _run(_parser().parse_args(arguments))
    except (UsageError, ValueError, FileNotFoundError) as error:
        message = " ".join(str(error).split())
        print(f"{prefix}: {message}", file=sys.stderr)
        return USAGE_ERROR


if __name__ == "__main__":
    sys.exit(main())
