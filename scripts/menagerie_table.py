"""Which MJCF models robodyn loads, and how closely it agrees with MuJoCo on them: a Markdown table.

usage: python scripts/menagerie_table.py PATH [PATH ...]

Each PATH is an MJCF file or a folder searched for them (e.g. a checkout of MuJoCo Menagerie: every
robot's model files, `scene*.xml` left out as they only add a floor and lights). For each file that
MuJoCo loads, robodyn loads it too and `robodyn.crosscheck.mujoco_discrepancies` compares M, bias,
forward and inverse dynamics, body and site poses, Jacobians and J̇v at random states; or the row
gives robodyn's error message, which names what it does not support. docs/menagerie.md holds the
results.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import mujoco

import robodyn
from robodyn.crosscheck import mujoco_discrepancies

#: The agreement the cross-check tests ask for.
TOLERANCE = 1e-9
#: MuJoCo's principal axes of a mesh's inertia come from an iterative eigen-solver good to about
#: 1e-7 rad; robodyn keeps the exact tensor (python/tests/test_mjcf_features.py measures it).
MESH_AXES_TOLERANCE = 1e-6


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


def row(path: Path, root: Path | None = None) -> str:
    """One table row: whether MuJoCo and robodyn load the file, and how far apart they are."""
    name = path.relative_to(root) if root else path
    try:
        mj_model = mujoco.MjModel.from_xml_path(str(path))
    except Exception as error:  # MuJoCo's own error, e.g. a mesh file this copy lacks
        return f"| `{name}` | MuJoCo does not load it here | {first_line(error)} |"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            model = robodyn.load(path)
        except ValueError as error:
            return f"| `{name}` | no | {first_line(error)} |"
    ignored = sorted({str(w.message).split(": <")[-1].split(">")[0] for w in caught if ": <" in str(w.message)})
    try:
        errors = mujoco_discrepancies(model, mj_model, seed=0, states=2)
    except ValueError as error:
        return f"| `{name}` | yes | not compared: {first_line(error)} |"
    worst = max(errors.values())
    if worst <= TOLERANCE:
        verdict = "matches"
    elif mj_model.nmesh and worst <= MESH_AXES_TOLERANCE:
        verdict = "matches, to the accuracy of MuJoCo's mesh principal axes"
    else:
        verdict = "DIFFERS"
    note = f"nq = {model.nq}; not read: {', '.join(f'<{t}>' for t in ignored)}" if ignored else f"nq = {model.nq}"
    return f"| `{name}` | yes | {verdict} (largest relative error {worst:.1e}); {note} |"


def main(paths: list[str]) -> None:
    print("| model | loads | result |")
    print("|---|---|---|")
    for path in paths:
        root = Path(path) if Path(path).is_dir() else None
        for file in model_files([path]):
            print(row(file, root), flush=True)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
