"""Checkpoints and --resume: a run killed at any moment and resumed ends with
the same numbers as a run never interrupted (docs/outputs.md, "Checkpoints": 1e-9)."""

import csv
import dataclasses
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import cases
from meshwear.longrun import checkpoint
from meshwear.cli import main
from meshwear.model.build import build_model, initial_state
from meshwear.scene.reader import load_scene
from meshwear.step.simulate import run

ROOT = Path(__file__).resolve().parents[1]


def _block_scene(tmp_path, duration=0.6, extra=""):
    text = (ROOT / "examples" / "reciprocating_block.toml").read_text()
    text = text.replace('"../meshes/', f'"{(ROOT / "meshes").as_posix()}/')
    text = text.replace("duration = 1.0 ", f"duration = {duration} ")
    text = text.replace('law = "energy_density"', f'law = "energy_density"\n{extra}')
    path = tmp_path / "block.toml"
    path.write_text(text)
    return path


def _meshwear(*args):
    return subprocess.Popen([sys.executable, "-m", "meshwear.cli", *map(str, args)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _rows(path):
    with open(path, newline="") as f:
        return list(csv.reader(f))


def test_sigkill_then_resume_matches_an_uninterrupted_run(tmp_path):
    scene = _block_scene(tmp_path)
    full, cut = tmp_path / "full", tmp_path / "cut"
    assert _meshwear("run", scene, "-o", full, "-q").wait(timeout=300) == 0
    job = _meshwear("run", scene, "-o", cut, "-q", "--checkpoint-every", "0.2")
    deadline = time.time() + 120
    while not (cut / checkpoint.FILE_NAME).exists():
        assert job.poll() is None, "the run ended before its first checkpoint"
        assert time.time() < deadline
        time.sleep(0.05)
    time.sleep(0.5)
    job.send_signal(signal.SIGKILL)
    job.wait()
    # killed outright: summary.json still says what it said from the start
    assert json.loads((cut / "summary.json").read_text())["status"] == "running"
    # the series stays valid while stopped: every listed frame exists
    listed = [line for line in (cut / "block.pvd").read_text().splitlines() if "DataSet" in line]
    assert all((cut / line.split('file="')[1].split('"')[0]).is_file() for line in listed)

    resumed = _meshwear("run", scene, "-o", cut, "--resume", "--checkpoint-every", "0.2")
    out, err = resumed.communicate(timeout=300)
    assert resumed.returncode == 0, err
    assert "resuming at t = " in out
    assert not (cut / checkpoint.FILE_NAME).exists()

    a = json.loads((full / "summary.json").read_text())["bodies"]["block"]
    b = json.loads((cut / "summary.json").read_text())["bodies"]["block"]
    for key in ("max_wear_depth", "wear_volume", "friction_work"):
        assert b[key] == pytest.approx(a[key], rel=1e-9, abs=0.0)
    assert _rows(cut / "history.csv") == _rows(full / "history.csv")
    frames = sorted(p.name for p in (cut / "block").iterdir())
    assert frames == sorted(p.name for p in (full / "block").iterdir())
    assert (cut / "block.pvd").read_text() == (full / "block.pvd").read_text()


@pytest.mark.parametrize("number, code, status", [(signal.SIGTERM, 143, "terminated"),
                                                   (signal.SIGINT, 130, "interrupted")])
def test_sigterm_or_ctrl_c_stop_at_a_checkpoint_and_resume(tmp_path, number, code, status):
    """A batch scheduler's SIGTERM (or Ctrl-C) stops the run at its next
    consistent state: a checkpoint, summary.json with the status, exit 143
    (130); --resume ends with the numbers of a run never stopped. Progress
    goes to stderr as plain lines (not a terminal); every file is 0644
    under umask 022."""
    scene = _block_scene(tmp_path)
    full, cut = tmp_path / "full", tmp_path / "cut"
    assert _meshwear("run", scene, "-o", full, "-q").wait(timeout=300) == 0
    mask = os.umask(0o022)                # the runs below inherit it
    try:
        job = _meshwear("run", scene, "-o", cut)
    finally:
        os.umask(mask)
    deadline = time.time() + 120
    while not (cut / "history.csv").exists() or len(_rows(cut / "history.csv")) < 4:
        assert job.poll() is None, "the run ended before it could be stopped"
        assert time.time() < deadline
        time.sleep(0.05)
    job.send_signal(number)
    out, err = job.communicate(timeout=120)
    assert job.returncode == code, err
    assert f"meshwear: {status} at t = " in err and "--resume" in err
    summary = json.loads((cut / "summary.json").read_text())
    assert summary["status"] == status
    assert (cut / checkpoint.FILE_NAME).exists()
    for path in [cut / checkpoint.FILE_NAME, cut / "summary.json", cut / "history.csv",
                 cut / "block.pvd", *sorted((cut / "block").iterdir())[:2]]:
        assert path.stat().st_mode & 0o777 == 0o644, path

    resumed = _meshwear("run", scene, "-o", cut, "--resume", "-q")
    out, err = resumed.communicate(timeout=300)
    assert resumed.returncode == 0, err
    a = json.loads((full / "summary.json").read_text())["bodies"]["block"]
    b = json.loads((cut / "summary.json").read_text())["bodies"]["block"]
    for key in ("max_wear_depth", "wear_volume", "friction_work"):
        assert b[key] == pytest.approx(a[key], rel=1e-9, abs=0.0)
    assert _rows(cut / "history.csv") == _rows(full / "history.csv")


def test_progress_lines_when_not_a_terminal(tmp_path, monkeypatch, capsys):
    """Without a terminal, progress is a plain line every LINE_SECONDS."""
    from meshwear import cli

    monkeypatch.setattr(cli._ProgressLines, "LINE_SECONDS", 0.0)
    progress = cli._ProgressLines(build_model(load_scene(_block_scene(tmp_path, 0.05))))
    progress(10, 40)
    progress(40, 40)                      # the end: the run's own report says it
    err = capsys.readouterr().err
    assert err.startswith("meshwear: 25.0 % t = ") and "eta" in err and err.count("\n") == 1
    # with cycle jumping, the last jump and its bound
    from meshwear.longrun.wear import JumpState

    model = build_model(load_scene(_block_scene(tmp_path, 0.05)))
    state = initial_state(model)
    state.jump = JumpState(last_jump=7, last_limit="drift")
    progress = cli._ProgressLines(model, state)
    progress(10, 40)
    assert capsys.readouterr().err.rstrip().endswith("last jump 7 cycles (drift)")


class _Stop(Exception):
    pass


class _KillAt:
    """Raises at the sample of the given time, as a kill would stop the run."""

    def __init__(self, time_):
        self.time = time_

    def on_frame(self, model, state):
        pass

    def on_sample(self, model, state):
        if state.time >= self.time:
            raise _Stop


def test_cycle_jump_run_resumes_to_the_same_wear(tmp_path):
    scene = load_scene(cases.VALIDATION / "sphere_pin.toml")
    scene = dataclasses.replace(
        scene, wear=dataclasses.replace(scene.wear, coefficient=6e-14, acceleration="cycle_jump",
                                        period=0.1),
        run=dataclasses.replace(scene.run, duration=30.0, frames=0, history=31))
    model = build_model(scene)
    full = run(model, initial_state(model))

    saver = checkpoint.Checkpointer(tmp_path, every=0.0)
    first = initial_state(model)
    with pytest.raises(_Stop):
        run(model, first, observers=[_KillAt(17.0)], checkpoint=saver)
    resumed = initial_state(model)
    checkpoint.load(saver.path, model, resumed)
    assert 0.0 < resumed.time <= 17.0 and resumed.jump.jumps > 0
    run(model, resumed)
    w, w_full = resumed.bodies[0].wear_depth, full.bodies[0].wear_depth
    assert np.abs(w - w_full).max() <= 1e-9 * w_full.max()
    assert resumed.jump.resolved_steps == full.jump.resolved_steps


def test_resume_without_a_checkpoint_is_an_input_error(tmp_path, capsys):
    code = main(["run", str(_block_scene(tmp_path)), "-o", str(tmp_path / "none"), "--resume", "-q"])
    err = capsys.readouterr().err
    assert code == 2 and "no checkpoint" in err and "--resume" in err


def test_resume_refuses_a_checkpoint_of_another_scene(tmp_path, capsys):
    scene = _block_scene(tmp_path, duration=0.05)
    out = tmp_path / "out"
    model = build_model(load_scene(scene))
    out.mkdir()
    checkpoint.save(out / checkpoint.FILE_NAME, model, initial_state(model), 0.0)
    scene.write_text(scene.read_text().replace("friction = 0.3", "friction = 0.31"))
    code = main(["run", str(scene), "-o", str(out), "--resume", "-q"])
    err = capsys.readouterr().err
    assert code == 2 and "another version of this scene" in err
    assert "the scene file block.toml changed" in err and ".mesh (" not in err


def test_resume_names_the_mesh_file_that_changed(tmp_path, capsys):
    mesh = tmp_path / "block.stl"
    mesh.write_bytes((ROOT / "meshes" / "block_10x10x5mm.stl").read_bytes())
    scene = _block_scene(tmp_path, duration=0.05)
    scene.write_text(scene.read_text().replace(f"{(ROOT / 'meshes').as_posix()}/block_10x10x5mm.stl",
                                               mesh.as_posix()))
    out = tmp_path / "out"
    out.mkdir()
    model = build_model(load_scene(scene))
    checkpoint.save(out / checkpoint.FILE_NAME, model, initial_state(model), 0.0)
    # the same mesh, one byte of its header changed
    data = bytearray(mesh.read_bytes())
    data[0] = (data[0] + 1) % 128
    mesh.write_bytes(bytes(data))
    code = main(["run", str(scene), "-o", str(out), "--resume", "-q"])
    err = capsys.readouterr().err
    assert code == 2 and "body[0].mesh (block.stl) changed" in err
    assert "scene file" not in err and len(err.strip().splitlines()) == 1
