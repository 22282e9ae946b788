"""What an MJCF scene says of contacts and simulation, read as MuJoCo compiles it: the geoms as
collision shapes with their contact parameters, `<contact>` pairs and exclusions, `<option>` and
its flags, the joints' soft limits and friction. Compared field by field with `mujoco`'s compiled
model, on a scene written to exercise defaults, classes and leading values, and on robots from
Menagerie and mjlab."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import mujoco
import numpy as np
import pytest
from conftest import REPOSITORY, assert_close, assert_refused_as_in_mujoco
from conftest import load_quietly as load

import robodyn
from robodyn.convert import MujocoLayout

#: MuJoCo's compiler and robodyn place the geoms from the same poses in double precision.
COMPILER_TOLERANCE = 1e-12

SCENE = """<mujoco model="scene">
  <compiler angle="degree"/>
  <option timestep="0.001" integrator="implicitfast" cone="elliptic" impratio="10" tolerance="1e-10"
          iterations="50" ls_iterations="20" noslip_iterations="3" o_margin="0.01" o_solimp="0.8 0.9"
          o_friction="0.5 0.5">
    <flag warmstart="disable" energy="enable"/>
  </option>
  <default>
    <geom friction="0.6 0.01" solimp="0.8 0.9" condim="4"/>
    <joint solreflimit="0.03" solimplimit="0.8 0.9 0.002"/>
    <pair condim="1" friction="0.2"/>
    <default class="soft">
      <geom friction="0.3" solref="0.05 0.9" solmix="2" margin="0.002" gap="0.001" priority="1"/>
      <joint solimplimit="0.7" margin="0.01" solreffriction="0.01 0.5" solimpfriction="0.5"/>
      <pair solimp="0.7 0.8"/>
    </default>
  </default>
  <worldbody>
    <geom name="floor" type="plane" size="0 0 0.05" contype="1" conaffinity="3"/>
    <body name="base" pos="0 0 0.5">
      <freejoint name="root"/>
      <geom name="torso" type="box" size="0.2 0.1 0.05" class="soft" friction="0.9"/>
      <body name="thigh" pos="0.2 0 0">
        <joint name="hip" axis="0 1 0" range="-60 60" class="soft"/>
        <geom name="leg" type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03" contype="2" conaffinity="0"/>
        <body name="shin" pos="0 0 -0.3">
          <joint name="knee" axis="0 1 0" range="-120 0" frictionloss="0.1" margin="0.05"/>
          <geom name="ankle" size="0.03"/>
          <geom name="foot" type="sphere" size="0.04" pos="0 0 -0.25" solimp="0.95" condim="6"/>
          <body name="toe" pos="0.05 0 -0.25">
            <geom name="toe" type="ellipsoid" size="0.02 0.01 0.01" friction="1.2 0.02 0.003"/>
          </body>
        </body>
      </body>
      <frame pos="-0.2 0 0" euler="0 90 0">
        <geom name="tail" type="cylinder" size="0.02 0.1" class="soft"/>
      </frame>
    </body>
  </worldbody>
  <contact>
    <pair geom1="floor" geom2="foot"/>
    <pair name="soft_toe" geom1="floor" geom2="toe" class="soft" friction="0.4 0.3 0.01" margin="0.003"
          solreffriction="0.02 0.8"/>
    <exclude body1="base" body2="shin"/>
  </contact>
</mujoco>"""


def package_folder(name: str) -> Path:
    """Where a test-data package is installed (found without importing it)."""
    spec = importlib.util.find_spec(name)
    assert spec is not None and spec.submodule_search_locations, f"{name} is a test dependency: run ./scripts/test"
    return Path(list(spec.submodule_search_locations)[0])


def mujoco_name(compiled, kind, index):
    return mujoco.mj_id2name(compiled, kind, index)


def assert_geoms_are_mujocos(model, compiled, label):
    """Every geom's filter and contact parameters, and a primitive's size and world pose at
    qpos0, equal MuJoCo's (SDFs are not read)."""
    kept = [g for g in range(compiled.ngeom) if compiled.geom_type[g] != mujoco.mjtGeom.mjGEOM_SDF]
    geoms = model.geoms
    assert len(geoms) == len(kept), label
    data = mujoco.MjData(compiled)
    mujoco.mj_kinematics(compiled, data)
    poses = model.body_poses(model.neutral())
    for geom, g in zip(geoms, kept, strict=True):
        where = f"{label} geom {g} ({geom['name']})"
        name = mujoco_name(compiled, mujoco.mjtObj.mjOBJ_GEOM, g)
        if name:
            assert geom["name"] == name, where
        body = mujoco_name(compiled, mujoco.mjtObj.mjOBJ_BODY, int(compiled.geom_bodyid[g]))
        if body:
            assert geom["source_body"] == body, where
        integers = ("contype", "conaffinity", "condim", "priority")
        expected = (compiled.geom_contype[g], compiled.geom_conaffinity[g], compiled.geom_condim[g], compiled.geom_priority[g])
        assert tuple(geom[k] for k in integers) == tuple(int(x) for x in expected), where
        for key, value in [
            ("friction", compiled.geom_friction[g]),
            ("solmix", compiled.geom_solmix[g]),
            ("solref", compiled.geom_solref[g]),
            ("solimp", compiled.geom_solimp[g]),
            ("margin", compiled.geom_margin[g]),
            ("gap", compiled.geom_gap[g]),
        ]:
            assert_close(geom[key], value, 0.0, f"{where} {key}")
        if geom["kind"] == "mesh":
            continue  # MuJoCo moves a mesh geom's frame to the mesh's inertia frame
        if geom["kind"] == "hfield":
            # MuJoCo's geom size of a field is its inertia box's; the field's own is the asset's
            assert_close(geom["size"], compiled.hfield_size[compiled.geom_dataid[g]], 0.0, f"{where} size")
        else:
            assert_close(geom["size"], compiled.geom_size[g][: len(geom["size"])], COMPILER_TOLERANCE, f"{where} size")
        world = poses[geom["body"]] @ geom["placement"]
        assert_close(world[:3, 3], data.geom_xpos[g], COMPILER_TOLERANCE, f"{where} position")
        assert_close(world[:3, :3], data.geom_xmat[g].reshape(3, 3), COMPILER_TOLERANCE, f"{where} rotation")


def assert_contacts_are_mujocos(model, compiled, label):
    pairs = model.contact_pairs
    assert len(pairs) == compiled.npair, label
    for k, pair in enumerate(pairs):
        where = f"{label} pair {k}"
        geom = lambda g: mujoco_name(compiled, mujoco.mjtObj.mjOBJ_GEOM, int(g))  # noqa: E731
        assert (pair["geom1"], pair["geom2"]) == (geom(compiled.pair_geom1[k]), geom(compiled.pair_geom2[k])), where
        assert pair["condim"] == compiled.pair_dim[k], where
        for key, value in [
            ("friction", compiled.pair_friction[k]),
            ("solref", compiled.pair_solref[k]),
            ("solreffriction", compiled.pair_solreffriction[k]),
            ("solimp", compiled.pair_solimp[k]),
            ("margin", compiled.pair_margin[k]),
            ("gap", compiled.pair_gap[k]),
        ]:
            assert_close(pair[key], value, 0.0, f"{where} {key}")
    # MuJoCo keeps an exclusion as the signature body1 << 16 | body2, whichever way it is written
    body = lambda name: mujoco.mj_name2id(compiled, mujoco.mjtObj.mjOBJ_BODY, name)  # noqa: E731
    signature = lambda one, other: min(one, other) << 16 | max(one, other)  # noqa: E731
    ours = sorted(signature(body(one), body(other)) for one, other in model.contact_excludes)
    theirs = sorted(signature(s >> 16, s & 0xFFFF) for s in compiled.exclude_signature)
    assert ours == theirs, label


def assert_options_are_mujocos(model, compiled, label):
    options, expected = model.options, compiled.opt
    assert options.integrator == ["Euler", "RK4", "implicit", "implicitfast", "discrete"][expected.integrator], label
    assert options.cone == ["pyramidal", "elliptic"][expected.cone], label
    assert options.solver == ["PGS", "CG", "Newton"][expected.solver], label
    for key in ("timestep", "impratio", "tolerance", "ls_tolerance", "noslip_tolerance"):
        assert getattr(options, key) == getattr(expected, key), f"{label} {key}"
    for key in ("iterations", "ls_iterations", "noslip_iterations"):
        assert getattr(options, key) == getattr(expected, key), f"{label} {key}"
    assert options.o_margin == expected.o_margin, label
    assert_close(options.o_solref, expected.o_solref, 0.0, f"{label} o_solref")
    assert_close(options.o_solimp, expected.o_solimp, 0.0, f"{label} o_solimp")
    assert_close(options.o_friction, expected.o_friction, 0.0, f"{label} o_friction")
    # each flag as MuJoCo's bit says
    for name, bit in mujoco.mjtDisableBit.__members__.items():
        if name != "mjNDISABLE":
            flag = name.removeprefix("mjDSBL_").lower()
            assert options.flag(flag) == (not expected.disableflags & int(bit)), f"{label} {flag}"
    for name, bit in mujoco.mjtEnableBit.__members__.items():
        if name != "mjNENABLE":
            flag = name.removeprefix("mjENBL_").lower()
            assert options.flag(flag) == bool(expected.enableflags & int(bit)), f"{label} {flag}"


def assert_joint_softness_is_mujocos(model, compiled, label):
    for name, softness in zip(model.joint_names, model.joint_softness, strict=True):
        j = mujoco.mj_name2id(compiled, mujoco.mjtObj.mjOBJ_JOINT, name)
        if j < 0:
            continue  # an unnamed joint robodyn names itself
        dof = compiled.jnt_dofadr[j]
        for key, value in [
            ("solreflimit", compiled.jnt_solref[j]),
            ("solimplimit", compiled.jnt_solimp[j]),
            ("margin", compiled.jnt_margin[j]),
            ("solreffriction", compiled.dof_solref[dof]),
            ("solimpfriction", compiled.dof_solimp[dof]),
        ]:
            assert_close(softness[key], value, 0.0, f"{label} joint {name} {key}")


def assert_scene_is_mujocos(model, compiled, label):
    assert_geoms_are_mujocos(model, compiled, label)
    assert_contacts_are_mujocos(model, compiled, label)
    assert_options_are_mujocos(model, compiled, label)
    assert_joint_softness_is_mujocos(model, compiled, label)


def test_a_scene_with_classes_and_leading_values_is_mujocos():
    model, compiled = load(text=SCENE), mujoco.MjModel.from_xml_string(SCENE)
    assert_scene_is_mujocos(model, compiled, "scene")
    # what the classes and leading values make of it, spelled out
    geoms = {geom["name"]: geom for geom in model.geoms}
    torso, foot = geoms["torso"], geoms["foot"]
    assert torso["friction"] == [0.9, 0.01, 0.0001] and torso["priority"] == 1
    assert foot["solimp"] == [0.95, 0.9, 0.001, 0.5, 2.0] and foot["condim"] == 6
    assert model.contact_pairs[0]["friction"] == [0.2, 1.0, 0.005, 0.0001, 0.0001]
    assert model.contact_excludes == [("base", "shin")]
    assert model.options.disabled == ["warmstart"] and model.options.enabled == ["energy"]


#: Two top-level <default>s (an included file's and the includer's): the second adds to the
#: first's "main", a class takes its parent as it stands where the class is declared.
TWO_DEFAULTS = """<mujoco>
  <default><geom contype="0" size="0.3"/><default class="a"><geom conaffinity="0"/></default></default>
  <default><geom priority="2"/><default class="b"><geom size="0.5"/></default></default>
  <worldbody><geom name="g"/><geom name="h" class="a"/><geom name="k" class="b"/></worldbody>
</mujoco>"""


def test_a_second_top_level_default_adds_to_the_first():
    model, compiled = load(text=TWO_DEFAULTS), mujoco.MjModel.from_xml_string(TWO_DEFAULTS)
    assert_geoms_are_mujocos(model, compiled, "two defaults")
    geoms = {geom["name"]: geom for geom in model.geoms}
    assert [(geoms[n]["contype"], geoms[n]["conaffinity"], geoms[n]["priority"]) for n in "ghk"] == [
        (0, 1, 2),
        (0, 0, 0),
        (0, 1, 2),
    ]


SCENE_FILES = [
    ("testdata", "mjcf/cassie_nomesh.xml"),
    ("testdata", "mjcf/iiwa14_scene.xml"),
    ("testdata", "menagerie/robotiq_2f85/2f85.xml"),
    ("mjlab", "asset_zoo/robots/unitree_g1/xmls/g1.xml"),
    ("mjlab", "asset_zoo/robots/unitree_go1/xmls/go1.xml"),
    ("mjlab", "asset_zoo/robots/i2rt_yam/xmls/yam.xml"),
]


@pytest.mark.parametrize(("package", "file"), SCENE_FILES)
def test_published_scenes_are_read_as_mujoco_compiles_them(package, file):
    folder = REPOSITORY / "testdata" if package == "testdata" else package_folder(package)
    path = folder / file
    model, compiled = load(path), mujoco.MjModel.from_xml_path(str(path))
    assert_scene_is_mujocos(model, compiled, file)


def test_disabled_gravity_and_equalities_are_followed_and_the_rest_named():
    held = SCENE.replace("</contact>", '</contact><equality><joint joint1="knee"/></equality>')
    assert len(load(text=held).constraints) == 1
    flags = '<flag gravity="disable" equality="disable" limit="disable"/>'
    text = held.replace('<flag warmstart="disable" energy="enable"/>', flags)
    model = robodyn.load_mjcf_string(text)
    assert_close(model.gravity, np.zeros(3), 0.0, "gravity")
    assert model.constraints == []
    assert not model.options.flag("gravity") and not model.options.flag("limit")
    messages = " ".join(model.warnings)
    # the scene's own dynamics follows 'limit'; robodyn's other integrators have no soft limits
    assert "'limit'" not in messages
    springless = held.replace('<flag warmstart="disable" energy="enable"/>',
                              '<flag spring="disable" clampctrl="disable" multiccd="disable"/>')
    messages = " ".join(robodyn.load_mjcf_string(springless).warnings)
    assert "<flag> 'multiccd' not followed" in messages and "clampctrl" not in messages
    assert "<flag> 'spring' followed by the scene's own dynamics" in messages
    assert "robodyn.simulate feels them only with integrator='mujoco'" in messages


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (('condim="6"', 'condim="2"'), r"line \d+.*attribute 'condim': expected 1, 3, 4 or 6, got 2"),
        (('geom2="foot"', 'geom2="hand"'), r"line \d+.*attribute 'geom2': no geom is called 'hand'"),
        (('body2="shin"', 'body2="arm"'), r"line \d+.*attribute 'body2': no body is called 'arm'"),
        (('energy="enable"', 'energy="on"'), r"line \d+.*attribute 'energy': expected enable or disable, got 'on'"),
        (('cone="elliptic"', 'cone="Elliptic"'), r"line \d+.*attribute 'cone': expected one of pyramidal, elliptic"),
        (('solimp="0.95"', 'solimp="0.95 0.9 0.001 0.5 2 7"'), r"line \d+.*attribute 'solimp': expected 1 to 5 numbers"),
        (('contype="2"', 'contype="two"'), r"line \d+.*attribute 'contype': expected an integer, got 'two'"),
    ],
)
def test_what_mujoco_refuses_is_refused_by_name_and_line(change, message):
    broken = SCENE.replace(*change)
    assert broken != SCENE
    with pytest.raises(ValueError, match=message):
        robodyn.load_mjcf_string(broken)
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_string(broken)


def test_a_time_step_that_is_not_positive_is_refused():
    """MuJoCo compiles timestep="0"; no simulation can step with it."""
    with pytest.raises(ValueError, match=r"line \d+.*attribute 'timestep': expected a positive time step"):
        robodyn.load_mjcf_string(SCENE.replace('timestep="0.001"', 'timestep="0"'))


def test_models_from_other_formats_have_mujocos_defaults_and_no_geoms():
    model = robodyn.load_bundled(robodyn.bundled_names()[0])
    assert model.geoms == [] and model.contact_pairs == [] and model.contact_excludes == []
    assert model.options.timestep == 0.002 and model.options.integrator == "Euler"
    assert all(s["solreflimit"] == [0.02, 1.0] for s in model.joint_softness)
    with pytest.raises(ValueError, match="argument 'name': unknown flag 'gravty'"):
        model.options.flag("gravty")


def pairs_mujoco_checks(compiled):
    """The geom pairs MuJoCo's collision driver checks, as sorted geom ids: with every margin
    overridden to 100 m, each checked pair of primitives and convex meshes is found in contact."""
    compiled.opt.enableflags |= int(mujoco.mjtEnableBit.mjENBL_OVERRIDE)
    compiled.opt.o_margin = 100.0
    data = mujoco.MjData(compiled)
    mujoco.mj_forward(compiled, data)
    return {tuple(sorted((int(c.geom1), int(c.geom2)))) for c in data.contact[: data.ncon]}


@pytest.mark.parametrize(("package", "file"), [("text", "scene"), *SCENE_FILES])
def test_the_pairs_checked_for_contact_are_mujocos(package, file):
    if package == "text":
        model, compiled = load(text=SCENE), mujoco.MjModel.from_xml_string(SCENE)
    else:
        folder = REPOSITORY / "testdata" if package == "testdata" else package_folder(package)
        model, compiled = load(folder / file), mujoco.MjModel.from_xml_path(str(folder / file))
    # robodyn's geoms are MuJoCo's in order, SDFs left out
    kept = [g for g in range(compiled.ngeom) if compiled.geom_type[g] != mujoco.mjtGeom.mjGEOM_SDF]
    index = {geom["name"]: kept[k] for k, geom in enumerate(model.geoms)}
    ids = lambda one, other: tuple(sorted((index[one], index[other])))  # noqa: E731
    explicit = {ids(p["geom1"], p["geom2"]) for p in model.contact_pairs}
    candidates = [ids(*pair) for pair in model.contact_candidates]
    assert len(set(candidates)) == len(candidates) and not set(candidates) & explicit
    assert set(candidates) | explicit == pairs_mujoco_checks(compiled), file


#: MuJoCo and robodyn add the same two margins of about 50 m in double precision.
MARGIN_TOLERANCE = 1e-12


@pytest.mark.parametrize("override", [False, True])
def test_each_contact_takes_mujocos_parameters(override):
    """Every contact MuJoCo finds (every margin raised by 50 or 100 m so that every checked pair is in
    contact) has the condim, friction, solref, solreffriction, solimp and margin robodyn's
    `contact_parameters` gives its two geoms: explicit pairs as they are, dynamic pairs mixed
    by priority and solmix; with the `<option>` override, the override's."""
    text = SCENE.replace('<flag warmstart="disable" energy="enable"/>', '<flag override="enable"/>') if override else SCENE
    # solmix, priority and direct (negative) solref cases beside the scene's
    text = text.replace('name="leg" type="capsule"', 'name="leg" solmix="0" solref="-2000 -50" type="capsule"')
    # margins of 50 m on every geom and 100 m on every pair (100 m overriding), so that every
    # pair MuJoCo checks is in contact: the file's own margins are raised in the text both read
    text = text.replace('margin="0.002"', 'margin="50.002"').replace('margin="0.003"', 'margin="100.003"')
    text = text.replace('<geom friction="0.6 0.01"', '<geom margin="50" friction="0.6 0.01"')
    text = text.replace('<pair condim="1"', '<pair margin="100" condim="1"').replace('o_margin="0.01"', 'o_margin="100"')
    model, compiled = load(text=text), mujoco.MjModel.from_xml_string(text)
    data = mujoco.MjData(compiled)
    mujoco.mj_forward(compiled, data)
    names = [mujoco_name(compiled, mujoco.mjtObj.mjOBJ_GEOM, g) for g in range(compiled.ngeom)]
    checked = set()
    for contact in data.contact[: data.ncon]:
        one, other = names[contact.geom1], names[contact.geom2]
        expected = model.contact_parameters(one, other)
        where = f"{one}-{other}"
        assert contact.dim == expected["condim"], where
        for key, value in [
            ("friction", contact.friction),
            ("solref", contact.solref),
            ("solreffriction", contact.solreffriction),
            ("solimp", contact.solimp),
        ]:
            assert_close(expected[key], value, 1e-15, f"{where} {key}")
        assert abs(contact.includemargin - expected["margin"]) <= MARGIN_TOLERANCE, where
        checked.add(tuple(sorted((one, other))))
    assert len(checked) == len(model.contact_candidates) + len(model.contact_pairs)
    with pytest.raises(ValueError, match="argument 'geom1': no geom is called 'hand'"):
        model.contact_parameters("hand", "floor")
    with pytest.raises(ValueError, match="argument 'geom2': expected a geom other than geom1"):
        model.contact_parameters("floor", "floor")


# --- fixed tendons ------------------------------------------------------------------------------

TENDON_ARM = """<mujoco><worldbody>
  <body name="a"><joint name="hinge" axis="0 1 0"/><geom size="0.1"/>
    <body name="b" pos="0 0 -0.3"><joint name="slide" type="slide" axis="1 0 0"/><geom size="0.1"/>
      <body name="c" pos="0 0 -0.3"><joint name="ball" type="ball"/><geom size="0.1"/></body></body></body>
  </worldbody>
  <tendon><fixed name="pull" range="0 1" springlength="0.2 0.4">
    <joint joint="hinge" coef="1"/><joint joint="slide" coef="-2"/></fixed></tendon>
  <actuator><motor name="drive" tendon="pull" gear="3"/></actuator></mujoco>"""


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (('joint="slide" coef="-2"', 'joint="slid" coef="-2"'), r"line \d+.*attribute 'joint': no joint is called 'slid'"),
        (('joint="slide" coef="-2"', 'joint="hinge" coef="-2"'), r"line \d+.*joint 'hinge' is repeated"),
        (('joint="slide" coef="-2"', 'joint="ball" coef="-2"'), r"line \d+.*must be a hinge or slide, got 'ball'"),
        (('joint="slide" coef="-2"', 'joint="slide"'), r"line \d+.*expected attribute 'coef'"),
        (('springlength="0.2 0.4"', 'springlength="0.4 0.2"'), r"line \d+.*attribute 'springlength'"),
        (('range="0 1"', 'range="1 0" limited="true"'), r"line \d+.*a limited tendon needs lower < upper"),
        (('tendon="pull"', 'tendon="push"'), r"line \d+.*attribute 'tendon': no tendon named 'push'"),
    ],
)
def test_a_tendon_mujoco_refuses_is_refused_by_name_and_line(change, message):
    broken = TENDON_ARM.replace(*change)
    assert broken != TENDON_ARM
    with pytest.raises(ValueError, match=message):
        robodyn.load_mjcf_string(broken)
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_string(broken)


def test_what_tendons_robodyn_does_not_model_are_named():
    """A tendon's springyield makes its spring plastic, a warning says in the scene's dynamics
    only; an invalid range under limited="auto" leaves the tendon
    unlimited, as in MuJoCo; the actuator on the fixed tendon pulls with gear times its
    coefficients, the one on the spatial tendon wrapping a cylinder with gear times its J."""
    text = TENDON_ARM.replace('range="0 1"', 'range="1 0" springyield="0.1"').replace(
        "</fixed></tendon>", '</fixed><spatial name="string"><site site="s1"/><site site="s2"/></spatial>'
        '<spatial name="wrapped"><site site="s1"/><geom geom="pin"/><site site="s2"/></spatial></tendon>'
    ).replace('<geom size="0.1"/></body></body></body>', '<geom size="0.1"/><site name="s2"/></body></body><site name="s1"/>'
              '<geom name="pin" type="cylinder" size="0.02 0.1" pos="0.2 0 -0.3"/></body>')
    text = text.replace("</actuator>", '<motor name="reel" tendon="wrapped"/></actuator>')
    mj_model = mujoco.MjModel.from_xml_string(text)
    model = robodyn.load_mjcf_string(text)
    messages = " ".join(model.warnings)
    assert "tendon 'pull' yield (springyield) in the scene's own dynamics" in messages
    assert "wrapped" not in messages and model.tendon_spring_yield == [0.1, 0.0, 0.0]
    assert model.tendon_names == ["pull", "string", "wrapped"]
    q = model.neutral()
    q[model.joint_idx_q[model.joint_names.index("hinge")]] = 0.3
    assert_close(model.tendon_lengths(q)[:1], [0.3], 0.0, "L = q_hinge")
    tau = model.actuator_forces(q, np.zeros(model.nv), [1.0, 0.0])
    expected = np.zeros(model.nv)
    expected[model.joint_idx_v[model.joint_names.index("hinge")]] = 3.0
    expected[model.joint_idx_v[model.joint_names.index("slide")]] = -6.0
    assert_close(tau, expected, 0.0, "gear × coefficients")
    layout = MujocoLayout(model, mj_model)
    d = mujoco.MjData(mj_model)
    d.qpos[:], d.ctrl[:] = layout.q_to_mujoco(q), [1.0, 1.0]
    mujoco.mj_forward(mj_model, d)
    tau = model.actuator_forces(q, np.zeros(model.nv), [1.0, 1.0])
    assert_close(tau, layout.force_from_mujoco(q, d.qfrc_actuator), 1e-12, "and gear × J on the wrapped tendon")


@pytest.mark.parametrize(
    ("original", "change", "neutral", "warning"),
    [
        ('<geom name="ankle" size="0.03"/>', '<geom name="ankle" size="0.03" adhesion="2"/>', 'adhesion="0"',
         r"<geom name='ankle'> \(line \d+\): attribute 'adhesion' not modelled \(robodyn models no adhesion\)"),
        ('<geom name="ankle" size="0.03"/>', '<geom name="ankle" size="0.03" surfacevel="0 0 1"/>', 'surfacevel="0 0 0"',
         r"<geom name='ankle'> \(line \d+\): attribute 'surfacevel' not modelled"),
    ],
)
def test_what_mujoco_reads_and_robodyn_does_not_model_is_named(original, change, neutral, warning):
    """Each attribute that changes MuJoCo's result and that robodyn does not model warns, naming
    the element and its line; at its neutral value it does not."""
    assert SCENE.count(original) == 1
    text = SCENE.replace(original, change)
    mujoco.MjModel.from_xml_string(text)
    messages = "\n".join(load(text=text).warnings)
    assert re.search(warning, messages), messages
    attribute = neutral.split("=")[0]
    calm = re.sub(rf'{attribute}="[^"]*"', neutral, text)
    assert not [w for w in load(text=calm).warnings if f"'{attribute}'" in w]


def test_a_mocap_body_and_an_aligned_free_body_are_named():
    """A mocap body is held where the file places it; MuJoCo's alignment of a childless free body
    with its inertial frame (freejoint align, compiler alignfree) changes what its qpos means."""
    extra = ('<body name="target" pos="1 0 1" mocap="true"><geom size="0.05" contype="0" conaffinity="0"/></body>'
             '<body name="puck" pos="0 1 1"><freejoint name="puck"{align}/><geom size="0.1" pos="0.02 0 0"/></body>'
             "</worldbody>")
    for align, compiler, aligned in [("", "", False), (' align="true"', "", True), ("", ' alignfree="true"', True),
                                     (' align="false"', ' alignfree="true"', False)]:
        text = SCENE.replace("</worldbody>", extra.replace("{align}", align)).replace(
            'angle="degree"', f'angle="degree"{compiler}')
        mujoco.MjModel.from_xml_string(text)
        messages = "\n".join(load(text=text).warnings)
        assert re.search(r"<body name='target'> \(line \d+\): attribute 'mocap' not modelled", messages)
        assert ("<freejoint name='puck'>" in messages and "free-joint alignment not followed" in messages) == aligned
        # the base has children: MuJoCo aligns only childless free bodies
        assert "<freejoint name='root'>" not in messages


def test_flags_and_plugins_robodyn_does_not_follow_are_named():
    flags = SCENE.replace('<flag warmstart="disable" energy="enable"/>',
                          '<flag multiccd="disable" diagexact="enable" sleep="enable"/>')
    messages = "\n".join(load(text=flags).warnings)
    assert all(f"'{flag}'" in messages for flag in ["multiccd", "diagexact", "sleep"]), messages
    assert "'warmstart'" not in "\n".join(load(text=SCENE).warnings)
    plugin = SCENE.replace('<body name="toe" pos="0.05 0 -0.25">',
                           '<body name="toe" pos="0.05 0 -0.25"><plugin plugin="mujoco.elasticity.cable"/>')
    assert re.search(r"<plugin> \(line \d+\): not read \(robodyn runs no MuJoCo plugins", "\n".join(load(text=plugin).warnings))


def test_an_actuator_delay_is_named():
    text = SCENE.replace("</contact>", '</contact><actuator><motor name="m" joint="hip" delay="0.01" nsample="5"/></actuator>')
    assert mujoco.MjModel.from_xml_string(text).nu == 1
    messages = "\n".join(load(text=text).warnings)
    assert re.search(r"<motor name='m'> \(line \d+\): attribute 'delay' not modelled \(the control acts at once\)", messages)


def test_a_deformable_section_is_named():
    text = SCENE.replace("</contact>", "</contact><deformable/>")
    assert [w for w in load(text=text).warnings if "<deformable>" in w and "not read" in w]


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (('angle="degree"', 'angle="degree" autolimits="false"'),
         r"<joint name='hip'> \(line \d+\): attribute 'range' without 'limited': with <compiler autolimits=\"false\">"),
        (('angle="degree"', 'angle="degree" coordinate="global"'),
         r"<compiler> \(line \d+\): attribute 'coordinate': global coordinates are refused"),
        (('<body name="toe" pos="0.05 0 -0.25">', '<body name="toe" pos="0.05 0 -0.25" mocap="true">'),
         r"<body name='toe'> \(line \d+\): a mocap body must be a child of the worldbody without joints"),
        (('<body name="base" pos="0 0 0.5">', '<body name="base" pos="0 0 0.5" mocap="true">'),
         r"<body name='base'> \(line \d+\): a mocap body must be a child of the worldbody without joints"),
        (("</contact>", '</contact><actuator><motor name="m" joint="hip" delay="0.01"/></actuator>'),
         r"<motor name='m'> \(line \d+\): attribute 'delay': 0.01 s needs a history buffer \('nsample' > 0\)"),
    ],
)
def test_settings_mujoco_refuses_are_refused(change, message):
    assert_refused_as_in_mujoco(SCENE.replace(*change), message)


def test_autolimits_false_takes_an_explicit_limited():
    """With autolimits="false" every range says whether it limits (joints, tendons, actuators)."""
    text = SCENE.replace('angle="degree"', 'angle="degree" autolimits="false"').replace(
        'range="-60 60"', 'range="-60 60" limited="true"').replace('range="-120 0"', 'range="-120 0" limited="false"')
    model = load(text=text)
    compiled = mujoco.MjModel.from_xml_string(text)
    assert compiled.jnt_limited.tolist() == [0, 1, 0]
    knee = model.joint_idx_q[model.joint_names.index("knee")]
    hip = model.joint_idx_q[model.joint_names.index("hip")]
    assert np.isinf(model.lower_position_limit[knee]) and model.lower_position_limit[hip] == pytest.approx(-np.pi / 3)
    actuated = text.replace("</contact>", '</contact><actuator><motor joint="hip" ctrlrange="-1 1"/></actuator>')
    assert_refused_as_in_mujoco(actuated, r"attribute 'ctrlrange' without 'ctrllimited'")
