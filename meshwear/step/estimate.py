"""What ``meshwear check`` says a run will take (docs/outputs.md): trial
steps of the compiled loop, a trial of the outputs' writing, and for cycle
jumping a short trial of the jumping run itself.

The estimate is of the wall time ``meshwear run`` reports (``done in``,
``summary.json`` ``wall_time``): from the model built to the outputs closed.
"""

import math
import tempfile
import time
from dataclasses import dataclass

import numpy as np

from . import stepper
from ..model.build import initial_state

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
#: :func:`meshwear.longrun.jump_errors._counter_noise`)
FIRST_JUMP_MEASUREMENTS = 3
#: wall time (s) from the start of ``meshwear check`` (or of
#: :func:`estimate_run`) by which the jump trial ends at the latest (in
#: place of JUMP_TRIAL_LONGEST): a trial whose range is wider than WIDEST
#: goes on until then (the answer within 30 s, docs/performance.md:
#: the interpreter's start and imports come before, and the trial looks at
#: the clock only every output or 2 000 steps; at 24 s the CAD part's check
#: answered in 30.4 s on a busy machine)
ANSWER_SECONDS = 20.0
#: the range (high / low) a jump trial with BOUNDED_JUMPS stops at
WIDEST = 3.0
#: the confidence the range's trends of bounded jumps are taken at, either
#: side (Student's t of the trial's scatter: :func:`_trend_range`)
CONFIDENCE = 0.95


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
    low: float = 0.0
    high: float = 0.0
    cycles: tuple = ()

    @property
    def total(self):
        return self.stepping + self.writing

    @property
    def range(self):
        """``(low, high)`` s of the run's wall time: for cycle jumping, the
        jumps after the trial following the slowest and fastest trends its
        bounded jumps allow (:func:`_trend_range`); else the estimate."""
        if not self.cycles:
            return self.total, self.total
        return self.low + self.writing, self.high + self.writing


class _Budget(Exception):
    pass


def estimate_run(model, state=None, started=None):
    """The :class:`Estimate` of ``model``'s run from ``state``, a fresh one
    (made here if None; it is stepped); nothing written but temporary
    files. ``started``: the ``time.perf_counter()`` the answer's
    :data:`ANSWER_SECONDS` count from (default now)."""
    started = time.perf_counter() if started is None else started
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
        j = _jumping(model, e.stepping - load, started + ANSWER_SECONDS, per_step)
        e.stepping, e.low, e.high = load + j.seconds, load + j.low, load + j.high
        e.trial_time, e.trial_covered, e.trial_jumps = j.trial_time, j.covered, j.jumps
        e.cycles = j.cycles
    return e


def _returns(model, state):
    """Seconds the run spends, beyond its steps, leaving the compiled loop
    for each output and every few thousand steps and checking the state at
    each output (:func:`meshwear.step.simulate.advance`): :data:`RETURNS`
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
    from ..output.recorder import RunRecorder

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


def _trend_range(taken, longest):
    """``(fast, slow)``: the trends ``(a, b, c)``, jumps ``J = a (p / c)^b``
    at cycle ``p``, that bound the run's jumps after a trial that took
    ``taken`` (``longest``: its longest jump); ``fast`` None for jumps
    growing by :data:`meshwear.longrun.wear.GROWTH` alone, ``slow`` None for no jump
    at all.

    What a bound other than growth allows moves with the depth worn and the
    error it reads, as ``p^b``: b = 1 for an error allowance in proportion
    to the depth and a steady per-cycle error; less where the error grows
    with the scar (b = 0: drift or noise growing as the depth does; below:
    faster), more where it falls (running-in settles, a wider window
    averages the noise: the fretting ball's noise-held jumps went from
    5 to 45 cycles while its cycles went from 72 to 457). So ``b`` is not
    bounded by the physics, only measured: the trial's bounded jumps (three
    or more) give ``b`` and the level by least squares of ``log J`` on
    ``log p``, each within its :data:`CONFIDENCE` interval (Student's t of
    the scatter of noise-held jumps about their trend, n - 2 degrees of
    freedom: three jumps on a line tell little of its slope). With one or
    two: from growth alone to jumps held at their median. With none: from
    growth alone to jumps held at the longest the trial took."""
    from scipy.stats import t as student_t

    bounded = [(p, j) for p, j, which in taken if which not in ("growth", "end")]
    if not bounded:
        return None, ((float(longest), 0.0, 1.0) if longest >= 1 else None)
    x, y = np.log(np.array(bounded, dtype=float).T)
    sxx = float(((x - x.mean()) ** 2).sum())
    if len(x) < 3 or sxx <= 0.0:
        return None, (float(np.exp(np.median(y))), 0.0, 1.0)
    centre, level = float(x.mean()), float(y.mean())
    b = float(((x - centre) * (y - level)).sum()) / sxx
    scatter = float(np.sqrt(((y - level - b * (x - centre)) ** 2).sum() / (len(x) - 2)))
    t = float(student_t.ppf(0.5 + 0.5 * CONFIDENCE, len(x) - 2))
    spread = t * scatter / np.sqrt(len(x))           # of the level at the centre
    error = t * scatter / np.sqrt(sxx)               # of the slope
    return ((float(np.exp(level + spread)), b + error, float(np.exp(centre))),
            (float(np.exp(level - spread)), b - error, float(np.exp(centre))))


def _jump_at(trend, p):
    """``trend``'s jump (cycles) at cycle ``p``: ``a (p / c)^b``."""
    a, b, c = trend
    return a * math.exp(min(700.0, b * math.log(max(p, 1e-300) / c)))


def _cycles_left(position, total, window, settle, jump, trend):
    """Cycles the run resolves from cycle ``position`` to ``total`` by the
    controller's rule: a measurement of ``window`` cycles, then a jump
    (``GROWTH J + 1`` from the last ``jump``, up to ``trend``'s ``a p^b``,
    at least one cycle; None: growth alone, "none": no jump) that leaves
    the run's last cycle resolved, and ``settle`` cycles after it."""
    from ..longrun.jump_choice import GROWTH

    cycles = 0.0
    if trend == "none":
        return max(0.0, total - position)
    while position < total:
        cycles += min(window, total - position)     # (the run's last cycle may be cut short)
        position += window
        jump = GROWTH * jump + 1.0
        if trend is not None:
            jump = max(1.0, min(jump, _jump_at(trend, position)))
        # the run ends with a resolved cycle (the bound "end")
        taken = min(jump, math.ceil(total - position) - 1.0)
        if taken >= 1.0:
            position += taken + settle
            cycles += settle
    return cycles


@dataclass
class _Jumped:
    """What :func:`_jumping` tells: seconds of stepping (central, low,
    high), the trial, and the resolved cycles (central, low, high)."""

    seconds: float
    low: float
    high: float
    trial_time: float
    covered: int
    jumps: int
    cycles: tuple


def _resolved(js, step, n_c):
    """Cycles a trial that stopped at ``step`` resolved (``js``: its
    :class:`meshwear.longrun.wear.JumpState`): the steps of the measurement it
    stopped in count too (stopped past it, at a jump: none)."""
    partial = step - js.cycle_start
    return (js.resolved_steps + (partial if 0 < partial < js.window * n_c else 0)) / n_c


def _per_cycle(elapsed, js, step, n_c):
    """Seconds of a resolved cycle, its jump's work included, from a trial
    of ``elapsed`` s that stopped at ``step`` (``js``: its
    :class:`meshwear.longrun.wear.JumpState`): the steps of the cycle it stopped in
    count too, their time being in the trial's (not counting them made the
    gear pair's estimate 25 % high: a trial of 3 revolutions read as 2)."""
    return (elapsed - js.fill_seconds) / max(_resolved(js, step, n_c), 1.0)


def _forecast(model, state, elapsed, resolved):
    """The :class:`_Jumped` of a run whose trial took ``elapsed`` s to
    ``state`` (see :func:`_jumping`)."""
    js = state.jump
    n_c = model.cycle_steps
    done = _resolved(js, state.step, n_c)
    if state.step >= model.n_steps:
        seconds = min(resolved, elapsed)
        return _Jumped(seconds, seconds, seconds, elapsed, state.step, js.jumps,
                       (done, done, done))
    # outputs inside a jump are filled from it: their cost beyond writing
    # them goes with the outputs left, not with the cycles
    per_output = js.fill_seconds / max(js.filled_outputs, 1)
    remaining = int((model.output_steps > state.step).sum())
    per_cycle = _per_cycle(elapsed, js, state.step, n_c)
    settle = 0 if model.quasi_static else 1      # a dynamic run resolves a cycle after a jump
    position, total = state.step / n_c, model.n_steps / n_c
    window = float(js.window)
    resolved_by = js.resolved_steps / n_c
    if 0 < state.step - js.cycle_start < js.window * n_c:
        # stopped inside a measurement: the rule counts it whole from its start
        position = js.cycle_start / n_c
    waiting = soonest = 0.0
    if js.jumps == 0:
        # the measurements the noise bounds need before the first jump; the
        # controller may jump from the second (it needs one before)
        waiting = max(0, FIRST_JUMP_MEASUREMENTS - len(js.history)) * window
        soonest = max(0, 1 - len(js.history)) * window
    longest = max((j for _, j, _ in js.taken), default=0)
    fast, slow = _trend_range(js.taken, longest)
    cycles = []
    central = _bound_trend(js.taken)
    central = None if central is None else (*central, 1.0)
    for trend, wait in ((central, waiting), (fast, soonest),
                        ("none" if slow is None else slow, waiting)):
        start = min(position + wait, total)
        cycles.append(resolved_by + min(wait, total - position)
                      + _cycles_left(start, total, window, settle, float(js.last_jump), trend))
    seconds = [min(resolved, elapsed + per_output * remaining + (c - done) * per_cycle)
               for c in cycles]
    return _Jumped(seconds[0], min(seconds), max(seconds), elapsed, state.step, js.jumps,
                   (cycles[0], min(cycles), max(cycles)))


def _jumping(model, resolved, deadline=None, per_step=0.0):
    """The :class:`_Jumped` of a cycle-jumping run: the run itself tried for
    :data:`JUMP_TRIAL` s (or to its end; longer, up to
    :data:`JUMP_TRIAL_LONGEST` s, or with a ``deadline`` (a ``perf_counter``
    time) up to it less the steps it may take between two looks at the
    clock (``per_step`` s each), while it has seen fewer than :data:`BOUNDED_JUMPS`
    jumps set by a bound other than growth or its range is wider than
    :data:`WIDEST`), the rest simulated at the trial's cost per resolved
    cycle with the controller's rule: the measurements it still needs
    before a first jump (:data:`FIRST_JUMP_MEASUREMENTS`), then per jump a
    cycle to settle (the dynamic mode) and a measurement of the trial's
    window of cycles, jumps growing (``GROWTH J + 1``) up to the trend of
    the other bounds in the trial (:func:`_bound_trend`; for the range, the
    fastest and slowest trends they allow: :func:`_trend_range`); and the
    remaining outputs filled from jumps at the trial's cost per filled
    output (the writing itself is :func:`_writing`'s). Never more than
    ``resolved``."""
    from ..longrun.jumps import compile_kernels
    from .simulate import PROGRESS_STEPS, run

    if model.scene.wear.jump == "implicit":
        compile_kernels()            # as the loop's kernels are, before the timing
    state = initial_state(model)
    start = time.perf_counter()
    budget = min(JUMP_TRIAL, resolved)
    longest = JUMP_TRIAL_LONGEST
    if deadline is not None:
        # the trial sees the clock every PROGRESS_STEPS steps, output or
        # cycle at least: it may run that much past its limit (the spur
        # gears' check answered in 35 s, its steps of 5 ms on a busy machine)
        gap = min(PROGRESS_STEPS, model.cycle_steps) * per_step
        longest = max(budget, deadline - start - gap)

    def progress(step, n_steps):
        elapsed = time.perf_counter() - start
        if elapsed <= budget:
            return
        if elapsed > longest:
            raise _Budget
        js = state.jump
        bounded = 0 if js is None else sum(w not in ("growth", "end") for _, _, w in js.taken)
        if bounded >= BOUNDED_JUMPS:
            j = _forecast(model, state, elapsed, resolved)
            if j.high <= WIDEST * j.low:
                raise _Budget

    try:
        run(model, state, progress=progress)
    except _Budget:
        pass
    return _forecast(model, state, time.perf_counter() - start, resolved)
