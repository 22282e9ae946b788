"""Models pickle, deep-copy and cross to worker processes with every field, edits included
(issue 17's first part): the copies compute exactly what the original computes."""

import copy
import multiprocessing
import pickle
from pathlib import Path

import numpy as np
import pytest
import robodyn
from conftest import ROBOTS

TESTDATA = Path(__file__).resolve().parents[2] / "testdata"


def every_model(robots_dir):
    """The bundled models, example-robot-data's, and the test MJCF and DH files."""
    models = [robodyn.load(name) for name in robodyn.models()]
    models += [robodyn.load("ur5", floating_base=True)]
    for path, floating in ROBOTS.values():
        models.append(robodyn.load(robots_dir / path, floating_base=floating))
    for name in ("iiwa14.xml", "free_armature.xml", "mesh_inertia.xml", "ur5e_nomesh.xml", "reference_pose.xml"):
        models.append(robodyn.load(TESTDATA / "mjcf" / name))
    models.append(robodyn.load(TESTDATA / "dh" / "rpp_arm.toml"))
    return models


def edited(m):
    """`m` with every settable field changed from what its file gave."""
    rng = np.random.default_rng(len(m.joint_names))
    m.gravity = [0.3, -0.2, -7.5]
    m.armature = rng.uniform(0.01, 0.2, m.nv) if "free" not in m.joint_types else m.armature
    m.damping = rng.uniform(0.0, 0.5, m.nv)
    m.friction = rng.uniform(0.0, 0.1, m.nv)
    m.stiffness = rng.uniform(0.0, 2.0, m.nv)
    parameters = m.inertial_parameters.copy()
    parameters[:, 0] *= 1.1
    m.inertial_parameters = parameters
    return m


def outputs(m):
    """What a model computes at a few states: enough to tell two models apart."""
    q = m.random_configuration(n=5, seed=2)
    rng = np.random.default_rng(4)
    v, a = rng.uniform(-1, 1, (5, m.nv)), rng.uniform(-1, 1, (5, m.nv))
    return {
        "tau": m.inverse_dynamics(q, v, a),
        "M": m.mass_matrix(q),
        "poses": m.body_poses(q),
        "gravity": np.asarray(m.gravity),
        "passive": np.concatenate([m.armature, m.damping, m.friction, m.stiffness]),
        "parameters": m.inertial_parameters,
        "neutral": m.neutral(),
    }


def assert_same(a, b, label):
    assert a.name == b.name and a.joint_names == b.joint_names and a.frame_names == b.frame_names
    assert len(a.visuals) == len(b.visuals) and a.warnings == b.warnings, label
    for key, value in outputs(a).items():
        np.testing.assert_array_equal(outputs(b)[key], value, err_msg=f"{label}: {key}")


def test_every_model_pickles_and_deep_copies_with_its_edits(robots_dir):
    for m in every_model(robots_dir):
        m = edited(m)
        for label, copied in [
            ("pickle", pickle.loads(pickle.dumps(m))),
            ("pickle protocol 2", pickle.loads(pickle.dumps(m, protocol=2))),
            ("deepcopy", copy.deepcopy(m)),
            ("copy", copy.copy(m)),
        ]:
            assert copied is not m
            assert_same(m, copied, f"{m.name} {label}")


def torques(m, q):
    """Runs in a worker process."""
    return m.inverse_dynamics(q, np.zeros(m.nv), np.zeros(m.nv))


def test_a_model_goes_to_worker_processes():
    m = edited(robodyn.load("ur5"))
    states = list(m.random_configuration(n=4, seed=9))
    with multiprocessing.get_context("spawn").Pool(2) as pool:
        remote = pool.starmap(torques, [(m, q) for q in states])
    for q, tau in zip(states, remote):
        np.testing.assert_array_equal(tau, torques(m, q))


def test_bytes_of_another_format_or_damaged_are_refused():
    reader, (data,) = robodyn.load("pendulum").__reduce__()
    assert reader(data).name == "pendulum"
    with pytest.raises(ValueError, match="expected a robodyn model snapshot"):
        reader(b"a pickle of something else")
    other_format = bytearray(data)
    other_format[8] += 1
    with pytest.raises(ValueError, match=r"saved by robodyn .* \(model format \d+\).*load the model"):
        reader(bytes(other_format))
    with pytest.raises(ValueError, match="damaged"):
        reader(data[:-5])
