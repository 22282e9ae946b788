"""Symbolic robots: the notes' planar arms and pendulum, DH tables and URDF files.

Numbers read from files are kept as the exact decimals they are written as (0.425 is 17/40), so
every cancellation in the derivation is exact; results print them back as decimals. A joint or
link angle within ``angle_tolerance`` (1e-9 rad) of a multiple of π/2 is taken as that multiple,
since URDF writers round π/2 (``1.570796327``); pass ``angle_tolerance=0`` to keep them as written.

``symbolic_params`` turns a file's numbers into symbols (``True`` for all, or a collection of the
kinds ``"mass"``, ``"com"``, ``"inertia"``, ``"length"``, ``"gravity"``), named by link number i:
``m_i``, ``c_ix`` (centre of mass), ``I_ixx`` … ``I_iyz`` (inertia about the centre of mass; the
products with the sign of the notes' tensor), ``a_i``/``d_i`` (DH lengths) or ``p_ix`` (URDF joint
origin), ``g``. The file's values stay in ``chain.values`` for ``lambdify`` and ``codegen``.
"""

from __future__ import annotations

import math
import os
import tomllib
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import sympy as sp

from robodyn.symbolic.chain import (
    Chain,
    Link,
    coordinate_symbols,
    homogeneous,
    rotation_about,
    rotation_rpy,
    translation,
)

__all__ = ["planar_chain", "pendulum", "from_dh", "from_urdf", "STANDARD_GRAVITY", "PARAMETER_KINDS"]

#: Gravity of files without a symbolic g, m/s² (the Rust core's ``STANDARD_GRAVITY``).
STANDARD_GRAVITY = sp.Rational("9.81")
#: Default slack for reading an angle as a multiple of π/2, rad.
ANGLE_TOLERANCE = 1e-9
PARAMETER_KINDS = ("mass", "com", "inertia", "length", "gravity")

_X, _Y, _Z = sp.Matrix([1, 0, 0]), sp.Matrix([0, 1, 0]), sp.Matrix([0, 0, 1])


def _rotation(axis: sp.Matrix, angle) -> sp.Matrix:
    return homogeneous(rotation_about(axis, angle), [0, 0, 0])


def planar_chain(n: int, point_masses: bool = True, *, coordinate: str = "q", base_angle=0,
                 name: str | None = None) -> Chain:
    """The notes' planar arm of ``n`` links in the x-y plane, every joint about z (the ECE 470 notes,
    "Given the following 2-link planar manipulator"): ``⁰₁T = Rz(q₁)``, ``ⁱ⁻¹ᵢT = Tx(lᵢ₋₁) Rz(qᵢ)``.

    Link i has length ``l_i`` and mass ``m_i``: a point mass at its distal end (``point_masses``,
    ``ⁱP_Cᵢ = lᵢ X̂ᵢ`` and ``ᶜⁱIᵢ = 0`` as in the TUM notes) or a uniform thin rod (centre at lᵢ/2,
    inertia mᵢlᵢ²/12 about y and z). Gravity ``g`` acts along −y (the notes' ``⁰v̇₀ = g Ŷ₀``).
    ``base_angle`` turns the first link at q = 0 (−π/2 hangs it down); frame ``"tool"`` is the tip.
    """
    if not isinstance(n, int) or isinstance(n, bool) or n < 1:
        raise ValueError(f"argument 'n': expected a positive number of links, got {n!r}")
    q, qd, qdd = coordinate_symbols(n, coordinate)
    g = sp.Symbol("g", positive=True)
    links = []
    for i in range(1, n + 1):
        m, length = sp.Symbol(f"m_{i}", positive=True), sp.Symbol(f"l_{i}", positive=True)
        origin = _rotation(_Z, base_angle) if i == 1 else translation(sp.Symbol(f"l_{i - 1}", positive=True))
        if point_masses:
            com, inertia = sp.Matrix([length, 0, 0]), sp.zeros(3, 3)
        else:
            com, inertia = sp.Matrix([length / 2, 0, 0]), sp.diag(0, m * length**2 / 12, m * length**2 / 12)
        links.append(Link(f"link{i}", "revolute", i - 2, origin, _Z, m, com, inertia))
    kind = "point masses" if point_masses else "rods"
    return Chain(
        name or f"planar{n} ({kind})", tuple(links), sp.Matrix([0, -g, 0]), q, qd, qdd,
        frames={"tool": (n - 1, translation(sp.Symbol(f"l_{n}", positive=True)))},
    )


def pendulum(*, coordinate: str = "theta") -> Chain:
    """The UR5 dynamics notes' simple pendulum: a point mass m on a massless rod of length l, θ = 0 hanging
    down, so that ``m l² θ̈ + m g l sin θ = τ``."""
    chain = planar_chain(1, coordinate=coordinate, base_angle=-sp.pi / 2, name="pendulum")
    m, length = sp.Symbol("m_1", positive=True), sp.Symbol("l_1", positive=True)
    return chain.substitute({m: sp.Symbol("m", positive=True), length: sp.Symbol("l", positive=True)})


# numbers from files
def _exact(value, place: str) -> sp.Expr:
    """A number from a file as an exact rational of its decimal form."""
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise ValueError(f"{place}: expected a number, got {value!r}")
    try:
        number = float(value)
    except ValueError:
        raise ValueError(f"{place}: expected a number, got {value!r}") from None
    if not math.isfinite(number):
        raise ValueError(f"{place}: expected a finite number, got {value!r}")
    return sp.Integer(value) if isinstance(value, int) else sp.Rational(repr(number))


def _angle(value, place: str, tolerance: float, unit=1) -> sp.Expr:
    """An angle; within ``tolerance`` of a multiple of π/2 it is that multiple, exactly."""
    exact = _exact(value, place) * unit
    if exact.is_Rational:
        quarter_turns = round(float(exact) / (math.pi / 2))
        if abs(float(exact) - quarter_turns * math.pi / 2) <= tolerance:
            return quarter_turns * sp.pi / 2
    return exact


def _kinds(symbolic_params) -> set:
    if symbolic_params is True:
        return set(PARAMETER_KINDS)
    if symbolic_params is False or symbolic_params is None:
        return set()
    kinds = set(symbolic_params)
    unknown = kinds - set(PARAMETER_KINDS)
    if unknown:
        raise ValueError(
            f"argument 'symbolic_params': expected True, False or kinds from {PARAMETER_KINDS}, got {sorted(unknown)}"
        )
    return kinds


class _Parameters:
    """Numbers that become symbols for the chosen kinds, with their values remembered."""

    def __init__(self, kinds: set):
        self.kinds = kinds
        self.values: dict = {}

    def __call__(self, kind: str, name: str, value: sp.Expr, positive: bool = False) -> sp.Expr:
        if kind not in self.kinds or value == 0:
            return value
        symbol = sp.Symbol(name, positive=True) if positive else sp.Symbol(name, real=True)
        self.values[symbol] = value
        return symbol

    def mass_properties(self, i: int, mass, com, inertia) -> tuple:
        mass = self("mass", f"m_{i}", mass, positive=True)
        com = sp.Matrix([self("com", f"c_{i}{axis}", c) for axis, c in zip("xyz", com)])
        symbols = {}
        for a, b in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)):
            label = "xyz"[a] + "xyz"[b]
            # the tensor holds −I_xy etc. (the TUM notes' I_c); the symbol is I_xy itself
            sign = 1 if a == b else -1
            symbols[(a, b)] = sign * self("inertia", f"I_{i}{label}", sign * inertia[a, b], positive=a == b)
        tensor = sp.Matrix(3, 3, lambda a, b: symbols[(min(a, b), max(a, b))])
        return mass, com, tensor

    def gravity(self, vector: sp.Matrix) -> sp.Matrix:
        magnitude = sp.sqrt(sum(x**2 for x in vector))
        if "gravity" not in self.kinds or magnitude == 0:
            return vector
        g = self("gravity", "g", magnitude, positive=True)
        return vector / magnitude * g


def _pose(table: dict | None, place: str, tolerance: float, unit) -> sp.Matrix:
    if table is None:
        return sp.eye(4)
    if not isinstance(table, dict):
        raise ValueError(f"{place}: expected a table with 'xyz' and 'rpy', got {table!r}")
    xyz = [_exact(x, f"{place} xyz") for x in table.get("xyz", [0, 0, 0])]
    rpy = [_angle(x, f"{place} rpy", tolerance, unit) for x in table.get("rpy", [0, 0, 0])]
    return homogeneous(rotation_rpy(*rpy), xyz)


def from_dh(table, convention: str | None = None, *, symbolic_params=False, gravity=None,
            angle_tolerance: float = ANGLE_TOLERANCE, coordinate: str = "q") -> Chain:
    """A chain from a DH table: a path to the TOML format ``robodyn.load`` reads (see
    docs/guide/loading-models.md), or a list of rows (dicts with the same keys: ``type``, ``a``, ``alpha``,
    ``d``, ``theta``, ``mass``, ``com``, ``inertia`` = [ixx, iyy, izz, ixy, ixz, iyz], whose values
    may be SymPy expressions) with ``convention`` "standard" or "modified".

    Each link's frame is its joint frame (standard convention: DH frame i−1 turned by joint i;
    modified: DH frame i), its mass properties moved there from DH frame i, as the core does.
    """
    source = "DH table"
    decimals = False
    document: dict = {}
    if isinstance(table, (str, os.PathLike)):
        path = Path(table)
        if not path.is_file():
            raise FileNotFoundError(f"DH table '{path}' not found")
        source = str(path)
        try:
            document = tomllib.loads(path.read_text())
        except tomllib.TOMLDecodeError as error:
            raise ValueError(f"{source}: malformed TOML: {error}") from None
        rows = document.get("joint")
        convention = convention or document.get("convention")
        decimals = True
    else:
        rows = table
        # rows written with floats print their results as decimals too
        decimals = isinstance(rows, list) and any(
            isinstance(value, float) or (isinstance(value, (list, tuple)) and any(isinstance(x, float) for x in value))
            for row in rows if isinstance(row, dict) for value in row.values())
    if not isinstance(rows, list) or not rows:
        raise ValueError(f"{source}: expected a non-empty list of rows ([[joint]] tables), got {rows!r}")
    if convention not in ("standard", "modified"):
        raise ValueError(f"{source}: convention expected \"standard\" or \"modified\", got {convention!r}")
    unit = {"radian": 1, "degree": sp.pi / 180}.get(document.get("angle_unit", "radian"))
    if unit is None:
        raise ValueError(f"{source}: 'angle_unit' expected \"radian\" or \"degree\", got {document['angle_unit']!r}")
    parameters = _Parameters(_kinds(symbolic_params))
    q, qd, qdd = coordinate_symbols(len(rows), coordinate)

    def number(row, key, place, default=None):
        if key not in row:
            if default is None:
                raise ValueError(f"{place}: missing key '{key}'")
            return sp.sympify(default)
        value = row[key]
        return sp.sympify(value) if isinstance(value, sp.Basic) else _exact(value, f"{place} '{key}'")

    def angle(row, key, place):
        value = row.get(key)
        if value is None:
            raise ValueError(f"{place}: missing key '{key}'")
        return sp.sympify(value) if isinstance(value, sp.Basic) else _angle(value, f"{place} '{key}'", angle_tolerance, unit)

    links = []
    # the part of the previous row after its joint (standard convention), in the next row's origin
    after_previous = _pose(document.get("base"), f"{source}: [base]", angle_tolerance, unit)
    for i, row in enumerate(rows, start=1):
        place = f"{source}: row {i}"
        if not isinstance(row, dict):
            raise ValueError(f"{place}: expected a table of a, alpha, d, theta, got {row!r}")
        kind = row.get("type", "revolute")
        if kind not in ("revolute", "prismatic"):
            raise ValueError(f"{place}: 'type' expected \"revolute\" or \"prismatic\", got {kind!r}")
        a = parameters("length", f"a_{i}", number(row, "a", place))
        d = parameters("length", f"d_{i}", number(row, "d", place))
        alpha, theta = angle(row, "alpha", place), angle(row, "theta", place)
        if convention == "modified":
            before = _rotation(_X, alpha) * translation(a) * _rotation(_Z, theta) * translation(0, 0, d)
            after = sp.eye(4)
        elif kind == "revolute":
            before, after = _rotation(_Z, theta), translation(0, 0, d) * translation(a) * _rotation(_X, alpha)
        else:
            before, after = _rotation(_Z, theta) * translation(0, 0, d), translation(a) * _rotation(_X, alpha)
        mass = number(row, "mass", place, 0)
        com = sp.Matrix([sp.sympify(c) if isinstance(c, sp.Basic) else _exact(c, f"{place} 'com'")
                         for c in row.get("com", [0, 0, 0])])
        ixx, iyy, izz, ixy, ixz, iyz = [sp.sympify(c) if isinstance(c, sp.Basic) else _exact(c, f"{place} 'inertia'")
                                        for c in row.get("inertia", [0] * 6)]
        inertia = sp.Matrix([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        mass, com, inertia = parameters.mass_properties(i, mass, com, inertia)
        # mass properties from DH frame i into the joint frame: c' = R c + p, I' = R I Rᵀ
        rotation, position = after[:3, :3], after[:3, 3]
        links.append(Link(
            str(row.get("name", f"joint{i}")), kind, i - 2, after_previous * before, _Z, mass,
            rotation * com + position, rotation * inertia * rotation.T,
        ))
        after_previous = after
    tool = after_previous * _pose(document.get("tool"), f"{source}: [tool]", angle_tolerance, unit)
    default_gravity = document.get("gravity", [0, 0, -float(STANDARD_GRAVITY)])
    gravity_vector = sp.Matrix(gravity) if gravity is not None else sp.Matrix(
        [_exact(x, f"{source}: 'gravity'") for x in default_gravity])
    return Chain(
        str(document.get("name", "dh_robot")), tuple(links), parameters.gravity(gravity_vector), q, qd, qdd,
        values=parameters.values, frames={"tool": (len(rows) - 1, tool)}, decimals=decimals,
    )


def from_urdf(path, *, symbolic_params=False, gravity=None, angle_tolerance: float = ANGLE_TOLERANCE,
              coordinate: str = "q", mimic: bool = False) -> Chain:
    """A chain (or tree) from a URDF file: revolute, continuous and prismatic joints move links,
    fixed joints merge their child into its parent (mass, centre of mass and inertia combined),
    links in depth-first file order as the core numbers them. Gravity −9.81 along z unless given.

    A file with ``<mimic>`` joints needs ``mimic=True``: the chain then keeps the relations
    (``chain.mimics``), and its equations come in the coordinates they leave, as
    ``robodyn.load(path, mimic=True)``'s (see :mod:`robodyn.symbolic.mimic`).
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"URDF file '{path}' not found")
    try:
        robot = ElementTree.parse(path).getroot()
    except ElementTree.ParseError as error:
        raise ValueError(f"{path}: malformed XML: {error}") from None
    if robot.tag != "robot":
        raise ValueError(f"{path}: expected a <robot> root element, got <{robot.tag}>")
    links = {link.get("name"): link for link in robot.findall("link")}
    joints = robot.findall("joint")
    children: dict = {}
    child_names = set()
    mimic_tags: dict = {}
    for joint in joints:
        parent, child = joint.find("parent"), joint.find("child")
        if parent is None or child is None:
            raise ValueError(f"{path}: joint '{joint.get('name')}': expected <parent> and <child>")
        children.setdefault(parent.get("link"), []).append(joint)
        child_names.add(child.get("link"))
        tag = joint.find("mimic")
        if tag is not None:
            where = f"{path}: joint '{joint.get('name')}' <mimic>"
            if not mimic:
                raise ValueError(f"{where}: a mimic joint follows another; pass mimic=True for the equations "
                                 "in the coordinates its relation leaves")
            mimic_tags[joint.get("name")] = (tag.get("joint"), _exact(tag.get("multiplier", "1"), f"{where} 'multiplier'"),
                                             _exact(tag.get("offset", "0"), f"{where} 'offset'"))
    roots = [name for name in links if name not in child_names]
    if len(roots) != 1:
        raise ValueError(f"{path}: expected one root link, got {roots}")

    def numbers(element, attribute, where, default="0 0 0"):
        text = element.get(attribute, default) if element is not None else default
        values = text.split()
        if len(values) != 3:
            raise ValueError(f"{where}: '{attribute}' expected 3 numbers, got {text!r}")
        return [_exact(v, f"{where} '{attribute}'") for v in values]

    def origin(element, where):
        tag = element.find("origin") if element is not None else None
        xyz = numbers(tag, "xyz", where)
        rpy = [_angle(v, f"{where} 'rpy'", angle_tolerance) for v in (tag.get("rpy", "0 0 0").split() if tag is not None else [0, 0, 0])]
        if len(rpy) != 3:
            raise ValueError(f"{where}: 'rpy' expected 3 numbers")
        return homogeneous(rotation_rpy(*rpy), xyz)

    def inertial(link_name):
        """(mass, com, inertia about the com) of a URDF link, in its frame."""
        element = links[link_name].find("inertial")
        where = f"{path}: link '{link_name}' <inertial>"
        if element is None:
            return sp.S.Zero, sp.zeros(3, 1), sp.zeros(3, 3)
        mass_tag, inertia_tag = element.find("mass"), element.find("inertia")
        mass = _exact(mass_tag.get("value", "0"), f"{where} <mass>") if mass_tag is not None else sp.S.Zero
        pose = origin(element, where)
        keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
        ixx, ixy, ixz, iyy, iyz, izz = [
            _exact(inertia_tag.get(k, "0"), f"{where} <inertia> '{k}'") if inertia_tag is not None else sp.S.Zero
            for k in keys
        ]
        tensor = sp.Matrix([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        rotation = pose[:3, :3]
        return mass, pose[:3, 3], rotation * tensor * rotation.T

    parameters = _Parameters(_kinds(symbolic_params))
    bodies: list[dict] = []

    def add_mass(body, mass, com, inertia, pose):
        """Merges (mass, com, inertia) given in a frame at ``pose`` of the body into the body."""
        if mass == 0 and inertia == sp.zeros(3, 3):
            return
        rotation = pose[:3, :3]
        com = rotation * com + pose[:3, 3]
        inertia = rotation * inertia * rotation.T
        total = body["mass"] + mass
        if total == 0:
            body["inertia"] += inertia
            return
        center = (body["mass"] * body["com"] + mass * com) / total
        # parallel axis: I_center = Σ I_k + m_k (|d|² 1 − d dᵀ), d = c_k − center
        combined = sp.zeros(3, 3)
        for m, c, i in ((body["mass"], body["com"], body["inertia"]), (mass, com, inertia)):
            offset = c - center
            combined += i + m * ((offset.T * offset)[0] * sp.eye(3) - offset * offset.T)
        body.update(mass=total, com=center, inertia=combined)

    def visit(link_name, body_index, pose_in_body):
        for joint in children.get(link_name, []):
            where = f"{path}: joint '{joint.get('name')}'"
            kind = joint.get("type")
            child = joint.find("child").get("link")
            if child not in links:
                raise ValueError(f"{where}: child link '{child}' is not defined")
            joint_origin = origin(joint, where)
            if kind == "fixed":
                pose = pose_in_body * joint_origin
                if body_index >= 0:
                    add_mass(bodies[body_index], *inertial(child), pose)
                visit(child, body_index, pose)
                continue
            if kind not in ("revolute", "continuous", "prismatic"):
                raise ValueError(f"{where}: type expected revolute, continuous, prismatic or fixed, got {kind!r}")
            axis = sp.Matrix(numbers(joint.find("axis"), "xyz", f"{where} <axis>", "1 0 0"))
            norm = sp.sqrt((axis.T * axis)[0])
            if norm == 0:
                raise ValueError(f"{where}: <axis> expected a non-zero vector")
            index = len(bodies) + 1
            position = [parameters("length", f"p_{index}{a}", x) for a, x in zip("xyz", joint_origin[:3, 3])]
            bodies.append(dict(
                name=child, joint=joint.get("name"), kind="prismatic" if kind == "prismatic" else "revolute",
                parent=body_index, origin=pose_in_body * homogeneous(joint_origin[:3, :3], position),
                axis=axis / norm, mass=sp.S.Zero, com=sp.zeros(3, 1), inertia=sp.zeros(3, 3),
            ))
            add_mass(bodies[-1], *inertial(child), sp.eye(4))
            visit(child, len(bodies) - 1, sp.eye(4))

    visit(roots[0], -1, sp.eye(4))
    if not bodies:
        raise ValueError(f"{path}: expected at least one moving joint, got none")
    q, qd, qdd = coordinate_symbols(len(bodies), coordinate)
    chain_links = []
    for i, body in enumerate(bodies, start=1):
        mass, com, inertia = parameters.mass_properties(i, body["mass"], body["com"], body["inertia"])
        chain_links.append(Link(body["joint"], body["kind"], body["parent"], body["origin"], body["axis"],
                                mass, com, inertia))
    gravity_vector = sp.Matrix(gravity) if gravity is not None else sp.Matrix([0, 0, -STANDARD_GRAVITY])
    moving = {body["joint"]: k for k, body in enumerate(bodies)}
    mimics = {}
    for follower, (leader, ratio, offset) in mimic_tags.items():
        for role, name in (("joint", follower), ("the joint it mimics", leader)):
            if name not in moving:
                raise ValueError(f"{path}: joint '{follower}' <mimic>: {role} '{name}' is not a moving joint")
        mimics[moving[follower]] = (moving[leader], ratio, offset)
    return Chain(robot.get("name", path.stem), tuple(chain_links), parameters.gravity(gravity_vector),
                 q, qd, qdd, values=parameters.values, decimals=True, mimics=mimics)
