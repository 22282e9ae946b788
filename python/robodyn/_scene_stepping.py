"""Scenes stepped as MuJoCo's ``mj_step`` steps them: :func:`robodyn.simulate` and :func:`robodyn.step`
with ``integrator="mujoco"`` (the loop runs in Rust, ``robodyn._core.simulate_scene``)."""

from __future__ import annotations

from typing import Any

import numpy as np

from robodyn import _core
from robodyn._arguments import bad, callback, flag, numbers, real, robot_model
from robodyn.mimic import MimicModel

#: How close ``dt`` must be to a whole number of a scene's time steps (relative).
STEP_MULTIPLE_TOLERANCE = 1e-9


def simulate_scene(model: Any, q0: Any, v0: Any, t_end: float, dt: float | None, controller: Any, wrenches: Any,
                    progress: Any, constraints: Any, ctrl: Any, act0: Any, plastic0: Any) -> Any:
    """:func:`simulate` with ``integrator="mujoco"``: the scene stepped as ``mj_step`` steps it."""
    from robodyn.simulation import Trajectory, _controller_argument

    model = scene_model(model)
    if wrenches is not None:
        raise bad("wrenches", "None with integrator='mujoco' (wrenches on bodies are not taken there yet)",
                  "wrenches")
    if not (isinstance(constraints, str) and constraints == "model") and constraints:
        raise bad("constraints", "'model' with integrator='mujoco' (the scene's own equality constraints)",
                  repr(constraints))
    start = keyframe(model, q0).time if isinstance(q0, str) else 0.0
    q0, v0, ctrl, act0, plastic0 = scene_start(model, q0, v0, ctrl, act0, plastic0)
    h = model.options.timestep
    dt = h if dt is None else real("dt", dt)
    record_every = round(dt / h)
    if record_every < 1 or abs(record_every * h - dt) > STEP_MULTIPLE_TOLERANCE * dt:
        raise bad("dt", f"a whole number of the scene's time steps ({h} s) with integrator='mujoco'", repr(dt))
    steps = int(np.ceil((real("t_end", t_end) - start) / h - STEP_MULTIPLE_TOLERANCE))
    if steps < 0:
        raise bad("t_end", f"a time (s) not before the start, {start}", repr(t_end))
    result = _core.simulate_scene(model, q0, v0, steps, record_every, start=start, ctrl=ctrl,
                                  controller=_controller_argument(model, controller),
                                  progress=callback("progress", progress), act0=act0, plastic0=plastic0)
    series = ("q", "v", "a", "tau", "tau_passive", "ctrl", "tau_constraint", "act", "plastic")
    batch = result["q"].ndim == 3
    runs = [
        Trajectory(model, result["t"], integrator="mujoco",
                   **{key: result[key][k] if batch else result[key] for key in series},
                   **{key: result[key][k] for key in ("steps", "rejected_steps", "evaluations", "contacts")})
        for k in range(len(result["steps"]))
    ]
    return runs if batch else runs[0]


def scene_model(model: Any) -> _core.Model:
    """The model a scene's step takes: a :class:`MimicModel` without mimic joints is its full model."""
    if isinstance(model, MimicModel):
        if model.mimic_joints:
            raise bad("model", "a model without mimic joints with integrator='mujoco' (step its full model: "
                      "MuJoCo's soft model holds the mimic relations there, as joint equalities)", f"mimic joints {[name for name, *_ in model.mimic_joints]}")
        return model.full
    robot_model("model", model)
    return model


def scene_start(model: _core.Model, q0: Any, v0: Any, ctrl: Any, act0: Any,
                plastic0: Any) -> tuple[Any, Any, Any, Any, Any]:
    """(q0, v0, ctrl, act0, plastic0) of a scene's run: a keyframe's name gives its q, v, ctrl, act
    and plastic (those given win)."""
    if isinstance(q0, str):
        key = keyframe(model, q0)
        q0, v0 = key.q, key.v if v0 is None else v0
        ctrl, act0 = key.ctrl if ctrl is None else ctrl, key.act if act0 is None else act0
        plastic0 = key.plastic if plastic0 is None else plastic0
    q0 = numbers("q0", q0)
    v0 = np.zeros(q0.shape[:-1] + (model.nv,)) if v0 is None else numbers("v0", v0)
    if ctrl is not None and not callable(ctrl):
        ctrl = numbers("ctrl", ctrl)
    act0 = None if act0 is None else numbers("act0", act0)
    return q0, v0, ctrl, act0, None if plastic0 is None else numbers("plastic0", plastic0)


def keyframe(model: _core.Model, name: str) -> Any:
    """The keyframe ``q0`` names; a ValueError naming ``q0`` and the model's keyframes if none."""
    names = [key.name for key in model.keyframes]
    if name not in names:
        known = f"one of {names}" if names else "the model has none"
        raise bad("q0", f"a configuration or the name of one of the model's keyframes ({known})", repr(name))
    return model.keyframe(name)


def step_scene(model: Any, q: Any, v: Any, tau: Any, dt: float, derivatives: bool, constraints: Any,
                ctrl: Any, act: Any, plastic: Any) -> Any:
    """:func:`step` with ``integrator="mujoco"``: one ``mj_step`` of the scene."""
    model = scene_model(model)
    if flag("derivatives", derivatives):
        raise bad("derivatives", "False with integrator='mujoco' (the derivatives of MuJoCo's step are not made "
                  "yet)", "True")
    if not (isinstance(constraints, str) and constraints == "model") and constraints:
        raise bad("constraints", "'model' with integrator='mujoco' (the scene's own equality constraints)",
                  repr(constraints))
    h = model.options.timestep
    if abs(real("dt", dt) - h) > STEP_MULTIPLE_TOLERANCE * h:
        raise bad("dt", f"the scene's time step ({h} s) with integrator='mujoco'", repr(dt))
    ctrl = np.zeros(model.nu) if ctrl is None else ctrl
    act = np.zeros(model.na) if act is None else act
    plastic = model.plastic0 if plastic is None else plastic
    return _core.step_scene(model, q, v, tau, ctrl, act, plastic)
