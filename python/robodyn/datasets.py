"""Datasets of sampled states and their dynamics, and batches of rollouts, on this machine or a
Dask cluster; datasets are written to a chunked Zarr store or a folder of Parquet files (vector
quantities), rollouts gathered or written to Zarr.

`dataset(model, n, quantities, sampler, seed, chunk, out, client)` samples n states (q, v, a),
evaluates the requested quantities with the batched core calls (all cores, lanes) chunk by
chunk, and writes every array of the store chunk by chunk (one Parquet file per chunk). Samples are drawn in blocks of
`SEED_BLOCK` states, block b from the seed sequence (seed, b); a chunk draws the blocks it
overlaps and keeps its own states, so the store is the same for any chunk size and any number of
workers. Each chunk is marked done when
written, so an interrupted run resumes (`resume=True`) without recomputing finished chunks, and
a chunk whose worker died is simply computed again (Dask reruns its task).

Dask (`dask[distributed]`), Zarr (3 or later, so Python 3.11 or later) and PyArrow are the
optional extra `robodyn[distributed]`.
"""

from __future__ import annotations

import hashlib
import json
import os
import pickle
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from importlib.metadata import version
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from robodyn import _arguments, _core

#: States per independently seeded block: a chunk draws the blocks it overlaps and keeps its
#: states, so the chunking changes nothing.
SEED_BLOCK = 256
#: Half-ranges of the uniform v, a and applied τ where the model gives no limit.
DEFAULT_VELOCITY = 1.0
DEFAULT_ACCELERATION = 10.0
DEFAULT_TORQUE = 10.0

FloatArray = NDArray[np.float64]

#: What can be asked for: name -> (the call on a chunk of q, v, a, τ; the shape per state).
QUANTITIES: dict[str, tuple[Callable[..., FloatArray], Callable[[_core.Model], tuple[int, ...]]]] = {
    "tau": (lambda m, q, v, a, t: m.inverse_dynamics(q, v, a), lambda m: (m.nv,)),
    "M": (lambda m, q, v, a, t: m.mass_matrix(q), lambda m: (m.nv, m.nv)),
    "g": (lambda m, q, v, a, t: m.generalized_gravity(q), lambda m: (m.nv,)),
    "qdd": (lambda m, q, v, a, t: m.forward_dynamics(q, v, t), lambda m: (m.nv,)),
}


def _symmetric_limit(limit: FloatArray, default: float) -> FloatArray:
    """The limit where finite, `default` elsewhere."""
    return np.where(np.isfinite(limit), limit, default)


def _limits(model: _core.Model) -> tuple[FloatArray, FloatArray]:
    """The half-ranges of the sampled v and applied τ."""
    velocity = _symmetric_limit(np.asarray(model.velocity_limit), DEFAULT_VELOCITY)
    return velocity, _symmetric_limit(np.asarray(model.effort_limit), DEFAULT_TORQUE)


def _block(model: _core.Model, sampler: Any, limits: tuple[FloatArray, FloatArray], seed: int, block: int, start: int, stop: int) -> dict[str, FloatArray]:
    """q, v, a and the applied τ of block `block`, states [start, stop) of the dataset: the whole
    block (its last states only if the dataset ends inside it)."""
    rng = np.random.default_rng(np.random.SeedSequence([seed, block]))
    count = stop - start
    kind = sampler["kind"]
    if kind == "uniform":
        q = model.random_configuration(n=count, seed=int(rng.integers(2**62)))
    elif kind == "gaussian":
        center = np.tile(sampler["center"], (count, 1))
        q = model.integrate(center, rng.normal(0.0, sampler["std"], (count, model.nv)))
    else:
        q = np.asarray(sampler["q"][start:stop], dtype=np.float64)
    velocity, torque = limits
    return {
        "q": np.asarray(q, dtype=np.float64),
        "v": rng.uniform(-velocity, velocity, (count, model.nv)),
        "a": rng.uniform(-DEFAULT_ACCELERATION, DEFAULT_ACCELERATION, (count, model.nv)),
        "tau_applied": rng.uniform(-torque, torque, (count, model.nv)),
    }


def _fill_chunk(model: _core.Model, out: str, form: str, index: int, chunk: int, n: int, quantities: Sequence[str], sampler: Any, seed: int) -> int:
    """Samples chunk `index`, evaluates the quantities, writes them and marks the chunk done."""
    start, stop = index * chunk, min((index + 1) * chunk, n)
    limits = _limits(model)
    first, last = start // SEED_BLOCK, (stop + SEED_BLOCK - 1) // SEED_BLOCK
    parts = [_block(model, sampler, limits, seed, b, b * SEED_BLOCK, min((b + 1) * SEED_BLOCK, n)) for b in range(first, last)]
    # the blocks overlapped draw whole, so a state's values do not depend on where chunks end
    offset = first * SEED_BLOCK
    arrays = {key: np.concatenate([p[key] for p in parts])[start - offset : stop - offset] for key in parts[0]}
    q, v, a, tau = arrays["q"], arrays["v"], arrays["a"], arrays["tau_applied"]
    for name in quantities:
        arrays[name] = QUANTITIES[name][0](model, q, v, a, tau)
    if form == "parquet":
        _write_part(Path(out), index, arrays)
    else:
        import zarr

        store = zarr.open_group(out, mode="r+")
        for name, values in arrays.items():
            store[name][start:stop] = values
        store["done"][index] = True
    return index


#: A Parquet dataset's provenance, beside its parts (readers skip names starting with "_").
PARQUET_ATTRIBUTES = "_robodyn.json"


def _part(directory: Path, index: int) -> Path:
    """Where chunk `index` of a Parquet dataset goes: names that sort in chunk order."""
    return directory / f"part-{index:06d}.parquet"


def _write_part(directory: Path, index: int, arrays: dict[str, FloatArray]) -> None:
    """Chunk `index` as one Parquet file, a fixed-size list column per quantity; written under a
    temporary name and renamed, so that a part that exists is complete (that marks it done)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    columns = {
        name: pa.FixedSizeListArray.from_arrays(pa.array(values.reshape(-1)), values.shape[1])
        for name, values in arrays.items()
    }
    attributes = (directory / PARQUET_ATTRIBUTES).read_text()
    table = pa.table(columns).replace_schema_metadata({"robodyn": attributes})
    partial = directory / f".{_part(directory, index).name}.{os.getpid()}.partial"
    # uncompressed, as the Zarr arrays: sampled floats barely compress
    pq.write_table(table, partial, compression="none")
    os.replace(partial, _part(directory, index))


def read_dataset(path: str | Path) -> dict[str, FloatArray]:
    """A dataset written by `dataset` (a Zarr store or a Parquet folder) as arrays: `q`, `v`,
    `a`, `tau_applied` and the quantities, each (n, ...); raises if chunks are missing."""
    path = Path(_arguments.path("path", path))
    if (path / PARQUET_ATTRIBUTES).exists():
        import pyarrow.parquet as pq

        attributes = json.loads((path / PARQUET_ATTRIBUTES).read_text())
        chunks = -(-attributes["n"] // attributes["chunk"])
        missing = [k for k in range(chunks) if not _part(path, k).exists()]
        if missing:
            raise ValueError(f"{path}: chunks {missing} are missing; complete it with dataset(..., resume=True)")
        table = pq.read_table([str(_part(path, k)) for k in range(chunks)])
        return {
            name: column.combine_chunks().flatten().to_numpy().reshape(len(table), -1)
            for name, column in zip(table.column_names, table.columns)
        }
    import zarr

    store = zarr.open_group(str(path), mode="r")
    flags = np.asarray(store["done"][:])
    if not flags.all():
        raise ValueError(f"{path}: chunks {np.flatnonzero(~flags).tolist()} are missing; complete it with dataset(..., resume=True)")
    return {name: np.asarray(store[name][:]) for name in store.array_keys() if name != "done"}


def _describe(sampler: Any) -> dict[str, Any]:
    """The sampler as metadata (a user array by its hash)."""
    if sampler["kind"] == "array":
        return {"kind": "array", "sha256": hashlib.sha256(np.ascontiguousarray(sampler["q"]).tobytes()).hexdigest()}
    if sampler["kind"] == "gaussian":
        return {"kind": "gaussian", "center": list(map(float, sampler["center"])), "std": float(sampler["std"])}
    return {"kind": "uniform"}


def _sampler(model: _core.Model, sampler: Any, n: int, center: Any, std: float) -> dict[str, Any]:
    """The sampler argument checked: "uniform", "gaussian" (around `center`) or an (n, nq) array."""
    center = _arguments.array("center", model.neutral() if center is None else center, (model.nq,))
    std = _arguments.positive("std", std)
    if isinstance(sampler, str):
        if sampler == "uniform":
            return {"kind": "uniform"}
        if sampler == "gaussian":
            return {"kind": "gaussian", "center": center, "std": std}
        raise ValueError(f"argument 'sampler': expected 'uniform', 'gaussian' or an (n, nq) array, got {sampler!r}")
    q = _arguments.numbers("sampler", sampler)
    if q.shape != (n, model.nq):
        raise ValueError(f"argument 'sampler': expected an array of shape ({n}, {model.nq}), got {q.shape}")
    return {"kind": "array", "q": q}


def dataset(
    model: _core.Model,
    n: int,
    quantities: Sequence[str] = ("tau",),
    sampler: Any = "uniform",
    seed: int = 0,
    chunk: int = 65_536,
    out: str | Path = "dataset.zarr",
    client: Any = None,
    resume: bool = False,
    center: Any = None,
    std: float = 0.1,
    progress: Callable[[float], None] | None = None,
    format: str | None = None,
) -> Any:
    """Samples `n` states and writes them with the requested `quantities` to `out`: a Zarr store
    (returned, a `zarr.Group`) or, with `format="parquet"` or `out` ending in ".parquet", a
    folder of Parquet files, one per chunk, a fixed-size list column per quantity (returned as a
    `pyarrow.dataset.Dataset`; vector quantities only). `read_dataset(out)` reads either back
    as NumPy arrays.

    - States: q by `sampler` — "uniform" (within the position limits, [-π, π] where none, random
      rotations for ball and free joints), "gaussian" (around `center`, the neutral
      configuration by default, with standard deviation `std` in the tangent space) or an (n, nq)
      array; v uniform within the velocity limits (±1 where none), a uniform in ±10, and an
      applied τ uniform within the effort limits (±10 where none), stored as `q`, `v`, `a`,
      `tau_applied`.
    - `quantities`: any of "tau" (inverse dynamics at q, v, a), "M" (mass matrix), "g" (gravity),
      "qdd" (forward dynamics at q, v, tau_applied).
    - `chunk`: states per task and per Zarr chunk, any positive number; `seed` and the sampler
      decide the store, whatever the chunk size and the number of workers (states are drawn in
      blocks of `SEED_BLOCK`, each chunk drawing the blocks it overlaps).
    - `client`: a `dask.distributed.Client` (a local cluster or a scheduler's address); without
      one the chunks run here, one after the other, by the same code.
    - `resume=True` continues a store left incomplete by an interrupted run (same arguments),
      computing only the chunks not marked done.
    - `progress`, if given, is called with the fraction of chunks done after each chunk.
    The store's attributes (Parquet: each file's metadata under "robodyn" and `_robodyn.json`)
    record the model's name and content hash, the robodyn version, the seed, the sampler, the
    chunk size and the quantities.
    """
    _arguments.robot_model("model", model)
    n = _arguments.count("n", n)
    if isinstance(chunk, bool) or not isinstance(chunk, (int, np.integer)) or chunk < 1:
        raise ValueError(f"argument 'chunk': expected a positive whole number of states, got {chunk!r}")
    chunk = int(chunk)
    if isinstance(quantities, str) or not isinstance(quantities, Sequence):
        raise _arguments.bad("quantities", f"a list of names among {sorted(QUANTITIES)}", repr(quantities))
    unknown = [q for q in quantities if q not in QUANTITIES]
    if unknown:
        raise ValueError(f"argument 'quantities': expected names among {sorted(QUANTITIES)}, got {unknown}")
    path = _arguments.path("out", out)
    seed = _arguments.count("seed", seed, 0)
    resume = _arguments.flag("resume", resume)
    _arguments.callback("progress", progress)
    _client(client)
    form = _format(out, format, model, quantities)
    spec = _sampler(model, sampler, n, center, std)
    model_bytes = pickle.dumps(model)
    attributes = {
        "model": model.name,
        "model_sha256": hashlib.sha256(model_bytes).hexdigest(),
        "robodyn_version": version("robodyn"),
        "seed": int(seed),
        "sampler": _describe(spec),
        "n": n,
        "chunk": int(chunk),
        "seed_block": SEED_BLOCK,
        "quantities": list(quantities),
    }
    chunks = (n + chunk - 1) // chunk
    shapes = {"q": (model.nq,), "v": (model.nv,), "a": (model.nv,), "tau_applied": (model.nv,)}
    shapes.update({name: QUANTITIES[name][1](model) for name in quantities})
    if resume:
        stored = _stored_attributes(path, form)
        differing = [key for key, value in attributes.items() if stored.get(key) != value]
        if differing:
            raise ValueError(f"argument 'resume': the store {path} was made with other {', '.join(differing)}")
    elif Path(path).exists():
        raise ValueError(f"argument 'out': {path} exists; pass resume=True to complete it, or remove it")
    else:
        _create(path, form, attributes, shapes, n, chunk, chunks)
    done = _done(path, form, chunks)
    todo = [k for k in range(chunks) if not done[k]]
    rest = (chunk, n, list(quantities), spec, int(seed))
    finished = chunks - len(todo)
    if client is None:
        # two chunks at a time, so that one's store writes overlap the other's sampling and
        # dynamics (both release the GIL); each writes only its own region and flag
        with ThreadPoolExecutor(max_workers=2) as pool:
            for _ in pool.map(lambda k: _fill_chunk(model, path, form, k, *rest), todo):
                finished += 1
                if progress is not None:
                    progress(finished / chunks)
    else:
        from dask.distributed import as_completed

        # the model goes to every worker once (it pickles), each chunk is one task; a fresh key
        # each call (hash=False): a worker restarted since an earlier scatter lacks the old one
        remote = client.scatter(model, broadcast=True, hash=False)
        futures = [client.submit(_fill_chunk, remote, path, form, k, *rest, pure=False) for k in todo]
        for future in as_completed(futures):
            future.result()
            finished += 1
            if progress is not None:
                progress(finished / chunks)
    if form == "parquet":
        import pyarrow.dataset

        return pyarrow.dataset.dataset(path, format="parquet")
    import zarr

    return zarr.open_group(path, mode="r")


def _format(out: str | Path, format: str | None, model: _core.Model, quantities: Sequence[str]) -> str:
    """"zarr" or "parquet", from `format` or else `out`'s suffix; Parquet holds vectors only."""
    form = format if format is not None else ("parquet" if Path(out).suffix == ".parquet" else "zarr")
    if not isinstance(form, str) or form not in ("zarr", "parquet"):
        raise ValueError(f"argument 'format': expected 'zarr' or 'parquet', got {format!r}")
    matrices = [name for name in quantities if len(QUANTITIES[name][1](model)) > 1]
    if form == "parquet" and matrices:
        raise ValueError(
            f"argument 'quantities': {matrices} are matrices and Parquet holds vector quantities; "
            "write them to a Zarr store (an 'out' not ending in .parquet)"
        )
    return form


def _create(path: str, form: str, attributes: dict[str, Any], shapes: dict[str, tuple[int, ...]], n: int, chunk: int, chunks: int) -> None:
    """A new, empty store: the Zarr arrays and chunk flags, or the Parquet folder and its
    attributes file."""
    if form == "parquet":
        Path(path).mkdir(parents=True)
        (Path(path) / PARQUET_ATTRIBUTES).write_text(json.dumps(attributes))
        return
    import zarr

    store = zarr.open_group(path, mode="w")
    for name, shape in shapes.items():
        # uncompressed: sampled floats barely compress, and compressing them cost 5x the dynamics
        store.create_array(name, shape=(n, *shape), chunks=(chunk, *shape), dtype="float64", compressors=None)
    # one Zarr chunk per flag: workers marking different chunks never rewrite each other's
    store.create_array("done", shape=(chunks,), chunks=(1,), dtype="bool", fill_value=False)
    store.attrs.update(attributes)


def _stored_attributes(path: str, form: str) -> dict[str, Any]:
    """The attributes an existing store was made with."""
    if form == "parquet":
        return dict(json.loads((Path(path) / PARQUET_ATTRIBUTES).read_text()))
    import zarr

    return dict(zarr.open_group(path, mode="r").attrs)


def _done(path: str, form: str, chunks: int) -> list[bool]:
    """Which chunks are written: a flag per chunk in Zarr, a part file per chunk in Parquet."""
    if form == "parquet":
        return [_part(Path(path), k).exists() for k in range(chunks)]
    import zarr

    return [bool(x) for x in zarr.open_group(path, mode="r")["done"][:]]


def _client(client: Any) -> None:
    """None or a Dask client."""
    if client is not None and not (hasattr(client, "submit") and hasattr(client, "scatter")):
        raise _arguments.bad("client", "None or a dask.distributed.Client", repr(client))


def _rollouts(model: _core.Model, q0: FloatArray, v0: FloatArray, options: dict[str, Any]) -> list[Any]:
    """One task: a batch of rollouts, in parallel on the worker's cores."""
    from robodyn.simulation import simulate

    return list(simulate(model, q0, v0, **options))


def simulate_many(
    model: _core.Model,
    q0: Any,
    v0: Any = None,
    client: Any = None,
    per_task: int = 64,
    out: str | Path | None = None,
    progress: Callable[[float], None] | None = None,
    **options: Any,
) -> Any:
    """Rollouts from every row of `q0` (N, nq) and `v0` (N, nv; zeros by default), in tasks of
    `per_task` rollouts spread over the workers of a `dask.distributed` `client`, each task
    simulating its rollouts in parallel on its worker's cores (`robodyn.simulate`); without a
    client the tasks run here. `options` are `robodyn.simulate`'s (t_end, dt, integrator,
    controller, ...; the controller and wrenches must pickle: the native controller
    descriptions do, a Python callable must be a module-level function). `progress`, if given,
    is called with the fraction of rollouts done after each task.

    Returns the N trajectories in order (each equal to `robodyn.simulate`'s), or, with `out`, writes
    a Zarr store with `t` (T,) and `q`, `v`, `a`, `tau` (N, T, ...) and returns it.
    """
    _arguments.robot_model("model", model)
    q0 = np.atleast_2d(_arguments.numbers("q0", q0))
    if q0.ndim != 2 or q0.shape[1] != model.nq:
        raise ValueError(f"argument 'q0': expected an array of shape (N, {model.nq}), got {q0.shape}")
    count = q0.shape[0]
    v0 = np.zeros((count, model.nv)) if v0 is None else np.atleast_2d(_arguments.numbers("v0", v0))
    if v0.shape != (count, model.nv):
        raise ValueError(f"argument 'v0': expected an array of shape ({count}, {model.nv}), got {v0.shape}")
    per_task = _arguments.count("per_task", per_task)
    _arguments.callback("progress", progress)
    _client(client)
    if out is not None and Path(_arguments.path("out", out)).exists():
        raise ValueError(f"argument 'out': {out} exists; remove it or choose another")
    groups = [(start, min(start + per_task, count)) for start in range(0, count, per_task)]
    parts: list[list[Any]] = [[] for _ in groups]
    finished = 0

    def record(task: int, part: list[Any]) -> None:
        nonlocal finished
        parts[task] = part
        finished += len(part)
        if progress is not None:
            progress(finished / count)

    if client is None:
        for task, (a, b) in enumerate(groups):
            record(task, _rollouts(model, q0[a:b], v0[a:b], options))
    else:
        from dask.distributed import as_completed

        remote = client.scatter(model, broadcast=True, hash=False)
        futures = {client.submit(_rollouts, remote, q0[a:b], v0[a:b], options, pure=False): task for task, (a, b) in enumerate(groups)}
        for future in as_completed(futures):
            record(futures[future], future.result())
    trajectories = [trajectory for part in parts for trajectory in part]
    if out is None:
        return trajectories
    import zarr

    store = zarr.open_group(str(out), mode="w")
    store.create_array("t", data=trajectories[0].t)
    for name in ("q", "v", "a", "tau"):
        store.create_array(name, data=np.stack([getattr(t, name) for t in trajectories]))
    store.attrs.update({"model": model.name, "rollouts": count, "robodyn_version": version("robodyn")})
    return store
