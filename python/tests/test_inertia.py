"""robodyn.inertia: the notes' inertia tensors (the TU Berlin notes), checked against their closed forms,
against MuJoCo's inertia of the same primitive, and against robodyn's own mass matrix."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from conftest import IDENTITY_TOLERANCE, assert_close

import robodyn
from robodyn import inertia


def test_box_about_a_corner_is_the_notes_example():
    """The TU Berlin notes, "Inertia Tensor Example": sides w (x), l (y), h (z), about the corner."""
    m, w, l, h = 3.0, 0.2, 0.5, 0.3
    expected = [
        [m / 3 * (l**2 + h**2), -m / 4 * w * l, -m / 4 * h * w],
        [-m / 4 * w * l, m / 3 * (w**2 + h**2), -m / 4 * h * l],
        [-m / 4 * h * w, -m / 4 * h * l, m / 3 * (l**2 + w**2)],
    ]
    corner = inertia.solid_box(m, (w, l, h), about="corner")
    np.testing.assert_allclose(corner, expected, rtol=1e-15)
    # the parallel-axis theorem both ways links it to the box about its centre
    centre = inertia.solid_box(m, (w, l, h))
    assert_close(inertia.shift_from_com(centre, m, (w / 2, l / 2, h / 2)), corner, IDENTITY_TOLERANCE)
    assert_close(inertia.shift_to_com(corner, m, (w / 2, l / 2, h / 2)), centre, IDENTITY_TOLERANCE)


def test_primitives_closed_forms():
    m, r, length = 2.0, 0.1, 0.6
    assert_close(inertia.solid_sphere(m, r), np.eye(3) * 0.4 * m * r * r, IDENTITY_TOLERANCE)
    assert_close(inertia.hollow_sphere(m, r), np.eye(3) * 2 / 3 * m * r * r, IDENTITY_TOLERANCE)
    # a thick shell tends to the thin one
    assert_close(inertia.hollow_sphere(m, r, inner_radius=r * (1 - 1e-7)), inertia.hollow_sphere(m, r), 1e-6)
    assert_close(inertia.solid_cylinder(m, r, length, axis="x"), np.diag([m * r * r / 2, *(2 * [m * (3 * r * r + length**2) / 12])]), IDENTITY_TOLERANCE)
    assert_close(inertia.hollow_cylinder(m, r, length), np.diag([*(2 * [m * (6 * r * r + length**2) / 12]), m * r * r]), IDENTITY_TOLERANCE)
    assert_close(inertia.rod(m, length, about="end"), inertia.rod(m, length) + np.diag([1, 1, 0]) * m * (length / 2) ** 2, IDENTITY_TOLERANCE)


@pytest.mark.parametrize("geom", ["capsule", "cylinder", "sphere", "box"])
def test_primitives_agree_with_mujoco(geom):
    """The same solid in MuJoCo (a body whose inertia comes from one geom)."""
    size = {"capsule": "0.05 0.2", "cylinder": "0.05 0.2", "sphere": "0.07", "box": "0.1 0.2 0.3"}[geom]
    text = f"<mujoco><worldbody><body><freejoint/><geom type='{geom}' size='{size}' mass='1.5'/></body></worldbody></mujoco>"
    mj = mujoco.MjModel.from_xml_string(text)
    ours = {
        "capsule": lambda: inertia.capsule(1.5, 0.05, 0.4),
        "cylinder": lambda: inertia.solid_cylinder(1.5, 0.05, 0.4),
        "sphere": lambda: inertia.solid_sphere(1.5, 0.07),
        "box": lambda: inertia.solid_box(1.5, (0.2, 0.4, 0.6)),
    }[geom]()
    np.testing.assert_allclose(np.sort(np.diag(ours)), np.sort(mj.body_inertia[1]), rtol=1e-12)


def test_rotation_and_principal_axes():
    rng = np.random.default_rng(1)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    rotation = q * np.sign(np.linalg.det(q))
    tensor = inertia.rotate(np.diag([0.3, 0.1, 0.25]), rotation)
    moments, axes = inertia.principal_axes(tensor)
    np.testing.assert_allclose(moments, [0.1, 0.25, 0.3], rtol=1e-12)
    assert np.linalg.det(axes) == pytest.approx(1.0)
    assert_close(axes @ np.diag(moments) @ axes.T, tensor, IDENTITY_TOLERANCE)
    # the trace (sum of moments) does not depend on the axes
    assert np.trace(tensor) == pytest.approx(0.65)
    with pytest.raises(ValueError, match="argument 'rotation'"):
        inertia.rotate(tensor, np.diag([1.0, 1.0, -1.0]))


def test_physical_validity():
    inertia.check_physical(inertia.solid_box(1.0, (0.1, 0.2, 0.3)), mass=1.0)
    for bad, message in [
        (np.diag([1.0, 1.0, 3.0]), "triangle inequality"),
        (np.diag([1.0, -1.0, 1.0]), "positive semi-definite"),
        ([[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], "symmetric"),
        (np.eye(2), "3x3"),
    ]:
        with pytest.raises(ValueError, match=message):
            inertia.check_physical(bad)
    with pytest.raises(ValueError, match="argument 'mass'"):
        inertia.solid_sphere(-1.0, 0.1)


def test_spatial_inertia_is_the_free_bodys_mass_matrix():
    """A free body at the identity pose: M = the spatial inertia about its origin, [linear; angular]."""
    mass, com, tensor = 2.5, np.array([0.1, -0.2, 0.05]), inertia.solid_box(2.5, (0.3, 0.2, 0.1))
    urdf = f"""<robot name="body"><link name="b"><inertial><origin xyz="{com[0]} {com[1]} {com[2]}"/><mass value="{mass}"/>
      <inertia ixx="{tensor[0, 0]}" iyy="{tensor[1, 1]}" izz="{tensor[2, 2]}" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>"""
    model = robodyn.load_urdf_string(urdf, floating_base=True)
    spatial = inertia.spatial_inertia(mass, com, tensor)
    assert_close(model.mass_matrix(model.neutral()), spatial, IDENTITY_TOLERANCE)
    back_mass, back_com, back_tensor = inertia.from_spatial_inertia(spatial)
    assert back_mass == mass
    assert_close(back_com, com, IDENTITY_TOLERANCE)
    assert_close(back_tensor, tensor, IDENTITY_TOLERANCE)
