"""--set KEY=VALUE: scene keys set over the file's, by the dotted names the
errors print, validated as the file's own."""

import json
from pathlib import Path

import pytest

from meshwear.longrun import checkpoint
from meshwear.cli import main
from meshwear.model.build import build_model, initial_state
from meshwear.scene.reader import load_scene, parse_override, set_key
from meshwear.scene.checks import SceneError

ROOT = Path(__file__).resolve().parents[1]
POD = str(ROOT / "examples" / "pin_on_disc.toml")
SHORT = ["--set", "run.duration=0.2", "--set", "run.frames=2", "--set", "run.history=3"]


@pytest.mark.parametrize("text, key, value", [
    ("wear.coefficient=1e-13", "wear.coefficient", 1e-13),
    ("body[0].force=[0, 0, -20]", "body[0].force", [0, 0, -20]),
    ("run.mode=quasi-static", "run.mode", "quasi-static"),
    ('wear.law="archard"', "wear.law", "archard"),
    ("surface[0].rotation={ axis = [0, 0, 1], rate = 10 }", "surface[0].rotation",
     {"axis": [0, 0, 1], "rate": 10}),
    ("contact.friction = 0.5", "contact.friction", 0.5),
])
def test_an_override_is_a_key_and_a_toml_value(text, key, value):
    assert parse_override(text) == (key, value)


def test_set_key_walks_tables_and_indexed_arrays():
    data = {"wear": {"law": "energy"}, "body": [{"name": "a"}, {"name": "b"}]}
    set_key(data, "wear.coefficient", 2.0)
    set_key(data, "body[1].path.oscillation.amplitude", 1e-3)
    set_key(data, "run.dt", 1e-4)
    assert data["wear"] == {"law": "energy", "coefficient": 2.0}
    assert data["body"][1]["path"] == {"oscillation": {"amplitude": 1e-3}}
    assert data["run"] == {"dt": 1e-4}
    with pytest.raises(SceneError, match=r"body\[2\].*has 2 \[\[body\]\] table"):
        set_key(data, "body[2].force", [0, 0, 1])
    with pytest.raises(SceneError, match="wear.law is not a table"):
        set_key(data, "wear.law.x", 1)


def test_run_with_a_doubled_coefficient_wears_twice_the_volume(tmp_path):
    volumes = []
    for k in ("1e-13", "2e-13"):
        out = tmp_path / k
        assert main(["run", POD, "-o", str(out), "-q", *SHORT,
                     "--set", f"wear.coefficient={k}"]) == 0
        volumes.append(json.loads((out / "summary.json").read_text())["bodies"]["pin"]
                       ["wear_volume"])
    assert volumes[1] == pytest.approx(2.0 * volumes[0], rel=1e-9)


@pytest.mark.parametrize("setting, words", [
    ("wear.coeficient=1", ["wear.coeficient", "unknown key", "did you mean 'coefficient'"]),
    ("body[4].force=[0, 0, 1]", ["body[4].force", "no body[4]"]),
    ("run.dt=-1", ["run.dt"]),
    ("nonsense", ["--set", "KEY=VALUE"]),
])
def test_a_bad_override_is_one_line_naming_the_key(capsys, setting, words):
    assert main(["check", POD, "--set", setting]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    for word in words:
        assert word in err


def test_check_says_what_it_set(capsys):
    assert main(["check", POD, *SHORT]) == 0
    out = capsys.readouterr().out
    assert "set run.duration = 0.2" in out


def test_resume_refuses_a_checkpoint_of_other_settings(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    scene = load_scene(POD, [("run.duration", 0.2), ("run.frames", 2), ("run.history", 3)])
    model = build_model(scene)
    checkpoint.save(out / checkpoint.FILE_NAME, model, initial_state(model), 0.0)
    code = main(["run", POD, "-o", str(out), "-q", "--resume", "--set", "run.duration=0.3",
                 "--set", "run.frames=2", "--set", "run.history=3"])
    assert code == 2 and "another version of this scene" in capsys.readouterr().err
