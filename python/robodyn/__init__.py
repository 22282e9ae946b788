"""robodyn: rigid-body dynamics for robots.

A Rust core (RNEA, CRBA, ABA, kinematics, Jacobians) behind a NumPy API::

    import numpy as np, robodyn
    m = robodyn.load("ur5")                 # bundled model, or a path to a .urdf
    q = m.random_configuration()
    tau = m.inverse_dynamics(q, np.zeros(m.nv), np.zeros(m.nv))

Every numeric method takes one state (``q`` of shape ``(nq,)``) or a batch (``(N, nq)``);
batches release the GIL and run on all cores. Conventions: 6-vectors and Jacobian rows are
``[linear; angular]``; quaternions are ``[qx, qy, qz, qw]``; SI units.
"""

from __future__ import annotations

import os
import sys
import warnings
from pathlib import Path
from typing import Literal, overload

from robodyn._core import (
    Distance,
    FrameAnchor,
    JointCoupling,
    Keyframe,
    Model,
    Options,
    PointAnchor,
    SimulationError,
    bundled_names,
    load_bundled,
    load_dh,
    load_dh_dict,
    load_mjcf,
    load_mjcf_string,
    load_urdf,
    load_urdf_string,
)
from robodyn import _arguments
from robodyn.operational_space import operational_space as _operational_space
from robodyn.simulation import (
    PD,
    AccuracyError,
    AccuracyWarning,
    ComputedTorque,
    GravityCompensation,
    Trajectory,
    simulate,
    step,
)
from robodyn.datasets import dataset, read_dataset, simulate_many
from robodyn.mimic import MimicModel


def _operational_space_method(self, q, v, frame, task="full", damping=None, reference="world"):
    """Λ, μ, p and J̄ of a frame's task (:func:`robodyn.operational_space.operational_space` of
    this model), composed in NumPy from the core's batched calls."""
    return _operational_space(self, q, v, frame, task, damping, reference)


Model.operational_space = _operational_space_method


def _view(self, q=None, **options):
    """The robot in a browser page at ``q`` (default: neutral), served from this machine: a
    :class:`robodyn.viewer.Viewer` (``viewer.show(q)`` poses it, ``viewer.close()`` stops it).
    Options: ``frames``, ``com``, ``ground`` (overlays), ``groups`` (MJCF geom groups drawn),
    ``host``, ``port``, ``open_browser``."""
    from robodyn.viewer import Viewer

    return Viewer(self, q, **options)


def _to_html(self, path, q=None, **options):
    """Writes one self-contained HTML file showing the robot at ``q`` (default: neutral) that
    opens offline in any browser. Options: ``frames``, ``com``, ``ground``, ``groups``."""
    from robodyn.viewer import model_html

    return model_html(self, path, q, **options)


Model.view = _view
Model.to_html = _to_html

__all__ = [
    "AccuracyError",
    "AccuracyWarning",
    "ComputedTorque",
    "Distance",
    "FrameAnchor",
    "JointCoupling",
    "Keyframe",
    "MimicModel",
    "Options",
    "PointAnchor",
    "dataset",
    "read_dataset",
    "simulate_many",
    "GravityCompensation",
    "Model",
    "PD",
    "SimulationError",
    "Trajectory",
    "simulate",
    "step",
    "ModelWarning",
    "from_dh",
    "load",
    "models",
    "load_mjcf",
    "load_mjcf_string",
    "load_urdf",
    "load_urdf_string",
    "__version__",
]
__version__ = "0.1.0"


class ModelWarning(UserWarning):
    """A model loaded, but with something you should know (see ``Model.warnings``)."""


# the warning (a UserWarning, like ModelWarning) and error of simulate's accuracy check live
# beside simulate, in robodyn.simulation


def models() -> list[str]:
    """Names of the robot models bundled with robodyn (``robodyn.load(name)`` loads one)."""
    return list(bundled_names())


def _example_robot_data_dir() -> Path | None:
    """The robots folder of the ``example-robot-data`` package (PyPI), when it is installed."""
    for entry in sys.path:
        folder = Path(entry) / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if folder.is_dir():
            return folder
    return None


def _find_file(name: str) -> Path:
    """``name`` as a path, or else a file of that name in example-robot-data's robots folder.

    Raises ``FileNotFoundError`` saying where robodyn looked and how to get example-robot-data."""
    path = Path(name).expanduser()
    if path.exists():
        return path
    looked = [f"{path.resolve()}"]
    robots = _example_robot_data_dir()
    if path.parent == Path("."):
        if robots is not None:
            matches = sorted(robots.rglob(path.name))
            if matches:
                return matches[0]
            looked.append(f"example-robot-data's robots folder {robots}")
        else:
            looked.append("example-robot-data (not installed: pip install 'robodyn[robots]' brings its URDFs)")
    raise FileNotFoundError(
        f"model file not found: '{name}'; looked in {' and in '.join(looked)}; "
        f"bundled models are {models()}"
    )


@overload
def load(
    name_or_path: str | os.PathLike[str], floating_base: bool = False, check_inertia: bool = True,
    strict: bool = False, mimic: Literal[False] = False,
) -> Model: ...
@overload
def load(
    name_or_path: str | os.PathLike[str], floating_base: bool = False, check_inertia: bool = True,
    strict: bool = False, *, mimic: Literal[True],
) -> MimicModel: ...
def load(
    name_or_path: str | os.PathLike[str], floating_base: bool = False, check_inertia: bool = True,
    strict: bool = False, mimic: bool = False,
) -> Model | MimicModel:
    """Load a robot model.

    ``name_or_path`` is a bundled model's name (see :func:`models`), a path to a URDF file, an MJCF
    file (``.xml``, MuJoCo's format), or a DH table in TOML (``.toml``, the format :func:`from_dh`
    documents). A bare file name that does not exist in the working directory is also looked up in
    the ``example-robot-data`` package when it is installed (``pip install 'robodyn[robots]'``;
    ``robodyn.load("talos_full_v2.urdf")``).
    ``floating_base=True`` puts a free joint named ``root_joint`` between the world and the root
    link (q gains ``[x, y, z, qx, qy, qz, qw]``, v gains ``[v_linear, omega]`` in the base frame).

    ``check_inertia=False`` loads a file whose inertia tensors are not positive semi-definite (a few
    published URDFs have them) and reports each as a :class:`ModelWarning` instead of failing.

    A URDF element or attribute the specification does not know (a typo such as ``<inertal>``) is a
    :class:`ModelWarning` naming the file, line and the nearest known name; in MJCF it is an error,
    as in MuJoCo. ``strict=True`` turns every warning into a ``ValueError``.

    URDF mimic joints (``<mimic>``: q_f = multiplier q_l + offset) are joints of their own by default,
    held as :class:`JointCoupling` constraints in ``m.constraints`` (which :func:`simulate` holds);
    a :class:`ModelWarning` says so. ``mimic=True`` enforces them in reduced coordinates: a
    :class:`MimicModel`, whose q and v leave the followers out and whose every method (dynamics,
    kinematics, derivatives, constraints, simulation) takes and returns them. The leader may come
    anywhere in the tree; a cycle of relations, or a relation between joints of different kinds,
    is a ``ValueError``.

    Raises ``FileNotFoundError`` for a missing file (saying where robodyn looked) and ``ValueError``
    for an invalid model, naming the file, element and line, or for a wrong argument.
    """
    text = _arguments.path("name_or_path", name_or_path, "a model name or a path")
    floating_base = _arguments.flag("floating_base", floating_base)
    check_inertia = _arguments.flag("check_inertia", check_inertia)
    strict = _arguments.flag("strict", strict)
    mimic = _arguments.flag("mimic", mimic)
    model = _load_model(text, floating_base, check_inertia)
    if mimic:
        model = MimicModel(model)
    if strict and model.warnings:
        raise ValueError("strict=True: " + " | ".join(model.warnings))
    for message in model.warnings:
        warnings.warn(message, ModelWarning, stacklevel=2)
    if mimic:
        return model
    held = [c.joint for c in model.constraints if isinstance(c, JointCoupling) and c.joint in
            {follower for follower, _, _, _ in model.mimic_joints}]
    if held:
        warnings.warn(
            f"{text}: {len(held)} mimic joint(s) ({', '.join(repr(name) for name in held[:3])}"
            f"{', …' if len(held) > 3 else ''}) are joints of their own, "
            "held as robodyn.JointCoupling constraints in m.constraints (simulate holds them); "
            "robodyn.load(..., mimic=True) enforces them in reduced coordinates", ModelWarning, stacklevel=2)
    return model


def _load_model(text: str, floating_base: bool, check_inertia: bool) -> Model:
    """The model ``load`` names, before its warnings are reported."""
    if text in bundled_names():
        return load_bundled(text, floating_base)
    suffix = Path(text).suffix.lower()
    if suffix not in {".toml", ".xml", ".urdf"}:
        if not Path(text).expanduser().exists():
            raise FileNotFoundError(f"model file not found: '{text}' (and it is not a bundled model: {models()})")
        raise ValueError(
            f"argument 'name_or_path': expected a .urdf, MJCF .xml or .toml (DH table) file or one of {models()}, "
            f"got '{text}'"
        )
    path = _find_file(text)
    if suffix == ".toml":
        return load_dh(str(path))
    return load_mjcf(str(path)) if suffix == ".xml" else load_urdf(str(path), floating_base, check_inertia)


def _rows_or_none(rows: object) -> list[object]:
    """The rows of a DH table as a list, or a list holding only None when ``rows`` is not iterable."""
    try:
        return list(rows)  # type: ignore[call-overload]
    except TypeError:
        return [None]


def from_dh(
    rows: list[dict],
    convention: str = "modified",
    *,
    name: str = "dh_robot",
    base: dict | None = None,
    tool: dict | None = None,
    gravity=None,
    angle_unit: str = "radian",
) -> Model:
    """Build a robot from a Denavit-Hartenberg table.

    ``convention``: ``"modified"`` (Craig: row i holds α_{i-1}, a_{i-1}, θ_i, d_i and
    ``ⁱ⁻¹T_i = Rx(α) Tx(a) Rz(θ) Tz(d)``) or ``"standard"`` (row i holds θ_i, d_i, a_i, α_i and
    ``ⁱ⁻¹T_i = Rz(θ) Tz(d) Tx(a) Rx(α)``). Each row is a dict::

        {"type": "revolute" | "prismatic", "a": ..., "alpha": ..., "d": ..., "theta": ...,
         "name": "joint1", "mass": 0.0, "com": [x, y, z], "inertia": [ixx, iyy, izz, ixy, ixz, iyz],
         "lower": -inf, "upper": inf}

    The joint variable adds to θ (revolute) or d (prismatic), so the table's θ or d is the joint
    offset. Mass, centre of mass and inertia (about the centre of mass) are in DH frame i.
    ``base`` and ``tool`` are ``{"xyz": [...], "rpy": [...]}``: DH frame 0 in the world and the tool
    frame in the last DH frame. Frames: ``"base"``, one per row (DH frame i, named after the row) and
    ``"tool"``. ``angle_unit="degree"`` reads α, θ, revolute limits and rpy in degrees. A ``.toml``
    file with the same keys (``[[joint]]`` rows) loads with :func:`load`.
    """
    if isinstance(rows, (str, bytes, dict)) or not all(isinstance(row, dict) for row in _rows_or_none(rows)):
        raise ValueError(f"argument 'rows': expected a list of dicts, one per joint, got {rows!r}")
    document = {"name": name, "convention": convention, "angle_unit": angle_unit, "joint": list(rows)}
    for key, value in (("base", base), ("tool", tool), ("gravity", gravity)):
        if value is not None:
            document[key] = value
    return load_dh_dict(document)
