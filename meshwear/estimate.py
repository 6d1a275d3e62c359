"""What ``meshwear check`` says a run will take (docs/outputs.md): trial
steps of the compiled loop, a trial of the outputs' writing, and for cycle
jumping a short trial of the jumping run itself.

The estimate is of the wall time ``meshwear run`` reports (``done in``,
``summary.json`` ``wall_time``): from the model built to the outputs closed.
"""

import tempfile
import time
from dataclasses import dataclass

from . import stepper
from .model import initial_state

#: steps timed for the per-step cost
TRIAL_STEPS = 200
#: wall time (s) a cycle-jumping run is tried for
JUMP_TRIAL = 3.0


@dataclass
class Estimate:
    """Seconds of a run: ``stepping`` (steps, jumps), ``writing`` (frames,
    history rows, the series' set-up), their ``total``; the cost of a step
    and what it covers; for cycle jumping the trial's length and the steps
    it covered."""

    stepping: float
    writing: float
    per_step: float
    points: int
    active: int
    vertices: int
    trial_time: float = 0.0
    trial_covered: int = 0

    @property
    def total(self):
        return self.stepping + self.writing


class _Budget(Exception):
    pass


def estimate_run(model):
    """The :class:`Estimate` of ``model``'s run (a fresh state; nothing
    written but temporary files)."""
    state = initial_state(model)
    warm = 1 if model.n_steps > 1 else 0
    stepper.advance(model, state, warm)  # compile (or load the cached) kernels
    trial = min(model.n_steps - warm, TRIAL_STEPS)
    start = time.perf_counter()
    stepper.advance(model, state, warm + trial)
    per_step = max(time.perf_counter() - start, 1e-9) / max(trial, 1)
    active = sum(len(s.active) for s in state.bodies)
    vertices = sum(len(b.tributary_area) for b in model.bodies)
    writing = _writing(model, state)
    e = Estimate(stepping=per_step * model.n_steps, writing=writing, per_step=per_step,
                 points=active * max(1, model.slots), active=active, vertices=vertices)
    if model.cycle_steps:
        e.stepping, e.trial_time, e.trial_covered = _jumping(model, e.stepping)
    return e


def _writing(model, state):
    """Seconds to set up the outputs and write every frame and history row
    of ``model`` (one of each timed, after one to warm up)."""
    from .output.recorder import RunRecorder

    with tempfile.TemporaryDirectory() as out:
        start = time.perf_counter()
        recorder = RunRecorder(out, model)
        setup = time.perf_counter() - start
        recorder.on_frame(model, state)
        recorder.on_sample(model, state)
        start = time.perf_counter()
        recorder.on_frame(model, state)
        frame = time.perf_counter() - start
        start = time.perf_counter()
        recorder.on_sample(model, state)
        sample = time.perf_counter() - start
        recorder.finish()
    return setup + frame * len(model.frame_steps) + sample * len(model.sample_steps)


def _jumping(model, resolved):
    """``(seconds, trial seconds, steps covered by the trial)`` of a
    cycle-jumping run: the run itself tried for :data:`JUMP_TRIAL` s (or to
    its end), the rest simulated at the trial's cost per resolved cycle with
    the controller's rule: jumps go on growing (``GROWTH J + 1``) if growth
    bounded the trial's last one, else stay as long; and the remaining outputs
    filled from jumps at the trial's cost per filled output (the writing
    itself is :func:`_writing`'s). Never more than ``resolved``."""
    from .simulate import run
    from .wear import GROWTH

    state = initial_state(model)
    start = time.perf_counter()
    budget = min(JUMP_TRIAL, resolved)

    def progress(step, n_steps):
        if time.perf_counter() - start > budget:
            raise _Budget

    try:
        run(model, state, progress=progress)
    except _Budget:
        pass
    elapsed = time.perf_counter() - start
    if state.step >= model.n_steps:
        return elapsed, elapsed, state.step
    n_c = model.cycle_steps
    js = state.jump
    # outputs inside a jump are filled from it: their cost beyond writing
    # them goes with the outputs left, not with the cycles
    per_output = js.fill_seconds / max(js.filled_outputs, 1)
    remaining = int((model.output_steps > state.step).sum())
    # a resolved cycle, its jump's work included
    per_cycle = (elapsed - js.fill_seconds) / max(js.resolved_steps / n_c, 1.0)
    settle = 0 if model.quasi_static else 1      # a dynamic run resolves a cycle after a jump
    growing = js.last_limit in (None, "growth")
    position, total = state.step / n_c, model.n_steps / n_c
    jump, seconds = float(js.last_jump), elapsed + per_output * remaining
    while position < total and seconds < resolved:
        position += 1.0
        seconds += per_cycle
        jump = GROWTH * jump + 1.0 if growing else max(1.0, jump)
        if position < total:
            position += jump + settle
            seconds += settle * per_cycle
    return min(resolved, seconds), elapsed, state.step
