"""The Python interface (docs/api.md): load with keys set, Scene.set, run in
memory with outputs and progress, per-part arrays, worn meshes, history
columns and summary, all agreeing with the files ``meshwear run`` writes."""

import csv
import json

import numpy as np
import pytest
import pyvista
import trimesh

import meshwear
from meshwear.cli import main
from meshwear.kernels.contact import rotation_entries
from meshwear.scene.reader import load_scene
from meshwear.scene.checks import SceneError
from test_counter_wear import PIN_ON_WORN_DISC

#: a tenth of a turn of the pin on a worn disc: both parts wear
DURATION = 0.0628


@pytest.fixture(scope="module")
def scene_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("api") / "pin_on_worn_disc.toml"
    path.write_text(PIN_ON_WORN_DISC.format(duration=DURATION, coefficient=2e-13, dt=2e-3))
    return path


@pytest.fixture(scope="module")
def result(scene_file, tmp_path_factory):
    calls = []
    out = tmp_path_factory.mktemp("api_out")
    scene = meshwear.load(scene_file, {"body[0].force": np.array([0.0, 0.0, -12.0])})
    r = meshwear.run(scene, out=out, progress=lambda step, n: calls.append((step, n)),
                     vertex_history=True)
    r.calls = calls
    return r


def test_load_sets_keys_as_the_command_line_does(scene_file):
    by_api = meshwear.load(scene_file, {"wear.coefficient": 3e-13, "body[0].force": [0, 0, -5]})
    by_set = load_scene(scene_file, [("wear.coefficient", 3e-13), ("body[0].force", [0, 0, -5])])
    assert by_api == by_set
    assert by_api.wear.coefficient == 3e-13 and by_api.bodies[0].force == (0, 0, -5)


def test_scene_set_makes_a_checked_copy(scene_file):
    scene = meshwear.load(scene_file)
    changed = scene.set("wear.coefficient", np.float64(5e-13)).set({"run.history": 3})
    assert changed.wear.coefficient == 5e-13 and changed.run.history == 3
    assert scene.wear.coefficient == 1e-13, "set changed the original"
    assert changed.overrides == (("wear.coefficient", 5e-13), ("run.history", 3))
    with pytest.raises(SceneError, match=r"wear\.coefficient"):
        scene.set("wear.coefficient", -1.0)
    with pytest.raises(SceneError, match=r"body\[3\]"):
        scene.set("body[3].force", [0, 0, 1])


def test_parts_are_the_bodies_and_the_worn_surfaces(result):
    assert list(result.parts) == ["pin", "disc"]
    assert [p.kind for p in result.parts.values()] == ["body", "surface"]
    for name, part in result.parts.items():
        entry = result.summary["bodies" if part.kind == "body" else "surfaces"][name]
        assert part.wear_depth.max() > 0.0
        assert part.wear_depth.max() == entry["max_wear_depth"]
        assert part.history["wear_volume"][-1] == entry["wear_volume"]
        assert set(part.fields) == {"wear_depth", "normal_force", "friction_force", "pressure",
                                    "contact_state", "friction_work"}


def test_the_load_was_set(result):
    # quasi-static balance: the contact carries the 12 N set over the file's 10 N
    assert result.parts["pin"].history["fz"][-1] == pytest.approx(12.0, rel=1e-3)


def test_the_worn_mesh_is_in_the_part_s_frame(result):
    pin = result.parts["pin"]
    mesh = pin.mesh
    assert mesh.is_watertight
    body = result.model.bodies[0]
    unworn = trimesh.Trimesh(body.reference_vertices - body.origin, body.faces, process=False)
    # worn volume = the summary's, the worn vertices moved in by their depth
    lost = unworn.volume - mesh.volume
    assert lost == pytest.approx(result.summary["bodies"]["pin"]["wear_volume"], rel=0.02)
    # the frame's world points are the part's own vertices placed by its pose
    entry = result.summary["bodies"]["pin"]
    R = np.array(rotation_entries(np.array(entry["orientation"]))).reshape(3, 3)
    last = pyvista.read(sorted((result.out / "pin").glob("*.vtp"))[-1])
    assert np.allclose(last.points, entry["position"] + pin.vertices @ R.T, atol=1e-9)


def test_history_columns_match_history_csv(result):
    with open(result.out / "history.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(result.history["time"])
    for column, values in result.history.items():
        if column == "body":
            assert [r["body"] for r in rows] == list(values)
        else:
            assert np.allclose([float(r[column]) for r in rows], values.astype(float),
                               rtol=1e-12, atol=0.0), column


def test_summary_matches_summary_json(result):
    written = json.loads((result.out / "summary.json").read_text())
    assert written["bodies"] == result.summary["bodies"]
    assert written["surfaces"] == result.summary["surfaces"]


def test_vertex_history_only_when_asked(result, scene_file):
    pin = result.parts["pin"]
    assert pin.depth_history.shape == (len(pin.history["time"]), len(pin.vertices))
    assert np.array_equal(pin.depth_history[-1], pin.wear_depth)
    plain = meshwear.run(meshwear.load(scene_file, {"run.duration": 0.01}))
    assert all(p.depth_history is None for p in plain.parts.values())
    assert plain.out is None


def test_progress_reaches_the_last_step(result):
    n = result.model.n_steps
    assert result.calls and result.calls[-1] == (n, n)
    assert [s for s, _ in result.calls] == sorted(s for s, _ in result.calls)


def test_the_package_exposes_the_interface():
    assert {"load", "run", "Result", "Part", "Scene", "SceneError"} <= set(meshwear.__all__)
    with pytest.raises(AttributeError):
        meshwear.no_such_name


@pytest.mark.parametrize("fmt", ["stl", "ply", "obj"])
def test_export_writes_each_worn_part_in_its_own_frame(result, tmp_path, fmt):
    dest = tmp_path / fmt
    assert main(["export", str(result.out), "--format", fmt, "--units", "mm",
                 "-d", str(dest)]) == 0
    frames = len(result.model.frame_steps)
    for name, part in result.parts.items():
        path = dest / f"{name}_{frames - 1:05d}.{fmt}"
        loaded = trimesh.load(path, process=False, force="mesh")
        # the triangles of the worn part, in mm; STL holds float32
        assert np.allclose(loaded.triangles * 1e-3, part.vertices[part.faces], rtol=0.0,
                           atol=1e-9)


def test_export_takes_a_frame_and_a_part(result, tmp_path):
    assert main(["export", str(result.out), "--part", "disc", "--frame", "0",
                 "-d", str(tmp_path)]) == 0
    first = trimesh.load(tmp_path / "disc_00000.stl", process=False)
    disc = result.parts["disc"]
    unworn = result.model.surfaces.per_vertex[0].reference_vertices
    assert np.allclose(first.triangles, unworn[disc.faces], atol=1e-9)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["disc_00000.stl"]


@pytest.mark.parametrize("args, key", [
    (["--part", "disco"], "--part disco"),
    (["--frame", "99"], "--frame 99"),
    (["--units", "furlong"], "--units furlong"),
])
def test_export_refuses_in_one_line(result, tmp_path, capsys, args, key):
    assert main(["export", str(result.out), "-d", str(tmp_path), *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and key in err
    assert not list(tmp_path.iterdir())


def test_export_refuses_a_folder_that_is_not_a_run(tmp_path, capsys):
    assert main(["export", str(tmp_path)]) == 2
    assert str(tmp_path) in capsys.readouterr().err


def _picture(path):
    import matplotlib.image

    return matplotlib.image.imread(path)[..., :3]


def test_plot_draws_non_blank_pictures(result, tmp_path):
    line = "-0.001,0,-0.0015:0.001,0,-0.0015"      # across the pin's worn end face
    assert main(["plot", str(result.out), "--part", "pin", f"--profile={line}",
                 "-d", str(tmp_path)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "history.png", "pin_profile.csv", "pin_profile.png", "pin_wear_map.png"]
    for name in ("history.png", "pin_profile.png", "pin_wear_map.png"):
        image = _picture(tmp_path / name)
        assert image.std() > 0.05, f"{name} is blank"
    # the wear map shows more than background and one colour
    colours = np.unique((_picture(tmp_path / "pin_wear_map.png") * 255).astype(int).reshape(-1, 3),
                        axis=0)
    assert len(colours) > 20
    with open(tmp_path / "pin_profile.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    depth = np.array([float(r["wear_depth"]) for r in rows])
    pin = result.parts["pin"]
    assert len(rows) > 100 and np.all(depth >= 0.0)
    assert pin.wear_depth.max() * 0.5 < depth.max() <= pin.wear_depth.max() * (1 + 1e-12)
    assert np.allclose([float(rows[0]["x"]), float(rows[-1]["x"])], [-1e-3, 1e-3], atol=1e-9)


def test_plot_draws_every_worn_part_by_default(result, tmp_path):
    assert main(["plot", str(result.out), "-d", str(tmp_path)]) == 0
    assert {"pin_wear_map.png", "disc_wear_map.png", "history.png"} == {
        p.name for p in tmp_path.iterdir()}


@pytest.mark.parametrize("args, key", [
    (["--view", "0,0,0"], "--view"),
    (["--view", "1,0"], "--view"),
    (["--profile=0,0,0:1,1"], "--profile"),
    (["--profile=0,0,0:0,0,0", "--part", "pin"], "--profile"),
    (["--profile=0,0,0:1,0,0"], "--profile"),                 # two parts: which?
    (["--part", "disco"], "--part disco"),
])
def test_plot_refuses_in_one_line(result, tmp_path, capsys, args, key):
    assert main(["plot", str(result.out), "-d", str(tmp_path / "p"), *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and key in err
    assert not (tmp_path / "p").exists(), "files written before the refusal"
