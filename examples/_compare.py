"""Printing a textbook value next to robodyn's, shared by the examples."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike


def show(label: str, textbook: ArrayLike, robodyn_value: ArrayLike, tolerance: float = 1e-10) -> None:
    """Prints both and their largest difference; stops the example if they disagree."""
    expected, value = np.asarray(textbook, dtype=float), np.asarray(robodyn_value, dtype=float)
    difference = float(np.max(np.abs(expected - value))) if expected.size else 0.0
    with np.printoptions(precision=6, suppress=True):
        print(f"{label}\n  textbook: {expected.tolist()}\n  robodyn:  {value.tolist()}\n  largest difference {difference:.1e}")
    assert difference <= tolerance * max(1.0, float(np.max(np.abs(expected)))), f"{label}: they differ"
