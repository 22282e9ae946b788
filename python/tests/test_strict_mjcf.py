"""MJCF is checked as MuJoCo checks it: an unknown element or attribute is an error naming the file,
line and nearest known name, for exactly the names MuJoCo refuses (the table is generated from
MuJoCo's own schema)."""

from __future__ import annotations

import re
import subprocess
import sys

import mujoco
import pytest
from conftest import REPOSITORY

import robodyn

MODEL = """<mujoco model="m">
  <compiler angle="radian"/>
  <default><joint damping="0.1"/></default>
  <worldbody>
    <body name="a" pos="0 0 1">
      <joint name="j" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.04"/>
      <site name="s" pos="0.3 0 0"/>
    </body>
  </worldbody>
</mujoco>"""

TYPOS = [
    ('<joint name="j"', '<jiont name="j"', "unknown element <jiont> in <body>; did you mean <joint>?"),
    ('size="0.04"', 'sizee="0.04"', "unknown attribute 'sizee' of <geom>; did you mean 'size'?"),
    ('<compiler angle="radian"/>', '<compiler angel="radian"/>', "unknown attribute 'angel' of <compiler>; did you mean 'angle'?"),
    ('<default><joint damping="0.1"/></default>', '<default><joint dampng="0.1"/></default>', "unknown attribute 'dampng' of <joint>; did you mean 'damping'?"),
    ("worldbody>", "worldbdy>", "unknown element <worldbdy> in <mujoco>; did you mean <worldbody>?"),
    ('<body name="a" pos="0 0 1">', '<body name="a" pos="0 0 1" mas="1">', "unknown attribute 'mas' of <body>"),
    ("<worldbody>", '<worldbody pos="1 0 0">', "unknown attribute 'pos' of <worldbody>"),
]


@pytest.mark.parametrize(("old", "new", "message"), TYPOS, ids=[t[2].split(";")[0] for t in TYPOS])
def test_an_unknown_name_is_an_error_as_in_mujoco(old, new, message, tmp_path):
    text = MODEL.replace(old, new)
    path = tmp_path / "arm.xml"
    path.write_text(text)
    with pytest.raises(ValueError, match=re.escape(message)) as error:
        robodyn.load(path)
    assert "arm.xml" in str(error.value) and "(line " in str(error.value)
    with pytest.raises(ValueError, match="Schema violation|World body cannot have attributes"):
        mujoco.MjModel.from_xml_path(str(path))


def test_names_mujoco_knows_but_robodyn_does_not_read_pass_the_check():
    text = MODEL.replace("</worldbody>", """</worldbody>
  <visual><global offwidth="640"/></visual>
  <asset><texture name="t" type="2d" builtin="checker" width="8" height="8"/></asset>
  <actuator><motor joint="j" gear="2"/></actuator>
  <sensor><jointpos joint="j"/></sensor>""").replace('<site name="s"', '<camera name="c" fovy="45"/><light pos="0 0 1"/><site name="s"')
    model = robodyn.load_mjcf_string(text)
    mujoco.MjModel.from_xml_string(text)
    assert model.joint_names == ["j"]


def test_frames_and_includes_are_checked_too(tmp_path):
    (tmp_path / "arm.xml").write_text('<mujoco><worldbody><frame pos="0 0 1"><body name="b"><geom size="0.1" densty="2"/></body></frame></worldbody></mujoco>')
    (tmp_path / "scene.xml").write_text('<mujoco><include file="arm.xml"/></mujoco>')
    with pytest.raises(ValueError, match=r"arm\.xml: <body name='b'>/<geom> \(line 1\): unknown attribute 'densty' of <geom>; did you mean 'density'\?"):
        robodyn.load(tmp_path / "scene.xml")


def test_the_schema_table_is_mujocos():
    """crates/robodyn/src/io/mjcf/schema_table.rs is what scripts/mjcf_schema.py makes of the installed
    MuJoCo's schema (when it is the version the table says)."""
    table = (REPOSITORY / "crates/robodyn/src/io/mjcf/schema_table.rs").read_text()
    version = re.search(r"as MuJoCo (\S+) reads them", table).group(1)
    assert version == mujoco.__version__, f"the table is MuJoCo {version}'s; run scripts/mjcf_schema.py for {mujoco.__version__}"
    result = subprocess.run([sys.executable, str(REPOSITORY / "scripts/mjcf_schema.py"), "--check"], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
