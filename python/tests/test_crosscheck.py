"""robodyn.crosscheck.mujoco_agreement (issue 42, "honest agreement"): every body's compiled mass,
centre of mass and inertia tensor against MuJoCo's, the dynamics against MuJoCo's model with
robodyn's exact tensors put in, and a verdict that tells MuJoCo's compile noise from a real
disagreement."""

from __future__ import annotations

import importlib.util

import mujoco
import numpy as np
import pytest
from conftest import REPOSITORY

import robodyn
from robodyn.crosscheck import (
    COMPILED_TOLERANCE,
    DISAGREES,
    DYNAMICS_TOLERANCE,
    EXACT,
    MUJOCO_INERTIA_NOISE,
    WITHIN_NOISE,
    compare_bodies,
    measure_mujoco_inertia_noise,
    mujoco_agreement,
    with_robodyn_inertias,
)

TEST_MJCF = REPOSITORY / "testdata" / "mjcf"

#: A body whose inertia comes from a mesh (a tetrahedron, corners in 1/64ths: MuJoCo's tensor is
#: off by 2.4e-8 of its trace), one with a fullinertia of tilted axes (compiled exactly), and one
#: without joints that robodyn merges into its parent.
TILTED = """
<mujoco model="tilted">
  <asset>
    <mesh name="tetrahedron" face="0 2 1 0 1 3 0 3 2 1 2 3"
          vertex="0.015625 -0.03125 -0.09375 -0.125 -0.125 -0.125 -0.09375 0.125 -0.078125 0.046875 0.0625 -0.078125"/>
  </asset>
  <worldbody>
    <body name="upper" pos="0 0 1">
      <joint name="shoulder" axis="0 1 0"/>
      <geom type="mesh" mesh="tetrahedron" density="1000"/>
      <body name="lower" pos="0 0 -0.6">
        <joint name="elbow" axis="1 0 0" pos="0 0.05 0"/>
        <inertial pos="0 0 -0.25" mass="1.2" fullinertia="0.031 0.027 0.012 0.0041 -0.0023 0.0017"/>
        <body name="hand" pos="0 0 -0.5" euler="10 20 30">
          <inertial pos="0.01 0 -0.04" mass="0.4" diaginertia="0.001 0.0008 0.0005"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def agreement_of(text: str, robodyn_text: str | None = None):
    """MuJoCo's model of `text` against robodyn's of `robodyn_text` (the same by default)."""
    mj = mujoco.MjModel.from_xml_string(text)
    return mujoco_agreement(robodyn.load_mjcf_string(robodyn_text or text), mj, seed=2, states=2)


def test_mujocos_compile_noise_is_what_the_constant_says():
    """The bound is MuJoCo's measured noise, not a loose guess: MuJoCo's tensors of 1 000 random
    tetrahedra of exactly known inertia lie within it, the worst above a third of it (rerun on
    a new MuJoCo), with masses and centres of mass exact."""
    measured = measure_mujoco_inertia_noise(samples=1000)
    assert MUJOCO_INERTIA_NOISE / 3 < measured.inertia <= MUJOCO_INERTIA_NOISE, measured
    assert max(measured.mass, measured.center_of_mass) <= COMPILED_TOLERANCE, measured


def test_a_fullinertia_is_compiled_exactly():
    """Where MuJoCo's compiler diagonalises a given tensor its eigensolver is exact: tensors of
    random principal axes and moments spread over 1e3, at any magnitude, come back to 1e-14."""
    rng = np.random.default_rng(0)
    for scale in (1e2, 1.0, 1e-4, 1e-8):
        for _ in range(50):
            small, middle = np.sort(10.0 ** rng.uniform(-3.0, 0.0, 2))
            moments = scale * np.array([small, middle, rng.uniform(middle, small + middle)])
            axes, _ = np.linalg.qr(rng.normal(size=(3, 3)))
            tensor = axes @ np.diag(moments) @ axes.T
            entries = " ".join(repr(float(x)) for x in tensor[[0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]])
            mj = mujoco.MjModel.from_xml_string(f"<mujoco><worldbody><body><joint/><inertial pos='0 0 0' mass='1' fullinertia='{entries}'/></body></worldbody></mujoco>")
            rotation = np.zeros(9)
            mujoco.mju_quat2Mat(rotation, mj.body_iquat[1])
            compiled = rotation.reshape(3, 3) @ np.diag(mj.body_inertia[1]) @ rotation.reshape(3, 3).T
            assert np.linalg.norm(compiled - tensor, 2) <= 1e-14 * np.trace(tensor)


@pytest.mark.parametrize("name", ["ur5e_nomesh.xml", "panda_nomesh.xml", "iiwa14_scene.xml", "viewer_arm.xml"])
def test_models_of_given_tensors_agree_exactly(name):
    """Menagerie's arms (diaginertia and fullinertia) and an arm with a body merged into its
    parent: every body exact, the dynamics too against MuJoCo's model as compiled."""
    path = TEST_MJCF / name
    agreement = mujoco_agreement(robodyn.load(path), mujoco.MjModel.from_xml_path(str(path)))
    assert agreement.verdict == EXACT, str(agreement)
    assert {body.verdict for body in agreement.bodies} == {EXACT}
    assert max(agreement.dynamics_as_compiled.values()) <= DYNAMICS_TOLERANCE
    assert str(agreement).splitlines()[0] == f"{agreement.name}: exact"


def test_a_mesh_tensor_agrees_within_mujocos_compile_noise():
    agreement = agreement_of(TILTED)
    assert agreement.verdict == WITHIN_NOISE
    by_name = {body.body: body for body in agreement.bodies}
    # the hand is merged into the lower arm, as robodyn merges it; a fullinertia is exact
    assert sorted(by_name) == ["lower", "upper"] and by_name["lower"].verdict == EXACT
    upper = by_name["upper"]
    assert upper.verdict == WITHIN_NOISE and agreement.worst_body == upper
    assert 1e-8 < upper.inertia <= MUJOCO_INERTIA_NOISE
    assert max(upper.mass, upper.center_of_mass) <= COMPILED_TOLERANCE
    assert max(agreement.dynamics.values()) <= DYNAMICS_TOLERANCE
    report = str(agreement)
    assert "tilted: within MuJoCo's compile noise" in report and "worst body: 'upper'" in report


def test_mesh_inertias_are_noisy_in_mujoco_and_exact_in_robodyn():
    """MuJoCo's mesh tensors carry its compile noise into the dynamics (5e-10 in q̈ here, where
    M is well conditioned); with robodyn's tensors put in, MuJoCo agrees to rounding."""
    path = TEST_MJCF / "mesh_inertia.xml"
    agreement = mujoco_agreement(robodyn.load(path), mujoco.MjModel.from_xml_path(str(path)), seed=3, states=3)
    assert agreement.verdict == WITHIN_NOISE
    assert COMPILED_TOLERANCE < agreement.worst_body.inertia <= MUJOCO_INERTIA_NOISE
    substituted, as_compiled = max(agreement.dynamics.values()), max(agreement.dynamics_as_compiled.values())
    assert substituted <= 1e-13 and as_compiled > 1000 * substituted, (substituted, as_compiled)


@pytest.mark.parametrize(
    ("change", "field"),
    [
        (('mass="1.2"', 'mass="1.2001"'), "mass"),
        (('pos="0 0 -0.25"', 'pos="0 0 -0.2501"'), "center_of_mass"),
        (("-0.0023 0.0017", "-0.0023 0.00171"), "inertia"),
    ],
    ids=["mass", "centre of mass", "tensor"],
)
def test_a_real_difference_disagrees_and_names_the_body(change, field):
    agreement = agreement_of(TILTED, TILTED.replace(*change))
    assert agreement.verdict == DISAGREES
    worst = agreement.worst_body
    assert worst is not None and worst.body == "lower" and worst.verdict == DISAGREES
    assert getattr(worst, field) > MUJOCO_INERTIA_NOISE
    assert "worst body: 'lower'" in str(agreement) and str(agreement).startswith("tilted: disagrees")


def test_robodyns_inertias_put_into_mujoco_leave_its_model_as_it_was():
    mj = mujoco.MjModel.from_xml_string(TILTED)
    model = robodyn.load_mjcf_string(TILTED)
    before = mj.body_inertia.copy()
    substituted = with_robodyn_inertias(model, mj)
    np.testing.assert_array_equal(mj.body_inertia, before)
    # the hand's mass now sits in the lower arm, where robodyn merged it
    assert substituted.body_mass[3] == 0.0 and substituted.body_mass[2] == pytest.approx(1.6, rel=1e-15)
    assert [body.verdict for body in compare_bodies(model, substituted)] == [EXACT, EXACT]
    assert mujoco_agreement(model, substituted).verdict == EXACT


#: A body at its own centre of mass with a weight robodyn merges into it, and a cart on a slider
#: whose diagonal tensor MuJoCo compiles as "simple" (a diagonal mass block).
OWN_INERTIAL_FRAMES = {
    "weighted arm": """<mujoco model="weighted"><worldbody><body name="arm"><joint axis="0 1 0"/>
      <inertial pos="0 0 0" mass="1" diaginertia="0.01 0.02 0.03"/>
      <body name="weight" pos="0.3 0 0.1"><inertial pos="0 0 0" mass="0.5" diaginertia="0.001 0.002 0.001"/></body>
      </body></worldbody></mujoco>""",
    "cart": """<mujoco model="cart"><worldbody><body name="cart"><joint name="x" type="slide" axis="1 0 0"/>
      <inertial pos="0 0 0" mass="1" diaginertia="0.03 0.02 0.01"/></body></worldbody></mujoco>""",
}


@pytest.mark.parametrize("name", sorted(OWN_INERTIAL_FRAMES))
def test_robodyns_inertia_goes_into_a_body_mujoco_compiled_as_its_own_inertial_frame(name):
    """MuJoCo's model flags a body whose inertial frame is its own (and a simple one); robodyn's
    inertia put in moves that frame (the merged weight's centre of mass, the principal axes in
    ascending order), and mj_setConst must work the flags out again."""
    mj = mujoco.MjModel.from_xml_string(OWN_INERTIAL_FRAMES[name])
    assert mj.body_sameframe[1] != 0
    agreement = mujoco_agreement(robodyn.load_mjcf_string(OWN_INERTIAL_FRAMES[name]), mj)
    assert agreement.verdict == EXACT, str(agreement)


def test_the_menagerie_table_reports_the_verdict_and_the_worst_body():
    spec = importlib.util.spec_from_file_location("menagerie_table", REPOSITORY / "scripts" / "menagerie_table.py")
    assert spec is not None and spec.loader is not None
    table = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(table)
    line, outcome = table.row(TEST_MJCF / "mesh_inertia.xml", TEST_MJCF)
    assert outcome == WITHIN_NOISE and line.startswith("| `mesh_inertia.xml` | yes | within MuJoCo's compile noise: worst body '")
    line, outcome = table.row(TEST_MJCF / "ur5e_nomesh.xml", TEST_MJCF)
    assert outcome == EXACT and "| yes | exact (dynamics" in line


def test_a_mocap_body_is_left_out_like_the_world():
    """A mocap body is its own weld root in MuJoCo but has no joint (as in Menagerie's
    franka_emika_panda/mjx_single_cube.xml): robodyn welds it, and its children, to the world."""
    text = """
<mujoco model="mocap">
  <worldbody>
    <body name="target" mocap="true" pos="0.3 0 0.5">
      <geom type="box" size="0.02 0.02 0.02"/>
      <body name="on_target" pos="0 0 0.1"><geom type="sphere" size="0.03"/></body>
    </body>
    <body name="arm" pos="0 0 1">
      <joint name="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.03"/>
    </body>
  </worldbody>
</mujoco>
"""
    agreement = agreement_of(text)
    assert agreement.verdict == EXACT, agreement
    assert [body.body for body in agreement.bodies] == ["arm"]


def test_the_menagerie_table_counts_a_file_absent_from_the_copy_apart(tmp_path):
    """A model naming a file the copy lacks (Menagerie's mirror leaves out blobs over 4 MiB) is
    "not compared", naming the file; one MuJoCo refuses for another reason is "not loaded"."""
    spec = importlib.util.spec_from_file_location("menagerie_table", REPOSITORY / "scripts" / "menagerie_table.py")
    assert spec is not None and spec.loader is not None
    table = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(table)
    robot = tmp_path / "robot"
    robot.mkdir()
    (robot / "robot.xml").write_text("""<mujoco><compiler meshdir="assets"/><asset><mesh file="big.obj"/></asset>
      <worldbody><body><joint/><geom type="mesh" mesh="big"/></body></worldbody></mujoco>""")
    line, outcome = table.row(robot / "robot.xml", tmp_path, {"robot/assets/big.obj"})
    assert outcome == "not compared: a file absent from the snapshot"
    assert "not compared: file `robot/assets/big.obj` absent from the snapshot" in line
    line, outcome = table.row(robot / "robot.xml", tmp_path, set())
    assert outcome == "not loaded by MuJoCo" and "Error opening file" in line
