"""``meshwear check``'s range for a cycle-jumping run (docs/performance.md,
"How close `meshwear check`'s estimate comes"): the controller's rule
simulated over the cycles left, from the fastest to the slowest trend of
the trial's bounded jumps, holds the run's resolved cycles."""

import dataclasses
import math
import re

import numpy as np
import pytest

import cases
from meshwear.step import estimate
from meshwear.cli import main
from meshwear.step.estimate import _cycles_left, _forecast, _jump_at, _trend_range
from meshwear.model.build import build_model, initial_state
from meshwear.scene.reader import load_scene
from meshwear.step.simulate import run
from meshwear.longrun.jump_choice import GROWTH


# ---------------------------------------------------------------- the rule, in closed form

@pytest.mark.parametrize("total", [1.0, 5.0, 100.0, 1000.0, 12345.0])
def test_jumps_growing_alone_resolve_a_cycle_per_doubling(total):
    # jumps 1, 3, 7, ... (GROWTH J + 1 from 0) after one cycle each: the
    # k-th measurement ends at cycle 2^k - 1, and the jump that would pass
    # the end stops a cycle short of it, which is resolved (the bound "end"):
    # ceil(log2(total + 1)) measurements in all
    assert GROWTH == 2.0
    expected = math.ceil(math.log2(total + 1.0))
    assert _cycles_left(0.0, total, 1.0, 0, 0.0, None) == expected


@pytest.mark.parametrize("window, settle, jump", [(1.0, 0, 40.0), (2.0, 1, 40.0), (1.0, 1, 7.0)])
def test_jumps_held_at_a_level_resolve_a_window_and_a_settling_per_jump(window, settle, jump):
    # b = 0: every jump is the level once growth has reached it (from the
    # level itself here): measurements of ``window`` cycles, ``jump + settle``
    # cycles apart, and the settling cycles resolved as well; the last jump
    # stops short of the end, whose cycle is resolved too
    total = 10_000.0
    measurements = math.ceil(total / (window + jump + settle))
    cycles = _cycles_left(0.0, total, window, settle, jump, (jump, 0.0, 1.0))
    assert measurements * window + (measurements - 1) * settle <= cycles
    assert cycles <= (measurements + 1) * (window + settle)


def test_no_jump_at_all_resolves_every_cycle_left():
    assert _cycles_left(123.0, 1000.0, 1.0, 0, 5.0, "none") == 877.0


def test_a_trend_without_scatter_is_its_own_range():
    a, b = 0.3, 0.6
    taken = [(p, a * p ** b, "noise") for p in (10.0, 30.0, 100.0, 300.0)] + [(5.0, 3, "growth")]
    fast, slow = _trend_range(taken, 60)
    for p in (1.0, 50.0, 1e4, 1e6):
        assert _jump_at(fast, p) == pytest.approx(a * p ** b)
        assert _jump_at(slow, p) == pytest.approx(a * p ** b)


def test_a_scattered_trend_spans_its_slope_either_side():
    rng = np.random.default_rng(1)
    p = np.geomspace(10.0, 1000.0, 12)
    taken = [(x, 0.5 * x ** 0.5 * math.exp(rng.normal(0.0, 0.4)), "noise") for x in p]
    fast, slow = _trend_range(taken, 100)
    assert slow[1] < 0.5 < fast[1]
    # beyond the trial the fast trend allows the longer jumps
    assert _jump_at(fast, 1e4) > 0.5 * 1e4 ** 0.5 > _jump_at(slow, 1e4)


def test_few_bounded_jumps_range_from_growth_alone_to_jumps_held():
    assert _trend_range([(1.0, 1, "growth"), (3.0, 3, "growth")], 3) == (None, (3.0, 0.0, 1.0))
    assert _trend_range([], 0) == (None, None)
    fast, slow = _trend_range([(10.0, 4, "noise"), (20.0, 9, "drift"), (30.0, 19, "growth")], 19)
    assert fast is None and _jump_at(slow, 1e5) == pytest.approx(6.0)


# ---------------------------------------------------------------- against a run

class _Stop(Exception):
    pass


@pytest.fixture(scope="module")
def ball():
    """The fretting ball of the validation cases, 600 cycles of 0.1 s with
    cycle jumping: a model, and the run's resolved cycles."""
    scene = load_scene(cases.VALIDATION / "sphere_pin.toml")
    scene = dataclasses.replace(scene, wear=dataclasses.replace(
        scene.wear, acceleration="cycle_jump", period=0.1, tolerance=0.01))
    scene = dataclasses.replace(scene, run=dataclasses.replace(scene.run, duration=60.0,
                                                                 frames=0, history=3))
    model = build_model(scene)
    state = initial_state(model)
    run(model, state)
    return model, state.jump.resolved_steps / model.cycle_steps


@pytest.mark.parametrize("bounded", [3, 5, pytest.param(7, marks=pytest.mark.xfail(
    strict=True, reason="a known miss: the trial's bounded jumps (5-10 cycles to cycle 135) "
    "do not show the growth-held 21, 43, 57 and 115 that follow: its range starts above the "
    "run's 150 cycles"))])
def test_the_range_of_resolved_cycles_holds_the_run_s(ball, bounded):
    """A trial stopped once ``bounded`` jumps were set by a bound other than
    growth (not on the clock: the cycles resolved do not depend on the
    machine), forecast: the run's resolved cycles lie in its range, the
    central figure within it, the range under 3x wide."""
    model, resolved = ball
    state = initial_state(model)

    def stop(model, state):
        if sum(w not in ("growth", "end") for _, _, w in state.jump.taken) >= bounded:
            raise _Stop

    with pytest.raises(_Stop):
        run(model, state, checkpoint=stop)
    assert state.step < model.n_steps
    j = _forecast(model, state, 1.0, math.inf)
    central, few, many = j.cycles
    assert few <= central <= many and j.low <= j.seconds <= j.high
    assert few <= resolved <= many, (j.cycles, resolved)
    assert many <= 3.0 * few


def test_check_prints_the_range_of_a_jumping_run(capsys, monkeypatch):
    """The line is printed after the estimate's, ordered, with the estimate
    inside (a trial cut short, so that it does not take the whole run)."""
    monkeypatch.setattr(estimate, "JUMP_TRIAL", 0.05)
    monkeypatch.setattr(estimate, "ANSWER_SECONDS", 0.0)
    monkeypatch.setattr(estimate, "JUMP_TRIAL_LONGEST", 0.05)
    scene = cases.EXAMPLES / "long" / "sphere_fretting_1e5.toml"
    assert main(["check", str(scene)]) == 0
    out = capsys.readouterr().out
    total = float(re.search(r"estimated run time .*?(\S+) s: stepping", out)[1])
    found = re.search(r"run time range with cycle jumping (\S+)–(\S+) s \((\S+)x\), "
                      r"(\S+)–(\S+) of 100000 cycles resolved \(estimate (\S+)\)", out)
    assert found, out
    low, high, few, many, cycles = (float(found[i]) for i in (1, 2, 4, 5, 6))
    assert low <= total * 1.001 and total <= high * 1.001 and few <= cycles <= many


# ---------------------------------------------------------------- meshes of different spacing

def test_check_gives_notice_of_a_pad_twice_as_coarse_as_its_worn_flat(tmp_path, capsys):
    """The fretting pad refined to 20 µm on its flat at 10 µm (docs/model.md,
    "Worn counter-surfaces": stripes 84 % of the depth): a notice naming
    both; at 10 µm on 10 µm none."""
    text = (cases.EXAMPLES / "cylinder_on_flat_fretting.toml").read_text()
    coarse = text.replace("resolution = 1e-5\n", "resolution = 2e-5\n", 1)
    assert coarse != text
    short = ["--set", "run.duration=2.0", "--set", "wear.acceleration=\"none\""]
    for scene_text, noticed in ((coarse, True), (text, False)):
        scene = tmp_path / "scene.toml"
        scene.write_text(scene_text)
        assert main(["check", str(scene), *short]) == 0
        out = capsys.readouterr().out
        notices = [line for line in out.splitlines() if line.startswith("  notice: ")]
        assert len(notices) == int(noticed), out
        if noticed:
            assert "body 'cylinder'" in notices[0] and "mesh surface 'flat'" in notices[0]
            assert "in tracks a body vertex apart" in notices[0]
            ratio = float(re.search(r"differ (\S+):1", notices[0])[1])
            assert 1.8 <= ratio <= 3.0
