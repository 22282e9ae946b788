"""MJCF `<keyframe>`: each key in robodyn's coordinates, compared with MuJoCo's compiled `key_qpos`,
`key_qvel`, `key_ctrl` and `key_time` through `MujocoLayout`; keys of the wrong size refused as
MuJoCo refuses them; keyframes pickled with the model."""

from __future__ import annotations

import pickle

import mujoco
import numpy as np
import pytest
from conftest import REPOSITORY

import robodyn
from robodyn.convert import MujocoLayout

#: MuJoCo keeps the file's numbers and robodyn reorders and normalises them: the same values
#: up to the quaternion's normalisation and the free joint's rotation of its velocity.
LAYOUT_TOLERANCE = 1e-14

FILES = [
    REPOSITORY / "testdata" / "mjcf" / "cassie_nomesh.xml",
    REPOSITORY / "testdata" / "mjcf" / "panda_nomesh.xml",
]

#: A turned free body with a ball joint and a hinge below it, two actuators, and three keys: one
#: moving, one with nothing (qpos0), one whose quaternions are not of unit norm.
KEYED = (REPOSITORY / "testdata" / "mjcf" / "keyframes.xml").read_text()


def keyed():
    """The model of KEYED, read without a warning but that its geoms do not collide yet."""
    model = robodyn.load_mjcf_string(KEYED)
    assert all("robodyn.simulate feels them only with integrator='mujoco'" in w for w in model.warnings), model.warnings
    return model


def mujoco_keys(model, compiled):
    """MuJoCo's keys in robodyn's coordinates: (name, time, q, v, ctrl) each."""
    layout = MujocoLayout(model, compiled)
    keys = []
    for k in range(compiled.nkey):
        q = layout.q_from_mujoco(compiled.key_qpos[k])
        # MuJoCo normalises a quaternion where it uses it; robodyn where it reads it
        for kind, iq in zip(model.joint_types, model.joint_idx_q):
            start = {"free": iq + 3, "spherical": iq}.get(kind)
            if start is not None:
                q[start : start + 4] /= np.linalg.norm(q[start : start + 4])
        v = layout.v_from_mujoco(q, compiled.key_qvel[k])
        keys.append((compiled.key(k).name, compiled.key_time[k], q, v, compiled.key_ctrl[k]))
    return keys


def assert_keys_match(model, compiled):
    assert len(model.keyframes) == compiled.nkey
    for ours, (name, time, q, v, ctrl) in zip(model.keyframes, mujoco_keys(model, compiled)):
        assert (ours.name, ours.time) == (name, time)
        np.testing.assert_allclose(ours.q, q, rtol=0, atol=LAYOUT_TOLERANCE)
        np.testing.assert_allclose(ours.v, v, rtol=0, atol=LAYOUT_TOLERANCE)
        np.testing.assert_array_equal(ours.ctrl, ctrl)


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_keyframes_equal_mujocos(path):
    model = robodyn.load(path)
    assert model.keyframes, "the file has keys"
    assert not [w for w in model.warnings if "keyframe" in w or "<key" in w]
    assert_keys_match(model, mujoco.MjModel.from_xml_path(str(path)))


def test_a_turned_free_body_moving_and_keys_with_nothing():
    model = keyed()
    compiled = mujoco.MjModel.from_xml_string(KEYED)
    assert_keys_match(model, compiled)
    # a key with nothing is qpos0: the free body where the file draws it, the hinge at its ref
    np.testing.assert_array_equal(model.keyframe("qpos0").q, model.neutral())
    assert model.keyframe("qpos0").q[-1] == pytest.approx(np.radians(10), abs=1e-15)
    # by index, as MuJoCo numbers its keys
    assert model.keyframe(2).name == "unnormalised"
    np.testing.assert_allclose(model.keyframe(2).q[3:7], [0, 0, 0, 1], atol=0)


def test_simulation_starts_from_a_keyframe():
    model = keyed()
    key = model.keyframe("moving")
    run = robodyn.simulate(model, key.q, key.v, t_end=1e-3, dt=1e-3)
    np.testing.assert_array_equal(run.q[0], key.q)
    np.testing.assert_array_equal(run.v[0], key.v)


def test_unknown_keys_and_wrong_sizes_are_refused_by_name():
    model = keyed()
    with pytest.raises(ValueError, match=r"argument 'key'.*'moving', 'qpos0', 'unnormalised'.*got 'home'"):
        model.keyframe("home")
    for key in (3, -1, True, 1.0):
        with pytest.raises(ValueError, match=r"argument 'key': expected a keyframe's name or an index below 3"):
            model.keyframe(key)
    with pytest.raises(ValueError, match=r"argument 'key': expected a keyframe of the model \(the model has none\)"):
        robodyn.load("ur5").keyframe("home")
    # as MuJoCo (4.0): a short key gives the first entries (the rest from qpos0, or zeros), a long
    # one is refused, by robodyn naming the element and the attribute
    short = KEYED.replace('<key name="qpos0"/>', '<key name="short" qpos="5 6 7" qvel="3" ctrl="1"/>')
    assert_keys_match(robodyn.load_mjcf_string(short), mujoco.MjModel.from_xml_string(short))
    for attribute, size in [("qpos", 13), ("qvel", 11), ("ctrl", 3)]:
        wrong = " ".join(["0.5"] * size)
        text = KEYED.replace('<key name="qpos0"/>', f'<key name="bad" {attribute}="{wrong}"/>')
        with pytest.raises(ValueError):
            mujoco.MjModel.from_xml_string(text)
        with pytest.raises(ValueError, match=rf"<key[^>]*> \(line \d+.*attribute '{attribute}': expected at most {size - 1} numbers, got {size}"):
            robodyn.load_mjcf_string(text)


def test_keyframes_pickle_alone_and_with_their_model():
    model = keyed()
    key = model.keyframe("moving")
    back = pickle.loads(pickle.dumps(key))
    assert (back.name, back.time) == (key.name, key.time)
    for field in ("q", "v", "ctrl"):
        np.testing.assert_array_equal(getattr(back, field), getattr(key, field))
    again = pickle.loads(pickle.dumps(model))
    np.testing.assert_array_equal(again.keyframe("moving").v, key.v)
    # a keyframe hands out copies: changing one leaves the key as it was
    key.q[0] = 99.0
    assert model.keyframe("moving").q[0] == 0.1
    with pytest.raises(ValueError, match="argument 'q': expected a sequence of finite numbers"):
        robodyn.Keyframe("k", 0.0, [np.nan], [], [])
