"""The joint kinds of ``Model.joint_types``, in one table: how many coordinates each has, what they
are called and in which unit a one-coordinate joint moves."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class JointKind:
    """A joint kind's coordinates: ``q_labels`` and ``v_labels`` name the configuration and velocity
    coordinates (empty for one coordinate, named after the joint); ``unit`` is its position's."""

    q_labels: tuple[str, ...] = ()
    v_labels: tuple[str, ...] = ()
    unit: str = ""

    @property
    def nq(self) -> int:
        return max(1, len(self.q_labels))

    @property
    def nv(self) -> int:
        return max(1, len(self.v_labels))


JOINT_KINDS = {
    "revolute": JointKind(unit="rad"),
    "prismatic": JointKind(unit="m"),
    # q a unit quaternion, v an angular velocity
    "spherical": JointKind(("qx", "qy", "qz", "qw"), ("wx", "wy", "wz")),
    # q a position and a unit quaternion, v a linear and an angular velocity
    "free": JointKind(("x", "y", "z", "qx", "qy", "qz", "qw"), ("vx", "vy", "vz", "wx", "wy", "wz")),
}


def coordinate_names(model: Any) -> tuple[list[str], list[str]]:
    """The names of q's and of v's coordinates: a joint's name, with ``.label`` where it has several."""
    q_names: list[str] = []
    v_names: list[str] = []
    for name, kind in zip(model.joint_names, model.joint_types):
        joint = JOINT_KINDS[kind]
        q_names += [f"{name}.{label}" for label in joint.q_labels] or [name]
        v_names += [f"{name}.{label}" for label in joint.v_labels] or [name]
    return q_names, v_names
