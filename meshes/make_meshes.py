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
slider_shoe_mm.stl
    A CAD-style slider shoe as a CAD system exports it: a 40 x 12 mm pad,
    chamfered 2 x 1 mm at both ends, with a cylindrical crown (radius 28.3
    mm, 24 facets), extruded 12 mm. Flat faces carry no inner vertices: the
    36 x 12 mm running face is two triangles, the side faces are fans of long
    slivers (aspect ratios up to ~60). meshwear refines it where it can touch
    (``resolution`` in examples/cad_part.toml).
bushing_d10.1_mm.stl
    A plain bushing: bore 10.1 mm, outer diameter 16 mm, 3 mm long, its axis
    along z from z = -1.5 to 1.5 mm; 1024 facets round the bore (each 31 µm
    wide), so a shaft 0.1 mm smaller rests on several of them
    (examples/shaft_in_worn_bushing.toml).
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


def shoe(width=12.0, segments=24):
    """The slider shoe's profile in x-z (mm), extruded along y, tessellated
    the way CAD exports are: fans on the flat end faces, strips on the rest."""
    profile = [(-18.0, 0.0), (18.0, 0.0), (20.0, 1.0)]
    # crown: an arc about (0, -16) from (20, 4) over the top to (-20, 4)
    radius = np.hypot(20.0, 20.0)
    for a in np.linspace(np.pi / 4, 3 * np.pi / 4, segments + 1):
        profile.append((radius * np.cos(a), -16.0 + radius * np.sin(a)))
    profile.append((-20.0, 1.0))
    p = np.array(profile)
    k = len(p)
    vertices = np.concatenate([np.column_stack([p[:, 0], np.full(k, -width / 2), p[:, 1]]),
                               np.column_stack([p[:, 0], np.full(k, width / 2), p[:, 1]])])
    faces = []
    for i in range(k):                       # strips around the profile
        j = (i + 1) % k
        faces += [[i, j, k + j], [i, k + j, k + i]]
    for i in range(1, k - 1):                # end faces: fans from the first corner
        faces += [[0, i + 1, i], [k, k + i, k + i + 1]]
    faces = np.array(faces)
    # wind outwards (positive volume)
    if trimesh.Trimesh(vertices, faces, process=False).volume < 0:
        faces = faces[:, ::-1]
    return vertices, faces


def bushing():
    mesh = trimesh.creation.annulus(r_min=5.05, r_max=8.0, height=3.0, sections=1024)
    return mesh.vertices, mesh.faces


if __name__ == "__main__":
    save("cube_20mm.stl", *cube())
    save("block_10x10x5mm.stl", *block())
    save("slider_shoe_mm.stl", *shoe())
    save("bushing_d10.1_mm.stl", *bushing())
