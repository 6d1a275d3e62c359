"""``run.dt = "auto"``, the default (docs/scene-format.md): a minimal dynamic
scene runs at its largest stable step, a quasi-static one resolves its cycle
into 200 steps, cycle jumping rounds the step down to whole steps per cycle
(never above the stable limit), and an explicit dt above the limit is
refused with the limit in full."""

import json

import numpy as np
import pytest

from meshwear.cli import main
from meshwear.model.build import build_model, check_time_step
from meshwear.model.timestep import AUTO_STEPS_PER_CYCLE, AUTO_STEPS_PER_RUN, stable_time_step
from meshwear.scene.checks import SceneError
from meshwear.scene.reader import load_scene

# the minimal scene: a steel block dropped on a floor, nothing but
# what it needs (stiffness 1e9 N/m per vertex: the default 1e-5 s was unstable)
MINIMAL = """format = 1

[run]
duration = {duration}

[contact]
stiffness = 1e9

[[body]]
name = "block"
shape = {{ type = "box", size = [0.01, 0.01, 0.005] }}
position = [0.0, 0.0, 0.0025]

[[surface]]
name = "floor"
"""

# a pin driven round a track, quasi-static
PIN = """format = 1

[run]
mode = "{mode}"
duration = 3.0

[contact]
stiffness_per_area = 1e12
damping_per_area = 1e5

[wear]
law = "archard"
coefficient = 1e-13
{wear}

[[body]]
name = "pin"
shape = {{ type = "cylinder", radius = 0.003, height = 0.01, sections = 12 }}
position = [0.0, 0.0, 0.005]
force = [0.0, 0.0, -10.0]
motion = "guided"

[body.path]
circle = {{ radius = 0.01, frequency = 1.7 }}
free_axis = [0.0, 0.0, 1.0]

[[surface]]
name = "disc"
"""


def write(tmp_path, text):
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return path


def test_a_minimal_dynamic_scene_runs_at_its_stable_step(tmp_path, capsys):
    path = write(tmp_path, MINIMAL.format(duration=0.002))
    model = build_model(load_scene(path))
    limit, who = stable_time_step(model)
    assert who == "block" and np.isfinite(limit)
    assert model.dt <= limit and model.dt > 0.999 * limit  # whole steps: a hair below
    assert model.n_steps * model.dt == pytest.approx(0.002, rel=1e-12)
    out = tmp_path / "out"
    assert main(["run", str(path), "-o", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "ok" and summary["dt"] == pytest.approx(model.dt, rel=1e-12)
    assert "is above the stability limit" not in capsys.readouterr().err


def test_a_long_run_is_resolved_into_at_least_the_run_s_share(tmp_path):
    # a soft contact's stable step is long: the run still gets its 1000 steps
    text = MINIMAL.format(duration=0.5).replace("stiffness = 1e9", "stiffness = 10.0\ndamping = 0.0")
    model = build_model(load_scene(write(tmp_path, text)))
    assert stable_time_step(model)[0] > 0.5 / AUTO_STEPS_PER_RUN
    assert model.n_steps == AUTO_STEPS_PER_RUN


def test_quasi_static_auto_resolves_the_cycle(tmp_path):
    model = build_model(load_scene(write(tmp_path, PIN.format(mode="quasi-static", wear=""))))
    assert model.dt * AUTO_STEPS_PER_CYCLE <= 1 / 1.7 * (1 + 1e-12)
    assert model.n_steps == int(np.ceil(3.0 * 1.7 * AUTO_STEPS_PER_CYCLE - 1e-9))


def test_cycle_jumping_rounds_the_step_down_to_whole_steps_per_cycle(tmp_path):
    jump = 'acceleration = "cycle_jump"'
    model = build_model(load_scene(write(tmp_path, PIN.format(mode="dynamic", wear=jump))))
    limit = stable_time_step(model)[0]
    assert model.cycle_steps * model.dt == pytest.approx(1 / 1.7, rel=1e-12)
    assert model.dt <= limit
    assert model.cycle_steps == max(AUTO_STEPS_PER_CYCLE, int(np.ceil(1 / 1.7 / limit)))
    # an explicit dt a hair below the limit is not rounded above it either
    path = write(tmp_path, PIN.format(mode="dynamic", wear=jump).replace(
        "duration = 3.0", f"duration = 3.0\ndt = {float(0.9999 * limit)!r}"))
    model = build_model(load_scene(path))
    assert model.dt <= limit
    check_time_step(model)


def test_an_explicit_step_above_the_limit_is_refused_with_the_limit(tmp_path):
    limit = stable_time_step(build_model(load_scene(write(tmp_path, MINIMAL.format(
        duration=0.01)))))[0]
    path = write(tmp_path, MINIMAL.format(duration=0.01).replace(
        "[run]", f"[run]\ndt = {float(1.02 * limit)!r}"))
    with pytest.raises(SceneError, match=r"run\.dt.*largest stable dt is") as err:
        check_time_step(build_model(load_scene(path)))
    shown = float(str(err.value).rsplit(" is ", 1)[1].split()[0])
    assert shown == pytest.approx(limit, rel=1e-5)  # not rounded to the refused value


def test_check_s_estimate_counts_the_outputs_and_caps_jumps_at_resolved(tmp_path):
    from meshwear.step.estimate import estimate_run

    few = build_model(load_scene(write(tmp_path, PIN.format(mode="quasi-static", wear="")),
                                 [("run.frames", 2), ("run.history", 2)]))
    many = build_model(load_scene(write(tmp_path, PIN.format(mode="quasi-static", wear="")),
                                  [("run.frames", 400), ("run.history", 400)]))
    a, b = estimate_run(few), estimate_run(many)
    assert a.total == a.stepping + a.writing and a.writing > 0
    assert b.writing > 2 * a.writing  # 200 times the outputs cost more
    jumped = build_model(load_scene(write(tmp_path, PIN.format(
        mode="quasi-static", wear='acceleration = "cycle_jump"').replace(
        "duration = 3.0", "duration = 300.0"))))
    e = estimate_run(jumped)
    # (no more than stepping every step: the loading and returns aside)
    assert 0 < e.stepping <= e.per_step * jumped.n_steps + e.load + e.returns
    assert e.trial_covered > 0


def test_check_s_estimate_counts_a_return_to_python_per_output(tmp_path, monkeypatch):
    """The run leaves the compiled loop at each output and every
    PROGRESS_STEPS steps, and checks the state at each output; ``check``
    times both: with the spans free and the check taking 2 ms, 2 ms per
    output, none for the returns every PROGRESS_STEPS steps (a validation
    case writing a row every step had half its run estimated)."""
    import time

    from meshwear.step import estimate, simulate
    from meshwear.model.build import initial_state

    model = build_model(load_scene(write(tmp_path, PIN.format(mode="quasi-static", wear="")),
                                   [("run.frames", 3), ("run.history", 50)]))
    state = initial_state(model)
    monkeypatch.setattr(estimate.stepper, "advance",
                        lambda m, s, until: setattr(s, "step", until))
    took = []

    def check(*args):
        start = time.perf_counter()
        time.sleep(2e-3)
        took.append(time.perf_counter() - start)

    monkeypatch.setattr(simulate, "check", check)
    assert len(model.output_steps) >= 50
    # (the check's own time as measured: a sleep of 2 ms takes longer on a
    # busy machine)
    assert estimate._returns(model, state) == pytest.approx(
        np.mean(took) * len(model.output_steps), rel=0.3)


def test_check_writes_no_trial_frame_for_a_run_without_frames(tmp_path, monkeypatch):
    """A run with ``frames = 0`` writes no frame: the writing's trial writes
    none either (one frame of a 52 000-vertex ball, 0.13 s, made a 0.3 s
    validation case's estimate half as long again); history rows are
    written and timed as before."""
    from meshwear.step import estimate
    from meshwear.model.build import initial_state
    from meshwear.output.recorder import RunRecorder

    written = []
    monkeypatch.setattr(RunRecorder, "on_frame", lambda *a: written.append("frame"))
    monkeypatch.setattr(RunRecorder, "on_sample", lambda *a: written.append("row"))
    for frames, rows in ((0, 5), (3, 2)):
        model = build_model(load_scene(write(tmp_path, PIN.format(mode="quasi-static", wear="")),
                                       [("run.frames", frames), ("run.history", rows)]))
        assert len(model.frame_steps) == frames and len(model.sample_steps) == rows
        written.clear()
        estimate._writing(model, initial_state(model))
        assert written.count("frame") == min(frames, 2) and written.count("row") == min(rows, 2)


def test_a_jump_trial_stopped_inside_a_cycle_counts_its_steps():
    """The cost of a resolved cycle from ``meshwear check``'s jumping trial:
    a trial that stopped half-way through its third resolved cycle resolved
    2.5 cycles, not 2; the outputs filled from jumps are costed apart."""
    from meshwear.step.estimate import _per_cycle
    from meshwear.longrun.wear import JumpState

    n_c = 100
    js = JumpState(resolved_steps=2 * n_c, cycle_start=3 * n_c, fill_seconds=1.0)
    assert _per_cycle(11.0, js, 3 * n_c + n_c // 2, n_c) == pytest.approx(10.0 / 2.5)
    assert _per_cycle(11.0, js, 3 * n_c, n_c) == pytest.approx(10.0 / 2.0)   # at a cycle's start
    assert _per_cycle(3.0, JumpState(cycle_start=0), n_c // 4, n_c) == 3.0   # less than one: one
