"""End-to-end tests of the command line (docs/scene-format.md errors, docs/outputs.md outputs and exit codes).

Most tests call :func:`meshwear.cli.main` in-process and read its output with
capsys; one runs the installed ``meshwear`` console script in a subprocess.
Scenes are small (a few hundred vertices, a few thousand steps) so the whole
file runs in seconds.
"""

import contextlib
import csv
import io
import json
import logging
import math
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import pyvista
import trimesh
import vtk
from vtk.util.numpy_support import vtk_to_numpy

from meshwear import geometry
from meshwear.geometry import remesh
from meshwear.cli import main

#: docs/outputs.md: history.csv starts with these columns, in this order
HISTORY_COLUMNS = ["time", "body", "x", "y", "z", "qw", "qx", "qy", "qz", "vx", "vy", "vz",
                   "fx", "fy", "fz", "friction_work", "wear_volume", "max_wear_depth"]
#: docs/outputs.md: keys of summary.json and of each body in it
SUMMARY_KEYS = {"format", "time", "steps", "cycles", "resolved_cycles", "wall_time", "bodies"}
BODY_KEYS = {"wear_volume", "max_wear_depth", "friction_work", "position", "orientation",
             "velocity", "angular_velocity", "contact_force"}
#: docs/outputs.md: point data of every frame, and their number of components
POINT_DATA = {"wear_depth": 1, "normal_force": 1, "friction_force": 3, "pressure": 1,
              "contact_state": 1, "friction_work": 1}

# A small scene that is valid as it stands; the bad-input cases edit one thing.
BASE = """\
format = 1

[run]
duration = 0.01
dt = 1e-5
frames = 3
history = 5

[contact]
stiffness_per_area = 1e11
damping_per_area = 2e4
friction = 0.3

[wear]
law = "energy"
coefficient = 1e-6

[[body]]
name = "block"
shape = { type = "box", size = [0.01, 0.01, 0.005] }
position = [0.0, 0.0, 0.0025]

[[surface]]
name = "floor"
type = "plane"
"""
BOX_SHAPE = 'shape = { type = "box", size = [0.01, 0.01, 0.005] }'

# Two free bodies sliding on a plane and wearing (energy law). The block is
# refined, turned 90° about z and placed away from the origin, so frame 0 tells
# world coordinates from body coordinates.
GOOD = """\
format = 1

[run]
duration = 0.02
dt = 1e-5
frames = 6
history = 21

[contact]
stiffness_per_area = 5e10
damping_per_area = 2e4
friction = 0.3

[wear]
law = "energy"
coefficient = 1e-3

[[body]]
name = "block"
shape = { type = "box", size = [0.01, 0.006, 0.004] }
resolution = 0.0025
position = [0.1, -0.2, 0.002]
orientation = [0.7071067811865476, 0.0, 0.0, 0.7071067811865476]
velocity = [0.5, 0.0, 0.0]

[[body]]
name = "pin"
shape = { type = "box", size = [0.008, 0.008, 0.008] }
position = [-0.05, 0.0, 0.004]
velocity = [0.0, 0.3, 0.0]

[[surface]]
name = "floor"
type = "plane"
size = 0.5
"""
GOOD_DURATION, GOOD_STEPS, GOOD_FRAMES, GOOD_HISTORY = 0.02, 2000, 6, 21
BLOCK_SIZE, BLOCK_RESOLUTION = (0.01, 0.006, 0.004), 0.0025
BLOCK_POSITION = np.array([0.1, -0.2, 0.002])

# A thin plate pressed on a plane and dragged along it, with a wear coefficient
# so large that wear goes through the 0.5 mm thickness within a few ms: the
# worn bottom vertices pass the top ones and the side triangles turn over.
INVERTING = """\
format = 1

[run]
duration = 0.06
dt = 5e-6
frames = 11
history = 21

[contact]
stiffness_per_area = 1e11
damping_per_area = 2e4
friction = 0.5

[wear]
law = "energy"
coefficient = 1.0

[[body]]
name = "plate"
shape = { type = "box", size = [0.01, 0.01, 0.0005] }
resolution = 0.002
position = [0.0, 0.0, 0.00025]
force = [0.0, 0.0, -5.0]
motion = "guided"

[body.path]
velocity = [0.5, 0.0, 0.0]
free_axis = [0.0, 0.0, 1.0]

[[surface]]
name = "floor"
type = "plane"
"""

# An OBJ tetrahedron with one face missing (open), and one with a NaN vertex.
OPEN_OBJ = """\
v 0 0 0
v 0.01 0 0
v 0 0.01 0
v 0 0 0.01
f 1 3 2
f 1 2 4
f 2 3 4
"""
NAN_OBJ = OPEN_OBJ.replace("v 0 0 0.01", "v 0 0 nan") + "f 3 1 4\n"


def write(path, text):
    path = Path(path)
    path.write_text(text, encoding="utf-8")
    return path


def with_mesh(mesh_file, text=BASE):
    """BASE with the block read from ``mesh_file`` instead of a primitive."""
    return text.replace(BOX_SHAPE, f'mesh = "{mesh_file}"')


def cli(capsys, caplog, *argv):
    """Run ``meshwear argv`` in-process: (return code, stdout, stderr lines).

    Log records of level WARNING and above count as stderr lines: the real
    command prints them there (``logging.basicConfig`` in ``main``), but under
    pytest they go to pytest's own handler.
    """
    caplog.clear()
    with caplog.at_level(logging.WARNING):
        code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    lines = err.splitlines() + [f"meshwear: {r.getMessage()}" for r in caplog.records
                                if r.levelno >= logging.WARNING]
    return code, out, lines


def read_vtp(path):
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(str(path))
    reader.Update()
    return reader.GetOutput()


def pvd_entries(path):
    """[(time, frame path)] of a .pvd, read with the standard library."""
    root = ET.parse(path).getroot()
    assert root.tag == "VTKFile" and root.get("type") == "Collection"
    return [(float(d.get("timestep")), Path(path).parent / d.get("file"))
            for d in root.findall("./Collection/DataSet")]


def read_history(path):
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    header, rows = rows[0], rows[1:]
    assert all(len(r) == len(header) for r in rows), "incomplete history row"
    return header, [dict(zip(header, r)) for r in rows]


# ------------------------------------------------------------------ bad input

# (id, edit of BASE or a whole scene, extra files {name: text}, substrings of the message)
BAD_SCENES = [
    ("unknown_key", BASE.replace("friction = 0.3", "friction = 0.3\nfricton = 0.4"), {},
     ["contact.fricton", "unknown key", "did you mean 'friction'"]),
    ("bad_value", BASE.replace("duration = 0.01", "duration = -1.0"), {},
     ["run.duration", "must be > 0"]),
    ("wrong_type", BASE.replace("frames = 3", 'frames = "three"'), {},
     ["run.frames", "expected an integer"]),
    ("missing_format", BASE.replace("format = 1\n", ""), {},
     ["format", "missing"]),
    ("unsupported_format", BASE.replace("format = 1", "format = 2"), {},
     ["format", "version 2 is not supported"]),
    ("bad_enum", BASE.replace('law = "energy"', 'law = "archrd"'), {},
     ["wear.law", "'archrd'", "did you mean 'archard'"]),
    ("toml_syntax", BASE.replace("frames = 3", "frames = = 3"), {},
     ["line 6", "TOML syntax error"]),
    ("missing_mesh_file", with_mesh("missing.stl"), {},
     ["body[0].mesh", "file not found", "missing.stl"]),
    ("duplicate_names", BASE.replace('name = "floor"', 'name = "block"'), {},
     ["surface[0].name", "'block' is already the name of body[0]"]),
    ("static_below_kinetic", BASE.replace("friction = 0.3", "friction = 0.5\nstatic_friction = 0.2"), {},
     ["contact.static_friction", "must be >= friction"]),
    ("vector_length", BASE.replace("position = [0.0, 0.0, 0.0025]", "position = [0.0, 0.0]"), {},
     ["body[0].position", "expected a list of 3 numbers"]),
    ("guided_without_free_axis",
     BASE.replace("position = [0.0, 0.0, 0.0025]",
                  'position = [0.0, 0.0, 0.0025]\nmotion = "guided"\npath = { velocity = [0.1, 0.0, 0.0] }'), {},
     ["body[0].path.free_axis", "missing"]),
    ("quasi_static_free_body", BASE.replace("[run]", '[run]\nmode = "quasi-static"'), {},
     ["body[0].motion", "'free' is not allowed"]),
    ("shape_missing_key", BASE.replace(BOX_SHAPE, 'shape = { type = "sphere" }'), {},
     ["body[0].shape.radius", "missing"]),
    ("key_of_another_shape", BASE.replace("size = [0.01, 0.01, 0.005]", "size = [0.01, 0.01, 0.005], radius = 0.01"),
     {}, ["body[0].shape.radius", "does not apply to a box"]),
    ("mesh_key_on_a_plane", BASE.replace('type = "plane"', 'type = "plane"\nresolution = 1e-3'),
     {}, ["surface[0].resolution", 'does not apply to a type = "plane" surface']),
    ("plane_tumbling", BASE.replace('type = "plane"', 'type = "plane"\nrotation = { axis = [1, 0, 0], rate = 1.0 }'),
     {}, ["surface[0].rotation.axis", "turns about its normal"]),
    ("cylinder_without_radius", BASE.replace('type = "plane"', 'type = "cylinder"\naxis = [0, 1, 0]'),
     {}, ["surface[0].radius", "missing"]),
    ("infinite_cylinder_tumbling", BASE.replace('type = "plane"', 'type = "cylinder"\nradius = 0.01\naxis = [0, 1, 0]\nrotation = { axis = [0, 0, 1], rate = 1.0 }'),
     {}, ["surface[0].rotation.axis", "infinite cylinder"]),
    ("sphere_with_an_axis", BASE.replace('type = "plane"', 'type = "sphere"\nradius = 0.01\naxis = [0, 1, 0]'),
     {}, ["surface[0].axis", 'does not apply to a type = "sphere" surface']),
    ("bad_side", BASE.replace('type = "plane"', 'type = "sphere"\nradius = 0.01\nside = "under"'),
     {}, ["surface[0].side", "'under' is not one of"]),
    ("name_with_path_separator", BASE.replace('name = "block"', 'name = "a/b"'), {},
     ["body[0].name", "not usable as a file name"]),
    ("name_clashes_with_an_output_file", BASE.replace('name = "block"', 'name = "summary.json"'), {},
     ["body[0].name", "'summary.json'", "clash with summary.json"]),
    ("names_clash_ignoring_case", BASE.replace('name = "floor"', 'name = "Block"'), {},
     ["surface[0].name", "'Block'", "clash with those of body[0]"]),
    ("cycle_jump_without_period", BASE.replace('coefficient = 1e-6', 'coefficient = 1e-6\nacceleration = "cycle_jump"'),
     {}, ["wear.period", "missing"]),
    ("no_bodies", BASE.split("[[body]]")[0], {}, ["body", "no bodies"]),
    ("quasi_static_load_without_carrier",
     BASE.replace("[run]", '[run]\nmode = "quasi-static"').replace(
         "position = [0.0, 0.0, 0.0025]",
         'position = [0.0, 0.0, 0.0025]\nmotion = "guided"\n'
         'path = { velocity = [0.0, 0.1, 0.0], free_axis = [1.0, 0.0, 0.0] }'), {},
     ["body[0].path.free_axis", "no surface can carry the load of body 'block'"]),
    ("cycle_jump_of_a_free_body",
     BASE.replace('coefficient = 1e-6', 'coefficient = 1e-6\nacceleration = "cycle_jump"\nperiod = 0.1'),
     {}, ["body[0].motion", "'free' bodies have no cycle to jump over"]),
    ("guided_body_spinning",
     BASE.replace("position = [0.0, 0.0, 0.0025]",
                  'position = [0.0, 0.0, 0.0025]\nmotion = "guided"\nangular_velocity = [0.0, 0.0, 1.0]\n'
                  'path = { velocity = [0.1, 0.0, 0.0], free_axis = [0.0, 0.0, 1.0] }'), {},
     ["body[0].angular_velocity", "does not apply to a guided body"]),
    ("body_starts_inside_a_plane", BASE.replace("position = [0.0, 0.0, 0.0025]", "position = [0.0, 0.0, 0.001]"),
     {}, ["body[0].position", "starts 0.0015 m inside surface 'floor'"]),
    ("force_overflows", BASE.replace("position = [0.0, 0.0, 0.0025]",
                                     "position = [0.0, 0.0, 0.0025]\nforce = [1e308, 0.0, 0.0]"),
     {}, ["body[0].force", "overflows the acceleration"]),
    ("dt_above_stability_limit", BASE.replace("dt = 1e-5", "dt = 1e-3"), {},
     ["run.dt", "stability limit", "largest stable dt"]),
    ("body_inside_a_mesh_surface",
     BASE.replace('type = "plane"', 'type = "mesh"\nshape = { type = "box", size = [0.1, 0.1, 0.01] }'), {},
     ["body[0].position", "inside surface 'floor'"]),
    ("mesh_surface_with_nan",
     BASE.replace('type = "plane"', 'type = "mesh"\nmesh = "nan.obj"'), {"nan.obj": NAN_OBJ},
     ["surface[0].mesh", "nan.obj", "NaN"]),
    ("smooth_normals_on_a_plane",
     BASE.replace('type = "plane"', 'type = "plane"\nsmooth_normals = true'), {},
     ["surface[0].smooth_normals", "does not apply"]),
    ("smooth_normals_not_a_boolean",
     BASE.replace('type = "plane"', 'type = "mesh"\nshape = { type = "box", size = [0.1, 0.1, 0.01] }'
                  '\nposition = [0, 0, -0.005]\nsmooth_normals = 1'), {},
     ["surface[0].smooth_normals", "true or false"]),
    ("negative_margin", BASE.replace("[contact]", "[contact]\nmargin = -1e-4"), {},
     ["contact.margin"]),
    ("mesh_is_a_folder", with_mesh("."), {}, ["body[0].mesh", "a folder, not a mesh file"]),
    ("garbage_stl", with_mesh("garbage.stl"), {"garbage.stl": "solid x\nthis is not an stl file\n\x01\x02"},
     ["body[0].mesh", "garbage.stl", "no triangle faces"]),
    ("obj_with_nan_vertex", with_mesh("nan.obj"), {"nan.obj": NAN_OBJ},
     ["body[0].mesh", "nan.obj", "NaN"]),
    ("open_mesh_for_free_body", with_mesh("open.obj"), {"open.obj": OPEN_OBJ},
     ["body[0].mesh", "open.obj", "open mesh"]),
    ("bad_mesh_of_second_body",
     BASE.replace("[[surface]]", '[[body]]\nname = "pin"\nmesh = "open.obj"\nposition = [0.1, 0.0, 0.0]\n\n[[surface]]'),
     {"open.obj": OPEN_OBJ}, ["body[1].mesh", "open.obj", "open mesh"]),
]


@pytest.mark.parametrize("text, files, expected", [c[1:] for c in BAD_SCENES],
                         ids=[c[0] for c in BAD_SCENES])
def test_bad_scene_exits_2_with_one_line_naming_file_and_key(tmp_path, capsys, caplog,
                                                             text, files, expected):
    for name, content in files.items():
        write(tmp_path / name, content)
    scene = write(tmp_path / "scene.toml", text)
    out_dir = tmp_path / "out"
    code, out, err = cli(capsys, caplog, "run", scene, "-o", out_dir, "-q")
    assert code == 2
    assert len(err) == 1, err
    assert "Traceback" not in err[0]
    assert err[0].startswith("meshwear: error: ")
    assert str(scene) in err[0]
    for part in expected:
        assert part in err[0]
    assert not out_dir.exists(), "bad input must not write outputs"
    assert out == ""

    # check refuses it the same way
    code, out, err_check = cli(capsys, caplog, "check", scene)
    assert code == 2 and err_check == err and out == ""


def test_bad_scene_kinds_are_distinct():
    assert len(BAD_SCENES) >= 15
    assert len({c[0] for c in BAD_SCENES}) == len(BAD_SCENES)
    assert len({c[1] for c in BAD_SCENES}) == len(BAD_SCENES)


@pytest.mark.parametrize("kind", ["missing", "folder", "not_utf8"])
def test_unreadable_scene_file_exits_2(tmp_path, capsys, caplog, kind):
    scene = tmp_path / "scene.toml"
    if kind == "folder":
        scene.mkdir()
    elif kind == "not_utf8":
        scene.write_bytes(b"format = 1\n# caf\xe9\n")
    for command in (["run", scene, "-o", tmp_path / "out"], ["check", scene]):
        code, out, err = cli(capsys, caplog, *command)
        assert code == 2 and len(err) == 1 and str(scene) in err[0], err
        assert "Traceback" not in err[0]
    assert not (tmp_path / "out").exists()


def test_output_folder_that_is_a_file_exits_2(tmp_path, capsys, caplog):
    scene = write(tmp_path / "scene.toml", BASE)
    target = write(tmp_path / "out", "not a folder")
    code, out, err = cli(capsys, caplog, "run", scene, "-o", target, "-q")
    assert code == 2 and len(err) == 1, err
    assert str(target) in err[0] and "output folder" in err[0]
    assert target.read_text() == "not a folder"


@pytest.mark.parametrize("content", [None, "solid x\nnot a mesh\n\x00\x01", ""],
                         ids=["missing", "garbage", "empty"])
def test_info_on_a_bad_mesh_file_exits_2(tmp_path, capsys, caplog, content):
    mesh = tmp_path / "part.stl"
    if content is not None:
        mesh.write_text(content)
    code, out, err = cli(capsys, caplog, "info", mesh)
    assert code == 2 and len(err) == 1, err
    assert str(mesh) in err[0] and "Traceback" not in err[0]
    assert out == ""


# ------------------------------------------------------------------ a good run

@pytest.fixture(scope="module")
def good_run(tmp_path_factory):
    """Run GOOD once for the output tests: (out dir, return code, stdout, stderr)."""
    folder = tmp_path_factory.mktemp("good")
    scene = write(folder / "scene.toml", GOOD)
    out_dir = folder / "out"
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["run", str(scene), "-o", str(out_dir)])
    return out_dir, code, out.getvalue(), err.getvalue()


def test_good_run_writes_every_output(good_run):
    out_dir, code, out, err = good_run
    assert code == 0 and err == ""
    for name in ("block.pvd", "pin.pvd", "floor.pvd", "history.csv", "summary.json"):
        assert (out_dir / name).is_file(), name
        assert str(out_dir / name) in out, f"{name} not announced on stdout"
    assert (out_dir / "block" / "block_00000.vtp").is_file()
    assert not list(out_dir.rglob(".*.tmp")), "temporary files left behind"


@pytest.mark.parametrize("body", ["block", "pin"])
def test_good_run_frames(good_run, body):
    out_dir = good_run[0]
    entries = pvd_entries(out_dir / f"{body}.pvd")
    times = [t for t, _ in entries]
    assert len(entries) == GOOD_FRAMES
    np.testing.assert_allclose(times, np.linspace(0.0, GOOD_DURATION, GOOD_FRAMES), rtol=0, atol=1e-12)
    for i, (_, path) in enumerate(entries):
        assert path == out_dir / body / f"{body}_{i:05d}.vtp"

    polys = [read_vtp(path) for _, path in entries]
    n = polys[0].GetNumberOfPoints()
    assert n > 0 and all(p.GetNumberOfPoints() == n for p in polys)
    assert all(p.GetNumberOfPolys() == polys[0].GetNumberOfPolys() > 0 for p in polys)
    fields = []
    for poly in polys:
        data = poly.GetPointData()
        frame = {}
        for name, components in POINT_DATA.items():
            array = data.GetArray(name)
            assert array is not None, f"{name} missing"
            assert array.GetNumberOfComponents() == components and array.GetNumberOfTuples() == n
            frame[name] = vtk_to_numpy(array)
        frame["points"] = vtk_to_numpy(poly.GetPoints().GetData())
        fields.append(frame)
        assert np.all(np.isfinite(frame["points"]))
        assert set(np.unique(frame["contact_state"])) <= {0, 1, 2}
        assert np.all(frame["normal_force"] >= 0.0) and np.all(frame["pressure"] >= 0.0)
    for before, after in zip(fields, fields[1:]):
        assert np.all(after["wear_depth"] >= before["wear_depth"]), "wear depth decreased"
        assert np.all(after["friction_work"] >= before["friction_work"]), "friction work decreased"
    assert np.all(fields[0]["wear_depth"] == 0.0)
    assert fields[-1]["wear_depth"].max() > 0.0, "the sliding body did not wear"
    assert fields[-1]["friction_work"].sum() > 0.0

    # points in world coordinates: each frame's box centre (xy) is the body
    # origin that history.csv gives at that time
    _, rows = read_history(out_dir / "history.csv")
    origin = {round(float(r["time"]), 9): (float(r["x"]), float(r["y"]))
              for r in rows if r["body"] == body}
    for t, frame in zip(times, fields):
        p = frame["points"]
        centre = 0.5 * (p.min(axis=0) + p.max(axis=0))
        np.testing.assert_allclose(centre[:2], origin[round(t, 9)], atol=1e-7)


def test_good_run_frame_0_is_the_reference_mesh_placed_in_the_world(good_run):
    vertices, faces = geometry.primitive("box", size=BLOCK_SIZE)
    vertices, faces = remesh.refine(vertices, faces, BLOCK_RESOLUTION)
    turned = np.column_stack([-vertices[:, 1], vertices[:, 0], vertices[:, 2]])   # 90° about z
    points = vtk_to_numpy(read_vtp(good_run[0] / "block" / "block_00000.vtp").GetPoints().GetData())
    np.testing.assert_allclose(points, turned + BLOCK_POSITION, rtol=0, atol=1e-12)
    # the turned block is 6 mm along x and 10 mm along y, its bottom on the plane
    np.testing.assert_allclose(points.min(axis=0), BLOCK_POSITION - [0.003, 0.005, 0.002], atol=1e-12)
    np.testing.assert_allclose(points.max(axis=0), BLOCK_POSITION + [0.003, 0.005, 0.002], atol=1e-12)


def test_good_run_pvd_opens_in_pyvista(good_run):
    out_dir = good_run[0]
    reader = pyvista.PVDReader(out_dir / "block.pvd")
    np.testing.assert_allclose(reader.time_values, np.linspace(0.0, GOOD_DURATION, GOOD_FRAMES),
                               rtol=0, atol=1e-12)
    reader.set_active_time_value(reader.time_values[-1])
    last = reader.read()[0]
    assert last.point_data["wear_depth"].max() > 0.0
    assert last.point_data["friction_force"].shape == (last.n_points, 3)
    floor = pyvista.PVDReader(out_dir / "floor.pvd")
    assert floor.time_values == [0.0]
    patch = floor.read()[0]
    np.testing.assert_allclose(patch.points[:, 2], 0.0, atol=1e-15)
    np.testing.assert_allclose(np.ptp(patch.points[:, :2], axis=0), [0.5, 0.5], rtol=1e-12)


def test_good_run_history(good_run):
    header, rows = read_history(good_run[0] / "history.csv")
    assert header[:len(HISTORY_COLUMNS)] == HISTORY_COLUMNS
    for body in ("block", "pin"):
        mine = [r for r in rows if r["body"] == body]
        assert len(mine) == GOOD_HISTORY
        times = np.array([float(r["time"]) for r in mine])
        np.testing.assert_allclose(times, np.linspace(0.0, GOOD_DURATION, GOOD_HISTORY), rtol=0, atol=1e-12)
        for column in ("friction_work", "wear_volume", "max_wear_depth"):
            values = np.array([float(r[column]) for r in mine])
            assert values[0] == 0.0 and np.all(np.diff(values) >= 0.0), column
        assert float(mine[-1]["wear_volume"]) > 0.0
        for r in mine:
            assert all(math.isfinite(float(r[c])) for c in HISTORY_COLUMNS if c != "body")
        # the body started where the scene put it, turned as given
        first = mine[0]
        assert float(first["qw"]) == pytest.approx(
            0.7071067811865476 if body == "block" else 1.0, rel=1e-12)
    block0 = next(r for r in rows if r["body"] == "block")
    np.testing.assert_allclose([float(block0[c]) for c in "xyz"], BLOCK_POSITION, atol=1e-15)


def test_good_run_summary(good_run):
    out_dir = good_run[0]
    summary = json.loads((out_dir / "summary.json").read_text())
    assert SUMMARY_KEYS <= set(summary)
    assert summary["format"] == 1 and summary.get("status", "ok") == "ok"
    assert summary["time"] == pytest.approx(GOOD_DURATION, rel=1e-12)
    assert summary["steps"] == GOOD_STEPS
    assert summary["wall_time"] > 0.0
    assert set(summary["bodies"]) == {"block", "pin"}
    _, rows = read_history(out_dir / "history.csv")
    for name, body in summary["bodies"].items():
        assert BODY_KEYS <= set(body), name
        for key in ("position", "velocity", "angular_velocity", "contact_force"):
            assert len(body[key]) == 3 and all(math.isfinite(v) for v in body[key])
        assert len(body["orientation"]) == 4
        assert np.linalg.norm(body["orientation"]) == pytest.approx(1.0, rel=1e-9)
        last = [r for r in rows if r["body"] == name][-1]
        assert body["wear_volume"] == pytest.approx(float(last["wear_volume"]), rel=1e-12, abs=0.0)
        assert body["max_wear_depth"] == pytest.approx(float(last["max_wear_depth"]), rel=1e-12, abs=0.0)
        assert body["friction_work"] == pytest.approx(float(last["friction_work"]), rel=1e-12, abs=0.0)
        np.testing.assert_allclose(body["position"], [float(last[c]) for c in "xyz"], rtol=1e-12)
        assert body["wear_volume"] > 0.0


def test_a_second_run_replaces_the_first(tmp_path, capsys, caplog):
    scene = write(tmp_path / "scene.toml", BASE.replace("frames = 3", "frames = 4"))
    out_dir = tmp_path / "out"
    assert cli(capsys, caplog, "run", scene, "-o", out_dir, "-q")[0] == 0
    write(scene, BASE.replace("frames = 3", "frames = 2"))
    assert cli(capsys, caplog, "run", scene, "-o", out_dir, "-q")[0] == 0
    assert len(pvd_entries(out_dir / "block.pvd")) == 2
    assert sorted(p.name for p in (out_dir / "block").iterdir()) == ["block_00000.vtp", "block_00001.vtp"]
    _, rows = read_history(out_dir / "history.csv")
    assert len(rows) == 5


# ------------------------------------------------------------------ numerical error

def test_wear_through_the_thickness_stops_with_exit_3_and_valid_outputs(tmp_path, capsys, caplog):
    scene = write(tmp_path / "thin.toml", INVERTING)
    out_dir = tmp_path / "out"
    code, out, err = cli(capsys, caplog, "run", scene, "-o", out_dir, "-q")
    assert code == 3, err
    assert not any("Traceback" in line for line in err)
    reasons = [line for line in err if "inverted" in line]
    assert len(reasons) == 1 and "triangle" in reasons[0] and "'plate'" in reasons[0], err
    assert reasons[0].startswith("meshwear: run stopped: ")

    summary = json.loads((out_dir / "summary.json").read_text())
    assert summary["status"] == "numerical_error"
    assert "inverted" in summary["message"]
    # about 0.3 mm of wear every 0.02 s: through the 0.5 mm plate by 0.04 s
    assert 0.02 < summary["time"] < 0.06
    assert summary["steps"] < 12000

    entries = pvd_entries(out_dir / "plate.pvd")
    assert 1 <= len(entries) < 11
    times = [t for t, _ in entries]
    assert times == sorted(times) and times[0] == 0.0 and times[-1] < summary["time"]
    for _, path in entries:
        assert path.is_file()
        poly = read_vtp(path)
        assert poly.GetNumberOfPoints() > 0
        assert poly.GetPointData().GetArray("wear_depth").GetNumberOfTuples() == poly.GetNumberOfPoints()
    listed = {path.name for _, path in entries}
    assert {p.name for p in (out_dir / "plate").iterdir()} == listed
    assert pyvista.PVDReader(out_dir / "plate.pvd").time_values == times

    header, rows = read_history(out_dir / "history.csv")
    assert header[:len(HISTORY_COLUMNS)] == HISTORY_COLUMNS
    history_times = [float(r["time"]) for r in rows]
    assert history_times[0] == 0.0 and history_times[-1] < summary["time"]
    wear = [float(r["max_wear_depth"]) for r in rows]
    assert all(b >= a for a, b in zip(wear, wear[1:]))


def test_non_finite_state_stops_with_exit_3(tmp_path, capsys, caplog, monkeypatch):
    """A state that turns NaN mid-run (injected once the run passes step 400
    of 1000) stops the run at the next sample with exit 3; the samples before
    it stay valid."""
    import meshwear.step.stepper

    real_advance = meshwear.step.stepper.advance

    def advance(model, state, until):
        before = state.step
        real_advance(model, state, until)
        if before < 400 <= state.step:
            state.bodies[0].pose[7] = float("nan")

    monkeypatch.setattr(meshwear.step.stepper, "advance", advance)
    scene = write(tmp_path / "scene.toml", BASE)
    out_dir = tmp_path / "out"
    code, out, err = cli(capsys, caplog, "run", scene, "-o", out_dir, "-q")
    assert code == 3, err
    assert err[0].startswith("meshwear: run stopped: ") and "non-finite" in err[0], err
    summary = json.loads((out_dir / "summary.json").read_text())
    assert summary["status"] == "numerical_error" and summary["steps"] == 500
    _, rows = read_history(out_dir / "history.csv")
    assert [float(r["time"]) for r in rows] == pytest.approx([0.0, 0.0025])
    assert all(math.isfinite(float(v)) for r in rows for k, v in r.items() if k != "body")


# ------------------------------------------------------------------ check, info, demo

def test_check_prints_the_cost_of_a_good_scene(tmp_path, capsys, caplog):
    scene = write(tmp_path / "scene.toml", GOOD)
    code, out, err = cli(capsys, caplog, "check", scene)
    assert code == 0 and err == []
    for part in ("ok", "mass", "contact points", "largest stable dt", f"{GOOD_STEPS} steps",
                 "estimated run time", "'block'", "'pin'", "'floor'"):
        assert part in out, part
    assert not (tmp_path / "out").exists()


def test_check_accepts_an_open_mesh_for_a_fixed_body(tmp_path, capsys, caplog):
    # open meshes are refused only where a volume (mass, inertia) is needed
    write(tmp_path / "open.obj", OPEN_OBJ)
    text = with_mesh("open.obj").replace("position = [0.0, 0.0, 0.0025]",
                                         'position = [0.0, 0.0, 0.001]\nmotion = "fixed"')
    code, out, err = cli(capsys, caplog, "check", write(tmp_path / "scene.toml", text))
    assert code == 0, err
    assert "4 contact points" in out and "mass n/a" in out


def test_info_describes_a_generated_stl(tmp_path, capsys, caplog):
    size = np.array([0.02, 0.01, 0.005])
    mesh = tmp_path / "box.stl"
    trimesh.creation.box(extents=size).export(mesh)
    code, out, err = cli(capsys, caplog, "info", mesh)
    assert code == 0 and err == []
    info = dict(line.split(": ", 1) for line in out.splitlines())
    assert {"vertices", "faces", "watertight", "extents", "area", "volume"} <= set(info)
    assert int(info["vertices"]) == 8 and int(info["faces"]) == 12     # STL seams merged
    assert info["watertight"] == "True"
    np.testing.assert_allclose(json.loads(info["extents"]), size, rtol=1e-6)
    a, b, c = size
    assert float(info["area"]) == pytest.approx(2 * (a * b + b * c + c * a), rel=1e-6)
    assert float(info["volume"]) == pytest.approx(a * b * c, rel=1e-6)

    # the same file read as millimetres
    code, out, _ = cli(capsys, caplog, "info", mesh, "--units", "mm")
    info = dict(line.split(": ", 1) for line in out.splitlines())
    assert code == 0 and float(info["volume"]) == pytest.approx(a * b * c * 1e-9, rel=1e-6, abs=0.0)


def test_demo_runs_and_prints_its_series(tmp_path, capsys, caplog):
    code, out, err = cli(capsys, caplog, "demo", "-o", tmp_path / "demo")
    assert code == 0, err
    series = [Path(word) for line in out.splitlines() for word in line.split() if word.endswith(".pvd")]
    assert series, out
    for path in series:
        assert path.is_file(), path
        assert pvd_entries(path)
    cube = pvd_entries(tmp_path / "demo" / "cube.pvd")
    assert len(cube) == 61 and all(p.is_file() for _, p in cube)
    summary = json.loads((tmp_path / "demo" / "summary.json").read_text())
    assert summary["bodies"]["cube"]["max_wear_depth"] > 0.0


# ------------------------------------------------------------------ the installed command

def test_installed_command_refuses_a_bad_scene(tmp_path):
    command = Path(sys.executable).parent / "meshwear"
    assert command.is_file(), f"console script not installed next to {sys.executable}"
    write(tmp_path / "bad.toml", BASE.replace("friction = 0.3", "friction = 0.3\nfricton = 0.4"))
    result = subprocess.run([str(command), "run", "bad.toml"], cwd=tmp_path, capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr
    lines = result.stderr.splitlines()
    assert len(lines) == 1, lines
    assert "bad.toml" in lines[0] and "contact.fricton" in lines[0] and "friction" in lines[0]
    assert result.stdout == ""
    assert not (tmp_path / "out").exists()


def test_progress_is_reported_between_sparse_samples(tmp_path):
    from meshwear.model.build import build_model, initial_state
    from meshwear.scene.reader import load_scene
    from meshwear.step.simulate import PROGRESS_STEPS, run

    scene = write(tmp_path / "scene.toml", BASE.replace("history = 5", "history = 2").replace(
        "duration = 0.01", "duration = 0.05"))
    model = build_model(load_scene(scene))
    calls = []
    run(model, initial_state(model), progress=lambda step, n: calls.append((step, n)))
    steps = [c[0] for c in calls]
    assert steps == sorted(steps) and steps[-1] == model.n_steps
    assert np.diff([0, *steps]).max() <= PROGRESS_STEPS
    assert model.n_steps == 5000 and len(steps) >= 3


def test_progress_bar_line(capsys):
    from meshwear.cli import _ProgressBar

    class Model:
        dt = 1e-5

    bar = _ProgressBar(Model())
    bar(0, 1000)
    bar(1000, 1000)
    bar.finish()
    err = capsys.readouterr().err
    assert "eta    -- s" in err and "100.0%" in err and err.endswith("\n")


def test_write_error_mid_run_is_one_line(tmp_path, capsys, caplog, monkeypatch):
    from meshwear.output import recorder

    def full_disk(self, model, state):
        raise OSError(28, "No space left on device", str(tmp_path / "out" / "history.csv"))

    monkeypatch.setattr(recorder.RunRecorder, "on_sample", full_disk)
    code, out, err = cli(capsys, caplog, "run", write(tmp_path / "scene.toml", BASE),
                         "-o", tmp_path / "out", "-q")
    assert code == 2 and len(err) == 1, err
    assert "history.csv: cannot write the outputs (No space left on device)" in err[0]


def test_check_of_a_quasi_static_scene_has_no_stability_limit(capsys, caplog):
    code, out, err = cli(capsys, caplog, "check", Path(__file__).parents[1] / "examples" / "pin_on_disc.toml")
    assert code == 0, err
    assert "mode quasi-static" in out and "no stability limit (quasi-static)" in out


def test_check_of_a_cycle_jumping_scene_says_how_it_jumps(capsys, caplog):
    scene = Path(__file__).parents[1] / "examples" / "long" / "sphere_fretting_1e5.toml"
    code, out, err = cli(capsys, caplog, "check", scene)
    assert code == 0, err
    assert ("cycle jumping: 20 steps per cycle, 100000 cycles, implicit jumps, tolerance 0.01; "
            "outputs inside jumps are filled from them") in out
    # the jumping run itself is tried, not every cycle counted as resolved
    assert re.search(r"estimated run time with cycle jump(ing|s growing as in a \S+ s trial) "
                     r"\S+ s: stepping", out), out


def test_a_short_run_writes_a_frame_and_a_row_at_each_step(tmp_path, capsys, caplog):
    """More frames and history rows than step times (a trial with a short
    duration): one at each step time, and a warning naming the keys."""
    scene = write(tmp_path / "scene.toml",
                  BASE.replace("duration = 0.01", "duration = 4e-5")
                  .replace("frames = 3", "frames = 51").replace("history = 5", "history = 1001"))
    code, out, err = cli(capsys, caplog, "run", scene, "-o", tmp_path / "out", "-q")
    assert code == 0, err
    assert any("run.frames: 51 asked, but the run has 5 step times" in line for line in err)
    assert any("run.history: 1001 asked" in line for line in err)
    assert len(pvd_entries(tmp_path / "out" / "block.pvd")) == 5
    rows = (tmp_path / "out" / "history.csv").read_text().splitlines()
    assert len(rows) == 1 + 5                # the header, then the block at 5 times
