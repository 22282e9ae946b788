"""Which MJCF models robodyn loads, and how closely it agrees with MuJoCo on them: a Markdown table.

usage: python scripts/menagerie_table.py [--absent LIST] PATH [PATH ...]

Each PATH is an MJCF file or a folder searched for them (e.g. a checkout of MuJoCo Menagerie: every
robot's model files, `scene*.xml` left out as they only add a floor and lights). For each file that
MuJoCo loads, robodyn loads it too and `robodyn.crosscheck.mujoco_agreement` compares every body's
compiled mass, centre of mass and inertia tensor, then M, bias, forward and inverse dynamics, body
and site poses, Jacobians and J̇v at random states with robodyn's tensors put into MuJoCo's model
(and with MuJoCo's own); the row gives the verdict (exact, within MuJoCo's compile noise, or
DISAGREES) with the worst body, or robodyn's error message, which names what it does not support
(a file with no joint has nothing to compare, and says so). docs/menagerie.md holds the results.

--absent LIST names a file listing, one a line, the files a copy lacks (e.g. the blobs over 4 MiB
that a mirror of Menagerie leaves out), as paths relative to the PATH folders. A model that MuJoCo
cannot open because it names one of them is counted as not compared, not as a failure.
"""

from __future__ import annotations

import re
import sys
import warnings
from collections import Counter
from collections.abc import Collection
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


def absent_file(error: Exception, path: Path, root: Path | None, absent: Collection[str]) -> str | None:
    """The absent file that MuJoCo's error names ("Error opening file 'X'"), relative to root."""
    match = re.search(r"Error opening file '([^']+)'", str(error))
    if not match or root is None:
        return None
    named = match.group(1)
    folder = path.parent.relative_to(root)
    for candidate in (folder / named, Path(named)):
        if candidate.as_posix() in absent:
            return candidate.as_posix()
    ends = [a for a in absent if a.endswith("/" + named) and a.startswith(folder.parts[0] + "/")] if folder.parts else []
    return ends[0] if len(ends) == 1 else None


def row(path: Path, root: Path | None = None, absent: Collection[str] = ()) -> tuple[str, str]:
    """One table row (whether MuJoCo and robodyn load the file, and how far apart they are) and
    the outcome it counts under in the summary."""
    name = path.relative_to(root) if root else path
    try:
        mj_model = mujoco.MjModel.from_xml_path(str(path))
    except Exception as error:  # MuJoCo's own error, e.g. a mesh file this copy lacks
        missing = absent_file(error, path, root, absent)
        if missing:
            return (f"| `{name}` | — | not compared: file `{missing}` absent from the snapshot |",
                    "not compared: a file absent from the snapshot")
        return f"| `{name}` | MuJoCo does not load it | {first_line(error)} |", "not loaded by MuJoCo"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            model = robodyn.load(path)
        except ValueError as error:
            return f"| `{name}` | no | {first_line(error)} |", "refused by robodyn"
    if model.nq == 0:  # a fragment meant for <include>, whose bodies MuJoCo welds to the world
        return f"| `{name}` | yes | nothing to compare: no joint (nq = 0) |", "nothing to compare (no joint)"
    messages = [str(w.message) for w in caught]
    ignored = sorted({m.split(": <")[-1].split(">")[0] for m in messages if ": <" in m and "not read" in m})
    try:
        agreement = mujoco_agreement(model, mj_model, seed=0, states=2, name=str(name))
    except ValueError as error:
        return f"| `{name}` | yes | not compared: {first_line(error)} |", "not compared"
    except Exception as error:  # a failure of the comparison itself, shown rather than hidden
        return (f"| `{name}` | yes | comparison failed: {type(error).__name__} {first_line(error)} |",
                "comparison failed")
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


def main(arguments: list[str]) -> None:
    """The table on standard output, then how many files had each outcome on standard error."""
    absent: set[str] = set()
    if arguments[:1] == ["--absent"]:
        absent = {line.strip() for line in Path(arguments[1]).read_text().splitlines() if line.strip()}
        arguments = arguments[2:]
    print("| model | loads | result |")
    print("|---|---|---|")
    outcomes: Counter[str] = Counter()
    for path in arguments:
        root = Path(path) if Path(path).is_dir() else None
        for file in model_files([path]):
            line, outcome = row(file, root, absent)
            outcomes[outcome] += 1
            print(line, flush=True)
    print("; ".join(f"{count} {outcome}" for outcome, count in outcomes.most_common()), file=sys.stderr)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
