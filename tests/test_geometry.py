"""Mesh loading, cleaning, primitives, refinement, areas, normals and mass properties."""

import logging

import numpy as np
import pytest
import trimesh

from meshwear import geometry
from meshwear.geometry import meshes, remesh
from meshwear.geometry.meshes import MeshError


def watertight(vertices, faces):
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    return mesh.is_watertight and mesh.is_winding_consistent


def area(vertices, faces):
    return geometry.tributary_areas(vertices, faces).sum()


def edge_lengths(vertices, faces):
    tri = vertices[faces]
    return np.linalg.norm(np.roll(tri, -1, axis=1) - tri, axis=2)


def check_arrays(vertices, faces):
    assert vertices.dtype == np.float64 and vertices.flags.c_contiguous and vertices.shape[1] == 3
    assert faces.dtype == np.int64 and faces.flags.c_contiguous and faces.shape[1] == 3


# ---------------------------------------------------------------- loading

def test_stl_seams_are_merged_and_units_scale(tmp_path, caplog):
    path = tmp_path / "box.stl"
    trimesh.creation.box(extents=[1.0, 2.0, 3.0]).export(path)
    assert len(trimesh.load(path, force="mesh", process=False).vertices) == 36
    with caplog.at_level(logging.INFO, logger="meshwear.geometry"):
        vertices, faces = geometry.load_mesh(path, units="mm")
    check_arrays(vertices, faces)
    assert (len(vertices), len(faces)) == (8, 12)
    assert "merged 28 duplicate vertices" in caplog.text
    np.testing.assert_allclose(np.ptp(vertices, axis=0), [1e-3, 2e-3, 3e-3], rtol=1e-12)
    assert watertight(vertices, faces)


@pytest.mark.parametrize("suffix", ["obj", "ply", "off", "glb"])
def test_other_formats_load(tmp_path, suffix):
    path = tmp_path / f"box.{suffix}"
    trimesh.creation.box(extents=[1.0, 2.0, 3.0]).export(path)
    vertices, faces = geometry.load_mesh(path, units="cm")
    assert (len(vertices), len(faces)) == (8, 12)
    np.testing.assert_allclose(np.ptp(vertices, axis=0), [0.01, 0.02, 0.03], rtol=1e-12)
    assert watertight(vertices, faces)


@pytest.mark.parametrize("content, reason", [
    ("v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "NaN"),
    ("v inf 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "NaN or infinite"),
    ("", "no triangle faces"),
    ("this is not a mesh\n", "no triangle faces"),
    ("v 0 0 0\nv 1 0 0\n", "no triangle faces"),
])
def test_bad_files_are_refused_naming_the_file(tmp_path, content, reason):
    path = tmp_path / "bad.obj"
    path.write_text(content)
    with pytest.raises(MeshError, match=reason) as err:
        geometry.load_mesh(path)
    assert str(path) in str(err.value) and "\n" not in str(err.value)


def test_garbage_and_missing_files_are_refused(tmp_path):
    garbage = tmp_path / "garbage.stl"
    garbage.write_bytes(b"\x00\x17solid?" * 50)
    with pytest.raises(MeshError, match="garbage.stl"):
        geometry.load_mesh(garbage)
    with pytest.raises(MeshError, match="missing.stl: mesh file not found"):
        geometry.load_mesh(tmp_path / "missing.stl")
    with pytest.raises(MeshError, match="garbage.stl: units 'furlong'"):
        geometry.load_mesh(garbage, units="furlong")


def test_zero_area_and_duplicate_faces_dropped(caplog):
    vertices, faces = geometry.primitive("box", size=1.0)
    extra = np.array([[0, 0, 1], faces[3], faces[3][::-1]])        # repeated index, duplicates
    with caplog.at_level(logging.WARNING, logger="meshwear.geometry"):
        v, f = geometry.clean(vertices, np.concatenate([faces, extra]), source="box.stl")
    assert len(f) == 12 and watertight(v, f)
    assert "box.stl: removed 1 degenerate face(s)" in caplog.text and "2 duplicate face(s)" in caplog.text


def test_collinear_sliver_removed_keeping_the_mesh_closed():
    # a zero-area face (a, b, m) with m the midpoint of edge (a, b): closed but degenerate
    vertices, faces = geometry.primitive("box", size=[1.0, 2.0, 3.0])
    a, b, c = faces[0]
    m = len(vertices)
    vertices = np.vstack([vertices, 0.5 * (vertices[a] + vertices[b])])
    faces = np.vstack([faces[1:], [[a, m, c], [m, b, c], [a, b, m]]])
    assert watertight(vertices, faces)
    v, f = geometry.clean(vertices, faces)
    assert len(v) == 9 and len(f) == 14
    assert watertight(v, f)
    assert np.all(np.linalg.norm(geometry.face_normals(v, f), axis=1) > 0.5)
    assert area(v, f) == pytest.approx(22.0, rel=1e-12)


def test_inside_out_closed_mesh_is_flipped(caplog):
    vertices, faces = geometry.primitive("box", size=1.0)
    with caplog.at_level(logging.WARNING, logger="meshwear.geometry"):
        v, f = geometry.clean(vertices, faces[:, ::-1], source="inside-out.stl")
    assert "inside-out.stl: faces were wound inwards" in caplog.text
    assert trimesh.Trimesh(v, f, process=False).volume == pytest.approx(1.0)
    assert np.all(np.einsum("ij,ij->i", geometry.vertex_normals(v, f), v) > 0)


def test_stray_vertices_and_near_duplicates_are_merged():
    vertices, faces = geometry.primitive("box", size=1.0)
    jitter = vertices + 1e-12                                   # within 1e-9 of the diagonal
    v = np.vstack([vertices, jitter, [[5.0, 5.0, 5.0]]])
    f = np.vstack([faces[:6], faces[6:] + 8])
    v2, f2 = geometry.clean(v, f)
    assert (len(v2), len(f2)) == (8, 12) and watertight(v2, f2)


def test_exact_copies_group_the_rows_as_numpys_unique_does():
    """The merge takes exact copies by a lexsort (numpy's unique of rows
    took 0.08 s of a gear's load): the same groups, each the first index of
    its rows, -0.0 and 0.0 alike; the merged mesh is then the same."""
    rng = np.random.default_rng(3)
    for _ in range(100):
        v = rng.integers(-2, 3, (int(rng.integers(1, 80)), 3)).astype(float) * 0.25
        v[v == 0.0] *= rng.choice([1.0, -1.0], int((v == 0.0).sum()))        # signed zeros
        rows, first, inverse = meshes._exact_copies(v)
        want, want_first, want_inverse = np.unique(v, axis=0, return_index=True,
                                                   return_inverse=True)
        assert len(rows) == len(want) and sorted(first) == sorted(want_first)
        assert np.array_equal(rows[inverse], v)
        # a row's group is the same in both
        pairs = set(zip(inverse.tolist(), want_inverse.ravel().tolist()))
        assert len(pairs) == len(rows)
        assert np.array_equal(v[first], rows)


def test_a_mesh_file_is_read_once_per_model(monkeypatch):
    """The gear pair's two gears are one file, and a refined body's mesh is
    read for the checks before refining too: each read once per build."""
    from meshwear.model.build import build_model
    from meshwear.scene.reader import load_scene

    reads = []
    load = meshes.load_mesh
    monkeypatch.setattr(meshes, "load_mesh", lambda *a, **k: reads.append(a) or load(*a, **k))
    scene = load_scene("examples/gear_pair.toml", (("body[0].resolution", 2e-3),))
    build_model(scene)
    assert len(reads) == 1, reads


# ------------------------------------------------------- areas, primitives

@pytest.mark.parametrize("kind, kwargs", [
    ("box", dict(size=[0.01, 0.02, 0.005])),
    ("sphere", dict(radius=0.01, subdivisions=2)),
    ("cylinder", dict(radius=0.01, height=0.03, sections=24)),
])
def test_primitives_closed_and_areas_sum(kind, kwargs):
    vertices, faces = geometry.primitive(kind, **kwargs)
    check_arrays(vertices, faces)
    assert watertight(vertices, faces)
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    assert mesh.volume > 0                                       # outward winding
    np.testing.assert_allclose(vertices.min(axis=0), -vertices.max(axis=0), atol=1e-15)
    assert area(vertices, faces) == pytest.approx(mesh.area, rel=1e-12)
    normals = geometry.vertex_normals(vertices, faces)
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, rtol=1e-12)
    assert np.all(np.einsum("ij,ij->i", normals, vertices) > 0)  # outward for a convex body


def test_primitive_arguments_checked():
    with pytest.raises(ValueError, match="torus"):
        geometry.primitive("torus", radius=1.0)
    with pytest.raises(ValueError, match="radius"):
        geometry.primitive("sphere")
    with pytest.raises(ValueError, match="height"):
        geometry.primitive("cylinder", radius=1.0, height=-1.0)


def test_face_normals_unit_and_zero_for_zero_area():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0]], float)
    faces = np.array([[0, 1, 2], [0, 1, 3]])
    np.testing.assert_array_equal(geometry.face_normals(vertices, faces), [[0, 0, 1], [0, 0, 0]])


# ---------------------------------------------------------- mass properties

def test_box_mass_properties_closed_form():
    a, b, c, rho = 0.02, 0.03, 0.05, 7850.0
    vertices, faces = geometry.primitive("box", size=[a, b, c])
    offset = np.array([1.0, -2.0, 3.0])
    mass, com, inertia = geometry.mass_properties(vertices + offset, faces, density=rho)
    m = rho * a * b * c
    assert mass == pytest.approx(m, rel=1e-12)
    np.testing.assert_allclose(com, offset, rtol=1e-12)
    expected = m / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])
    np.testing.assert_allclose(inertia, expected, rtol=1e-9, atol=1e-12 * expected.max())

    mass2, _, inertia2 = geometry.mass_properties(vertices, faces, mass=2.0)
    assert mass2 == 2.0
    np.testing.assert_allclose(inertia2, inertia * 2.0 / m, rtol=1e-12)


def test_sphere_mass_properties_match_its_polyhedron():
    radius, rho = 0.01, 1000.0
    vertices, faces = geometry.primitive("sphere", radius=radius, subdivisions=3)
    mass, com, inertia = geometry.mass_properties(vertices, faces, density=rho)
    volume = trimesh.Trimesh(vertices, faces, process=False).volume
    assert mass == pytest.approx(rho * volume, rel=1e-12)
    np.testing.assert_allclose(com, 0.0, atol=1e-15)
    # icosphere: isotropic within its discretisation, close to 2/5 m R²
    np.testing.assert_allclose(np.diag(inertia), 0.4 * mass * radius ** 2, rtol=2e-2)
    np.testing.assert_allclose(inertia - np.diag(np.diag(inertia)), 0.0, atol=1e-3 * inertia[0, 0])
    assert volume == pytest.approx(4 / 3 * np.pi * radius ** 3, rel=2e-2)


def test_mass_properties_refuses_open_and_accepts_inverted():
    vertices, faces = geometry.primitive("box", size=1.0)
    with pytest.raises(MeshError, match="open mesh.*closed mesh"):
        geometry.mass_properties(vertices, faces[1:], density=1.0)
    mass, com, inertia = geometry.mass_properties(vertices, faces[:, ::-1], density=1.0)
    assert mass == pytest.approx(1.0) and inertia[0, 0] == pytest.approx(1 / 6)
    with pytest.raises(ValueError, match="not both"):
        geometry.mass_properties(vertices, faces, density=1.0, mass=1.0)


def test_mesh_info(tmp_path):
    path = tmp_path / "box.stl"
    trimesh.creation.box(extents=[10.0, 20.0, 30.0]).export(path)
    info = geometry.mesh_info(path, units="mm")
    assert info["vertices"] == 8 and info["faces"] == 12 and info["watertight"]
    np.testing.assert_allclose(info["extents"], [0.01, 0.02, 0.03])
    assert info["volume"] == pytest.approx(6e-6) and info["area"] == pytest.approx(2.2e-3)
    trimesh.Trimesh(*geometry.primitive("box", size=1.0), process=False).export(path)
    mesh = trimesh.load(path, force="mesh")
    trimesh.Trimesh(mesh.vertices, mesh.faces[1:]).export(path)
    info = geometry.mesh_info(path)
    assert not info["watertight"] and info["volume"] is None


# --------------------------------------------------------------- refinement

def test_refine_whole_box():
    vertices, faces = geometry.primitive("box", size=[0.01, 0.02, 0.03])
    v, f = remesh.refine(vertices, faces, 2e-3)
    check_arrays(v, f)
    assert edge_lengths(v, f).max() <= 2e-3
    assert area(v, f) == pytest.approx(area(vertices, faces), rel=1e-12)
    assert watertight(v, f)
    # every new vertex lies on the box surface
    assert np.all(np.isclose(np.abs(v), [0.005, 0.01, 0.015], rtol=0, atol=1e-15).any(axis=1))
    assert trimesh.Trimesh(v, f, process=False).volume == pytest.approx(6e-6, rel=1e-12)


def test_refine_bottom_only_stays_conforming():
    vertices, faces = geometry.primitive("box", size=[0.01, 0.02, 0.03])
    bottom = geometry.face_normals(vertices, faces)[:, 2] < -0.99
    v, f = remesh.refine(vertices, faces, 1e-3, face_mask=bottom)
    assert trimesh.Trimesh(v, f, process=False).is_watertight                  # no T-junctions
    assert watertight(v, f)
    on_bottom = np.all(np.isclose(v[f][:, :, 2], -0.015, rtol=0, atol=1e-15), axis=1)
    assert edge_lengths(v, f[on_bottom]).max() <= 1e-3
    assert area(v, f[on_bottom]) == pytest.approx(2e-4, rel=1e-12)
    assert area(v, f) == pytest.approx(area(vertices, faces), rel=1e-12)
    # the top is untouched, the sides only split where they meet the bottom
    on_top = np.all(np.isclose(v[f][:, :, 2], 0.015, rtol=0, atol=1e-15), axis=1)
    assert on_top.sum() == 2
    assert (~on_bottom).sum() < on_bottom.sum()


def test_refine_long_thin_triangles_economically():
    # a CAD-style strip: two triangles of aspect ratio 100
    length, width, resolution = 0.1, 1e-3, 2.5e-4
    vertices = np.array([[0, 0, 0], [length, 0, 0], [length, width, 0], [0, width, 0]], float)
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    v, f = remesh.refine(vertices, faces, resolution)
    assert edge_lengths(v, f).max() <= resolution
    assert area(v, f) == pytest.approx(length * width, rel=1e-12)
    # right isosceles triangles with hypotenuse = resolution: area/(resolution²/4) faces;
    # bisection may halve once more, and 4-way subdivision would need 2·4^9 ≈ 5e5
    ideal = length * width / (resolution ** 2 / 4)
    assert len(f) <= 2.5 * ideal
    tri = v[f]
    quality = (4 * np.sqrt(3) * geometry.tributary_areas(v, f).sum() / len(f)
               / (edge_lengths(v, f) ** 2).sum(axis=1).mean())
    assert quality > 0.5                                         # no slivers left, on average
    assert np.all(np.abs(tri[:, :, 2]) == 0.0)
    boundary = trimesh.Trimesh(v, f, process=False).outline()
    assert len(boundary.entities) == 1                           # one open strip, no holes


@pytest.mark.parametrize("kind, kwargs, resolution", [
    ("cylinder", dict(radius=0.003, height=0.012, sections=400), 5e-4),
    ("cylinder", dict(radius=0.005, height=0.005, sections=256), 2.5e-4),
    ("sphere", dict(radius=0.01, subdivisions=2), 1e-3),
    ("box", dict(size=[0.01, 0.02, 0.003]), 7e-4),
])
def test_the_edges_of_the_faces_refined_bound_the_faces_made(kind, kwargs, resolution):
    """Each edge of a face refined is cut in ceil(L / resolution) pieces at
    least, each an edge of a face on either side: a third of their sum is
    no more than the faces a refinement makes, all faces or the bottom's;
    for a cylinder of many sections (caps of slivers) it is several times
    what their area asks for."""
    vertices, faces = geometry.primitive(kind, **kwargs)
    bottom = geometry.face_normals(vertices, faces)[:, 2] < -0.5
    for mask in (np.ones(len(faces), bool), bottom):
        least = remesh._edge_faces(edge_lengths(vertices, faces), mask, resolution)
        refined = remesh.refine(vertices, faces, resolution, face_mask=mask)[1]
        assert len(refined) >= least
        by_area = area(vertices, faces[mask]) / (np.sqrt(3.0) / 4.0 * resolution**2)
        if kind == "cylinder" and kwargs["sections"] == 400:
            assert least > 5.0 * by_area


def test_a_fan_of_slivers_is_refused_from_its_edges_before_any_pass(monkeypatch):
    """A pin of 20 000 sections refined to 0.5 mm: its caps' slivers make
    at least 4/3 of 20 000 x 6 faces each where their area asks for 150;
    refused before the first pass, not at the pass that makes too many."""
    vertices, faces = geometry.primitive("cylinder", radius=0.003, height=0.012,
                                         sections=20_000)
    monkeypatch.setattr(remesh, "_bisect", lambda *a: pytest.fail("a pass was made"))
    with pytest.raises(MeshError, match="needs at least"):
        remesh.refine(vertices, faces, 5e-4, max_faces=100_000)


def test_refine_leaves_fine_meshes_alone_and_checks_inputs():
    vertices, faces = geometry.primitive("sphere", radius=1.0, subdivisions=1)
    v, f = remesh.refine(vertices, faces, 10.0)
    np.testing.assert_array_equal(f, faces)
    with pytest.raises(ValueError, match="resolution"):
        remesh.refine(vertices, faces, 0.0)
    with pytest.raises(ValueError, match="face_mask"):
        remesh.refine(vertices, faces, 0.1, face_mask=np.ones(3, bool))
    # refused before any work: 11.7 m² in triangles of at most 0.433 mm² is 2.7e7 faces
    with pytest.raises(MeshError, match=r"at least 2.69e\+07 faces, more than 1000 \(the limit asked\);"):
        remesh.refine(vertices, faces, 1e-3, max_faces=1000)
    # and, past that lower bound (299 faces), when a pass makes more
    with pytest.raises(MeshError, match="needs more than 400 faces"):
        remesh.refine(vertices, faces, 0.3, max_faces=400)


def test_refine_curved_surface_closed():
    vertices, faces = geometry.primitive("cylinder", radius=0.01, height=0.05, sections=16)
    v, f = remesh.refine(vertices, faces, 2e-3)
    assert watertight(v, f) and edge_lengths(v, f).max() <= 2e-3
    assert area(v, f) == pytest.approx(area(vertices, faces), rel=1e-12)


# -------------------------------------------------------- inverted faces

def test_inverted_faces_found():
    vertices, faces = geometry.primitive("box", size=1.0)
    vertices, faces = remesh.refine(vertices, faces, 0.3)
    reference = geometry.face_normals(vertices, faces)
    assert len(geometry.inverted_faces(reference, vertices, faces)) == 0
    # drag one bottom vertex sideways past its neighbours: part of its fan flips
    bottom = np.flatnonzero(np.isclose(vertices[:, 2], -0.5) & (np.abs(vertices[:, :2]).max(axis=1) < 0.45))
    worn = vertices.copy()
    worn[bottom[0], 0] += 0.6
    flipped = geometry.inverted_faces(reference, worn, faces)
    fan = np.flatnonzero((faces == bottom[0]).any(axis=1))
    assert len(flipped) > 0 and set(flipped) <= set(fan)
    # collapse: a face squashed to zero area is flagged too
    squashed = vertices.copy()
    a, b, c = faces[fan[0]]
    squashed[c] = 0.5 * (squashed[a] + squashed[b])
    assert fan[0] in geometry.inverted_faces(reference, squashed, faces)
    reference_areas = trimesh.Trimesh(vertices, faces, process=False).area_faces
    assert fan[0] in geometry.inverted_faces(reference, squashed, faces, reference_areas=reference_areas)
    assert len(geometry.inverted_faces(reference, vertices, faces, reference_areas=reference_areas)) == 0


def test_glb_scene_is_concatenated(tmp_path):
    scene = trimesh.Scene()
    scene.add_geometry(trimesh.creation.box(extents=[1.0, 1.0, 1.0]), node_name="a")
    scene.add_geometry(trimesh.creation.box(extents=[1.0, 1.0, 1.0]), node_name="b",
                       transform=trimesh.transformations.translation_matrix([3.0, 0.0, 0.0]))
    path = tmp_path / "two.glb"
    scene.export(path)
    vertices, faces = geometry.load_mesh(path)
    assert (len(vertices), len(faces)) == (16, 24) and watertight(vertices, faces)
    np.testing.assert_allclose(np.ptp(vertices, axis=0), [4.0, 1.0, 1.0])


@pytest.mark.parametrize("ext", ["vtu", "msh", "inp"])
def test_fe_formats_load_through_meshio(tmp_path, ext):
    """Gmsh, Abaqus and VTK surface meshes are read through trimesh's meshio bridge."""
    import meshio

    V, F = geometry.primitive("box", size=[10.0, 20.0, 30.0])
    path = tmp_path / f"box.{ext}"
    meshio.write(path, meshio.Mesh(V, [("triangle", F)]))
    v, f = geometry.load_mesh(path, units="mm")
    assert f.shape == (12, 3)
    np.testing.assert_allclose(np.ptp(v, axis=0), [0.01, 0.02, 0.03], rtol=1e-12)


def test_area_vectors_project_to_the_footprint():
    # a flat-ended cylinder: on a plane under its end face, the end-face
    # vertices (rim included) add up to the end polygon's area; the side
    # wall, standing on the plane, contributes nothing
    vertices, faces = geometry.primitive("cylinder", radius=0.003, height=0.01, sections=48)
    a = geometry.area_vectors(vertices, faces)
    assert np.allclose(a.sum(axis=0)[0:3], 0.0, atol=1e-18)  # a closed surface
    bottom = vertices[:, 2] < vertices[:, 2].min() + 1e-12
    polygon = 0.5 * 48 * 0.003 ** 2 * np.sin(2 * np.pi / 48)
    assert (-a[bottom, 2]).sum() == pytest.approx(polygon, rel=1e-12, abs=0.0)
    # the unprojected tributary areas of the rim carry a share of the wall
    assert geometry.tributary_areas(vertices, faces)[bottom].sum() > 2 * polygon
    # every length is at most the tributary area, equal on a flat face
    tributary = geometry.tributary_areas(vertices, faces)
    assert np.all(a[:, 3] <= tributary * (1 + 1e-12))
    centre = bottom & (np.linalg.norm(vertices[:, 0:2], axis=1) < 1e-12)
    assert a[centre, 3] == pytest.approx(tributary[centre], rel=1e-12)


BALL_ON_A_PLANE = """format = 1
[run]
mode = "quasi-static"
duration = 0.1
dt = 0.01
frames = 2
history = 2
gravity = [0.0, 0.0, 0.0]
[contact]
stiffness_per_area = 1e15
[[body]]
name = "ball"
shape = { type = "sphere", radius = 0.01 }
resolution = 2e-5
resolution_reach = 2e-5
position = [0.0, 0.0, 0.01]
force = [0.0, 0.0, -1.0]
motion = "guided"
[body.path]
oscillation = { axis = [1.0, 0.0, 0.0], amplitude = 1e-5, frequency = 10.0 }
free_axis = [0.0, 0.0, 1.0]
[[surface]]
name = "flat"
type = "plane"
"""


def test_a_ball_is_refined_within_its_resolution_reach_not_over_its_coarse_faces(tmp_path):
    """``resolution_reach`` chooses the faces anew at each pass, on the
    sphere itself: every face with a corner within the reach of the plane
    is refined, and no refined face lies more than the reach and twice the
    resolution (the last split's parent) above it. (Taken whole, the coarse
    faces a millimetre wide under the ball were refined to 123 um above the
    plane: 50 172 vertices where 11 730 do.)"""
    from meshwear.model.build import build_model
    from meshwear.scene.reader import load_scene

    path = tmp_path / "ball.toml"
    path.write_text(BALL_ON_A_PLANE)
    body = build_model(load_scene(path)).bodies[0]
    v, f = body.reference_vertices, body.faces
    height = v[:, 2] - v[:, 2].min()
    refined = remesh._edge_lengths(v, f).max(axis=1) <= 2e-5 * (1.0 + 1e-9)
    assert np.all(refined[height[f].min(axis=1) <= 2e-5])
    assert height[f[refined]].max() <= 2e-5 + 2 * 2e-5
    assert np.abs(np.linalg.norm(v - body.origin, axis=1) - 0.01).max() <= 1e-9 * 0.01
    # too fine a resolution is refused before the passes, from the faces
    # wholly within the reach (chosen anew at each pass, the selection's
    # size is not known before: 17 passes and 4 GB went by before the
    # refusal)
    path.write_text(BALL_ON_A_PLANE.replace("resolution = 2e-5", "resolution = 2e-6")
                    .replace("resolution_reach = 2e-5", "resolution_reach = 1e-3"))
    with pytest.raises(Exception, match="needs at least"):
        build_model(load_scene(path))


def test_refined_primitives_put_their_vertices_on_the_exact_surface():
    """A refined cylinder's side and rims, and every vertex of a refined
    sphere, lie at the radius (the flat facets' new vertices would sag
    towards the axis by up to R (1 - cos(pi / sections)): 0.45 um for R = 6 mm
    and 256 sections); the caps stay flat; the facets then sag at most
    SAG_FRACTION of the resolution where refined."""
    from meshwear.scene.parts import ShapeConfig

    class Part:
        def __init__(self, shape, resolution):
            self.shape, self.resolution, self.mesh = shape, resolution, None

    R = 0.006
    cylinder = ShapeConfig(type="cylinder", radius=R, height=0.002, sections=16)
    v, f = geometry.primitive("cylinder", radius=R, height=0.002, sections=16)
    low = v[f].mean(axis=1)[:, 0] > 0.004                  # refine one side only
    v2, f2, info = remesh.refine_part(Part(cylinder, 2e-4), v, f, low)
    assert len(v2) > 4 * len(v)
    radial = np.linalg.norm(v2[:, 0:2], axis=1)
    on_side = np.abs(np.abs(v2[:, 2]) - 0.001) > 1e-12    # not on a cap
    rim = ~on_side & (radial > R * np.cos(np.pi / 16) - 1e-12)
    assert np.all(np.abs(radial[on_side | rim] - R) <= 1e-9 * R)
    assert on_side.sum() > 100
    caps = ~on_side
    assert np.all(np.abs(np.abs(v2[caps, 2]) - 0.001) <= 1e-15)     # the caps stay flat
    assert info["sag"] <= remesh.SAG_FRACTION * 2e-4
    assert info["sag_elsewhere"] == pytest.approx(R * (1 - np.cos(np.pi / 16)), rel=1e-6)
    assert geometry.mass_properties(v2, f2, density=1.0)[0] > 0   # still closed, outward
    # a sphere refined where it can touch: every vertex at R
    sphere = ShapeConfig(type="sphere", radius=R, subdivisions=2)
    v, f = geometry.primitive("sphere", radius=R, subdivisions=2)
    v2, f2, info = remesh.refine_part(Part(sphere, 5e-4), v, f, v[f].mean(axis=1)[:, 2] < -0.004)
    assert np.all(np.abs(np.linalg.norm(v2, axis=1) - R) <= 1e-9 * R)
    assert info["sag"] <= remesh.SAG_FRACTION * 5e-4 < info["sag_elsewhere"]
    assert "facet sag" in remesh.describe_refinement(info)
    # a coarse resolution on a small radius is refined finer, to keep the sag small
    v3, f3, info = remesh.refine_part(Part(ShapeConfig(type="sphere", radius=1e-3), 5e-4), v / 6,
                                      f)
    assert info["sag"] <= remesh.SAG_FRACTION * 5e-4
