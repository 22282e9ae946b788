"""Loading time of MJCF models whose inertia comes from mesh files: robodyn.load against MuJoCo's own
compile (mujoco.MjModel.from_xml_path), median of a few runs each, as a ratio.

usage: .venv/bin/python benchmarks/mesh_loading.py MODEL.xml [MODEL.xml ...]
       (without arguments: the repository's testdata/mjcf/mesh_inertia.xml)
"""

from __future__ import annotations

import statistics
import sys
import time
import warnings
from pathlib import Path

import mujoco

import robodyn

RUNS = 5


def median_seconds(load) -> float:
    times = []
    for _ in range(RUNS):
        start = time.perf_counter()
        load()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main(paths: list[str]) -> None:
    print("| model | robodyn.load | MuJoCo compile | ratio |")
    print("|---|---|---|---|")
    for path in paths:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ours = median_seconds(lambda: robodyn.load(path))
        theirs = median_seconds(lambda: mujoco.MjModel.from_xml_path(path))
        print(f"| `{Path(path).name}` | {ours * 1e3:.1f} ms | {theirs * 1e3:.1f} ms | {ours / theirs:.2f} |")


if __name__ == "__main__":
    main(sys.argv[1:] or [str(Path(__file__).resolve().parents[1] / "testdata" / "mjcf" / "mesh_inertia.xml")])
