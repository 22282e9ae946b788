"""Model files are checked as MuJoCo checks MJCF: a typo is never read as a default. In URDF an
unknown element or attribute is a ModelWarning naming the file, line and nearest known name
(strict=True makes it an error); a missing required attribute is an error; what ROS's parser
accepts as XML loads."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import robodyn
from robodyn import inertia

LINK = """<link name="{name}"><inertial><origin xyz="0 0 0.1"/><mass value="1"/>
  <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>"""


def robot(body: str, header: str = "") -> str:
    return f"""{header}<robot name="r">
  {LINK.format(name="base")}
  {LINK.format(name="arm")}
  {body}
</robot>"""


JOINT = """<joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
  <limit lower="-1" upper="1" effort="10" velocity="2"/></joint>"""


def load(tmp_path, text, **options):
    path = tmp_path / "robot.urdf"
    path.write_text(text)
    return robodyn.load(path, **options)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        (robot(JOINT).replace('<inertial><origin xyz="0 0 0.1"/>', '<inertal><origin xyz="0 0 0.1"/>', 1)
         .replace("</inertial></link>", "</inertal></link>", 1),
         "robot.urdf: <link name='base'>/<inertal> (line 2): unknown element <inertal> in <link>; did you mean <inertial>?"),
        (robot(JOINT.replace("<limit ", "<limt ")),
         "<joint name='j'>/<limt> (line 7): unknown element <limt> in <joint>; did you mean <limit>?"),
        (robot(JOINT.replace('effort="10"', 'efort="10" effort="10"')),
         "unknown attribute 'efort' of <limit>; did you mean 'effort'?"),
        (robot(JOINT).replace("<robot ", '<robot nmae="x" ', 1), "unknown attribute 'nmae' of <robot>; did you mean 'name'?"),
        (robot(JOINT + '<jiont name="k"/>'), "unknown element <jiont> in <robot>; did you mean <joint>?"),
    ],
)
def test_a_typo_is_a_warning_naming_the_file_line_and_nearest_name(tmp_path, text, expected):
    with pytest.warns(robodyn.ModelWarning) as caught:
        model = load(tmp_path, text)
    assert any(expected in w for w in model.warnings), model.warnings
    assert any(expected in str(w.message) for w in caught)
    with pytest.raises(ValueError, match="strict=True: .*" + expected.split(": ")[-1].replace("?", r"\?").replace("<", "<")[:20]):
        load(tmp_path, text, strict=True)


def test_a_typo_inside_an_attribute_name_is_not_read_as_a_default(tmp_path):
    """`ixxx="0.1"` used to load as ixx = 0; now the missing ixx is an error naming the typo."""
    text = robot(JOINT).replace('ixx="0.01"', 'ixxx="0.01"', 1)
    with pytest.raises(
        ValueError,
        match=r"<link name='base'>/<inertia> \(line 3\): missing attribute 'ixx' \(the element has 'ixxx': a misspelling of 'ixx'\?\)",
    ):
        load(tmp_path, text)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (robot(JOINT).replace("<mass ", "<maas ", 1), r"missing <mass> \(it has <maas>: a misspelling of <mass>\?\)"),
        (robot(JOINT.replace('<parent link="base"/>', '<parnet link="base"/>')), r"missing <parent> \(it has <parnet>"),
        (robot(JOINT.replace('<parent link="base"/>', '<parent lnk="base"/>')), r"missing attribute 'link' \(the element has 'lnk'"),
        (robot(JOINT.replace(' type="revolute"', ' tpye="revolute"')), r"missing attribute 'type' \(the element has 'tpye'"),
    ],
)
def test_a_missing_name_error_names_the_unknown_name_beside_it(tmp_path, text, message):
    with pytest.raises(ValueError, match=message):
        load(tmp_path, text)


def test_a_missing_name_error_names_no_known_or_distant_name(tmp_path):
    """Only unknown names close to the missing one are suggested: `ixy` is a known attribute
    one edit from `ixx`, and `weight` is unknown but far from `value`."""
    text = robot(JOINT).replace('ixx="0.01" ', "", 1)
    with pytest.raises(ValueError, match=r"missing attribute 'ixx'$"):
        load(tmp_path, text)
    text = robot(JOINT).replace('<mass value="1"/>', '<mass weight="1"/>', 1)
    with pytest.raises(ValueError, match=r"missing attribute 'value'$"):
        load(tmp_path, text)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (robot(JOINT).replace('<mass value="1"/>', "<mass/>", 1), "missing attribute 'value'"),
        (robot(JOINT.replace(' type="revolute"', "")), "missing attribute 'type'"),
        (robot(JOINT.replace('<axis xyz="0 0 1"/>', "<axis/>")), "missing attribute 'xyz'"),
        (robot(JOINT.replace('<parent link="base"/>', "<parent/>")), "missing attribute 'link'"),
        (robot(JOINT).replace('<origin xyz="0 0 0.1"/>', '<origin xyz="0.07, 0, -0.69"/>', 1), "attribute 'xyz'"),
        (robot(JOINT).replace('<origin xyz="0 0 0.1"/>', '<origin rpy="0 0 0 1"/>', 1), "attribute 'rpy': expected 3 numbers"),
        (robot(JOINT.replace('upper="1"', 'upper="$(optenv LIMIT 1)"')), "attribute 'upper'"),
    ],
)
def test_missing_required_attributes_and_malformed_values_are_errors(tmp_path, text, message):
    with pytest.raises(ValueError, match=message) as error:
        load(tmp_path, text)
    assert "robot.urdf" in str(error.value) and "(line " in str(error.value)


def test_elements_that_are_not_robodyns_business_pass_silently(tmp_path):
    text = robot(JOINT + """
  <material name="blue"><color rgba="0 0 1 1"/></material>
  <gazebo reference="arm"><mu1>0.2</mu1><anything at="all"/></gazebo>
  <transmission name="t"><type>SimpleTransmission</type><joint name="j"/></transmission>
  <ros2_control name="c" type="system"><hardware><plugin>mock</plugin></hardware></ros2_control>""").replace(
        '<link name="arm">', '<link name="arm"><visual name="v"><origin xyz="0 0 0"/><geometry><mesh filename="arm.stl" scale="1 1 1"/></geometry>'
        '<material name="blue"/></visual><collision><geometry><cylinder radius="0.1" length="0.2"/></geometry></collision>', 1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model = load(tmp_path, text, strict=True)
    assert model.warnings == []


def test_an_xml_declaration_after_a_comment_loads_with_a_warning(tmp_path):
    """As in two URDFs pybullet ships: a comment, blank lines, then <?xml ...?>."""
    text = robot(JOINT, header='<!-- exported -->\n\n<?xml version="1.0" ?>\n')
    with pytest.warns(robodyn.ModelWarning, match=r"the XML declaration is not at the start of the file \(line 3\)"):
        model = load(tmp_path, text)
    assert model.joint_names == ["j"]
    with pytest.raises(ValueError, match="XML declaration"):
        load(tmp_path, text, strict=True)


def test_unknown_names_are_grouped_per_name(tmp_path):
    text = robot(JOINT).replace('<mass value="1"/>', '<mass value="1" unit="kg"/>')
    with pytest.warns(robodyn.ModelWarning):
        model = load(tmp_path, text)
    assert len(model.warnings) == 1 and "(2 times; the first is here)" in model.warnings[0]


def test_published_urdfs(robots_dir):
    """UR5 and Solo12 follow the specification; the Panda's <dynamics> carries four attributes of its
    own, reported once each."""
    for path in ("ur_description/urdf/ur5_robot.urdf", "solo_description/robots/solo12.urdf"):
        model = robodyn.load(robots_dir / path, strict=True)
        assert model.warnings == []
    with pytest.warns(robodyn.ModelWarning):
        panda = robodyn.load(robots_dir / "panda_description/urdf/panda.urdf")
    assert sorted(w.split("unknown attribute ")[1].split(" of")[0] for w in panda.warnings) == ["'D'", "'K'", "'mu_coulomb'", "'mu_viscous'"]
    assert all("times; the first is here" in w for w in panda.warnings)


def test_an_inertia_that_breaks_the_triangle_inequality_follows_the_one_rule(tmp_path):
    """One rule for physical inertias: a file's tensor whose principal moments break the triangle
    inequality is a ModelWarning naming the link and the three moments (strict=True refuses it),
    the setter takes it back with the same warning, and check_physical refuses it."""
    text = robot(JOINT)
    at = text.rindex('ixx="0.01"')
    text = text[:at] + 'ixx="0.03"' + text[at + len('ixx="0.01"'):]
    expected = (
        r"<link name='arm'>/<inertial> \(line 4\): the principal moments about the centre of mass "
        r"\[1\.000000e-2, 1\.000000e-2, 3\.000000e-2\] break the triangle inequality"
    )
    with pytest.warns(robodyn.ModelWarning, match=expected):
        model = load(tmp_path, text)
    with pytest.raises(ValueError, match="strict=True: .*break the triangle inequality"):
        load(tmp_path, text, strict=True)
    parameters = model.inertial_parameters
    with pytest.warns(robodyn.ModelWarning, match=r"row 0 \(body 'arm'\): the principal moments .* break the triangle inequality"):
        model.inertial_parameters = parameters
    assert (model.inertial_parameters == parameters).all()
    with pytest.raises(ValueError, match="argument 'inertia': the principal moments .* break the triangle inequality"):
        inertia.check_physical(np.diag([0.01, 0.01, 0.03]), mass=1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        load(tmp_path, robot(JOINT)).inertial_parameters = load(tmp_path, robot(JOINT)).inertial_parameters
