"""The checks of arguments that come from users, one place for robodyn's Python API and its command.

Each returns the value as robodyn uses it or raises the error robodyn's rule asks for bad input: a
``ValueError`` naming the argument, what was expected and what came.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Sequence

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def bad(name: str, expected: str, got: str) -> ValueError:
    """The error for argument ``name``: ``got`` is what came, as the message shows it."""
    return ValueError(f"argument '{name}': expected {expected}, got {got}")


def flag(name: str, value: Any) -> bool:
    """True or False (a NumPy bool too); not 1, "yes" or None."""
    if not isinstance(value, (bool, np.bool_)):
        raise bad(name, "True or False", repr(value))
    return bool(value)


def numbers(name: str, value: Any) -> FloatArray:
    """Finite numbers of any shape, as a float array."""
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError):
        raw = np.asarray(None)
    if raw.dtype.kind not in "iuf":
        raise bad(name, "numbers", repr(value))
    array = raw.astype(float)
    if not np.isfinite(array).all():
        raise bad(name, "finite numbers", repr(value))
    return array


def _shape_text(shape: tuple[int | None, ...]) -> str:
    """``3 finite numbers``, ``a 3x3 matrix of finite numbers``; N for any size."""
    sizes = ["N" if size is None else str(size) for size in shape]
    if len(sizes) == 1:
        return f"{sizes[0]} finite numbers"
    article = "an" if sizes[0][0] in "N8" else "a"
    return f"{article} {'x'.join(sizes)} matrix of finite numbers"


def array(name: str, value: Any, *shapes: tuple[int | None, ...]) -> FloatArray:
    """Finite numbers of one of ``shapes`` (a size None is any size), as a float array."""
    result = numbers(name, value)
    for shape in shapes:
        if result.ndim == len(shape) and all(want in (None, size) for want, size in zip(shape, result.shape)):
            return result
    raise bad(name, " or ".join(_shape_text(shape) for shape in shapes), f"shape {result.shape}")


def real(name: str, value: Any) -> float:
    """One finite number (an int or a float, not a bool)."""
    if isinstance(value, (bool, np.bool_)) or np.ndim(value) != 0:
        raise bad(name, "a number", repr(value))
    return float(numbers(name, value))


def positive(name: str, value: Any) -> float:
    """One finite number above zero."""
    number = real(name, value)
    if number <= 0.0:
        raise bad(name, "a positive number", repr(value))
    return number


def count(name: str, value: Any, minimum: int = 1) -> int:
    """A whole number (an int, not a bool or a float) of at least ``minimum``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < minimum:
        expected = "a positive integer" if minimum == 1 else f"an integer of at least {minimum}"
        raise bad(name, expected, repr(value))
    return int(value)


def choice(name: str, value: Any, choices: Sequence[str], note: str = "") -> str:
    """One of the names ``choices``; ``note`` says more in the message."""
    if not isinstance(value, str) or value not in choices:
        raise bad(name, f"one of {list(choices)}{note}", repr(value))
    return value


def path(name: str, value: Any, expected: str = "a path") -> str:
    """A ``str`` or ``os.PathLike`` path, as a ``str``."""
    if not isinstance(value, (str, os.PathLike)):
        raise bad(name, expected, repr(value))
    return os.fspath(value)


def writable_folder(name: str, value: Any) -> Path:
    """A path to a file whose folder exists and can be written to, as a ``Path``."""
    target = Path(path(name, value))
    folder = target.resolve().parent
    if not folder.is_dir():
        raise ValueError(f"argument '{name}': the folder {folder} does not exist")
    if not os.access(folder, os.W_OK):
        raise ValueError(f"argument '{name}': the folder {folder} is not writable")
    return target


def robot_model(name: str, value: Any) -> Any:
    """A ``robodyn.Model``, or one in reduced coordinates (``robodyn.MimicModel``)."""
    from robodyn._core import Model
    from robodyn.mimic import MimicModel

    if not isinstance(value, (Model, MimicModel)):
        raise bad(name, "a robodyn.Model", repr(value))
    return value


def trajectory(name: str, value: Any) -> Any:
    """A ``robodyn.Trajectory``."""
    from robodyn.simulation import Trajectory

    if not isinstance(value, Trajectory):
        raise bad(name, "a robodyn.Trajectory", repr(value))
    return value


def callback(name: str, value: Any) -> Any:
    """None or something to call."""
    if value is not None and not callable(value):
        raise bad(name, "None or a function", repr(value))
    return value
