"""The Python API contract: names, shapes, batching, array-likes, the bundled models and the CLI."""

from __future__ import annotations

import subprocess
import sys
import threading

import numpy as np
import pytest
from conftest import IDENTITY_TOLERANCE, assert_close

import robodyn


@pytest.fixture(scope="module")
def ur5():
    return robodyn.load("ur5")


@pytest.fixture(scope="module")
def floating(robots_dir):
    """Solo12, a quadruped with a floating base (the UR5's massless base link makes a floating UR5
    singular)."""
    return robodyn.load(robots_dir / "solo_description/robots/solo12.urdf", floating_base=True)


def test_bundled_models():
    assert robodyn.models() == ["ur5", "planar2", "pendulum"]
    for name in robodyn.models():
        model = robodyn.load(name)
        assert model.nq == model.nv == len(model.joint_names)
    assert list(robodyn.load("planar2").gravity) == [0.0, -9.81, 0.0]
    assert list(robodyn.load("ur5").gravity) == [0.0, 0.0, -9.81]


def test_model_description(ur5):
    floating = robodyn.load("ur5", floating_base=True)
    assert (ur5.nq, ur5.nv) == (6, 6)
    assert ur5.joint_names[0] == "shoulder_pan_joint"
    assert ur5.joint_idx_q == ur5.joint_idx_v == list(range(6))
    assert ur5.joint_types == ["revolute"] * 6
    assert "tool0" in ur5.frame_names and "base_link" in ur5.frame_names
    assert ur5.body_names[0] == "shoulder_link"
    assert ur5.total_mass == pytest.approx(3.7 + 8.393 + 2.275 + 1.219 + 1.219 + 0.1879)
    assert ur5.lower_position_limit.shape == (6,) and ur5.effort_limit[0] == 150.0
    assert (floating.nq, floating.nv) == (13, 12)
    assert floating.joint_names[0] == "root_joint" and floating.joint_types[0] == "free"
    assert floating.joint_idx_q[:2] == [0, 7] and floating.joint_idx_v[:2] == [0, 6]
    assert "nq=6" in repr(ur5)
    np.testing.assert_array_equal(floating.neutral()[:7], [0, 0, 0, 0, 0, 0, 1])


def test_issue_example(ur5, robots_dir):
    talos = robodyn.load("talos_full_v2.urdf", floating_base=True)
    assert talos.nv == 50
    for m in (ur5, talos):
        q, v, a = m.random_configuration(), np.ones(m.nv), np.zeros(m.nv)
        tau = m.inverse_dynamics(q, v, a)
        mass = m.mass_matrix(q)
        assert mass.shape == (m.nv, m.nv)
        assert_close(m.forward_dynamics(q, v, tau), a, IDENTITY_TOLERANCE)
        states = np.stack([m.random_configuration() for _ in range(200)])
        assert m.generalized_gravity(states).shape == (200, m.nv)


def test_shapes_and_dtypes(floating):
    m = floating
    q = m.random_configuration(seed=1)
    v = np.linspace(-1, 1, m.nv)
    frame = m.frame_names[-1]
    expected = {
        "inverse_dynamics": ((q, v, v), (m.nv,)),
        "forward_dynamics": ((q, v, v), (m.nv,)),
        "bias_forces": ((q, v), (m.nv,)),
        "generalized_gravity": ((q,), (m.nv,)),
        "mass_matrix": ((q,), (m.nv, m.nv)),
        "inverse_mass_matrix": ((q,), (m.nv, m.nv)),
        "center_of_mass": ((q,), (3,)),
        "center_of_mass_jacobian": ((q,), (3, m.nv)),
        "frame_pose": ((q, frame), (4, 4)),
        "jacobian": ((q, frame), (6, m.nv)),
        "frame_velocity": ((q, v, frame), (6,)),
        "jacobian_time_variation": ((q, v, frame), (6, m.nv)),
        "frame_acceleration": ((q, v, v, frame), (6,)),
        "integrate": ((q, v), (m.nq,)),
        "difference": ((q, q), (m.nv,)),
    }
    for name, (args, shape) in expected.items():
        result = getattr(m, name)(*args)
        assert result.shape == shape and result.dtype == np.float64, name
    assert isinstance(m.kinetic_energy(q, v), float)
    assert isinstance(m.potential_energy(q), float)


def batch_of_states(m, n: int, seed: int):
    """n random (q, v, a, f_ext) and the model's last frame."""
    q = m.random_configuration(n=n, seed=seed)
    rng = np.random.default_rng(seed)
    v, a = rng.uniform(-1, 1, (n, m.nv)), rng.uniform(-1, 1, (n, m.nv))
    f_ext = rng.uniform(-1, 1, (n, len(m.body_names), 6))
    return q, v, a, f_ext, m.frame_names[-1]


def test_batches_equal_the_loop_bit_for_bit(floating):
    m = floating
    n = 64
    q, v, a, f_ext, frame = batch_of_states(m, n, seed=3)
    calls = {
        "inverse_dynamics": (q, v, a),
        "forward_dynamics": (q, v, a),
        "bias_forces": (q, v),
        "generalized_gravity": (q,),
        "mass_matrix": (q,),
        "inverse_mass_matrix": (q,),
        "kinetic_energy": (q, v),
        "potential_energy": (q,),
        "center_of_mass": (q,),
        "center_of_mass_jacobian": (q,),
        "integrate": (q, v),
    }
    for name, args in calls.items():
        batch = getattr(m, name)(*args)
        loop = np.stack([np.asarray(getattr(m, name)(*(x[k] for x in args))) for k in range(n)])
        assert batch.shape == loop.shape, name
        np.testing.assert_array_equal(batch, loop, err_msg=name)
    for reference in ("world", "local", "spatial"):
        batch = m.jacobian(q, frame, reference)
        loop = np.stack([m.jacobian(x, frame, reference) for x in q])
        np.testing.assert_array_equal(batch, loop, err_msg=reference)
    batch = m.frame_pose(q, frame)
    np.testing.assert_array_equal(batch, np.stack([m.frame_pose(x, frame) for x in q]))
    batch = m.frame_acceleration(q, v, a, frame)
    np.testing.assert_array_equal(batch, np.stack([m.frame_acceleration(q[k], v[k], a[k], frame) for k in range(n)]))
    batch = m.frame_velocity(q, v, frame, "spatial")
    np.testing.assert_array_equal(batch, np.stack([m.frame_velocity(q[k], v[k], frame, "spatial") for k in range(n)]))
    batch = m.inverse_dynamics(q, v, a, f_ext=f_ext)
    np.testing.assert_array_equal(batch, np.stack([m.inverse_dynamics(q[k], v[k], a[k], f_ext=f_ext[k]) for k in range(n)]))


def calls_taking_out(q, v, a, f_ext, frame):
    """The methods that take `out=`, each with its arguments and options."""
    return {
        "inverse_dynamics": ((q, v, a), {}),
        "forward_dynamics": ((q, v, a), {"f_ext": f_ext}),
        "bias_forces": ((q, v), {}),
        "generalized_gravity": ((q,), {}),
        "mass_matrix": ((q,), {}),
        "frame_pose": ((q, frame), {}),
        "jacobian": ((q, frame), {"reference": "local"}),
    }


def test_results_can_be_written_into_a_given_array(floating):
    """`out=`: the result written into the caller's array, which is returned; single and batch,
    equal to the plain call bit for bit; a wrong array is refused, naming `out`."""
    m, n = floating, 8
    q, v, a, f_ext, frame = batch_of_states(m, n, seed=4)
    for name, (args, options) in calls_taking_out(q, v, a, f_ext, frame).items():
        method = getattr(m, name)
        for batch in (True, False):
            call_args = args if batch else tuple(x[0] if isinstance(x, np.ndarray) else x for x in args)
            call_options = options if batch else {k: x[0] if isinstance(x, np.ndarray) else x for k, x in options.items()}
            expected = method(*call_args, **call_options)
            out = np.full_like(expected, np.nan)
            returned = method(*call_args, **call_options, out=out)
            assert returned is out, name
            np.testing.assert_array_equal(out, expected, err_msg=f"{name} (batch: {batch})")
    tau = m.inverse_dynamics(q[0], v[0], a[0])
    for wrong, message in [
        (np.zeros(m.nv + 1), r"argument 'out': expected shape \(%d,\), got \(%d,\)" % (m.nv, m.nv + 1)),
        (np.zeros(m.nv, dtype=np.float32), "argument 'out': expected a float64 NumPy array of shape .* got an array of dtype float32"),
        ([0.0] * m.nv, "argument 'out': expected a float64 NumPy array .* got list"),
        (np.zeros((m.nv, 2))[:, 0], "argument 'out': expected a C-contiguous array"),
        (np.zeros(m.nv).view(), None),
        (a[0], "argument 'out': shares memory with argument 'a'"),
    ]:
        if message is None:
            wrong.flags.writeable = False
            message = "argument 'out': expected a writeable array"
        with pytest.raises(ValueError, match=message):
            m.inverse_dynamics(q[0], v[0], a[0], out=wrong)
    with pytest.raises(ValueError, match=r"argument 'out': expected shape \(8, %d\)" % m.nv):
        m.inverse_dynamics(q, v, a, out=np.zeros(m.nv))
    np.testing.assert_array_equal(m.inverse_dynamics(q[0], v[0], a[0]), tau)


def test_new_results_hold_no_stale_memory(floating):
    """A method that can write into a caller's `out` gets a new result array that is not zeroed
    first: its kernel writes every value. A new array takes the memory of one just freed of the
    same size (NumPy's for a result up to 1 KiB, the extension's own past that), so arrays of NaN
    of both kinds are freed before each call — NumPy's, and robodyn's own results filled with
    NaN: a value the kernel left alone would come through as NaN (the Jacobian's columns of the
    other legs are zeros, as are M's entries between legs)."""
    m = floating
    q, v, a, f_ext, frame = batch_of_states(m, 1, seed=5)
    q, v, a, f_ext = q[0], v[0], a[0], f_ext[0]
    calls = calls_taking_out(q, v, a, f_ext, frame) | {
        "center_of_mass_jacobian": ((q,), {}),
        "centroidal_momentum_matrix": ((q,), {}),
        "inverse_mass_matrix": ((q,), {}),
    }
    options = [{}, {"method": "rnea"}, {"method": "jacobians"}]
    for name, (args, keywords) in calls.items():
        method = getattr(m, name)
        for extra in options if name in ("mass_matrix", "generalized_gravity") else [{}]:
            if extra.get("method") == "rnea" and name == "generalized_gravity":
                continue
            expected = method(*args, **keywords, **extra)
            assert np.isfinite(expected).all(), name
            for _ in range(8):
                stale = [np.full(expected.shape, np.nan) for _ in range(4)]
                stale += [method(*args, **keywords, **extra) for _ in range(4)]
                for array in stale:
                    array.fill(np.nan)
                del stale, array
                np.testing.assert_array_equal(method(*args, **keywords, **extra), expected, err_msg=f"{name} {extra}")


def test_large_results_are_ordinary_arrays_that_outlive_the_model(robots_dir):
    """A result past NumPy's cache of small blocks (1 KiB: Talos's 6 x 50 Jacobian, its 50 x 50
    mass matrix, its 3 x 50 x 50 derivatives, of which each is a view) lives in a buffer of the extension's: still a
    writeable, C-ordered float64 array with the values a NumPy array given as `out` receives; it
    outlives the model, and its memory goes back when it is freed (a leak of the 20 000 mass
    matrices below would hold 400 MB)."""
    import gc
    import resource

    talos = robodyn.load(robots_dir / "talos_data/robots/talos_full_v2.urdf", floating_base=True)
    q = talos.random_configuration(seed=2)
    rng = np.random.default_rng(2)
    v, a = rng.uniform(-1, 1, talos.nv), rng.uniform(-1, 1, talos.nv)
    frame = "gripper_left_fingertip_1_link"
    results = {
        "jacobian": talos.jacobian(q, frame),
        "mass_matrix": talos.mass_matrix(q),
        "dtau_dq": talos.inverse_dynamics_derivatives(q, v, a)["dtau_dq"],
    }
    assert results["jacobian"].nbytes > 1024
    for name, result in results.items():
        assert result.dtype == np.float64 and result.flags.c_contiguous and result.flags.writeable, name
        assert result.shape == {"jacobian": (6, 50)}.get(name, (50, 50)), name
        # as docs/guide/performance.md says: robodyn's memory, not the array's own
        assert not result.flags.owndata, name
        assert np.isfinite(result).all(), name
    for name in ("jacobian", "mass_matrix"):
        given = np.full_like(results[name], np.nan)
        arguments = (q, frame) if name == "jacobian" else (q,)
        np.testing.assert_array_equal(getattr(talos, name)(*arguments, out=given), results[name])
    copies = {name: result.copy() for name, result in results.items()}
    results["jacobian"][0, 0] += 1.0
    copies["jacobian"][0, 0] += 1.0
    del talos
    gc.collect()
    for name, result in results.items():
        np.testing.assert_array_equal(result, copies[name], err_msg=name)
    talos = robodyn.load(robots_dir / "talos_data/robots/talos_full_v2.urdf", floating_base=True)
    for _ in range(1000):
        talos.mass_matrix(q)
    peak_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    for _ in range(20_000):
        talos.mass_matrix(q)
    grown_mib = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - peak_kib) / 1024
    assert grown_mib < 100, f"20 000 mass matrices of 20 KB grew the peak memory by {grown_mib:.0f} MiB"


def test_crba_mass_matrix_is_exactly_symmetric(floating):
    """CRBA's M is handed to NumPy as stored, which is right only because it is mirrored."""
    q = floating.random_configuration(n=4, seed=5)
    for mass_matrix in [floating.mass_matrix(q[0]), *floating.mass_matrix(q)]:
        np.testing.assert_array_equal(mass_matrix, mass_matrix.T)
    assert_close(floating.mass_matrix(q[1]), floating.mass_matrix(q[1], method="rnea"), IDENTITY_TOLERANCE, "M")


def test_any_array_like_is_accepted(ur5):
    q = [0.1, -0.5, 1, 0, 2, 3]  # a list with ints
    expected = ur5.generalized_gravity(np.array(q, dtype=float))
    np.testing.assert_array_equal(ur5.generalized_gravity(q), expected)
    np.testing.assert_array_equal(ur5.generalized_gravity(tuple(q)), expected)
    np.testing.assert_array_equal(ur5.generalized_gravity(np.array(q, dtype=np.float32).astype(np.int64)), ur5.generalized_gravity(np.trunc(q)))
    # non-contiguous views
    wide = np.zeros((6, 2))
    wide[:, 0] = q
    np.testing.assert_array_equal(ur5.generalized_gravity(wide[:, 0]), expected)
    batch = np.asfortranarray(np.stack([q, q]))
    np.testing.assert_array_equal(ur5.generalized_gravity(batch), np.stack([expected, expected]))


class _Subclass(np.ndarray):
    """An ndarray subclass: read like any float64 array, though not by the plain array's path."""


def test_every_kind_of_float64_array_reads_the_same(ur5):
    """A plain float64 ndarray is recognised by its type and NumPy's own descriptor; a subclass,
    the other byte order, a descriptor with metadata or a 0-stride array take the general path,
    a read-only array the plain one, an unaligned one a copy: all must give the same numbers bit
    for bit."""
    q = ur5.random_configuration(seed=12)
    v = np.linspace(-1, 1, ur5.nv)
    expected = ur5.inverse_dynamics(q, v, v)
    read_only = q.copy()
    read_only.flags.writeable = False
    variants = {
        "subclass": q.view(_Subclass),
        "big-endian": q.astype(">f8"),
        "metadata": q.astype(np.dtype(np.float64, metadata={"unit": "rad"})),
        "read-only": read_only,
    }
    for name, variant in variants.items():
        assert variant.dtype == np.float64 or variant.dtype.newbyteorder("=") == np.float64, name
        np.testing.assert_array_equal(ur5.inverse_dynamics(variant, v, v), expected, err_msg=name)
        np.testing.assert_array_equal(ur5.generalized_gravity(variant), ur5.generalized_gravity(q), err_msg=name)
    constant = np.broadcast_to(np.float64(0.3), (ur5.nv,))  # stride 0: not contiguous, copied
    np.testing.assert_array_equal(ur5.generalized_gravity(constant), ur5.generalized_gravity(np.full(ur5.nv, 0.3)))
    # contiguous but one byte off an 8-byte boundary: read through a copy, never in place
    unaligned = np.zeros(8 * ur5.nq + 1, dtype=np.uint8)[1:].view(np.float64)
    unaligned[:] = q
    assert unaligned.flags.c_contiguous and not unaligned.flags.aligned
    np.testing.assert_array_equal(ur5.inverse_dynamics(unaligned, v, v), expected)
    np.testing.assert_array_equal(ur5.generalized_gravity(unaligned), ur5.generalized_gravity(q))


def test_random_configuration_respects_limits_and_seed(ur5, floating):
    q = ur5.random_configuration(n=500, seed=4)
    assert np.all(q >= ur5.lower_position_limit) and np.all(q <= ur5.upper_position_limit)
    np.testing.assert_array_equal(q, ur5.random_configuration(n=500, seed=4))
    quaternions = floating.random_configuration(n=100)[:, 3:7]
    np.testing.assert_allclose(np.linalg.norm(quaternions, axis=1), 1.0, atol=1e-12)


def test_integrate_and_difference(floating):
    q = floating.random_configuration(seed=9)
    v = np.linspace(-1, 1, floating.nv)
    q1 = floating.integrate(q, v, 0.1)
    assert_close(floating.difference(q, q1), 0.1 * v, IDENTITY_TOLERANCE)


def test_gravity_and_armature_are_settable():
    m = robodyn.load("pendulum")
    m.gravity = [0.0, 0.0, -1.62]  # the Moon
    assert m.generalized_gravity([np.pi / 2])[0] == pytest.approx(1.62)
    m.armature = [0.5]
    assert m.mass_matrix([0.0])[0, 0] == pytest.approx(1.5)
    assert m.inverse_dynamics([0.0], [0.0], [2.0])[0] == pytest.approx(3.0)
    assert m.forward_dynamics([0.0], [0.0], [3.0])[0] == pytest.approx(2.0)
    assert m.kinetic_energy([0.0], [2.0]) == pytest.approx(0.5 * 1.5 * 4)


def test_mimic_joints_are_reported_and_held():
    urdf = """<robot name="gripper"><link name="base"/><link name="left"/><link name="right"/>
      <joint name="l" type="prismatic"><parent link="base"/><child link="left"/><limit lower="0" upper="0.04" effort="1" velocity="1"/></joint>
      <joint name="r" type="prismatic"><parent link="base"/><child link="right"/><limit lower="-0.04" upper="0" effort="1" velocity="1"/>
        <mimic joint="l" multiplier="-1" offset="0"/></joint></robot>"""
    m = robodyn.load_urdf_string(urdf)
    assert m.nv == 2
    assert m.mimic_joints == [("r", "l", -1.0, 0.0)]
    # held as a coupling, which simulation holds by default
    (coupling,) = m.constraints
    assert (coupling.joint, coupling.leader, coupling.polycoef[:2]) == ("r", "l", [0.0, -1.0])
    inertial = '<inertial><mass value="0.1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial>'
    massive = urdf.replace('<link name="left"/>', f'<link name="left">{inertial}</link>')
    m = robodyn.load_urdf_string(massive.replace('<link name="right"/>', f'<link name="right">{inertial}</link>'))
    run = robodyn.simulate(m, [0.01, -0.01], [0.2, -0.2], t_end=0.1, dt=1e-3)
    assert np.max(np.abs(run.q[:, 1] + run.q[:, 0])) < 1e-12
    # a prismatic joint mimicking a revolute one is held too (a rack and pinion)
    mixed = urdf.replace('<joint name="l" type="prismatic">', '<joint name="l" type="revolute"><axis xyz="0 0 1"/>')
    m = robodyn.load_urdf_string(mixed)
    assert m.warnings == [] and m.mimic_joints == [("r", "l", -1.0, 0.0)]
    (coupling,) = m.constraints
    assert (coupling.joint, coupling.leader, coupling.polycoef[:2]) == ("r", "l", [0.0, -1.0])
    # a spherical joint (four coordinates) cannot lead a coupling: reported, not held, warned
    spherical = urdf.replace('<joint name="l" type="prismatic">', '<joint name="l" type="spherical">')
    m = robodyn.load_urdf_string(spherical)
    (warning,) = m.warnings
    assert "1 <mimic> relation(s) reported" in warning and "'l' (spherical)" in warning
    assert m.constraints == [] and m.mimic_joints == [("r", "l", -1.0, 0.0)]


@pytest.mark.parametrize("n", [1, 7, 37, 1001])
def test_batches_in_lanes_equal_the_loop_bit_for_bit(floating, n):
    """Inverse dynamics, bias forces, gravity, forward dynamics, the mass matrix and the
    derivatives of inverse and forward dynamics run a batch several states per instruction (the widest lanes this CPU has) and leftover states one at a time: every state's
    result is the one-state call's, bit for bit, whatever the batch size."""
    for m in (floating, robodyn.load("ur5")):
        q, v, a, _, _ = batch_of_states(m, n, seed=n)
        for name, args in {
            "inverse_dynamics": (q, v, a),
            "bias_forces": (q, v),
            "generalized_gravity": (q,),
            "forward_dynamics": (q, v, a),
            "mass_matrix": (q,),
        }.items():
            batch = getattr(m, name)(*args)
            loop = np.stack([getattr(m, name)(*(x[k] for x in args)) for k in range(n)])
            np.testing.assert_array_equal(batch, loop, err_msg=f"{m.name} {name} n={n}")
        for name in ("inverse_dynamics_derivatives", "forward_dynamics_derivatives"):
            batch = getattr(m, name)(q, v, a)
            for k in range(n):
                one = getattr(m, name)(q[k], v[k], a[k])
                for key, value in one.items():
                    np.testing.assert_array_equal(batch[key][k], value, err_msg=f"{m.name} {key} {k}")


def test_an_overflow_in_lanes_names_its_batch_element():
    m = robodyn.load("ur5")
    q, v, a, _, _ = batch_of_states(m, 40, seed=5)
    v[29, 1] = 1e200
    with pytest.raises(ValueError, match=r"batch element 29: the result is not finite"):
        m.inverse_dynamics(q, v, a)


def test_batches_release_the_gil(floating):
    """A batch in one thread lets another Python thread run meanwhile."""
    states = floating.random_configuration(n=200_000, seed=1)
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(1)

    counter = threading.Thread(target=count)
    counter.start()
    try:
        before = len(ticks)
        floating.mass_matrix(states)
        during = len(ticks) - before
    finally:
        done.set()
        counter.join()
    assert during > 10, "the other thread did not run while the batch computed"


def test_demo_command_runs():
    result = subprocess.run([sys.executable, "-m", "robodyn.cli", "demo", "--batch", "1000"], capture_output=True, text=True, check=True)
    assert "M(q)" in result.stdout and "yes" in result.stdout
    assert "batch of 1000 states" in result.stdout


def test_single_calls_from_many_threads(floating):
    """Threads sharing one model get the same results as sequential calls (each call that finds the
    shared workspace busy uses its own)."""
    from concurrent.futures import ThreadPoolExecutor

    states = floating.random_configuration(n=400, seed=8)
    expected = [floating.mass_matrix(q) for q in states]
    with ThreadPoolExecutor(max_workers=4) as pool:
        results = list(pool.map(floating.mass_matrix, states))
    for got, want in zip(results, expected):
        np.testing.assert_array_equal(got, want)


def test_manipulability_matches_singular_values(ur5):
    for seed in range(5):
        q = ur5.random_configuration(seed=seed)
        jacobian = ur5.jacobian(q, "tool0")
        for task, rows in (("full", slice(0, 6)), ("position", slice(0, 3)), ([3, 4, 5], slice(3, 6))):
            sigma = np.linalg.svd(jacobian[rows], compute_uv=False)
            assert_close(ur5.manipulability(q, "tool0", task), np.prod(sigma), IDENTITY_TOLERANCE)
            assert_close(ur5.inverse_condition_number(q, "tool0", task), sigma[-1] / sigma[0], 1e-8)
    with pytest.raises(ValueError, match="argument 'task'"):
        ur5.manipulability(q, "tool0", "elbow")
    # batched like every call
    assert ur5.manipulability(ur5.random_configuration(n=4), "tool0").shape == (4,)


def test_workspace_samples_frame_positions(ur5):
    points = ur5.workspace("tool0", n=500, seed=3)
    assert points.shape == (500, 3) and points.flags.c_contiguous
    states = ur5.random_configuration(n=500, seed=3)
    np.testing.assert_array_equal(points, ur5.frame_pose(states, "tool0")[:, :3, 3])
    # the UR5's reach: shoulder offset plus the two arm links plus the wrist
    assert np.max(np.linalg.norm(points - [0, 0, 0.089159], axis=1)) < 0.425 + 0.39225 + 0.2


def test_ignored_mimic_tags_are_one_warning(robots_dir):
    """Talos's grippers have twelve mimic tags on joints the reduced model fixes: one warning."""
    with pytest.warns(robodyn.ModelWarning) as caught:
        m = robodyn.load(robots_dir / "talos_data/robots/talos_reduced.urdf")
    mimic = [w for w in m.warnings if "<mimic>" in w]
    assert len(mimic) == 1 and "12 <mimic> tag(s) ignored" in mimic[0], m.warnings
    assert len([w for w in caught if "<mimic>" in str(w.message)]) == 1
