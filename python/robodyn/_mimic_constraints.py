"""The constrained-dynamics methods of a model in reduced coordinates
(:class:`robodyn.mimic.MimicModel`): the full model's, holding each mimic relation as a
:class:`robodyn.JointCoupling` after the user's constraints. The relations are linear in q and
their rows independent, so that is the same system: q̈ = G q̈_red. Rows are kept (q̈_red, the
user's forces), columns mapped through G (q, v) and E (τ, put on the kept coordinates)."""

from __future__ import annotations

from typing import Any

import numpy as np

from robodyn import _core
from robodyn._arguments import bad


class ConstrainedMethods:
    """What :class:`robodyn.mimic.MimicModel` does with constraints (its maps are its own)."""

    full: Any
    followers: dict
    coupling: np.ndarray
    independent_v: np.ndarray
    _selection: np.ndarray

    def _couplings(self) -> list:
        """Each mimic relation as a JointCoupling of the full model."""
        return [_core.JointCoupling(follower, leader, ratio, offset)
                for follower, leader, ratio, offset in self.full.mimic_joints if follower in self.followers]

    def _held(self, constraints: Any) -> list:
        """The user's constraints, then the mimic relations (rows after the user's)."""
        given = list(constraints) if isinstance(constraints, (list, tuple)) else [constraints]
        return given + self._couplings()

    def _user_rows(self, q: Any, constraints: Any) -> int:
        """Number of rows of the user's constraints."""
        return np.asarray(self.full.constraint_jacobian(self.expand(q), constraints)).shape[-2]

    def constraint_jacobian(self, q: Any, constraints: Any) -> np.ndarray:
        """J_red = J G."""
        return self._columns(self.full.constraint_jacobian(self.expand(q), constraints))

    def constraint_error(self, q: Any, constraints: Any) -> np.ndarray:
        """φ of the full model at the expanded configuration (the followers hold by construction)."""
        return np.asarray(self.full.constraint_error(self.expand(q), constraints))

    def close_constraints(self, q: Any, constraints: Any, tolerance: float = 1e-12, max_iterations: int = 50,
                          damping: float = 1e-8) -> dict[str, np.ndarray]:
        """The full model's closure holding the mimic relations too (so the followers stay on
        them), reduced; ``residual`` covers both."""
        self._user_rows(q, constraints)  # the argument checked as given, before the relations join it
        full = self.full.close_constraints(self.expand(q), self._held(constraints), tolerance, max_iterations, damping)
        return {**full, "q": self.reduce(full["q"])}

    def delassus(self, q: Any, constraints: Any) -> np.ndarray:
        """J_red M_red⁻¹ J_redᵀ."""
        jacobian = self.constraint_jacobian(q, constraints)
        return jacobian @ np.linalg.solve(self.mass_matrix(q), np.swapaxes(jacobian, -1, -2))

    def constrained_forward_dynamics(self, q: Any, v: Any, tau: Any, constraints: Any, f_ext: Any = None,
                                     baumgarte: Any = None, damping: float = 0.0) -> dict[str, np.ndarray]:
        """The full model's, holding the mimic relations too (the same equations: the relations
        are linear, their rows independent); ``forces`` are the user's rows."""
        rows = self._user_rows(q, constraints)
        full = self.full.constrained_forward_dynamics(
            self.expand(q), self.expand_velocity(v), self._actuation(tau), self._held(constraints), f_ext,
            baumgarte, damping)
        return {"qdd": full["qdd"][..., self.independent_v], "forces": full["forces"][..., :rows]}

    def impulse_dynamics(self, q: Any, v: Any, constraints: Any, restitution: float = 0.0,
                         damping: float = 0.0) -> dict[str, np.ndarray]:
        """The full model's, holding the mimic relations too; ``impulses`` are the user's rows."""
        rows = self._user_rows(q, constraints)
        full = self.full.impulse_dynamics(self.expand(q), self.expand_velocity(v), self._held(constraints),
                                          restitution, damping)
        return {"v": full["v"][..., self.independent_v], "impulses": full["impulses"][..., :rows]}

    def constrained_forward_dynamics_derivatives(self, q: Any, v: Any, tau: Any, constraints: Any,
                                                 f_ext: Any = None, damping: float = 0.0) -> dict[str, np.ndarray]:
        """The full model's derivatives, holding the mimic relations: rows kept (q̈_red, the user's
        forces), columns by G (q, v) and E (τ)."""
        rows = self._user_rows(q, constraints)
        full = self.full.constrained_forward_dynamics_derivatives(
            self.expand(q), self.expand_velocity(v), self._actuation(tau), self._held(constraints), f_ext, damping)
        out = {"qdd": full["qdd"][..., self.independent_v], "forces": full["forces"][..., :rows]}
        for key in ("dqdd_dq", "dqdd_dv", "dqdd_dtau", "dforces_dq", "dforces_dv", "dforces_dtau"):
            value = full[key][..., self.independent_v, :] if key.startswith("dqdd") else full[key][..., :rows, :]
            out[key] = value @ (self._selection if key.endswith("tau") else self.coupling)
        return out

    def impulse_dynamics_derivatives(self, q: Any, v: Any, constraints: Any, restitution: float = 0.0,
                                     damping: float = 0.0) -> dict[str, np.ndarray]:
        """As :meth:`constrained_forward_dynamics_derivatives`, for impulses."""
        rows = self._user_rows(q, constraints)
        full = self.full.impulse_dynamics_derivatives(self.expand(q), self.expand_velocity(v),
                                                      self._held(constraints), restitution, damping)
        out = {"v": full["v"][..., self.independent_v], "impulses": full["impulses"][..., :rows]}
        for key in ("dv_dq", "dv_dv", "dimpulses_dq", "dimpulses_dv"):
            value = full[key][..., self.independent_v, :] if key.startswith("dv") else full[key][..., :rows, :]
            out[key] = value @ self.coupling
        return out

    def constrained_inverse_dynamics(self, q: Any, v: Any, a: Any, constraints: Any, actuated: Any = None,
                                     f_ext: Any = None, weights: Any = None) -> dict[str, np.ndarray]:
        """The full model's, with each follower actuated where its leader is: the unactuated
        rows, and so the forces, are the reduced problem's; τ_red = Gᵀ τ. A group whose leader
        is not actuated is refused (its follower's row would need a force of its own)."""
        names = self.full.joint_names
        if actuated is not None:
            if not (isinstance(actuated, (list, tuple)) and all(isinstance(name, str) for name in actuated)):
                raise bad("actuated", "None or a list of joint names", repr(actuated))
            given = list(actuated)
            unactuated = sorted(name for name, (leader, _, _) in self.followers.items() if leader not in given)
            if unactuated:
                raise ValueError(
                    f"argument 'actuated': mimic=True expects the leaders of mimic joints to be actuated; "
                    f"the leaders of {unactuated} are not")
            actuated = [name for name in names
                        if name in given or (name in self.followers and self.followers[name][0] in given)]
        full = self.full.constrained_inverse_dynamics(self.expand(q), self.expand_velocity(v),
                                                      self._expand_velocity(a, "a"), constraints, actuated,
                                                      f_ext, weights)
        return {"tau": self._generalized(full["tau"]), "forces": full["forces"]}

    def _actuation(self, tau: Any) -> np.ndarray:
        """E τ_red: the reduced generalized force on the kept coordinates (Gᵀ E τ_red = τ_red)."""
        return self._vector("tau", tau, self.nv) @ self._selection.T
