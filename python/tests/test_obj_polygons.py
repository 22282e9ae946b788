"""OBJ faces of more than 100 corners give no triangles, as in MuJoCo 4.0 (its reader cuts a face
into triangles only up to 100 corners and drops a larger one without a word): a pyramid whose
base is one regular n-gon face and whose sides are n triangles, beside MuJoCo at n = 100 and 101."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

import robodyn

#: Mass and centre of mass of a compiled mesh body agree with MuJoCo's to this, relative.
MESH_MASS_TOLERANCE = 1e-12

CORNER_LIMIT = 100


def pyramid_obj(n: int) -> str:
    """A comment line, n base vertices, the apex, the base face, then the n side faces."""
    lines = ["# pyramid"]
    lines += [f"v {math.cos(2 * math.pi * k / n)!r} {math.sin(2 * math.pi * k / n)!r} 0" for k in range(n)]
    lines.append("v 0 0 1")
    lines.append("f " + " ".join(str(k) for k in range(n, 0, -1)))
    lines += [f"f {k} {k % n + 1} {n + 1}" for k in range(1, n + 1)]
    return "\n".join(lines) + "\n"


def scene(tmp_path, n: int):
    (tmp_path / "pyramid.obj").write_text(pyramid_obj(n))
    path = tmp_path / "pyramid.xml"
    path.write_text("""<mujoco><asset><mesh name="pyramid" file="pyramid.obj"/></asset>
      <worldbody><body name="b"><freejoint/><geom type="mesh" mesh="pyramid"/></body></worldbody></mujoco>""")
    return path


@pytest.mark.parametrize("n", [CORNER_LIMIT, CORNER_LIMIT + 1])
def test_a_large_obj_face_is_dropped_as_mujoco_drops_it(tmp_path, n):
    path = scene(tmp_path, n)
    mj = mujoco.MjModel.from_xml_path(str(path))
    if n > CORNER_LIMIT:
        with pytest.warns(robodyn.ModelWarning, match=rf"pyramid\.obj'?: line {n + 3}: a face of {n} corners gives no triangles"):
            model = robodyn.load(path)
    else:
        model = robodyn.load(path)
        assert not any("corners" in w for w in model.warnings)
    mass, com = model.inertial_parameters[0, 0], model.inertial_parameters[0, 1:4] / model.inertial_parameters[0, 0]
    np.testing.assert_allclose(mass, mj.body_mass[1], rtol=MESH_MASS_TOLERANCE)
    np.testing.assert_allclose(com, mj.body_ipos[1], rtol=0, atol=MESH_MASS_TOLERANCE * np.abs(mj.body_ipos[1]).max())
    # the closed pyramid's centre of mass is a quarter of its height up; its open sides' is not
    assert (abs(com[2] - 0.25) < 1e-3) == (n <= CORNER_LIMIT), com

