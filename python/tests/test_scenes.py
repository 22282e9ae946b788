"""MJCF scenes as MuJoCo shows them: the first view frames the robot, not the floor; textures are
drawn (builtin patterns pixel for pixel as MuJoCo's compiler makes them, PNG files by a mesh's
texture coordinates, checker floors by MuJoCo's plane coordinates, the skybox), and what cannot be
drawn is drawn in its material's colour with a warning; robodyn's page beside MuJoCo's own
offscreen render of the same scene from the same camera."""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import mujoco
import numpy as np
import pytest
from PIL import Image

import robodyn
from browser import HEIGHT, WIDTH, colour_fraction, project, screenshot
from robodyn.viewer import Viewer
from robodyn.viewer.geometry import visual_pieces
from robodyn.viewer.offscreen import mujoco_render
from robodyn.viewer.scene import CAMERA_FOV
from robodyn.viewer.textures import builtin_image, cube_faces, skybox_panorama

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "testdata" / "mjcf" / "textured" / "scene.xml"

BUILTIN_TEXTURES = """<mujoco><asset>
  <texture name="checker" type="2d" builtin="checker" rgb1=".2 .3 .4" rgb2=".1 .2 .3" mark="edge" markrgb=".8 .8 .8" width="30" height="20"/>
  <texture name="gradient" type="2d" builtin="gradient" rgb1=".9 .5 .1" rgb2="0 .2 .6" mark="cross" markrgb="1 1 1" width="31" height="17"/>
  <texture name="flat" type="2d" builtin="flat" rgb1=".6 .3 .3" width="8" height="6"/>
  <texture name="dots" type="2d" builtin="flat" rgb1="0 0 0" mark="random" random="0.1" markrgb="1 1 1" width="100" height="100"/>
  <texture name="cube" type="cube" builtin="checker" rgb1="1 1 1" rgb2=".1 .1 .1" mark="edge" markrgb="1 0 0" width="16"/>
  <texture name="cubeflat" type="cube" builtin="flat" rgb1=".2 .4 .6" rgb2=".6 .4 .2" width="8"/>
  <texture type="skybox" builtin="gradient" rgb1=".3 .5 .7" rgb2="0 0 0" width="32" height="192"/>
  {materials}
</asset><worldbody>{geoms}</worldbody></mujoco>"""
TEXTURE_NAMES = ["checker", "gradient", "flat", "dots", "cube", "cubeflat"]
#: The random dots fall where NumPy's generator puts them, not MuJoCo's: the fraction of dotted
#: pixels agrees within five binomial standard deviations of 10 000 pixels at p = 0.1 (0.015).
RANDOM_DOT_FRACTION_TOLERANCE = 0.015


def builtin_textures():
    """The test textures, each on a plane geom, with MuJoCo's compiled model of the same file."""
    text = BUILTIN_TEXTURES.format(materials="".join(f'<material name="{n}" texture="{n}"/>' for n in TEXTURE_NAMES),
                                   geoms="".join(f'<geom type="plane" size="1 1 1" material="{n}"/>' for n in TEXTURE_NAMES))
    return robodyn.load_mjcf_string(text), mujoco.MjModel.from_xml_string(text)


def mujoco_texture(mj, name: str) -> np.ndarray:
    """MuJoCo's compiled texture `name` as (height, width, 3) bytes (a cube's faces stacked)."""
    t = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_TEXTURE, name) if name else int(np.flatnonzero(mj.tex_type == mujoco.mjtTexture.mjTEXTURE_SKYBOX)[0])
    height, width, channels = int(mj.tex_height[t]), int(mj.tex_width[t]), int(mj.tex_nchannel[t])
    data = mj.tex_data[mj.tex_adr[t]:mj.tex_adr[t] + height * width * channels]
    return np.asarray(data, dtype=np.uint8).reshape(height, width, channels)[..., :3]


def test_builtin_textures_are_mujocos_pixel_for_pixel():
    model, mj = builtin_textures()
    specs = {v["texture"]["name"]: v["texture"] for v in model.visuals}
    for name in ["checker", "gradient", "flat"]:
        np.testing.assert_array_equal(builtin_image(specs[name]["builtin"]), mujoco_texture(mj, name), err_msg=name)
    for name in ["cube", "cubeflat"]:
        np.testing.assert_array_equal(np.concatenate(cube_faces(specs[name]["builtin"])), mujoco_texture(mj, name), err_msg=name)
    assert model.skybox["kind"] == "skybox" and model.skybox["name"].startswith("texture")
    np.testing.assert_array_equal(np.concatenate(cube_faces(model.skybox["builtin"])), mujoco_texture(mj, ""))
    # random dots: the same share of pixels, elsewhere
    ours = (builtin_image(specs["dots"]["builtin"]) == 255).all(axis=-1).mean()
    theirs = (mujoco_texture(mj, "dots") == 255).all(axis=-1).mean()
    assert abs(ours - theirs) < RANDOM_DOT_FRACTION_TOLERANCE and abs(ours - 0.1) < RANDOM_DOT_FRACTION_TOLERANCE


def test_the_skybox_panorama_is_the_gradient_by_elevation():
    """Straight up is rgb1's bytes, straight down rgb2's, the horizon their even mix, all round."""
    model, mj = builtin_textures()
    panorama = skybox_panorama(model.skybox["builtin"]).astype(int)
    faces = mujoco_texture(mj, "").reshape(6, 32, 32, 3).astype(int)
    up_face, down_face, side_face = faces[2], faces[3], faces[0]
    # the top and bottom rows sample the up and down faces' middles; the middle row the sides' middle
    assert np.abs(panorama[0] - up_face[16, 16]).max() <= 1
    assert np.abs(panorama[-1] - down_face[16, 16]).max() <= 1
    middle = panorama.shape[0] // 2
    assert np.abs(panorama[middle] - side_face[16, 16]).max() <= np.abs(side_face[15, 16] - side_face[17, 16]).max() + 1


def test_what_cannot_be_drawn_is_drawn_in_its_materials_colour_with_a_warning(tmp_path: Path):
    (tmp_path / "image.jpg").write_bytes(b"not read")
    path = tmp_path / "scene.xml"
    path.write_text("""<mujoco><asset>
      <texture name="cube" type="cube" builtin="checker" width="8"/>
      <texture name="tiles" type="2d" builtin="checker" width="8" height="8"/>
      <texture name="photo" type="2d" file="image.jpg"/>
      <texture name="gone" type="2d" file="missing.png"/>
      <material name="cube" texture="cube" rgba="0.9 0.1 0.1 1"/>
      <material name="tiles" texture="tiles" rgba="0.1 0.9 0.1 1"/>
      <material name="photo" texture="photo"/>
      <material name="gone" texture="gone"/>
    </asset><worldbody>
      <geom name="a" type="sphere" size="0.1" material="cube"/>
      <geom name="b" type="box" size="0.1 0.1 0.1" material="tiles"/>
      <geom name="c" type="plane" size="1 1 1" material="photo"/>
      <geom name="d" type="plane" size="1 1 1" material="gone"/>
    </worldbody></mujoco>""")
    model = robodyn.load(path)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        pieces = visual_pieces(model)
    messages = [str(w.message) for w in caught if issubclass(w.category, robodyn.ModelWarning)]
    assert len(messages) == 4, messages
    assert any("texture 'cube'" in m and "cube texture on a sphere" in m for m in messages)
    assert any("texture 'tiles'" in m and "not on a box" in m for m in messages)
    assert any("texture 'photo'" in m and "'image.jpg' is not a PNG" in m for m in messages)
    assert any("texture 'gone'" in m and "missing.png' not found" in m for m in messages)
    assert all(piece.image is None for piece in pieces)
    assert [piece.rgba for piece in pieces[:2]] == [(0.9, 0.1, 0.1, 1.0), (0.1, 0.9, 0.1, 1.0)]


@pytest.mark.parametrize("texture, message", [
    ('<texture name="t" builtin="stripes" width="8" height="8"/>', "attribute 'builtin': expected none, gradient, checker or flat, got 'stripes'"),
    ('<texture name="t" builtin="checker" mark="dots" width="8" height="8"/>', "attribute 'mark': expected none, edge, cross or random, got 'dots'"),
    ('<texture name="t" builtin="checker" width="8"/>', "a builtin texture needs a positive 'width'"),
    ('<texture name="t"/>', "expected a 'file' or a 'builtin' pattern, got neither"),
    ('<texture name="other" builtin="flat" width="8" height="8"/>', "attribute 'texture': no <texture name='t'>"),
])
def test_bad_textures_name_the_file_and_element(texture: str, message: str):
    text = f'<mujoco><asset>{texture}<material name="mine" texture="t"/></asset><worldbody><geom size="1" material="mine"/></worldbody></mujoco>'
    where = r"scene\.xml: <(texture|material) name='\w+'> \(line \d+\): "
    with pytest.raises(ValueError, match=where + message.replace("(", r"\(").replace(")", r"\)")):
        robodyn.load_mjcf_string(text, "scene.xml")


def test_textured_pieces_carry_their_images_and_coordinates():
    model = robodyn.load(SCENE)
    with pytest.warns(robodyn.ModelWarning, match="texture 'marble'"):
        pieces = {piece.name.split("/")[0]: piece for piece in visual_pieces(model)}
    floor, panel, knob = pieces["floor"], pieces["panel"], pieces["knob"]
    assert floor.backdrop and floor.image.size == (100, 100) and floor.uv is not None
    assert panel.image.size == (8, 8) and panel.uv.shape == (len(panel.vertices), 2) and not panel.backdrop
    assert knob.image is None and knob.rgba == (0.9, 0.5, 0.1, 1.0)
    # texrepeat 5 per two metres on an unbounded floor: s = 5 x / 2 - 1/2
    x = floor.vertices[:, 0]
    np.testing.assert_allclose(floor.uv[:, 0], 2.5 * x - 0.5)


def test_an_unnamed_texture_goes_by_its_files_name_as_in_mujoco(tmp_path: Path):
    shutil.copytree(SCENE.parent, tmp_path / "textured")
    scene = tmp_path / "textured" / "scene.xml"
    scene.write_text(scene.read_text().replace('<texture type="2d" name="quadrants" file=', '<texture type="2d" file='))
    mujoco.MjModel.from_xml_path(str(scene))
    with pytest.warns(robodyn.ModelWarning, match="texture 'marble'"):
        pieces = {piece.name.split("/")[0]: piece for piece in visual_pieces(robodyn.load(scene))}
    assert pieces["panel"].image.size == (8, 8)


def test_the_first_view_frames_the_robot_not_the_floor():
    model = robodyn.load(SCENE)
    q = model.neutral()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", robodyn.ModelWarning)
        with Viewer(model, q, open_browser=False, port=0) as viewer:
            low, high = viewer.scene.bounds
    # the robot's pieces: the panel and the post around the free body at its pose in the file
    assert np.all(low > [-0.2, -0.35, 0.2]) and np.all(high < [0.2, 0.4, 0.8]), (low, high)


#: The free camera both renderers look through: MuJoCo's (look-at point, distance, azimuth and
#: elevation in degrees) and the same as robodyn's (position, point looked at).
LOOKAT, DISTANCE, AZIMUTH, ELEVATION = np.array([0.05, 0.05, 0.5]), 1.6, 0.0, -20.0


def camera_position() -> np.ndarray:
    azimuth, elevation = np.radians(AZIMUTH), np.radians(ELEVATION)
    forward = np.array([np.cos(elevation) * np.cos(azimuth), np.cos(elevation) * np.sin(azimuth), np.sin(elevation)])
    return LOOKAT - DISTANCE * forward


#: The magenta post's silhouette in the two images: its box agrees within this many pixels (the
#: two renderers tessellate the capsule and smooth its edges differently: 0-1 pixels measured).
SILHOUETTE_TOLERANCE_PX = 4
#: A pixel is the post's where red and blue lead green by this much and by about as much as each
#: other: low, since MuJoCo shades the post's far side dark (red and blue about 40 over green).
MAGENTA_CHROMA, MAGENTA_HUE = 30, 60
#: How strongly the leading channel must lead for a pixel to count as a colour, and how much of
#: a window round a projected point must show the expected one.
CHROMA = 40
WINDOW = 6
DRAWN_FRACTION = 0.8
#: The panel's image: red top left, green top right, yellow bottom left (and white bottom right),
#: at the panel's (x, y) where its texture coordinates put them.
QUADRANTS = {"red": ((-0.1, 0.1), (220, 30, 30)), "green": ((0.1, 0.1), (30, 200, 30)), "yellow": ((-0.1, -0.1), (230, 210, 20))}


def magenta_box(pixels: np.ndarray) -> np.ndarray:
    """The bounding box (column, row, column, row) of the magenta pixels."""
    p = pixels.astype(int)
    magenta = (np.minimum(p[..., 0], p[..., 2]) - p[..., 1] > MAGENTA_CHROMA) & (np.abs(p[..., 0] - p[..., 2]) < MAGENTA_HUE)
    rows, columns = np.nonzero(magenta)
    assert len(rows) > 0, "no magenta pixels"
    return np.array([columns.min(), rows.min(), columns.max(), rows.max()])


def window_around(pixels: np.ndarray, pixel: np.ndarray) -> np.ndarray:
    """The pixels (n, 3) within :data:`WINDOW` of ``pixel`` (column, row)."""
    column, row = (int(round(c)) for c in pixel)
    return pixels[row - WINDOW:row + WINDOW + 1, column - WINDOW:column + WINDOW + 1].reshape(-1, 3)


def test_the_page_shows_what_mujoco_renders(tmp_path: Path):
    """MuJoCo's offscreen render (osmesa) and robodyn's page in headless Chromium of the textured
    scene at its neutral configuration, from the same camera: the post's silhouette box, the
    panel's texture quadrants where its texture coordinates put them, a bluish checker floor and
    a bluish sky above the horizon, in both."""
    camera = (camera_position(), LOOKAT)
    theirs = mujoco_render(SCENE, tmp_path / "mujoco.npy", WIDTH, HEIGHT, camera)[0].astype(np.int16)
    model = robodyn.load(SCENE)
    with pytest.warns(robodyn.ModelWarning, match="texture 'marble'"):
        page = model.to_html(tmp_path / "scene.html", camera=camera)
    ours, _ = screenshot(page.resolve().as_uri(), tmp_path, "scene")
    # beside robodyn's screenshot (scene.png), for a look when this fails
    Image.fromarray(theirs.astype(np.uint8)).save(tmp_path / "mujoco.png")
    assert np.abs(magenta_box(ours) - magenta_box(theirs)).max() <= SILHOUETTE_TOLERANCE_PX, (magenta_box(ours), magenta_box(theirs))
    # the panel lies in the body's y-z plane facing -x: its local (x, y) is world (-y, z)
    body = np.asarray(model.frame_pose(model.neutral(), "robot"))
    for name, ((u, v), rgb) in QUADRANTS.items():
        point = body[:3, :3] @ np.array([0.0, -u, v]) + body[:3, 3]
        pixel = project(point, camera, CAMERA_FOV)[0]
        for label, pixels in [("robodyn", ours), ("MuJoCo", theirs)]:
            assert colour_fraction(pixels, pixel, WINDOW, rgb, CHROMA // 2) > DRAWN_FRACTION, f"{name} quadrant in {label}'s image"
            # yellow, not red: green leads blue there too
            green_over_blue = np.median(window_around(pixels, pixel) @ np.array([0, 1, -1]))
            assert (green_over_blue > CHROMA) == (name != "red"), f"{name} quadrant in {label}'s image"
    floor_pixel, sky_pixel = np.array([WIDTH / 2, HEIGHT - 20]), np.array([WIDTH / 2, 20])
    for label, pixels in [("robodyn", ours), ("MuJoCo", theirs)]:
        for where, pixel in [("floor", floor_pixel), ("sky", sky_pixel)]:
            window = window_around(pixels, pixel)
            assert (window[:, 2] > window[:, 0]).mean() > DRAWN_FRACTION, f"{where} in {label}'s image is not bluish"
