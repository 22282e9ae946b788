"""Height fields (`<hfield>`): read as MuJoCo's compiler reads them, and collided, prism by
prism, as MuJoCo's `mj_collision` collides them.

The field is a random bumpy grid on a tilted world body; each partner geom (sphere, capsule,
ellipsoid, cylinder, box, a cuboid mesh) is placed at random over it, from well inside the
surface to above it by its bounding radius, with margins and without. Both engines are given the
very same placements (`collide_placed`), so that their arithmetic can be compared.

What differs, and why (measured here, MuJoCo 4.0.0): against the cuboid mesh without margins, in
3 placements of 200 one contact of the pair is another: both engines stop EPA at a support
point met before (a polytope's "discrete" search), and where a prism's face is turned so that
two of the mesh's corners tie, MuJoCo's mesh support (a walk over the mesh's graph) may return
the other one, and its search stops elsewhere.
"""

import struct
import zlib

import mujoco
import numpy as np
import pytest
import robodyn
import test_collision as pairs
import test_mesh_collision as meshes
from conftest import load_quietly
from robodyn.convert import MujocoLayout
from test_contact_dynamics import assert_matches_mujoco, converged, load_both
from test_menagerie import MENAGERIE, mujoco_model
from test_scene_stepping import (
    ELLIPTIC_STEP_AGREEMENT,
    INTEGRATORS,
    STEP_AGREEMENT,
    assert_steps_like_mujoco,
)

#: The same prisms, the same GJK and EPA: the geom's pose in the field's frame is computed in
#: another order of operations (R_fᵀ R_g by nalgebra, by rows in MuJoCo), a few ulp, which GJK's
#: and EPA's iterations amplify (measured: at most 1.5e-12 over the cases below).
HEIGHT_FIELD_AGREEMENT = 1e-11
#: Placements of the cuboid mesh where one contact is another (see the module's header;
#: measured: 3 of 200 without margins, none with).
MESH_TIES = 3
CASES = 200
SIZE = (0.6, 0.5, 0.15, 0.05)
ROWS, COLUMNS = 7, 9
TILT = "0.98 0.12 -0.1 0.08"
PARTNERS = ["sphere", "capsule", "ellipsoid", "cylinder", "box", "mesh"]


def elevations(rng):
    return rng.uniform(0.0, 1.0, size=(ROWS, COLUMNS))


def scene(partner, margin, heights):
    """The field on a tilted world body, `partner` on a free body; both geoms with margin/2."""
    written = " ".join(f"{h:.6f}" for h in heights.ravel())
    field = (
        f'<hfield name="terrain" nrow="{ROWS}" ncol="{COLUMNS}" size="{" ".join(map(str, SIZE))}" '
        f'elevation="{written}"/>'
    )
    if partner == "mesh":
        geom = f'<geom name="b" type="mesh" mesh="cuboid" margin="{margin / 2}"/>'
    else:
        geom = f'<geom name="b" type="{partner}" size="{pairs.SIZES[partner]}" margin="{margin / 2}"/>'
    return (
        f'<mujoco><asset>{field}<mesh name="cuboid" vertex="{meshes.VERTICES}"/></asset><worldbody>'
        f'<body name="ground" pos="0.1 -0.2 0.3" quat="{TILT}">'
        f'<geom name="a" type="hfield" hfield="terrain" margin="{margin / 2}"/></body>'
        f'<body name="other"><freejoint name="other"/>{geom}</body></worldbody></mujoco>'
    )


def random_placement(mj_model, mj_data, rng, partner):
    """The partner over the field, at a random height about its surface, turned at random."""
    mujoco.mj_kinematics(mj_model, mj_data)
    rotation, origin = mj_data.geom_xmat[0].reshape(3, 3), mj_data.geom_xpos[0]
    local = rng.uniform(-1.1, 1.1, size=2) * SIZE[:2]
    radius = meshes.BOUNDING_RADIUS[partner]
    height = rng.uniform(0.0, SIZE[2]) + rng.uniform(-0.6, 1.05) * radius
    qpos = np.zeros(mj_model.nq)
    qpos[0:3] = origin + rotation @ np.array([local[0], local[1], height])
    qpos[3:7] = pairs.random_quaternion(rng)
    return qpos


@pytest.mark.parametrize("margin", [0.0, pairs.MARGIN], ids=["touching", "margin"])
@pytest.mark.parametrize("partner", PARTNERS)
def test_height_field_pairs_collide_as_in_mujoco(partner, margin):
    """Each convex type over a random field: MuJoCo's contacts, in MuJoCo's order."""
    rng = np.random.default_rng(7)
    text = scene(partner, margin, elevations(rng))
    model, mj_model = load_quietly(text=text), mujoco.MjModel.from_xml_string(text)
    mj_data = mujoco.MjData(mj_model)
    touching, several, ties = 0, 0, []
    for case in range(CASES):
        qpos = random_placement(mj_model, mj_data, rng, partner)
        expected = pairs.mujoco_contacts(mj_model, mj_data, qpos)
        found = model.collide_placed(*pairs.placed_as_in_mujoco(model, mj_model, mj_data))
        assert len(found) == len(expected), (case, len(found), len(expected))
        assert all((ours["geom1"], ours["geom2"]) == theirs[:2] for ours, theirs in zip(found, expected))
        apart = [meshes.offset(ours, theirs) for ours, theirs in zip(found, expected)]
        if any(error > HEIGHT_FIELD_AGREEMENT for error in apart):
            # a mesh's tied corners: that one contact only, the others MuJoCo's
            assert partner == "mesh" and sum(error > HEIGHT_FIELD_AGREEMENT for error in apart) == 1, (case, apart)
            ties.append(case)
        touching += bool(expected)
        several += len(expected) > 1
    assert len(ties) <= (MESH_TIES if partner == "mesh" else 0), ties
    # the cases are not vacuous: most touch, many on several prisms
    assert touching > CASES // 3 and several > CASES // 10, (touching, several)


def test_many_prisms_give_at_most_fifty_contacts():
    """A wide box sunk into a fine field: MuJoCo's first fifty contacts, as MuJoCo stops there."""
    heights = 0.5 + 0.5 * np.sin(np.linspace(0, 9, 30))[:, None] * np.cos(np.linspace(0, 7, 30))[None, :]
    text = f"""<mujoco><asset><hfield name="bumps" nrow="30" ncol="30" size="1 1 0.1 0.1"
      elevation="{' '.join(f'{h:.5f}' for h in heights.ravel())}"/></asset><worldbody>
      <geom name="a" type="hfield" hfield="bumps"/>
      <body name="slab" pos="0.02 -0.03 0.08"><freejoint/><geom name="b" type="box" size="0.8 0.7 0.05"/></body>
    </worldbody></mujoco>"""
    model, mj_model = load_quietly(text=text), mujoco.MjModel.from_xml_string(text)
    mj_data = mujoco.MjData(mj_model)
    expected = pairs.mujoco_contacts(mj_model, mj_data, mj_model.qpos0)
    found = model.collide(model.neutral())
    assert len(expected) == len(found) == 50
    for ours, theirs in zip(found, expected):
        assert meshes.offset(ours, theirs) <= HEIGHT_FIELD_AGREEMENT


# --- reading the elevations --------------------------------------------------------------------


def png(pixels, color_type, bit_depth):
    """A PNG file's bytes: `pixels` (rows, columns, channels) unfiltered, one IDAT chunk."""
    rows, columns = pixels.shape[:2]
    sample = ">u2" if bit_depth == 16 else "u1"
    raw = b"".join(b"\x00" + row.astype(sample).tobytes() for row in pixels.reshape(rows, -1))

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))

    header = struct.pack(">IIBBBBB", columns, rows, bit_depth, color_type, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


def surface_heights(model, count):
    """The drawn field's surface heights, row by row (row 0 along −y): its first `count`
    vertices."""
    (visual,) = [v for v in model.visuals if v["kind"] == "hfield"]
    return np.asarray(visual["mesh_vertices"])[:count, 2]


def field_scene(asset):
    return f"""<mujoco><asset>{asset}</asset><worldbody>
      <geom name="terrain" type="hfield" hfield="terrain"/></worldbody></mujoco>"""


def test_a_file_gives_the_samples_and_nrow_ncol_elevation_are_warned_unread(tmp_path):
    """As in MuJoCo, a file's samples win over `nrow`, `ncol` and `elevation`; a warning says so."""
    (tmp_path / "t.png").write_bytes(png(np.array([[[0], [255], [9]], [[3], [4], [5]]]), 0, 8))
    asset = '<hfield name="terrain" file="t.png" nrow="5" ncol="7" elevation="1 2" size="1 1 1 1"/>'
    (tmp_path / "scene.xml").write_text(field_scene(asset))
    with pytest.warns(robodyn.ModelWarning, match="its nrow, ncol and elevation are left unread"):
        model = robodyn.load(tmp_path / "scene.xml")
    mj_model = mujoco.MjModel.from_xml_path(str(tmp_path / "scene.xml"))
    np.testing.assert_array_equal(surface_heights(model, 6), mj_model.hfield_data.astype(float))


@pytest.mark.parametrize(
    "kind",
    ["inline", "grey8", "grey16", "rgb", "palette", "binary", "binary_named"],
)
def test_elevations_are_read_as_mujoco_reads_them(tmp_path, kind):
    """Inline numbers (rows written from +y down), PNG images (grey, 16-bit, colour: the red
    channel; a palette) and MuJoCo's binary format give MuJoCo's elevations, scaled to [0, 1]."""
    rng = np.random.default_rng(3)
    rows, columns = 5, 6
    size = 'size="2 1.5 0.4 0.1"'
    if kind == "inline":
        heights = rng.uniform(-1, 3, size=(rows, columns))
        asset = f'<hfield name="terrain" nrow="{rows}" ncol="{columns}" {size} elevation="{" ".join(f"{h:.7g}" for h in heights.ravel())}"/>'
    elif kind == "binary" or kind == "binary_named":
        heights = rng.uniform(-1, 3, size=(rows, columns)).astype("<f4")
        name = "terrain.bin" if kind == "binary" else "terrain.data"
        (tmp_path / name).write_bytes(struct.pack("<ii", rows, columns) + heights.tobytes())
        content = ' content_type="image/vnd.mujoco.hfield"' if kind == "binary_named" else ""
        asset = f'<hfield name="terrain" file="{name}" {size}{content}/>'
    else:
        if kind == "grey8":
            pixels, color_type, depth = rng.integers(0, 256, size=(rows, columns, 1)), 0, 8
        elif kind == "grey16":
            pixels, color_type, depth = rng.integers(0, 65536, size=(rows, columns, 1)), 0, 16
        elif kind == "rgb":
            pixels, color_type, depth = rng.integers(0, 256, size=(rows, columns, 3)), 2, 8
        else:
            pixels, color_type, depth = None, 3, 8
        if kind == "palette":
            palette = rng.integers(0, 256, size=(4, 3)).astype("u1")
            indices = rng.integers(0, 4, size=(rows, columns, 1))
            data = png(indices, 3, 8)
            plte = struct.pack(">I", 12) + b"PLTE" + palette.tobytes() + struct.pack(">I", zlib.crc32(b"PLTE" + palette.tobytes()))
            data = data[:33] + plte + data[33:]
        else:
            data = png(pixels, color_type, depth)
        (tmp_path / "terrain.png").write_bytes(data)
        asset = f'<hfield name="terrain" file="terrain.png" {size}/>'
    (tmp_path / "scene.xml").write_text(field_scene(asset))
    mj_model = mujoco.MjModel.from_xml_path(str(tmp_path / "scene.xml"))
    model = load_quietly(tmp_path / "scene.xml")
    assert (int(mj_model.hfield_nrow[0]), int(mj_model.hfield_ncol[0])) == (rows, columns)
    expected = mj_model.hfield_data.astype(float) * mj_model.hfield_size[0, 2]
    np.testing.assert_array_equal(surface_heights(model, rows * columns), expected)
    (geom,) = model.geoms
    assert geom["kind"] == "hfield" and geom["size"] == [2.0, 1.5, 0.4, 0.1]


@pytest.mark.parametrize(
    ("asset", "said"),
    [
        ('<hfield name="other" nrow="2" ncol="2" size="1 1 1 1"/>', "no <hfield> named 'terrain' among the assets (known: other)"),
        ('<hfield name="terrain" nrow="2" ncol="2" size="1 1 0 1"/>', "attribute 'size': expected four positive numbers"),
        ('<hfield name="terrain" nrow="2" ncol="3" size="1 1 1 1" elevation="1 2 3"/>', "expected nrow x ncol = 6 numbers, got 3"),
        ('<hfield name="terrain" size="1 1 1 1"/>', "a height field needs a file, or nrow and ncol"),
        ('<hfield name="terrain" file="t.png" content_type="image/jpeg" size="1 1 1 1"/>', "expected 'image/png' or 'image/vnd.mujoco.hfield', got 'image/jpeg'"),
        ('<hfield name="terrain" file="missing.png" size="1 1 1 1"/>', "height field file 'missing.png' not found"),
        ('<hfield name="terrain" file="broken.png" size="1 1 1 1"/>', "not a PNG image"),
        ('<hfield name="terrain" file="short.bin" size="1 1 1 1"/>', "expected 24 bytes for 2 x 2 elevations, got 20"),
    ],
)
def test_bad_height_fields_are_refused_naming_the_element(tmp_path, asset, said):
    """A field that MuJoCo refuses is refused, the message naming the file and element."""
    (tmp_path / "t.png").write_bytes(png(np.zeros((2, 2, 1), int), 0, 8))
    (tmp_path / "broken.png").write_bytes(b"not an image")
    (tmp_path / "short.bin").write_bytes(struct.pack("<ii", 2, 2) + b"\0" * 12)
    (tmp_path / "scene.xml").write_text(field_scene(asset))
    with pytest.raises(ValueError, match="scene.xml") as raised:
        load_quietly(tmp_path / "scene.xml")
    assert said in str(raised.value)
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_path(str(tmp_path / "scene.xml"))


# --- forces and steps on a field ---------------------------------------------------------------

#: A contact of a field through robodyn's kinematics: its placements round otherwise than MuJoCo's
#: (a geom's position by up to 1e-10 m where MuJoCo's compiler moved its body's frame), and GJK's
#: iterations carry that into the contact points; Jacobian rows, R and aref (measured: 1.4e-12).
FIELD_ROW_AGREEMENT = 1e-11

TERRAIN = """<mujoco><option cone="{cone}" integrator="{integrator}"/>
  <asset><hfield name="terrain" nrow="9" ncol="11" size="0.8 0.7 0.12 0.05" elevation="{elevation}"/></asset>
  <worldbody><geom name="terrain" type="hfield" hfield="terrain" euler="3 -2 10"/>{polytopes}
    <body name="ball" pos="0.25 0.2 0.25"><freejoint name="ball"/><geom name="ball" type="sphere" size="0.06"/></body>
    <body name="bar" pos="-0.25 0.3 0.25" euler="85 0 30"><freejoint name="bar"/><geom name="bar" type="capsule" size="0.03 0.1"/></body>
  </worldbody></mujoco>"""
#: Bodies whose contacts on prisms EPA finds (see test_bodies_on_a_height_field_step_as_in_mujoco).
CRATE_AND_CAN = """
    <body name="crate" pos="-0.3 -0.2 0.25" euler="10 20 5"><freejoint name="crate"/><geom name="crate" type="box" size="0.08 0.06 0.05"/></body>
    <body name="can" pos="0.2 -0.3 0.25" euler="80 10 0"><freejoint name="can"/><geom name="can" type="cylinder" size="0.05 0.07"/></body>"""


def terrain(cone, integrator="Euler", polytopes=True):
    """A ball, a bar (and a crate and a can) on a bumpy field (random elevations), and where
    MuJoCo lets them settle: 300 steps from above it."""
    heights = " ".join(f"{h:.4f}" for h in np.random.default_rng(11).uniform(0.0, 1.0, size=(9, 11)).ravel())
    text = TERRAIN.format(cone=cone, integrator=integrator, elevation=heights, polytopes=CRATE_AND_CAN if polytopes else "")
    model, mj_model, layout = load_both(text)
    data = mujoco.MjData(mj_model)
    for _ in range(300):
        mujoco.mj_step(mj_model, data)
    return model, mj_model, layout, data.qpos.copy(), data.qvel.copy()


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_bodies_on_a_height_field_as_in_mujoco(cone):
    """A crate, a can, a ball and a bar come to rest on the field: MuJoCo's contacts, constraint
    rows and forces (`mj_forward`, solved to convergence), still and pushed."""
    model, mj_model, layout, qpos, qvel = terrain(cone)
    _, expected = assert_matches_mujoco(model, mj_model, layout, qpos, qvel, label="settled", row_agreement=FIELD_ROW_AGREEMENT)
    touching = {geom for contact in expected["contacts"] for geom in contact[:2]}
    assert touching == {"terrain", "crate", "ball", "can", "bar"}, expected["contacts"]
    tau = np.random.default_rng(2).normal(size=model.nv) * 2
    assert_matches_mujoco(model, mj_model, layout, qpos, qvel + 0.3, tau=tau, label="pushed", row_agreement=FIELD_ROW_AGREEMENT)


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_bodies_on_a_height_field_step_as_in_mujoco(integrator, cone):
    """From where the ball and the bar settle, set moving: 100 steps of mj_step. The crate and the
    can are left out: their contacts on prisms come from EPA, which stops anywhere within
    `ccd_tolerance` (1e-6) of the depth, and for a box at a support point met before, a choice
    that turns on the last bit of its placement (measured: the crate's rotation moved by 1e-16
    takes a contact from 9e-6 m deep to 2.5e-5 m, in MuJoCo's arithmetic too; the can's contacts
    part from MuJoCo's by up to 1.4e-3 within 30 steps). Given MuJoCo's placements their contacts
    are MuJoCo's (test_height_field_pairs_collide_as_in_mujoco), but robodyn's kinematics round
    otherwise than MuJoCo's, and a run then parts at such a turn."""
    model, mj_model, layout, qpos, qvel = terrain(cone, integrator, polytopes=False)
    tolerance = ELLIPTIC_STEP_AGREEMENT if cone == "elliptic" else STEP_AGREEMENT
    assert_steps_like_mujoco(model, mj_model, layout, qpos, qvel + 0.2, tolerance=tolerance, label=integrator)


def test_a_field_on_a_moving_body_weighs_as_mujocos_box():
    """A field on a free body, with no <inertial>: MuJoCo's box of half-sides s₀, s₁, s₂/4 + s₃/2
    at its density gives the body's mass and inertia."""
    text = """<mujoco><asset><hfield name="terrain" nrow="2" ncol="3" size="0.3 0.2 0.1 0.05"/></asset>
      <worldbody><body name="raft"><freejoint/><geom type="hfield" hfield="terrain" density="500" euler="0 0 30"/></body>
      </worldbody></mujoco>"""
    model, mj_model = load_quietly(text=text), mujoco.MjModel.from_xml_string(text)
    half = np.array([0.3, 0.2, 0.1 / 4 + 0.05 / 2])
    assert mj_model.body_mass[1] == pytest.approx(500 * 8 * np.prod(half), rel=1e-12)
    assert model.body_masses[0] == pytest.approx(mj_model.body_mass[1], rel=1e-12)
    # the centre of mass at the origin: I is the inertia about it, MuJoCo's principal moments
    _, _, _, _, i_xx, i_xy, i_yy, i_xz, i_yz, i_zz = model.inertial_parameters[0]
    inertia = np.array([[i_xx, i_xy, i_xz], [i_xy, i_yy, i_yz], [i_xz, i_yz, i_zz]])
    assert np.sort(np.linalg.eigvalsh(inertia)) == pytest.approx(np.sort(mj_model.body_inertia[1]), rel=1e-9)


def test_the_viewer_draws_a_field_where_it_lies():
    """The field's piece: its surface, walls and bottom placed on its body; a closed surface."""
    from robodyn.viewer.geometry import visual_pieces

    text = """<mujoco><asset><hfield name="terrain" nrow="3" ncol="4" size="1 0.5 0.2 0.1"
      elevation="0 1 2 3 1 0 1 0 3 2 1 0"/></asset>
      <worldbody><geom name="terrain" type="hfield" hfield="terrain" pos="0.5 0 -0.2" rgba="0.2 0.6 0.3 1"/></worldbody></mujoco>"""
    (piece,) = visual_pieces(load_quietly(text=text))
    assert piece.backdrop and piece.rgba == (0.2, 0.6, 0.3, 1.0)
    lowest, highest = piece.vertices.min(axis=0), piece.vertices.max(axis=0)
    np.testing.assert_allclose(lowest, [-0.5, -0.5, -0.3], atol=1e-15)
    np.testing.assert_allclose(highest, [1.5, 0.5, 0.0], atol=1e-15)
    # every edge shared by two faces, in opposite directions
    edges = {(int(f[k]), int(f[(k + 1) % 3])) for f in piece.faces for k in range(3)}
    assert len(edges) == 3 * len(piece.faces) and all((b, a) in edges for a, b in edges)


# --- Menagerie's Barkour vB on its terrain -----------------------------------------------------

#: A scene of Menagerie on a PNG height field (testdata/menagerie/README.md).
BARKOUR = "google_barkour_vb/scene_hfield_mjx.xml"
PLACES = 30
#: Its contacts through robodyn's kinematics: a foot sunk wholly into a prism (lowered up to
#: 20 cm) is EPA's, whose normal carries the placements' rounding further (measured: 1.6e-11 over
#: 180 places, 8e-13 to 1.6e-11 per 30).
BARKOUR_AGREEMENT = 1e-10


def test_barkour_on_its_terrain_as_in_mujoco():
    """Menagerie's Barkour vB at `home`, moved over its PNG terrain (the field 20 m wide, 5 cm
    high) and lowered onto it: MuJoCo's contacts through robodyn's own kinematics (its feet are
    spheres), and at a few of the places MuJoCo's forces."""
    model = load_quietly(MENAGERIE / BARKOUR)
    mj_model = converged(mujoco_model(MENAGERIE / BARKOUR, BARKOUR))
    mj_data, layout = mujoco.MjData(mj_model), MujocoLayout(model, mj_model)
    rng = np.random.default_rng(5)
    touching = 0
    for place in range(PLACES):
        qpos = mj_model.key_qpos[0].copy()
        qpos[0:2] += rng.uniform(-8, 8, size=2)
        qpos[2] -= rng.uniform(0.0, 0.2)
        expected = pairs.mujoco_contacts(mj_model, mj_data, qpos)
        found = model.collide(layout.q_from_mujoco(qpos))
        assert [(c["geom1"], c["geom2"]) for c in found] == [theirs[:2] for theirs in expected], place
        for ours, theirs in zip(found, expected):
            assert meshes.offset(ours, theirs) <= BARKOUR_AGREEMENT, place
        touching += bool(expected)
        if place < 3 and expected:
            qvel = rng.normal(size=mj_model.nv) * 0.1
            assert_matches_mujoco(model, mj_model, layout, qpos, qvel, label=f"place {place}", row_agreement=FIELD_ROW_AGREEMENT)
    assert touching > PLACES // 2


def test_planes_and_fields_never_touch_as_in_mujoco():
    """A field on a body over a plane, and two fields: MuJoCo has no collision function for them,
    and neither has robodyn; no warning calls their contacts missing."""
    text = """<mujoco><asset><hfield name="t" nrow="2" ncol="2" size="1 1 1 1"/></asset><worldbody>
      <geom name="floor" type="plane" size="1 1 1"/>
      <body name="raft" pos="0 0 0.5"><freejoint/><geom name="raft" type="hfield" hfield="t" mass="1"/></body>
      <body name="other" pos="0 0 1"><freejoint/><geom name="other" type="hfield" hfield="t" mass="1"/></body>
    </worldbody></mujoco>"""
    model, mj_model = load_quietly(text=text), mujoco.MjModel.from_xml_string(text)
    assert len(model.contact_candidates) == 3
    assert pairs.mujoco_contacts(mj_model, mujoco.MjData(mj_model), mj_model.qpos0) == []
    assert model.collide(model.neutral()) == []
    assert not any("not found yet" in message for message in model.warnings), model.warnings
