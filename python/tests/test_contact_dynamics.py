"""Soft-constraint forward dynamics (`m.contact_forward_dynamics`) against MuJoCo's `mj_forward`:
the same constraint rows (type, id, order), contact addresses, Jacobians, regularisation R and
reference accelerations, then the same solution (row forces, accelerations, constraint forces).

MuJoCo is made to solve to convergence (Newton, tolerance 1e-15, 1000 iterations, 100 line-search
steps) with a dense constraint Jacobian. Scenes: a box on a plane (every condim, both cones, two
impratios), explicit contact pairs with their own solref/solreffriction/solimp/margin/gap, joint
limits and dof friction loss with actuators, and dm_control's suite models; equalities, tendons and
simple bodies are in test_soft_elements.py."""

import mujoco
import numpy as np
import pytest
from conftest import REPOSITORY, assert_close, load_quietly

from test_menagerie import MENAGERIE, mujoco_model

from robodyn.convert import MujocoLayout

# Jacobian, R and aref: the same formulas evaluated in another order (rounding only); entry by
# entry, relative to max(1, |value|).
ROW_AGREEMENT = 1e-12
# A contact's distance is a difference of world coordinates of order 1 m, each rounded to ~1e-16 m:
# its rounding is absolute, not relative to the distance (a Panda finger pad 6e-5 m into its cube:
# distances 1.4e-17 m apart, 2e-13 of themselves). aref's spring term k d (pos − margin) carries it
# times k d (1e4 /s² for solref 0.01): aref is also allowed k d POSITION_ROUNDING.
POSITION_ROUNDING = 1e-15
# Forces, accelerations and constraint forces, relative to max(1, max|value|). MuJoCo 4's Newton
# solver at tolerance 1e-15 is not at the optimum: it also stops on its Newton decrement ½gᵀH⁻¹g
# (the next step's predicted improvement; since MuJoCo 3.11), a step before the cost stops
# changing, leaving the gradient at ~sqrt(tolerance) (1e-6 N seen). Measured against MuJoCo at tolerance 0
# (1000 iterations: gradient M(qacc − qacc_smooth) − Jᵀf down to 1e-12): frictionless and pyramidal
# contacts, limits and friction loss (piecewise quadratic: Newton ends exact) agree to 4.4e-13;
# elliptic contacts with friction do not: on this file's states forces differ by up to 8.5e-9 and
# qacc by 1.1e-9 (box, condim 6, moving); over 40 random velocities per box/pair scene, forces by
# up to 1.7e-7 (box, condim 4), qacc by 5.6e-9. 1e-7 holds a solver that stops where MuJoCo does
# (same iterates to rounding) or one that goes on to the optimum, on these states.
FORCE_AGREEMENT = 1e-7

#: MuJoCo's mjtConstraint names, lower-cased without the prefix: 6 -> "contact_pyramidal".
ROW_TYPES = {int(v): k.removeprefix("mjCNSTR_").lower() for k, v in mujoco.mjtConstraint.__members__.items()}


def converged(mj_model, tolerance=1e-15, iterations=1000):
    """`mj_model` set to solve to convergence with a dense efc_J (returned)."""
    mj_model.opt.solver = mujoco.mjtSolver.mjSOL_NEWTON
    mj_model.opt.tolerance, mj_model.opt.iterations, mj_model.opt.ls_iterations = tolerance, iterations, 100
    mj_model.opt.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
    return mj_model


def load_both(text=None, path=None):
    """(robodyn model, converged MuJoCo model, layout) of an MJCF string or file."""
    model = load_quietly(path, text)
    mj_model = mujoco.MjModel.from_xml_string(text) if path is None else mujoco.MjModel.from_xml_path(str(path))
    return model, converged(mj_model), MujocoLayout(model, mj_model)


def mujoco_solution(mj_model, layout, qpos, qvel, tau=None, ctrl=None):
    """(q, v, MuJoCo's mj_forward in robodyn's coordinates and in the method's dict layout;
    `contacts` as (geom1, geom2, first_row, dim) tuples)."""
    d = mujoco.MjData(mj_model)
    d.qpos[:], d.qvel[:] = qpos, qvel
    q = layout.q_from_mujoco(d.qpos)
    v = layout.v_from_mujoco(q, d.qvel)
    if tau is not None:
        d.qfrc_applied[:] = layout.force_to_mujoco(q, tau)
    if ctrl is not None:
        d.ctrl[:] = ctrl
    mujoco.mj_forward(mj_model, d)
    nefc, nv = d.nefc, mj_model.nv
    name = lambda g: mj_model.geom(int(g)).name
    contact_forces = []
    for i in range(d.ncon):
        force = np.zeros(6)
        mujoco.mj_contactForce(mj_model, d, i, force)
        contact_forces.append(force)
    return q, v, {
        "contact_forces": np.array(contact_forces).reshape(d.ncon, 6),
        "qdd": layout.a_from_mujoco(q, v, d.qacc),
        "forces": d.efc_force.copy(),
        "row_types": [ROW_TYPES[int(t)] for t in d.efc_type],
        "row_ids": d.efc_id.copy(),
        "jacobian": layout.jacobian_from_mujoco(q, d.efc_J[: nefc * nv].reshape(nefc, nv)),
        "R": d.efc_R.copy(),
        "aref": d.efc_aref.copy(),
        "aref_rounding": d.efc_KBIP[:nefc, 0] * d.efc_KBIP[:nefc, 2] * POSITION_ROUNDING,
        "contacts": [(name(c.geom[0]), name(c.geom[1]), int(c.efc_address), int(c.dim)) for c in d.contact[: d.ncon]],
        "tau_actuator": layout.force_from_mujoco(q, d.qfrc_actuator),
        "tau_constraint": layout.force_from_mujoco(q, d.qfrc_constraint),
    }


def contact_dynamics(model, q, v, tau=None, ctrl=None):
    """robodyn's answer (one place, so that a scratch run can stand MuJoCo in for it)."""
    return model.contact_forward_dynamics(q, v, tau=tau, ctrl=ctrl)


def assert_entries_close(actual, expected, tolerance, label):
    """|actual - expected| <= tolerance * max(1, |expected|), entry by entry."""
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    assert actual.shape == expected.shape, f"{label}: shape {actual.shape} vs {expected.shape}"
    excess = np.abs(actual - expected) - tolerance * np.maximum(1.0, np.abs(expected))
    assert not np.any(excess > 0), f"{label}: entries {np.argwhere(excess > 0).ravel()[:6]} off by up to {np.max(np.abs(actual - expected)):.3e}"


def assert_matches_mujoco(model, mj_model, layout, qpos, qvel, tau=None, ctrl=None, label="", row_agreement=ROW_AGREEMENT):
    """robodyn's solution at MuJoCo's (qpos, qvel) is MuJoCo's, row by row (Jacobian, R and aref to
    `row_agreement`); returns both."""
    q, v, expected = mujoco_solution(mj_model, layout, qpos, qvel, tau, ctrl)
    ours = contact_dynamics(model, q, v, tau=tau, ctrl=ctrl)
    assert list(ours["row_types"]) == expected["row_types"], label
    assert list(ours["row_ids"]) == list(expected["row_ids"]), label
    found = [(c["geom1"], c["geom2"], c["first_row"], c["dim"]) for c in ours["contacts"]]
    assert found == expected["contacts"], label
    for key in ("jacobian", "R"):
        assert_entries_close(ours[key], expected[key], row_agreement, f"{label} {key}")
    aref, expected_aref = np.asarray(ours["aref"]), expected["aref"]
    assert aref.shape == expected_aref.shape, label
    allowed = row_agreement * np.maximum(1.0, np.abs(expected_aref)) + expected["aref_rounding"]
    assert np.all(np.abs(aref - expected_aref) <= allowed), f"{label} aref: off by up to {np.max(np.abs(aref - expected_aref)):.3e}"
    assert_close(ours["tau_actuator"], expected["tau_actuator"], row_agreement, f"{label} tau_actuator")
    for key in ("forces", "qdd", "tau_constraint"):
        assert_close(ours[key], expected[key], FORCE_AGREEMENT, f"{label} {key}")
    # each contact's force in its frame: MuJoCo's mj_contactForce
    forces = np.array([c["force"] for c in ours["contacts"]]).reshape(-1, 6)
    assert_close(forces, expected["contact_forces"], FORCE_AGREEMENT, f"{label} contact forces")
    return ours, expected


# --- 1. a box on a plane ----------------------------------------------------------------------


def box_scene(condim=3, cone="pyramidal", impratio=1, depth=0.001):
    """A 0.2 m cube (8 kg) `depth` into a plane: four corner contacts of `condim` (set on both
    geoms: a contact takes the larger of the two)."""
    return f"""<mujoco><option cone="{cone}" impratio="{impratio}"/>
      <default><geom condim="{condim}"/></default>
      <worldbody><geom name="floor" type="plane" size="0 0 1"/>
        <body name="box" pos="0 0 {0.1 - depth!r}"><freejoint name="box"/><geom name="box" type="box" size="0.1 0.1 0.1"/></body>
      </worldbody></mujoco>"""


@pytest.mark.parametrize("moving", [False, True], ids=["at_rest", "moving"])
@pytest.mark.parametrize("impratio", [1, 10])
@pytest.mark.parametrize("condim", [1, 3, 4, 6])
@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_box_on_a_plane_as_in_mujoco(cone, condim, impratio, moving):
    model, mj_model, layout = load_both(box_scene(condim, cone, impratio))
    rng = np.random.default_rng(condim + 10 * impratio)
    for case in range(3 if moving else 1):
        qvel = rng.normal(size=6) * 0.5 if moving else np.zeros(6)
        tau = rng.normal(size=6) * 5 if moving else None
        _, expected = assert_matches_mujoco(model, mj_model, layout, mj_model.qpos0, qvel, tau=tau, label=f"case {case}")
        assert len(expected["contacts"]) == 4 and all(dim == condim for *_, dim in expected["contacts"])


def rest_depth(g=9.81, timeconst=0.02, dampratio=1.0, solimp=(0.9, 0.95, 0.001, 0.5, 2.0)):
    """The overlap at which a soft contact (MuJoCo's documented model, default solref/solimp)
    carries its share of a free body's weight with no motion: f = aref / R per contact, with
    aref = k·imp·d, R = (1 − imp)/imp · (1/m) (A's diagonal: one body's 1/m) and f = m·g/4, so
    k·imp(d)²·d / (1 − imp(d)) = g/4, k = 1/(d_max²·timeconst²·dampratio²)."""
    d0, dmax, width, mid, power = solimp
    k = 1.0 / (dmax**2 * timeconst**2 * dampratio**2)

    def imp(d):
        x = min(d / width, 1.0)
        y = x**power / mid ** (power - 1) if x <= mid else 1 - (1 - x) ** power / (1 - mid) ** (power - 1)
        return d0 + y * (dmax - d0)

    low, high = 0.0, width
    for _ in range(200):  # bisection: the left side grows with d
        d = 0.5 * (low + high)
        low, high = (d, high) if k * imp(d) ** 2 * d / (1 - imp(d)) < g / 4 else (low, d)
    return 0.5 * (low + high)


def normal_forces(result):
    """Each contact's normal force: its first row (elliptic, frictionless), or the sum of its
    2(dim − 1) pyramid edges' forces (pyramidal)."""
    forces, types = np.asarray(result["forces"]), result["row_types"]
    totals = []
    for contact in result["contacts"]:
        first, dim = contact["first_row"], contact["dim"]
        if types[first] == "contact_pyramidal":
            totals.append(forces[first : first + 2 * (dim - 1)].sum())
        else:
            totals.append(forces[first])
    return np.array(totals)


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_a_box_at_rest_is_carried_by_its_contacts(cone):
    """Newton's law and the soft contact's rest depth, without MuJoCo. A soft contact pushes in
    proportion to how far the box overlaps the plane (a spring k·imp·d, impedance imp < 1): at
    1 mm in, the four contacts push harder than the weight and the box is pushed out (≈ +2.5 m/s²:
    checked only in sign here); the sum of the normal forces is always m (g + a_z) and the
    sideways and turning accelerations vanish by symmetry. At the depth where the springs carry
    m·g exactly (0.108 mm for the default solref/solimp, `rest_depth`) the box rests: qdd = 0 to
    rounding (MuJoCo: 3e-15) — a soft contact holds a body only by its overlap, so a body set on
    the plane sinks into it until it reaches that depth (and, dropped deeper, is pushed back)."""
    for depth in (0.001, rest_depth()):
        model = load_quietly(text=box_scene(3, cone, depth=depth))
        mass, g = model.total_mass, -model.gravity[2]
        result = contact_dynamics(model, model.neutral(), np.zeros(6))
        qdd = np.asarray(result["qdd"])  # the box is upright and at rest: qdd[:3] is world-frame
        assert len(result["contacts"]) == 4
        assert normal_forces(result).sum() == pytest.approx(mass * (g + qdd[2]), rel=1e-6)
        np.testing.assert_allclose(qdd[[0, 1, 3, 4, 5]], 0, atol=1e-9)
        if depth == 0.001:
            assert qdd[2] > 1.0
        else:
            assert normal_forces(result).sum() == pytest.approx(mass * g, rel=1e-6)
            np.testing.assert_allclose(qdd, 0, atol=1e-9)


# --- 2. explicit pairs: solref, solreffriction, solimp, margin and gap --------------------------

PAIRS = """<mujoco><option cone="{cone}"/>
  <worldbody>
    <geom name="floor" type="plane" size="0 0 1"/>
    <body name="ball" pos="0 0 0.095"><freejoint name="ball"/><geom name="ball" size="0.1" contype="0" conaffinity="0"/></body>
    <body name="rod" pos="1 0 0.048" quat="0.70710678 0 0.70710678 0"><freejoint name="rod"/>
      <geom name="rod" type="capsule" size="0.05 0.2" condim="4" solimp="0.8 0.95 0.002 0.4 3"/></body>
    <body name="hover" pos="2 0 0.12"><freejoint name="hover"/><geom name="hover" size="0.1" contype="0" conaffinity="0"/></body>
    <body name="gap" pos="3 0 0.17"><freejoint name="gap"/><geom name="gap" size="0.1" contype="0" conaffinity="0"/></body>
  </worldbody>
  <contact>
    <pair name="ball_floor" geom1="ball" geom2="floor" condim="6" solref="-9000 -70" solreffriction="0.03 1.2"/>
    <pair name="hover_floor" geom1="hover" geom2="floor" margin="0.06" gap="0.02"/>
    <pair name="gap_floor" geom1="gap" geom2="floor" margin="0.06" gap="0.02"/>
  </contact>
</mujoco>"""


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_contact_pairs_and_their_parameters_as_in_mujoco(cone):
    """A ball 5 mm in on a pair with direct stiffness/damping (solref < 0), its own friction
    solref and condim 6; a capsule lying flat (two contacts, condim 4, its solimp averaged with
    the floor's as MuJoCo mixes two geoms'); a ball 2 cm above the floor, within the pair's margin
    6 cm (rows before it touches, its distance counted from the margin); one 7 cm above, in the
    gap band: MuJoCo 4's margin < distance < margin + gap (since 3.9.0; before, gap was taken off
    the margin), a contact without rows (first_row −1)."""
    model, mj_model, layout = load_both(PAIRS.format(cone=cone))
    rng = np.random.default_rng(2)
    for case in range(4):
        qvel = np.zeros(mj_model.nv) if case == 0 else rng.normal(size=mj_model.nv) * 0.5
        _, expected = assert_matches_mujoco(model, mj_model, layout, mj_model.qpos0, qvel, label=f"case {case}")
        first_rows = {geom2: first for geom1, geom2, first, _ in expected["contacts"]}
        assert sorted(geom2 for _, geom2, *_ in expected["contacts"]) == ["ball", "gap", "hover", "rod", "rod"]
        assert first_rows["gap"] == -1 and first_rows["hover"] >= 0


# --- 3. joint limits, dof friction loss and actuators -----------------------------------------

ARM = """<mujoco><compiler angle="radian"/>
  <default><geom contype="0" conaffinity="0"/></default>
  <worldbody>
    <body name="cart" pos="0 0 1">
      <joint name="slide" type="slide" axis="1 0 0" limited="true" range="-0.2 0.2" solreflimit="-5000 -30"/>
      <geom name="cart" type="box" size="0.1 0.1 0.05"/>
      <body name="upper">
        <joint name="shoulder" axis="0 1 0" limited="true" range="-1 1" frictionloss="0.8"/>
        <geom name="upper" type="capsule" fromto="0 0 0 0.4 0 0" size="0.03"/>
        <body name="fore" pos="0.4 0 0">
          <joint name="elbow" axis="0 1 0" limited="true" range="-1.5 0.5" margin="0.05" frictionloss="0.3"/>
          <geom name="fore" type="capsule" fromto="0 0 0 0.3 0 0" size="0.025"/>
          <body name="hand" pos="0.3 0 0">
            <joint name="wrist" axis="0 1 0" limited="true" range="-2 2"/>
            <geom name="hand" type="sphere" size="0.04" pos="0.05 0 0"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="push" joint="slide" gear="2"/>
    <position name="hold" joint="wrist" kp="30"/>
  </actuator>
</mujoco>"""


def test_joint_limits_friction_loss_and_actuators_as_in_mujoco():
    """The slide 1 cm past its lower limit (direct solreflimit), the shoulder past its upper
    limit, the elbow 0.03 rad inside its 0.05 rad margin of the lower, the wrist within its range
    (no row); friction loss on the shoulder and elbow; a motor and a position actuator driven."""
    model, mj_model, layout = load_both(ARM)
    qpos = np.array([-0.21, 1.05, -1.47, 0.3])
    rng = np.random.default_rng(3)
    for case in range(4):
        qvel = np.zeros(4) if case == 0 else rng.normal(size=4)
        ctrl, tau = rng.uniform(-2, 2, size=2), rng.normal(size=4)
        _, expected = assert_matches_mujoco(model, mj_model, layout, qpos, qvel, tau=tau, ctrl=ctrl, label=f"case {case}")
        assert expected["row_types"] == ["friction_dof"] * 2 + ["limit_joint"] * 3
        assert list(expected["row_ids"]) == [1, 2, 0, 1, 2]


# --- 4. dm_control's suite -------------------------------------------------------------------

# Of the suite's 16 models (test_collision.py's SUITE), those with contacts and constraints:
# ball_in_cup's string is a spatial tendon with a limit; manipulator, point_mass and stacker drive
# fixed tendons, manipulator and stacker couple two fingers by a tendon equality; quadruped's twelve actuators
# filter their controls (activation dynamics) and its height field lies flat 1 cm below its floor;
# none has a limited ball joint.
SUITE = ["ball_in_cup", "cheetah", "finger", "hopper", "humanoid", "humanoid_CMU", "manipulator", "point_mass", "quadruped",
         "stacker", "walker"]
# The rest disable constraints (acrobot, fish: <flag constraint="disable"/>) or contacts (cartpole,
# reacher, swimmer: contact="disable"): MuJoCo finds no contacts at all there (an empty
# d.contact; cartpole and reacher would have 3–7 otherwise), nor limit rows in acrobot; fish's
# tendon spring and tendon actuators still act.
FLAGGED = ["acrobot", "cartpole", "fish", "reacher", "swimmer"]
SUITE_STATES = 5


def without_unmodelled(mj_model):
    """What robodyn does not model, switched off in MuJoCo: the medium's forces (swimmer's
    density)."""
    mj_model.opt.density = mj_model.opt.viscosity = 0.0


def root_height_address(mj_model):
    """qpos address of the root's height (a free joint's z or a slide named rootz), or None."""
    for j in range(mj_model.njnt):
        if mj_model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            return int(mj_model.jnt_qposadr[j]) + 2
        if mj_model.joint(j).name == "rootz":
            return int(mj_model.jnt_qposadr[j])
    return None


def random_suite_state(mj_model, rng):
    """qpos0 turned at random (0.3 rad or m per dof, as test_collision.py), lowered 2 cm at a time
    until something touches where the model has a root height; random qvel."""
    qpos = mj_model.qpos0.copy()
    mujoco.mj_integratePos(mj_model, qpos, rng.normal(size=mj_model.nv) * 0.3, 1.0)
    height, d = root_height_address(mj_model), mujoco.MjData(mj_model)
    for _ in range(200 if height is not None else 0):
        d.qpos[:] = qpos
        mujoco.mj_kinematics(mj_model, d)
        mujoco.mj_collision(mj_model, d)
        if d.ncon:
            break
        qpos[height] -= 0.02
    return qpos, rng.normal(size=mj_model.nv)


def check_suite_model(name):
    """SUITE_STATES random states of a suite model, with random tau and controls (past ±1: the
    clamped controls too), against MuJoCo; the largest number of rows seen."""
    model, mj_model, layout = load_both(path=REPOSITORY / "testdata" / "dm_control" / f"{name}.xml")
    without_unmodelled(mj_model)
    rng, rows = np.random.default_rng(4), 0
    for case in range(SUITE_STATES):
        qpos, qvel = random_suite_state(mj_model, rng)
        ctrl, tau = rng.uniform(-1.2, 1.2, size=mj_model.nu), rng.normal(size=mj_model.nv)
        _, expected = assert_matches_mujoco(model, mj_model, layout, qpos, qvel, tau, ctrl, label=f"{name} case {case}")
        rows = max(rows, len(expected["forces"]))
    return rows


@pytest.mark.parametrize("name", SUITE)
def test_dm_control_models_as_in_mujoco(name):
    assert check_suite_model(name) > 0


@pytest.mark.parametrize("name", FLAGGED)
def test_dm_control_flags_as_in_mujoco(name):
    """What MuJoCo's <flag> switches off has no rows and no contacts."""
    assert check_suite_model(name) == 0


# --- 5. a Menagerie quadruped on its floor ------------------------------------------------------


@pytest.mark.parametrize("cone", ["elliptic", "pyramidal"])
def test_go2_standing_at_home_as_in_mujoco(cone, tmp_path):
    """Menagerie's Unitree Go2 on its scene's floor at its `home` keyframe (its file's elliptic
    cone, impratio 100, condim-6 feet of their own solimp and priority, condim-1 shins, dry
    friction on every joint), at rest and moving, its motors driven; and the same with a
    pyramidal cone (a copy of the files). Its visual meshes are left out
    (testdata/menagerie/README.md)."""
    folder = MENAGERIE / "unitree_go2"
    if cone == "pyramidal":
        for name in ("go2.xml", "scene.xml"):
            text = (folder / name).read_text()
            (tmp_path / name).write_text(text.replace('cone="elliptic"', 'cone="pyramidal"'))
        folder = tmp_path
    path = folder / "scene.xml"
    model, mj_model = load_quietly(path), converged(mujoco_model(path, "unitree_go2/scene.xml"))
    assert model.options.cone == cone
    layout = MujocoLayout(model, mj_model)
    home = mj_model.key("home")
    rng = np.random.default_rng(6)
    for case in range(3):
        qvel = np.zeros(mj_model.nv) if case == 0 else rng.normal(size=mj_model.nv) * 0.3
        _, expected = assert_matches_mujoco(model, mj_model, layout, home.qpos, qvel, ctrl=home.ctrl, label=f"case {case}")
        assert sum(geom2 in ("FL", "FR", "RL", "RR") for _, geom2, *_ in expected["contacts"]) == 4


PANDA_CUBE = "franka_emika_panda/mjx_single_cube.xml"


def panda_lift_ctrl(start, t):
    """The Panda's controls at time t from its `pickup1` keyframe's (`start`): the gripper open, closed
    from 0.1 s, then from 0.6 s the shoulder (joint 2) and elbow (joint 4) turned over 0.8 s to
    raise the hand 30 cm."""
    ctrl = np.array(start, dtype=float)
    ctrl[7] = 0.0 if t > 0.1 else 0.04
    if t > 0.6:
        s = min(1.0, (t - 0.6) / 0.8)
        ctrl[1] -= 0.35 * s
        ctrl[3] += 0.2 * s
    return ctrl


def panda_holding_the_cube(mj_model):
    """(qpos, qvel, ctrl) of the Panda with the cube lifted in its fingers: MuJoCo's own run of
    `panda_lift_ctrl` from `pickup1` for 1.2 s (its file's solver settings)."""
    d = mujoco.MjData(mj_model)
    key = mj_model.key("pickup1")
    mujoco.mj_resetDataKeyframe(mj_model, d, key.id)
    while d.time < 1.2:
        d.ctrl[:] = panda_lift_ctrl(key.ctrl, d.time)
        mujoco.mj_step(mj_model, d)
    return d.qpos.copy(), d.qvel.copy(), d.ctrl.copy()


@pytest.mark.parametrize("cone", ["elliptic", "pyramidal"])
def test_a_panda_holding_a_cube_as_in_mujoco(cone, tmp_path):
    """Menagerie's Franka Panda (its MJX scene: box and capsule colliders, the fingers coupled by a
    joint equality, position actuators) holding its cube 15 cm over the floor, only its finger pads
    touching it; and at its three keyframes (the cube on the floor). Visual meshes left out
    (testdata/menagerie/README.md)."""
    folder = MENAGERIE / "franka_emika_panda"
    for name in ("mjx_panda.xml", "mjx_scene.xml", "mjx_single_cube.xml"):
        text = (folder / name).read_text()
        (tmp_path / name).write_text(text.replace('<option timestep="0.005"', f'<option cone="{cone}" timestep="0.005"'))
    path = tmp_path / "mjx_single_cube.xml"
    model, mj_model = load_quietly(path), mujoco_model(path, PANDA_CUBE)
    qpos, qvel, ctrl = panda_holding_the_cube(mj_model)
    converged(mj_model)
    layout = MujocoLayout(model, mj_model)
    _, expected = assert_matches_mujoco(model, mj_model, layout, qpos, qvel, ctrl=ctrl, label="holding")
    touching = {(geom1, geom2) for geom1, geom2, first, _ in expected["contacts"] if first >= 0}
    assert touching == {("left_finger_pad", "box"), ("right_finger_pad", "box")}, touching
    assert expected["row_types"][0] == "equality"
    for key in range(mj_model.nkey):
        assert_matches_mujoco(model, mj_model, layout, mj_model.key_qpos[key], mj_model.key_qvel[key],
                              ctrl=mj_model.key_ctrl[key], label=f"keyframe {key}")


# --- 9. what is refused ---------------------------------------------------------------------


def test_bad_input_is_refused_naming_it():
    """Arguments of the wrong size, and what the method does not model yet: an active equality
    constraint (MuJoCo's soft equality rows)."""
    model = load_quietly(text=box_scene())
    q, v = model.neutral(), np.zeros(model.nv)
    with pytest.raises(ValueError, match="argument 'tau'"):
        model.contact_forward_dynamics(q, v, tau=np.zeros(5))
    with pytest.raises(ValueError, match="argument 'ctrl'"):
        model.contact_forward_dynamics(q, v, ctrl=np.zeros(2))
    with pytest.raises(ValueError, match="argument 'v'"):
        model.contact_forward_dynamics(q, np.zeros(7))


BALL = """<mujoco><compiler angle="degree"/>
  <worldbody><body name="bob" pos="0 0 1">
    <joint name="socket" type="ball" range="0 {limit}" margin="0.05"/>
    <geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05"/>
  </body></worldbody></mujoco>"""


@pytest.mark.parametrize("limit", [30, 37, 60])
def test_ball_joint_cone_limit_as_in_mujoco(limit):
    """A ball joint turned 35° about a tilted axis: past a 30° cone, within the 0.05 rad margin
    of a 37° one (a row before it is reached), inside a 60° one (no row); MuJoCo's row is −u on
    the ball's three velocities, its position the cone's angle less the rotation's."""
    model, mj_model, layout = load_both(BALL.format(limit=limit))
    axis = np.array([1.0, 2.0, 0.5]) / np.linalg.norm([1.0, 2.0, 0.5])
    half = np.radians(35) / 2
    qpos = np.array([np.cos(half), *(np.sin(half) * axis)])
    rng = np.random.default_rng(5)
    for case in range(3):
        qvel = rng.normal(size=3)
        _, expected = assert_matches_mujoco(model, mj_model, layout, qpos, qvel, tau=rng.normal(size=3), label=f"case {case}")
        assert expected["row_types"] == ([] if limit == 60 else ["limit_joint"])
