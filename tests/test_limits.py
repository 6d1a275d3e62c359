"""Limits measured against this machine (docs/outputs.md, "Limits checked
before any work"): refinements larger than the available memory holds, history
kept in memory beyond it, and outputs larger than the folder's free disk are
refused with exit 2 and the figure, before the work."""

import json
import shutil
import time
import types
from pathlib import Path

import pytest

import meshwear
from meshwear import api
from meshwear.geometry import remesh
from meshwear.cli import main
from meshwear.output import recorder
from meshwear.scene.checks import SceneError

ROOT = Path(__file__).resolve().parents[1]
POD = str(ROOT / "examples" / "pin_on_disc.toml")


def test_the_face_limit_is_the_smaller_of_memory_and_the_fixed_cap():
    faces, why = remesh.face_limit(memory=100 * 2**20)
    assert faces == 100 * 2**20 // remesh.BYTES_PER_FACE and "available memory" in why
    assert remesh.face_limit(memory=2**50) == (remesh.MAX_FACES,
                                               "the largest refinement meshwear makes")
    assert remesh.available_memory() is None or remesh.available_memory() > 0


def test_a_refinement_larger_than_memory_is_refused_before_refining(monkeypatch, capsys):
    """A pin's face refined to 20 µm needs more than the 262 144 faces that
    256 MiB hold at 1 KiB a face: refused at the pass that first makes more,
    never holding a mesh much larger than the limit. (It took 5 s here; a
    wall-clock bound on it failed with the machine loaded, 8.7-11 s.)"""
    monkeypatch.setattr(remesh, "available_memory", lambda: 256 * 2**20)
    largest = [0]
    bisect = remesh._bisect

    def counting(F, *args):
        out = bisect(F, *args)
        largest[0] = max(largest[0], len(out[0]))
        return out

    monkeypatch.setattr(remesh, "_bisect", counting)
    assert main(["check", POD, "--set", "body[0].resolution=2e-5"]) == 2
    assert 262_144 < largest[0] <= 4 * 262_144       # one pass past the limit at most
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "body[0]" in err[0]
    assert "more than 262144 faces (what this machine's 0.25 GiB of available memory" in err[0]


def test_history_kept_in_memory_beyond_the_available_memory_is_refused(monkeypatch):
    from meshwear.api import ROW_BYTES
    from meshwear.model.build import build_model

    scene = meshwear.load(POD, {"run.duration": 0.2, "run.history": 1001})
    model = build_model(scene)
    samples, n = len(model.sample_steps), len(model.bodies[0].tributary_area)
    rows, depths = samples * ROW_BYTES, 8 * samples * n
    monkeypatch.setattr(api, "available_memory", lambda: rows - 1)
    with pytest.raises(SceneError, match=rf"run\.history: {samples} samples of 1 part\(s\): "
                                         r"their history rows take about .* GiB in memory"):
        meshwear.run(scene)
    # room for the rows, not for every vertex's depth at every sample too
    monkeypatch.setattr(api, "available_memory", lambda: rows + depths // 2)
    assert meshwear.run(scene).history["time"].size == samples
    with pytest.raises(SceneError, match="history rows and per-vertex wear depths"):
        meshwear.run(scene, vertex_history=True)


def test_outputs_larger_than_the_free_disk_stop_after_the_first_frame(tmp_path, monkeypatch,
                                                                     capsys):
    """The 20 frames to come of the pin do not fit in 100 KiB beyond the spare
    space kept: the run stops after its first frame with exit 2, the figure,
    a valid one-frame series and summary.json saying write_error."""
    from meshwear.output.folder import SPARE_BYTES

    tight = shutil.disk_usage(tmp_path)._replace(free=SPARE_BYTES + 100 * 2**10)
    monkeypatch.setattr(recorder, "shutil", types.SimpleNamespace(disk_usage=lambda p: tight))
    out = tmp_path / "out"
    start = time.perf_counter()
    short = ["--set", "run.duration=0.2", "--set", "run.frames=21", "--set", "run.history=21"]
    assert main(["run", POD, "-o", str(out), "-q", *short]) == 2
    assert time.perf_counter() - start < 30.0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "No space left on device for this run: its 20 frames to come" in err[0]
    assert "GiB are free (fewer run.frames, or another folder)" in err[0]
    assert len(list((out / "pin").glob("*.vtp"))) == 1
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "write_error" and "No space left" in summary["message"]
    # with the space it needs, the same run goes through
    monkeypatch.setattr(recorder, "shutil", shutil)
    assert main(["run", POD, "-o", str(out), "-q", *short]) == 0
