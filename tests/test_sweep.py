"""Parameter sweeps (docs/sweeps.md): runs on a LocalCluster, a failing run
as a row, finished runs not run again, the table against the runs' own
summaries, and the sweep file."""

import csv
import json

import numpy as np
import pytest

from meshwear.cli import main
from meshwear.scene.checks import SceneError
from meshwear.sweep import from_arguments, run_sweep
from test_counter_wear import PIN_ON_WORN_DISC

COEFFICIENTS = [1e-13, 2e-13, 3e-13, -1.0]     # the last one is refused: its row says so


@pytest.fixture(scope="module")
def scene_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("sweep") / "pin_on_worn_disc.toml"
    path.write_text(PIN_ON_WORN_DISC.format(duration=0.02, coefficient=2e-13, dt=2e-3))
    return path


def _table(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


@pytest.fixture(scope="module")
def swept(scene_file, tmp_path_factory):
    out = tmp_path_factory.mktemp("swept")
    code = main(["sweep", str(scene_file), "--vary", f"wear.coefficient={COEFFICIENTS}",
                 "--workers", "2", "-o", str(out)])
    return code, out


def test_a_sweep_on_a_local_cluster_writes_a_row_per_run(swept):
    code, out = swept
    assert code == 1, "a sweep with a failed run exits 1"
    rows = _table(out / "sweep.csv")
    assert [r["run"] for r in rows] == ["run_000", "run_001", "run_002", "run_003"]
    assert [float(r["wear.coefficient"]) for r in rows] == COEFFICIENTS
    assert [r["status"] for r in rows] == ["ok", "ok", "ok", "bad_input"]
    assert "wear.coefficient" in rows[3]["message"] and rows[3]["pin.wear_volume"] == ""
    for r in rows[:3]:
        summary = json.loads((out / r["run"] / "summary.json").read_text())
        assert float(r["pin.wear_volume"]) == summary["bodies"]["pin"]["wear_volume"]
        assert float(r["disc.wear_volume"]) == summary["surfaces"]["disc"]["wear_volume"]
        assert float(r["wall_time"]) > 0.0
    # Archard: the pin's worn volume is its coefficient times the same load and sliding
    volumes = np.array([float(r["pin.wear_volume"]) for r in rows[:3]])
    assert np.allclose(volumes / volumes[0], [1.0, 2.0, 3.0], rtol=1e-3)


def test_a_re_run_runs_only_the_unfinished(swept, scene_file, capsys):
    _, out = swept
    before = _table(out / "sweep.csv")
    stamp = (out / "run_001" / "summary.json").stat().st_mtime_ns
    code = main(["sweep", str(scene_file), "--vary", f"wear.coefficient={COEFFICIENTS}",
                 "--workers", "0", "-o", str(out)])
    assert code == 1
    printed = capsys.readouterr().out
    assert "3 of 4 runs already finished" in printed and "run_003 bad_input" in printed
    assert "run_000 ok" not in printed
    assert (out / "run_001" / "summary.json").stat().st_mtime_ns == stamp
    assert _table(out / "sweep.csv")[:3] == before[:3]


def test_in_process_runs_give_the_cluster_s_figures(swept, scene_file, tmp_path):
    _, out = swept
    sweep = from_arguments(scene_file, [f"wear.coefficient={COEFFICIENTS[:2]}"])
    rows = run_sweep(sweep, tmp_path, workers=0, report=lambda line: None)
    cluster = _table(out / "sweep.csv")
    for row, other in zip(rows, cluster):
        assert row["pin.wear_volume"] == pytest.approx(float(other["pin.wear_volume"]),
                                                       rel=1e-9)


def test_a_sweep_file_and_list_mode(scene_file, tmp_path):
    sweep_file = tmp_path / "sweep.toml"
    sweep_file.write_text(f'scene = "{scene_file}"\nmode = "list"\n[values]\n'
                          '"wear.coefficient" = [1e-13, 2e-13]\n'
                          '"body[0].force" = [[0.0, 0.0, -10.0], [0.0, 0.0, -20.0]]\n')
    sweep = from_arguments(None, (), sweep_file)
    assert sweep.runs() == [{"wear.coefficient": 1e-13, "body[0].force": [0.0, 0.0, -10.0]},
                            {"wear.coefficient": 2e-13, "body[0].force": [0.0, 0.0, -20.0]}]
    grid = from_arguments(scene_file, ["wear.coefficient=[1, 2]", "run.dt=[1e-3, 2e-3, 3e-3]"])
    assert len(grid.runs()) == 6


@pytest.mark.parametrize("vary, mode, key", [
    (["wear.coefficient=1e-13"], None, "wear.coefficient"),          # not a list
    (["wear.coefficient=[]"], None, "wear.coefficient"),
    (["a=[1, 2]", "b=[1]"], "list", "a"),                            # list lengths differ
    (["a=[1]", "a=[2]"], None, "a"),
    ([], None, ""),
])
def test_bad_sweeps_are_refused(scene_file, vary, mode, key):
    with pytest.raises(SceneError) as err:
        from_arguments(scene_file, vary, None, mode)
    assert err.value.key == key


def test_the_command_refuses_in_one_line(tmp_path, capsys):
    assert main(["sweep", str(tmp_path / "none.toml"), "--vary", "run.dt=[1e-3]",
                 "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "none.toml" in err


def test_plot_draws_a_sweep_against_its_key(swept, tmp_path):
    import matplotlib.image

    _, out = swept
    assert main(["plot", str(out), "-d", str(tmp_path)]) == 0
    image = matplotlib.image.imread(tmp_path / "sweep.png")[..., :3]
    assert image.std() > 0.05
