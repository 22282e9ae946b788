"""Printing a textbook value next to robodyn's, and the Go2 scene, shared by the examples."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

#: The repository's Go2 scene: examples/ lies beside testdata/ (the Go2 without its visual meshes).
GO2_SCENE = Path(__file__).resolve().parents[1] / "testdata" / "menagerie" / "unitree_go2" / "scene.xml"


#: The repository's Franka Panda with a cube to pick up (its MJX scene, without its visual meshes).
PANDA_CUBE = GO2_SCENE.parents[1] / "franka_emika_panda" / "mjx_single_cube.xml"


def go2_scene() -> Any:
    """Menagerie's Unitree Go2 on its floor (:data:`GO2_SCENE`), loaded without its warnings (the
    scene's <visual> is not read, and its contacts are felt only with integrator='mujoco')."""
    return quietly_loaded(GO2_SCENE)


def quietly_loaded(path: Path) -> Any:
    """The scene at ``path``, loaded without its ModelWarnings."""
    import robodyn

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", robodyn.ModelWarning)
        return robodyn.load(path)


def show(label: str, textbook: ArrayLike, robodyn_value: ArrayLike, tolerance: float = 1e-10) -> None:
    """Prints both and their largest difference; stops the example if they disagree."""
    expected, value = np.asarray(textbook, dtype=float), np.asarray(robodyn_value, dtype=float)
    difference = float(np.max(np.abs(expected - value))) if expected.size else 0.0
    with np.printoptions(precision=6, suppress=True):
        print(f"{label}\n  textbook: {expected.tolist()}\n  robodyn:  {value.tolist()}\n  largest difference {difference:.1e}")
    assert difference <= tolerance * max(1.0, float(np.max(np.abs(expected)))), f"{label}: they differ"
