"""Writes the test meshes of this folder (run from anywhere): made for robodyn's tests, to compare
mesh inertia with MuJoCo's in every mode. BSD-3-Clause, as robodyn."""

from __future__ import annotations

import math
import struct
from pathlib import Path

HERE = Path(__file__).resolve().parent

#: a box's corners and its 12 triangles, counter-clockwise seen from outside
BOX_CORNERS = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
BOX_FACES = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]


def box(size, offset):
    return [tuple(o + s * c for o, s, c in zip(offset, size, corner)) for corner in BOX_CORNERS]


def write_binary_stl(path: Path, vertices, faces) -> None:
    data = bytearray(b"robodyn test mesh".ljust(80, b" "))
    data += struct.pack("<I", len(faces))
    for face in faces:
        data += struct.pack("<3f", 0.0, 0.0, 0.0)
        for k in face:
            data += struct.pack("<3f", *vertices[k])
        data += struct.pack("<H", 0)
    path.write_bytes(bytes(data))


def write_obj(path: Path, vertices, faces, comment: str) -> None:
    lines = [f"# {comment}"] + [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in vertices]
    lines += ["f " + " ".join(str(k + 1) for k in face) for face in faces]
    path.write_text("\n".join(lines) + "\n")


def main() -> None:
    # a 0.1 x 0.2 x 0.3 m box with a corner at the origin (its centre of mass is off the origin)
    write_binary_stl(HERE / "box.stl", box((0.1, 0.2, 0.3), (0, 0, 0)), BOX_FACES)
    # a tetrahedron, faces as quads would not do: triangles
    tetra = [(0, 0, 0), (0.2, 0, 0), (0, 0.15, 0), (0.02, 0.03, 0.1)]
    write_obj(HERE / "tetrahedron.obj", tetra, [(0, 2, 1), (0, 1, 3), (1, 2, 3), (0, 3, 2)], "a tetrahedron")
    # a non-convex L-shaped prism: the profile extruded along z, written with quads (triangulated on reading)
    profile = [(0, 0), (0.3, 0), (0.3, 0.1), (0.1, 0.1), (0.1, 0.25), (0, 0.25)]
    bottom = [(x, y, 0.0) for x, y in profile]
    top = [(x, y, 0.05) for x, y in profile]
    n = len(profile)
    faces = [(0, 5, 4, 3), (0, 3, 2, 1)]  # bottom, facing -z
    faces += [(n + 0, n + 1, n + 2, n + 3), (n + 0, n + 3, n + 4, n + 5)]  # top, facing +z
    faces += [(k, (k + 1) % n, n + (k + 1) % n, n + k) for k in range(n)]  # sides
    write_obj(HERE / "l_prism.obj", bottom + top, faces, "a non-convex L-shaped prism")
    # a box with one corner pulled out, written with quads: four of its quads are not planar, so
    # how a quad is cut into triangles changes the numbers
    warped = box((0.2, 0.1, 0.1), (0, 0, 0))
    warped[7] = (0.26, 0.13, 0.14)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    write_obj(HERE / "warped_box.obj", warped, quads, "a box with one corner pulled out, as quads")
    # a prism on a concave heptagon whose caps are not planar, written as two heptagons and
    # quads: how a polygon of five or more corners is cut into triangles changes the numbers;
    # a second object follows whose faces MuJoCo's reader ignores (it reads the first object's)
    radii = [0.10, 0.05, 0.11, 0.09, 0.04, 0.12, 0.10]
    ring = [(r * math.cos(2 * math.pi * k / 7), r * math.sin(2 * math.pi * k / 7)) for k, r in enumerate(radii)]
    n = len(ring)
    bottom = [(x, y, 0.01 * (k % 3)) for k, (x, y) in enumerate(ring)]
    top = [(0.8 * x, y, 0.15 + 0.02 * (k % 2)) for k, (x, y) in enumerate(ring)]
    caps = [tuple(reversed(range(n))), tuple(range(n, 2 * n))]
    sides = [(k, (k + 1) % n, n + (k + 1) % n, n + k) for k in range(n)]
    ignored = box((0.05, 0.05, 0.05), (0.3, 0, 0))
    lines = ["# a prism on a concave heptagon, caps not planar, then an object MuJoCo ignores", "o prism"]
    lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in bottom + top]
    lines += ["f " + " ".join(str(k + 1) for k in face) for face in caps + sides]
    lines += ["o ignored"] + [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in ignored]
    lines += ["f " + " ".join(str(2 * n + k + 1) for k in face) for face in BOX_FACES]
    (HERE / "warped_prism.obj").write_text("\n".join(lines) + "\n")
    # an open box (no lid): a surface, for shell inertia
    corners = box((0.2, 0.2, 0.1), (-0.1, -0.1, 0))
    write_obj(HERE / "open_box.obj", corners, [f for f in BOX_FACES if f not in [(1, 5, 7), (1, 7, 3)]], "a box without its lid")


if __name__ == "__main__":
    main()
