"""The inertia tensor, as the TU Berlin notes ("Inertia Tensor") and the UR5 dynamics notes ("Relation between I and I_b")
teach it: tensors of primitive solids, the parallel-axis theorem, rotation, principal axes, a
physical-validity check, and the spatial inertia built from (mass, centre of mass, inertia).

Every tensor is a 3×3 NumPy array with the products of inertia carried with their sign, as the
notes write it::

        [  I_xx  -I_xy  -I_xz ]          I_xx = ∭ (y² + z²) ρ dV,   I_xy = ∭ x y ρ dV, ...
    I = [ -I_xy   I_yy  -I_yz ]
        [ -I_xz  -I_yz   I_zz ]

Primitives are solids of uniform density (hollow ones say what is hollow), about their centre of
mass in axes along their symmetry axes unless ``about`` says otherwise; lengths in m, masses in kg.
"""

from __future__ import annotations

import numpy as np

from robodyn import _core
from robodyn._arguments import array, choice, positive, real

__all__ = [
    "solid_box",
    "solid_sphere",
    "hollow_sphere",
    "solid_cylinder",
    "hollow_cylinder",
    "capsule",
    "rod",
    "shift_from_com",
    "shift_to_com",
    "rotate",
    "principal_axes",
    "check_physical",
    "spatial_inertia",
    "from_spatial_inertia",
]

#: Relative slack for the symmetry check (the rest of the rule is the core's, with its tolerance).
VALIDITY_TOLERANCE = 1e-12

_AXES = {"x": 0, "y": 1, "z": 2}


def _axis_index(axis: str) -> int:
    return _AXES[choice("axis", axis, tuple(_AXES))]


def _about_axis(along: float, across: float, axis: str) -> np.ndarray:
    """diag with `along` on the symmetry axis and `across` on the other two."""
    moments = np.full(3, across)
    moments[_axis_index(axis)] = along
    return np.diag(moments)


def solid_box(mass: float, size, about: str = "center") -> np.ndarray:
    """A box with side lengths ``size = (a, b, c)`` along x, y, z. ``about="center"``:
    diag(m(b²+c²)/12, m(a²+c²)/12, m(a²+b²)/12). ``about="corner"``: about the corner at the
    origin with the box along +x, +y, +z (the TU Berlin notes' example, sides w, l, h):
    I_xx = m/3 (b² + c²), I_xy = m/4 a b, …, i.e. the matrix [[m/3(l²+h²), −m/4 wl, −m/4 hw], …]."""
    mass = positive("mass", mass)
    a, b, c = (positive("size", s) for s in array("size", size, (3,)))
    squares = np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    if about == "center":
        return np.diag(mass * squares / 12.0)
    if about == "corner":
        products = mass / 4.0 * np.array([[0.0, a * b, a * c], [a * b, 0.0, b * c], [a * c, b * c, 0.0]])
        return np.diag(mass * squares / 3.0) - products
    raise ValueError(f"argument 'about': expected 'center' or 'corner', got {about!r}")


def solid_sphere(mass: float, radius: float) -> np.ndarray:
    """⅖ m r² about every axis through the centre."""
    return np.eye(3) * 0.4 * positive("mass", mass) * positive("radius", radius) ** 2


def hollow_sphere(mass: float, radius: float, inner_radius: float = 0.0) -> np.ndarray:
    """A spherical shell between ``inner_radius`` and ``radius``:
    ⅖ m (r⁵ − rᵢ⁵)/(r³ − rᵢ³); ``inner_radius = 0`` (the default) is a thin shell, ⅔ m r²."""
    mass, radius = positive("mass", mass), positive("radius", radius)
    if inner_radius == 0.0:
        return np.eye(3) * 2.0 / 3.0 * mass * radius**2
    inner = positive("inner_radius", inner_radius)
    if inner >= radius:
        raise ValueError(f"argument 'inner_radius': expected less than radius {radius}, got {inner}")
    return np.eye(3) * 0.4 * mass * (radius**5 - inner**5) / (radius**3 - inner**3)


def solid_cylinder(mass: float, radius: float, length: float, axis: str = "z") -> np.ndarray:
    """m r²/2 along the axis, m(3r² + L²)/12 across."""
    mass, radius, length = positive("mass", mass), positive("radius", radius), positive("length", length)
    return _about_axis(mass * radius**2 / 2.0, mass * (3.0 * radius**2 + length**2) / 12.0, axis)


def hollow_cylinder(mass: float, radius: float, length: float, inner_radius: float = 0.0, axis: str = "z") -> np.ndarray:
    """A tube between ``inner_radius`` and ``radius``: m(r² + rᵢ²)/2 along the axis,
    m(3(r² + rᵢ²) + L²)/12 across; ``inner_radius = 0`` is a thin-walled tube (rᵢ = r)."""
    mass, radius, length = positive("mass", mass), positive("radius", radius), positive("length", length)
    inner = radius if inner_radius == 0.0 else positive("inner_radius", inner_radius)
    if inner > radius:
        raise ValueError(f"argument 'inner_radius': expected at most radius {radius}, got {inner}")
    squares = radius**2 + inner**2
    return _about_axis(mass * squares / 2.0, mass * (3.0 * squares + length**2) / 12.0, axis)


def capsule(mass: float, radius: float, length: float, axis: str = "z") -> np.ndarray:
    """A cylinder of ``length`` capped by two hemispheres of ``radius`` (MuJoCo's capsule), the mass
    shared by volume: cylinder m_c, hemispheres together m_s;
    across m_c(L²/12 + r²/4) + m_s(2r²/5 + L²/4 + 3Lr/8), along m_c r²/2 + m_s 2r²/5."""
    mass, r, length = positive("mass", mass), positive("radius", radius), positive("length", length)
    cylinder, sphere = np.pi * r * r * length, 4.0 / 3.0 * np.pi * r**3
    m_c, m_s = mass * cylinder / (cylinder + sphere), mass * sphere / (cylinder + sphere)
    across = m_c * (length**2 / 12.0 + r * r / 4.0) + m_s * (0.4 * r * r + length**2 / 4.0 + 3.0 * length * r / 8.0)
    return _about_axis(m_c * r * r / 2.0 + m_s * 0.4 * r * r, across, axis)


def rod(mass: float, length: float, axis: str = "z", about: str = "center") -> np.ndarray:
    """A thin rod along ``axis``: m L²/12 across about its centre, m L²/3 about an end
    (``about="end"``, the end at the origin, the rod along +axis), 0 along it."""
    mass, length = positive("mass", mass), positive("length", length)
    if about == "center":
        return _about_axis(0.0, mass * length**2 / 12.0, axis)
    if about == "end":
        return _about_axis(0.0, mass * length**2 / 3.0, axis)
    raise ValueError(f"argument 'about': expected 'center' or 'end', got {about!r}")


def _point_term(mass: float, p: np.ndarray) -> np.ndarray:
    """m [(pᵀp) 1 − p pᵀ]: what the parallel-axis theorem adds."""
    return mass * (p @ p * np.eye(3) - np.outer(p, p))


def shift_from_com(inertia_com, mass: float, com) -> np.ndarray:
    """Parallel-axis theorem (the TU Berlin notes): the inertia about a frame's origin A, given the inertia
    about the centre of mass C (same axes) and C's position p_C in A:
    ᴬI = ᶜI + m [(p_Cᵀ p_C) 1 − p_C p_Cᵀ]."""
    return array("inertia_com", inertia_com, (3, 3)) + _point_term(real("mass", mass), array("com", com, (3,)))


def shift_to_com(inertia, mass: float, com) -> np.ndarray:
    """The parallel-axis theorem backwards: ᶜI = ᴬI − m [(p_Cᵀ p_C) 1 − p_C p_Cᵀ]."""
    return array("inertia", inertia, (3, 3)) - _point_term(real("mass", mass), array("com", com, (3,)))


def rotate(inertia, rotation) -> np.ndarray:
    """The same tensor in other axes (the TU Berlin notes "Rotation Transformation"): ᴮI = ᴮR_A ᴬI ᴮR_Aᵀ,
    with ``rotation`` = ᴮR_A mapping A coordinates to B coordinates."""
    rotation = array("rotation", rotation, (3, 3))
    if not np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-9) or np.linalg.det(rotation) <= 0:
        raise ValueError("argument 'rotation': expected a rotation matrix (orthonormal, det +1)")
    return rotation @ array("inertia", inertia, (3, 3)) @ rotation.T


def principal_axes(inertia) -> tuple[np.ndarray, np.ndarray]:
    """Principal moments (eigenvalues, ascending) and principal axes (the eigenvectors as the
    columns of a right-handed rotation R), so that inertia = R diag(moments) Rᵀ."""
    inertia = array("inertia", inertia, (3, 3))
    moments, axes = np.linalg.eigh(0.5 * (inertia + inertia.T))
    if np.linalg.det(axes) < 0:
        axes[:, 2] = -axes[:, 2]
    return moments, axes


def check_physical(inertia, mass: float | None = None) -> None:
    """Raises ValueError unless the tensor (about the centre of mass) could belong to a rigid body:
    symmetric, positive semi-definite, and its principal moments obey the triangle inequality
    I₁ + I₂ ≥ I₃ (the notes' "facts about inertia tensors"); ``mass``, when given, must be positive.

    This is robodyn's one rule for physical inertias, the same code the loaders and the
    ``Model.inertial_parameters`` setter apply. They differ only in what follows a tensor that
    breaks the triangle inequality alone (every algorithm still computes with it): a loaded file
    and the setter report it as a ``ModelWarning`` (``load(..., strict=True)`` refuses it), while
    this check raises."""
    inertia = array("inertia", inertia, (3, 3))
    scale = max(1e-300, float(np.abs(inertia).max()))
    if mass is not None:
        mass = positive("mass", mass)
    if np.abs(inertia - inertia.T).max() > VALIDITY_TOLERANCE * scale:
        raise ValueError(f"argument 'inertia': expected a symmetric matrix, got {inertia.tolist()}")
    # the ten parameters [m, m c, I] of a body whose centre of mass is its origin
    i = inertia
    parameters = [1.0 if mass is None else float(mass), 0.0, 0.0, 0.0, i[0, 0], i[0, 1], i[1, 1], i[0, 2], i[1, 2], i[2, 2]]
    try:
        _core.check_physical_parameters(parameters)
    except ValueError as error:
        raise ValueError(f"argument 'inertia': {error}") from None


def spatial_inertia(mass: float, com, inertia_com) -> np.ndarray:
    """The 6×6 spatial inertia about a frame's origin, acting on [linear; angular] velocities
    (robodyn's order) to give [force; moment] momenta:
    [[m 1, −m c×], [m c×, ᶜI − m c× c×]] (Featherstone eq. 2.63, reordered)."""
    c = array("com", com, (3,))
    cross = np.array([[0.0, -c[2], c[1]], [c[2], 0.0, -c[0]], [-c[1], c[0], 0.0]])
    mass = real("mass", mass)
    return np.block([[mass * np.eye(3), -mass * cross], [mass * cross, array("inertia_com", inertia_com, (3, 3)) - mass * cross @ cross]])


def from_spatial_inertia(matrix) -> tuple[float, np.ndarray, np.ndarray]:
    """(mass, centre of mass, inertia about the centre of mass) from a 6×6 spatial inertia in
    robodyn's [linear; angular] order; the inverse of :func:`spatial_inertia`."""
    matrix = array("matrix", matrix, (6, 6))
    mass = float(matrix[0, 0])
    if mass <= 0.0:
        raise ValueError(f"argument 'matrix': expected a positive mass in entry (0, 0), got {mass}")
    # the lower-left block is m c×
    h = matrix[3:, :3]
    com = np.array([h[2, 1], h[0, 2], h[1, 0]]) / mass
    return mass, com, shift_to_com(matrix[3:, 3:], mass, com)
