"""Collision detection, one pair type at a time, against MuJoCo's `mj_collision`: the same
contacts (count and order), at the same points, with the same frames and distances.

Each case places two geoms at random: the second at a random direction from the first, its
centre at 0.2–1.05 times the sum of their bounding radii (deep overlaps, shallow ones, contacts
within the margin only, and misses), both turned at random; a plane is tilted and the other geom
set at a random height about it."""

import mujoco
import numpy as np
import pytest
from conftest import REPOSITORY, load_quietly

from robodyn.convert import MujocoLayout

# Closed-form colliders: the same formulas in another order of floating-point operations.
CLOSED_FORM_AGREEMENT = 1e-9
# The convex colliders (GJK, EPA, multi-contact) given the very placements MuJoCo computed: the
# same arithmetic, but for the contact frame's normal, made unit in another order (2 ulp).
CONVEX_AGREEMENT = 1e-15
CASES = 300
MARGIN = 0.01

SIZES = {
    "plane": "0 0 1",
    "sphere": "0.1",
    "capsule": "0.07 0.15",
    "ellipsoid": "0.12 0.08 0.05",
    "cylinder": "0.08 0.12",
    "box": "0.1 0.07 0.05",
}
BOUNDING_RADIUS = {
    "sphere": 0.1,
    "capsule": 0.22,
    "ellipsoid": 0.12,
    "cylinder": np.hypot(0.08, 0.12),
    "box": np.linalg.norm([0.1, 0.07, 0.05]),
}
CLOSED_FORM_PAIRS = [
    ("plane", "sphere"),
    ("plane", "capsule"),
    ("plane", "cylinder"),
    ("plane", "box"),
    ("sphere", "sphere"),
    ("sphere", "capsule"),
    ("sphere", "cylinder"),
    ("sphere", "box"),
    ("capsule", "capsule"),
    ("capsule", "box"),
    ("box", "box"),
]

#: The pairs MuJoCo collides by support functions (GJK, EPA and its multi-contact).
CONVEX_PAIRS = [
    ("plane", "ellipsoid"),
    ("sphere", "ellipsoid"),
    ("capsule", "ellipsoid"),
    ("ellipsoid", "ellipsoid"),
    ("capsule", "cylinder"),
    ("ellipsoid", "cylinder"),
    ("ellipsoid", "box"),
    ("cylinder", "cylinder"),
    ("cylinder", "box"),
]


def scene(first, second, margin=MARGIN):
    """Two geoms: a plane on the world (tilted) or `first` on a free body, `second` on one."""
    geom = lambda name, kind: f'<geom name="{name}" type="{kind}" size="{SIZES[kind]}" margin="{margin / 2}"/>'
    if first == "plane":
        one = f'<body name="ground" quat="0.97 0.2 -0.1 0.05">{geom("a", "plane")}</body>'
    else:
        one = f'<body name="one"><freejoint name="one"/>{geom("a", first)}</body>'
    other = f'<body name="other"><freejoint name="other"/>{geom("b", second)}</body>'
    return f"<mujoco><worldbody>{one}{other}</worldbody></mujoco>"


def random_quaternion(rng):
    quaternion = rng.normal(size=4)
    return quaternion / np.linalg.norm(quaternion)


def random_qpos(first, second, mj_model, mj_data, rng, bounding_radius=BOUNDING_RADIUS):
    """A random placement of the two geoms near contact (see the module's header), their
    bounding radii by kind in `bounding_radius`."""
    qpos = np.zeros(mj_model.nq)
    if first == "plane":
        mujoco.mj_kinematics(mj_model, mj_data)
        normal = mj_data.geom_xmat[0].reshape(3, 3)[:, 2]
        along = rng.uniform(-1, 1, size=3) * 0.3
        height = rng.uniform(-1.0, 1.1) * bounding_radius[second]
        qpos[0:3] = along - normal * along.dot(normal) + normal * height
        qpos[3:7] = random_quaternion(rng)
        return qpos
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    reach = bounding_radius[first] + bounding_radius[second]
    qpos[0:3] = rng.normal(size=3) * 0.05
    qpos[3:7] = random_quaternion(rng)
    qpos[7:10] = qpos[0:3] + direction * reach * rng.uniform(0.2, 1.05)
    qpos[10:14] = random_quaternion(rng)
    return qpos


def mujoco_contacts(mj_model, mj_data, qpos):
    mj_data.qpos[:] = qpos
    mujoco.mj_kinematics(mj_model, mj_data)
    mujoco.mj_collision(mj_model, mj_data)
    names = lambda g: mj_model.geom(int(g)).name
    return [
        (names(c.geom[0]), names(c.geom[1]), c.dist, c.pos.copy(), c.frame.reshape(3, 3).copy())
        for c in mj_data.contact[: mj_data.ncon]
    ]


def placed_as_in_mujoco(model, mj_model, mj_data):
    """`model.collide_placed`'s arguments: the geoms where MuJoCo placed them (by name)."""
    ids = [mj_model.geom(geom["name"]).id for geom in model.geoms]
    return mj_data.geom_xpos[ids], mj_data.geom_xmat[ids]


def disagreements(first, second, tolerance, cases=CASES, seed=0, placements=None, same_placements=False):
    """The cases where robodyn's contacts differ from MuJoCo's, and how many touched: random
    cases, or the given `placements` (qpos); the geoms placed by robodyn's kinematics, or
    (`same_placements`) exactly where MuJoCo placed them."""
    text = scene(first, second)
    model, mj_model = load_quietly(text=text), mujoco.MjModel.from_xml_string(text)
    mj_data, layout = mujoco.MjData(mj_model), MujocoLayout(model, mj_model)
    rng = np.random.default_rng(seed)
    failures, touching = [], 0
    for case in range(cases if placements is None else len(placements)):
        qpos = random_qpos(first, second, mj_model, mj_data, rng) if placements is None else np.asarray(placements[case], float)
        expected = mujoco_contacts(mj_model, mj_data, qpos)
        if same_placements:
            found = model.collide_placed(*placed_as_in_mujoco(model, mj_model, mj_data))
        else:
            found = model.collide(layout.q_from_mujoco(qpos))
        touching += bool(expected)
        if len(found) != len(expected):
            failures.append((case, f"{len(found)} contacts, MuJoCo {len(expected)}"))
            continue
        for k, (ours, (g1, g2, dist, pos, frame)) in enumerate(zip(found, expected)):
            error = max(
                abs(ours["distance"] - dist),
                np.abs(ours["position"] - pos).max(),
                np.abs(ours["frame"] - frame).max(),
            )
            if (ours["geom1"], ours["geom2"]) != (g1, g2) or not error <= tolerance:
                failures.append((case, f"contact {k}: {ours['geom1']}, {ours['geom2']} off by {error:.3g}"))
    return failures, touching


@pytest.mark.parametrize("first,second", CLOSED_FORM_PAIRS, ids=lambda kind: kind)
def test_closed_form_pairs_collide_as_in_mujoco(first, second):
    failures, touching = disagreements(first, second, CLOSED_FORM_AGREEMENT)
    assert touching > CASES // 4, "too few cases touch to check anything"
    assert not failures, f"{len(failures)} of {CASES} cases differ: {failures[:5]}"


@pytest.mark.parametrize("first,second", CONVEX_PAIRS, ids=lambda kind: kind)
def test_convex_pairs_collide_as_in_mujoco(first, second):
    """Given MuJoCo's own placements (`collide_placed`): robodyn's kinematics rounds differently
    from MuJoCo's (1e-16), and these colliders amplify rounding as MuJoCo's do (EPA stops within
    `ccd_tolerance` 1e-6 of the depth; the multi-contact picks faces by angle thresholds), so only
    the same inputs can show they compute what MuJoCo computes."""
    failures, touching = disagreements(first, second, CONVEX_AGREEMENT, same_placements=True)
    assert touching > CASES // 4, "too few cases touch to check anything"
    assert not failures, f"{len(failures)} of {CASES} cases differ: {failures[:5]}"


UPRIGHT = [1, 0, 0, 0]
SIDEWAYS = [np.cos(np.pi / 4), np.sin(np.pi / 4), 0, 0]  # z turned onto -y
TILTED = [np.cos(5e-6), 0, np.sin(5e-6), 0]  # 1e-5 rad about y: parallel for MuJoCo 4.0
FLIPPED = [0, np.cos(5e-6), 0, np.sin(5e-6)]  # z turned onto -z, 1e-5 rad off
#: Placements where the colliders switch branches: parallel axes, concentric centres, a disk
#: or face flat on a plane, a centre inside, edges and corners.
SPECIAL_CASES = {
    ("capsule", "capsule"): [
        [0, 0, 0, *UPRIGHT, 0.12, 0, 0.05, *UPRIGHT],
        [0, 0, 0, *UPRIGHT, 0.12, 0, 0.25, *UPRIGHT],
        [0, 0, 0, *UPRIGHT, 0.12, 0, 0, 0, 0, 0, 1],
        [0, 0, 0, *SIDEWAYS, 0, 0, 0.1, *SIDEWAYS],
        [0, 0, 0, *UPRIGHT, 0.05, 0.05, 0.1, *SIDEWAYS],
        [0, 0, 0, *UPRIGHT, 0.1, 0, 0.35, *UPRIGHT],
        [0, 0, 0, *UPRIGHT, 0, 0, 0.3, *UPRIGHT],
        [0, 0, 0, *UPRIGHT, 0.12, 0, 0.05, *TILTED],
        [0, 0, 0, *UPRIGHT, 0.12, 0, -0.05, *FLIPPED],
    ],
    ("sphere", "sphere"): [[0, 0, 0, *UPRIGHT, 0, 0, 0, *UPRIGHT], [0, 0, 0, *UPRIGHT, 0, 0, 0, *SIDEWAYS]],
    ("sphere", "cylinder"): [
        [0, 0, 0, *UPRIGHT, 0, 0, 0, *UPRIGHT],
        [0, 0, 0.02, *UPRIGHT, 0, 0, 0, *UPRIGHT],
        [0.07, 0, 0.1, *UPRIGHT, 0, 0, 0, *UPRIGHT],
        [0.15, 0, 0.17, *UPRIGHT, 0, 0, 0, *UPRIGHT],
    ],
    ("sphere", "capsule"): [[0, 0, 0.3, *UPRIGHT, 0, 0, 0, *UPRIGHT], [0, 0, 0, *UPRIGHT, 0, 0, 0, *UPRIGHT]],
    ("plane", "cylinder"): [[0, 0, 0.1, *UPRIGHT], [0, 0, 0.07, *SIDEWAYS], [0, 0, 0.12, *UPRIGHT]],
    ("plane", "box"): [[0, 0, 0.045, *UPRIGHT], [0, 0, 0.06, *SIDEWAYS]],
    ("plane", "capsule"): [[0, 0, 0.05, *SIDEWAYS], [0, 0, 0.2, *UPRIGHT]],
}


#: Where the convex colliders switch branches: faces flat on faces (four contacts), a capsule
#: flat on a cap (two), coaxial cylinders, a cylinder's side on a box's edge, centres together.
CONVEX_SPECIAL_CASES = {
    ("cylinder", "box"): [
        [0, 0, 0, *UPRIGHT, 0, 0, 0.165, *UPRIGHT],
        [0, 0, 0, *SIDEWAYS, 0, 0, 0.125, *UPRIGHT],
        [0, 0, 0, *UPRIGHT, 0.12, 0.02, 0.16, *TILTED],
    ],
    ("cylinder", "cylinder"): [
        [0, 0, 0, *UPRIGHT, 0, 0, 0.235, *UPRIGHT],
        [0, 0, 0, *UPRIGHT, 0.05, 0.03, 0.235, *FLIPPED],
        [0, 0, 0, *UPRIGHT, 0.155, 0, 0, *UPRIGHT],
    ],
    ("capsule", "cylinder"): [[0, 0, 0.185, *SIDEWAYS, 0, 0, 0, *UPRIGHT], [0, 0, 0, *UPRIGHT, 0, 0, 0, *UPRIGHT]],
    ("ellipsoid", "ellipsoid"): [[0, 0, 0, *UPRIGHT, 0, 0, 0, *UPRIGHT], [0, 0, 0, *UPRIGHT, 0.2, 0, 0, *UPRIGHT]],
}


@pytest.mark.parametrize("first,second", list(SPECIAL_CASES) + list(CONVEX_SPECIAL_CASES), ids=lambda kind: kind)
def test_special_placements_collide_as_in_mujoco(first, second):
    convex = (first, second) in CONVEX_SPECIAL_CASES
    placements = (CONVEX_SPECIAL_CASES if convex else SPECIAL_CASES)[(first, second)]
    if first == "plane":
        # the plane is tilted: set the geom on it by the plane's frame
        text = scene(first, second)
        mj_model = mujoco.MjModel.from_xml_string(text)
        mj_data = mujoco.MjData(mj_model)
        mujoco.mj_kinematics(mj_model, mj_data)
        plane_rotation, plane_quaternion = mj_data.geom_xmat[0].reshape(3, 3), mj_data.xquat[1]
        placed = []
        for qpos in placements:
            quaternion = np.zeros(4)
            mujoco.mju_mulQuat(quaternion, plane_quaternion, np.asarray(qpos[3:7], float))
            placed.append([*(plane_rotation @ np.asarray(qpos[0:3], float)), *quaternion])
        placements = placed
    tolerance = CONVEX_AGREEMENT if convex else CLOSED_FORM_AGREEMENT
    failures, touching = disagreements(first, second, tolerance, placements=placements, same_placements=convex)
    assert touching == len(placements)
    assert not failures, failures


def test_pairs_without_a_collider_are_named_at_load(tmp_path):
    """A mesh whose file is missing: nothing touches it, and the warnings say so; the other
    pairs are found."""
    text = """<mujoco><asset><mesh name="lost" file="no_such_file.stl"/></asset>
    <worldbody><geom name="floor" type="plane" size="0 0 1"/>
      <body pos="0 0 0.05"><freejoint/><geom name="egg" type="ellipsoid" size="0.1 0.08 0.06"/></body>
      <body pos="0.5 0 0.05"><freejoint/><geom name="drum" type="cylinder" size="0.1 0.06"/></body>
      <body pos="0.5 0 0.1"><freejoint/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
        <geom name="lost" type="mesh" mesh="lost"/></body>
    </worldbody></mujoco>"""
    (tmp_path / "scene.xml").write_text(text)
    model = load_quietly(tmp_path / "scene.xml")
    assert any("the geom's mesh file is missing, so nothing touches it" in message for message in model.warnings)
    said = "the contacts of plane–mesh, ellipsoid–mesh, cylinder–mesh pairs are not found yet"
    assert any(said in message for message in model.warnings), model.warnings
    found = [(c["geom1"], c["geom2"]) for c in model.collide(model.neutral())]
    assert found == [("floor", "egg")] + [("floor", "drum")] * 3


def test_placements_must_be_rotations():
    """`collide_placed` refuses a matrix that is not a rotation, naming the geom."""
    model = load_quietly(text=scene("sphere", "box"))
    positions, rotations = np.zeros((2, 3)), np.tile(np.eye(3).ravel(), (2, 1))
    assert model.collide_placed(positions, rotations)
    rotations[1, 0] = 2.0
    with pytest.raises(ValueError, match="argument 'rotations': expected rotation matrices, row 1 .geom 'b'"):
        model.collide_placed(positions, rotations)
    with pytest.raises(ValueError, match="argument 'positions'"):
        model.collide_placed(np.zeros((3, 3)), rotations)


def test_contact_fields_and_order():
    """An explicit pair and dynamic pairs: names, pair, frame orthonormal with n × t₁ = t₂."""
    text = """<mujoco><worldbody>
      <geom name="floor" type="plane" size="0 0 1"/>
      <body name="ball" pos="0 0 0.09"><freejoint/><geom name="ball" size="0.1"/></body>
      <body name="crate" pos="0.5 0 0.04"><freejoint/><geom name="crate" type="box" size="0.05 0.05 0.05"/></body>
    </worldbody>
    <contact><pair name="ball_floor" geom1="ball" geom2="floor"/></contact></mujoco>"""
    model, mj_model = load_quietly(text=text), mujoco.MjModel.from_xml_string(text)
    mj_data = mujoco.MjData(mj_model)
    q = MujocoLayout(model, mj_model).q_from_mujoco(mj_model.qpos0)
    found = model.collide(q)
    expected = mujoco_contacts(mj_model, mj_data, mj_model.qpos0)
    assert [(c["geom1"], c["geom2"]) for c in found] == [(g1, g2) for g1, g2, *_ in expected]
    assert [c["pair"] for c in found] == ["ball_floor"] + [None] * 4
    ball = found[0]
    assert ball["distance"] == pytest.approx(-0.01, abs=1e-15)
    np.testing.assert_allclose(ball["position"], [0, 0, -0.005], atol=1e-15)
    for contact in found:
        frame = contact["frame"]
        np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-14)
        np.testing.assert_allclose(np.cross(frame[0], frame[1]), frame[2], atol=1e-14)
        np.testing.assert_array_equal(contact["normal"], frame[0])


# dm_control's suite: a holdout of MuJoCo scenes (testdata/dm_control/README.md)
SUITE = ["acrobot", "ball_in_cup", "cartpole", "cheetah", "finger", "fish", "hopper", "humanoid",
         "humanoid_CMU", "manipulator", "point_mass", "quadruped", "reacher", "stacker", "swimmer", "walker"]
SUITE_CASES = 40


@pytest.mark.parametrize("name", SUITE)
def test_dm_control_contacts_as_in_mujoco(name):
    """At random configurations about each model's `qpos0` (its joints turned by 0.3 rad or
    moved 0.3 m at random), the same contacts as MuJoCo's (the quadruped's on its height field
    too)."""
    path = REPOSITORY / "testdata" / "dm_control" / f"{name}.xml"
    model, mj_model = load_quietly(path), mujoco.MjModel.from_xml_path(str(path))
    mj_data, layout = mujoco.MjData(mj_model), MujocoLayout(model, mj_model)
    rng = np.random.default_rng(1)
    for case in range(SUITE_CASES):
        qpos = mj_model.qpos0.copy()
        mujoco.mj_integratePos(mj_model, qpos, rng.normal(size=mj_model.nv) * 0.3, 1.0)
        expected = mujoco_contacts(mj_model, mj_data, qpos)
        found = model.collide(layout.q_from_mujoco(qpos))
        assert [(c["geom1"], c["geom2"]) for c in found] == [(g1, g2) for g1, g2, *_ in expected], case
        for ours, (g1, g2, dist, pos, frame) in zip(found, expected):
            assert abs(ours["distance"] - dist) <= CLOSED_FORM_AGREEMENT, (case, g1, g2)
            assert np.abs(ours["position"] - pos).max() <= CLOSED_FORM_AGREEMENT, (case, g1, g2)
            assert np.abs(ours["frame"] - frame).max() <= CLOSED_FORM_AGREEMENT, (case, g1, g2)
