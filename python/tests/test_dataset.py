"""robodyn.dataset: sampled states and their dynamics in a Zarr store, here or on a Dask cluster
(issue 17): values equal to the batched calls, the same store for any chunking and any workers,
resumable, and complete after a worker dies."""

import json
import os
import threading
import time

import numpy as np
import pytest
import robodyn
import robodyn.datasets
import zarr
from dask.distributed import Client, LocalCluster

ARRAYS = ["q", "v", "a", "tau_applied", "tau", "M", "qdd"]  # what `make` stores


def make(tmp_path, name, **options):
    m = options.pop("model", None) or robodyn.load("ur5")
    arguments = dict(n=1500, quantities=["tau", "M", "qdd"], seed=5, chunk=512)
    arguments.update(options)
    return robodyn.dataset(m, out=str(tmp_path / name), **arguments)


def assert_same_store(a, b):
    """The same samples and values (the chunk flags differ with the chunking)."""
    names = sorted(set(a.array_keys()) - {"done"})
    assert names == sorted(set(b.array_keys()) - {"done"})
    for name in names:
        np.testing.assert_array_equal(a[name][:], b[name][:], err_msg=name)


@pytest.fixture(scope="module")
def client():
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with Client(cluster) as c:
            yield c


def test_a_store_holds_the_batched_calls_and_its_provenance(tmp_path):
    m = robodyn.load("ur5")
    store = make(tmp_path, "a.zarr", model=m)
    q, v, a, applied = (store[k][:] for k in ["q", "v", "a", "tau_applied"])
    assert q.shape == (1500, 6) and store["M"].shape == (1500, 6, 6) and store["done"][:].all()
    np.testing.assert_array_equal(store["tau"][:], m.inverse_dynamics(q, v, a))
    np.testing.assert_array_equal(store["M"][:], m.mass_matrix(q))
    np.testing.assert_array_equal(store["qdd"][:], m.forward_dynamics(q, v, applied))
    lower, upper = m.lower_position_limit, m.upper_position_limit
    assert np.all((q >= lower) & (q <= upper)) and np.all(np.abs(v) <= m.velocity_limit)
    attributes = dict(store.attrs)
    assert attributes["model"] == m.name and attributes["seed"] == 5 and attributes["n"] == 1500
    assert attributes["sampler"] == {"kind": "uniform"} and len(attributes["model_sha256"]) == 64
    assert attributes["robodyn_version"] and attributes["quantities"] == ["tau", "M", "qdd"]


def test_the_store_does_not_depend_on_the_chunking(tmp_path):
    assert_same_store(make(tmp_path, "a.zarr", chunk=256), make(tmp_path, "b.zarr", chunk=1024))
    other_seed = make(tmp_path, "c.zarr", seed=6)
    assert not np.array_equal(other_seed["q"][:], make(tmp_path, "d.zarr")["q"][:])


#: States for the chunkings below: not a multiple of 256, 1000 or 5000, so each last chunk is short.
UNEVEN_N = 5300


def test_chunks_of_any_size_give_the_same_store(tmp_path):
    # chunk edges inside seed blocks (5000, 1000, 77), on them (256), and one chunk of all states
    options = dict(n=UNEVEN_N, quantities=["tau", "qdd"])
    reference = make(tmp_path, "256.zarr", chunk=256, **options)
    for chunk in (5000, 1000, 77, UNEVEN_N):
        store = make(tmp_path, f"{chunk}.zarr", chunk=chunk, **options)
        assert store["q"].chunks == (chunk, 6) and store["done"].shape == (-(-UNEVEN_N // chunk),)
        assert_same_store(store, reference)
    expected = robodyn.read_dataset(tmp_path / "256.zarr")
    for chunk in (5000, 1000):
        make(tmp_path, f"{chunk}.parquet", chunk=chunk, **options)
        written = robodyn.read_dataset(tmp_path / f"{chunk}.parquet")
        for name, values in expected.items():
            np.testing.assert_array_equal(written[name], values, err_msg=f"{name}, Parquet chunks of {chunk}")


def test_the_gaussian_and_given_samplers_do_not_depend_on_the_chunking(tmp_path):
    q = robodyn.load("ur5").random_configuration(n=UNEVEN_N, seed=2)
    for label, sampler in (("gaussian", "gaussian"), ("given", q)):
        options = dict(n=UNEVEN_N, quantities=["tau"], sampler=sampler)
        assert_same_store(make(tmp_path, f"{label}-1000.zarr", chunk=1000, **options),
                          make(tmp_path, f"{label}-256.zarr", chunk=256, **options))


def test_a_store_in_uneven_chunks_resumes_to_the_same_values(tmp_path, monkeypatch):
    options = dict(n=UNEVEN_N, quantities=["tau"], chunk=1000)
    complete = make(tmp_path, "full.zarr", **options)
    make(tmp_path, "partial.zarr", **options)
    make(tmp_path, "partial.parquet", **options)
    # chunk 1, states 1000-1999, starts and ends inside seed blocks 3 and 7
    writable = zarr.open_group(str(tmp_path / "partial.zarr"), mode="r+")
    writable["done"][1] = False
    for name in ("q", "v", "a", "tau_applied", "tau"):
        writable[name][1000:2000] = 0.0
    # chunk 5, the short last one (states 5000-5299)
    (tmp_path / "partial.parquet" / "part-000005.parquet").unlink()
    computed = []
    fill = robodyn.datasets._fill_chunk
    monkeypatch.setattr(robodyn.datasets, "_fill_chunk", lambda *a: computed.append(a[3]) or fill(*a))
    assert_same_store(make(tmp_path, "partial.zarr", resume=True, **options), complete)
    make(tmp_path, "partial.parquet", resume=True, **options)
    assert computed == [1, 5]
    resumed = robodyn.read_dataset(tmp_path / "partial.parquet")
    for name in resumed:
        np.testing.assert_array_equal(resumed[name], complete[name][:], err_msg=name)


def test_gaussian_and_given_samplers(tmp_path):
    m = robodyn.load("ur5")
    center = m.neutral() + 0.3
    store = make(tmp_path, "g.zarr", model=m, sampler="gaussian", center=center, std=0.05)
    spread = store["q"][:] - center
    assert abs(spread.std() - 0.05) < 0.005 and abs(spread.mean()) < 0.005
    q = m.random_configuration(n=1500, seed=1)
    given = make(tmp_path, "q.zarr", model=m, sampler=q)
    np.testing.assert_array_equal(given["q"][:], q)
    assert dict(given.attrs)["sampler"]["kind"] == "array"


def test_bad_arguments_are_named(tmp_path):
    m = robodyn.load("ur5")
    for chunk in (0, -256, 2.5, "512"):
        with pytest.raises(ValueError, match=f"argument 'chunk': expected a positive whole number of states, got {chunk!r}"):
            make(tmp_path, "x.zarr", chunk=chunk)
    with pytest.raises(ValueError, match="argument 'quantities'"):
        make(tmp_path, "x.zarr", quantities=["torque"])
    with pytest.raises(ValueError, match="argument 'sampler'"):
        make(tmp_path, "x.zarr", sampler="sobol")
    with pytest.raises(ValueError, match=r"argument 'sampler': expected an array of shape \(1500, 6\)"):
        make(tmp_path, "x.zarr", sampler=np.zeros((3, 6)))
    make(tmp_path, "y.zarr")
    with pytest.raises(ValueError, match="argument 'out': .* exists; pass resume=True"):
        make(tmp_path, "y.zarr")
    with pytest.raises(ValueError, match="argument 'resume': .* made with other seed"):
        make(tmp_path, "y.zarr", seed=9, resume=True)
    assert m.nv == 6


def test_an_interrupted_store_resumes_without_recomputing_finished_chunks(tmp_path, monkeypatch):
    complete = make(tmp_path, "full.zarr")
    partial = make(tmp_path, "partial.zarr")
    # as a run stopped after chunks 0 and 2: chunk 1 never written, never marked done
    writable = zarr.open_group(str(tmp_path / "partial.zarr"), mode="r+")
    writable["done"][1] = False
    for name in ARRAYS:
        writable[name][512:1024] = 0.0
    computed = []
    fill = robodyn.datasets._fill_chunk
    monkeypatch.setattr(robodyn.datasets, "_fill_chunk", lambda *a: computed.append(a[3]) or fill(*a))
    resumed = make(tmp_path, "partial.zarr", resume=True)
    assert computed == [1]
    assert_same_store(resumed, complete)
    assert partial["done"][:].all()


def test_a_dask_cluster_writes_the_same_store(tmp_path, client):
    assert_same_store(make(tmp_path, "dask.zarr", client=client), make(tmp_path, "here.zarr"))


def test_a_worker_killed_mid_run_leaves_a_complete_equal_store(tmp_path, client):
    talos = robodyn.load("talos_full_v2.urdf", floating_base=True)
    options = dict(model=talos, n=256 * 40, chunk=256, quantities=["tau", "M"])
    result = {}
    run = threading.Thread(target=lambda: result.setdefault("store", make(tmp_path, "killed.zarr", client=client, **options)))
    run.start()
    done_path = str(tmp_path / "killed.zarr")
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        try:
            if zarr.open_group(done_path, mode="r")["done"][:].any():
                break
        except Exception:
            pass
        time.sleep(0.02)
    finished_before = int(zarr.open_group(done_path, mode="r")["done"][:].sum())
    victim = sorted(client.scheduler_info()["workers"])[0]
    try:
        client.run(os._exit, 1, workers=[victim])
    except Exception:
        pass  # the worker died before it could answer
    run.join(timeout=300)
    # the worker died with chunks still to do, and the run finished them all anyway
    assert 0 < finished_before < 40, finished_before
    store = result["store"]
    assert store["done"][:].all()
    assert_same_store(store, make(tmp_path, "unharmed.zarr", **options))


def test_the_dataset_command(tmp_path):
    from robodyn.cli import main

    out = str(tmp_path / "cli.zarr")
    assert main(["dataset", "ur5", "--n", "2e3", "--out", out, "--quantities", "tau", "M", "--chunk", "512",
                 "--no-progress"]) == 0
    store = zarr.open_group(out, mode="r")
    assert store["M"].shape == (2000, 6, 6) and store["done"][:].all()
    assert_same_store(store, make(tmp_path, "api.zarr", n=2000, quantities=["tau", "M"], seed=0))
    assert main(["dataset", "ur5", "--n", "1.5", "--out", out]) == 2
    assert main(["dataset", "ur5", "--n", "2e3", "--out", out]) == 2


def test_rollouts_spread_over_workers_equal_the_local_batch(tmp_path, client):
    m = robodyn.load("ur5")
    q0 = m.random_configuration(n=7, seed=3)
    options = dict(t_end=0.2, dt=1e-3, controller=robodyn.GravityCompensation())
    here = robodyn.simulate(m, q0, **options)
    for spread in (robodyn.simulate_many(m, q0, client=client, per_task=3, **options),
                   robodyn.simulate_many(m, q0, per_task=2, **options)):
        assert len(spread) == 7
        for one, other in zip(here, spread):
            for name in ("t", "q", "v", "a", "tau"):
                np.testing.assert_array_equal(getattr(other, name), getattr(one, name), err_msg=name)
    store = robodyn.simulate_many(m, q0, client=client, per_task=4, out=str(tmp_path / "r.zarr"), **options)
    assert store["q"].shape == (7, len(here[0].t), 6)
    np.testing.assert_array_equal(store["tau"][3], here[3].tau)
    with pytest.raises(ValueError, match=r"argument 'q0': expected an array of shape \(N, 6\)"):
        robodyn.simulate_many(m, np.zeros((2, 5)), **options)


def test_parquet_files_hold_the_same_vectors_as_a_zarr_store(tmp_path, client):
    vectors = dict(quantities=["tau", "qdd", "g"])
    store = robodyn.read_dataset(make(tmp_path, "a.zarr", **vectors).store.root)
    here = make(tmp_path, "a.parquet", **vectors)
    assert sorted(here.files) == [str(tmp_path / "a.parquet" / f"part-00000{k}.parquet") for k in range(3)]
    # a column per quantity, the provenance in every file; the same values for any chunking and workers
    assert here.schema.names == ["q", "v", "a", "tau_applied", "tau", "qdd", "g"]
    provenance = json.loads(here.schema.metadata[b"robodyn"])
    assert provenance["seed"] == 5 and provenance["quantities"] == ["tau", "qdd", "g"]
    make(tmp_path, "b.parquet", chunk=1024, client=client, **vectors)
    for name in ("a.parquet", "b.parquet"):
        arrays = robodyn.read_dataset(tmp_path / name)
        assert sorted(arrays) == sorted(store)
        for name, values in store.items():
            np.testing.assert_array_equal(arrays[name], values, err_msg=name)
    m = robodyn.load("ur5")
    np.testing.assert_array_equal(store["g"], m.generalized_gravity(store["q"]))


def test_an_interrupted_parquet_dataset_resumes_and_matrices_are_refused(tmp_path, monkeypatch):
    make(tmp_path, "full.parquet", quantities=["tau"])
    complete = robodyn.read_dataset(tmp_path / "full.parquet")
    make(tmp_path, "partial.parquet", quantities=["tau"])
    (tmp_path / "partial.parquet" / "part-000001.parquet").unlink()
    with pytest.raises(ValueError, match=r"chunks \[1\] are missing"):
        robodyn.read_dataset(tmp_path / "partial.parquet")
    computed = []
    fill = robodyn.datasets._fill_chunk
    monkeypatch.setattr(robodyn.datasets, "_fill_chunk", lambda *a: computed.append(a[3]) or fill(*a))
    make(tmp_path, "partial.parquet", quantities=["tau"], resume=True)
    assert computed == [1]
    resumed = robodyn.read_dataset(tmp_path / "partial.parquet")
    for name, values in complete.items():
        np.testing.assert_array_equal(resumed[name], values, err_msg=name)
    with pytest.raises(ValueError, match=r"\['M'\] are matrices and Parquet holds vector quantities"):
        make(tmp_path, "m.parquet")
    with pytest.raises(ValueError, match="argument 'format': expected 'zarr' or 'parquet', got 'csv'"):
        make(tmp_path, "c.csv", format="csv")
    with pytest.raises(ValueError, match="the store .* was made with other seed"):
        make(tmp_path, "partial.parquet", quantities=["tau"], resume=True, seed=6)


def test_the_dataset_command_writes_parquet(tmp_path, capsys):
    from robodyn.cli import main

    out = tmp_path / "cli.parquet"
    assert main(["dataset", "ur5", "--n", "600", "--out", str(out), "--chunk", "256", "--no-progress"]) == 0
    assert "3 chunks" in capsys.readouterr().out
    assert robodyn.read_dataset(out)["tau"].shape == (600, 6)
    assert main(["dataset", "ur5", "--n", "600", "--out", str(tmp_path / "m.parquet"), "--quantities", "M"]) == 2
    assert "Parquet holds vector quantities" in capsys.readouterr().err


def test_rollouts_report_their_progress(client):
    m = robodyn.load("ur5")
    q0 = m.random_configuration(n=5, seed=3)
    for spread in (dict(client=client), {}):
        seen = []
        robodyn.simulate_many(m, q0, per_task=2, t_end=0.01, dt=1e-3, progress=seen.append, **spread)
        # after each of the three tasks (2, 2 and 1 rollouts, finishing in any order)
        assert len(seen) == 3 and sorted(seen) == seen and seen[-1] == 1.0 and 0 < seen[0] < 1
