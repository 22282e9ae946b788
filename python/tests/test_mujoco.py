"""Cross-checks against MuJoCo on the example-robot-data URDFs, which MuJoCo imports itself
(fixed base; meshes removed: they do not enter the dynamics)."""

from __future__ import annotations

import re

import mujoco
import numpy as np
import pytest
from conftest import CROSS_CHECK_TOLERANCE, REPOSITORY, ROBOTS, assert_close

import robodyn
from robodyn.convert import MujocoLayout
from robodyn.crosscheck import EXACT, compare_bodies, mujoco_discrepancies, rigid_body_only


def mujoco_model(urdf):
    text = re.sub(r"<(visual|collision|gazebo|transmission)\b.*?</\1>", "", urdf.read_text(), flags=re.S)
    return rigid_body_only(mujoco.MjModel.from_xml_string(text))


#: Every quantity robodyn.crosscheck compares (the site poses only where the model has sites).
QUANTITIES = {"M", "bias", "forward_dynamics", "inverse_dynamics", "body_pose", "jacobian", "jacobian_dot_v"}


def check_against_mujoco(model, mj, seed, label, states=3):
    """Every body's compiled inertia exactly MuJoCo's (none comes from a mesh), then dynamics, body
    and site poses, Jacobians and J̇v at a few random states, through robodyn.convert's MuJoCo
    layout (robodyn.crosscheck)."""
    inexact = [str(body) for body in compare_bodies(model, mj) if body.verdict != EXACT]
    assert not inexact, f"{label}: compiled inertias differ from MuJoCo's: {inexact}"
    errors = mujoco_discrepancies(model, mj, seed=seed, states=states)
    assert QUANTITIES <= set(errors), f"{label}: compared only {sorted(errors)}"
    assert ("site_pose" in errors) == (mj.nsite > 0)
    too_large = {name: error for name, error in errors.items() if error > CROSS_CHECK_TOLERANCE}
    assert not too_large, f"{label}: relative errors above {CROSS_CHECK_TOLERANCE}: {too_large}"


@pytest.fixture(scope="module", params=sorted(ROBOTS))
def robot(request, robots_dir):
    urdf = robots_dir / ROBOTS[request.param][0]
    model = robodyn.load(urdf)
    mj = mujoco_model(urdf)
    joint_names = [mj.joint(j).name for j in range(mj.njnt)]
    # MuJoCo keeps the URDF's file order too
    assert joint_names == model.joint_names
    return request.param, model, mj


def test_urdf_robots_agree_with_mujoco(robot):
    name, model, mj = robot
    check_against_mujoco(model, mj, 5, name)


TEST_MJCF = REPOSITORY / "testdata" / "mjcf"

#: MJCF models read by robodyn's loader and by MuJoCo: Menagerie's UR5e and Panda (meshes removed)
#: and the iiwa 14 written from Menagerie's inertial data,
#: through a scene that <include>s it.
MJCF_MODELS = {
    "ur5e": TEST_MJCF / "ur5e_nomesh.xml",
    "panda": TEST_MJCF / "panda_nomesh.xml",
    "iiwa14": TEST_MJCF / "iiwa14_scene.xml",
}


@pytest.mark.parametrize("name", sorted(MJCF_MODELS))
def test_mjcf_models_agree_with_mujoco(name):
    path = MJCF_MODELS[name]
    model = robodyn.load(path, check_inertia=True)
    mj = rigid_body_only(mujoco.MjModel.from_xml_path(str(path)))
    assert model.joint_names == [mj.joint(j).name for j in range(mj.njnt)]
    np.testing.assert_array_equal(model.armature, mj.dof_armature)
    np.testing.assert_allclose(model.lower_position_limit, np.where(mj.jnt_limited, mj.jnt_range[:, 0], -np.inf))
    check_against_mujoco(model, mj, 6, name)


def floating_mjcf(urdf):
    """An MJCF file written by MuJoCo from an example-robot-data URDF, its root body on a free
    joint: a floating-base robot as MuJoCo itself writes one."""
    text = re.sub(r"<(visual|collision|gazebo|transmission)\b.*?</\1>", "", urdf.read_text(), flags=re.S)
    spec = mujoco.MjSpec.from_string(text)
    spec.worldbody.first_body().add_freejoint(name="root_joint")
    spec.compile()
    return spec.to_xml()


@pytest.mark.parametrize("name", ["solo12", "talos"])
def test_floating_base_mjcf_agrees_with_mujoco(name, robots_dir):
    """A quadruped and a humanoid on free joints: MuJoCo's quaternion order and world-frame linear
    velocity, converted by robodyn.convert.MujocoLayout."""
    xml = floating_mjcf(robots_dir / ROBOTS[name][0])
    model = robodyn.load_mjcf_string(xml, source=f"{name}.xml")
    mj = rigid_body_only(mujoco.MjModel.from_xml_string(xml))
    assert model.joint_types[0] == "free"
    check_against_mujoco(model, mj, 8, name, states=2)


MJCF_FEATURES = """<mujoco model="features">
  <compiler angle="degree" eulerseq="zyx"/>
  <option gravity="0 -9.81 -3"/>
  <default>
    <joint armature="0.01" axis="1 0 0"/>
    <default class="heavy">
      <joint armature="0.2" damping="3"/>
    </default>
  </default>
  <worldbody>
    <site name="world_site" pos="0.1 0 0"/>
    <body name="a" pos="0 0 0.5" euler="10 20 30" childclass="heavy">
      <inertial pos="0.1 0 0" mass="2" diaginertia="0.1 0.2 0.3" axisangle="1 1 0 30"/>
      <joint name="a1" type="hinge" pos="0.1 0.2 0" axis="0 0 1"/>
      <joint name="a2" type="hinge" pos="-0.1 0 0.3" axis="0 1 0" ref="20" stiffness="4" springref="-10"/>
      <joint name="a3" type="slide" axis="1 0 1" range="-0.2 0.2" ref="0.05" stiffness="7" springref="0.1"/>
      <body name="b" pos="0.3 0 0" xyaxes="0 1 0 -1 0 0">
        <inertial pos="0 0 0.1" mass="1" fullinertia="0.05 0.04 0.03 0.001 0.002 0.003"/>
        <joint name="b1" class="main"/>
        <site name="b_tip" pos="0 0 0.2" zaxis="1 1 1"/>
        <body name="c" pos="0 0.1 0.2">
          <inertial pos="0 0 0" mass="0.5" diaginertia="0.01 0.01 0.01"/>
          <joint name="c1" type="ball" pos="0 0 0.05"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>"""


def test_mjcf_orientations_defaults_and_joint_chains_agree_with_mujoco():
    """Every orientation form, degrees, eulerseq, classes and childclass, several joints in one
    body with their own pos and ref, a ball joint off the body origin, sites, springs."""
    model = robodyn.load_mjcf_string(MJCF_FEATURES)
    mj = mujoco.MjModel.from_xml_string(MJCF_FEATURES)
    assert model.joint_names == ["a1", "a2", "a3", "b1", "c1"]
    np.testing.assert_allclose(model.stiffness, np.repeat(mj.jnt_stiffness, [1, 1, 1, 1, 3]))
    mj = rigid_body_only(mj)
    np.testing.assert_allclose(model.armature, mj.dof_armature)
    np.testing.assert_allclose(model.gravity, mj.opt.gravity)
    layout = MujocoLayout(model, mj)
    np.testing.assert_allclose(layout.q_to_mujoco(model.spring_reference), mj.qpos_spring, atol=1e-15)
    check_against_mujoco(model, mj, 2, "features")


MJCF_GEOMS = """<mujoco model="geoms">
  <compiler angle="radian" inertiagrouprange="0 3"/>
  <default>
    <geom density="500"/>
    <default class="light"><geom density="100"/></default>
    <default class="visual"><geom group="4" type="box" size="1 1 1"/></default>
  </default>
  <worldbody>
    <geom name="floor" type="plane" size="0 0 1"/>
    <body name="a" pos="0 0 1">
      <joint name="a1" axis="0 1 0"/>
      <geom type="sphere" size="0.1" pos="0.2 0 0"/>
      <geom type="capsule" size="0.05" fromto="0 0 0 0.3 0.1 -0.2" class="light"/>
      <geom class="visual"/>
      <frame pos="0 0.1 0" euler="0.3 0 0.2">
        <geom type="box" size="0.1 0.05 0.02" pos="0.1 0 0" euler="0.1 0.2 0.3" mass="2"/>
        <site name="in_frame" pos="0.1 0.1 0"/>
      </frame>
      <body name="b" pos="0.3 0.1 -0.2">
        <joint name="b1" axis="1 0 0" ref="0.4"/>
        <geom type="ellipsoid" size="0.1 0.05 0.03" quat="1 0.2 0.3 0.1"/>
        <geom type="cylinder" size="0.04 0.1" pos="0 0 -0.1" axisangle="1 0 0 0.5"/>
        <geom type="box" fromto="0 0 0 0 0.2 0" size="0.02 0.03"/>
        <frame pos="0 0 -0.2" xyaxes="0 1 0 -1 0 0">
          <body name="c">
            <joint name="c1" type="slide" axis="0 0 1"/>
            <geom type="cylinder" fromto="0 0 0 0.1 0 0.1" size="0.03"/>
          </body>
        </frame>
      </body>
    </body>
  </worldbody>
</mujoco>"""


def test_mjcf_inertia_from_geoms_agrees_with_mujoco():
    """Bodies without <inertial> get MuJoCo's inertia from their primitive geoms: every type,
    `fromto`, density from classes, an explicit mass, geoms inside a <frame>, a group outside
    inertiagrouprange; joints with `ref`; bodies and sites inside frames."""
    model = robodyn.load_mjcf_string(MJCF_GEOMS)
    mj = rigid_body_only(mujoco.MjModel.from_xml_string(MJCF_GEOMS))
    assert model.joint_names == ["a1", "b1", "c1"]
    check_against_mujoco(model, mj, 3, "geoms")


def test_mjcf_inertiafromgeom_true_and_false():
    """`inertiafromgeom="true"` ignores <inertial>; "false" ignores geoms."""
    body = "<body name='a'><joint name='a1'/><inertial mass='1' diaginertia='0.1 0.1 0.1' pos='0.5 0 0'/><geom size='0.1 0.2 0.3' type='box'/></body>"
    for setting in ["true", "false"]:
        text = f"<mujoco><compiler inertiafromgeom='{setting}'/><worldbody>{body}</worldbody></mujoco>"
        model = robodyn.load_mjcf_string(text)
        mj = rigid_body_only(mujoco.MjModel.from_xml_string(text))
        check_against_mujoco(model, mj, 1, f"inertiafromgeom={setting}", states=1)


def test_mjcf_include(tmp_path):
    """<include> splices the included file's <mujoco> children in place, in the main file's
    sections and inside a body; errors name the included file."""
    (tmp_path / "parts").mkdir()
    (tmp_path / "parts" / "defaults.xml").write_text("<mujoco><default><joint damping='2' axis='0 1 0'/></default></mujoco>")
    (tmp_path / "arm.xml").write_text(
        "<mujoco><body name='forearm' pos='0.3 0 0'><joint name='elbow'/>"
        "<inertial mass='1' pos='0.15 0 0' diaginertia='0.01 0.01 0.001'/><site name='tip' pos='0.3 0 0'/></body></mujoco>"
    )
    main = tmp_path / "robot.xml"
    main.write_text(
        "<mujoco model='included'><include file='parts/defaults.xml'/><worldbody>"
        "<body name='upper' pos='0 0 1'><joint name='shoulder'/><inertial mass='2' pos='0.15 0 0' diaginertia='0.02 0.02 0.002'/>"
        "<include file='arm.xml'/></body></worldbody></mujoco>"
    )
    model = robodyn.load(main)
    mj = rigid_body_only(mujoco.MjModel.from_xml_path(str(main)))
    assert model.joint_names == ["shoulder", "elbow"]
    np.testing.assert_array_equal(model.damping, [2.0, 2.0])
    check_against_mujoco(model, mj, 4, "include")
    (tmp_path / "arm.xml").write_text("<mujoco><body name='forearm'><joint type='screw'/></body></mujoco>")
    with pytest.raises(ValueError, match=r"arm\.xml: <body name='forearm'>/<joint>.*unknown joint type 'screw'"):
        robodyn.load(main)
    (tmp_path / "twice.xml").write_text("<mujoco><include file='parts/defaults.xml'/><include file='parts/defaults.xml'/></mujoco>")
    with pytest.raises(ValueError, match="included more than once"):
        robodyn.load(tmp_path / "twice.xml")
    (tmp_path / "missing.xml").write_text("<mujoco><include file='nowhere.xml'/></mujoco>")
    with pytest.raises(FileNotFoundError, match="nowhere.xml"):
        robodyn.load(tmp_path / "missing.xml")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("<mujoco><worldbody><body name='x'><geom type='mesh' mesh='m'/><joint/></body></worldbody></mujoco>", "<body name='x'>/<geom> \\(line 1\\): attribute 'mesh': no <mesh name='m'> in the <asset>s"),
        ("<mujoco><worldbody><body name='x'><geom type='plane' size='1 1 1'/><joint/></body></worldbody></mujoco>", "a plane may only be on a body welded to the world"),
        ("<mujoco><worldbody><body name='x'><geom type='box' size='0.1 0.1'/><joint/></body></worldbody></mujoco>", "a box needs 3 positive numbers"),
        ("<mujoco><worldbody><body name='x'><geom type='sphere' fromto='0 0 0 1 0 0' size='0.1'/><joint/></body></worldbody></mujoco>", "'fromto'"),
        ("<mujoco><include file='robot.xml'/></mujoco>", "<include>.*load the model from its file"),
        ("<mujoco><worldbody><body name='x'><inertial mass='1' diaginertia='0.1 0.1 1'/><joint/></body></worldbody></mujoco>",
         r"<body name='x'> \(line 1\): the principal moments .* must satisfy A \+ B >= C \(use <compiler balanceinertia"),
        ("<mujoco><worldbody><replicate count='2'/></worldbody></mujoco>", "<replicate> is not supported"),
        ("<mujoco><worldbody><frame><joint/></frame></worldbody></mujoco>", "the world body cannot have joints"),
        ("<mujoco><worldbody><body name='x'><inertial mass='1' diaginertia='1 1 1'/><joint type='ball' ref='1'/></body></worldbody></mujoco>", "'ref': only hinge and slide"),
        ("<mujoco><worldbody><body name='x'><inertial mass='1' diaginertia='1 1 1'/><joint type='screw'/></body></worldbody></mujoco>", "unknown joint type 'screw'"),
        ("<mujoco><default><default><joint/></default></default></mujoco>", "needs a 'class'"),
        ("<mujoco><worldbody><body name='x' quat='0 0 0 0'/></worldbody></mujoco>", "non-zero quaternion"),
        ("<mujoco><worldbody><body name='x' pos='1 2'/></worldbody></mujoco>", "attribute 'pos': expected 3 numbers"),
        ("<robot/>", "expected the root element <mujoco>"),
        ("<mujoco><worldbody><body name='x'><inertial mass='1' diaginertia='1 1 1'/><joint class='nope'/></body></worldbody></mujoco>", "unknown class 'nope'"),
    ],
)
def test_mjcf_errors_name_the_element(text, message):
    with pytest.raises(ValueError, match=message):
        robodyn.load_mjcf_string(text, source="bad.xml")


def test_crosscheck_sees_a_wrong_mass():
    """robodyn.crosscheck is not blind: a 0.1% heavier link shows in M and the dynamics, not in
    the kinematics."""
    heavier = robodyn.load_mjcf_string(MJCF_FEATURES.replace('mass="1"', 'mass="1.001"', 1))
    errors = mujoco_discrepancies(heavier, mujoco.MjModel.from_xml_string(MJCF_FEATURES), states=1)
    assert min(errors["M"], errors["bias"], errors["forward_dynamics"], errors["inverse_dynamics"]) > 1e-6
    assert max(errors["body_pose"], errors["jacobian"], errors["jacobian_dot_v"]) < CROSS_CHECK_TOLERANCE
