"""Freezes Pinocchio's outputs into testdata/reference/ so tests keep a reference when Pinocchio is
missing, and so the Rust tests can check the bundled models without Python.

Run from the repository root with the test environment: ``.venv/bin/python python/tests/make_reference.py``.
Each file records Pinocchio's version, the URDF's SHA-256 and, for a few random states in robodyn's
layout (q, v, a, tau), Pinocchio's τ = rnea(q, v, a), M = crba(q), g(q), bias C(q, v)v + g,
q̈ = aba(q, v, tau), every frame's pose and world-aligned Jacobians of a few frames.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin

sys.path.insert(0, str(Path(__file__).parent))
import robodyn  # noqa: E402
from robodyn.convert import PinocchioLayout  # noqa: E402
from conftest import REFERENCE_DIR, REPOSITORY, ROBOTS  # noqa: E402

STATES = 3
JACOBIAN_FRAMES = 4


def reference(name: str, urdf: Path, floating_base: bool, model, source: str) -> dict:
    pin_model = (
        pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
        if floating_base
        else pin.buildModelFromUrdf(str(urdf))
    )
    pin_model.gravity.linear = np.asarray(model.gravity)
    data = pin_model.createData()
    mapping = PinocchioLayout(model, pin_model)
    rng = np.random.default_rng(2026)
    frames = model.frame_names
    jacobian_frames = sorted({frames[int(k)] for k in np.linspace(0, len(frames) - 1, JACOBIAN_FRAMES)})
    states = []
    for k in range(STATES):
        q = model.random_configuration(seed=100 + k)
        v, a, tau = (rng.uniform(-1, 1, model.nv) for _ in range(3))
        pq, pv = mapping.q_to_pinocchio(q), mapping.v_to_pinocchio(v)
        mass = pin.crba(pin_model, data, pq)
        mass = np.triu(mass) + np.triu(mass, 1).T
        pin.framesForwardKinematics(pin_model, data, pq)
        poses = {f: data.oMf[pin_model.getFrameId(f)].homogeneous.tolist() for f in frames}
        pin.computeJointJacobians(pin_model, data, pq)
        jacobians = {
            f: mapping.jacobian_from_pinocchio(
                pin.getFrameJacobian(pin_model, data, pin_model.getFrameId(f), pin.LOCAL_WORLD_ALIGNED)
            ).tolist()
            for f in jacobian_frames
        }
        states.append(
            {
                "q": q.tolist(),
                "v": v.tolist(),
                "a": a.tolist(),
                "tau": tau.tolist(),
                "rnea": mapping.v_from_pinocchio(pin.rnea(pin_model, data, pq, pv, mapping.v_to_pinocchio(a))).tolist(),
                "mass_matrix": mapping.matrix_from_pinocchio(mass).tolist(),
                "gravity": mapping.v_from_pinocchio(pin.computeGeneralizedGravity(pin_model, data, pq)).tolist(),
                "bias": mapping.v_from_pinocchio(pin.nle(pin_model, data, pq, pv)).tolist(),
                "aba": mapping.v_from_pinocchio(pin.aba(pin_model, data, pq, pv, mapping.v_to_pinocchio(tau))).tolist(),
                "frame_poses": poses,
                "world_jacobians": jacobians,
            }
        )
    return {
        "provenance": {
            "generator": "python/tests/make_reference.py",
            "pinocchio_version": pin.__version__,
            "urdf": source,
            "urdf_sha256": hashlib.sha256(urdf.read_bytes()).hexdigest(),
            "floating_base": floating_base,
            "gravity": list(model.gravity),
            "layout": "robodyn: q, v and matrix rows/columns in robodyn's joint order; continuous joints as angles",
        },
        "nq": model.nq,
        "nv": model.nv,
        "joint_names": model.joint_names,
        "states": states,
    }


def main() -> None:
    REFERENCE_DIR.mkdir(parents=True, exist_ok=True)
    robots = robodyn._example_robot_data_dir()
    jobs = [
        (f"pinocchio_{name}", robots / path, floating, f"example-robot-data robots/{path}")
        for name, (path, floating) in ROBOTS.items()
    ]
    jobs += [
        (f"pinocchio_bundled_{name}", REPOSITORY / "models" / f"{name}.urdf", False, f"models/{name}.urdf")
        for name in robodyn.models()
    ]
    for name, urdf, floating, source in jobs:
        bundled = name.startswith("pinocchio_bundled_")
        model = robodyn.load(source.split("/")[-1].removesuffix(".urdf")) if bundled else robodyn.load(urdf, floating)
        result = reference(name, urdf, floating, model, source)
        (REFERENCE_DIR / f"{name}.json").write_text(json.dumps(result, indent=None, separators=(",", ":")) + "\n")
        print(f"wrote {name}.json")


if __name__ == "__main__":
    main()
