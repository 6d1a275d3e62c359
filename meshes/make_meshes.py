"""Regenerate the example meshes (binary STL, millimetres).

    .venv/bin/python meshes/make_meshes.py

cube_20mm.stl
    A 20 mm cube centred at the origin, every face refined to a grid of
    triangles with edges <= 2.5 mm (every face can hit the floor when the
    cube is tossed).
block_10x10x5mm.stl
    A 10 x 10 x 5 mm block centred at the origin; only the bottom face (-z,
    the one pressed on the plane) is refined to edges <= 1 mm, the other faces
    only where needed to keep the mesh closed.
"""

from pathlib import Path

import numpy as np
import trimesh

from meshwear.geometry import face_normals, primitive, refine

HERE = Path(__file__).resolve().parent


def save(name, vertices, faces):
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    assert mesh.is_watertight and mesh.volume > 0.0, name
    path = HERE / name
    mesh.export(path, file_type="stl")  # binary STL
    print(f"{path.name}: {len(vertices)} vertices, {len(faces)} faces, "
          f"{path.stat().st_size / 1024:.0f} KiB")


def cube():
    vertices, faces = primitive("box", size=20.0)          # mm
    return refine(vertices, faces, 2.5)


def block():
    vertices, faces = primitive("box", size=[10.0, 10.0, 5.0])   # mm
    bottom = face_normals(vertices, faces)[:, 2] < -0.5
    return refine(vertices, faces, 1.0, face_mask=bottom)


if __name__ == "__main__":
    save("cube_20mm.stl", *cube())
    save("block_10x10x5mm.stl", *block())
