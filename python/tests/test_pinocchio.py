"""Cross-checks against Pinocchio, field by field, on example-robot-data robots and the bundled
models; the same comparisons against the frozen references in testdata/reference/."""

from __future__ import annotations

import hashlib
import warnings

import numpy as np
import pinocchio as pin
import pytest
from conftest import CROSS_CHECK_TOLERANCE, REPOSITORY, ROBOTS, assert_close, load_reference, pinocchio_forces, pinocchio_model

import robodyn
from robodyn.convert import PinocchioLayout


def test_dynamics_agree_with_pinocchio(pinocchio_robot):
    name, model, pin_model, mapping = pinocchio_robot
    data = pin_model.createData()
    rng = np.random.default_rng(7)
    for seed in range(5):
        q = model.random_configuration(seed=seed)
        v, a = rng.uniform(-2, 2, model.nv), rng.uniform(-2, 2, model.nv)
        pq, pv, pa = mapping.q_to_pinocchio(q), mapping.v_to_pinocchio(v), mapping.v_to_pinocchio(a)
        tau = model.inverse_dynamics(q, v, a)
        assert_close(tau, mapping.v_from_pinocchio(pin.rnea(pin_model, data, pq, pv, pa)), CROSS_CHECK_TOLERANCE, f"{name} tau")
        mass = pin.crba(pin_model, data, pq)
        mass = np.triu(mass) + np.triu(mass, 1).T
        assert_close(model.mass_matrix(q), mapping.matrix_from_pinocchio(mass), CROSS_CHECK_TOLERANCE, f"{name} M")
        assert_close(
            model.generalized_gravity(q),
            mapping.v_from_pinocchio(pin.computeGeneralizedGravity(pin_model, data, pq)),
            CROSS_CHECK_TOLERANCE,
            f"{name} g",
        )
        assert_close(model.bias_forces(q, v), mapping.v_from_pinocchio(pin.nle(pin_model, data, pq, pv)), CROSS_CHECK_TOLERANCE, f"{name} bias")
        assert_close(
            model.forward_dynamics(q, v, tau),
            mapping.v_from_pinocchio(pin.aba(pin_model, data, pq, pv, mapping.v_to_pinocchio(tau))),
            CROSS_CHECK_TOLERANCE,
            f"{name} aba",
        )
        assert_close(
            model.inverse_mass_matrix(q),
            mapping.matrix_from_pinocchio(np.linalg.inv(mass)),
            CROSS_CHECK_TOLERANCE,
            f"{name} M^-1",
        )
        assert_close(model.kinetic_energy(q, v), pin.computeKineticEnergy(pin_model, data, pq, pv), CROSS_CHECK_TOLERANCE, f"{name} KE")
        assert_close(model.potential_energy(q), pin.computePotentialEnergy(pin_model, data, pq), CROSS_CHECK_TOLERANCE, f"{name} PE")
        assert_close(model.center_of_mass(q), pin.centerOfMass(pin_model, data, pq), CROSS_CHECK_TOLERANCE, f"{name} com")
        assert_close(
            model.center_of_mass_jacobian(q),
            mapping.jacobian_from_pinocchio(pin.jacobianCenterOfMass(pin_model, data, pq)),
            CROSS_CHECK_TOLERANCE,
            f"{name} J_com",
        )


def test_external_forces_agree_with_pinocchio(pinocchio_robot):
    name, model, pin_model, mapping = pinocchio_robot
    data = pin_model.createData()
    rng = np.random.default_rng(8)
    q = model.random_configuration(seed=11)
    v, a = rng.uniform(-1, 1, model.nv), rng.uniform(-1, 1, model.nv)
    f_ext = rng.uniform(-5, 5, (len(model.body_names), 6))
    pin_forces = pinocchio_forces(model, pin_model, f_ext)
    expected = mapping.v_from_pinocchio(pin.rnea(pin_model, data, mapping.q_to_pinocchio(q), mapping.v_to_pinocchio(v), mapping.v_to_pinocchio(a), pin_forces))
    tau = model.inverse_dynamics(q, v, a, f_ext=f_ext)
    assert_close(tau, expected, CROSS_CHECK_TOLERANCE, f"{name} tau with f_ext")
    assert_close(model.forward_dynamics(q, v, tau, f_ext=f_ext), a, CROSS_CHECK_TOLERANCE, f"{name} aba with f_ext")


def test_kinematics_agree_with_pinocchio(pinocchio_robot):
    name, model, pin_model, mapping = pinocchio_robot
    data = pin_model.createData()
    for seed in range(3):
        q = model.random_configuration(seed=20 + seed)
        pq = mapping.q_to_pinocchio(q)
        pin.framesForwardKinematics(pin_model, data, pq)
        pin.computeJointJacobians(pin_model, data, pq)
        for frame in model.frame_names:
            frame_id = pin_model.getFrameId(frame)
            assert_close(model.frame_pose(q, frame), data.oMf[frame_id].homogeneous, CROSS_CHECK_TOLERANCE, f"{name} pose {frame}")
            for reference, pin_reference in [("world", pin.LOCAL_WORLD_ALIGNED), ("local", pin.LOCAL), ("spatial", pin.WORLD)]:
                expected = mapping.jacobian_from_pinocchio(pin.getFrameJacobian(pin_model, data, frame_id, pin_reference))
                assert_close(model.jacobian(q, frame, reference), expected, CROSS_CHECK_TOLERANCE, f"{name} J {reference} {frame}")


def test_frame_velocity_and_acceleration_agree_with_pinocchio(pinocchio_robot):
    """Frame velocity, classical acceleration (J a + J̇ v) and spatial acceleration."""
    name, model, pin_model, mapping = pinocchio_robot
    data = pin_model.createData()
    rng = np.random.default_rng(12)
    for seed in range(3):
        q = model.random_configuration(seed=30 + seed)
        v, a = rng.uniform(-1, 1, model.nv), rng.uniform(-1, 1, model.nv)
        pin.forwardKinematics(pin_model, data, mapping.q_to_pinocchio(q), mapping.v_to_pinocchio(v), mapping.v_to_pinocchio(a))
        pin.updateFramePlacements(pin_model, data)
        for frame in model.frame_names[:: max(1, len(model.frame_names) // 8)]:
            frame_id = pin_model.getFrameId(frame)
            for reference, pin_reference in [("world", pin.LOCAL_WORLD_ALIGNED), ("local", pin.LOCAL)]:
                velocity = pin.getFrameVelocity(pin_model, data, frame_id, pin_reference).vector
                assert_close(model.frame_velocity(q, v, frame, reference), velocity, CROSS_CHECK_TOLERANCE, f"{name} v {frame}")
                classical = pin.getFrameClassicalAcceleration(pin_model, data, frame_id, pin_reference).vector
                assert_close(model.frame_acceleration(q, v, a, frame, reference), classical, CROSS_CHECK_TOLERANCE, f"{name} a {frame}")
            pin.computeJointJacobiansTimeVariation(pin_model, data, mapping.q_to_pinocchio(q), mapping.v_to_pinocchio(v))
            for reference, pin_reference in [("world", pin.LOCAL_WORLD_ALIGNED), ("local", pin.LOCAL), ("spatial", pin.WORLD)]:
                expected = mapping.jacobian_from_pinocchio(pin.getFrameJacobianTimeVariation(pin_model, data, frame_id, pin_reference))
                assert_close(model.jacobian_time_variation(q, v, frame, reference), expected, CROSS_CHECK_TOLERANCE, f"{name} J̇ {reference} {frame}")
            spatial = pin.getFrameAcceleration(pin_model, data, frame_id, pin.WORLD).vector
            assert_close(model.frame_acceleration(q, v, a, frame, "spatial"), spatial, CROSS_CHECK_TOLERANCE, f"{name} spatial a {frame}")


def test_bundled_models_agree_with_pinocchio():
    for name in robodyn.models():
        model = robodyn.load(name)
        pin_model = pinocchio_model(REPOSITORY / "models" / f"{name}.urdf", False)
        pin_model.gravity.linear = model.gravity
        mapping = PinocchioLayout(model, pin_model)
        data = pin_model.createData()
        q = model.random_configuration(seed=5)
        v, a = np.linspace(-1, 1, model.nv), np.linspace(1, -1, model.nv)
        expected = mapping.v_from_pinocchio(pin.rnea(pin_model, data, mapping.q_to_pinocchio(q), mapping.v_to_pinocchio(v), mapping.v_to_pinocchio(a)))
        assert_close(model.inverse_dynamics(q, v, a), expected, CROSS_CHECK_TOLERANCE, f"{name} tau")


@pytest.mark.parametrize("name", sorted(ROBOTS) + [f"bundled_{n}" for n in ("ur5", "planar2", "pendulum")])
def test_frozen_references(name, robots_dir):
    reference = load_reference(f"pinocchio_{name}")
    provenance = reference["provenance"]
    if name.startswith("bundled_"):
        urdf = REPOSITORY / provenance["urdf"]
        model = robodyn.load(name.removeprefix("bundled_"))
    else:
        urdf = robots_dir / provenance["urdf"].removeprefix("example-robot-data robots/")
        model = robodyn.load(urdf, floating_base=provenance["floating_base"])
    digest = hashlib.sha256(urdf.read_bytes()).hexdigest()
    assert digest == provenance["urdf_sha256"], f"{urdf} changed since the reference was frozen: run make_reference.py"
    assert model.joint_names == reference["joint_names"]
    for k, state in enumerate(reference["states"]):
        q, v, a, tau = (np.array(state[key]) for key in ("q", "v", "a", "tau"))
        label = f"{name} state {k}"
        assert_close(model.inverse_dynamics(q, v, a), state["rnea"], CROSS_CHECK_TOLERANCE, f"{label} rnea")
        assert_close(model.mass_matrix(q), state["mass_matrix"], CROSS_CHECK_TOLERANCE, f"{label} M")
        assert_close(model.generalized_gravity(q), state["gravity"], CROSS_CHECK_TOLERANCE, f"{label} g")
        assert_close(model.bias_forces(q, v), state["bias"], CROSS_CHECK_TOLERANCE, f"{label} bias")
        assert_close(model.forward_dynamics(q, v, tau), state["aba"], CROSS_CHECK_TOLERANCE, f"{label} aba")
        for frame, pose in state["frame_poses"].items():
            assert_close(model.frame_pose(q, frame), pose, CROSS_CHECK_TOLERANCE, f"{label} pose {frame}")
        for frame, jacobian in state["world_jacobians"].items():
            assert_close(model.jacobian(q, frame), jacobian, CROSS_CHECK_TOLERANCE, f"{label} J {frame}")


def test_loads_every_urdf_pinocchio_loads(robots_dir):
    """Every example-robot-data URDF that Pinocchio loads, robodyn loads with the same dimensions.
    A file whose inertias are not positive semi-definite is refused by default, naming the link,
    and loads with check_inertia=False, which reports each such inertia as a warning."""
    loaded = 0
    for path in sorted(robots_dir.rglob("*.urdf")):
        try:
            pin_model = pin.buildModelFromUrdf(str(path))
        except Exception:  # noqa: BLE001  (a file Pinocchio itself cannot load is out of scope)
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", robodyn.ModelWarning)
            try:
                model = robodyn.load(path)
            except ValueError as error:
                assert "positive semi-definite" in str(error), f"{path}: {error}"
                model = robodyn.load(path, check_inertia=False)
                assert any("positive semi-definite" in w for w in model.warnings)
        continuous = sum(1 for j in pin_model.joints[1:] if j.nq == 2 and j.nv == 1)
        assert (model.nq + continuous, model.nv) == (pin_model.nq, pin_model.nv), path
        loaded += 1
    assert loaded >= 50, f"only {loaded} URDFs found in {robots_dir}"


ROTATED_INERTIALS = """<robot name="tree">
  <link name="base"><inertial><origin xyz="0.1 0 0.05" rpy="0.1 0.2 0.3"/><mass value="4"/>
    <inertia ixx="0.3" ixy="0.01" ixz="0.02" iyy="0.25" iyz="0.03" izz="0.2"/></inertial></link>
  <joint name="a" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0.2 0.1 0.3" rpy="0.3 -0.2 0.5"/>
    <axis xyz="1 1 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <link name="arm"><inertial><origin xyz="0 0 0.2" rpy="0 0.4 0.2"/><mass value="1.5"/>
    <inertia ixx="0.05" ixy="0.002" ixz="0" iyy="0.04" iyz="0.001" izz="0.01"/></inertial></link>
  <joint name="b" type="prismatic"><parent link="arm"/><child link="slider"/><origin xyz="0.1 0.2 0" rpy="0.5 0 0"/>
    <axis xyz="0 0.6 0.8"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="slider"><inertial><origin xyz="0 0.05 0" rpy="1 0 0"/><mass value="0.3"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.001"/></inertial></link>
  <joint name="fixed" type="fixed"><parent link="slider"/><child link="tip"/><origin xyz="0 0.1 0.02" rpy="0 0 1"/></joint>
  <link name="tip"><inertial><origin xyz="0.01 0 0" rpy="0.3 0.2 0.1"/><mass value="0.1"/>
    <inertia ixx="0.0001" ixy="0" ixz="0" iyy="0.0002" iyz="0" izz="0.0003"/></inertial></link>
  <joint name="c" type="continuous"><parent link="base"/><child link="leg"/><origin xyz="-0.2 0 -0.1" rpy="0 0.3 0"/>
    <axis xyz="0 1 0"/></joint>
  <link name="leg"><inertial><origin xyz="0 0 -0.2"/><mass value="2"/>
    <inertia ixx="0.03" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.004"/></inertial></link>
</robot>"""


@pytest.mark.parametrize("floating_base", [False, True])
def test_oblique_axes_rotated_inertials_and_merged_links_agree_with_pinocchio(floating_base):
    model = robodyn.load_urdf_string(ROTATED_INERTIALS, floating_base=floating_base)
    pin_model = (
        pin.buildModelFromXML(ROTATED_INERTIALS, pin.JointModelFreeFlyer())
        if floating_base
        else pin.buildModelFromXML(ROTATED_INERTIALS)
    )
    mapping = PinocchioLayout(model, pin_model)
    data = pin_model.createData()
    rng = np.random.default_rng(3)
    for seed in range(3):
        q = model.random_configuration(seed=seed)
        v, a = rng.uniform(-1, 1, model.nv), rng.uniform(-1, 1, model.nv)
        pq = mapping.q_to_pinocchio(q)
        expected = mapping.v_from_pinocchio(pin.rnea(pin_model, data, pq, mapping.v_to_pinocchio(v), mapping.v_to_pinocchio(a)))
        assert_close(model.inverse_dynamics(q, v, a), expected, CROSS_CHECK_TOLERANCE, "tau")
        mass = pin.crba(pin_model, data, pq)
        assert_close(model.mass_matrix(q), mapping.matrix_from_pinocchio(np.triu(mass) + np.triu(mass, 1).T), CROSS_CHECK_TOLERANCE, "M")
        pin.framesForwardKinematics(pin_model, data, pq)
        assert_close(model.frame_pose(q, "tip"), data.oMf[pin_model.getFrameId("tip")].homogeneous, CROSS_CHECK_TOLERANCE, "tip")
