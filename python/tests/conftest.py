"""Shared fixtures: the robots the cross-checks use and the tolerances."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest

import robodyn

#: Field-by-field agreement with Pinocchio, relative to the field's largest magnitude (or 1).
CROSS_CHECK_TOLERANCE = 1e-9
#: Identities between robodyn's own algorithms.
IDENTITY_TOLERANCE = 1e-10

REPOSITORY = Path(__file__).resolve().parents[2]
REFERENCE_DIR = REPOSITORY / "testdata" / "reference"

#: Robots from example-robot-data cross-checked against Pinocchio: name -> (path under robots/, floating base)
ROBOTS = {
    "ur5": ("ur_description/urdf/ur5_robot.urdf", False),
    "panda": ("panda_description/urdf/panda.urdf", False),
    "talos": ("talos_data/robots/talos_full_v2.urdf", True),
    "solo12": ("solo_description/robots/solo12.urdf", True),
}


def assert_close(actual, expected, tolerance, label=""):
    """|actual - expected| <= tolerance * max(1, max|expected|), entry by entry."""
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    assert actual.shape == expected.shape, f"{label}: shape {actual.shape} vs {expected.shape}"
    scale = max(1.0, float(np.max(np.abs(expected))) if expected.size else 1.0)
    error = float(np.max(np.abs(actual - expected))) if expected.size else 0.0
    assert error <= tolerance * scale, f"{label}: max error {error:.3e} > {tolerance * scale:.3e}"


@pytest.fixture(scope="session")
def robots_dir() -> Path:
    """example-robot-data's robots folder (a test dependency)."""
    folder = robodyn._example_robot_data_dir()
    assert folder is not None, "example-robot-data is a test dependency: pip install '.[test]'"
    return folder


def pinocchio_model(path, floating_base: bool):
    """Pinocchio's model of a URDF, on a free-flyer root joint when `floating_base`."""
    import pinocchio as pin

    if floating_base:
        return pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    return pin.buildModelFromUrdf(str(path))


def pinocchio_forces(model, pin_model, f_ext):
    """robodyn's (nbodies, 6) body-frame wrenches as Pinocchio's per-joint forces."""
    import pinocchio as pin

    forces = [pin.Force.Zero() for _ in range(pin_model.njoints)]
    for joint_name, wrench in zip(model.joint_names, f_ext):
        forces[pin_model.getJointId(joint_name)] = pin.Force(wrench[:3], wrench[3:])
    return forces


@pytest.fixture(scope="module", params=sorted(ROBOTS))
def pinocchio_robot(request, robots_dir):
    """(name, robodyn model, Pinocchio model, PinocchioLayout) for each example-robot-data robot."""
    from robodyn.convert import PinocchioLayout

    path, floating_base = ROBOTS[request.param]
    model = robodyn.load(robots_dir / path, floating_base=floating_base)
    pin_model = pinocchio_model(robots_dir / path, floating_base)
    return request.param, model, pin_model, PinocchioLayout(model, pin_model)


def load_reference(name: str) -> dict:
    return json.loads((REFERENCE_DIR / f"{name}.json").read_text())


def load_quietly(path=None, text=None):
    """A model from a file or an MJCF string, its ModelWarnings silenced."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", robodyn.ModelWarning)
        return robodyn.load(path) if text is None else robodyn.load_mjcf_string(text)


def assert_refused_as_in_mujoco(text, match):
    """robodyn refuses the MJCF string `text` with a ValueError matching `match`, and MuJoCo refuses
    it too."""
    import mujoco

    with pytest.raises(ValueError, match=match):
        load_quietly(None, text)
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_string(text)
