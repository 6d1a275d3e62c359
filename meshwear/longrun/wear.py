"""Long durations: cycle jumping with error control (docs/model.md, "Long durations").

Resolve one cycle of the motion with the ordinary step, measure each
vertex's wear in that cycle, extrapolate it over ``J`` cycles, then resolve
again. The extrapolation (``wear.jump``) is

implicit (default)
    a backward-Euler step in which each vertex's pressure is relieved by its
    own wear and a guided body's load re-balanced (:mod:`meshwear.longrun.jumps`):
    stable for any ``J``. ``J`` is the largest one whose error, estimated by
    step doubling (one jump of ``J`` against two of ``J / 2``), stays under
    ``tolerance`` times the depth the jump adds where wear is fastest, and
    whose drift and noise of the wear per unit penetration between resolved
    cycles leave errors of depth (each vertex's relaxed by the contact
    since) within ``tolerance`` of the depth; a body carrying a load along
    its axis keeps the volume its measurements give
    (:func:`meshwear.longrun.jump_volume._keep_volume`);
explicit
    the cycle's wear times ``J``, ``J`` bounded by the slope criterion (the
    change of each vertex's wear rate between the last two resolved cycles,
    ``rho`` per cycle, makes the extrapolation wrong by about ``rho J^2 / 2``)
    and for stability (no vertex may wear by more than a fraction
    :data:`~meshwear.longrun.jump_choice.THETA` of its elastic penetration in
    one jump: past that the extrapolated wear opens a gap where the contact
    carried load, and the worn profile oscillates from jump to jump while
    the worn volume looks right).

A worn counter-part (docs/model.md, "Worn counter-surfaces") jumps with
the bodies: its wear in the resolved cycle relieves the body vertices over it
in the implicit step (:func:`meshwear.longrun.jumps.counter_relief`), and its own
wear over the ``J`` cycles is relieved as theirs is (the same contact wears
both: :func:`meshwear.longrun.jumps.counter_factors`; a vertex that relaxes faster on
its own, by its stiffness summed in the wear kernel, jumps at the rate it
settles to, :func:`meshwear.longrun.jumps.settled_rates`, its departure from it
relaxing over the jump on its own), ``J`` bounded by the
bodies' implicit step, by the sampling noise of the counter's wear per cycle and by
a fraction of its mesh spacing
(:data:`meshwear.kernels.counter_wear.SPACING_FRACTION`) per jump.

Either way ``J`` grows by at most a factor :data:`GROWTH` from one jump to
the next, the errors of all jumps add up to at most ``tolerance`` times the
deepest wear (the summary's ``error_estimate``), and the run ends with a
resolved cycle. Outputs falling inside a jumped span are filled from the jump
(:mod:`meshwear.output.filled`), so they cost no resolved cycle. In the
dynamic mode the cycle after a jump only lets the contact settle and the
next one is measured.

This module holds the controller (:func:`run_cycle_jump`, one pass of its
loop per measurement) and its memory (:class:`JumpState`); choosing ``J`` is
:mod:`meshwear.longrun.jump_choice`, the errors it keeps and the run's
:func:`error_estimate` :mod:`meshwear.longrun.jump_errors`, the volume a
load-carrying body's jump wears :mod:`meshwear.longrun.jump_volume`, and
taking the jump :mod:`meshwear.longrun.extrapolate`.
"""

import time
from dataclasses import dataclass, field

import numpy as np

from . import jump_geometry, jumps
from ..output import filled
from .extrapolate import _jump, _jump_parts, _progress
from .jump_choice import GROWTH, _choose_implicit, _part_limit, choose_jump, penetration
from .jump_errors import (_counter_noise, _relax_resolved, _relaxation, _slope_error,
                          error_estimate)
from .jump_volume import _keep_volume

#: most consecutive resolved cycles one measurement averages its rates over
MAX_WINDOW = 8
#: the bounds that read sampling noise: when one holds the jumps under twice
#: the cycles a measurement resolves, the measurements average over twice as many
NOISY = ("noise", "counter noise")
#: the bounds that keep the errors so far within the tolerance: a cycle they
#: refuse lets the contact relax them, and the jumps after it grow from the
#: last one taken, not from one again
BUDGET = ("drift", "noise", "counter noise")
#: the refusals after which the jumps grow on from the last one taken: the
#: budget's, and the volume's (the implicit step misses the measured volume
#: at every length down to one cycle: what was measured is the transient a
#: long jump leaves, penetrations still settling, and the next cycle is not)
RESUME = BUDGET + ("volume",)
#: measurements (this one included) a vertex's drift and noise are fitted over
HISTORY = 8


@dataclass
class JumpState:
    """The controller's memory, saved with checkpoints.

    The outputs, a stage below the long run, read its error through
    :meth:`error_estimate` and import nothing of this module."""

    rate: list = field(default_factory=list)       # per body (n,) wear per cycle, last measured
    gap: float = 0.0                                # cycles between the last two measurements
    last_jump: int = 0
    jumps: int = 0
    resolved_steps: int = 0
    error: list = field(default_factory=list)      # per body (n,) estimated error of w (m):
                                                    # step doubling's (explicit: the slope
                                                    # criterion's), as the contact has
                                                    # relaxed it since
    drift: list = field(default_factory=list)      # per body (n,) the drift's error of w (m),
                                                    # relaxed alike
    settling: bool = False                          # dynamic: the next cycle only settles
    alpha: list = field(default_factory=list)      # per body (n,) implicit: wear per cycle per
                                                    # unit penetration, last measured (0: none)
    limits: dict = field(default_factory=lambda: {"accuracy": 0, "growth": 0, "end": 0})
    part_rate: list = field(default_factory=list)  # per worn counter-part (V,) wear per
                                                    # cycle, last measured (or None)
    part_error: list = field(default_factory=list)  # per worn counter-part (V,) estimated
                                                     # error of its depth (m), relaxed
    part_noise: list = field(default_factory=list)  # per worn counter-part (V,): the sampling
                                                     # noise of its wear per cycle (m) in this
                                                     # measurement, from ``history`` (None:
                                                     # too few; not saved: measured anew)
    part_noise_var: list = field(default_factory=list)  # per worn counter-part (V,): the
                                                     # variance (m^2) the jumps' noise added
                                                     # to its depth (random across jumps)
    window: int = 1                                 # resolved cycles a measurement averages
    history: list = field(default_factory=list)     # the measurements before at this window
                                                    # (at most HISTORY - 1): (their middle,
                                                    # cycles; per body alpha; per part the
                                                    # rates it settles to)
    relax: float = np.inf                           # cycles the contact relaxes errors over
    noise_var: list = field(default_factory=list)  # per body (n,): the variance (m^2) the
                                                    # jumps' noise added to its depth
    bias: list = field(default_factory=list)       # per body: the part of its errors common
                                                    # to the whole contact (m), which the
                                                    # contact does not relax
                                                    # (jump_errors._after)
    # not saved with checkpoints: what the run has done since it (re)started,
    # for meshwear check's estimate
    last_limit: str | None = None                   # the bound that set the latest jump,
                                                    # or refused the latest cycle's
    fill_seconds: float = 0.0                       # wall time filling outputs from jumps
    filled_outputs: int = 0                         # outputs filled from jumps
    taken: list = field(default_factory=list)       # the jumps taken: (cycle it starts at,
                                                    # cycles, the bound that set it)
    cycle_start: int = 0                            # the step the cycle being resolved began at
    volumes: list = field(default_factory=list)     # the measurements at this window (at
                                                    # most HISTORY): (their middle, cycles;
                                                    # per body its worn volume per cycle, m^3)
    noisy: bool = False                             # a jump of twice the window, by its own
                                                    # noise alone, would break the tolerance
    part_past: list = field(default_factory=list)  # per worn counter-part: its last
                                                    # measurements (at most HISTORY), each
                                                    # (middle, cycles; (V,) depth then, m;
                                                    # rate, m per cycle; stiffness, per cycle)

    def error_estimate(self, state):
        """:func:`error_estimate` of ``state``, whose controller this is."""
        return error_estimate(state)


@dataclass
class _Measurement:
    """One pass of the controller's loop: the ``window`` resolved cycles
    from step ``start`` to ``stop`` that a measurement averages
    (:func:`_resolve`), and what the jump after it reads of them
    (:func:`_measure`)."""

    start: int                      # the step it began at
    before: list                    # per body (wear_depth, vertices, wear_volume,
                                    # friction_work) at its start
    before_parts: list              # per worn counter-part (depth, volume, work) at its start
    starts: list                    # per body its penetrations at its start
                                    # (jumps.start_depths; None: explicit, or at t = 0)
    window: int                     # the resolved cycles it averages
    stop: int                       # the step it ends at
    end_limit: int                  # the most cycles a jump after it may cover (the run
                                    # ends with a resolved cycle)
    could: int                      # the cycles its outputs were recorded for
    snapshots: object               # those records (meshwear.output.filled.record)
    rates: list = None              # per body (n,) wear per cycle
    part_rates: list = None         # per worn counter-part (V,) wear per cycle
    measures: list = None           # per body its jumps.measure (implicit; None: explicit)
    middle: float = 0.0             # its middle (cycles)
    increments: list = None         # per per-vertex surface: a worn counter-part's wear
                                    # per cycle (None: not worn)
    settled: list = None            # per per-vertex surface: the rates it settles to
    stiffness: list = None          # per per-vertex surface: its stiffness per cycle,
                                    # summed in the wear kernel (implicit)


def run_cycle_jump(model, state, advance, check, observers=(), progress=None, checkpoint=None,
                   forced_jump=None):
    """Run ``state`` to the end of ``model``'s duration, jumping over cycles.

    The step loop is the caller's (:func:`meshwear.step.simulate.run` passes its
    own): ``advance(model, state, stop, observers, progress)`` resolves
    steps up to ``stop`` writing the outputs due, and
    ``check(model, state, face_normals)`` refuses an invalid state.
    ``forced_jump`` replaces the controller by a fixed jump (still stopping
    at the end): the fixed-factor scheme of finite-element wear codes, for
    comparisons and tests.

    Each pass resolves a measurement (:func:`_resolve`), reads its rates
    (:func:`_measure`), chooses the jump (:func:`_choose`), takes it
    (:func:`_take`) and keeps what the next pass grows from
    (:func:`_remember`).
    """
    n_c = model.cycle_steps
    tolerance = model.scene.wear.tolerance
    implicit = model.scene.wear.jump == "implicit"
    parts = [(j, part) for j, part in enumerate(state.parts) if part is not None]
    js = _controller_state(model, state, parts)
    while state.step < model.n_steps:
        cycle = _resolve(model, state, js, parts, implicit, advance, observers, progress,
                         forced_jump)
        if cycle.stop - cycle.start < n_c or state.step >= model.n_steps:
            break
        if js.settling:
            js.settling = False
            continue
        _measure(model, state, js, parts, implicit, cycle)
        jump, which, results = _choose(model, state, js, parts, implicit, tolerance, cycle,
                                       forced_jump)
        if jump > 0:
            _take(model, state, js, parts, implicit, cycle, jump, which, results, observers,
                  check, forced_jump)
        _remember(js, parts, implicit, cycle, jump, which, forced_jump)
        if checkpoint is not None:
            checkpoint(model, state)
    return state


def _controller_state(model, state, parts):
    """``state``'s :class:`JumpState`, made at the run's start (or read from
    a checkpoint), its per-body and per-part lists sized to ``model`` and
    the worn counter-parts ``parts`` ((surface index, part) pairs), and each
    body's load log sized to its vertices."""
    if state.jump is None:
        state.jump = JumpState(rate=[None] * len(model.bodies),
                               error=[np.zeros(len(b.tributary_area)) for b in model.bodies],
                               alpha=[None] * len(model.bodies),
                               part_rate=[None] * len(parts),
                               part_error=[np.zeros(len(p.depth)) for _, p in parts])
    js = state.jump
    if len(js.part_noise) != len(parts):
        js.part_noise = [None] * len(parts)
    if len(js.part_past) != len(parts):
        js.part_past = [[] for _ in parts]
    if len(js.part_noise_var) != len(parts):
        js.part_noise_var = [np.zeros(len(p.depth)) for _, p in parts]
    if len(js.noise_var) != len(model.bodies):
        js.noise_var = [np.zeros(len(s.wear_depth)) for s in state.bodies]
    if len(js.bias) != len(model.bodies):
        js.bias = [np.zeros(2) for _ in model.bodies]
    if len(js.drift) != len(model.bodies):
        js.drift = [np.zeros(len(s.wear_depth)) for s in state.bodies]
    for body, s in zip(model.bodies, state.bodies):
        if s.load.shape != (jumps.LOAD_ROWS, len(s.wear_depth)):
            s.load = np.zeros((jumps.LOAD_ROWS, len(s.wear_depth)))
    return js


def _resolve(model, state, js, parts, implicit, advance, observers, progress, forced_jump):
    """Resolve the next measurement's cycles (``js.window`` of them, or up
    to the run's end) from ``state``, recording the last one's states for
    the outputs a jump after it fills; return the :class:`_Measurement`."""
    n_c = model.cycle_steps
    start = js.cycle_start = state.step
    before = [(s.wear_depth.copy(), s.vertices.copy(), s.wear_volume.copy(),
               s.friction_work.copy()) for s in state.bodies]
    before_parts = [(p.depth.copy(), p.volume.copy(), p.work.copy()) for _, p in parts]
    # the penetrations at the cycle's start, to see each one's change at
    # the same phase (the state at t = 0 is not yet placed in balance)
    starts = ([jumps.start_depths(model, body, s) for body, s in zip(model.bodies,
                                                                      state.bodies)]
              if implicit and start > 0 else [None] * len(model.bodies))
    for s in state.bodies:
        s.load[:] = 0.0
    for _, part in parts:
        part.stiffness[:] = 0.0      # each counter vertex's, summed over the measurement
    if implicit and parts:
        for s in state.bodies:       # the pairs that wear the counters, over the measurement
            jumps.start_log(s, start, js.window * n_c)
    # a measurement averages the wear of ``window`` consecutive cycles
    # (one, unless single cycles disagree): the last one is recorded for
    # the outputs a jump after it fills
    window = js.window
    stop = min(start + window * n_c, model.n_steps)
    last = max(start, stop - n_c)
    if last > start:
        advance(model, state, last, observers, progress)
    # the cycles a jump after this one may cover: the outputs in them are
    # filled from the states of this cycle at the same phase
    end_limit = max(0, (model.n_steps - stop - 1) // n_c)
    could = 0 if js.settling or forced_jump == 0 else min(
        end_limit, forced_jump if forced_jump is not None else int(GROWTH * js.last_jump + 1))
    snapshots = filled.record(model, state, last, stop, could, observers, progress,
                              advance)
    js.resolved_steps += stop - start
    return _Measurement(start, before, before_parts, starts, window, stop, end_limit, could,
                        snapshots)


def _measure(model, state, js, parts, implicit, cycle):
    """Read the resolved measurement ``cycle`` into its rates: each body's
    and worn counter-part's wear per cycle, the bodies' implicit measures,
    the rates the counter-parts settle to and their noise; relax the errors
    so far over its cycles (:func:`meshwear.longrun.jump_errors._relax_resolved`)."""
    n_c = model.cycle_steps
    window, before, before_parts = cycle.window, cycle.before, cycle.before_parts
    start, starts = cycle.start, cycle.starts
    rates = [(s.wear_depth - b[0]) / window for s, b in zip(state.bodies, before)]
    part_rates = [(p.depth - b[0]) / window for (_, p), b in zip(parts, before_parts)]
    measures = ([jumps.measure(model, body, s, rate, start, window)
                 for body, s, rate, start in zip(model.bodies, state.bodies, rates, starts)]
                if implicit else None)
    middle = state.step / n_c - 0.5 * window
    # (the counter's wear under a body vertex at the rate it settles
    # to: a counter vertex catching up with the contact wears faster for
    # a few cycles, and read as the contact's it relieved the bodies'
    # jumps, and its own, by as much as it took; and its scatter is the
    # noise the jumps extrapolate, the departure relaxing on its own)
    increments = [None] * len(state.parts)
    settled = [None] * len(state.parts)
    stiffness = [None] * len(state.parts)     # per cycle, summed in the wear kernel
    for k, ((j, part), rate) in enumerate(zip(parts, part_rates)):
        increments[j] = settled[j] = rate
        if implicit and len(part.stiffness):
            stiffness[j] = part.stiffness / window
            depth = before_parts[k][0] + 0.5 * window * rate
            settled[j] = jumps.settled_rates(rate, stiffness[j], depth, middle,
                                             js.part_past[k])
            js.part_past[k] = (js.part_past[k] + [(middle, depth, rate, stiffness[j])]
                               )[-HISTORY:]
        js.part_noise[k] = _counter_noise(js, k, settled[j], middle)
    logs = None
    if parts and implicit:
        logs = [jumps.pair_log(s, start) for s in state.bodies]
        # (before the relaxation: the counter-part's wear under each
        # body vertex relaxes its errors too, gamma_i)
        for s, m, log in zip(state.bodies, measures, logs):
            jumps.counter_relief(model, s, m, settled, state.time, log)
    js.relax = _relaxation(measures)
    _relax_resolved(js, measures, part_rates, window)
    js.noisy = False
    cycle.rates, cycle.part_rates, cycle.measures = rates, part_rates, measures
    cycle.middle = middle
    cycle.increments, cycle.settled, cycle.stiffness = increments, settled, stiffness


def _choose(model, state, js, parts, implicit, tolerance, cycle, forced_jump):
    """The jump after measurement ``cycle``: its cycles, the bound that set
    it, and per body its ``(wear, move, error)``. Implicit:
    :func:`meshwear.longrun.jump_choice._choose_implicit`, the volume kept
    (:func:`meshwear.longrun.jump_volume._keep_volume`) and the mesh's
    bounds (:func:`meshwear.longrun.jump_geometry.cut`); explicit:
    :func:`meshwear.longrun.jump_choice.choose_jump` per body and the fold
    bound; either within the worn counter-parts' bound
    (:func:`meshwear.longrun.jump_choice._part_limit`)."""
    window, before, rates, measures = cycle.window, cycle.before, cycle.rates, cycle.measures
    end_limit, could, middle = cycle.end_limit, cycle.could, cycle.middle
    part_limit, part_which = float("inf"), None
    if parts:
        if forced_jump is None:
            part_limit, part_which = _part_limit(model, parts, cycle.part_rates, js, measures,
                                                 tolerance, end_limit, implicit,
                                                 min(could, end_limit))
    volumes = np.array([float((s.wear_volume - b[2]).sum()) / window
                        for s, b in zip(state.bodies, before)])
    js.volumes = (js.volumes + [(middle, volumes)])[-HISTORY:]
    if implicit:
        def keep(results, jump, forced=False):
            return _keep_volume(model.bodies, measures, rates, state.bodies, before,
                                results, jump, window, js.volumes, forced)

        reaches = [jump_geometry.reach(model, body, s, state.time)
                   for body, s in zip(model.bodies, state.bodies)]

        def fits(results):
            return jump_geometry.cut(model, state.bodies, before, rates, results, measures,
                                     window, reaches)

        jump, which, results = _choose_implicit(
            measures, rates, js, end_limit, int(min(could, part_limit)), tolerance,
            forced_jump, middle, [float(s.wear_depth.max(initial=0.0)) for s in state.bodies],
            keep, fits)
        if part_limit < could and (which == "growth" or part_limit < 1):
            which = part_which       # the counter-parts bounded it (or refused it)
    else:
        jump, which = end_limit, "end"
        if forced_jump is not None:
            jump, which = min(end_limit, forced_jump), "forced"
        else:
            for body, s, rate, previous in zip(model.bodies, state.bodies, rates, js.rate):
                j, w = choose_jump(rate, previous, js.gap, penetration(model, body, s),
                                   tolerance, js.last_jump, end_limit)
                if j < jump:
                    jump, which = j, w
        jump = min(jump, could)
        if forced_jump is None and jump > 0:
            # fold: the extrapolated moves are the cycle's times the
            # jump, so the share of one cycle allowed is the cycles
            per_cycle = [(rate, 0.0, None) for rate in rates]
            cut = jump_geometry.cut(model, state.bodies, before, rates, per_cycle, None, window)
            if cut is not None and cut[1] < jump:
                which, jump = cut[0], int(np.floor(cut[1]))
        results = [(jump * rate, 0.0, _slope_error(rate, previous, js.gap, jump))
                   for rate, previous in zip(rates, js.rate)]
    return jump, which, results


def _take(model, state, js, parts, implicit, cycle, jump, which, results, observers, check,
          forced_jump):
    """Take the chosen jump of ``jump`` cycles (``which`` bound set it;
    ``results`` per body its wear, move and error) after measurement
    ``cycle``: add its errors, move the bodies and the worn counter-parts
    on (:mod:`meshwear.longrun.extrapolate`), and fill the outputs inside
    it (:func:`meshwear.output.filled.write`)."""
    n_c = model.cycle_steps
    window, before, rates, measures = cycle.window, cycle.before, cycle.rates, cycle.measures
    if not implicit:
        for error, (_, _, estimate) in zip(js.error, results):
            error += estimate
    js.limits[which] = js.limits.get(which, 0) + 1
    js.last_limit = which
    factors = None
    if parts and implicit:
        # (before the jump moves the bodies: the feet at the cycle's end)
        factors = jumps.counter_factors(model, state, measures, results, rates, jump,
                                        cycle.increments, state.time, cycle.stiffness,
                                        cycle.settled)
    spans = _jump(model, state, before, rates, jump, results, measures, window)
    share = None
    if factors is not None:
        # (the jump has moved the bodies' arrays on: the measurement's
        # volume is from before it to the jump's start)
        volume = sum(float((span["wear_volume"][0] - b[2]).sum()) for span, b in
                     zip(spans, before)) / window
        jumped = sum(float((span["wear_volume"][1] - span["wear_volume"][0]).sum())
                     for span in spans)
        share = jumped / volume if volume > 0.0 else None
    part_spans = _jump_parts(model, parts, cycle.before_parts, cycle.part_rates, js, jump,
                             factors, window, share)
    before_fill = time.perf_counter()
    js.filled_outputs += filled.write(
        model, state, cycle.stop, jump, cycle.snapshots, spans, observers, check, part_spans,
        _progress(measures, results, jump) if implicit and forced_jump is None
        else None)
    js.fill_seconds += time.perf_counter() - before_fill
    js.jumps += 1
    js.taken.append((cycle.stop / n_c, jump, which))
    js.settling = not model.quasi_static


def _remember(js, parts, implicit, cycle, jump, which, forced_jump):
    """Keep in ``js`` what the measurement after ``cycle`` grows from: the
    jump ``jump`` (0: none) that ``which`` bound set, the rates, the
    history the drift and the noise are read from, the window (doubled
    where single measurements are too noisy for the jumps they allow) and
    the cycles between this measurement's middle and the next's."""
    window, measures, rates = cycle.window, cycle.measures, cycle.rates
    js.last_jump = _grows_from(jump, which, js.last_jump)
    if jump == 0:
        js.last_limit = which        # why none was taken (the progress line says)
    js.rate = rates
    js.part_rate = cycle.part_rates
    if implicit:
        js.alpha = []
        for m, rate in zip(measures, rates):
            alpha = np.zeros(len(rate))
            alpha[m.index] = np.where(m.mean > 0.0, m.alpha, 0.0)
            js.alpha.append(alpha)
    js.history = (js.history + [(cycle.middle, js.alpha if implicit else None,
                                  [cycle.settled[j] for j, _ in parts])])[1 - HISTORY:]
    following = window
    if (forced_jump is None and which in NOISY and jump < 2 * window
            and window < MAX_WINDOW and js.noisy):
        # single measurements disagree by more than the jumps they allow
        # (a vertex at a contact's edge touched every other cycle, a
        # flank switching between two rates): average over more cycles,
        # and measure the noise and the drift again at that window (not
        # where the errors of the jumps before fill the tolerance: the
        # resolved cycles relax them)
        following = js.window = 2 * window
        js.history = []
        js.volumes = []
    # cycles between the middles of this measurement and the next
    js.gap = jump + 0.5 * (window + following) + (1.0 if js.settling else 0.0)


def _grows_from(jump, which, last):
    """The jump the next one may grow from (:data:`GROWTH`), after this
    measurement's ``jump`` (0: refused) set by ``which``: the one taken; or,
    refused by a bound a resolved cycle mends (:data:`RESUME`), the last
    one taken; else none (growth starts again from one cycle)."""
    return jump if jump > 0 or which not in RESUME else last
