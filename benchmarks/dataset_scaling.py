"""How robodyn.dataset scales with Dask workers, and what a cluster would produce.

Runs the same UR5 dataset (tau and M, chunks of 16 384 states) here without Dask, then on local
Dask clusters of 1 and 2 worker processes (one thread each: each worker's batched calls still use
every core of this machine through rayon, so on a 2-core machine the workers share the cores), and
prints states per second for each, the plain batched call's rate, and the projection for a
cluster from the measured rate per core. Usage: .venv/bin/python benchmarks/dataset_scaling.py
[--n 524288]
"""

from __future__ import annotations

import argparse
import os
import shutil
import tempfile
import time

import numpy as np
import robodyn
from dask.distributed import Client, LocalCluster


def rate(run) -> float:
    """States per second of the best of three runs of `run()`, which returns the state count."""
    best = 0.0
    for _ in range(3):
        started = time.perf_counter()
        n = run()
        best = max(best, n / (time.perf_counter() - started))
    return best


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--n", type=int, default=524_288)
    n = parser.parse_args().n
    m = robodyn.load("ur5")
    folder = tempfile.mkdtemp()

    def dataset(client=None) -> int:
        out = os.path.join(folder, "ur5.zarr")
        shutil.rmtree(out, ignore_errors=True)
        robodyn.dataset(m, n, ["tau", "M"], chunk=16_384, out=out, client=client)
        return n

    q = m.random_configuration(n=n, seed=1)
    v = np.random.default_rng(0).uniform(-1, 1, (n, m.nv))

    def plain() -> int:
        m.inverse_dynamics(q, v, v)
        m.mass_matrix(q)
        return n

    cores = os.cpu_count() or 1
    rows = [("plain batched call (no sampling, no store)", rate(plain)), ("dataset, no Dask", rate(dataset))]
    for workers in (1, 2):
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
            with Client(cluster) as client:
                rows.append((f"dataset, Dask, {workers} worker(s)", rate(lambda: dataset(client))))
    shutil.rmtree(folder, ignore_errors=True)
    print(f"robodyn {robodyn.__version__}, UR5, tau and M, {n} states, {cores} cores")
    for label, states_per_second in rows:
        print(f"{label:45s} {states_per_second / 1e6:8.2f} M states/s")
    per_core = rows[1][1] / cores
    print(f"per core (dataset, no Dask): {per_core / 1e6:.2f} M states/s; a 100-core cluster at this rate "
          f"and with storage that keeps up: {100 * per_core * 3600 / 1e9:.0f} G states per hour")


if __name__ == "__main__":
    main()
