"""The ``robodyn`` command: ``robodyn demo``, ``robodyn models``, ``robodyn derive`` and
``robodyn simulate``."""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

import robodyn

#: forward_dynamics(inverse_dynamics(a)) must return a to this relative accuracy.
ROUND_TRIP_TOLERANCE = 1e-9


def _matrix(rows: np.ndarray, names: list[str]) -> str:
    width = max(len(n) for n in names)
    column = max(10, width + 2)
    lines = [" " * (width + 2) + "".join(f"{n:>{column}}" for n in names)]
    for name, row in zip(names, np.atleast_2d(rows)):
        lines.append(f"  {name:<{width}}" + "".join(f"{x:{column}.4f}" for x in row))
    return "\n".join(lines)


def _table(columns: dict[str, np.ndarray], names: list[str]) -> str:
    width = max(len(n) for n in names)
    lines = [f"  {'joint':<{width}}" + "".join(f"{c:>14}" for c in columns)]
    for k, name in enumerate(names):
        lines.append(f"  {name:<{width}}" + "".join(f"{values[k]:14.6f}" for values in columns.values()))
    return "\n".join(lines)


def demo(model_name: str = "ur5", batch: int = 10_000) -> int:
    """Print the dynamics of a bundled robot at a sample state and time a batch."""
    m = robodyn.load(model_name)
    names = [n.removesuffix("_joint") for n in m.joint_names]
    q = m.random_configuration(seed=1)
    v = np.linspace(-1.0, 1.0, m.nv)
    a = np.linspace(0.5, -0.5, m.nv)

    mass = m.mass_matrix(q)
    gravity = m.generalized_gravity(q)
    coriolis = m.bias_forces(q, v) - gravity
    tau = m.inverse_dynamics(q, v, a)
    print(f"robodyn {robodyn.__version__}: {m!r}\n")
    print("State and the terms of  tau = M(q) a + C(q, v) v + g(q)  (SI units):")
    print(_table({"q [rad]": q, "v [rad/s]": v, "a [rad/s2]": a, "g(q)": gravity, "C(q,v)v": coriolis, "tau": tau}, names))
    print("\nMass matrix M(q):")
    print(_matrix(mass, names))

    qdd = m.forward_dynamics(q, v, tau)
    error = np.max(np.abs(qdd - a)) / max(1.0, np.max(np.abs(a)))
    ok = error < ROUND_TRIP_TOLERANCE
    print(f"\nforward_dynamics(inverse_dynamics(a)) == a: {'yes' if ok else 'NO'} (max error {error:.1e})")

    states = m.random_configuration(n=batch, seed=2)
    start = time.perf_counter()
    m.generalized_gravity(states)
    elapsed = time.perf_counter() - start
    print(
        f"generalized_gravity on a batch of {batch} states: {elapsed * 1e3:.2f} ms "
        f"({elapsed / batch * 1e9:.0f} ns per state, {os.cpu_count()} cores)"
    )
    return 0 if ok else 1


def derive(model: str, rods: bool, latex: str | None, codegen: str | None, symbolic_params: bool,
           newton_euler: bool, output: str | None) -> int:
    """Print the closed-form equations of motion of a planar arm (``planar<n>``), the pendulum, or
    a DH table (``.toml``) or URDF file."""
    from robodyn import symbolic as sym

    planar = model.removeprefix("planar")
    if model.startswith("planar") and planar.isdigit():
        chain = sym.planar_chain(int(planar), point_masses=not rods)
    elif model == "pendulum":
        chain = sym.pendulum()
    elif model.lower().endswith(".toml"):
        chain = sym.from_dh(model, symbolic_params=symbolic_params)
    elif model.lower().endswith(".urdf"):
        chain = sym.from_urdf(model, symbolic_params=symbolic_params)
    else:
        raise ValueError(f"model: expected planar<n>, pendulum, a .toml DH table or a .urdf file, got {model!r}")
    start = time.perf_counter()
    equations = sym.lagrange(chain)
    if newton_euler:
        difference = sym.newton_euler(chain).difference(equations)
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


#: Runs with more recorded samples than this show a progress bar.
PROGRESS_BAR_SAMPLES = 2_000


def _progress_bar(stream=sys.stderr, width: int = 40):
    """A text progress bar on ``stream``, redrawn in place: ``[#####.....]  50 %``."""

    def draw(fraction: float) -> None:
        filled = int(round(fraction * width))
        stream.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {fraction * 100:5.1f} %")
        if fraction >= 1.0:
            stream.write("\n")
        stream.flush()

    return draw


def simulate(model: str, t_end: float, dt: float, integrator: str, q0: list[float] | None, controller: str,
             plot: str | None, animate: str | None, csv: str | None, npz: str | None,
             show_progress: bool | None = None) -> int:
    """Simulate a model from rest and report the run; optionally save a plot, an animation and data."""
    m = robodyn.load(model)
    start_q = m.neutral() if q0 is None else np.asarray(q0, dtype=float)
    controllers = {
        "none": None,
        "gravity": robodyn.GravityCompensation(),
        "pd": robodyn.PD(kp=100.0 * np.diag(m.mass_matrix(start_q)), kd=20.0 * np.diag(m.mass_matrix(start_q)),
                         q_ref=start_q, gravity_compensation=True),
    }
    if show_progress is None:
        show_progress = t_end / dt > PROGRESS_BAR_SAMPLES and sys.stderr.isatty()
    progress = _progress_bar() if show_progress else None
    begin = time.perf_counter()
    trajectory = robodyn.simulate(m, start_q, t_end=t_end, dt=dt, integrator=integrator,
                                  controller=controllers[controller], progress=progress)
    elapsed = time.perf_counter() - begin
    drift = float(np.max(np.abs(trajectory.energy - trajectory.energy[0])))
    print(f"{m.name}: {t_end:g} s with {integrator} in {elapsed:.3f} s ({trajectory.steps} steps, "
          f"{trajectory.rejected_steps} rejected, {trajectory.evaluations} evaluations of the dynamics)")
    print(f"energy: {trajectory.energy[0]:.6g} J at the start, {trajectory.energy[-1]:.6g} J at the end, "
          f"largest change {drift:.3g} J")
    for violation in trajectory.limit_violations:
        print(f"limit: {violation['coordinate']} left its range at t = {violation['first_time']:.3f} s, "
              f"by up to {violation['worst_excess']:.3g}")
    for path, write in ((plot, trajectory.plot), (animate, trajectory.animate), (csv, trajectory.to_csv),
                        (npz, trajectory.to_npz)):
        if path:
            write(path)
            print(f"wrote {path}")
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="robodyn", description="Rigid-body dynamics for robots.")
    commands = parser.add_subparsers(dest="command", required=True)
    demo_parser = commands.add_parser("demo", help="dynamics of a bundled robot at a sample state")
    demo_parser.add_argument("model", nargs="?", default="ur5", choices=robodyn.models())
    demo_parser.add_argument("--batch", type=int, default=10_000, help="batch size to time")
    commands.add_parser("models", help="list the bundled models")
    derive_parser = commands.add_parser("derive", help="closed-form equations of motion (SymPy)")
    derive_parser.add_argument("model", help="planar<n> (e.g. planar2), pendulum, a DH table .toml or a .urdf")
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
    simulate_parser.add_argument("model", help="a bundled model name or a .urdf, MJCF .xml or DH .toml file")
    simulate_parser.add_argument("--t", type=float, default=5.0, dest="t_end", help="duration in s (default 5)")
    simulate_parser.add_argument("--dt", type=float, default=1e-3,
                                 help="step (recording interval for rk45) in s (default 1e-3)")
    simulate_parser.add_argument("--integrator", default="rk4", choices=robodyn.simulation.INTEGRATORS)
    simulate_parser.add_argument("--q0", type=float, nargs="+", help="initial configuration (default: neutral)")
    simulate_parser.add_argument("--controller", default="none", choices=["none", "gravity", "pd"],
                                 help="no torque, gravity compensation, or PD holding q0 with gravity compensation")
    simulate_parser.add_argument("--plot", help="save q, v, τ and energy over time (PNG, PDF or SVG)")
    simulate_parser.add_argument("--animate", help="save a stick-figure animation (.gif, or .mp4 with ffmpeg)")
    simulate_parser.add_argument("--csv", help="save the trajectory as CSV")
    simulate_parser.add_argument("--npz", help="save the trajectory as NumPy .npz")
    simulate_parser.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                                 help="show a progress bar (default: for long runs on a terminal)")
    args = parser.parse_args(argv)
    if args.command == "simulate":
        try:
            return simulate(args.model, args.t_end, args.dt, args.integrator, args.q0, args.controller,
                            args.plot, args.animate, args.csv, args.npz, args.progress)
        except (ValueError, FileNotFoundError) as error:
            print(f"robodyn simulate: {error}", file=sys.stderr)
            return 2
    if args.command == "derive":
        try:
            return derive(args.model, args.rods, args.latex, args.codegen, args.symbolic_params,
                          args.newton_euler, args.output)
        except (ValueError, FileNotFoundError) as error:
            print(f"robodyn derive: {error}", file=sys.stderr)
            return 2
    if args.command == "models":
        print("\n".join(robodyn.models()))
        return 0
    return demo(args.model, args.batch)


if __name__ == "__main__":
    sys.exit(main())
