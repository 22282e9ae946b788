"""MuJoCo Menagerie models as published (meshes included, or left out where they are visual only),
read by robodyn and by MuJoCo: each either
agrees with MuJoCo (robodyn.crosscheck.mujoco_agreement: every body's compiled inertia exact or
within MuJoCo's compile noise, the dynamics at 1e-9 with robodyn's inertias in MuJoCo's model)
or fails with an error naming what robodyn does not support. The table in docs/menagerie.md lists the same results (scripts/menagerie_table.py)."""

from __future__ import annotations

import importlib.util
import warnings
from pathlib import Path

import mujoco
import numpy as np
import pytest

from test_actuators import FORCE_TOLERANCE, mujoco_actuator_forces
from test_actuators import states as actuated_states

import robodyn
from robodyn.crosscheck import DISAGREES, mujoco_agreement


#: Menagerie files kept in the repository (testdata/menagerie/README.md names the commit).
MENAGERIE = Path(__file__).resolve().parents[2] / "testdata" / "menagerie"
#: The testdata files kept without their visual meshes: MuJoCo reads them with their mesh geoms
#: removed, which every body's explicit <inertial> keeps out of the dynamics.
WITHOUT_MESHES = {
    "universal_robots_ur5e/ur5e.xml",
    "unitree_go2/go2.xml",
    "unitree_go2/scene.xml",
    "franka_emika_panda/mjx_panda.xml",
    "franka_emika_panda/mjx_single_cube.xml",
    "google_barkour_vb/scene_hfield_mjx.xml",
}


def package_folder(name: str) -> Path:
    """Where a test-data package is installed (found without importing it)."""
    spec = importlib.util.find_spec(name)
    assert spec is not None and spec.submodule_search_locations, f"{name} is a test dependency: run ./scripts/test"
    return Path(list(spec.submodule_search_locations)[0])


def mujoco_model(path: Path, file: str) -> mujoco.MjModel:
    """MuJoCo's model of the file; without its mesh geoms where the meshes are left out."""
    if file not in WITHOUT_MESHES:
        return mujoco.MjModel.from_xml_path(str(path))
    spec = mujoco.MjSpec.from_file(str(path))
    mesh = mujoco.mjtGeom.mjGEOM_MESH
    implicit = [body.name for body in spec.bodies[1:]
                if not body.explicitinertial and any(g.type == mesh for g in body.geoms)]
    assert not implicit, f"{file}: bodies {implicit} take their inertia from mesh geoms, so their meshes are needed"
    for geom in [g for g in spec.geoms if g.type == mujoco.mjtGeom.mjGEOM_MESH]:
        spec.delete(geom)
    for mesh in list(spec.meshes):
        spec.delete(mesh)
    return spec.compile()


#: (package, file) -> None when robodyn must agree with MuJoCo, else the error robodyn must give;
#: the package "testdata" is testdata/menagerie.
MODELS = {
    # unmodified Menagerie files
    ("testdata", "universal_robots_ur5e/ur5e.xml"): None,
    ("testdata", "unitree_go2/go2.xml"): None,
    ("testdata", "franka_emika_panda/mjx_panda.xml"): None,
    # bodies whose inertia comes from their mesh geoms
    ("testdata", "robotiq_2f85/2f85.xml"): None,
    # mjlab's versions of Menagerie's Unitree G1 humanoid and Go1 quadruped, and the i2rt YAM arm
    ("mjlab", "asset_zoo/robots/unitree_g1/xmls/g1.xml"): None,
    ("mjlab", "asset_zoo/robots/unitree_go1/xmls/go1.xml"): None,
    ("mjlab", "asset_zoo/robots/i2rt_yam/xmls/yam.xml"): None,
}


@pytest.mark.parametrize(("package", "file"), sorted(MODELS))
def test_published_model_loads_and_agrees_with_mujoco_or_names_what_is_missing(package, file):
    path = (MENAGERIE if package == "testdata" else package_folder(package)) / file
    mj = mujoco_model(path, file)
    expected_error = MODELS[(package, file)]
    if expected_error is not None:
        with pytest.raises(ValueError, match=expected_error):
            robodyn.load(path)
        return
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        model = robodyn.load(path)
    # what is not read is said (a model read whole warns of nothing but that contacts are not
    # computed yet)
    said = [str(w.message) for w in caught if issubclass(w.category, robodyn.ModelWarning)]
    assert all("not read" in message or "feels them only with integrator='mujoco'" in message for message in said), said
    # its active equality constraints are held
    assert len(model.constraints) == int(np.sum(mj.eq_active0))
    assert model.total_mass > 0
    assert model.nq == mj.nq and model.nv == mj.nv
    agreement = mujoco_agreement(model, mj, seed=1, states=2, name=file)
    assert agreement.verdict != DISAGREES, str(agreement)
    # its actuators give MuJoCo's qfrc_actuator where robodyn models each of them
    assert model.nu == mj.nu
    if model.nu and not [w for w in model.warnings if "exerts no force" in w]:
        q, v, ctrl = actuated_states(model, 3, seed=2)
        compiled = mujoco_model(path, file)  # as the file has it (the agreement changed mj's)
        for k in range(len(q)):
            expected = mujoco_actuator_forces(model, compiled, q[k], v[k], ctrl[k])
            scale = max(1.0, np.max(np.abs(expected)))
            assert np.max(np.abs(model.actuator_forces(q[k], v[k], ctrl[k]) - expected)) <= FORCE_TOLERANCE * scale
