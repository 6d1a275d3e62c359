"""What ``meshwear check`` says a run will take (docs/outputs.md): trial
steps of the compiled loop, a trial of the outputs' writing, and for cycle
jumping a short trial of the jumping run itself.

The estimate is of the wall time ``meshwear run`` reports (``done in``,
``summary.json`` ``wall_time``): from the model built to the outputs closed.
"""

import tempfile
import time
from dataclasses import dataclass

import numpy as np

from . import stepper
from .model import initial_state

#: steps timed for the per-step cost at least, and the wall time (s) after
#: which the trial stops sooner (steps of seconds: a fine worn mesh)
TRIAL_STEPS, TRIAL_SECONDS = 200, 2.0
#: the trial goes on past TRIAL_STEPS until this wall time (s), or the
#: run's end: the first steps may not be the run's (a tossed cube's 200
#: steps in flight cost a tenth of its steps on the floor, and its
#: estimate was a third short)
TRIAL_LEAST = 0.5
#: the most steps the trial takes between two looks at the clock
TRIAL_CHUNK = 256
#: wall time (s) a cycle-jumping run is tried for, and longer, up to
#: JUMP_TRIAL_LONGEST, until bounds other than growth have set BOUNDED_JUMPS
#: jumps (what the rest of the run's jumps are extrapolated from)
JUMP_TRIAL, JUMP_TRIAL_LONGEST, BOUNDED_JUMPS = 3.0, 10.0, 8
#: one-step spans of the compiled loop, and checks of the state, timed for
#: what the run's returns to Python cost beyond their steps (:func:`_returns`)
RETURNS = 20
#: measurements the controller takes before its noise bounds let a first
#: jump through (a vertex's scatter is fitted over three:
#: :func:`meshwear.wear._counter_noise`)
FIRST_JUMP_MEASUREMENTS = 3


@dataclass
class Estimate:
    """Seconds of a run: ``stepping`` (steps, jumps), ``writing`` (frames,
    history rows, the series' set-up), their ``total``; the cost of a step
    and what it covers; the seconds of loading the kernels (the first step)
    and of the returns from the compiled loop, both in ``stepping``; for
    cycle jumping the trial's length and the steps it covered."""

    stepping: float
    writing: float
    per_step: float
    points: int
    active: int
    vertices: int
    trial_time: float = 0.0
    trial_covered: int = 0
    trial_jumps: int = 0
    load: float = 0.0
    returns: float = 0.0

    @property
    def total(self):
        return self.stepping + self.writing


class _Budget(Exception):
    pass


def estimate_run(model, state=None):
    """The :class:`Estimate` of ``model``'s run from ``state``, a fresh one
    (made here if None; it is stepped); nothing written but temporary
    files."""
    state = initial_state(model) if state is None else state
    # compile (or load the cached) kernels, as the run does, and take the
    # steps in which the dynamics try their active sets (a mechanism's first
    # 200: refreshes every few steps where they do not pay), untimed per step
    warm = min(model.n_steps - 1, model.dynamics.warm_steps) if model.n_steps > 1 else 0
    start = time.perf_counter()
    stepper.advance(model, state, warm)
    load = time.perf_counter() - start
    # (leaving the steps the returns to Python are timed on, where the run
    # has them past its first TRIAL_STEPS)
    trial = model.n_steps - warm
    if trial - 2 * RETURNS >= TRIAL_STEPS:
        trial -= 2 * RETURNS
    done, chunk = 0, 1
    start = time.perf_counter()
    while done < trial:             # in doubling chunks, until TRIAL_SECONDS
        chunk = min(chunk, trial - done)
        stepper.advance(model, state, warm + done + chunk)
        done += chunk
        # (no more than TRIAL_CHUNK at a time: steps that turn dear, a
        # body landing, are not taken by the thousand past the budget)
        chunk = min(2 * chunk, TRIAL_CHUNK)
        elapsed = time.perf_counter() - start
        if elapsed > TRIAL_SECONDS or (done >= TRIAL_STEPS and elapsed >= TRIAL_LEAST):
            break
    per_step = max(time.perf_counter() - start, 1e-9) / max(done, 1)
    active = sum(len(s.active) for s in state.bodies)
    vertices = sum(len(b.tributary_area) for b in model.bodies)
    writing = _writing(model, state)
    returns = _returns(model, state)
    e = Estimate(stepping=load + per_step * (model.n_steps - warm) + returns, writing=writing,
                 per_step=per_step, points=active * max(1, model.slots), active=active,
                 vertices=vertices, load=load, returns=returns)
    if model.cycle_steps:
        e.stepping, e.trial_time, e.trial_covered, e.trial_jumps = _jumping(
            model, e.stepping - load)
        e.stepping += load
    return e


def _returns(model, state):
    """Seconds the run spends, beyond its steps, leaving the compiled loop
    for each output and every few thousand steps and checking the state at
    each output (:func:`meshwear.simulate.advance`): :data:`RETURNS`
    one-step spans timed against as many steps in one span just before them
    (not against the trial's mean step, which a run whose steps turn
    dearer, a body landing, would have booked as returns), and as many
    checks. A validation case writing a history row every step spent as
    long there as on its steps and rows (its estimate was half its run)."""
    from .simulate import PROGRESS_STEPS, check

    normals = [b.reference_face_normals for b in model.bodies]
    if state.step + 2 * RETURNS > model.n_steps:
        # the trial took the run's steps: a fresh state, as many spans as
        # its steps allow (a validation case of 16 steps returns at each)
        state = initial_state(model)
    spans = min(RETURNS, (model.n_steps - state.step) // 2)
    each = 0.0
    if spans > 0:
        start = time.perf_counter()
        stepper.advance(model, state, state.step + spans)
        spanned = time.perf_counter() - start
        start = time.perf_counter()
        for _ in range(spans):
            stepper.advance(model, state, state.step + 1)
        each = max(0.0, (time.perf_counter() - start - spanned) / spans)
    start = time.perf_counter()
    for _ in range(RETURNS):
        check(model, state, normals)
    checked = (time.perf_counter() - start) / RETURNS
    outputs = len(model.output_steps)
    return each * (outputs + model.n_steps // PROGRESS_STEPS) + checked * outputs


def _writing(model, state):
    """Seconds to set up the outputs and write every frame and history row
    of ``model``: the first of each timed (the writers' imports and set-up,
    which the run pays too), then one of each again."""
    from .output.recorder import RunRecorder

    frames, samples = len(model.frame_steps), len(model.sample_steps)
    with tempfile.TemporaryDirectory() as out:
        start = time.perf_counter()
        recorder = RunRecorder(out, model, check_space=False)  # a temporary folder
        # (a run without frames writes none: a validation case's one frame
        # of a 52 000-vertex ball, 0.13 s, made its 0.22 s run's estimate
        # half as long again)
        if frames:
            recorder.on_frame(model, state)
        if samples:
            recorder.on_sample(model, state)
        first = time.perf_counter() - start
        start = time.perf_counter()
        if frames > 1:
            recorder.on_frame(model, state)
        frame = time.perf_counter() - start
        start = time.perf_counter()
        if samples > 1:
            recorder.on_sample(model, state)
        sample = time.perf_counter() - start
        recorder.finish()
    return first + frame * max(0, frames - 1) + sample * max(0, samples - 1)


def _bound_trend(taken):
    """``(a, b)``: the jumps a bound other than growth set in the trial, as
    ``J = a p^b`` at cycle ``p``. The error such bounds allow is a fraction
    of the depth worn so far, which grows with the cycles run, so their
    jumps grow in proportion (b = 1, ``a`` the median of J / p) unless the
    trial's own jumps span a decade of cycles: then b is fitted (least
    squares of log J on log p, within 0..1). None if no such bound held a
    jump."""
    bounded = [(p, j) for p, j, which in taken if which not in ("growth", "end")]
    if not bounded:
        return None
    p, j = np.log(np.array(bounded, dtype=float).T)
    b = 1.0
    if np.ptp(p) >= np.log(10.0):
        b = float(np.clip(np.polyfit(p, j, 1)[0], 0.0, 1.0))
    return float(np.exp(np.median(j - b * p))), b


def _per_cycle(elapsed, js, step, n_c):
    """Seconds of a resolved cycle, its jump's work included, from a trial
    of ``elapsed`` s that stopped at ``step`` (``js``: its
    :class:`meshwear.wear.JumpState`): the steps of the cycle it stopped in
    count too, their time being in the trial's (not counting them made the
    gear pair's estimate 25 % high: a trial of 3 revolutions read as 2)."""
    steps = js.resolved_steps + max(0, step - js.cycle_start)
    return (elapsed - js.fill_seconds) / max(steps / n_c, 1.0)


def _jumping(model, resolved):
    """``(seconds, trial seconds, steps covered by the trial, jumps in the
    trial)`` of a cycle-jumping run: the run itself tried for
    :data:`JUMP_TRIAL` s (or to its end; longer while it has seen fewer than
    :data:`BOUNDED_JUMPS` jumps set by a bound other than growth), the rest
    simulated at the trial's cost per resolved cycle with the controller's
    rule: the measurements it still needs before a first jump
    (:data:`FIRST_JUMP_MEASUREMENTS`), then per jump a cycle to settle (the
    dynamic mode) and a measurement of the trial's window of cycles, jumps
    growing (``GROWTH J + 1``) up to the trend of the other bounds in the
    trial (:func:`_bound_trend`); and the remaining outputs filled from jumps
    at the trial's cost per filled output (the writing itself is
    :func:`_writing`'s). Never more than ``resolved``."""
    from .jumps import compile_kernels
    from .simulate import run
    from .wear import GROWTH

    if model.scene.wear.jump == "implicit":
        compile_kernels()            # as the loop's kernels are, before the timing
    state = initial_state(model)
    start = time.perf_counter()
    budget = min(JUMP_TRIAL, resolved)

    def progress(step, n_steps):
        elapsed = time.perf_counter() - start
        js = state.jump
        bounded = 0 if js is None else sum(w not in ("growth", "end") for _, _, w in js.taken)
        if elapsed > budget and (bounded >= BOUNDED_JUMPS or elapsed > JUMP_TRIAL_LONGEST):
            raise _Budget

    try:
        run(model, state, progress=progress)
    except _Budget:
        pass
    elapsed = time.perf_counter() - start
    if state.step >= model.n_steps:
        return (min(resolved, elapsed), elapsed, state.step,
                state.jump.jumps if state.jump else 0)
    n_c = model.cycle_steps
    js = state.jump
    # outputs inside a jump are filled from it: their cost beyond writing
    # them goes with the outputs left, not with the cycles
    per_output = js.fill_seconds / max(js.filled_outputs, 1)
    remaining = int((model.output_steps > state.step).sum())
    per_cycle = _per_cycle(elapsed, js, state.step, n_c)
    settle = 0 if model.quasi_static else 1      # a dynamic run resolves a cycle after a jump
    position, total = state.step / n_c, model.n_steps / n_c
    bound = _bound_trend(js.taken)
    jump = float(js.last_jump)
    window = float(js.window)
    seconds = elapsed + per_output * remaining
    if js.jumps == 0:
        # the measurements the noise bounds need before the first jump
        waiting = max(0, FIRST_JUMP_MEASUREMENTS - len(js.history)) * window
        position += waiting
        seconds += waiting * per_cycle
    while position < total and seconds < resolved:
        position += window
        seconds += window * per_cycle
        jump = GROWTH * jump + 1.0
        if bound is not None:
            jump = max(1.0, min(jump, bound[0] * position ** bound[1]))
        if position < total:
            position += jump + settle
            seconds += settle * per_cycle
    return min(resolved, seconds), elapsed, state.step, js.jumps
