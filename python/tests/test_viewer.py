"""The viewer: visuals read from URDF and MJCF (against MuJoCo's placement of the same geoms),
their errors, and the pages in headless Chromium (drawn where forward kinematics puts the robot,
loading nothing from outside the file)."""

from __future__ import annotations

import os
import shutil
import time
from pathlib import Path

import mujoco
import numpy as np
import pytest

import robodyn
from browser import colour_fraction, project, screenshot
from robodyn.viewer import TrajectoryViewer, Viewer
from robodyn.viewer.geometry import stick_pieces, visual_pieces
from robodyn.viewer.scene import CAMERA_FOV

ROOT = Path(__file__).resolve().parents[2]
ARM = ROOT / "testdata" / "mjcf" / "viewer_arm.xml"
MESH_INERTIA = ROOT / "testdata" / "mjcf" / "mesh_inertia.xml"
MESH_FITAABB = ROOT / "testdata" / "mjcf" / "mesh_fitaabb.xml"
BOX_STL = ROOT / "testdata" / "meshes" / "box.stl"
#: Poses agree with MuJoCo's to round-off; mesh vertices to MuJoCo's float32 storage.
POSE_TOLERANCE = 1e-9
VERTEX_TOLERANCE = 1e-6
#: A primitive fitted to a mesh lies along the mesh's principal axes, which MuJoCo's eigensolver
#: finds to about 1e-7 when two principal moments are close.
AXES_TOLERANCE = 1e-6
#: Sizes agree to round-off; a primitive fitted to a mesh's bounding box (fitaabb) takes that box
#: along those axes, so its size moves with them: 1e-7 rad times the mesh's extent.
SIZE_TOLERANCE = 1e-9
FITTED_BOX_SIZE_TOLERANCE = 1e-7
#: The arm's configurations in the screenshots, and the camera that looks at them.
ARM_CONFIGURATIONS = {"upright": [0.0, 0.0], "bent": [1.0, 0.8]}
ARM_CAMERA = (np.array([1.6, 1.2, 0.9]), np.array([0.0, 0.0, 0.4]))
RED, GREEN = (230, 25, 25), (25, 200, 25)
#: The README picture's view of the UR5 (below the browser's notice at the top left).
UR5_CAMERA = (np.array([1.15, 0.95, 0.75]), np.array([-0.05, 0.1, 0.45]))
#: Half-side of the pixel window checked around a projected point, and how much of it must have
#: the expected colour (the balls are 0.05-0.06 m: about 15 pixels across at this distance).
WINDOW = 5
DRAWN_FRACTION = 0.8
CHROMA = 40


def world_pose(model, q, visual) -> np.ndarray:
    return np.asarray(model.body_poses(q))[visual["body"]] @ np.asarray(visual["placement"])


def mujoco_colour(mj, g) -> np.ndarray:
    """MuJoCo's drawn colour of geom g: its rgba unless default and it has a material."""
    if mj.geom_matid[g] >= 0 and np.allclose(mj.geom_rgba[g], [0.5, 0.5, 0.5, 1]):
        return mj.mat_rgba[mj.geom_matid[g]]
    return mj.geom_rgba[g]


@pytest.mark.parametrize("path", [ARM, MESH_INERTIA, MESH_FITAABB], ids=["viewer_arm", "mesh_inertia", "mesh_fitaabb"])
def test_mjcf_visuals_are_placed_sized_and_coloured_as_mujoco_does(path: Path) -> None:
    model = robodyn.load(path)
    mj = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(mj)
    assert set(model.joint_types) == {"revolute"} and model.nq == mj.nq
    q = np.random.default_rng(3).uniform(-1, 1, model.nq)
    data.qpos[:] = q
    mujoco.mj_kinematics(mj, data)
    assert len(model.visuals) == mj.ngeom
    for g, visual in enumerate(model.visuals):
        pose = world_pose(model, q, visual)
        assert visual["group"] == mj.geom_group[g]
        np.testing.assert_allclose(visual["rgba"], mujoco_colour(mj, g), atol=1e-7)
        if visual["kind"] != "mesh":
            assert mujoco.mjtGeom(mj.geom_type[g]).name == "mjGEOM_" + visual["kind"].upper()
            np.testing.assert_allclose(pose[:3, 3], data.geom_xpos[g], atol=POSE_TOLERANCE)
            # the same axes; a primitive fitted to a mesh may have two of them reversed (the
            # principal axes' signs are free), which leaves every primitive unchanged
            alignment = pose[:3, :3].T @ data.geom_xmat[g].reshape(3, 3)
            np.testing.assert_allclose(np.abs(alignment), np.eye(3), atol=AXES_TOLERANCE)
            size_tolerance = FITTED_BOX_SIZE_TOLERANCE if path == MESH_FITAABB else SIZE_TOLERANCE
            np.testing.assert_allclose(visual["size"], mj.geom_size[g][: len(visual["size"])], rtol=size_tolerance)
            continue
        # a mesh: the same vertices in the world, whatever frame MuJoCo re-centred it in
        mesh = mj.geom_dataid[g]
        start, count = mj.mesh_vertadr[mesh], mj.mesh_vertnum[mesh]
        theirs = mj.mesh_vert[start:start + count] @ data.geom_xmat[g].reshape(3, 3).T + data.geom_xpos[g]
        (piece,) = [p for p in visual_pieces(model, None) if p.name.startswith(visual["name"] + "/")]
        body = np.asarray(model.body_poses(q))[visual["body"]]
        ours = piece.vertices @ body[:3, :3].T + body[:3, 3]
        distance = np.linalg.norm(theirs[:, None, :] - ours[None, :, :], axis=2)
        assert distance.min(axis=1).max() < VERTEX_TOLERANCE and distance.min(axis=0).max() < VERTEX_TOLERANCE


def write_urdf(folder: Path, visual: str, extra: str = "") -> Path:
    path = folder / "robot.urdf"
    path.write_text(f"""<robot name="r">
  <material name="orange"><color rgba="1 0.5 0 1"/></material>{extra}
  <link name="base"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <origin xyz="0 0 0.1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="arm">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    {visual}
  </link>
  <joint name="fixed" type="fixed"><parent link="arm"/><child link="hand"/><origin xyz="0.3 0 0" rpy="0 0 0.5"/></joint>
  <link name="hand">
    <visual><origin xyz="0.05 0 0"/><geometry><sphere radius="0.04"/></geometry><material name="orange"/></visual>
  </link>
</robot>
""")
    return path


def test_urdf_visuals_have_their_shapes_colours_and_places(tmp_path: Path) -> None:
    (tmp_path / "arm" / "meshes").mkdir(parents=True)
    shutil.copy(BOX_STL, tmp_path / "arm" / "meshes" / "box.stl")
    path = write_urdf(tmp_path / "arm", """
    <visual name="body"><origin xyz="0 0 0.2" rpy="0.1 0 0"/><geometry><box size="0.1 0.2 0.4"/></geometry>
      <material name="teal"><color rgba="0 0.5 0.5 1"/></material></visual>
    <visual><geometry><cylinder radius="0.02" length="0.3"/></geometry></visual>
    <visual><geometry><mesh filename="package://arm/meshes/box.stl" scale="2 2 2"/></geometry></visual>""")
    model = robodyn.load(path)
    by_name = {v["name"]: v for v in model.visuals}
    assert [v["kind"] for v in model.visuals] == ["box", "cylinder", "mesh", "sphere"]
    assert by_name["body"]["size"] == pytest.approx([0.05, 0.1, 0.2]) and by_name["body"]["rgba"] == [0, 0.5, 0.5, 1]
    assert by_name["arm_visual1"]["size"] == pytest.approx([0.02, 0.15])
    assert by_name["arm_visual1"]["rgba"] == [0.5, 0.5, 0.5, 1]
    mesh = by_name["arm_visual2"]
    assert Path(mesh["mesh_file"]).resolve() == (tmp_path / "arm" / "meshes" / "box.stl").resolve()
    np.testing.assert_allclose(np.asarray(mesh["file_to_visual"]), np.diag([2.0, 2.0, 2.0, 1.0]))
    # the hand's sphere rides on the arm's body, at the hand's frame
    hand = by_name["hand_visual0"]
    assert hand["rgba"] == [1, 0.5, 0, 1] and hand["body"] == 1
    q = [0.7]
    expected = np.asarray(model.frame_pose(q, "hand")) @ np.array([[1, 0, 0, 0.05], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
    np.testing.assert_allclose(world_pose(model, q, hand), expected, atol=1e-12)
    pieces = visual_pieces(model)
    assert len(pieces) == 4
    np.testing.assert_allclose(pieces[2].vertices.max(axis=0), [0.2, 0.4, 0.6], rtol=1e-6)


def test_urdf_meshes_in_collada_are_read(tmp_path: Path) -> None:
    model = robodyn.load("ur5_robot.urdf")
    files = {Path(v["mesh_file"]).suffix for v in model.visuals}
    assert files == {".dae"}
    pieces = visual_pieces(model)
    assert len(pieces) >= len(model.visuals) and all(len(p.faces) > 100 for p in pieces)


@pytest.mark.parametrize("visual, message", [
    ("<visual><origin/></visual>", "missing <geometry>"),
    ("<visual><geometry><sphere radius='-1'/></geometry></visual>", "attribute 'radius': expected a positive number, got '-1'"),
    ("<visual><geometry><box size='1 1'/></geometry></visual>", "size"),
    ("<visual><geometry><cone radius='1'/></geometry></visual>", "unknown geometry <cone>"),
    ("<visual><geometry><mesh/></geometry></visual>", "missing attribute 'filename'"),
])
def test_bad_urdf_visuals_name_the_file_element_and_line(tmp_path: Path, visual: str, message: str) -> None:
    path = write_urdf(tmp_path, visual)
    with pytest.raises(ValueError, match="robot.urdf") as error:
        robodyn.load(path)
    assert message in str(error.value) and "line" in str(error.value)


def test_a_material_defined_nowhere_is_drawn_grey_with_a_warning(tmp_path: Path) -> None:
    path = write_urdf(tmp_path, "<visual><geometry><sphere radius='1'/></geometry><material name='nowhere'/></visual>")
    with pytest.warns(robodyn.ModelWarning, match=r"robot.urdf: <material name='nowhere'> \(line \d+\): material 'nowhere' has no <color>"):
        model = robodyn.load(path)
    assert model.visuals[0]["rgba"] == [0.5, 0.5, 0.5, 1.0]
    with pytest.raises(ValueError, match="material 'nowhere'"):
        robodyn.load(path, strict=True)


def test_missing_and_unreadable_meshes_name_the_file_and_element(tmp_path: Path) -> None:
    path = write_urdf(tmp_path, "<visual><geometry><mesh filename='package://nowhere/meshes/a.stl'/></geometry></visual>")
    model = robodyn.load(path)  # the dynamics do not need the mesh
    missing = model.visuals[0]["mesh_missing"]
    assert "a.stl" in missing and "<mesh>" in missing and str(tmp_path / "nowhere" / "meshes" / "a.stl") in missing
    with pytest.raises(FileNotFoundError, match="package://nowhere/meshes/a.stl"):
        model.to_html(tmp_path / "robot.html")
    (tmp_path / "broken.stl").write_bytes(b"solid nothing\nthis is not an stl\n")
    (tmp_path / "mesh.xyz").write_text("1 2 3\n")
    for name, message in [("broken.stl", "broken.stl"), ("mesh.xyz", "mesh.xyz")]:
        path = write_urdf(tmp_path, f"<visual><geometry><mesh filename='{name}'/></geometry></visual>")
        with pytest.raises(ValueError, match=message) as error:
            visual_pieces(robodyn.load(path))
        assert "<visual>" in str(error.value)


def test_html_paths_and_configurations_are_checked(tmp_path: Path) -> None:
    model = robodyn.load(ARM)
    with pytest.raises(ValueError, match="argument 'path': expected a file name ending in .html"):
        model.to_html(tmp_path / "arm.png")
    with pytest.raises(ValueError, match="argument 'path': the folder"):
        model.to_html(tmp_path / "no" / "arm.html")
    with pytest.raises(ValueError, match=r"argument 'q': expected one configuration of shape \(2,\)"):
        model.to_html(tmp_path / "arm.html", [0.0])


def check_arm_drawn(pixels: np.ndarray, model, q) -> None:
    """The red ball at the tip and the green one at the elbow where forward kinematics puts them,
    and neither colour far from the robot."""
    tip = np.asarray(model.frame_pose(q, "tip"))[:3, 3]
    elbow = np.asarray(model.frame_pose(q, "fore"))[:3, 3]
    tip_pixel, elbow_pixel = project(np.array([tip, elbow]), ARM_CAMERA, CAMERA_FOV)
    assert colour_fraction(pixels, tip_pixel, WINDOW, RED, CHROMA) > DRAWN_FRACTION
    assert colour_fraction(pixels, elbow_pixel, WINDOW, GREEN, CHROMA) > DRAWN_FRACTION
    far_corner = np.array([780, 580])
    assert colour_fraction(pixels, far_corner, WINDOW, RED, CHROMA) == 0
    assert colour_fraction(pixels, far_corner, WINDOW, GREEN, CHROMA) == 0


#: Screenshots of a live server's page taken before its arm must be drawn: on a loaded machine
#: the browser's virtual time can run out before the server's scene reaches the page.
LIVE_ATTEMPTS = 3


def check_live_arm_drawn(url: str, folder: Path, name: str, model, q) -> None:
    """`check_arm_drawn` on a screenshot of the live page at ``url``, taken again (up to
    `LIVE_ATTEMPTS` times) while the arm is not there yet."""
    for attempt in range(LIVE_ATTEMPTS):
        pixels, _ = screenshot(url, folder, f"{name}-{attempt}")
        try:
            check_arm_drawn(pixels, model, q)
            return
        except AssertionError:
            if attempt + 1 == LIVE_ATTEMPTS:
                raise


def test_html_export_draws_the_robot_where_forward_kinematics_puts_it(tmp_path: Path) -> None:
    model = robodyn.load(ARM)
    shots = {}
    for name, q in ARM_CONFIGURATIONS.items():
        page = model.to_html(tmp_path / f"{name}.html", q, camera=ARM_CAMERA)
        shots[name], urls = screenshot(page.resolve().as_uri(), tmp_path, name, net_log=True)
        assert urls == [], f"the page requested {urls}"
        check_arm_drawn(shots[name], model, q)
    # where the tip is in one configuration, the other has no red
    upright_tip = project(np.asarray(model.frame_pose(ARM_CONFIGURATIONS["upright"], "tip"))[:3, 3], ARM_CAMERA, CAMERA_FOV)[0]
    assert colour_fraction(shots["bent"], upright_tip, WINDOW, RED, CHROMA) == 0


def test_the_network_check_sees_a_page_that_loads_from_outside(tmp_path: Path) -> None:
    page = tmp_path / "outside.html"
    page.write_text('<html><body><img src="https://example.invalid/robot.png"></body></html>')
    _, urls = screenshot(page.as_uri(), tmp_path, "outside", net_log=True)
    assert urls == ["https://example.invalid/robot.png"]


def test_live_viewer_shows_a_configuration_and_follows_show(tmp_path: Path) -> None:
    model = robodyn.load(ARM)
    upright, bent = ARM_CONFIGURATIONS["upright"], ARM_CONFIGURATIONS["bent"]
    with model.view(upright, open_browser=False, port=0, camera=ARM_CAMERA) as viewer:
        assert viewer.url.startswith("http://127.0.0.1:")
        check_live_arm_drawn(viewer.url, tmp_path, "live-upright", model, upright)
        viewer.show(bent)
        check_live_arm_drawn(viewer.url, tmp_path, "live-bent", model, bent)


def test_trajectory_player_and_its_offline_page(tmp_path: Path) -> None:
    model = robodyn.load(ARM)
    trajectory = robodyn.simulate(model, [0.3, 0.2], t_end=1.0, dt=1e-3)
    viewer = trajectory.view(open_browser=False, port=0, camera=ARM_CAMERA)
    try:
        assert viewer.time.max == pytest.approx(trajectory.t[-1]) and viewer.speed.value == "1x"
        k = len(trajectory.t) * 3 // 4
        viewer.seek(trajectory.t[k])  # pauses; the slider poses the robot
        time.sleep(0.2)
        assert viewer.time.value == float(trajectory.t[k]) and not viewer.playing.value
        check_live_arm_drawn(viewer.url, tmp_path, "player", model, trajectory.q[k])
    finally:
        viewer.close()
    page = trajectory.to_html(tmp_path / "swing.html", com=True, frames=True)
    pixels, urls = screenshot(page.resolve().as_uri(), tmp_path, "swing", net_log=True)
    assert urls == []
    red = (pixels[..., 0] - pixels[..., 2] > CHROMA) & (pixels[..., 0] - pixels[..., 1] > CHROMA)
    assert red.sum() > 50, "the played trajectory shows no robot"


def test_readme_picture(tmp_path: Path) -> None:
    """Renders docs/viewer.png (the README's picture) from example-robot-data's UR5 and its
    Collada meshes; ROBODYN_WRITE_DOCS=1 writes it into the repository."""
    model = robodyn.load("ur5_robot.urdf")
    page = model.to_html(tmp_path / "ur5.html", [0.0, -1.2, 1.5, -0.3, 1.2, 0.0], camera=UR5_CAMERA)
    pixels, urls = screenshot(page.resolve().as_uri(), tmp_path, "ur5", net_log=True)
    assert urls == []
    # below the browser's notice about software rendering
    picture = pixels[150:, 100:700]
    background = np.median(picture.reshape(-1, 3), axis=0)
    robot = np.abs(picture - background).sum(axis=2) > 60
    assert robot.mean() > 0.05, "the UR5 is not drawn"
    if os.environ.get("ROBODYN_WRITE_DOCS") == "1":
        from PIL import Image

        Image.fromarray(picture.astype(np.uint8)).save(ROOT / "docs" / "viewer.png", optimize=True)


def test_the_first_view_frames_the_bodies_not_the_floor() -> None:
    """The arm stands on a 1.2 m plane: the first view frames the arm alone (within its own reach),
    and the camera comes as close as the arm's size asks."""
    model = robodyn.load(ARM)
    with Viewer(model, open_browser=False, port=0) as viewer:
        low, high = viewer.scene.bounds
        position, target = viewer.scene.camera
    assert np.all(low[:2] > -0.2) and np.all(high[:2] < 0.2), (low, high)
    assert np.linalg.norm(position - target) < 2.0


def test_player_rejects_an_unknown_speed() -> None:
    model = robodyn.load(ARM)
    trajectory = robodyn.simulate(model, [0.3, 0.2], t_end=0.1, dt=1e-3)
    with pytest.raises(ValueError, match="argument 'speed': expected one of"):
        TrajectoryViewer(trajectory, speed="3x", open_browser=False, port=0)


def test_a_model_without_visuals_is_drawn_as_a_stick_figure() -> None:
    model = robodyn.load("ur5")
    assert model.visuals == []
    pieces = stick_pieces(model)
    q = np.array([0.3, -1.2, 1.5, -0.3, 1.2, 0.4])
    poses = np.asarray(model.body_poses(q))
    balls = [p for p in pieces if p.name.startswith("joint")]
    assert len(balls) == len(model.body_names)
    for ball in balls:
        centre = poses[ball.body][:3, :3] @ ball.vertices.mean(axis=0) + poses[ball.body][:3, 3]
        np.testing.assert_allclose(centre, poses[ball.body][:3, 3], atol=1e-9)
    # each rod ends at a child's joint: the wrist's rod reaches the last body's origin
    rods = [p for p in pieces if p.name.startswith("stick") and p.body == len(poses) - 2]
    ends = [poses[r.body][:3, :3] @ r.vertices.T + poses[r.body][:3, 3:4] for r in rods]
    reach = min(np.linalg.norm(e - poses[-1][:3, 3:4], axis=0).min() for e in ends)
    assert reach < 0.02


def test_the_shell_commands_write_pages_and_check_their_paths(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from robodyn.cli import main

    assert main(["view", str(ARM), "--q", "0.5", "0.5", "--html", str(tmp_path / "arm.html")]) == 0
    assert main(["simulate", str(ARM), "--t", "0.2", "--html", str(tmp_path / "swing.html")]) == 0
    for page in ("arm.html", "swing.html"):
        text = (tmp_path / page).read_text()
        assert "__VISER_EMBED_DATA__" in text and len(text) > 100_000
    assert main(["view", str(ARM), "--html", str(tmp_path / "no" / "arm.html")]) == 2
    assert main(["simulate", str(ARM), "--html", str(tmp_path / "arm.png")]) == 2
    errors = capsys.readouterr().err
    assert "robodyn view: argument '--html': the folder" in errors
    assert "robodyn simulate: argument '--html': expected a file name ending in .html" in errors


BOX_SCENE = """<mujoco><worldbody><geom name="floor" type="plane" size="1 1 1"/>
  <body name="box" pos="0 0 0.1"><freejoint/><geom name="box" type="box" size="0.1 0.1 0.1" rgba="0.9 0.1 0.1 1"/></body>
  </worldbody></mujoco>"""


def test_a_scene_run_shows_its_contact_points_and_force_arrows(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A box at rest on a floor: the player draws a point at each corner's contact and an arrow
    along the floor's push, the four together the box's weight m g at WEIGHT_ARROW_FRACTION of the
    robot's size; unchecked, none; the offline page draws each frame's sample; a run without
    contacts recorded has the box disabled."""
    from robodyn.viewer.scene import WEIGHT_ARROW_FRACTION, RobotScene

    scene = robodyn.load_mjcf_string(BOX_SCENE)
    run = robodyn.simulate(scene, scene.neutral(), t_end=0.3, dt=0.01, integrator="mujoco")
    viewer = run.view(open_browser=False, port=0)
    try:
        viewer.seek(run.t[-1])
        time.sleep(0.2)
        points, arrows = viewer.contacts[-1]
        assert np.allclose(points, [c["position"] for c in run.contacts[-1]])
        pushed = (arrows[:, 1] - arrows[:, 0]).sum(axis=0)
        assert np.allclose(pushed, [0.0, 0.0, WEIGHT_ARROW_FRACTION * viewer.scene.size], rtol=1e-6, atol=1e-9)
        cloud, lines = viewer.scene.contact_nodes
        assert cloud.visible and lines.visible
        viewer.contacts_box.value = False
        time.sleep(0.2)
        assert not viewer.scene.contact_nodes[1].visible
    finally:
        viewer.close()
    drawn: list[np.ndarray] = []
    original = RobotScene.show_contacts
    monkeypatch.setattr(RobotScene, "show_contacts",
                        lambda self, points, arrows, visible=True: (drawn.append(points), original(self, points, arrows, visible)))
    run.to_html(tmp_path / "box.html")
    assert len(drawn) == int(round(run.t[-1] * 60)) + 1
    assert np.allclose(drawn[-1], points)
    drawn.clear()
    run.to_html(tmp_path / "plain.html", contacts=False)
    assert drawn == []
    free_fall = robodyn.simulate(scene, scene.neutral(), t_end=0.01)
    player = free_fall.view(open_browser=False, port=0)
    try:
        assert player.contacts is None and player.contacts_box.disabled
    finally:
        player.close()


def test_the_viewer_draws_a_poses_contacts_and_their_forces() -> None:
    """A box resting on a floor, shown at rest: a point at each corner's contact and an arrow along
    the floor's push (contact_forward_dynamics at v = 0), the four the box's weight m g at
    WEIGHT_ARROW_FRACTION of the robot's size; hide_contacts draws none."""
    from robodyn.viewer.scene import WEIGHT_ARROW_FRACTION

    scene = robodyn.load_mjcf_string(BOX_SCENE)
    q = scene.neutral()
    q[2] = 0.099
    viewer = Viewer(scene, open_browser=False, port=0)
    try:
        contacts = viewer.show_contacts(q)
        assert len(contacts) == 4
        cloud, lines = viewer.scene.contact_nodes
        assert cloud.visible and lines.visible
        # viser keeps the points in float16 (11 significant bits) and the lines in float32
        assert np.allclose(cloud.points, [c["position"] for c in contacts], rtol=1e-3, atol=1e-6)
        arrows = np.asarray(lines.points, dtype=float)
        expected = sum(np.asarray(c["frame"]).T @ np.asarray(c["force"])[:3] for c in contacts)
        scale = WEIGHT_ARROW_FRACTION * viewer.scene.size / (scene.total_mass * np.linalg.norm(scene.gravity))
        assert np.allclose((arrows[:, 1] - arrows[:, 0]).sum(axis=0), scale * expected, rtol=1e-5, atol=1e-6)
        viewer.hide_contacts()
        assert not viewer.scene.contact_nodes[1].visible
    finally:
        viewer.close()


#: A see-through box resting on the floor (its contact arrows point up into it), and a camera
#: that shows its four bottom corners clear of the page's notices and panel.
SEE_THROUGH_BOX = BOX_SCENE.replace('rgba="0.9 0.1 0.1 1"', 'rgba="0.2 0.3 0.9 0.25"')
CONTACT_CAMERA = (np.array([0.5, -0.5, 0.4]), np.array([0.15, 0.1, 0.0]))
#: The points and arrows are a few pixels wide: a window of this half-side around a projected
#: point, of which more than this fraction has the contacts' colour where they are drawn
#: (measured: 0.16-0.4, the far corner's point, half under the floor, the least) and none where
#: they are not (0 exactly).
CONTACT_WINDOW = 2
CONTACT_DRAWN_FRACTION = 0.1


def test_a_screenshot_shows_the_contact_points_and_arrows_where_they_are(tmp_path: Path) -> None:
    """The live viewer's page, screenshot in headless Chromium: the contacts' colour at each corner
    of the box on the floor and halfway up each force arrow, none past an arrow's tip (the four
    carry the box's weight at WEIGHT_ARROW_FRACTION of its size); none once hidden."""
    from robodyn.viewer.scene import CONTACT_RGB, WEIGHT_ARROW_FRACTION

    scene = robodyn.load_mjcf_string(SEE_THROUGH_BOX)
    q = scene.neutral()
    q[2] = 0.099
    viewer = Viewer(scene, q, open_browser=False, port=0, camera=CONTACT_CAMERA)
    try:
        contacts = viewer.show_contacts(q)
        points = np.array([c["position"] for c in contacts])
        arrow = WEIGHT_ARROW_FRACTION * viewer.scene.size / len(contacts) * np.array([0.0, 0.0, 1.0])
        drawn = [points, points + arrow / 2]
        beyond = points + 1.6 * arrow

        def fractions(pixels: np.ndarray, where: np.ndarray) -> list[float]:
            pixel = project(where, CONTACT_CAMERA, CAMERA_FOV)
            return [colour_fraction(pixels, p, CONTACT_WINDOW, CONTACT_RGB, CHROMA) for p in pixel]

        pixels, _ = screenshot(viewer.url, tmp_path, "contacts")
        for where in drawn:
            assert min(fractions(pixels, where)) > CONTACT_DRAWN_FRACTION, fractions(pixels, where)
        assert max(fractions(pixels, beyond)) == 0.0, fractions(pixels, beyond)
        viewer.hide_contacts()
        pixels, _ = screenshot(viewer.url, tmp_path, "hidden")
        assert max(max(fractions(pixels, where)) for where in drawn) == 0.0
    finally:
        viewer.close()
