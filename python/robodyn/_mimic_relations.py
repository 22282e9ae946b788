"""Mimic relations resolved to their first leaders, for the numeric model in reduced coordinates
(:mod:`robodyn.mimic`) and the symbolic one (:mod:`robodyn.symbolic.mimic`): plain Python, the
numbers floats or SymPy's."""

from __future__ import annotations

from typing import Any, Callable, Hashable


def resolve_mimics(relations: dict[Hashable, tuple[Hashable, Any, Any]],
                   name: Callable[[Hashable], str] = str) -> dict[Hashable, tuple[Hashable, Any, Any]]:
    """Each follower as its first leader's coordinate, ``{follower: (leader, ratio, offset)}``,
    from the file's relations in the same form, chains composed: q_f = r₁ q_a + o₁ with
    q_a = r₂ q_b + o₂ is q_f = r₁r₂ q_b + r₁o₂ + o₁. A cycle is a ``ValueError`` naming its
    joints (``name`` gives a joint's name from its key)."""
    resolved = {}
    for follower in relations:
        path, ratio, offset, key = [follower], 1, 0, follower
        while key in relations:
            leader, r, o = relations[key]
            ratio, offset, key = ratio * r, ratio * o + offset, leader
            path.append(leader)
            if leader in path[:-1]:
                raise ValueError("mimic=True: the mimic relations form a cycle: " + " → ".join(name(k) for k in path))
        resolved[follower] = (key, ratio, offset)
    return resolved
