"""Physics a user can check on scenes stepped as MuJoCo steps them (`integrator="mujoco"`), without
MuJoCo: a crate on an incline sticks below atan μ and slides above it with a = g (sin θ − μ cos θ),
a ball rolls down without slipping (a = 5/7 g sin θ), Menagerie's Go2 held at its `home`
keyframe through its motors stands for 10 s, and Menagerie's Panda closing its gripper on a cube
lifts it.

The incline is the floor with gravity turned by θ (the same physics in the incline's axes)."""

import numpy as np
import pytest
import robodyn
from conftest import load_quietly
from test_contact_dynamics import PANDA_CUBE, panda_lift_ctrl
from test_menagerie import MENAGERIE

G = 9.81
MU = 0.5
# MuJoCo's friction is soft: a sliding crate feels slightly less or more than μN (measured, both in
# MuJoCo 4.0 and here, on this flat crate at 1.1 and 1.5 atan μ: within 3.8 % of Coulomb's a).
SLIDING_AGREEMENT = 0.05
# Below atan μ soft friction lets a crate creep: measured below 1e-9 m/s² after the first 0.5 s.
STICKING_ACCELERATION = 1e-6
# A rolling ball: a = 5/7 g sin θ (measured 0.10 % below), its contact point at rest but for a slip
# of 0.1 % of its speed (measured): soft friction lets it creep.
ROLLING_AGREEMENT = 2e-3


def tilted(body, theta, cone="elliptic"):
    """A floor of friction MU with gravity turned by `theta` about y (the incline's axes) and
    `body` (an MJCF body) on it."""
    gravity = f"{float(G * np.sin(theta))!r} 0 {float(-G * np.cos(theta))!r}"
    return f"""<mujoco><option gravity="{gravity}" cone="{cone}"/>
      <worldbody><geom name="incline" type="plane" size="0 0 1" friction="{MU} 0.005 0.0001"/>
      {body}</worldbody></mujoco>"""


CRATE = """<body name="crate" pos="0 0 0.0199"><freejoint/>
  <geom name="crate" type="box" size="0.1 0.1 0.02" friction="0.5 0.005 0.0001"/></body>"""


def down_the_slope(run, start=0.5):
    """The crate's or ball's speed along the slope (world x; the body stays level), and its mean
    acceleration from `start` to the end."""
    speed = np.array([model_velocity(q, v) for q, v in zip(run.q, run.v)])
    first = int(np.searchsorted(run.t, start))
    return speed, (speed[-1] - speed[first]) / (run.t[-1] - run.t[first])


def model_velocity(q, v):
    """The world x velocity of a free joint's origin: R v_linear."""
    x, y, z, w = q[3:7]
    row = np.array([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)])
    return row @ v[:3]


def crate_acceleration(theta, cone):
    """The crate's mean acceleration down a slope of `theta` over its second half-second."""
    model = load_quietly(text=tilted(CRATE, theta, cone))
    run = robodyn.simulate(model, model.neutral(), t_end=1.0, dt=0.01, integrator="mujoco")
    return down_the_slope(run)[1]


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
@pytest.mark.parametrize("fraction", [0.5, 0.9])
def test_a_crate_sticks_below_the_friction_angle(cone, fraction):
    assert abs(crate_acceleration(fraction * np.arctan(MU), cone)) < STICKING_ACCELERATION


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
@pytest.mark.parametrize("fraction", [1.1, 1.5])
def test_a_crate_slides_above_the_friction_angle_as_coulomb_says(cone, fraction):
    theta = fraction * np.arctan(MU)
    expected = G * (np.sin(theta) - MU * np.cos(theta))
    assert crate_acceleration(theta, cone) == pytest.approx(expected, rel=SLIDING_AGREEMENT)


def test_a_ball_rolls_down_without_slipping():
    """A solid ball (condim 3: no rolling friction) on a 20° slope: a = 5/7 g sin θ, and its
    contact point does not move (v + ω × (−r e_z) = 0) but for soft friction's creep."""
    theta, radius = np.radians(20.0), 0.1
    ball = f"""<body name="ball" pos="0 0 {radius - 1e-4}"><freejoint/>
      <geom name="ball" type="sphere" size="{radius}" friction="{MU} 0.005 0.0001"/></body>"""
    model = load_quietly(text=tilted(ball, theta))
    run = robodyn.simulate(model, model.neutral(), t_end=1.0, dt=0.01, integrator="mujoco")
    _, acceleration = down_the_slope(run)
    assert acceleration == pytest.approx(5 / 7 * G * np.sin(theta), rel=ROLLING_AGREEMENT)
    # the contact point's velocity: v + ω × (−r e_z), all in world axes
    for q, v in zip(run.q[50:], run.v[50:]):
        x, y, z, w = q[3:7]
        rotation = np.array([
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ])
        linear, angular = rotation @ v[:3], rotation @ v[3:]
        slip = linear + np.cross(angular, [0.0, 0.0, -radius])
        assert np.linalg.norm(slip[:2]) < ROLLING_AGREEMENT * np.linalg.norm(linear)


def test_go2_held_at_home_by_its_motors_stands_for_ten_seconds():
    """Menagerie's Go2 from `home`, its twelve motors driven by a PD law toward the keyframe's joint
    angles (k_p = 200 N·m/rad, k_d = 5 N·m·s/rad, clamped to ctrlrange): the trunk stays within 1 cm
    of where it started for 10 s (5000 steps), neither falling nor walking away."""
    model = load_quietly(MENAGERIE / "unitree_go2" / "scene.xml")
    home = model.keyframe("home")
    joints, rates = slice(7, model.nq), slice(6, model.nv)
    target = np.asarray(home.q)[joints]
    low, high = model.ctrl_range[:, 0], model.ctrl_range[:, 1]

    def hold(t, q, v):
        return np.clip(200.0 * (target - q[joints]) - 5.0 * v[rates], low, high)

    run = robodyn.simulate(model, "home", t_end=10.0, dt=0.1, integrator="mujoco", ctrl=hold)
    assert run.t[-1] == pytest.approx(10.0)
    trunk = run.q[:, :3]
    assert np.max(np.linalg.norm(trunk - trunk[0], axis=1)) < 0.01
    # at rest at the end, its feet carry its weight: Σ contact forces = m g (N)
    assert np.all(np.abs(run.v[-1]) < 1e-2)
    feet = sum(run.contact_force(foot)[-1] for foot in ("FL", "FR", "RL", "RR"))
    assert feet == pytest.approx([0.0, 0.0, model.total_mass * G], abs=0.01 * model.total_mass * G)


def test_a_panda_closing_on_its_cube_lifts_it():
    """Menagerie's Panda from `pickup1` (its fingers open about the cube on the floor) closes them,
    then raises its hand 30 cm (test_contact_dynamics's panda_lift_ctrl): the cube leaves the floor,
    rises with the hand without slipping in the fingers, and at the top its finger pads alone carry
    its weight (the floor's contacts gone)."""
    model = load_quietly(MENAGERIE / PANDA_CUBE)
    start = model.keyframe("pickup1")
    run = robodyn.simulate(model, "pickup1", t_end=2.0, dt=0.05, integrator="mujoco",
                           ctrl=lambda t, q, v: panda_lift_ctrl(start.ctrl, t))
    cube = np.array([model.frame_pose(q, "box")[:3, 3] for q in run.q])
    assert cube[-1, 2] - cube[0, 2] > 0.25, "lifted"
    # held: from 1.4 s (the hand at its top) the cube keeps its place in the hand's frame: soft
    # contacts creep (MuJoCo's model lets a held object slip at a rate its regulariser sets;
    # measured 1.2 mm in these 0.6 s, 2 mm/s), a dropped cube would fall 1.8 m in that time
    top = np.flatnonzero(run.t >= 1.4)
    in_hand = np.array([np.linalg.solve(model.frame_pose(run.q[k], "hand"), model.frame_pose(run.q[k], "box"))[:3, 3]
                        for k in top])
    assert np.max(np.linalg.norm(in_hand - in_hand[0], axis=1)) < 2e-3
    # carried by the pads alone: their vertical forces add up to the cube's weight within 5 %
    floor = run.contact_force("floor")[-1]
    pads = run.contact_force("left_finger_pad")[-1] + run.contact_force("right_finger_pad")[-1]
    weight = model.body_masses[model.body_names.index("box")] * G
    assert np.allclose(floor, 0.0) and -pads[2] == pytest.approx(weight, rel=0.05)


def test_the_contact_force_plot_shows_the_weight_carried(tmp_path):
    """A crate resting on a level floor: the plot's "up" line is the floor's push on it, m g once
    settled, its "across" line zero; a run without contacts recorded, or an unknown geom, is
    refused."""
    scene = load_quietly(text=tilted(CRATE, 0.0))
    run = robodyn.simulate(scene, scene.neutral(), t_end=0.5, integrator="mujoco")
    figure = run.plot_contact_forces(path=tmp_path / "forces.png")
    assert (tmp_path / "forces.png").stat().st_size > 0
    along, across = figure.axes[:2]
    up = {line.get_label(): line.get_ydata() for line in along.get_lines()}
    weight = scene.total_mass * G
    assert set(up) == {"crate", f"m g = {weight:.4g} N"}
    assert abs(up["crate"][-1] - weight) < 1e-6 * weight
    assert np.allclose(up["crate"], run.contact_force("crate")[:, 2])
    assert np.max(np.abs(across.get_lines()[0].get_ydata())) < 1e-9 * weight
    with pytest.raises(ValueError, match="geoms"):
        run.plot_contact_forces(["nothing"])
    with pytest.raises(ValueError, match="integrator='mujoco'"):
        robodyn.plot.plot_contact_forces(robodyn.simulate(scene, scene.neutral(), t_end=0.01))
