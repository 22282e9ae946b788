"""A walk over the public API with arguments of the wrong type. Each is a ValueError naming the
argument, never a TypeError, an AttributeError, an OverflowError or a Rust panic.

The walk finds the API itself: the functions of ``robodyn.__all__``, every public method and
settable property of ``robodyn.Model`` and the public functions of robodyn's submodules. Each
parameter of each, in turn, gets a value of no type it takes while the others get valid values
(``VALID`` and ``MADE``, by parameter name); a new function is walked as soon as it exists, and a new
parameter name fails the walk until it has a valid value. ``CASES`` adds wrong values of the
right type (negative counts, floats for integers, strings for flags)."""

from __future__ import annotations

import importlib
import inspect
import pickle
import pkgutil
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest

import robodyn
from robodyn.inertia import spatial_inertia
from conftest import REPOSITORY

UR5 = robodyn.load("ur5")
Q = UR5.neutral()
V = np.zeros(UR5.nv)
POSE = UR5.frame_pose(Q, "tool0")
URDF = """<robot name="arm"><link name="base"/><link name="link">
  <inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="link"/><axis xyz="0 0 1"/>
  <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"""
MJCF = REPOSITORY / "testdata" / "mjcf" / "iiwa14.xml"
#: UR5 with a finger on its tool that mimics the last wrist joint: in reduced coordinates, UR5's q.
MIMIC = robodyn.MimicModel(robodyn.load_urdf_string((REPOSITORY / "models" / "ur5.urdf").read_text().replace(
    "</robot>",
    '<link name="finger"><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" '
    'iyz="0"/></inertial></link><joint name="finger_joint" type="revolute"><parent link="tool0"/>'
    '<child link="finger"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/>'
    '<mimic joint="wrist_3_joint" multiplier="0.5"/></joint></robot>')))
DH_ROWS = [{"a": 0, "alpha": 0, "d": 0, "theta": 0, "type": "revolute"}]

#: A value no parameter of robodyn takes.
WRONG = object()

#: Submodules whose functions the walk leaves out, and why.
NOT_WALKED = {
    "robodyn.cli": "its input is the command line, checked by argparse (python/tests/test_cli.py)",
    "robodyn.convert": "its classes take Pinocchio's and MuJoCo's models, which it reads by their own API",
    "robodyn.crosscheck": "its functions take MuJoCo's models, which it reads by MuJoCo's API",
    "robodyn.symbolic": "it takes SymPy expressions and symbolic chains, which SymPy itself checks",
}

#: Parameters that take any value by design, and why.
ANY_VALUE = {
    "argument": "the name an error message gives the checked path, any text",
}

INERTIA = np.diag([1.0, 2.0, 2.5])
#: A valid value for each parameter name of the API.
VALID: dict[str, Any] = {
    "model": UR5, "q": Q, "v": V, "a": V, "tau": V, "q0": Q, "q1": Q, "v0": V, "f_ext": None,
    "frame": "tool0", "target": POSE, "task": "full", "reference": "world", "method": None,
    "n": 4, "seed": 1, "dt": 0.005, "t_end": 0.01, "integrator": "rk4", "out": None,
    "name_or_path": "ur5", "floating_base": False, "check_inertia": True, "strict": False,
    "text": URDF, "source": "<string>", "rows": DH_ROWS, "derivatives": False,
    "mass": 1.0, "radius": 0.1, "length": 0.2, "inner_radius": 0.05, "size": (0.1, 0.2, 0.3),
    "axis": "z", "about": "center", "inertia": INERTIA, "inertia_com": INERTIA, "com": (0.0, 0.0, 0.1),
    "rotation": np.eye(3), "matrix": spatial_inertia(1.0, (0, 0, 0.1), INERTIA),
    "inertia_body": INERTIA, "omega_body": (0.1, 0.2, 0.3), "moment_body": (0.0, 0.0, 0.0),
    "quaternion": (0.0, 0.0, 0.0, 1.0), "angles": (0.1, 0.2, 0.3), "orientation": "quaternion",
    "initial": None, "inertia_transverse": 1.0, "inertia_axial": 2.0, "omega_axial": 1.0,
    "quantities": ("tau",), "chunk": 4, "per_task": 2, "progress": None, "client": None,
    "constraints": [robodyn.PointAnchor("tool0")], "joint": "elbow_joint", "leader": "shoulder_lift_joint",
    "frame1": "tool0", "frame2": "wrist_3_link", "q_full": MIMIC.full.neutral(),
    "ctrl": np.zeros(UR5.nu), "act": np.zeros(UR5.na), "key": "home", "geom1": "floor", "geom2": "upper_link",
    "positions": np.zeros((8, 3)), "rotations": np.tile(np.eye(3).ravel(), (8, 1)),
}
#: Methods that need another model than UR5 to run (a keyframe): the method -> its model.
PANDA = robodyn.load(REPOSITORY / "testdata" / "mjcf" / "panda_nomesh.xml")
#: ... and contact parameters (geoms)
ARM = robodyn.load(REPOSITORY / "testdata" / "mjcf" / "viewer_arm.xml")
BOUND = {
    "robodyn.Model.keyframe": PANDA, "robodyn.MimicModel.keyframe": robodyn.MimicModel(PANDA),
    "robodyn.Model.contact_parameters": ARM, "robodyn.MimicModel.contact_parameters": robodyn.MimicModel(ARM),
    "robodyn.Model.collide_placed": ARM, "robodyn.MimicModel.collide_placed": robodyn.MimicModel(ARM),
    # ... and contact dynamics: a reduction without mimic joints (the full model's)
    "robodyn.MimicModel.contact_forward_dynamics": robodyn.MimicModel(UR5),
}


def _urdf_file(folder: Path) -> str:
    path = folder / "arm.urdf"
    path.write_text(URDF)
    return str(path)


#: Valid values made when a call needs them: parameter name -> a function of the folder files go in.
MADE: dict[str, Callable[[Path], Any]] = {
    "path": _urdf_file,
    "trajectory": lambda folder: robodyn.simulate(UR5, Q, t_end=0.01, dt=0.005),
}


def _scene_run() -> Any:
    """A box dropped on a plane, stepped as MuJoCo steps it: a run that records contacts."""
    scene = robodyn.load_mjcf_string("""<mujoco><worldbody><geom name="floor" type="plane" size="1 1 1"/>
      <body name="box" pos="0 0 0.1"><freejoint/><geom name="box" type="box" size="0.1 0.1 0.1"/></body>
      </worldbody></mujoco>""")
    return robodyn.simulate(scene, scene.neutral(), t_end=0.01, integrator="mujoco")


def _dataset_file(folder: Path) -> str:
    path = str(folder / "read.zarr")
    robodyn.dataset(UR5, 4, chunk=4, out=path)
    return path


#: Valid values that differ for one function: its name -> parameter -> a function of the folder
#: files go in.
SPECIFIC: dict[str, dict[str, Callable[[Path], Any]]] = {
    "robodyn.load_mjcf": {"path": lambda folder: str(MJCF)},
    "robodyn.load_mjcf_string": {"text": lambda folder: MJCF.read_text()},
    "robodyn.dataset": {"out": lambda folder: str(folder / "states.zarr")},
    "robodyn.read_dataset": {"path": lambda folder: _dataset_file(folder)},
    "robodyn.Model.to_html": {"path": lambda folder: str(folder / "model.html")},
    "robodyn.MimicModel.to_html": {"path": lambda folder: str(folder / "model.html")},
    "robodyn.plot.animate_trajectory": {"path": lambda folder: str(folder / "motion.gif")},
    "robodyn.plot.check_animation_path": {"path": lambda folder: str(folder / "motion.gif")},
    "robodyn.plot.check_figure_path": {"path": lambda folder: str(folder / "figure.png")},
    "robodyn.plot.plot_trajectory": {"path": lambda folder: str(folder / "figure.png")},
    "robodyn.plot.plot_contact_forces": {"path": lambda folder: str(folder / "figure.png"),
                                         "trajectory": lambda folder: _scene_run()},
    "robodyn.viewer.check_html_path": {"path": lambda folder: str(folder / "page.html")},
    "robodyn.viewer.model_html": {"path": lambda folder: str(folder / "model.html")},
    "robodyn.viewer.trajectory_html": {"path": lambda folder: str(folder / "motion.html")},
}


def _submodules() -> list[Any]:
    names = [m.name for m in pkgutil.iter_modules(robodyn.__path__, "robodyn.") if not m.name.split(".")[-1].startswith("_")]
    return [importlib.import_module(name) for name in sorted(names) if name not in NOT_WALKED]


def public_api() -> dict[str, Callable[..., Any]]:
    """Every public function of robodyn by its qualified name: ``robodyn.__all__``'s, Model's
    methods and settable properties (as a function setting them), the submodules' own."""
    found: dict[str, Callable[..., Any]] = {}
    seen: set[int] = set()

    def add(name: str, function: Callable[..., Any]) -> None:
        if id(function) not in seen:
            seen.add(id(function))
            found[name] = function

    for name in robodyn.__all__:
        if inspect.isroutine(getattr(robodyn, name)):
            add(f"robodyn.{name}", getattr(robodyn, name))
    for name in dir(robodyn.Model):
        attribute = inspect.getattr_static(robodyn.Model, name)
        if name.startswith("_"):
            continue
        if inspect.isroutine(attribute):
            add(f"robodyn.Model.{name}", getattr(robodyn.Model, name))
        elif _settable(name):
            add(f"robodyn.Model.{name} =", _setter(name))
    for name in dir(robodyn.MimicModel):
        attribute = inspect.getattr_static(robodyn.MimicModel, name)
        if not name.startswith("_") and inspect.isroutine(attribute):
            add(f"robodyn.MimicModel.{name}", getattr(robodyn.MimicModel, name))
    for module in _submodules():
        names = getattr(module, "__all__", [n for n in vars(module) if not n.startswith("_")])
        for name in names:
            function = getattr(module, name)
            if inspect.isfunction(function) and function.__module__ == module.__name__:
                add(f"{module.__name__}.{name}", function)
    return found


def _settable(name: str) -> bool:
    model = pickle.loads(pickle.dumps(UR5))
    try:
        setattr(model, name, getattr(model, name))
    except AttributeError:
        return False
    return True


def _setter(name: str) -> Callable[..., Any]:
    def assign(model: Any, **value: Any) -> None:
        setattr(model, name, value[name])

    assign.__signature__ = inspect.Signature(  # type: ignore[attr-defined]
        [inspect.Parameter("model", inspect.Parameter.POSITIONAL_ONLY),
         inspect.Parameter(name, inspect.Parameter.POSITIONAL_OR_KEYWORD)]
    )
    return assign


API = public_api()


def _walk() -> list[tuple[str, str, Any]]:
    """(function, parameter, wrong value): ``WRONG`` for every parameter, None too where None is
    neither the default nor in the annotation."""
    cases = []
    for qualified, function in API.items():
        for parameter in inspect.signature(function).parameters.values():
            if parameter.name in ("self", "cls") or parameter.kind in (parameter.VAR_POSITIONAL, parameter.VAR_KEYWORD):
                continue
            if qualified.startswith("robodyn.Model.") and parameter is next(iter(inspect.signature(function).parameters.values())):
                continue
            if parameter.name in ANY_VALUE:
                continue
            cases.append((qualified, parameter.name, WRONG))
            if parameter.default is not None and "None" not in str(parameter.annotation):
                cases.append((qualified, parameter.name, None))
    return cases


WALK = _walk()


def _call(qualified: str, wrong_parameter: str, wrong_value: Any, folder: Path) -> Any:
    """The function called with ``wrong_value`` for one parameter and valid values for the
    others (the required ones and the one a method is bound to)."""
    function = API[qualified]
    made = {**MADE, **SPECIFIC.get(qualified, {})}
    positional, keywords = [], {}
    parameters = list(inspect.signature(function).parameters.values())
    if qualified.startswith(("robodyn.Model.", "robodyn.MimicModel.")):
        # bound to a copy: a setter must not change the model the other cases use
        bound = BOUND.get(qualified, MIMIC if qualified.startswith("robodyn.MimicModel.") else UR5)
        positional.append(pickle.loads(pickle.dumps(bound)))
        parameters = parameters[1:]
    for parameter in parameters:
        if parameter.kind in (parameter.VAR_POSITIONAL, parameter.VAR_KEYWORD):
            continue
        if parameter.name == wrong_parameter:
            value = wrong_value
        elif qualified.endswith(" ="):
            value = getattr(UR5, parameter.name)
        elif parameter.name in made and (parameter.default is parameter.empty or parameter.name in SPECIFIC.get(qualified, {})):
            value = made[parameter.name](folder)
        elif parameter.default is not parameter.empty:
            continue
        else:
            assert parameter.name in VALID, f"{qualified}: give parameter '{parameter.name}' a valid value in VALID"
            value = VALID[parameter.name]
        if parameter.kind == parameter.POSITIONAL_ONLY:
            positional.append(value)
        else:
            keywords[parameter.name] = value
    return function(*positional, **keywords)


def test_the_walk_finds_the_api():
    """It reaches the top level, Model's methods and setters and the submodules' functions."""
    for name in ("robodyn.load", "robodyn.step", "robodyn.simulate_many", "robodyn.Model.inverse_dynamics",
                 "robodyn.Model.operational_space", "robodyn.Model.gravity =", "robodyn.inertia.solid_box",
                 "robodyn.viewer.model_html", "robodyn.MimicModel.inverse_kinematics"):
        assert name in API, name
    assert ("robodyn.step", "derivatives", WRONG) in WALK


@pytest.mark.parametrize(("qualified", "parameter", "wrong"), WALK,
                         ids=[f"{q}-{p}-{'None' if w is None else 'object'}" for q, p, w in WALK])
def test_every_parameter_refuses_a_value_of_the_wrong_type(qualified, parameter, wrong, tmp_path):
    with pytest.raises(ValueError) as error:
        result = _call(qualified, parameter, wrong, tmp_path)
        if hasattr(result, "close"):
            result.close()
    message = str(error.value)
    assert f"'{parameter}'" in message, message


def test_every_function_runs_with_the_valid_values(tmp_path):
    """The walk's calls are valid but for the one wrong value: each function runs with valid values only."""
    for qualified in API:
        result = _call(qualified, "", WRONG, tmp_path)
        if hasattr(result, "close"):
            result.close()


#: (call, the argument it gets wrong): wrong values of a type the argument may take
CASES = [
    (lambda: robodyn.load(42), "name_or_path"),
    (lambda: robodyn.load("ur5", floating_base="yes"), "floating_base"),
    (lambda: robodyn.load("ur5", floating_base=None), "floating_base"),
    (lambda: robodyn.load("ur5", check_inertia=1), "check_inertia"),
    (lambda: robodyn.load_urdf(3.5), "path"),
    (lambda: robodyn.load_urdf_string(b"<robot/>"), "text"),
    (lambda: robodyn.load_urdf_string("<robot/>", source=7), "source"),
    (lambda: robodyn.load_urdf_string("<robot/>", floating_base="no"), "floating_base"),
    (lambda: robodyn.load_mjcf(None), "path"),
    (lambda: robodyn.load_mjcf_string(None), "text"),
    (lambda: robodyn.from_dh([{"a": 0, "alpha": 0, "d": 0, "theta": 0, "type": "revolute"}], convention="craig"), "convention"),
    (lambda: robodyn.from_dh("not rows"), "rows"),
    (lambda: robodyn.from_dh([{"a": "x", "alpha": 0, "d": 0, "theta": 0, "type": "revolute"}]), "a"),
    (lambda: UR5.random_configuration(n=-1), "n"),
    (lambda: UR5.random_configuration(n=2.5), "n"),
    (lambda: UR5.random_configuration(n="3"), "n"),
    (lambda: UR5.random_configuration(n=True), "n"),
    (lambda: UR5.random_configuration(seed=-5), "seed"),
    (lambda: UR5.random_configuration(seed=1.5), "seed"),
    (lambda: UR5.random_configuration(seed="x"), "seed"),
    (lambda: UR5.inverse_dynamics("q", V, V), "q"),
    (lambda: UR5.inverse_dynamics(None, V, V), "q"),
    (lambda: UR5.inverse_dynamics(Q, V, V, f_ext="none"), "f_ext"),
    (lambda: UR5.forward_dynamics(Q, None, V), "v"),
    (lambda: UR5.mass_matrix(Q, method=3), "method"),
    (lambda: UR5.mass_matrix(Q, method="cholesky"), "method"),
    (lambda: UR5.generalized_gravity(Q, method=None), "method"),
    (lambda: UR5.frame_pose(Q, None), "frame"),
    (lambda: UR5.frame_pose(Q, -1), "frame"),
    (lambda: UR5.frame_pose(Q, 2.0), "frame"),
    (lambda: UR5.jacobian(Q, "tool0", reference=0), "reference"),
    (lambda: UR5.jacobian_time_variation(Q, V, "tool0", reference=None), "reference"),
    (lambda: UR5.frame_velocity(Q, V, "tool0", reference=1.0), "reference"),
    (lambda: UR5.frame_acceleration(Q, V, V, "tool0", reference=b"world"), "reference"),
    (lambda: UR5.manipulability(Q, "tool0", task=5), "task"),
    (lambda: UR5.manipulability(Q, "tool0", task=[-1, 2]), "task"),
    (lambda: UR5.workspace("tool0", n=-3), "n"),
    (lambda: UR5.workspace("tool0", n=10.0), "n"),
    (lambda: UR5.workspace("tool0", n=10, seed="a"), "seed"),
    (lambda: UR5.inverse_kinematics("tool0", POSE, max_iterations=-1), "max_iterations"),
    (lambda: UR5.inverse_kinematics("tool0", POSE, restarts=2.5), "restarts"),
    (lambda: UR5.inverse_kinematics("tool0", POSE, tolerance="small"), "tolerance"),
    (lambda: UR5.inverse_kinematics("tool0", POSE, damping=None), "damping"),
    (lambda: UR5.inverse_kinematics("tool0", POSE, position_only="yes"), "position_only"),
    (lambda: UR5.inverse_kinematics("tool0", POSE, seed=-1), "seed"),
    (lambda: UR5.integrate(Q, V, dt="0.1"), "dt"),
    (lambda: UR5.integrate(Q, V, dt=None), "dt"),
    (lambda: UR5.difference(Q, "q1"), "q1"),
    (lambda: setattr(UR5, "gravity", "down"), "gravity"),
    (lambda: setattr(UR5, "armature", None), "armature"),
    (lambda: setattr(UR5, "damping", -1), "damping"),
    (lambda: robodyn.simulate(UR5, Q, t_end="1"), "t_end"),
    (lambda: robodyn.simulate(UR5, Q, dt="fast"), "dt"),
    (lambda: robodyn.simulate(UR5, Q, integrator=4), "integrator"),
    (lambda: robodyn.simulate(UR5, "q0"), "q0"),
    (lambda: robodyn.simulate(UR5, Q, rtol="tight"), "rtol"),
    (lambda: robodyn.simulate(UR5, Q, limits=None), "limits"),
    (lambda: robodyn.simulate(UR5, Q, controller="pd"), "controller"),
    (lambda: robodyn.simulate(UR5, Q, controller=robodyn.PD(kp="high", kd=1.0, q_ref=Q)), "kp"),
    (lambda: robodyn.simulate(UR5, Q, t_end=0.01, controller=robodyn.PD(kp=1.0, kd=None, q_ref=Q)), "kd"),
    (lambda: robodyn.step(UR5, Q, V, V, 0.01, derivatives="yes"), "derivatives"),
    (lambda: robodyn.step(UR5, Q, V, V, 0.01, derivatives=1), "derivatives"),
]


@pytest.mark.parametrize(("call", "argument"), CASES, ids=[f"{k}-{a}" for k, (_, a) in enumerate(CASES)])
def test_wrong_type_is_a_value_error_naming_the_argument(call, argument):
    with pytest.raises(ValueError) as error:
        call()
    message = str(error.value)
    assert f"'{argument}'" in message, message
    assert "Some(" not in message and "None)" not in message.replace("got None)", ""), message
