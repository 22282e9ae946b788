"""Mimic joints enforced: a model in reduced coordinates (``robodyn.load(path, mimic=True)``).

A URDF ``<mimic joint="l" multiplier="r" offset="o"/>`` on joint f says q_f = r q_l + o. Kept in
the model's own coordinates (the default), f is a joint of its own and the relation a
:class:`robodyn.JointCoupling` that simulation holds. In reduced coordinates the follower has no
coordinate: q_red holds every other coordinate, in the model's order, and

    q = A q_red + b,    v = G v_red,    a = G a_red,

with A and G copying each kept coordinate and giving each follower r times its leader's (b its
offset; a leader that follows another is resolved to the first, so chains compose). G is constant,
so every quantity of the reduced model is the full model's at the expanded state, mapped by G
(the principle of virtual work: generalized forces map by Gᵀ):

    τ_red = Gᵀ τ,   M_red = Gᵀ M G,   C_red = Gᵀ C G,   g_red = Gᵀ g,   J_red = J G,
    q̈_red = M_red⁻¹ (τ_red − Gᵀ h),   ∂τ_red/∂q_red = Gᵀ (∂τ/∂q) G,   Γ_red = Γ ×₁ G ×₂ G ×₃ G.

Ṁ_red − 2 C_red = Gᵀ (Ṁ − 2C) G stays skew, and the follower's armature, damping, friction and
spring act through the transmission (its armature adds r² to its leader's). The leader may come
anywhere in the tree, before or after its follower. The passive forces and the simulation: a run
of the full model that holds each relation as a :class:`robodyn.JointCoupling` integrates the same
equations (the relations are linear in q, so the integrator's stages keep them to round-off), and
its record is mapped to q_red.

Properties in reduced coordinates (``armature``, the limits, …) are computed from the full model,
``m.full``: set values there.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robodyn import _core
from robodyn._arguments import bad, count, flag, numbers, positive, real
from robodyn._mimic_constraints import ConstrainedMethods
from robodyn._mimic_relations import resolve_mimics
from robodyn._mimic_motion import solve_pose
from robodyn.operational_space import task_rows

__all__ = ["MimicModel"]

#: Rounding slack (rad or m) when checking that a group's reduced limits keep each follower in its own.
LIMIT_ROUNDING = 1e-12
#: The joint kinds a mimic relation may join (one coordinate each, of the same kind).
ONE_COORDINATE_JOINTS = ("revolute", "prismatic")


def _set_on_full(name: str) -> None:
    """A per-coordinate value of a reduced model is its groups' values combined: set them on
    the full model."""
    raise ValueError(f"argument '{name}': a model in reduced coordinates computes its {name} from the full "
                     f"model's (one value per joint, followers included): set m.full.{name}")


def _transmitted(name: str, power: int, doc: str) -> property:
    """A per-coordinate value of the full model through the transmission (see ``_diagonal``)."""
    return property(lambda self: self._diagonal(getattr(self.full, name), power),
                    lambda self, value: _set_on_full(name), doc=doc)


class MimicModel(ConstrainedMethods):
    """A robot model in reduced coordinates: each URDF mimic joint follows its leader (see the
    module docstring). ``full`` is the model in its own coordinates; ``coupling`` is G (full nv ×
    nv); ``expand(q)`` and ``expand_velocity(v)`` give the full model's state. Every method of
    :class:`robodyn.Model` is here, taking and returning reduced coordinates."""

    def __init__(self, full: _core.Model):
        if not isinstance(full, _core.Model):
            raise bad("full", "a robodyn.Model", repr(full))
        self.full = full
        names, kinds = full.joint_names, full.joint_types
        index = {name: k for k, name in enumerate(names)}
        relations = {}
        for follower, leader, ratio, offset in full.mimic_joints:
            for role, name in (("follower", follower), ("leader", leader)):
                kind = kinds[index[name]]
                if kind not in ONE_COORDINATE_JOINTS:
                    raise ValueError(
                        f"mimic=True: joint '{name}' ({kind}), the {role} of '{follower}' mimicking "
                        f"'{leader}', expected a revolute or prismatic joint")
            if kinds[index[follower]] != kinds[index[leader]]:
                raise ValueError(
                    f"mimic=True: joint '{follower}' ({kinds[index[follower]]}) mimics '{leader}' "
                    f"({kinds[index[leader]]}): expected joints of the same kind")
            relations[follower] = (leader, ratio, offset)
        # each follower as its first leader's coordinate: q_f = ratio q_root + offset
        resolved = resolve_mimics(relations)
        self.followers = resolved
        idx_q, idx_v = full.joint_idx_q, full.joint_idx_v
        follower_q = {idx_q[index[f]] for f in resolved}
        follower_v = {idx_v[index[f]] for f in resolved}
        #: the full model's coordinates kept in q_red and v_red, in order
        self.independent_q = np.array([k for k in range(full.nq) if k not in follower_q], dtype=int)
        self.independent_v = np.array([k for k in range(full.nv) if k not in follower_v], dtype=int)
        reduced_q = {int(k): j for j, k in enumerate(self.independent_q)}
        reduced_v = {int(k): j for j, k in enumerate(self.independent_v)}
        self._q_map = np.zeros((full.nq, len(reduced_q)))
        self._q_offset = np.zeros(full.nq)
        self.coupling = np.zeros((full.nv, len(reduced_v)))
        self._q_map[self.independent_q, np.arange(len(reduced_q))] = 1.0
        self.coupling[self.independent_v, np.arange(len(reduced_v))] = 1.0
        # a joint's reduced index: its own, or its first leader's
        self._joint_idx_q, self._joint_idx_v = [], []
        for k, name in enumerate(names):
            own = index[resolved[name][0]] if name in resolved else k
            self._joint_idx_q.append(reduced_q[idx_q[own]])
            self._joint_idx_v.append(reduced_v[idx_v[own]])
        for follower, (root, ratio, offset) in resolved.items():
            f, r = index[follower], index[root]
            self._q_map[idx_q[f], reduced_q[idx_q[r]]] = ratio
            self._q_offset[idx_q[f]] = offset
            self.coupling[idx_v[f], reduced_v[idx_v[r]]] = ratio
        # the velocity coordinate of each one-coordinate joint's configuration coordinate
        self._velocity_of = {idx_q[k]: idx_v[k] for k, kind in enumerate(kinds) if kind in ONE_COORDINATE_JOINTS}
        self._joint_at = {idx_q[k]: name for k, name in enumerate(names)}
        # E: a reduced generalized force as a full one on the kept coordinates (Gᵀ E = 1)
        self._selection = np.zeros((full.nv, len(reduced_v)))
        self._selection[self.independent_v, np.arange(len(reduced_v))] = 1.0

    # --- the maps -----------------------------------------------------------------------------

    @property
    def nq(self) -> int:
        """Number of configuration coordinates (the followers' left out)."""
        return len(self.independent_q)

    @property
    def nv(self) -> int:
        """Number of velocity coordinates (degrees of freedom)."""
        return len(self.independent_v)

    def _vector(self, name: str, value: Any, size: int) -> np.ndarray:
        """One state (size,) or a batch (N, size) of finite numbers."""
        array = numbers(name, value)
        if array.ndim not in (1, 2) or array.shape[-1] != size:
            raise bad(name, f"shape ({size},) or (N, {size})", f"{array.shape}")
        return array

    def expand(self, q: Any) -> np.ndarray:
        """The full model's configuration: q = A q_red + b (followers from their leaders)."""
        return self._expand(q, "q")

    def expand_velocity(self, v: Any) -> np.ndarray:
        """The full model's velocity (or acceleration): G v_red."""
        return self._expand_velocity(v, "v")

    def reduce(self, q_full: Any) -> np.ndarray:
        """q_red of a full configuration (its kept coordinates; the followers' are dropped)."""
        return self._vector("q_full", q_full, self.full.nq)[..., self.independent_q]

    def _expand(self, q: Any, name: str) -> np.ndarray:
        return self._vector(name, q, self.nq) @ self._q_map.T + self._q_offset

    def _expand_velocity(self, v: Any, name: str) -> np.ndarray:
        return self._vector(name, v, self.nv) @ self.coupling.T

    def _generalized(self, x: np.ndarray) -> np.ndarray:
        """Gᵀ x: a full generalized force (..., nv) in reduced coordinates."""
        return x @ self.coupling

    def _columns(self, x: np.ndarray) -> np.ndarray:
        """X G: a matrix whose columns are per full velocity coordinate, in reduced ones."""
        return x @ self.coupling

    def _form(self, x: np.ndarray) -> np.ndarray:
        """Gᵀ X G: a matrix acting on velocities and giving generalized forces (M, C, ∂τ/∂q)."""
        return self.coupling.T @ x @ self.coupling

    def _tangent(self, x: np.ndarray) -> np.ndarray:
        """P X G: a map between full tangent vectors (Jacobians of integrate, difference) in
        reduced ones (P keeps the independent rows)."""
        return (x @ self.coupling)[..., self.independent_v, :]

    def _group(self, j: int) -> list[tuple[int, float]]:
        """The full velocity coordinates that reduced coordinate j moves, with G's entries."""
        return [(int(k), float(self.coupling[k, j])) for k in np.flatnonzero(self.coupling[:, j])]

    # --- properties -----------------------------------------------------------------------------

    def __repr__(self) -> str:
        return (f"<robodyn.MimicModel '{self.full.name}': nq={self.nq}, nv={self.nv} "
                f"({len(self.followers)} mimic joint(s) following their leaders)>")

    def __reduce__(self):
        return (MimicModel, (self.full,))

    def __getattr__(self, name: str) -> Any:
        # what does not depend on the coordinates is the full model's
        if name in _SHARED:
            return getattr(self.full, name)
        raise AttributeError(f"'MimicModel' object has no attribute '{name}'")

    @property
    def joint_idx_q(self) -> list[int]:
        """First index of each joint in q_red; a follower's is its first leader's."""
        return list(self._joint_idx_q)

    @property
    def joint_idx_v(self) -> list[int]:
        """First index of each joint in v_red; a follower's is its first leader's."""
        return list(self._joint_idx_v)

    @property
    def gravity(self) -> np.ndarray:
        return self.full.gravity

    @gravity.setter
    def gravity(self, value: Any) -> None:
        self.full.gravity = value

    @property
    def inertial_parameters(self) -> np.ndarray:
        return self.full.inertial_parameters

    @inertial_parameters.setter
    def inertial_parameters(self, value: Any) -> None:
        self.full.inertial_parameters = value

    @property
    def constraints(self) -> list:
        """The model file's own constraints, less the mimic relations (which q_red enforces)."""
        return [c for c in self.full.constraints
                if not (isinstance(c, _core.JointCoupling) and c.joint in self.followers)]

    @property
    def keyframes(self) -> list[_core.Keyframe]:
        """The model file's keyframes in reduced coordinates (the leaders' q and v)."""
        return [self._reduced_keyframe(key) for key in self.full.keyframes]

    def keyframe(self, key: Any) -> _core.Keyframe:
        """The model file's keyframe ``key`` (a name or an index) in reduced coordinates."""
        return self._reduced_keyframe(self.full.keyframe(key))

    def _reduced_keyframe(self, key: _core.Keyframe) -> _core.Keyframe:
        return _core.Keyframe(key.name, key.time, self.reduce(key.q), key.v[self.independent_v], key.ctrl, key.act,
                              key.plastic)

    def actuator_forces(self, q: Any, v: Any, ctrl: Any, act: Any = None) -> np.ndarray:
        """Gᵀ of the full model's actuator forces at the expanded state."""
        full = self.full.actuator_forces(self._expand(q, "q"), self._expand_velocity(v, "v"), ctrl, act)
        return self._generalized(full)

    def tendon_lengths(self, q: Any) -> np.ndarray:
        """The full model's tendon lengths at the expanded q."""
        return self.full.tendon_lengths(self._expand(q, "q"))

    def _diagonal(self, values: np.ndarray, power: int) -> np.ndarray:
        """Σ_k |G_kj|^power values_k over each reduced coordinate's group (Gᵀ diag(x) G is
        diagonal: each full coordinate moves with one reduced coordinate)."""
        return np.abs(self.coupling.T) ** power @ values

    armature = _transmitted("armature", 2, "Rotor inertia per reduced coordinate: Σ r² armature over its group.")
    damping = _transmitted("damping", 2, "Viscous damping per reduced coordinate: Σ r² damping over its group.")
    friction = _transmitted("friction", 1, "Dry friction per reduced coordinate: Σ |r| friction over its group.")
    stiffness = _transmitted("stiffness", 2, "Spring stiffness per reduced coordinate: Σ r² stiffness over its group.")

    def _spring_reference(self) -> np.ndarray:
        """Where the reduced coordinate's springs balance: the springs of a group,
        −k_k (r_k q + b_k − q_ref,k) summed through Gᵀ, pull towards
        Σ r_k k_k (q_ref,k − b_k) / Σ r_k² k_k (the kept coordinates' own reference where the
        group has no spring; a group's one spring's (q_ref,k − b_k) / r_k, whatever its terms)."""
        full = self.full
        reference = np.asarray(full.spring_reference)[self.independent_q].copy()
        stiffness = np.asarray(full.stiffness)
        for j in range(self.nq):
            group = self._q_group(j)
            springs = self._springs_of(group)
            total = sum(r * r * stiffness[self._velocity_of[k]] for k, r in group)
            if len(group) > 1 and len(springs) == 1:
                k, r = springs[0]
                reference[j] = (full.spring_reference[k] - self._q_offset[k]) / r
            elif len(group) > 1 and total > 0:
                reference[j] = sum(r * stiffness[self._velocity_of[k]] * (full.spring_reference[k] - self._q_offset[k])
                                   for k, r in group) / total
        return reference

    def _springs_of(self, group: list[tuple[int, float]]) -> list[tuple[int, float]]:
        """The members of a group (full configuration coordinate, r) that have a spring."""
        stiffness, terms = np.asarray(self.full.stiffness), np.asarray(self.full.stiffness_poly)
        return [(k, r) for k, r in group
                if stiffness[self._velocity_of[k]] != 0 or np.any(terms[self._velocity_of[k]] != 0)]

    @property
    def stiffness_poly(self) -> np.ndarray:
        """The springs' higher terms per reduced coordinate, (nv, 2): a group's one spring
        −(k + k₁ x + k₂ x²) x with x = r s (s = q − q_ref on the reduced coordinate) pulls it
        with r x, that is (r³ k₁, r⁴ k₂). A group with polynomial terms and more than one spring
        has no such pair (ValueError naming it: read m.full.stiffness_poly)."""
        terms = np.asarray(self.full.stiffness_poly)
        for j in range(self.nq):
            springs = self._springs_of(self._q_group(j))
            if len(springs) > 1 and any(np.any(terms[self._velocity_of[k]] != 0) for k, _ in springs):
                names = [self._joint_at[k] for k, _ in springs]
                raise ValueError(f"argument 'stiffness_poly': reduced coordinate {j} moves {len(springs)} springs "
                                 f"with polynomial terms ({', '.join(names)}), whose sum is no polynomial of it: "
                                 "read m.full.stiffness_poly")
        g = self.coupling.T
        return np.column_stack([g**3 @ terms[:, 0], g**4 @ terms[:, 1]])

    @stiffness_poly.setter
    def stiffness_poly(self, value: Any) -> None:
        _set_on_full("stiffness_poly")

    @property
    def damping_poly(self) -> np.ndarray:
        """The dampers' higher terms per reduced coordinate, (nv, 2): each follower's
        −(b + b₁ |r q̇| + b₂ r² q̇²) r q̇ pulls with r times it, so (Σ |r|³ b₁, Σ r⁴ b₂) over the
        group (exact)."""
        terms = np.asarray(self.full.damping_poly)
        return np.column_stack([self._diagonal(terms[:, 0], 3), self._diagonal(terms[:, 1], 4)])

    @damping_poly.setter
    def damping_poly(self, value: Any) -> None:
        _set_on_full("damping_poly")

    spring_reference = property(_spring_reference, lambda self, value: _set_on_full("spring_reference"),
                                doc=_spring_reference.__doc__)

    def _q_group(self, j: int) -> list[tuple[int, float]]:
        """The full configuration coordinates that q_red[j] sets, with A's entries."""
        return [(int(k), float(self._q_map[k, j])) for k in np.flatnonzero(self._q_map[:, j])]

    @property
    def lower_position_limit(self) -> np.ndarray:
        """The lowest q_red that keeps every joint of its group within its limits."""
        return self._limits()[0]

    @property
    def upper_position_limit(self) -> np.ndarray:
        """The highest q_red that keeps every joint of its group within its limits."""
        return self._limits()[1]

    def _limits(self) -> tuple[np.ndarray, np.ndarray]:
        """The reduced position limits: each group's limits intersected, except where the file's
        limits leave no range (a follower's limits that contradict its relation): there its
        leader's own, and a warning (:attr:`warnings`)."""
        lower_full, upper_full = np.asarray(self.full.lower_position_limit), np.asarray(self.full.upper_position_limit)
        lower, upper = lower_full[self.independent_q].copy(), upper_full[self.independent_q].copy()
        for j in range(self.nq):
            low, high = lower[j], upper[j]
            for k, r in self._q_group(j):
                # lower_k ≤ r q + b_k ≤ upper_k
                bounds = sorted(((lower_full[k] - self._q_offset[k]) / r, (upper_full[k] - self._q_offset[k]) / r))
                low, high = max(low, bounds[0]), min(high, bounds[1])
            if low < high:
                lower[j], upper[j] = low, high
        return lower, upper

    @property
    def warnings(self) -> list[str]:
        """The full model's warnings, and the groups whose limits contradict their relations."""
        lower, upper = self._limits()
        notes = []
        for j in range(self.nq):
            group = self._q_group(j)
            full_lower = np.asarray(self.full.lower_position_limit)
            full_upper = np.asarray(self.full.upper_position_limit)
            outside = [k for k, r in group if k != self.independent_q[j] and not all(
                full_lower[k] - LIMIT_ROUNDING <= r * x + self._q_offset[k] <= full_upper[k] + LIMIT_ROUNDING for x in (lower[j], upper[j])
                if np.isfinite(x))]
            if outside:
                names = [self._joint_of_q(k) for k in outside]
                notes.append(
                    f"mimic=True: the position limits of {names} contradict their relation to "
                    f"'{self._joint_of_q(int(self.independent_q[j]))}' (no common range): q_red keeps the leader's own limits "
                    f"[{lower[j]:g}, {upper[j]:g}]")
        return list(self.full.warnings) + notes

    def _joint_of_q(self, k: int) -> str:
        """The name of the joint whose configuration coordinate k is (one-coordinate joints)."""
        return self.full.joint_names[list(self.full.joint_idx_q).index(k)]

    @property
    def velocity_limit(self) -> np.ndarray:
        """The largest v_red that keeps every joint of its group within its velocity limit."""
        limit = np.asarray(self.full.velocity_limit)
        return np.array([min(limit[k] / abs(r) for k, r in self._group(j)) for j in range(self.nv)])

    @property
    def effort_limit(self) -> np.ndarray:
        """The effort limit of each kept coordinate's own joint (a leader's, for a group)."""
        return np.asarray(self.full.effort_limit)[self.independent_v]

    # --- configurations -------------------------------------------------------------------------

    def neutral(self) -> np.ndarray:
        """The full model's neutral configuration, reduced."""
        return np.asarray(self.full.neutral())[self.independent_q]

    def random_configuration(self, n: int | None = None, seed: int | None = None) -> np.ndarray:
        """Random configurations (one, or ``n``) within the reduced limits: the full model's, with
        each leader of a group drawn within the limits of its whole group."""
        q = np.asarray(self.full.random_configuration(n, seed))[..., self.independent_q]
        lower, upper = self._limits()
        rng = np.random.default_rng(seed)
        for j in range(self.nq):
            if len(self._q_group(j)) > 1 and np.isfinite(lower[j]) and np.isfinite(upper[j]):
                q[..., j] = rng.uniform(lower[j], upper[j], size=q.shape[:-1])
        return q

    def integrate(self, q: Any, v: Any, dt: float = 1.0) -> np.ndarray:
        """q ⊕ v dt in reduced coordinates (the full model's integration, reduced)."""
        return np.asarray(self.full.integrate(self.expand(q), self.expand_velocity(v), dt))[..., self.independent_q]

    def difference(self, q0: Any, q1: Any) -> np.ndarray:
        """q1 ⊖ q0 in reduced coordinates."""
        full = self.full.difference(self._expand(q0, "q0"), self._expand(q1, "q1"))
        return np.asarray(full)[..., self.independent_v]

    def integrate_jacobians(self, q: Any, v: Any) -> dict[str, np.ndarray]:
        """∂(q ⊕ v)/∂q and ∂(q ⊕ v)/∂v in reduced tangent coordinates."""
        full = self.full.integrate_jacobians(self.expand(q), self.expand_velocity(v))
        return {key: self._tangent(value) for key, value in full.items()}

    def difference_jacobians(self, q0: Any, q1: Any) -> dict[str, np.ndarray]:
        """∂(q1 ⊖ q0)/∂q0 and ∂(q1 ⊖ q0)/∂q1 in reduced tangent coordinates."""
        full = self.full.difference_jacobians(self._expand(q0, "q0"), self._expand(q1, "q1"))
        return {key: self._tangent(value) for key, value in full.items()}

    # --- dynamics -------------------------------------------------------------------------------

    def inverse_dynamics(self, q: Any, v: Any, a: Any, f_ext: Any = None, out: Any = None) -> np.ndarray:
        """τ_red = Gᵀ τ(q, G v, G a): RNEA of the full model, mapped."""
        tau = self.full.inverse_dynamics(self.expand(q), self.expand_velocity(v), self._expand_velocity(a, "a"), f_ext)
        return _written(self._generalized(tau), out)

    def forward_dynamics(self, q: Any, v: Any, tau: Any, f_ext: Any = None, out: Any = None) -> np.ndarray:
        """q̈_red = M_red⁻¹ (τ_red − Gᵀ h): the reduced equations solved (h from RNEA at q̈ = 0,
        with ``f_ext``)."""
        tau = self._vector("tau", tau, self.nv)
        expanded = self.expand(q)
        velocity = self.expand_velocity(v)
        bias = self._generalized(self.full.inverse_dynamics(expanded, velocity, np.zeros_like(velocity), f_ext))
        mass = self._form(self.full.mass_matrix(expanded))
        return _written(np.linalg.solve(mass, (tau - bias)[..., None])[..., 0], out)

    def inverse_dynamics_derivatives(self, q: Any, v: Any, a: Any, f_ext: Any = None) -> dict[str, np.ndarray]:
        """∂τ_red/∂q_red, ∂τ_red/∂v_red, ∂τ_red/∂a_red: Gᵀ (∂τ/∂·) G."""
        full = self.full.inverse_dynamics_derivatives(
            self.expand(q), self.expand_velocity(v), self._expand_velocity(a, "a"), f_ext)
        return {key: self._form(value) for key, value in full.items()}

    def forward_dynamics_derivatives(self, q: Any, v: Any, tau: Any, f_ext: Any = None) -> dict[str, np.ndarray]:
        """∂q̈_red/∂q_red = −M_red⁻¹ ∂τ_red/∂q_red (at q̈_red), the same for v; ∂q̈_red/∂τ_red = M_red⁻¹."""
        qdd = self.forward_dynamics(q, v, tau, f_ext)
        derivatives = self.inverse_dynamics_derivatives(q, v, qdd, f_ext)
        inverse = np.linalg.inv(derivatives["dtau_da"])
        return {"dqdd_dq": -inverse @ derivatives["dtau_dq"], "dqdd_dv": -inverse @ derivatives["dtau_dv"],
                "dqdd_dtau": inverse}

    def torque_regressor(self, q: Any, v: Any, a: Any) -> np.ndarray:
        """Gᵀ Y: τ_red linear in the inertial parameters."""
        full = self.full.torque_regressor(self.expand(q), self.expand_velocity(v), self._expand_velocity(a, "a"))
        return self.coupling.T @ full

    def mass_matrix(self, q: Any, method: str = "crba", out: Any = None) -> np.ndarray:
        """M_red = Gᵀ M G."""
        return _written(self._form(self.full.mass_matrix(self.expand(q), method)), out)

    def inverse_mass_matrix(self, q: Any) -> np.ndarray:
        """M_red⁻¹."""
        return np.linalg.inv(self.mass_matrix(q))

    def bias_forces(self, q: Any, v: Any, out: Any = None) -> np.ndarray:
        """Gᵀ (C(q, G v) G v + g(q))."""
        return _written(self._generalized(self.full.bias_forces(self.expand(q), self.expand_velocity(v))), out)

    def generalized_gravity(self, q: Any, method: str = "rnea", out: Any = None) -> np.ndarray:
        """g_red = Gᵀ g."""
        return _written(self._generalized(self.full.generalized_gravity(self.expand(q), method)), out)

    def coriolis_matrix(self, q: Any, v: Any) -> np.ndarray:
        """C_red = Gᵀ C G (Ṁ_red − 2 C_red skew, as G is constant)."""
        return self._form(self.full.coriolis_matrix(self.expand(q), self.expand_velocity(v)))

    def christoffel(self, q: Any) -> np.ndarray:
        """Γ_red,ijk = Σ G_ai G_bj G_ck Γ_abc."""
        full = self.full.christoffel(self.expand(q))
        g = self.coupling
        return np.einsum("...abc,ai,bj,ck->...ijk", full, g, g, g)

    def centrifugal_matrix(self, q: Any) -> np.ndarray:
        """Craig's centrifugal matrix of the reduced coordinates: Γ_red,ijj."""
        return np.diagonal(self.christoffel(q), axis1=-2, axis2=-1)

    def coriolis_pairs_matrix(self, q: Any) -> np.ndarray:
        """Craig's Coriolis matrix of the reduced coordinates: 2 Γ_red,ijk for the pairs j < k."""
        j, k = np.triu_indices(self.nv, 1)
        return 2.0 * self.christoffel(q)[..., j, k]

    def kinetic_energy(self, q: Any, v: Any) -> Any:
        return self.full.kinetic_energy(self.expand(q), self.expand_velocity(v))

    def potential_energy(self, q: Any) -> Any:
        return self.full.potential_energy(self.expand(q))

    def spring_energy(self, q: Any) -> Any:
        return self.full.spring_energy(self.expand(q))

    def lagrangian(self, q: Any, v: Any) -> Any:
        return self.full.lagrangian(self.expand(q), self.expand_velocity(v))

    def centroidal_momentum_matrix(self, q: Any) -> np.ndarray:
        """A_G G."""
        return self._columns(self.full.centroidal_momentum_matrix(self.expand(q)))

    def centroidal_momentum(self, q: Any, v: Any) -> np.ndarray:
        return self.full.centroidal_momentum(self.expand(q), self.expand_velocity(v))

    # --- kinematics -----------------------------------------------------------------------------

    def frame_pose(self, q: Any, frame: Any, out: Any = None) -> np.ndarray:
        return self.full.frame_pose(self.expand(q), frame, out)

    def body_poses(self, q: Any) -> np.ndarray:
        return self.full.body_poses(self.expand(q))

    def collide(self, q: Any) -> list[dict[str, Any]]:
        return self.full.collide(self.expand(q))

    def contact_forward_dynamics(
        self, q: Any, v: Any, tau: Any = None, ctrl: Any = None, act: Any = None, plastic: Any = None
    ) -> dict[str, Any]:
        """The full model's, where no joint mimics another; MuJoCo's soft model of a coupled
        joint (an equality row) is not made yet."""
        if self.mimic_joints:
            raise bad("model", "a model without mimic joints (MuJoCo's soft couplings are not made yet)",
                      f"mimic joints {[name for name, *_ in self.mimic_joints]}")
        return self.full.contact_forward_dynamics(q, v, tau, ctrl, act, plastic)

    def jacobian(self, q: Any, frame: Any, reference: str = "world", out: Any = None) -> np.ndarray:
        """J_red = J G."""
        return _written(self._columns(self.full.jacobian(self.expand(q), frame, reference)), out)

    def jacobian_time_variation(self, q: Any, v: Any, frame: Any, reference: str = "world") -> np.ndarray:
        """J̇_red = J̇ G (G is constant)."""
        return self._columns(self.full.jacobian_time_variation(self.expand(q), self.expand_velocity(v), frame, reference))

    def frame_velocity(self, q: Any, v: Any, frame: Any, reference: str = "world") -> np.ndarray:
        return self.full.frame_velocity(self.expand(q), self.expand_velocity(v), frame, reference)

    def frame_acceleration(self, q: Any, v: Any, a: Any, frame: Any, reference: str = "world") -> np.ndarray:
        return self.full.frame_acceleration(
            self.expand(q), self.expand_velocity(v), self._expand_velocity(a, "a"), frame, reference)

    def frame_velocity_derivatives(self, q: Any, v: Any, frame: Any, reference: str = "world") -> dict[str, np.ndarray]:
        full = self.full.frame_velocity_derivatives(self.expand(q), self.expand_velocity(v), frame, reference)
        return {key: self._columns(value) for key, value in full.items()}

    def frame_acceleration_derivatives(self, q: Any, v: Any, a: Any, frame: Any,
                                       reference: str = "world") -> dict[str, np.ndarray]:
        full = self.full.frame_acceleration_derivatives(
            self.expand(q), self.expand_velocity(v), self._expand_velocity(a, "a"), frame, reference)
        return {key: self._columns(value) for key, value in full.items()}

    def center_of_mass(self, q: Any) -> np.ndarray:
        return self.full.center_of_mass(self.expand(q))

    def center_of_mass_jacobian(self, q: Any) -> np.ndarray:
        return self._columns(self.full.center_of_mass_jacobian(self.expand(q)))

    def center_of_mass_velocity(self, q: Any, v: Any) -> np.ndarray:
        return self.full.center_of_mass_velocity(self.expand(q), self.expand_velocity(v))

    def center_of_mass_velocity_derivatives(self, q: Any, v: Any) -> dict[str, np.ndarray]:
        full = self.full.center_of_mass_velocity_derivatives(self.expand(q), self.expand_velocity(v))
        return {key: self._columns(value) for key, value in full.items()}

    def _task_jacobian(self, q: Any, frame: Any, task: Any) -> np.ndarray:
        rows = task_rows("full" if task is None else task)
        return self.jacobian(q, frame)[..., rows, :]

    def manipulability(self, q: Any, frame: Any, task: Any = None) -> Any:
        """Yoshikawa's √det(J_red J_redᵀ) of the task rows (as :meth:`robodyn.Model.manipulability`)."""
        squared = _squared_singular_values(self._task_jacobian(q, frame, task))
        return _scalar(np.prod(np.sqrt(squared), axis=-1))

    def inverse_condition_number(self, q: Any, frame: Any, task: Any = None) -> Any:
        """σ_min / σ_max of J_red's task rows (0 where J_red has fewer columns than rows)."""
        jacobian = self._task_jacobian(q, frame, task)
        squared = _squared_singular_values(jacobian)
        rank_bound = min(jacobian.shape[-2], self.nv)
        ratio = np.sqrt(np.where(squared[..., :1] > 0, squared[..., rank_bound - 1:rank_bound] / np.where(
            squared[..., :1] > 0, squared[..., :1], 1.0), 0.0))[..., 0]
        return _scalar(ratio)

    def workspace(self, frame: Any, n: int = 10000, seed: int | None = None) -> np.ndarray:
        """World positions (n, 3) of a frame's origin over n random reduced configurations."""
        n = count("n", n)
        return np.asarray(self.frame_pose(self.random_configuration(n, seed), frame))[:, :3, 3]

    def inverse_kinematics(self, frame: Any, target: Any, q0: Any = None, position_only: bool = False,
                           tolerance: float = 1e-10, max_iterations: int = 200, restarts: int = 20,
                           damping: float = 1e-6, seed: int = 0) -> dict[str, Any]:
        """:meth:`robodyn.Model.inverse_kinematics`'s damped least squares (the same steps, error
        and restarts) on q_red, with J_red and the reduced limits."""
        position_only, tolerance = flag("position_only", position_only), positive("tolerance", tolerance)
        max_iterations, restarts = count("max_iterations", max_iterations, 0), count("restarts", restarts, 0)
        damping, seed = real("damping", damping), count("seed", seed, 0)
        if damping < 0:
            raise bad("damping", "a number ≥ 0", repr(damping))
        poses = numbers("target", target)
        if poses.shape[-2:] != (4, 4) or poses.ndim not in (2, 3):
            raise bad("target", "a 4x4 pose or (N, 4, 4) poses", f"shape {poses.shape}")
        start = self.neutral() if q0 is None else self._vector("q0", q0, self.nq)
        solutions = [
            solve_pose(self, frame, pose, start if start.ndim == 1 else start[k], position_only, tolerance,
                        max_iterations, restarts, damping, np.random.default_rng(seed))
            for k, pose in enumerate(poses.reshape(-1, 4, 4))
        ]
        if poses.ndim == 2:
            return solutions[0]
        return {key: np.array([s[key] for s in solutions]) for key in solutions[0]}

    # --- display --------------------------------------------------------------------------------

    def view(self, q: Any = None, **options: Any) -> Any:
        """The robot in a browser page at q_red (see :meth:`robodyn.Model.view`)."""
        return self.full.view(None if q is None else self.expand(q), **options)

    def to_html(self, path: Any, q: Any = None, **options: Any) -> Any:
        """One self-contained HTML file of the robot at q_red (see :meth:`robodyn.Model.to_html`)."""
        return self.full.to_html(path, None if q is None else self.expand(q), **options)

    def operational_space(self, q: Any, v: Any, frame: Any, task: str = "full", damping: Any = None,
                          reference: str = "world") -> dict[str, np.ndarray]:
        """Λ, μ, p and J̄ of a frame's task in reduced coordinates."""
        from robodyn.operational_space import operational_space

        return operational_space(self, q, v, frame, task, damping, reference)


#: What the reduced model takes unchanged from the full one.
_SHARED = frozenset({
    "name", "body_names", "body_parents", "body_masses", "frame_names", "frame_bodies", "joint_names",
    "joint_types", "mimic_joints", "total_mass", "visuals", "skybox", "nu", "na", "activation_rates", "actuator_names", "ctrl_range",
    "tendon_names", "options", "geoms", "contact_pairs", "contact_excludes", "contact_candidates", "joint_softness",
    "contact_parameters", "collide_placed", "spring_yield", "nplastic", "plastic0", "tendon_spring_yield",
})


def _written(result: Any, out: Any) -> np.ndarray:
    """``result``, copied into ``out`` when one is given (as the core's ``out=``)."""
    result = np.asarray(result)
    if out is None:
        return result
    if not isinstance(out, np.ndarray) or out.dtype != np.float64 or out.shape != result.shape:
        raise bad("out", f"a float64 array of shape {result.shape}", repr(getattr(out, "shape", out)))
    out[...] = result
    return out


def _scalar(value: np.ndarray) -> Any:
    return float(value) if np.ndim(value) == 0 else value


def _squared_singular_values(jacobian: np.ndarray) -> np.ndarray:
    """The eigenvalues of J Jᵀ (σ²), largest first, none negative."""
    values = np.linalg.eigvalsh(jacobian @ np.swapaxes(jacobian, -1, -2))
    return np.maximum(values[..., ::-1], 0.0)
