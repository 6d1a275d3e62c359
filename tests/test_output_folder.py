"""Output folders and --resume at the edges (docs/outputs.md): one run per
folder at a time, nothing of an earlier run replaced before the new one is
known to be able to write, summary.json "running" from the start, damaged
checkpoints and series refused naming the file, a full disk an error."""

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from meshwear.longrun import checkpoint
from meshwear.cli import main
from meshwear.model.build import build_model, initial_state
from meshwear.output.recorder import RunRecorder
from meshwear.scene.reader import load_scene
from meshwear.step.simulate import advance

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "examples" / "pin_on_disc.toml"
SHORT = ["--set", "run.duration=0.05", "--set", "run.frames=3", "--set", "run.history=3"]


def run(capsys, *argv):
    """``meshwear argv`` in-process: (exit code, stderr lines)."""
    code = main([str(a) for a in argv])
    return code, capsys.readouterr().err.splitlines()


def short_model():
    return build_model(load_scene(SCENE, (("run.duration", 0.05), ("run.frames", 3),
                                          ("run.history", 3))))


def stopped_run(out):
    """The files of a run stopped half-way at a checkpoint, as --resume finds them."""
    model = short_model()
    state = initial_state(model)
    recorder = RunRecorder(out, model, state=state)
    advance(model, state, model.n_steps // 2, observers=[recorder])
    checkpoint.save(out / checkpoint.FILE_NAME, model, state, 1.0)
    recorder.finish()
    return model


def test_a_second_run_into_a_busy_folder_is_refused(tmp_path, capsys):
    out = tmp_path / "out"
    model = short_model()
    holder = RunRecorder(out, model)                       # a run writing there
    code, err = run(capsys, "run", SCENE, "-o", out, "-q", *SHORT)
    assert code == 2 and len(err) == 1, err
    assert str(out) in err[0] and "another meshwear run is writing there" in err[0], err
    holder.finish()                                       # once it ends, the folder is free
    code, err = run(capsys, "run", SCENE, "-o", out, "-q", *SHORT)
    assert code == 0, err


def test_a_refused_rerun_keeps_the_earlier_run(tmp_path, capsys):
    out = tmp_path / "out"
    assert run(capsys, "run", SCENE, "-o", out, "-q", *SHORT)[0] == 0
    frames = sorted((out / "pin").iterdir())
    summary = (out / "summary.json").read_text()
    (out / "history.csv").unlink()
    (out / "history.csv").mkdir()                 # cannot be written as a file
    code, err = run(capsys, "run", SCENE, "-o", out, "-q", *SHORT)
    assert code == 2 and len(err) == 1 and "history.csv" in err[0], err
    assert sorted((out / "pin").iterdir()) == frames and len(frames) == 3
    assert (out / "summary.json").read_text() == summary


def test_summary_says_running_from_the_start(tmp_path):
    model = short_model()
    state = initial_state(model)
    recorder = RunRecorder(tmp_path, model, state=state)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["status"] == "running" and summary["steps"] == 0
    recorder.finish()


@pytest.mark.parametrize("damage", ["truncated", "empty", "bit_flip", "random"])
def test_a_damaged_checkpoint_is_refused_naming_it(tmp_path, capsys, damage):
    out = tmp_path / "out"
    stopped_run(out)
    path = out / checkpoint.FILE_NAME
    data = path.read_bytes()
    if damage == "truncated":
        data = data[: len(data) // 2]
    elif damage == "empty":
        data = b""
    elif damage == "bit_flip":
        middle = len(data) // 2
        data = data[:middle] + bytes([data[middle] ^ 0xFF]) + data[middle + 1:]
    else:
        data = bytes(range(256)) * 16
    path.write_bytes(data)
    code, err = run(capsys, "run", SCENE, "-o", out, "-q", "--resume", *SHORT)
    assert code == 2 and len(err) == 1, err
    assert str(path) in err[0] and "allow_pickle" not in err[0], err


@pytest.mark.parametrize("damage", ["corrupt", "deleted"])
def test_a_damaged_or_missing_series_is_refused_on_resume(tmp_path, capsys, damage):
    out = tmp_path / "out"
    stopped_run(out)
    pvd = out / "pin.pvd"
    if damage == "corrupt":
        pvd.write_text("<VTKFile><Collection><DataSet timestep=")
    else:
        pvd.unlink()
    code, err = run(capsys, "run", SCENE, "-o", out, "-q", "--resume", *SHORT)
    assert code == 2 and len(err) == 1 and "pin.pvd" in err[0], err


def test_the_stopped_run_resumes_when_nothing_is_damaged(tmp_path, capsys):
    out = tmp_path / "out"
    stopped_run(out)
    code, err = run(capsys, "run", SCENE, "-o", out, "-q", "--resume", *SHORT)
    assert code == 0, err
    assert json.loads((out / "summary.json").read_text())["status"] == "ok"


def test_checkpoint_every_nan_is_refused(tmp_path, capsys):
    code, err = run(capsys, "run", SCENE, "-o", tmp_path, "--checkpoint-every", "nan")
    assert code == 2 and err == ["meshwear: error: --checkpoint-every: must be a number >= 0, "
                                 "got nan"], err


def test_a_full_disk_stops_the_run_with_its_outputs_valid(tmp_path, capsys, monkeypatch):
    import shutil

    from meshwear.output import folder

    real = shutil.disk_usage
    calls = []

    def filling_up(path):
        calls.append(path)
        usage = real(path)
        # room for the first frames, then none
        return usage._replace(free=usage.free if len(calls) <= 2 else 1024)

    monkeypatch.setattr(folder.shutil, "disk_usage", filling_up)
    out = tmp_path / "out"
    code, err = run(capsys, "run", SCENE, "-o", out, "-q", *SHORT)
    assert code == 2 and len(err) == 1 and "No space left on device" in err[0], err
    entries = list(ET.parse(out / "pin.pvd").getroot().iter("DataSet"))
    assert 1 <= len(entries) < 3
    assert all((out / e.get("file")).is_file() for e in entries)
