"""The symbolic layer (issue 5): the notes' closed forms exactly, Euler–Lagrange against Newton–Euler
symbolically, Ṁ − 2C skew symbolically, and the lambdified closed forms against the Rust core."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from conftest import REPOSITORY, assert_close

import robodyn
from robodyn import symbolic as sym

#: Lambdified closed forms against the numeric core (relative to the largest entry, or 1).
CLOSED_FORM_TOLERANCE = 1e-10

m1, m2, l1, l2, g = sp.symbols("m_1 m_2 l_1 l_2 g", positive=True)
q1, q2 = sp.symbols("q_1 q_2", real=True)
qd1, qd2 = sp.symbols("qdot_1 qdot_2", real=True)
qdd1, qdd2 = sp.symbols("qddot_1 qddot_2", real=True)
c1, c2, s2, c12 = sp.cos(q1), sp.cos(q2), sp.sin(q2), sp.cos(q1 + q2)


def assert_identical(actual, expected, label=""):
    """Symbolic equality: the difference expands to zero."""
    difference = sp.expand(sp.Matrix(actual) - sp.Matrix(expected))
    assert difference == sp.zeros(*difference.shape), f"{label}: differs by {difference}"


def spatial_rpp_arm():
    """A 3-DoF spatial arm with a prismatic joint (modified DH, all parameters symbolic): a
    vertical revolute base, a revolute shoulder about a horizontal axis and a prismatic forearm."""
    d1, a2 = sp.symbols("d_1 a_2", positive=True)
    ms = sp.symbols("m_1:4", positive=True)
    i1, j1, i2, i3, j3 = sp.symbols("I_1 J_1 I_2 I_3 J_3", positive=True)
    rows = [
        dict(type="revolute", a=0, alpha=0, d=d1, theta=0, mass=ms[0], com=[0, 0, -d1 / 2], inertia=[i1, i1, j1, 0, 0, 0]),
        dict(type="revolute", a=0, alpha=sp.pi / 2, d=0, theta=0, mass=ms[1], com=[a2 / 2, 0, 0], inertia=[0, i2, i2, 0, 0, 0]),
        dict(type="prismatic", a=a2, alpha=sp.pi / 2, d=0, theta=0, mass=ms[2], com=[0, 0, 0], inertia=[i3, i3, j3, 0, 0, 0]),
    ]
    return sym.from_dh(rows, convention="modified")


CHAINS = {
    "planar2": lambda: sym.planar_chain(2),
    "planar2 rods": lambda: sym.planar_chain(2, point_masses=False),
    "planar3": lambda: sym.planar_chain(3),
    "planar3 rods": lambda: sym.planar_chain(3, point_masses=False),
    "spatial rpp": spatial_rpp_arm,
    "planar2 springs dampers": lambda: sym.planar_chain(2).with_joint_springs(True, True).with_damping(True, True),
}


def test_two_link_arm_matches_seed_001():
    """The ECE 470 notes "Dynamic Equation": M, V and G of the 2-link arm with point masses, exactly."""
    eom = sym.lagrange(sym.planar_chain(2))
    assert_identical(eom.M, [[l2**2 * m2 + 2 * l1 * l2 * m2 * c2 + l1**2 * (m1 + m2), l2**2 * m2 + l1 * l2 * m2 * c2],
                             [l2**2 * m2 + l1 * l2 * m2 * c2, l2**2 * m2]], "M")
    assert_identical(eom.V, [-m2 * l1 * l2 * s2 * qd2**2 - 2 * m2 * l1 * l2 * s2 * qd1 * qd2,
                             m2 * l1 * l2 * s2 * qd1**2], "V")
    assert_identical(eom.G, [m2 * l2 * g * c12 + (m1 + m2) * l1 * g * c1, m2 * l2 * g * c12], "G")
    assert sp.expand(eom.C * eom.qd - eom.V) == sp.zeros(2, 1)


def test_two_link_arm_torques_match_seed_002_eq_6_58():
    """The TUM notes, eq. 6.58: τ₁ and τ₂ by Euler–Lagrange and by Newton–Euler."""
    tau1 = (m2 * l2**2 * (qdd1 + qdd2) + m2 * l1 * l2 * c2 * (2 * qdd1 + qdd2) + (m1 + m2) * l1**2 * qdd1
            - m2 * l1 * l2 * s2 * qd2**2 - 2 * m2 * l1 * l2 * s2 * qd1 * qd2 + m2 * l2 * g * c12 + (m1 + m2) * l1 * g * c1)
    tau2 = m2 * l1 * l2 * c2 * qdd1 + m2 * l1 * l2 * s2 * qd1**2 + m2 * l2 * g * c12 + m2 * l2**2 * (qdd1 + qdd2)
    arm = sym.planar_chain(2)
    assert_identical(sym.lagrange(arm).tau, [tau1, tau2], "Lagrange τ")
    assert_identical(sym.newton_euler(arm).tau, [tau1, tau2], "Newton–Euler τ")


def test_two_link_arm_newton_euler_intermediates_match_seed_002():
    """The TUM notes' outward iteration for the 2-link arm: ¹v̇_C₁ and ²F₂ (eq. 6.55 and after)."""
    ne = sym.newton_euler(sym.planar_chain(2))
    s1, s12 = sp.sin(q1), sp.sin(q1 + q2)
    assert_identical(ne.omega[1], [0, 0, qd1 + qd2], "²ω₂")
    assert_identical(ne.v_dot_c[0], [-l1 * qd1**2 + g * s1, l1 * qdd1 + g * c1, 0], "¹v̇_C₁")
    assert_identical(ne.F[1], [m2 * l1 * qdd1 * s2 - m2 * l1 * qd1**2 * c2 + m2 * g * s12 - m2 * l2 * (qd1 + qd2) ** 2,
                               m2 * l1 * qdd1 * c2 + m2 * l1 * qd1**2 * s2 + m2 * g * c12 + m2 * l2 * (qdd1 + qdd2), 0],
                     "²F₂")


def test_pendulum_matches_seed_003():
    """The UR5 dynamics notes: m l² θ̈ + m g l sin θ = τ; with a spring k (θ − θ_r) and a damper b θ̇ added."""
    m, length = sp.symbols("m l", positive=True)
    theta, thetadd = sp.Symbol("theta_1", real=True), sp.Symbol("thetaddot_1", real=True)
    thetad = sp.Symbol("thetadot_1", real=True)
    pendulum = sym.pendulum()
    assert_identical(sym.lagrange(pendulum).tau, [m * length**2 * thetadd + m * g * length * sp.sin(theta)], "pendulum")
    k, b, rest = sp.Symbol("k_1", real=True), sp.Symbol("b_1", real=True), sp.Symbol("q_r_1", real=True)
    sprung = pendulum.with_joint_springs(True, True).with_damping(True)
    eom = sym.lagrange(sprung)
    assert_identical(eom.tau, [m * length**2 * thetadd + m * g * length * sp.sin(theta) + k * (theta - rest) + b * thetad],
                     "pendulum with spring and damper")
    assert_identical(eom.G, [m * g * length * sp.sin(theta) + k * (theta - rest)], "G with the spring")
    assert_identical(eom.F, [b * thetad], "F")


def test_point_spring_energy():
    """The UR5 dynamics notes' spring V = ½ k (r − r₀)²: a spring from the pivot's height to the bob."""
    m, length = sp.symbols("m l", positive=True)
    k, rest = sp.symbols("k r_0", positive=True)
    theta = sp.Symbol("theta_1", real=True)
    chain = sym.pendulum().with_spring(k, rest, -1, [0, 0, 0], 0, [length, 0, 0])
    eom = sym.lagrange(chain)
    # the spring spans the rod, whose length is constant: no force
    assert sp.simplify(eom.G[0] - m * g * length * sp.sin(theta)) == 0
    anchored = sym.pendulum().with_spring(k, rest, -1, [length, 0, 0], 0, [length, 0, 0])
    energy = sym.lagrange(anchored).potential_energy
    bob = sp.Matrix([length * sp.sin(theta), -length * sp.cos(theta)])
    r = sp.sqrt((bob - sp.Matrix([length, 0])).dot(bob - sp.Matrix([length, 0])))
    expected = -m * g * length * sp.cos(theta) + k * (r - rest) ** 2 / 2
    assert sp.simplify(energy - expected) == 0


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_lagrange_equals_newton_euler(name):
    """The two formulations agree symbolically: the difference simplifies to zero."""
    chain = CHAINS[name]()
    difference = sym.newton_euler(chain).difference(sym.lagrange(chain))
    assert difference == sp.zeros(chain.n, 1), f"{name}: {difference}"


@pytest.mark.parametrize("name", ["planar2", "planar3", "planar3 rods", "spatial rpp"])
def test_mass_matrix_rate_minus_twice_coriolis_is_skew(name):
    """Ṁ − 2C is skew-symmetric, symbolically, and V = C q̇."""
    eom = sym.lagrange(CHAINS[name]())
    assert eom.skew_residual() == sp.zeros(eom.n, eom.n)
    assert sp.expand(eom.C * eom.qd - eom.V) == sp.zeros(eom.n, 1)


def test_craig_split_recombines_to_v():
    """C(q)[q̇²] + B(q)[q̇q̇] = V, and B has n(n−1)/2 columns (the TU Berlin notes)."""
    for name in ("planar3", "spatial rpp"):
        eom = sym.lagrange(CHAINS[name]())
        assert eom.coriolis_pairs.shape == (eom.n, eom.n * (eom.n - 1) // 2)
        recombined = eom.centrifugal * eom.velocity_squares + eom.coriolis_pairs * eom.velocity_products
        assert sp.expand(recombined - eom.V) == sp.zeros(eom.n, 1), name


def test_christoffel_symbols_of_the_two_link_arm():
    """The TU Berlin notes "Christoffel Symbols": b₁₂₂ = −m₂l₁l₂s₂ = b₁₁₂·1 and b₂₁₁ = m₂l₁l₂s₂."""
    gamma = sym.lagrange(sym.planar_chain(2)).christoffel
    assert sp.expand(gamma[0, 1, 1] + m2 * l1 * l2 * s2) == 0
    assert sp.expand(gamma[0, 0, 1] + m2 * l1 * l2 * s2) == 0
    assert sp.expand(gamma[1, 0, 0] - m2 * l1 * l2 * s2) == 0
    assert gamma[0, 0, 0] == 0 and gamma[1, 1, 1] == 0


def test_extract_terms_reads_m_v_g_off_tau():
    """The UR5 dynamics notes' reading of M, C, G off the equations, applied to Newton–Euler's τ."""
    arm = sym.planar_chain(2)
    eom = sym.lagrange(arm)
    mass, velocity, gravity = sym.extract_terms(sym.newton_euler(arm).tau, arm.q, arm.qd, arm.qdd)
    assert_identical(mass, eom.M, "M")
    assert_identical(velocity, eom.V, "V")
    assert_identical(gravity, eom.G, "G")


def test_trig_canonical_is_the_zero_test():
    assert sym.trig_canonical(sp.sin(q1) ** 2 + sp.cos(q1) ** 2 - 1, [q1]) == 0
    assert sym.trig_canonical(c1 * c2 - sp.sin(q1) * s2, [q1, q2]) == c12
    assert sym.is_identically_zero(sp.Matrix([sp.sin(q1 + q2) - sp.sin(q1) * c2 - c1 * s2]), [q1, q2])


def _random_states(n, count=6, seed=5):
    rng = np.random.default_rng(seed)
    return [(rng.uniform(-np.pi, np.pi, n), rng.uniform(-2, 2, n), rng.uniform(-2, 2, n)) for _ in range(count)]


@pytest.mark.parametrize("kind", ["dh", "urdf"])
def test_lambdified_closed_forms_match_the_core(kind):
    """M, C, G and τ of the UR5 (DH table and URDF) from the closed forms against the Rust core."""
    path = REPOSITORY / "models" / ("ur5_dh.toml" if kind == "dh" else "ur5.urdf")
    chain = sym.from_dh(path) if kind == "dh" else sym.from_urdf(path)
    numeric = sym.lagrange(chain).lambdify()
    model = robodyn.load(path)
    for q, v, a in _random_states(model.nv):
        assert_close(numeric.M(q), model.mass_matrix(q), CLOSED_FORM_TOLERANCE, f"{kind} M")
        assert_close(numeric.C(q, v), model.coriolis_matrix(q, v), CLOSED_FORM_TOLERANCE, f"{kind} C")
        assert_close(numeric.G(q), model.generalized_gravity(q), CLOSED_FORM_TOLERANCE, f"{kind} G")
        assert_close(numeric.tau(q, v, a), model.inverse_dynamics(q, v, a), CLOSED_FORM_TOLERANCE, f"{kind} τ")
    # a batch gives the rows of single calls
    qs = np.array([s[0] for s in _random_states(model.nv)])
    assert_close(numeric.G(qs), model.generalized_gravity(qs), CLOSED_FORM_TOLERANCE, f"{kind} batch G")


def test_symbolic_urdf_parameters_substitute_back():
    """from_urdf(symbolic_params=True) keeps the file's values; M evaluated with them is M."""
    path = REPOSITORY / "models" / "planar2.urdf"
    symbolic = sym.lagrange(sym.from_urdf(path, symbolic_params=True))
    names = {s.name for s in symbolic.M.free_symbols}
    assert {"m_1", "m_2", "p_2x", "c_1x", "c_2x"} <= names
    numeric = symbolic.lambdify()
    model = robodyn.load(path)
    for q, v, a in _random_states(2):
        assert_close(numeric.tau(q, v, a), model.inverse_dynamics(q, v, a), CLOSED_FORM_TOLERANCE, "planar2 τ")
    with pytest.raises(ValueError, match="'params'.*m_9"):
        symbolic.lambdify(params={"m_9": 1.0})


def test_lambdify_needs_every_parameter():
    eom = sym.lagrange(sym.planar_chain(2))
    with pytest.raises(ValueError, match=r"expected values for \['g', 'l_1', 'l_2', 'm_1', 'm_2'\]"):
        eom.lambdify()
    f = eom.lambdify(params={"m_1": 2.0, "m_2": 1.0, "l_1": 1.0, "l_2": 0.5, "g": 9.81})
    model = robodyn.load("planar2")
    q, v, a = np.array([0.3, -0.7]), np.array([0.5, 1.5]), np.array([0.2, -0.4])
    assert_close(f.tau(q, v, a), model.inverse_dynamics(q, v, a), CLOSED_FORM_TOLERANCE, "planar2 τ")
    with pytest.raises(ValueError, match="argument 'q': expected shape"):
        f.M(np.zeros(3))
    with pytest.raises(ValueError, match="argument 'v': expected finite"):
        f.C(np.zeros(2), np.array([np.nan, 0.0]))


def test_bad_models_are_refused(tmp_path):
    with pytest.raises(ValueError, match="argument 'n'"):
        sym.planar_chain(0)
    with pytest.raises(ValueError, match="convention"):
        sym.from_dh([dict(a=0, alpha=0, d=0, theta=0)], convention="sideways")
    with pytest.raises(ValueError, match="row 1: missing key 'alpha'"):
        sym.from_dh([dict(a=0, d=0, theta=0)], convention="standard")
    with pytest.raises(FileNotFoundError):
        sym.from_urdf(tmp_path / "missing.urdf")
    floating = tmp_path / "floating.urdf"
    floating.write_text('<robot name="r"><link name="a"/><link name="b"/>'
                        '<joint name="j" type="floating"><parent link="a"/><child link="b"/></joint></robot>')
    with pytest.raises(ValueError, match="joint 'j': type expected"):
        sym.from_urdf(floating)
    with pytest.raises(ValueError, match="'symbolic_params'"):
        sym.from_urdf(REPOSITORY / "models" / "planar2.urdf", symbolic_params=["masses"])


def test_latex_prints_the_notes_forms():
    eom = sym.lagrange(sym.planar_chain(2))
    text = eom.latex()
    assert text.startswith("\\begin{aligned}") and text.endswith("\\end{aligned}")
    for piece in ("c_{12}", "c_{2}", "s_{2}", r"\dot{q}_{1}", r"M(q) &= \begin{bmatrix}", "G(q)"):
        assert piece in text, piece
    torques = eom.latex("torques")
    assert r"\tau_{1} &=" in torques and r"\tau_{2} &=" in torques and r"\ddot{q}_{2}" in torques
    with pytest.raises(ValueError, match="argument 'form'"):
        eom.latex("poem")
    pendulum = sym.lagrange(sym.pendulum()).latex("torques")
    assert r"s_{1}" in pendulum and r"\ddot{\theta}_{1}" in pendulum


def test_abbreviations_round_trip():
    """The printed abbreviations stand for what they say: c_{12} back to cos(q_1 + q_2) gives G."""
    from robodyn.symbolic.printing import abbreviate

    eom = sym.lagrange(sym.planar_chain(2))
    short = abbreviate(eom.G, (q1, q2))
    back = short.xreplace({sp.Symbol("c_{12}", real=True): c12, sp.Symbol("c_{1}", real=True): c1})
    assert_identical(back, eom.G, "G")


def _generated_states(n):
    return [(q, v, a) for q, v, a in _random_states(n, count=3, seed=11)]


def test_generated_numpy_code_runs(tmp_path):
    eom = sym.lagrange(sym.from_dh(REPOSITORY / "models" / "ur5_dh.toml"))
    source = eom.codegen("numpy")
    namespace: dict = {}
    exec(compile(source, "ur5_dh_generated.py", "exec"), namespace)
    model = robodyn.load(REPOSITORY / "models" / "ur5_dh.toml")
    for q, v, a in _generated_states(6):
        assert_close(namespace["mass_matrix"](q), model.mass_matrix(q), CLOSED_FORM_TOLERANCE, "numpy M")
        assert_close(namespace["coriolis_matrix"](q, v), model.coriolis_matrix(q, v), CLOSED_FORM_TOLERANCE, "numpy C")
        assert_close(namespace["gravity"](q), model.generalized_gravity(q), CLOSED_FORM_TOLERANCE, "numpy G")
        assert_close(namespace["inverse_dynamics"](q, v, a), model.inverse_dynamics(q, v, a), CLOSED_FORM_TOLERANCE,
                     "numpy τ")


def test_generated_c_code_compiles_and_agrees(tmp_path):
    """The C source compiles with the system's C compiler and returns the core's numbers; the
    symbolic parameters of the planar arm become the argument p."""
    import ctypes
    import shutil
    import subprocess

    compiler = shutil.which("cc") or shutil.which("gcc")
    assert compiler, "a C compiler (cc) is needed: Rust's linker uses it too"
    eom = sym.lagrange(sym.planar_chain(2).with_damping(True))
    source = tmp_path / "planar2.c"
    source.write_text(eom.codegen("c"))
    library = tmp_path / "libplanar2.so"
    subprocess.run([compiler, "-O2", "-shared", "-fPIC", "-Wall", "-Werror", "-o", library, source, "-lm"], check=True)
    lib = ctypes.CDLL(str(library))
    array = ctypes.c_double * 4
    # p = [b_1, b_2, g, l_1, l_2, m_1, m_2]: the bundled planar2 without damping
    p = (ctypes.c_double * 7)(0.0, 0.0, 9.81, 1.0, 0.5, 2.0, 1.0)
    model = robodyn.load("planar2")
    for q, v, a in _generated_states(2):
        out = array()
        lib.planar2_mass_matrix((ctypes.c_double * 2)(*q), p, out)
        assert_close(np.array(out[:]).reshape(2, 2), model.mass_matrix(q), CLOSED_FORM_TOLERANCE, "C M")
        tau = (ctypes.c_double * 2)()
        lib.planar2_inverse_dynamics((ctypes.c_double * 2)(*q), (ctypes.c_double * 2)(*v), (ctypes.c_double * 2)(*a), p, tau)
        assert_close(np.array(tau[:]), model.inverse_dynamics(q, v, a), CLOSED_FORM_TOLERANCE, "C τ")


def test_generated_rust_code_compiles_and_agrees(tmp_path):
    """The Rust source compiles with rustc (warnings denied) and returns the core's numbers."""
    import shutil
    import subprocess

    rustc = shutil.which("rustc")
    assert rustc, "rustc is needed (the project builds with it)"
    path = REPOSITORY / "testdata" / "dh" / "rpp_arm.toml"
    eom = sym.lagrange(sym.from_dh(path))
    states = _generated_states(3)
    calls = "\n".join(
        f"    let (q, v, a) = ({list(map(float, q))}, {list(map(float, v))}, {list(map(float, a))});\n"
        "    println!(\"{:?} {:?} {:?} {:?}\", mass_matrix(&q), coriolis_matrix(&q, &v), gravity(&q), "
        "inverse_dynamics(&q, &v, &a));"
        for q, v, a in states
    )
    main = tmp_path / "main.rs"
    main.write_text(eom.codegen("rust") + "\nfn main() {\n" + calls + "\n}\n")
    binary = tmp_path / "rpp_arm"
    subprocess.run([rustc, "--edition", "2021", "-D", "warnings", "-O", "-o", binary, main], check=True)
    lines = subprocess.run([binary], check=True, capture_output=True, text=True).stdout.splitlines()
    model = robodyn.load(path)
    for line, (q, v, a) in zip(lines, states, strict=True):
        numbers = np.array([float(x) for x in line.replace("[", " ").replace("]", " ").replace(",", " ").split()])
        expected = np.concatenate([model.mass_matrix(q).ravel(), model.coriolis_matrix(q, v).ravel(),
                                   model.generalized_gravity(q), model.inverse_dynamics(q, v, a)])
        assert_close(numbers, expected, CLOSED_FORM_TOLERANCE, "Rust M, C, G, τ")


def test_codegen_refuses_unknown_languages():
    with pytest.raises(ValueError, match="argument 'language'"):
        sym.lagrange(sym.planar_chain(1)).codegen("fortran")


def test_cli_derive(capsys, tmp_path):
    from robodyn.cli import main

    assert main(["derive", "planar2", "--latex"]) == 0
    out = capsys.readouterr().out
    assert "c_{12}" in out and r"\begin{bmatrix}" in out
    assert main(["derive", str(REPOSITORY / "models" / "ur5_dh.toml"), "--newton-euler"]) == 0
    captured = capsys.readouterr()
    assert "M[6,6] = 0.000132117187500000" in captured.out and "agree: yes" in captured.err
    target = tmp_path / "pendulum.c"
    assert main(["derive", "pendulum", "--codegen", "c", "-o", str(target)]) == 0
    assert "pendulum_mass_matrix" in target.read_text()
    assert main(["derive", "nothing"]) == 2
    assert "expected planar<n>" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["planar2", "pendulum", "rpp_arm"])
def test_frozen_closed_form_references_are_up_to_date(name):
    """testdata/reference/symbolic_*.json (read by the Rust tests) is what the generator writes."""
    import json

    from robodyn.symbolic.fixtures import fixture

    frozen = json.loads((REPOSITORY / "testdata" / "reference" / f"symbolic_{name}.json").read_text())
    fresh = fixture(name, REPOSITORY)
    # the SymPy version may differ from the one that wrote the file; the numbers may not
    for record in (frozen, fresh):
        record["provenance"].pop("sympy")
    assert fresh == frozen


def test_generalized_forces_enter_as_minus_q():
    """The UR5 dynamics notes: d/dt ∂L/∂q̇ⱼ − ∂L/∂qⱼ = Qⱼ; a force Q on the pendulum leaves τ = … − Q."""
    m, length = sp.symbols("m l", positive=True)
    theta, thetad = sp.Symbol("theta_1", real=True), sp.Symbol("thetadot_1", real=True)
    thetadd = sp.Symbol("thetaddot_1", real=True)
    drag = -sp.Symbol("c", positive=True) * thetad**3
    eom = sym.lagrange(sym.pendulum(), forces=[drag])
    assert_identical(eom.tau, [m * length**2 * thetadd + m * g * length * sp.sin(theta) - drag], "τ")
    with pytest.raises(ValueError, match="argument 'forces'"):
        sym.lagrange(sym.pendulum(), forces=[1, 2])


def test_a_branching_urdf(tmp_path):
    """A tree (two pendulums hanging from one revolute base): Lagrange = Newton–Euler, and the
    closed forms agree with the core."""
    inertial = '<inertial><origin xyz="{x} 0 -0.3"/><mass value="{m}"/>' \
               '<inertia ixx="0.01" ixy="0" ixz="0.002" iyy="0.02" iyz="0" izz="0.015"/></inertial>'
    path = tmp_path / "tree.urdf"
    path.write_text(
        '<robot name="tree"><link name="world"/>'
        f'<link name="base">{inertial.format(x=0, m=2.0)}</link>'
        f'<link name="left">{inertial.format(x=0.1, m=1.0)}</link>'
        f'<link name="right">{inertial.format(x=-0.1, m=0.5)}</link>'
        '<joint name="turn" type="revolute"><parent link="world"/><child link="base"/><axis xyz="0 0 1"/></joint>'
        '<joint name="left_hinge" type="revolute"><parent link="base"/><child link="left"/>'
        '<origin xyz="0.2 0 0" rpy="0 0 0.5"/><axis xyz="0 1 0"/></joint>'
        '<joint name="right_slide" type="prismatic"><parent link="base"/><child link="right"/>'
        '<origin xyz="-0.2 0 0"/><axis xyz="0 0 1"/></joint></robot>'
    )
    chain = sym.from_urdf(path)
    assert [link.parent for link in chain.links] == [-1, 0, 0]
    eom = sym.lagrange(chain)
    assert sym.newton_euler(chain).difference(eom) == sp.zeros(3, 1)
    numeric, model = eom.lambdify(), robodyn.load(path)
    for q, v, a in _random_states(3):
        assert_close(numeric.tau(q, v, a), model.inverse_dynamics(q, v, a), CLOSED_FORM_TOLERANCE, "tree τ")
        assert_close(numeric.M(q), model.mass_matrix(q), CLOSED_FORM_TOLERANCE, "tree M")
