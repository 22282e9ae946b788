"""MJCF features MuJoCo applies to the model, each on a test model in testdata/mjcf/, compared field
by field with MuJoCo (robodyn.crosscheck): nested includes, the compiler's mass options, an
<inertial> without a tensor, armature on a free joint, sites placed by fromto, and the neutral
configuration (MuJoCo's qpos0)."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from conftest import CROSS_CHECK_TOLERANCE, REPOSITORY, load_quietly

import robodyn
from robodyn.convert import MujocoLayout
from robodyn.crosscheck import EXACT, WITHIN_NOISE, mujoco_agreement, mujoco_discrepancies, rigid_body_only

TEST_MJCF = REPOSITORY / "testdata" / "mjcf"
FEATURE_MODELS = ["nested/scene.xml", "compiler_mass.xml", "free_armature.xml", "framed_joints.xml", "mesh_inertia.xml", "mesh_fitaabb.xml",
                  "reference_pose.xml"]


def mujoco_and_robodyn(name):
    path = TEST_MJCF / name
    return rigid_body_only(mujoco.MjModel.from_xml_path(str(path))), robodyn.load(path)


#: robodyn finds a free joint's neutral quaternion from the body's rotation matrix, MuJoCo keeps the
#: file's orientation as a quaternion: the two agree to a few rounding errors of unit quantities.
QPOS0_TOLERANCE = 1e-14


@pytest.mark.parametrize("name", FEATURE_MODELS)
def test_feature_models_agree_with_mujoco(name):
    """Every body's compiled inertia exact, or within MuJoCo's compile noise where it comes from
    a mesh, and the dynamics at 1e-9 with robodyn's inertias in MuJoCo's model
    (robodyn.crosscheck.mujoco_agreement)."""
    mj, model = mujoco_and_robodyn(name)
    agreement = mujoco_agreement(model, mj, seed=3, states=4)
    assert {"M", "bias", "forward_dynamics", "body_pose"} <= set(agreement.dynamics)
    assert ("site_pose" in agreement.dynamics) == (mj.nsite > 0)
    assert agreement.verdict == (WITHIN_NOISE if mj.nmesh else EXACT), str(agreement)


def test_compiler_mass_options_give_mujocos_masses():
    mj, model = mujoco_and_robodyn("compiler_mass.xml")
    # settotalmass counts the pedestal welded to the world, which robodyn merges into the world
    assert mj.body_mass[1:].sum() == pytest.approx(12.0)
    assert model.total_mass == pytest.approx(mj.body_mass[2:].sum(), rel=1e-14)
    # the rod's thin tensor was balanced, the tip raised to boundmass before scaling
    assert np.allclose(mj.body_inertia[3], mj.body_inertia[3].mean())
    assert model.body_masses[-1] == pytest.approx(mj.body_mass[-1], rel=1e-14)


def test_free_joint_armature_acts_on_the_world_frame_linear_velocity():
    """With the body spinning, MuJoCo's armature on a free joint adds a(ω × v) in body axes;
    forward dynamics agrees only with that term."""
    mj, model = mujoco_and_robodyn("free_armature.xml")
    assert model.armature[:6].tolist() == [0.01] * 6
    errors = mujoco_discrepancies(model, mj, seed=11, states=6)
    assert errors["forward_dynamics"] < CROSS_CHECK_TOLERANCE and errors["bias"] < CROSS_CHECK_TOLERANCE
    # Ṁ − 2C stays skew-symmetric with the rotor term
    q, v = model.random_configuration(seed=2), np.linspace(-2, 2, model.nv)
    h = 1e-6
    m_dot = (model.mass_matrix(model.integrate(q, v, h)) - model.mass_matrix(model.integrate(q, v, -h))) / (2 * h)
    skew = m_dot - 2 * model.coriolis_matrix(q, v)
    assert np.abs(skew + skew.T).max() < 1e-7
    assert np.allclose(model.coriolis_matrix(q, v) @ v, model.bias_forces(q, v) - model.generalized_gravity(q), atol=1e-12)


def test_a_free_joints_armature_must_be_isotropic():
    model = robodyn.load(TEST_MJCF / "free_armature.xml")
    with pytest.raises(ValueError, match="joint 'root': a free joint's armature acts on its world-frame linear velocity"):
        model.armature = [0.01, 0.02, 0.01, 0.0, 0.0, 0.0, 0.05]


def test_a_sphere_site_with_fromto_is_refused_as_in_mujoco():
    text = '<mujoco><worldbody><body><joint/><geom size="0.1"/><site name="s" size="0.01" fromto="0 0 0 1 0 0"/></body></worldbody></mujoco>'
    with pytest.raises(ValueError, match="fromto"):
        mujoco.MjModel.from_xml_string(text)
    with pytest.raises(ValueError, match=r"<site name='s'> \(line 1\): attribute 'fromto': expected two distinct points on a capsule"):
        robodyn.load_mjcf_string(text)


def test_nested_includes_resolve_against_the_including_file(tmp_path):
    mj, model = mujoco_and_robodyn("nested/scene.xml")
    assert model.joint_names == ["shoulder", "elbow"]
    assert model.armature.tolist() == [0.02, 0.02] == mj.dof_armature.tolist()


def test_the_medium_is_switched_off_for_the_comparison():
    """robodyn models no fluid: a model in air (Menagerie's Crazyflie sets density and viscosity)
    is compared with MuJoCo's rigid-body dynamics alone."""
    text = (TEST_MJCF / "free_armature.xml").read_text().replace("<compiler", '<option density="1.225" viscosity="1.8e-5" wind="1 0 0"/><compiler')
    mj = mujoco.MjModel.from_xml_string(text)
    errors = mujoco_discrepancies(robodyn.load_mjcf_string(text), mj, seed=5, states=3)
    assert max(errors.values()) < CROSS_CHECK_TOLERANCE
    assert mj.opt.density == mj.opt.viscosity == 0.0 and not mj.opt.wind.any()


def test_mesh_inertia_gives_mujocos_masses():
    mj, model = mujoco_and_robodyn("mesh_inertia.xml")
    np.testing.assert_allclose(model.body_masses, mj.body_mass[1:], rtol=1e-13)


MESH_ERRORS = [
    ('<mesh name="m" file="missing.stl"/>', r"mesh file 'missing.stl' not found; tried .*meshes/missing.stl"),
    ('<mesh name="m" file="box.stl" inertia="convex" maxhullvert="6"/>', "inertia='convex' with maxhullvert='6': the mesh's convex hull has 8 vertices"),
    ('<mesh name="m" file="box.stl" inertia="solid"/>', "attribute 'inertia': expected legacy, exact, shell or convex, got 'solid'"),
    ('<mesh name="m" file="make_meshes.py"/>', r"expected a mesh file ending in \.stl, \.obj or \.msh"),
]


@pytest.mark.parametrize(("mesh", "message"), MESH_ERRORS, ids=[m for m, _ in MESH_ERRORS])
def test_mesh_errors_name_the_mesh(mesh, message, tmp_path):
    text = f"""<mujoco><compiler meshdir="{REPOSITORY / 'testdata' / 'meshes'}"/><asset>{mesh}</asset>
      <worldbody><body name="b"><joint/><geom type="mesh" mesh="m"/></body></worldbody></mujoco>"""
    path = tmp_path / "model.xml"
    path.write_text(text)
    with pytest.raises(ValueError, match=message) as error:
        robodyn.load(path)
    assert "<mesh name='m'>" in str(error.value) and "model.xml" in str(error.value)


def test_neutral_is_mujocos_qpos0():
    """A free joint at its body's pose in the file, hinges and slides at their ref, a ball joint at
    the identity: robodyn's neutral() is MuJoCo's qpos0, and every body is where MuJoCo puts it."""
    mj, model = mujoco_and_robodyn("reference_pose.xml")
    layout = MujocoLayout(model, mj)
    q = np.asarray(model.neutral())
    qpos0 = layout.q_from_mujoco(mj.qpos0)
    # q and -q are one rotation: each quaternion compared with the sign of MuJoCo's
    for kind, start in zip(model.joint_types, model.joint_idx_q):
        offset = {"free": 3, "spherical": 0}.get(kind)
        if offset is not None:
            quaternion = slice(start + offset, start + offset + 4)
            q[quaternion] *= np.sign(q[quaternion] @ qpos0[quaternion])
    np.testing.assert_allclose(q, qpos0, rtol=0, atol=QPOS0_TOLERANCE)
    assert q[model.joint_idx_q[model.joint_names.index("arm_hinge")]] == pytest.approx(np.radians(-45), abs=1e-16)
    data = mujoco.MjData(mj)
    data.qpos[:] = mj.qpos0
    mujoco.mj_kinematics(mj, data)
    for body in range(1, mj.nbody):
        pose = np.asarray(model.frame_pose(model.neutral(), mj.body(body).name))
        np.testing.assert_allclose(pose[:3, 3], data.xpos[body], rtol=0, atol=QPOS0_TOLERANCE)
        np.testing.assert_allclose(pose[:3, :3], data.xmat[body].reshape(3, 3), rtol=0, atol=QPOS0_TOLERANCE)


def test_urdf_neutral_is_zero_angles_and_identity_quaternions():
    model = robodyn.load("ur5", floating_base=True)
    expected = np.zeros(model.nq)
    expected[6] = 1.0
    assert np.asarray(model.neutral()).tolist() == expected.tolist()


def test_a_free_body_inside_a_frame_of_the_world_starts_where_mujoco_puts_it():
    text = """<mujoco><worldbody><frame pos="1 0 0" euler="0 0 90">
      <body name="b" pos="0 1 0" euler="30 0 0"><freejoint/><geom size="0.1"/></body>
    </frame></worldbody></mujoco>"""
    model, compiled = load_quietly(text=text), mujoco.MjModel.from_xml_string(text)
    data = mujoco.MjData(compiled)
    mujoco.mj_kinematics(compiled, data)
    pose = model.body_poses(model.neutral())[1]
    np.testing.assert_allclose(pose[:3, 3], data.xpos[1], atol=1e-12)
    np.testing.assert_allclose(pose[:3, :3], data.xmat[1].reshape(3, 3), atol=1e-12)
