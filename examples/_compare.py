"""Printing a textbook value next to robodyn's, shared by the examples."""

from __future__ import annotations

import numpy as np


def show(label: str, textbook, robodyn_value, tolerance: float = 1e-10) -> None:
    """Prints both and their largest difference; stops the example if they disagree."""
    textbook, robodyn_value = np.asarray(textbook, dtype=float), np.asarray(robodyn_value, dtype=float)
    difference = float(np.max(np.abs(textbook - robodyn_value))) if textbook.size else 0.0
    with np.printoptions(precision=6, suppress=True):
        print(f"{label}\n  textbook: {textbook.tolist()}\n  robodyn:  {robodyn_value.tolist()}\n  largest difference {difference:.1e}")
    assert difference <= tolerance * max(1.0, float(np.max(np.abs(textbook)))), f"{label}: they differ"
