"""A walk over the public API with arguments of the wrong type: strings, negatives, None, floats
for integers, integers for strings. Each is a ValueError naming the argument, never a TypeError,
an OverflowError or a Rust panic."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn

UR5 = robodyn.load("ur5")
Q = UR5.neutral()
V = np.zeros(UR5.nv)
POSE = UR5.frame_pose(Q, "tool0")

#: (call, the argument it gets wrong)
CASES = [
    (lambda: robodyn.load(42), "name_or_path"),
    (lambda: robodyn.load("ur5", floating_base="yes"), "floating_base"),
    (lambda: robodyn.load("ur5", floating_base=None), "floating_base"),
    (lambda: robodyn.load("ur5", check_inertia=1), "check_inertia"),
    (lambda: robodyn.load_urdf(3.5), "path"),
    (lambda: robodyn.load_urdf_string(b"<robot/>"), "text"),
    (lambda: robodyn.load_urdf_string("<robot/>", source=7), "source"),
    (lambda: robodyn.load_urdf_string("<robot/>", floating_base="no"), "floating_base"),
    (lambda: robodyn.load_mjcf(None), "path"),
    (lambda: robodyn.load_mjcf_string(None), "text"),
    (lambda: robodyn.from_dh([{"a": 0, "alpha": 0, "d": 0, "theta": 0, "type": "revolute"}], convention="craig"), "convention"),
    (lambda: robodyn.from_dh("not rows"), "rows"),
    (lambda: robodyn.from_dh([{"a": "x", "alpha": 0, "d": 0, "theta": 0, "type": "revolute"}]), "a"),
    (lambda: UR5.random_configuration(n=-1), "n"),
    (lambda: UR5.random_configuration(n=2.5), "n"),
    (lambda: UR5.random_configuration(n="3"), "n"),
    (lambda: UR5.random_configuration(n=True), "n"),
    (lambda: UR5.random_configuration(seed=-5), "seed"),
    (lambda: UR5.random_configuration(seed=1.5), "seed"),
    (lambda: UR5.random_configuration(seed="x"), "seed"),
    (lambda: UR5.inverse_dynamics("q", V, V), "q"),
    (lambda: UR5.inverse_dynamics(None, V, V), "q"),
    (lambda: UR5.inverse_dynamics(Q, V, V, f_ext="none"), "f_ext"),
    (lambda: UR5.forward_dynamics(Q, None, V), "v"),
    (lambda: UR5.mass_matrix(Q, method=3), "method"),
    (lambda: UR5.mass_matrix(Q, method="cholesky"), "method"),
    (lambda: UR5.generalized_gravity(Q, method=None), "method"),
    (lambda: UR5.frame_pose(Q, None), "frame"),
    (lambda: UR5.frame_pose(Q, -1), "frame"),
    (lambda: UR5.frame_pose(Q, 2.0), "frame"),
    (lambda: UR5.jacobian(Q, "tool0", reference=0), "reference"),
    (lambda: UR5.jacobian_time_variation(Q, V, "tool0", reference=None), "reference"),
    (lambda: UR5.frame_velocity(Q, V, "tool0", reference=1.0), "reference"),
    (lambda: UR5.frame_acceleration(Q, V, V, "tool0", reference=b"world"), "reference"),
    (lambda: UR5.manipulability(Q, "tool0", task=5), "task"),
    (lambda: UR5.manipulability(Q, "tool0", task=[-1, 2]), "task"),
    (lambda: UR5.workspace("tool0", n=-3), "n"),
    (lambda: UR5.workspace("tool0", n=10.0), "n"),
    (lambda: UR5.workspace("tool0", n=10, seed="a"), "seed"),
    (lambda: UR5.inverse_kinematics("tool0", POSE, max_iterations=-1), "max_iterations"),
    (lambda: UR5.inverse_kinematics("tool0", POSE, restarts=2.5), "restarts"),
    (lambda: UR5.inverse_kinematics("tool0", POSE, tolerance="small"), "tolerance"),
    (lambda: UR5.inverse_kinematics("tool0", POSE, damping=None), "damping"),
    (lambda: UR5.inverse_kinematics("tool0", POSE, position_only="yes"), "position_only"),
    (lambda: UR5.inverse_kinematics("tool0", POSE, seed=-1), "seed"),
    (lambda: UR5.integrate(Q, V, dt="0.1"), "dt"),
    (lambda: UR5.integrate(Q, V, dt=None), "dt"),
    (lambda: UR5.difference(Q, "q1"), "q1"),
    (lambda: setattr(UR5, "gravity", "down"), "gravity"),
    (lambda: setattr(UR5, "armature", None), "armature"),
    (lambda: setattr(UR5, "damping", -1), "damping"),
    (lambda: robodyn.simulate(UR5, Q, t_end="1"), "t_end"),
    (lambda: robodyn.simulate(UR5, Q, dt=None), "dt"),
    (lambda: robodyn.simulate(UR5, Q, integrator=4), "integrator"),
    (lambda: robodyn.simulate(UR5, "q0"), "q0"),
    (lambda: robodyn.simulate(UR5, Q, rtol="tight"), "rtol"),
    (lambda: robodyn.simulate(UR5, Q, limits=None), "limits"),
    (lambda: robodyn.simulate(UR5, Q, controller="pd"), "controller"),
    (lambda: robodyn.simulate(UR5, Q, controller=robodyn.PD(kp="high", kd=1.0, q_ref=Q)), "kp"),
    (lambda: robodyn.simulate(UR5, Q, t_end=0.01, controller=robodyn.PD(kp=1.0, kd=None, q_ref=Q)), "kd"),
]


@pytest.mark.parametrize(("call", "argument"), CASES, ids=[f"{k}-{a}" for k, (_, a) in enumerate(CASES)])
def test_wrong_type_is_a_value_error_naming_the_argument(call, argument):
    with pytest.raises(ValueError) as error:
        call()
    message = str(error.value)
    assert f"'{argument}'" in message, message
    assert "Some(" not in message and "None)" not in message.replace("got None)", ""), message
