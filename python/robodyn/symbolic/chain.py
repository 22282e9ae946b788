"""The symbolic robot: a tree of links, each moved by one revolute or prismatic joint, with SymPy
expressions for every length, mass, inertia and for gravity.

Each link's frame sits at its joint (the frame Craig's iterative Newton–Euler uses, the TUM notes):
``ⁱ⁻¹Tᵢ(qᵢ) = origin_i · joint_i(qᵢ)``, where ``origin_i`` is the joint frame in the parent's frame
at qᵢ = 0 and ``joint_i`` turns about (revolute) or slides along (prismatic) the unit ``axis`` given
in the joint frame. A DH row and a URDF joint both reduce to this form; a planar chain is the
notes' arm (the ECE 470 notes, "Given the following 2-link planar manipulator").

Mass properties are in the link's frame: centre of mass ``com`` and inertia ``inertia`` about the
centre of mass (products of inertia with their sign, as the TUM notes' I_c). Passive elements:
joint springs ``½ k (q − q_ref)²``, viscous damping ``b q̇`` and Coulomb friction ``f_c sign(q̇)``
per joint, and linear springs between two points (the UR5 dynamics notes' ``½ k (r − r₀)²``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import sympy as sp

__all__ = [
    "Link",
    "PointSpring",
    "Chain",
    "coordinate_symbols",
    "rotation_about",
    "rotation_rpy",
    "homogeneous",
    "translation",
]

JOINT_KINDS = ("revolute", "prismatic")


def coordinate_symbols(n: int, name: str = "q") -> tuple[tuple, tuple, tuple]:
    """(q, q̇, q̈) as real symbols ``q_1 … q_n``, ``qdot_i``, ``qddot_i`` (LaTeX: q̇ᵢ as ``\\dot{q}_{i}``)."""
    q = tuple(sp.Symbol(f"{name}_{i}", real=True) for i in range(1, n + 1))
    qd = tuple(sp.Symbol(f"{name}dot_{i}", real=True) for i in range(1, n + 1))
    qdd = tuple(sp.Symbol(f"{name}ddot_{i}", real=True) for i in range(1, n + 1))
    return q, qd, qdd


def rotation_about(axis: sp.Matrix, angle: sp.Expr) -> sp.Matrix:
    """Rotation by ``angle`` about the unit ``axis`` (Rodrigues): cos θ 1 + sin θ [a]× + (1 − cos θ) a aᵀ."""
    a = sp.Matrix(axis)
    cross = sp.Matrix([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    c, s = sp.cos(angle), sp.sin(angle)
    return (c * sp.eye(3) + s * cross + (1 - c) * a * a.T).applyfunc(sp.expand)


def rotation_rpy(roll, pitch, yaw) -> sp.Matrix:
    """URDF's fixed-axis roll, pitch, yaw: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    x, y, z = sp.Matrix([1, 0, 0]), sp.Matrix([0, 1, 0]), sp.Matrix([0, 0, 1])
    return rotation_about(z, yaw) * rotation_about(y, pitch) * rotation_about(x, roll)


def homogeneous(rotation: sp.Matrix, position) -> sp.Matrix:
    """The 4×4 transform [[R, p], [0, 1]]."""
    t = sp.eye(4)
    t[:3, :3] = rotation
    t[:3, 3] = sp.Matrix(position)
    return t


def translation(x=0, y=0, z=0) -> sp.Matrix:
    """The 4×4 transform of a pure translation."""
    return homogeneous(sp.eye(3), [x, y, z])


@dataclass(frozen=True)
class Link:
    """One link and the joint that moves it (see the module docstring for the frames)."""

    name: str
    joint: str
    parent: int
    origin: sp.Matrix
    axis: sp.Matrix
    mass: sp.Expr
    com: sp.Matrix
    inertia: sp.Matrix
    stiffness: sp.Expr = sp.S.Zero
    spring_reference: sp.Expr = sp.S.Zero
    damping: sp.Expr = sp.S.Zero
    friction: sp.Expr = sp.S.Zero

    def joint_transform(self, q: sp.Symbol) -> sp.Matrix:
        """The joint's own motion: a rotation about or a translation along ``axis`` by q."""
        if self.joint == "revolute":
            return homogeneous(rotation_about(self.axis, q), [0, 0, 0])
        return homogeneous(sp.eye(3), self.axis * q)


@dataclass(frozen=True)
class PointSpring:
    """A linear spring between ``point_a`` on link ``link_a`` and ``point_b`` on ``link_b`` (link
    index, -1 for the base; points in that link's frame), potential ``½ k (r − r₀)²``."""

    stiffness: sp.Expr
    rest_length: sp.Expr
    link_a: int
    point_a: sp.Matrix
    link_b: int
    point_b: sp.Matrix


@dataclass(frozen=True)
class Chain:
    """A symbolic robot: links in an order where every parent comes before its children.

    ``q``, ``qd``, ``qdd`` are the coordinate, velocity and acceleration symbols, one per link;
    ``gravity`` the gravity acceleration in the base frame; ``values`` the numbers of the symbolic
    parameters a file gave (used by ``lambdify`` and ``codegen`` unless overridden); ``frames``
    extra frames (tool, base) as ``name -> (link index or -1, 4×4 pose in that link)``;
    ``decimals`` whether its numbers are decimals (from a file), which the results then print as;
    ``mimics`` the mimic relations ``{follower: (leader, ratio, offset)}`` (link indices; q_follower
    = ratio q_leader + offset), with which :func:`robodyn.symbolic.lagrange` and
    :func:`robodyn.symbolic.newton_euler` give the equations in the other coordinates
    (:mod:`robodyn.symbolic.mimic`).
    """

    name: str
    links: tuple[Link, ...]
    gravity: sp.Matrix
    q: tuple
    qd: tuple
    qdd: tuple
    values: dict = field(default_factory=dict)
    springs: tuple[PointSpring, ...] = ()
    frames: dict = field(default_factory=dict)
    decimals: bool = False
    mimics: dict = field(default_factory=dict)

    def __post_init__(self):
        if not self.links:
            raise ValueError(f"chain '{self.name}': expected at least one link, got none")
        n = len(self.links)
        if not (len(self.q) == len(self.qd) == len(self.qdd) == n):
            raise ValueError(f"chain '{self.name}': expected {n} coordinate symbols per kind")
        for i, link in enumerate(self.links):
            if link.joint not in JOINT_KINDS:
                raise ValueError(
                    f"link '{link.name}': joint expected one of {JOINT_KINDS}, got '{link.joint}'"
                )
            if not -1 <= link.parent < i:
                raise ValueError(
                    f"link '{link.name}': parent expected an earlier link (-1 for the base), "
                    f"got {link.parent}"
                )
            shapes = {"origin": (4, 4), "axis": (3, 1), "com": (3, 1), "inertia": (3, 3)}
            for attribute, shape in shapes.items():
                value = getattr(link, attribute)
                if getattr(value, "shape", None) != shape:
                    raise ValueError(
                        f"link '{link.name}': {attribute} expected a {shape} matrix, "
                        f"got {getattr(value, 'shape', type(value).__name__)}"
                    )
        for follower, relation in self.mimics.items():
            leader = relation[0] if isinstance(relation, tuple) and len(relation) == 3 else None
            if not (isinstance(follower, int) and isinstance(leader, int) and 0 <= follower < n and 0 <= leader < n):
                raise ValueError(f"chain '{self.name}': mimics expected {{follower: (leader, ratio, offset)}} "
                                 f"with link indices in [0, {n - 1}], got {follower!r}: {relation!r}")
            kinds = (self.links[follower].joint, self.links[leader].joint)
            if follower == leader or kinds[0] != kinds[1]:
                raise ValueError(
                    f"chain '{self.name}': joint '{self.links[follower].name}' ({kinds[0]}) mimics "
                    f"'{self.links[leader].name}' ({kinds[1]}): expected another joint of the same kind")
        if getattr(self.gravity, "shape", None) != (3, 1):
            raise ValueError(f"chain '{self.name}': gravity expected a 3-vector")

    @property
    def n(self) -> int:
        """Number of joints (degrees of freedom)."""
        return len(self.links)

    @property
    def parameters(self) -> list[sp.Symbol]:
        """The symbols of the model other than the coordinates, sorted by name."""
        found = set(self.gravity.free_symbols)
        for link in self.links:
            for value in (link.origin, link.axis, link.mass, link.com, link.inertia, link.stiffness,
                          link.spring_reference, link.damping, link.friction):
                found |= sp.sympify(value).free_symbols
        for spring in self.springs:
            for value in (spring.stiffness, spring.rest_length, spring.point_a, spring.point_b):
                found |= sp.sympify(value).free_symbols
        return sorted(found - set(self.q), key=lambda s: s.name)

    def with_link(self, index: int, **changes) -> "Chain":
        """A copy with link ``index`` changed, e.g. ``chain.with_link(0, damping=b)``."""
        links = list(self.links)
        links[index] = dataclasses.replace(links[index], **{k: _sympify(v) for k, v in changes.items()})
        return dataclasses.replace(self, links=tuple(links))

    def with_joint_springs(self, stiffness, reference=None) -> "Chain":
        """A copy with a spring on every joint: ``stiffness`` and ``reference`` are sequences (one
        per joint) or ``True`` for symbols ``k_i`` and ``q_{r,i}`` (reference 0 when omitted)."""
        stiffness = _per_joint(stiffness, self.n, "k")
        reference = _per_joint(reference if reference is not None else [0] * self.n, self.n, "q_r")
        chain = self
        for i in range(self.n):
            chain = chain.with_link(i, stiffness=stiffness[i], spring_reference=reference[i])
        return chain

    def with_damping(self, damping=True, friction=None) -> "Chain":
        """A copy with viscous damping ``b_i q̇_i`` (and Coulomb friction ``f_i sign(q̇_i)`` when
        ``friction`` is given) on every joint: sequences, or ``True`` for symbols."""
        damping = _per_joint(damping, self.n, "b")
        friction = _per_joint(friction if friction is not None else [0] * self.n, self.n, "f_c")
        chain = self
        for i in range(self.n):
            chain = chain.with_link(i, damping=damping[i], friction=friction[i])
        return chain

    def with_spring(self, stiffness, rest_length, link_a: int, point_a, link_b: int, point_b) -> "Chain":
        """A copy with a linear spring between two points (see :class:`PointSpring`)."""
        for label, link in (("link_a", link_a), ("link_b", link_b)):
            if not -1 <= link < self.n:
                raise ValueError(f"{label}: expected a link index in [-1, {self.n - 1}], got {link}")
        spring = PointSpring(_sympify(stiffness), _sympify(rest_length), link_a,
                             _vector(point_a, "point_a"), link_b, _vector(point_b, "point_b"))
        return dataclasses.replace(self, springs=self.springs + (spring,))

    def substitute(self, values: dict) -> "Chain":
        """A copy with parameters replaced by numbers or expressions (``{m_1: 2.0, …}``)."""
        def sub(x):
            return sp.sympify(x).subs(values)
        links = tuple(
            dataclasses.replace(
                link, origin=sub(link.origin), axis=sub(link.axis), mass=sub(link.mass),
                com=sub(link.com), inertia=sub(link.inertia), stiffness=sub(link.stiffness),
                spring_reference=sub(link.spring_reference), damping=sub(link.damping),
                friction=sub(link.friction),
            )
            for link in self.links
        )
        springs = tuple(
            dataclasses.replace(s, stiffness=sub(s.stiffness), rest_length=sub(s.rest_length),
                                point_a=sub(s.point_a), point_b=sub(s.point_b))
            for s in self.springs
        )
        remaining = {k: v for k, v in self.values.items() if k not in values}
        return dataclasses.replace(self, links=links, springs=springs, gravity=sub(self.gravity),
                                   values=remaining)


def _sympify(value):
    if isinstance(value, (list, tuple)):
        return sp.Matrix(value)
    return sp.sympify(value)


def _vector(value, name: str) -> sp.Matrix:
    vector = sp.Matrix(value)
    if vector.shape != (3, 1):
        raise ValueError(f"{name}: expected 3 coordinates, got shape {vector.shape}")
    return vector


def _per_joint(values, n: int, symbol: str) -> list:
    """``True`` -> symbols ``symbol_i``; otherwise n values."""
    if values is True:
        return [sp.Symbol(f"{symbol}_{i}", real=True) for i in range(1, n + 1)]
    values = list(values)
    if len(values) != n:
        raise ValueError(f"expected {n} values (one per joint) or True, got {len(values)}")
    return [sp.sympify(v) for v in values]
