"""Which MJCF models robodyn loads, and how closely it agrees with MuJoCo on them: a Markdown table.

usage: python scripts/menagerie_table.py PATH [PATH ...]

Each PATH is an MJCF file or a folder searched for them (e.g. a checkout of MuJoCo Menagerie: every
robot's model files, `scene*.xml` left out as they only add a floor and lights). For each file that
MuJoCo loads, robodyn loads it too and `robodyn.crosscheck.mujoco_agreement` compares every body's
compiled mass, centre of mass and inertia tensor, then M, bias, forward and inverse dynamics, body
and site poses, Jacobians and J̇v at random states with robodyn's tensors put into MuJoCo's model
(and with MuJoCo's own); the row gives the verdict (exact, within MuJoCo's compile noise, or
DISAGREES) with the worst body, or robodyn's error message, which names what it does not support.
docs/menagerie.md holds the results.
"""

from __future__ import annotations

import sys
import warnings
from collections import Counter
from pathlib import Path

import mujoco

import robodyn
from robodyn.crosscheck import DISAGREES, EXACT, mujoco_agreement


def model_files(paths: list[str]) -> list[Path]:
    files: list[Path] = []
    for path in map(Path, paths):
        if path.is_dir():
            files.extend(p for p in sorted(path.rglob("*.xml")) if not p.name.startswith("scene"))
        else:
            files.append(path)
    return files


def first_line(error: Exception) -> str:
    return " ".join(str(error).split("\n")[0].split()).replace("|", "\\|")


def row(path: Path, root: Path | None = None) -> tuple[str, str]:
    """One table row (whether MuJoCo and robodyn load the file, and how far apart they are) and
    the outcome it counts under in the summary."""
    name = path.relative_to(root) if root else path
    try:
        mj_model = mujoco.MjModel.from_xml_path(str(path))
    except Exception as error:  # MuJoCo's own error, e.g. a mesh file this copy lacks
        return f"| `{name}` | MuJoCo does not load it here | {first_line(error)} |", "not loaded by MuJoCo here"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            model = robodyn.load(path)
        except ValueError as error:
            return f"| `{name}` | no | {first_line(error)} |", "refused by robodyn"
    ignored = sorted({str(w.message).split(": <")[-1].split(">")[0] for w in caught if ": <" in str(w.message)})
    try:
        agreement = mujoco_agreement(model, mj_model, seed=0, states=2, name=str(name))
    except ValueError as error:
        return f"| `{name}` | yes | not compared: {first_line(error)} |", "not compared"
    note = f"nq = {model.nq}; not read: {', '.join(f'<{t}>' for t in ignored)}" if ignored else f"nq = {model.nq}"
    return f"| `{name}` | yes | {verdict(agreement)}; {note} |", agreement.verdict


def verdict(agreement) -> str:
    """The verdict, the worst body where it is not exact, and the dynamics' largest errors."""
    dynamics = max(agreement.dynamics.values())
    as_compiled = max(agreement.dynamics_as_compiled.values())
    if agreement.verdict == EXACT:
        return f"exact (dynamics {as_compiled:.1e})"
    worst = agreement.worst_body
    label = "DISAGREES" if agreement.verdict == DISAGREES else agreement.verdict
    return (f"{label}: worst body {worst}; dynamics {dynamics:.1e} with robodyn's inertias, "
            f"{as_compiled:.1e} with MuJoCo's").replace("|", "\\|")


def main(paths: list[str]) -> None:
    """The table on standard output, then how many files had each outcome on standard error."""
    print("| model | loads | result |")
    print("|---|---|---|")
    outcomes: Counter[str] = Counter()
    for path in paths:
        root = Path(path) if Path(path).is_dir() else None
        for file in model_files([path]):
            line, outcome = row(file, root)
            outcomes[outcome] += 1
            print(line, flush=True)
    print("; ".join(f"{count} {outcome}" for outcome, count in outcomes.most_common()), file=sys.stderr)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
