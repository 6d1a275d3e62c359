"""CAD files in: the STEP fixture (meshes/make_step.py) read through trimesh and
cascadio (the ``cad`` extra), its units, the message when the extra is missing,
and a run of a STEP pin whose worn volume is Archard's k P s (docs/cad.md)."""

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh

from meshwear.cli import main
from meshwear.geometry.meshes import CAD_EXTRA, MeshError, load_mesh
from meshwear.scene.reader import load_scene
from meshwear.scene.checks import SceneError

ROOT = Path(__file__).resolve().parents[1]
STEP = ROOT / "meshes" / "pin_d6_h10_mm.step"
EXAMPLE = ROOT / "examples" / "step_pin_on_disc.toml"
RADIUS, HEIGHT = 3e-3, 10e-3


def test_the_step_fixture_is_a_closed_pin_in_metres():
    vertices, faces = load_mesh(STEP)
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0
    # the rim is tessellated by chords: the extent is exact along x and z and
    # within one chord's sagitta along y; the volume is an inscribed polygon's
    np.testing.assert_allclose(mesh.bounds[:, [0, 2]], [[-RADIUS, 0], [RADIUS, HEIGHT]],
                               atol=1e-12)
    exact = math.pi * RADIUS**2 * HEIGHT
    assert exact * (1 - 1e-3) < mesh.volume < exact


def test_a_step_file_takes_no_units(tmp_path):
    with pytest.raises(MeshError, match="its own length unit"):
        load_mesh(STEP, units="mm")
    text = EXAMPLE.read_text().replace('mesh = "../meshes/pin_d6_h10_mm.step"',
                                       f'mesh = "{STEP}"\nunits = "mm"')
    scene = tmp_path / "step.toml"
    scene.write_text(text)
    with pytest.raises(SceneError, match=r"body\[0\]\.units.*its own length unit"):
        load_scene(scene)


def test_without_the_cad_extra_the_error_names_it(monkeypatch):
    monkeypatch.setitem(sys.modules, "cascadio", None)  # import cascadio raises ImportError
    with pytest.raises(MeshError) as err:
        load_mesh(STEP)
    assert CAD_EXTRA in str(err.value) and str(STEP) in str(err.value)
    assert "\n" not in str(err.value)


def test_a_step_pin_wears_k_p_s(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", str(EXAMPLE), "-o", str(out), "--set", "run.duration=0.5",
                 "--set", "run.frames=3", "--set", "run.history=11"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    mass = 7850.0 * math.pi * RADIUS**2 * HEIGHT
    load = 20.0 + mass * 9.81
    sliding = 2 * math.pi * 0.02 * 0.5           # half a turn of a 20 mm track
    expected = 1e-15 * load * sliding            # k = 1e-6 mm³/(N m) = 1e-15 1/Pa
    worn = summary["bodies"]["pin"]["wear_volume"]
    assert worn == pytest.approx(expected, rel=5e-3)
