"""Compare a robodyn model with MuJoCo's model of the same robot: body by body, then quantity by
quantity.

``mujoco_agreement(model, mj_model)`` is the whole comparison, with a verdict
(:class:`MujocoAgreement`; ``print`` it for a summary):

1. Each body's compiled inertia, robodyn's against MuJoCo's (:class:`BodyComparison`): mass,
   centre of mass and the tensor about the centre of mass. robodyn merges a body without joints
   into its parent, so the bodies compared are MuJoCo's weld groups: a body with joints and the
   joint-less bodies welded to it (MuJoCo's ``body_weldid``), merged (masses summed, centres
   averaged by mass, tensors moved to the common centre), in the frame of the group's first body,
   against the robodyn body its last joint moves, brought into that frame by the two bodies'
   poses at the neutral configuration. Bodies welded to the world are left out (robodyn merges
   them into the world, where they move nothing); a robodyn body that no group claims (the
   massless links between the joints of one MuJoCo body) is compared with nothing, so it must be
   massless. Each agrees exactly (``COMPILED_TOLERANCE``) or within MuJoCo's compile noise
   (``MUJOCO_INERTIA_NOISE``: the inertia of a mesh, and of a primitive fitted to one).
2. The quantities below (``mujoco_discrepancies``) against MuJoCo's model with robodyn's
   inertias put in (``with_robodyn_inertias``), at ``DYNAMICS_TOLERANCE``; and against MuJoCo's
   model as compiled, reported only: MuJoCo's compile noise reaches the dynamics there, amplified
   where M is ill-conditioned, and no fixed tolerance could tell it from a bug.

The verdict: "exact" (every body exact, and the dynamics within ``DYNAMICS_TOLERANCE`` of MuJoCo's
model as compiled), "within MuJoCo's compile noise" (some body within the noise, none beyond, and
the dynamics within ``DYNAMICS_TOLERANCE`` with robodyn's inertias) or "disagrees"; the report
names the worst body.

``mujoco_discrepancies(model, mj_model)`` evaluates both at random states and returns, for each
quantity, the largest error relative to the quantity's size (``max|robodyn - mujoco| /
max(1, max|mujoco|)``), after converting MuJoCo's conventions with
:class:`robodyn.convert.MujocoLayout`. The quantities:

- ``"M"``: the joint-space inertia matrix (``mj_fullM``, armature included);
- ``"bias"``: C(q, v) v + g(q) (from ``qfrc_bias``);
- ``"forward_dynamics"``: q̈ for random τ (``qacc`` with ``qfrc_applied = τ``);
- ``"inverse_dynamics"``: τ for random q̈ (``mj_rne``, plus the armature times ``qacc`` it leaves out);
- ``"body_pose"``, ``"site_pose"``: every named body's and site's position and rotation (an unnamed one
  has no name to find it by in robodyn);
- ``"jacobian"``: every body's world-aligned Jacobian (``mj_jacBody``);
- ``"jacobian_dot_v"``: every body's J̇v, the classical acceleration at q̈ = 0 (``mj_jacDot``).

MuJoCo is made a rigid-body model first: damping, friction loss, springs, gravity compensation,
fluid forces, constraints and actuators are switched off on the ``mj_model`` passed in (its armature stays: robodyn models it too).
``mujoco`` is imported only when this is called.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import numpy as np

from .convert import MujocoLayout
from .inertia import principal_axes, shift_from_com, shift_to_com

__all__ = [
    "COMPILED_TOLERANCE",
    "DISAGREES",
    "DYNAMICS_TOLERANCE",
    "EXACT",
    "MUJOCO_INERTIA_NOISE",
    "WITHIN_NOISE",
    "BodyComparison",
    "MujocoAgreement",
    "compare_bodies",
    "measure_mujoco_inertia_noise",
    "mujoco_agreement",
    "mujoco_discrepancies",
    "rigid_body_only",
    "with_robodyn_inertias",
]

#: A body's compiled inertia, robodyn's against MuJoCo's, where both compilers do the same
#: arithmetic: mass (relative to the mass), centre of mass (relative to the larger of its distance
#: from the body's origin and the body's size √(tr I / m)), tensor (relative to its trace).
COMPILED_TOLERANCE = 1e-12
#: MuJoCo's compile noise on the inertia of a body whose mass comes from a mesh, relative to the
#: tensor's trace (its nuclear norm, so the bound also holds for bodies merged into one).
#: Measured by ``measure_mujoco_inertia_noise`` (MuJoCo 4.0.0): over 3 000 tetrahedra whose exact
#: inertia is known, MuJoCo's tensor is off by up to 4.8e-8 of its trace (99th percentile 3.9e-8,
#: median 8e-10; mass and centre of mass exact to 1e-14), about single precision (2^-24 = 6e-8).
#: The bound is that figure rounded up to 1e-7. MuJoCo's eigensolver is not the cause: a
#: ``fullinertia`` of any axes and magnitude is compiled to 1e-14, and ``mju_eig3`` reproduces
#: its input to 7e-15, nearly diagonal ones included. A primitive fitted to a mesh (``fitaabb``)
#: is sized along the mesh's noisy axes, so its mass and centre of mass carry the noise too (2e-9
#: and 3e-9 in testdata/mjcf/mesh_fitaabb.xml).
MUJOCO_INERTIA_NOISE = 1e-7
#: The dynamics, kinematics and Jacobians against MuJoCo, relative to each quantity's size (or 1).
DYNAMICS_TOLERANCE = 1e-9

#: The verdicts, of a body and of a model.
EXACT = "exact"
WITHIN_NOISE = "within MuJoCo's compile noise"
DISAGREES = "disagrees"


def rigid_body_only(mj_model):
    """Switches off what robodyn's dynamics calls leave out: joint damping, friction loss and
    springs, tendon springs and dampers, gravity compensation (``gravcomp``), the medium's forces
    (density, viscosity, wind), constraints (limits, contacts, equalities) and actuators. Returns
    ``mj_model``."""
    import mujoco

    mj_model.opt.density = 0.0
    mj_model.opt.viscosity = 0.0
    mj_model.opt.wind[:] = 0.0
    mj_model.body_gravcomp[:] = 0.0
    mj_model.tendon_stiffness[:] = 0.0
    mj_model.tendon_damping[:] = 0.0
    mj_model.dof_damping[:] = 0.0
    mj_model.dof_frictionloss[:] = 0.0
    mj_model.jnt_stiffness[:] = 0.0
    mj_model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT | mujoco.mjtDisableBit.mjDSBL_ACTUATION
    return mj_model


def _relative_error(actual, expected) -> float:
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    if actual.shape != expected.shape:
        return float("inf")
    scale = max(1.0, float(np.max(np.abs(expected)))) if expected.size else 1.0
    return float(np.max(np.abs(actual - expected))) / scale if expected.size else 0.0


def mujoco_discrepancies(model, mj_model, seed: int = 0, states: int = 3) -> dict[str, float]:
    """The largest relative error of each quantity (see the module's docstring) over ``states``
    random states drawn with ``seed``."""
    import mujoco

    rigid_body_only(mj_model)
    layout = MujocoLayout(model, mj_model)
    data = mujoco.MjData(mj_model)
    errors: dict[str, float] = {}

    def record(name, actual, expected):
        errors[name] = max(errors.get(name, 0.0), _relative_error(actual, expected))

    rng = np.random.default_rng(seed)
    nv = mj_model.nv
    jacp, jacr = np.zeros((3, nv)), np.zeros((3, nv))
    jacp_dot, jacr_dot = np.zeros((3, nv)), np.zeros((3, nv))
    for k in range(states):
        q = model.random_configuration(seed=seed + k)
        v, a, tau = (rng.uniform(-1, 1, model.nv) for _ in range(3))
        v_mj = layout.v_to_mujoco(q, v)
        data.qpos[:], data.qvel[:] = layout.q_to_mujoco(q), v_mj
        data.qfrc_applied[:] = layout.force_to_mujoco(q, tau)
        mujoco.mj_forward(mj_model, data)
        # dynamics
        mass = np.zeros((nv, nv))
        mujoco.mj_fullM(mj_model, data, mass)
        record("M", model.mass_matrix(q), layout.matrix_from_mujoco(q, mass))
        record("bias", model.bias_forces(q, v), layout.bias_from_mujoco(q, v, data.qfrc_bias, mass))
        record("forward_dynamics", model.forward_dynamics(q, v, tau), layout.a_from_mujoco(q, v, data.qacc))
        # frames: the point's acceleration at robodyn q̈ = 0 is J_mj a_mj + J̇_mj v_mj
        a_mj = layout.a_to_mujoco(q, v, np.zeros(model.nv))
        # bodies and sites by name (an unnamed one has no name to find it by in robodyn)
        for body in range(1, mj_model.nbody):
            name = mj_model.body(body).name
            if not name:
                continue
            pose = model.frame_pose(q, name)
            record("body_pose", pose[:3, 3], data.xpos[body])
            record("body_pose", pose[:3, :3], data.xmat[body].reshape(3, 3))
            mujoco.mj_jacBody(mj_model, data, jacp, jacr, body)
            jacobian = np.vstack([jacp, jacr])
            record("jacobian", model.jacobian(q, name), layout.jacobian_from_mujoco(q, jacobian))
            mujoco.mj_jacDot(mj_model, data, jacp_dot, jacr_dot, data.xpos[body], body)
            expected = jacobian @ a_mj + np.vstack([jacp_dot, jacr_dot]) @ v_mj
            record("jacobian_dot_v", model.jacobian_time_variation(q, v, name) @ v, expected)
        for site in range(mj_model.nsite):
            if not mj_model.site(site).name:
                continue
            pose = model.frame_pose(q, mj_model.site(site).name)
            record("site_pose", pose[:3, 3], data.site_xpos[site])
            record("site_pose", pose[:3, :3], data.site_xmat[site].reshape(3, 3))
        # inverse dynamics last: it overwrites qacc; mj_rne leaves out the rotors' armature · qacc
        result = np.zeros(nv)
        data.qacc[:] = layout.a_to_mujoco(q, v, a)
        mujoco.mj_rne(mj_model, data, 1, result)
        result += mj_model.dof_armature * data.qacc
        record("inverse_dynamics", model.inverse_dynamics(q, v, a), layout.force_from_mujoco(q, result))
    return errors


@dataclass(frozen=True)
class BodyComparison:
    """One body's compiled inertia, robodyn's against MuJoCo's (a weld group's, merged): the
    mass error relative to the mass, the centre of mass's relative to the larger of its distance
    from the body's origin and the body's size √(tr I / m), the tensor's (about the centre of
    mass, spectral norm of the difference) relative to its trace. Zero where both are massless."""

    body: str
    mass: float
    center_of_mass: float
    inertia: float

    @property
    def largest(self) -> float:
        """The largest of the three errors."""
        return max(self.mass, self.center_of_mass, self.inertia)

    @property
    def verdict(self) -> str:
        """"exact", "within MuJoCo's compile noise" or "disagrees", by the largest error."""
        if self.largest <= COMPILED_TOLERANCE:
            return EXACT
        return WITHIN_NOISE if self.largest <= MUJOCO_INERTIA_NOISE else DISAGREES

    def __str__(self) -> str:
        return f"'{self.body}' (mass {self.mass:.1e}, centre of mass {self.center_of_mass:.1e}, inertia {self.inertia:.1e} of its trace)"


@dataclass(frozen=True)
class MujocoAgreement:
    """What ``mujoco_agreement`` found: each body (:class:`BodyComparison`), the largest relative
    error of each quantity of ``mujoco_discrepancies`` against MuJoCo's model with robodyn's
    inertias put in (``dynamics``, judged) and as MuJoCo compiled it (``dynamics_as_compiled``,
    reported), and the verdict: "exact", "within MuJoCo's compile noise" or "disagrees" (see the
    module). ``print`` gives a summary naming the worst body."""

    name: str
    bodies: tuple[BodyComparison, ...]
    dynamics: dict[str, float] = field(default_factory=dict)
    dynamics_as_compiled: dict[str, float] = field(default_factory=dict)

    @property
    def worst_body(self) -> BodyComparison | None:
        """The body with the largest error (of its mass, centre of mass or tensor)."""
        return max(self.bodies, key=lambda b: b.largest, default=None)

    @property
    def verdict(self) -> str:
        """The model's verdict (see the module)."""
        verdicts = {body.verdict for body in self.bodies}
        if DISAGREES in verdicts or _worst(self.dynamics)[1] > DYNAMICS_TOLERANCE:
            return DISAGREES
        if verdicts <= {EXACT} and _worst(self.dynamics_as_compiled)[1] <= DYNAMICS_TOLERANCE:
            return EXACT
        return WITHIN_NOISE

    def __str__(self) -> str:
        quantity, error = _worst(self.dynamics)
        as_compiled, compiled_error = _worst(self.dynamics_as_compiled)
        lines = [
            f"{self.name}: {self.verdict}",
            f"  bodies: {len(self.bodies)} compared (mass, centre of mass and inertia tensor): exact to "
            f"{COMPILED_TOLERANCE:.0e}, or within MuJoCo's compile noise {MUJOCO_INERTIA_NOISE:.0e}",
        ]
        if self.worst_body is not None:
            lines.append(f"  worst body: {self.worst_body}: {self.worst_body.verdict}")
        lines.append(f"  dynamics with robodyn's inertias in MuJoCo: largest relative error {error:.1e} ({quantity}), "
                     f"tolerance {DYNAMICS_TOLERANCE:.0e}")
        lines.append(f"  dynamics with MuJoCo's compiled inertias: largest relative error {compiled_error:.1e} ({as_compiled}), "
                     "reported only")
        return "\n".join(lines)


def _worst(errors: dict[str, float]) -> tuple[str, float]:
    """The quantity with the largest error, and that error."""
    return max(errors.items(), key=lambda item: item[1], default=("nothing", 0.0))


@dataclass(frozen=True)
class _Inertia:
    """A body's mass, centre of mass and inertia about the centre of mass, in one frame."""

    mass: float
    com: np.ndarray
    tensor: np.ndarray

    def moved(self, rotation: np.ndarray, translation: np.ndarray) -> _Inertia:
        """The same body in a frame whose coordinates are rotation @ x + translation."""
        return _Inertia(self.mass, rotation @ self.com + translation, rotation @ self.tensor @ rotation.T)


def _merged(parts: list[_Inertia]) -> _Inertia:
    """Bodies fixed together as one: masses summed, centres averaged by mass, each tensor moved to
    the common centre (parallel axes)."""
    mass = sum(part.mass for part in parts)
    if mass == 0.0:
        return _Inertia(0.0, np.zeros(3), sum((part.tensor for part in parts), np.zeros((3, 3))))
    com = sum((part.mass * part.com for part in parts), np.zeros(3)) / mass
    tensor = sum((shift_from_com(part.tensor, part.mass, part.com - com) for part in parts), np.zeros((3, 3)))
    return _Inertia(mass, com, tensor)


def _rotation_of(quaternion_wxyz: np.ndarray) -> np.ndarray:
    """The rotation matrix of a MuJoCo quaternion (w first)."""
    import mujoco

    matrix = np.zeros(9)
    mujoco.mju_quat2Mat(matrix, np.asarray(quaternion_wxyz, dtype=float))
    return matrix.reshape(3, 3)


def _mujoco_body(mj_model: Any, body: int) -> _Inertia:
    """MuJoCo's compiled inertia of one body, in the body's frame."""
    axes = _rotation_of(mj_model.body_iquat[body])
    return _Inertia(float(mj_model.body_mass[body]), np.array(mj_model.body_ipos[body]), axes @ np.diag(mj_model.body_inertia[body]) @ axes.T)


def _in_root_frame(mj_model: Any, root: int, body: int) -> tuple[np.ndarray, np.ndarray]:
    """(R, p) of `body` in the frame of `root`, an ancestor it is welded to: x_root = R x_body + p."""
    rotation, translation = np.eye(3), np.zeros(3)
    while body != root:
        local = _rotation_of(mj_model.body_quat[body])
        rotation, translation = local @ rotation, local @ translation + mj_model.body_pos[body]
        body = int(mj_model.body_parentid[body])
    return rotation, translation


def _weld_groups(mj_model: Any) -> dict[int, list[int]]:
    """MuJoCo's bodies with joints, each with the joint-less bodies welded to it (itself first).
    A mocap body is its own weld root without a joint: robodyn welds it, and what is welded to
    it, to the world, so it is left out like the world's group."""
    groups: dict[int, list[int]] = {}
    for body in range(1, mj_model.nbody):
        root = int(mj_model.body_weldid[body])
        if root != 0 and mj_model.body_jntnum[root] > 0:
            groups.setdefault(root, []).append(body)
    return groups


def _robodyn_body(parameters: np.ndarray) -> _Inertia:
    """robodyn's ten inertial parameters [m, m c, I about the origin] as a body, in its frame."""
    mass, first_moment = float(parameters[0]), np.asarray(parameters[1:4])
    xx, xy, yy, xz, yz, zz = parameters[4:]
    about_origin = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    if mass == 0.0:
        return _Inertia(0.0, np.zeros(3), about_origin)
    com = first_moment / mass
    return _Inertia(mass, com, shift_to_com(about_origin, mass, com))


def _compare(body: str, robodyn: _Inertia, mujoco: _Inertia) -> BodyComparison:
    mass_scale = max(robodyn.mass, mujoco.mass)
    trace = max(float(np.trace(robodyn.tensor)), float(np.trace(mujoco.tensor)))
    inertia = _ratio(float(np.linalg.norm(robodyn.tensor - mujoco.tensor, 2)), trace)
    if mass_scale == 0.0:
        return BodyComparison(body, 0.0, 0.0, inertia)
    length = max(float(np.linalg.norm(mujoco.com)), np.sqrt(trace / mass_scale))
    return BodyComparison(
        body,
        mass=abs(robodyn.mass - mujoco.mass) / mass_scale,
        center_of_mass=_ratio(float(np.linalg.norm(robodyn.com - mujoco.com)), length),
        inertia=inertia,
    )


def _ratio(error: float, scale: float) -> float:
    """error / scale, 0 where both are 0."""
    return 0.0 if error == 0.0 else (error / scale if scale > 0.0 else float("inf"))


def _paired_inertias(model: Any, mj_model: Any) -> list[tuple[str, int, _Inertia, _Inertia]]:
    """(name, MuJoCo root body, robodyn's inertia, MuJoCo's merged inertia) of every weld group,
    both in the root's frame, then each robodyn body that no group claims against nothing."""
    import mujoco

    layout = MujocoLayout(model, mj_model)
    q = model.neutral()
    data = mujoco.MjData(mj_model)
    data.qpos[:] = layout.q_to_mujoco(q)
    mujoco.mj_kinematics(mj_model, data)
    parameters = np.asarray(model.inertial_parameters)
    # robodyn's moving body k is moved by its joint k and has row k of the parameters
    robodyn_of_joint = {j: k for k, j in enumerate(layout.mujoco_joints)}
    # each body's own frame: the first on it with its name (a site may share the name)
    frame_of_body: dict[int, int] = {}
    for index, (name, body) in enumerate(zip(model.frame_names, model.frame_bodies)):
        if body >= 0 and name == model.body_names[body]:
            frame_of_body.setdefault(body, index)
    pairs = []
    claimed = set()
    for root, members in _weld_groups(mj_model).items():
        last_joint = int(mj_model.body_jntadr[root] + mj_model.body_jntnum[root] - 1)
        body = robodyn_of_joint[last_joint]
        claimed.add(body)
        merged = _merged([_mujoco_body(mj_model, b).moved(*_in_root_frame(mj_model, root, b)) for b in members])
        pose = np.asarray(model.frame_pose(q, frame_of_body[body]))
        # MuJoCo's root frame in robodyn's body frame, from the two world poses
        rotation = pose[:3, :3].T @ data.xmat[root].reshape(3, 3)
        translation = pose[:3, :3].T @ (data.xpos[root] - pose[:3, 3])
        ours = _robodyn_body(parameters[body]).moved(rotation.T, -rotation.T @ translation)
        pairs.append((mj_model.body(root).name or model.body_names[body], root, ours, merged))
    for body in range(len(model.body_names)):
        if body not in claimed:
            pairs.append((model.body_names[body], -1, _robodyn_body(parameters[body]), _Inertia(0.0, np.zeros(3), np.zeros((3, 3)))))
    return pairs


def compare_bodies(model: Any, mj_model: Any) -> tuple[BodyComparison, ...]:
    """Each body's compiled mass, centre of mass and inertia tensor, robodyn's against MuJoCo's
    (MuJoCo's weld groups merged as robodyn merges them; see the module)."""
    return tuple(_compare(name, ours, theirs) for name, _, ours, theirs in _paired_inertias(model, mj_model))


def with_robodyn_inertias(model: Any, mj_model: Any) -> Any:
    """A copy of ``mj_model`` with robodyn's compiled inertias: each weld group's root body gets
    robodyn's mass, centre of mass and tensor (as principal moments and axes), the rest of the
    group none (robodyn holds them merged); then ``mj_setConst``. The inertias themselves are
    compared by ``compare_bodies``; this lets the dynamics be compared without MuJoCo's noise."""
    import mujoco

    substituted = copy.deepcopy(mj_model)
    groups = _weld_groups(mj_model)
    for _, root, ours, _ in _paired_inertias(model, mj_model):
        if root < 0:
            continue
        moments, axes = principal_axes(ours.tensor)
        quaternion = np.zeros(4)
        mujoco.mju_mat2Quat(quaternion, axes.reshape(-1))
        for member in groups[root]:
            substituted.body_mass[member] = 0.0
            substituted.body_ipos[member] = 0.0
            substituted.body_iquat[member] = [1.0, 0.0, 0.0, 0.0]
            substituted.body_inertia[member] = 0.0
        substituted.body_mass[root] = ours.mass
        substituted.body_ipos[root] = ours.com
        substituted.body_iquat[root] = quaternion
        substituted.body_inertia[root] = np.maximum(moments, 0.0)
    # mj_setConst refuses a body compiled as "simple" (its own inertial frame, a diagonal mass
    # block) whose inertia moved; cleared, it works the inertial frames out again, but leaves the
    # dofs' count of simple neighbours (read when M is factorised), so that is cleared too
    substituted.body_simple[:] = 0
    substituted.dof_simplenum[:] = 0
    mujoco.mj_setConst(substituted, mujoco.MjData(substituted))
    return substituted


def mujoco_agreement(model: Any, mj_model: Any, seed: int = 0, states: int = 3, name: str | None = None) -> MujocoAgreement:
    """The whole comparison of a robodyn model with MuJoCo's (see the module): every body's
    compiled inertia, then ``mujoco_discrepancies`` with robodyn's tensors substituted into
    MuJoCo's model and with MuJoCo's own, over ``states`` random states drawn with ``seed``."""
    rigid_body_only(mj_model)
    bodies = compare_bodies(model, mj_model)
    substituted = with_robodyn_inertias(model, mj_model)
    return MujocoAgreement(
        name=model.name if name is None else name,
        bodies=bodies,
        dynamics=mujoco_discrepancies(model, substituted, seed=seed, states=states),
        dynamics_as_compiled=mujoco_discrepancies(model, mj_model, seed=seed, states=states),
    )


def _tetrahedron(corners: list[list[Fraction]], density: int) -> _Inertia:
    """The exact inertia of a solid tetrahedron (rational arithmetic, then rounded once): mass,
    centroid, and I = tr(C) 1 − C about the centroid, C = m/20 (Σ pᵢpᵢᵀ + s sᵀ) − m c cᵀ with
    s = Σ pᵢ (the second moment of a tetrahedron about the origin)."""
    a, b, c, d = corners
    edges = [[p[i] - a[i] for i in range(3)] for p in (b, c, d)]
    volume = (
        edges[0][0] * (edges[1][1] * edges[2][2] - edges[1][2] * edges[2][1])
        - edges[0][1] * (edges[1][0] * edges[2][2] - edges[1][2] * edges[2][0])
        + edges[0][2] * (edges[1][0] * edges[2][1] - edges[1][1] * edges[2][0])
    ) / 6
    mass = density * volume
    total = [sum(p[i] for p in corners) for i in range(3)]
    centroid = [x / 4 for x in total]
    second = [[mass / 20 * (sum(p[i] * p[j] for p in corners) + total[i] * total[j]) - mass * centroid[i] * centroid[j]
               for j in range(3)] for i in range(3)]
    trace = second[0][0] + second[1][1] + second[2][2]
    tensor = [[(trace if i == j else 0) - second[i][j] for j in range(3)] for i in range(3)]
    return _Inertia(float(mass), np.array([float(x) for x in centroid]), np.array([[float(x) for x in row] for row in tensor]))


def measure_mujoco_inertia_noise(samples: int = 3000, seed: int = 0) -> BodyComparison:
    """MuJoCo's compile noise on a mesh's inertia: the largest error of its mass, centre of mass
    and tensor (as :class:`BodyComparison` measures them) over ``samples`` bodies, each one mesh
    geom, a random tetrahedron whose corners are multiples of 1/64 (exact in MuJoCo's
    single-precision vertices) and whose inertia is computed exactly: the figure
    ``MUJOCO_INERTIA_NOISE`` bounds."""
    import mujoco

    rng = np.random.default_rng(seed)
    worst = BodyComparison("tetrahedra", 0.0, 0.0, 0.0)
    for _ in range(samples):
        corners = rng.integers(-64, 65, size=(4, 3))
        orientation = np.linalg.det((corners[1:] - corners[0]).astype(float))
        if abs(orientation) < 1000.0:
            continue  # too flat to be a body
        if orientation < 0:
            corners[[1, 2]] = corners[[2, 1]]
        exact = _tetrahedron([[Fraction(int(x), 64) for x in corner] for corner in corners], density=1000)
        vertices = " ".join(repr(x / 64) for x in corners.reshape(-1).tolist())
        xml = (f"<mujoco><asset><mesh name='t' vertex='{vertices}' face='0 2 1 0 1 3 0 3 2 1 2 3'/></asset>"
               "<worldbody><body><joint/><geom type='mesh' mesh='t' density='1000'/></body></worldbody></mujoco>")
        found = _compare("tetrahedra", _mujoco_body(mujoco.MjModel.from_xml_string(xml), 1), exact)
        worst = BodyComparison("tetrahedra", *(max(getattr(worst, f), getattr(found, f)) for f in ("mass", "center_of_mass", "inertia")))
    return worst
