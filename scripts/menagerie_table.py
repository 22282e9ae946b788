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


def model_files(paths: list[str]) -> list[Path]:
    files: list[Path] = []
    for path in map(Path, paths):
        if path.is_dir():
            files.extend(p for p in sorted(path.rglob("*.xml")) if not p.name.startswith("scene"))
        else:
            files.append(path)
    return files


def row(path: Path) -> str | None:
    """One table row, or None when MuJoCo itself does not load the file."""
    try:
        mj_model = mujoco.MjModel.from_xml_path(str(path))
    except Exception:  # MuJoCo's own error: not a model file, or one MuJoCo rejects
        return None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            model = robodyn.load(path)
        except ValueError as error:
            return f"| {path} | no | {error} |"
    ignored = sorted({str(w.message).split(": <")[-1].split(">")[0] for w in caught})
    errors = mujoco_discrepancies(model, mj_model, seed=0, states=2)
    worst = max(errors.values())
    verdict = "matches" if worst <= TOLERANCE else "DIFFERS"
    note = f"nq = {model.nq}; not read: {', '.join(f'<{t}>' for t in ignored)}" if ignored else f"nq = {model.nq}"
    return f"| {path} | yes | {verdict} (largest relative error {worst:.1e}); {note} |"


def main(paths: list[str]) -> None:
    print("| model | loads | result |")
    print("|---|---|---|")
    for path in model_files(paths):
        line = row(path)
        if line is not None:
            print(line, flush=True)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
