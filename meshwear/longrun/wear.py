"""Long durations: cycle jumping with error control (docs/model.md, "Long durations").

Resolve one cycle of the motion with the ordinary step, measure each
vertex's wear in that cycle, extrapolate it over ``J`` cycles, then resolve
again. The extrapolation (``wear.jump``) is

implicit (default)
    a backward-Euler step in which each vertex's pressure is relieved by its
    own wear and a guided body's load re-balanced (:mod:`meshwear.jumps`):
    stable for any ``J``. ``J`` is the largest one whose error, estimated by
    step doubling (one jump of ``J`` against two of ``J / 2``), stays under
    ``tolerance`` times the depth the jump adds where wear is fastest, and
    whose drift and noise of the wear per unit penetration between resolved
    cycles leave errors of depth (each vertex's relaxed by the contact
    since) within ``tolerance`` of the depth; a body carrying a load along
    its axis keeps the volume its measurements give (:func:`_keep_volume`);
explicit
    the cycle's wear times ``J``, ``J`` bounded by the slope criterion (the
    change of each vertex's wear rate between the last two resolved cycles,
    ``rho`` per cycle, makes the extrapolation wrong by about ``rho J^2 / 2``)
    and for stability (no vertex may wear by more than a fraction
    :data:`THETA` of its elastic penetration in one jump: past that the
    extrapolated wear opens a gap where the contact carried load, and the worn
    profile oscillates from jump to jump while the worn volume looks right).

A worn counter-part (docs/model.md, "Worn counter-surfaces") jumps with
the bodies: its wear in the resolved cycle relieves the body vertices over it
in the implicit step (:func:`meshwear.jumps.counter_relief`), and its own
wear over the ``J`` cycles is relieved as theirs is (the same contact wears
both: :func:`meshwear.jumps.counter_factors`; a vertex that relaxes faster on
its own, by its stiffness summed in the wear kernel, jumps at the rate it
settles to, :func:`meshwear.jumps.settled_rates`, its departure from it
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
"""

import time
from dataclasses import dataclass, field

import numpy as np

from . import jump_geometry, jumps
from ..kernels.contact import ANCHOR
from ..kernels.counter_wear import SPACING_FRACTION
from ..kernels.nearest import face_frames
from ..kernels.rigid import SETTLED
from ..motion.motions import TurningMotion
from ..output import filled
from ..surfaces import contact_areas, quaternion_matrix, slot_normals

#: largest wear in one explicit jump, as a fraction of a vertex's elastic penetration
THETA = 0.3
#: a jump is at most this many times the previous one, plus one
GROWTH = 2.0
#: vertices wearing less than this fraction of the fastest one per cycle do not
#: limit the jump (their rates are round-off or contact-edge flicker)
SIGNIFICANT = 1e-3
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
                                                    # contact does not relax (:func:`_after`)
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


def penetration(model, body, s):
    """(n,) elastic penetration of each vertex at the end of the last step (m):
    its normal force over its normal stiffness, the largest over the surfaces."""
    out = np.zeros(len(s.wear_depth))
    for j, normal in enumerate(slot_normals(model, s)):
        area = contact_areas(body, s, normal)
        c = model.law[5] + model.law[6] * area
        loaded = (s.normal_force[j] > 0.0) & (c > 0.0)
        out[loaded] = np.maximum(out[loaded], s.normal_force[j][loaded] / c[loaded])
    return out


def choose_jump(rate, previous, gap, penetration_, tolerance, last_jump, limit, theta=THETA,
                stability=True):
    """Cycles to jump over, and which bound set it.

    Parameters
    ----------
    rate, previous : (n,) float
        Wear per cycle in the last resolved cycle and in the one before
        (``previous`` None after the first).
    gap : float
        Cycles between those two measurements.
    penetration_ : (n,) float
        Elastic penetration at the end of the last resolved cycle (m).
    tolerance : float
        Relative error allowed on wear depth.
    last_jump, limit : int
        The previous jump, and the most cycles that may be jumped here.
    stability : bool
        Bound by :data:`THETA` of the penetration (explicit jumps).
    """
    fastest = rate.max() if len(rate) else 0.0
    if fastest <= 0.0 or previous is None:
        return 0, "accuracy"
    active = rate > SIGNIFICANT * fastest
    bounds = {"end": float(limit), "growth": GROWTH * last_jump + 1.0}
    # stability: J r_i <= theta p_i
    pressed = active & (penetration_ > 0.0)
    if stability and pressed.any():
        bounds["stability"] = float((theta * penetration_[pressed] / rate[pressed]).min())
    # accuracy: rho_i J^2 / 2 <= tol J r_max, the error of each vertex's
    # extrapolation under tol times the depth the jump adds where wear is
    # fastest (the scale of the scar: a vertex just entering the contact
    # changes its rate fast, but its depth is small)
    rho = np.abs(rate - previous) / max(gap, 1.0)
    if rho.max() > 0.0:
        bounds["accuracy"] = float(2.0 * tolerance * fastest / rho.max())
    which = min(bounds, key=bounds.get)
    return max(0, int(np.floor(bounds[which]))), which


def run_cycle_jump(model, state, advance, check, observers=(), progress=None, checkpoint=None,
                   forced_jump=None):
    """Run ``state`` to the end of ``model``'s duration, jumping over cycles.

    The step loop is the caller's (:func:`meshwear.simulate.run` passes its
    own): ``advance(model, state, stop, observers, progress)`` resolves
    steps up to ``stop`` writing the outputs due, and
    ``check(model, state, face_normals)`` refuses an invalid state.
    ``forced_jump`` replaces the controller by a fixed jump (still stopping
    at the end): the fixed-factor scheme of finite-element wear codes, for
    comparisons and tests.
    """
    n_c = model.cycle_steps
    tolerance = model.scene.wear.tolerance
    implicit = model.scene.wear.jump == "implicit"
    parts = [(j, part) for j, part in enumerate(state.parts) if part is not None]
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
    while state.step < model.n_steps:
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
        if stop - start < n_c or state.step >= model.n_steps:
            break
        if js.settling:
            js.settling = False
            continue
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
        part_limit, part_which = float("inf"), None
        if parts:
            if forced_jump is None:
                part_limit, part_which = _part_limit(model, parts, part_rates, js, measures,
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
                cycle = [(rate, 0.0, None) for rate in rates]
                cut = jump_geometry.cut(model, state.bodies, before, rates, cycle, None, window)
                if cut is not None and cut[1] < jump:
                    which, jump = cut[0], int(np.floor(cut[1]))
            results = [(jump * rate, 0.0, _slope_error(rate, previous, js.gap, jump))
                       for rate, previous in zip(rates, js.rate)]
        if jump > 0:
            if not implicit:
                for error, (_, _, estimate) in zip(js.error, results):
                    error += estimate
            js.limits[which] = js.limits.get(which, 0) + 1
            js.last_limit = which
            factors = None
            if parts and implicit:
                # (before the jump moves the bodies: the feet at the cycle's end)
                factors = jumps.counter_factors(model, state, measures, results, rates, jump,
                                                increments, state.time, stiffness, settled)
            spans = _jump(model, state, before, rates, jump, results, measures, window)
            share = None
            if factors is not None:
                # (the jump has moved the bodies' arrays on: the measurement's
                # volume is from before it to the jump's start)
                cycle = sum(float((span["wear_volume"][0] - b[2]).sum()) for span, b in
                            zip(spans, before)) / window
                jumped = sum(float((span["wear_volume"][1] - span["wear_volume"][0]).sum())
                             for span in spans)
                share = jumped / cycle if cycle > 0.0 else None
            part_spans = _jump_parts(model, parts, before_parts, part_rates, js, jump, factors,
                                     window, share)
            before_fill = time.perf_counter()
            js.filled_outputs += filled.write(
                model, state, stop, jump, snapshots, spans, observers, check, part_spans,
                _progress(measures, results, jump) if implicit and forced_jump is None
                else None)
            js.fill_seconds += time.perf_counter() - before_fill
            js.jumps += 1
            js.taken.append((stop / n_c, jump, which))
            js.settling = not model.quasi_static
        js.last_jump = _grows_from(jump, which, js.last_jump)
        if jump == 0:
            js.last_limit = which        # why none was taken (the progress line says)
        js.rate = rates
        js.part_rate = part_rates
        if implicit:
            js.alpha = []
            for m, rate in zip(measures, rates):
                alpha = np.zeros(len(rate))
                alpha[m.index] = np.where(m.mean > 0.0, m.alpha, 0.0)
                js.alpha.append(alpha)
        js.history = (js.history + [(middle, js.alpha if implicit else None,
                                      [settled[j] for j, _ in parts])])[1 - HISTORY:]
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
        if checkpoint is not None:
            checkpoint(model, state)
    return state


def _grows_from(jump, which, last):
    """The jump the next one may grow from (:data:`GROWTH`), after this
    measurement's ``jump`` (0: refused) set by ``which``: the one taken; or,
    refused by a bound a resolved cycle mends (:data:`RESUME`), the last
    one taken; else none (growth starts again from one cycle)."""
    return jump if jump > 0 or which not in RESUME else last


def _progress(measures, results, jump):
    """Per body, the share of each vertex's wear (n,) and of the move done
    at a fraction of an implicit jump's cycles: one backward-Euler step over
    that fraction against one over the whole jump, so outputs filled inside
    a long jump follow each vertex's own curve (the middle of a pin's scar
    slowing, its edge starting, as the contact widens), not a straight line."""
    whole = [jumps.single_step(m, jump) for m in measures]

    def share(fraction):
        if fraction <= 0.0 or fraction >= 1.0:
            return [(fraction, fraction)] * len(measures)
        out = []
        for m, (wear, move), (full_wear, _, _) in zip(measures, whole, results):
            part, part_move = jumps.single_step(m, fraction * jump)
            full = np.full(len(full_wear), fraction)
            worn = wear > 0.0
            full[m.index[worn]] = np.clip(part[worn] / wear[worn], 0.0, 1.0)
            out.append((full, float(np.clip(part_move / move, 0.0, 1.0)) if move else fraction))
        return out
    return share


def _slope_error(rate, previous, gap, jump):
    """(n,) the slope criterion's estimate of an explicit jump's error (m)."""
    if previous is None:
        return np.zeros(len(rate))
    return 0.5 * np.abs(rate - previous) / max(gap, 1.0) * jump * jump


def _choose_implicit(measures, rates, js, end, could, tolerance, forced=None, t=0.0,
                     deepest=None, keep=None, fits=None):
    """Cycles to jump over with implicit jumps, which bound set it, and per
    body the jump's ``(wear, move, step-doubling error estimate)``.

    Bounds: ``end`` (the run ends with a resolved cycle), ``could`` (the
    growth bound the snapshots were taken for, or a forced jump), the drift
    of each vertex's wear per unit penetration over the measurements at
    this window (:func:`_trend`): its error within the tolerance of what the
    jump adds (``rho_i pbar_i J^2 / 2 <= tol J r_max``) or, with the drift
    errors of the jumps before as the contact has relaxed them
    (:func:`_after`), of the body's ``deepest`` wear after the jump; its
    noise about that drift, random from jump to jump, relaxed alike, within
    the latter; step doubling (the jump's estimated error ``<= tol J
    r_max``); ``keep(results, jump)``, which returns the jump's results
    with the volume kept (:func:`_keep_volume`) or None where the jump is
    too long; and ``fits(results)``, the mesh the jump moves
    (:func:`meshwear.jump_geometry.cut`: None, or the bound the results
    break and the share of the jump it allows). ``t``: the middle of this
    measurement (cycles). The jump taken
    adds its errors to ``js.error`` (step doubling's), ``js.drift``,
    ``js.noise_var`` and ``js.bias`` (the common part)."""
    fastest = max(float(r.max()) if len(r) else 0.0 for r in rates)
    if forced is not None:
        jump = min(end, could)
        spread = _spread(measures, rates, jump)
        return jump, "forced", spread if keep is None else keep(spread, jump, True)
    if fastest <= 0.0 or not js.history:
        return 0, "measuring", None
    bounds = {"end": float(end), "growth": float(could)}
    # per body, each measured vertex's drift of its wear per cycle, rho_i pbar_i,
    # and the noise of its wear per cycle about it, sigma_i pbar_i
    trends = [_trend(m, [(time, alphas[k][m.index]) for time, alphas, _ in js.history], t)
              for k, m in enumerate(measures)]
    deepest = [0.0] * len(measures) if deepest is None else deepest
    top = [float(r.max(initial=0.0)) for r in rates]
    if len(js.bias) != len(measures) or len(js.drift) != len(measures):  # (built by hand)
        js.error = [np.zeros(len(r)) for r in rates]
        js.drift = [np.zeros(len(r)) for r in rates]
        js.noise_var = [np.zeros(len(r)) for r in rates]
        js.bias = [np.zeros(2) for _ in rates]
    most = min(end, could)
    for k, (m, (drift, noise)) in enumerate(zip(measures, trends)):
        if noise is not None and len(noise):
            js.noisy |= _alone(noise, js.window, tolerance, deepest[k], top[k])
        if drift.any():
            # the drift's error within the tolerance of what the jump adds
            # (each jump's), or, with the errors of the jumps before as the
            # contact has relaxed them, of the depth the body will have
            steep = float(np.abs(drift).max())
            own = 2.0 * tolerance * top[k] / steep
            budget = _within(lambda j: _drift_total(*_drift_after(js, k, m, drift, j)),
                             tolerance, deepest[k], top[k], most)
            bounds["drift"] = min(bounds.get("drift", np.inf), max(own, float(budget)))
        if noise is not None and noise.any():
            still = _relax_rate(m) <= 0.0
            budget = _within(lambda j: float(np.sqrt((_settled(
                _noise_after(js, k, m, None, j), still, tolerance, deepest[k])
                + (j * noise) ** 2).max(initial=0.0))), tolerance, deepest[k], top[k], most)
            bounds["noise"] = min(bounds.get("noise", np.inf), float(budget))
    which = min(bounds, key=bounds.get)
    jump = int(np.floor(bounds[which]))
    for _ in range(40):
        if jump < 1:
            return 0, which if which in REFUSING else "accuracy", None
        results = [jumps.implicit(m, jump) for m in measures]
        worst = max(float(e.max(initial=0.0)) for _, _, e in results) / (tolerance * jump
                                                                          * fastest)
        if worst > 1.0:
            # the error grows like J^3, its allowance like J
            jump, which = int(jump * min(np.sqrt(0.9 / worst), 0.5 if worst > 4.0 else 0.9)), \
                "accuracy"
            continue
        spread = _spread(measures, rates, jump, results)
        if keep is not None:
            spread = keep(spread, jump)
            if spread is None:
                # the implicit step's volume is far off the measurements':
                # the jump is too long for the contact's wear per unit
                # penetration to hold (:func:`_keep_volume`)
                jump, which = jump // 2, "volume"
                continue
        cut = fits(spread) if fits is not None else None
        if cut is not None:
            # the moves the jump gives the mesh, at most linear in its
            # cycles (the implicit step relieves them as it grows), bring
            # the jump to about the cycles allowed, a little under them
            which, allowed = cut
            jump = int(min(0.9 * jump, 0.95 * allowed * jump))
            continue
        for k, (m, (drift, noise), (_, _, e)) in enumerate(zip(measures, trends, results)):
            doubling, drifted, variance, common = _after(js, k, m, drift, noise, jump, e)
            js.error[k][m.index], js.drift[k][m.index] = doubling, drifted
            js.noise_var[k][m.index], js.bias[k] = variance, common
        return jump, which, spread
    return 0, which if which in REFUSING else "accuracy", None


#: the bounds that, refusing even one cycle, name the refusal (the others
#: call it accuracy)
REFUSING = ("noise", "drift", "volume", "reach", "fold")


#: the most a load-carrying body's implicit jump may be off the volume its
#: measurements give (a fraction): the jump is moved to it within this, and
#: halved past it (:func:`_keep_volume`)
KEEP = 0.25


def _keep_volume(bodies, measures, rates, states, before, results, jump, window, volumes,
                 forced=False):
    """The implicit jump's ``results`` with each load-carrying body's wear
    per unit penetration taken larger or smaller alike
    (:func:`_volume_direction`) so that its worn volume over the jump is
    the one its measurements give: its volume per cycle ``volumes`` (the
    last one this measurement's), on the straight line fitted through them
    (:func:`_fit`), over the jump's cycles.

    Under a load carried along a free axis the volume a cycle wears is the
    load's work against the sliding (Archard's ``k L s`` when every point
    slides alike), whatever the contact's shape; the implicit step, which
    holds each vertex's wear per unit penetration fixed, moves the load
    towards the vertices that wear least per unit of it (at a scar's edge,
    in contact for part of the stroke, whose share of the stroke grows as
    they are pressed harder) and loses volume as the jump grows (a cylinder
    on a worn flat kept 0.87 of it at 40 cycles). The jump takes the
    volume of the measurements; None (the jump is too long) where they
    differ by more than :data:`KEEP`, unless the jump is ``forced``.
    Bodies that carry no load along an axis (a prescribed one, whose wear
    relieves its contact) keep the implicit step's volume."""
    times = np.array([t for t, _ in volumes])
    rate = np.vstack([v for _, v in volumes])
    slope = _fit(times, rate)[0] if len(volumes) > 2 else np.zeros(rate.shape[1])
    out = []
    for k, (body, m, r, s, b, (wear, move, error)) in enumerate(
            zip(bodies, measures, rates, states, before, results)):
        target = jump * rate[-1, k] + 0.5 * jump * jump * slope[k]
        if m.guided and m.load != 0.0 and target > 0.0:
            # the volume the jump plans (:func:`_jump`), per unit of each
            # vertex's wear: its volume of the cycle over its wear then, or,
            # brought into contact by the jump, its contact area
            area = np.zeros(len(r))
            wearing = r > 0.0
            area[wearing] = (s.wear_volume[wearing] - b[2][wearing]) / window / r[wearing]
            fresh = ~wearing & (wear > 0.0)
            if fresh.any():
                normal = np.zeros((len(r), 3))
                normal[m.index] = m.normal
                area[fresh] = _fresh_area(body, s, fresh, normal)
            planned = float(wear @ area)
            if abs(planned - target) > KEEP * target and not forced:
                return None
            # every vertex's wear per unit penetration taken a little larger
            # (or smaller) until the volume is the measurements'
            # (:func:`_volume_direction`)
            grow, sink = _volume_direction(m, wear, jump)
            per_unit = float(grow @ area)
            if per_unit > 0.0:
                more = (target - planned) / per_unit
                wear, move = np.maximum(wear + more * grow, 0.0), move + more * sink
        out.append((wear, move, error))
    return out


def _volume_direction(m, wear, jump):
    """How an implicit jump of ``jump`` cycles of body measure ``m`` changes
    as every vertex's wear per unit penetration ``alpha_i`` is taken
    ``(1 + lambda)`` times larger, to first order in ``lambda``: (n,) each
    vertex's wear (``wear`` (n,) the jump's) and the move along the axis,
    from one backward-Euler step with the balance held.

    A vertex wears ``J alpha_i (p_i - beta_i z) / (1 + J (alpha_i +
    gamma_i))``: its own part is ``w_i (1 + J gamma_i) / (1 + J (alpha_i +
    gamma_i))``, and the balance, whose end penetrations fall by ``w_i /
    (1 + J (alpha_i + gamma_i))``, moves the body by ``dz = -sum c_i beta_i
    w_i / (1 + J a_i) / sum c_i beta_i^2 / (1 + J a_i)`` (``a_i = alpha_i +
    gamma_i``, over its pairs in contact), which wears each vertex
    ``J alpha_i beta_i / (1 + J a_i)`` per unit. Where ``J alpha`` is small
    that is every vertex's wear scaled alike; where it is large the jump
    has worn the contact to its mate's shape (a block to a ring's arc) and
    it is a sink of the body that keeps that shape (scaling every vertex's
    wear there left the block-on-ring scar's edge 4.2 % of its depth off
    the arc after jumps of thousands of turns)."""
    n = len(wear)
    gamma = m.gamma if m.gamma is not None else np.zeros(len(m.alpha))
    relief = 1.0 / (1.0 + jump * (m.alpha + gamma))
    w = wear[m.index]
    own = w * (1.0 + jump * gamma) * relief
    pairs = m.member & (w > 0.0) & (m.stiffness > 0.0)
    c = m.stiffness[pairs] * m.beta[pairs] * relief[pairs]
    across = float(c @ m.beta[pairs])
    sink = -float(c @ w[pairs]) / across if across > 0.0 else 0.0
    grow = np.zeros(n)
    grow[m.index] = np.where(w > 0.0, own - sink * jump * m.alpha * m.beta * relief, 0.0)
    return grow, sink


def _after(js, k, m, drift, noise, jump, doubling=None):
    """Body ``k``'s errors of depth (m) after one more jump of ``jump``
    cycles, for the vertices of its measure ``m``: (k,) each one's step
    doubling error, (k,) its drift's, (k,) the variance of its random one,
    and the part common to the whole contact (the drift's, signed; step
    doubling's).

    A jump holds each vertex's ``alpha_i`` at its measured value, so a
    drift ``rho_i pbar_i`` (``drift``, m per cycle per cycle, signed) makes
    it wrong by ``rho_i pbar_i J^2 / 2``; the noise ``sigma_i`` of a
    measured rate about that drift (``noise``, m per cycle, or None) by
    ``J sigma_i``, random from jump to jump (so the variances add); the
    jump's own step doubling estimates ``doubling`` (k,) (None: not yet
    known). The contact relaxes an error of depth (a vertex worn too little
    carries more and wears more) at its own and its counter-part's wear per
    cycle per unit penetration, ``alpha_i + gamma_i``, so the errors left
    before decay by ``e^{-(alpha_i + gamma_i) J}`` over the jump, except
    their part common to the whole contact (its stiffness-weighted mean: a
    guided body's balance takes a uniform error of depth off its move, not
    its wear), which stays."""
    doubling = np.zeros(len(drift)) if doubling is None else doubling
    local, common = _drift_after(js, k, m, drift, jump)
    # the common part: the drift's signed (rates that rise at the contact's
    # edge and fall in its middle keep the volume), step doubling's not
    common = np.array([common, js.bias[k][1] + _stiffness_mean(m, doubling)])
    decay = np.exp(-_relax_rate(m) * jump)
    return (js.error[k][m.index] * decay + doubling, local, _noise_after(js, k, m, noise, jump),
            common)


def _drift_after(js, k, m, drift, jump):
    """Body ``k``'s drift errors after one more jump (:func:`_after`): (k,)
    each vertex's, relaxed, and the common part (m, signed)."""
    drifted = 0.5 * jump * jump * drift
    local = js.drift[k][m.index] * np.exp(-_relax_rate(m) * jump) + np.abs(drifted)
    return local, float(js.bias[k][0]) + _stiffness_mean(m, drifted)


def _noise_after(js, k, m, noise, jump):
    """Body ``k``'s noise variance after one more jump (:func:`_after`): (k,)
    each vertex's, relaxed, plus the jump's (``noise`` None: none)."""
    decay = np.exp(-_relax_rate(m) * jump)
    variance = js.noise_var[k][m.index] * decay * decay
    return variance if noise is None else variance + (jump * noise) ** 2


def _stiffness_mean(m, values):
    """The stiffness-weighted mean of ``values`` (k,) over the vertices of
    body measure ``m`` in contact (0 with none)."""
    weight = np.where(m.mean > 0.0, m.stiffness, 0.0)
    total = float(weight.sum())
    return float(weight @ values) / total if total > 0.0 else 0.0


def _drift_total(local, common):
    """The largest drift error of depth (m): a vertex's and the common part."""
    return float(local.max(initial=0.0)) + abs(common)


def _common(bias):
    """The magnitude (m) of a body's common error ``bias``: (its drift's,
    signed; its step doubling's)."""
    return abs(float(bias[0])) + float(bias[1])


def _alone(noise, window, tolerance, deepest, fastest):
    """Whether a jump of twice ``window`` cycles, by the error of its own
    ``noise`` (m per cycle) alone, breaks ``tol (deepest + J r)``
    (``fastest``: r)."""
    jump = 2 * window
    return bool(jump * float(noise.max(initial=0.0)) > tolerance * (deepest + jump * fastest))


def _within(error, tolerance, deepest, fastest, most):
    """The longest jump ``J``, at most ``most`` cycles, with ``error(J)``
    (m) within ``tol (deepest + J r)`` (``fastest``: r), searched down from
    ``most`` by a fifth at a time (0: none)."""
    jump = int(most)
    while jump >= 1:
        if error(jump) <= tolerance * (deepest + jump * fastest):
            return jump
        jump = int(jump * 0.8) if jump > 4 else jump - 1
    return 0


def _relax_rate(m):
    """(k,) the rate (1 / cycle) at which the contact relaxes an error of
    depth of each vertex of body measure ``m``: its own and its
    counter-part's wear per cycle per unit penetration (0 out of contact)."""
    return m.alpha if m.gamma is None else m.alpha + m.gamma


def _relax_resolved(js, measures, part_rates, window):
    """Relax the errors of depth so far over the ``window`` resolved cycles
    of a measurement, as the contact does (:func:`_after`): the bodies'
    vertices at their own rates, a worn counter-part's vertices that wore
    at the contact's (``js.relax``)."""
    for k, m in enumerate(measures or ()):
        if k < len(js.error) and len(js.error[k]) and m is not None:
            decay = np.exp(-_relax_rate(m) * window)
            js.error[k][m.index] *= decay
            js.noise_var[k][m.index] *= decay * decay
            if k < len(js.drift) and len(js.drift[k]):
                js.drift[k][m.index] *= decay
    for k, rate in enumerate(part_rates):
        _relax_part(js, k, rate > 0.0, window)


def _relax_part(js, k, wearing, cycles):
    """Relax worn counter-part ``k``'s errors of depth so far over
    ``cycles`` cycles at its vertices ``wearing`` (mask)."""
    decay = _decay(cycles, js.relax)
    js.part_error[k][wearing] *= decay
    js.part_noise_var[k][wearing] *= decay * decay


def _decay(cycles, relax):
    """The factor by which a worn counter-part's errors of depth relax over
    ``cycles`` cycles where it wears (``relax``: the contact's time, cycles;
    inf or 0: none)."""
    return float(np.exp(-cycles / relax)) if np.isfinite(relax) and relax > 0 else 1.0


def _trend(m, past, t):
    """Per vertex of body measure ``m`` (measured at ``t``, cycles), the
    drift of its wear per cycle (``rho_alpha pbar``, m per cycle per cycle, signed)
    and the noise of its wear per cycle about that drift (``sigma_alpha
    pbar``, m per cycle; None with fewer than three measurements), from
    :func:`_fit` of its wear per unit penetration ``alpha`` over ``past``
    (earlier measurements at the same window: (time, alpha)) and this one.
    Vertices not touching in every measurement have no drift (they enter or
    leave the contact)."""
    alpha = np.vstack([a for _, a in past] + [m.alpha])
    slope, sigma = _fit(np.array([time for time, _ in past] + [t]), alpha)
    both = (m.mean > 0.0) & np.all(alpha > 0.0, axis=0)
    noise = None if sigma is None else np.where(both, sigma * m.mean, 0.0)
    return np.where(both, slope * m.mean, 0.0), noise


def _fit(times, values):
    """A straight line fitted to each column of ``values`` (K, n) over
    ``times`` (K,): (n,) its slope, shrunk towards zero by twice the slope's
    own uncertainty (zero within it), and (n,) the scatter of the values
    about it (None with fewer than three). Single measurements scatter about the line (a
    vertex of a fine pad sliding over a finer worn flat sees its
    penetration change facet by facet, one at a pad's rim is touched
    every other cycle); counted as drift, that scatter would hold the
    jumps, and it is random from jump to jump."""
    centred = times - times.mean()
    spread = float(centred @ centred)
    if spread <= 0.0:
        return np.zeros(values.shape[1]), None
    slope = centred @ (values - values.mean(axis=0)) / spread
    if len(times) < 3:
        return slope, None
    residual = values - values.mean(axis=0) - np.outer(centred, slope)
    sigma = np.sqrt((residual * residual).sum(axis=0) / (len(times) - 2))
    return np.sign(slope) * np.maximum(np.abs(slope) - 2.0 * sigma / np.sqrt(spread), 0.0), sigma


def _spread(measures, rates, jump, results=None):
    """Per body ``(wear, move, error)`` of an implicit jump over every vertex
    (the jump measures the vertices that touch or can touch only)."""
    out = []
    for k, (m, rate) in enumerate(zip(measures, rates)):
        wear, move, error = results[k] if results is not None else jumps.implicit(m, jump)
        full, estimate = np.zeros(len(rate)), np.zeros(len(rate))
        full[m.index], estimate[m.index] = wear, error
        out.append((full, move, estimate))
    return out


#: the per-vertex arrays a jump extrapolates
JUMPED = ("vertices", "wear_depth", "wear_volume", "friction_work")


def _jump(model, state, before, rates, jump, results, measures=None, window=1):
    """Extrapolate the last measurement (``window`` resolved cycles, their
    per-cycle wear ``rates``, ``before`` the arrays at their start) over
    ``jump`` more cycles, each body's wear and move along its axis given
    by ``results``; return per body
    ``{name: (array at the jump's start, at its end)}`` for the :data:`JUMPED`
    arrays, and ``shift``, the move of its position."""
    spans = []
    for k, (body, s, b, rate) in enumerate(zip(model.bodies, state.bodies, before, rates)):
        _, vertices0, volume0, work0 = b
        span = {name: getattr(s, name).copy() for name in JUMPED}
        wear, z, _ = results[k]
        normal = None
        if measures is not None:
            normal = np.zeros((len(rate), 3))
            normal[measures[k].index] = measures[k].normal
        # every increment of the cycle scaled like the vertex's wear: a
        # vertex relieved by the jump wears, and dissipates, less; a vertex
        # the jump brought into contact had no cycle to scale: it moves
        # along its surface's normal (jump_geometry.displacement, which
        # the jump's bounds read)
        factor = np.full(len(rate), float(jump))
        wearing = rate > 0.0
        factor[wearing] = wear[wearing] / rate[wearing]
        factor /= window                 # the increments are the window's
        work = s.friction_work - work0
        volume = s.wear_volume - volume0
        s.vertices += jump_geometry.displacement(body, s, vertices0, rate, wear, normal, window)
        s.wear_volume += factor * volume
        s.friction_work += factor * work
        fresh = ~wearing & (wear > 0.0)
        if fresh.any() and normal is not None:
            # and wears its depth times its contact area, and dissipates
            # what the contact does per volume
            _wear_fresh(body, s, fresh, wear, normal,
                        work[wearing].sum() / max(volume[wearing].sum(), 1e-300))
        s.wear_depth += wear
        span = {name: (span[name], getattr(s, name).copy()) for name in JUMPED}
        span["shift"] = z * body.motion.axis if z else np.zeros(3)
        if isinstance(body.motion, TurningMotion):
            # its move is a turn, the arc at its largest lever (jumps.measure)
            span["shift"] = np.zeros(3)
            if z:
                body.motion.params[SETTLED] += z / body.motion.jump_lever
        spans.append(span)
    state.step += jump * model.cycle_steps
    state.time = state.step * model.dt
    state.resolved = False
    # (a mechanism goes on from its state at the end of the resolved cycle,
    # its clock moved on by the jump's whole cycles)
    model.dynamics.jumped(model, state, jump * model.cycle_steps * model.dt)
    # put every body where its path is at the new time (a steady sliding path
    # has moved on; a periodic one is back in phase), a guided one moved along
    # its axis as the jump's balance has it, and carry the stick anchors
    # along, so the next step does not see the jump as a slide
    for body, s, span in zip(model.bodies, state.bodies, spans):
        start = s.pose[0:3].copy()
        s.pose[0:3] += span["shift"]
        body.motion.place(s.pose, state.time)
        moved = s.pose[0:3] - start
        a = s.active                      # the others are in no contact
        for j, n in enumerate(slot_normals(model, s)):
            n = np.broadcast_to(n, s.tangential[j, :, ANCHOR].shape)[a]
            s.tangential[j, a, ANCHOR] += moved - np.einsum("ij,j->i", n, moved)[:, None] * n
    return spans


def _part_limit(model, parts, part_rates, js, measures, tolerance, end, implicit=False,
                most=None):
    """The most cycles the worn counter-parts allow a jump, and the bound
    that sets it: a part vertex sinking by at most SPACING_FRACTION of its
    spacing per jump, the sampling noise of its wear per cycle within the
    tolerance, and, for explicit extrapolation, their slope criterion and
    the counter's wear under each body vertex within :data:`THETA` of its
    penetration. ``implicit``: the jump relieves the counter's wear as the
    body's (:func:`meshwear.jumps.counter_factors`): the bodies' implicit
    step bounds its accuracy and stability; its noise's error is kept within
    the tolerance (:func:`_noise_bound`)."""
    bounds = {}
    for k, ((j, part), rate, previous) in enumerate(zip(parts, part_rates, js.part_rate)):
        if rate.max(initial=0.0) <= 0.0:
            continue
        if previous is None:
            return 0, "counter accuracy"
        # a counter vertex's wear in one cycle is sampled by the steps of the
        # passes over it, and differs from cycle to cycle by that sampling
        # (a pass over a track's edge takes a few steps, a vertex at the rim
        # of a pad is touched every other cycle); a jump multiplies one
        # measurement's, its error random from jump to jump
        if js.part_noise[k] is None:
            return 0, "measuring"
        most = end if most is None else most
        deepest = float(part.depth.max())
        js.noisy |= _alone(js.part_noise[k], js.window, tolerance, deepest, float(rate.max()))
        bound = _noise_bound(js.part_noise[k], js.part_noise_var[k], rate > 0.0, tolerance,
                             deepest, float(rate.max()), js.relax, most)
        if bound < 1.0 <= most:
            return 0, "counter noise"
        bounds["counter noise"] = min(bounds.get("counter noise", np.inf), bound)
        if not implicit:
            jump, which = choose_jump(rate, previous, js.gap, np.zeros(len(rate)), tolerance,
                                      js.last_jump, end, stability=False)
            key = "counter accuracy" if which == "accuracy" else which
            bounds[key] = min(bounds.get(key, np.inf), float(jump))
        spacing = model.surfaces.per_vertex[j].spacing
        sinking = rate > 0.0
        bounds["counter spacing"] = min(bounds.get("counter spacing", np.inf), float(
            (SPACING_FRACTION * spacing[sinking] / rate[sinking]).min()))
    for m in (measures if not implicit else ()):
        pressed = (m.counter > 0.0) & (m.depth > 0.0) & m.member
        if pressed.any():
            bounds["counter stability"] = min(bounds.get("counter stability", np.inf), float(
                (THETA * m.depth[pressed] / m.counter[pressed]).min()))
    if not bounds:
        return float("inf"), None
    which = min(bounds, key=bounds.get)
    return max(0, int(np.floor(bounds[which]))), which


def _jump_parts(model, parts, before_parts, part_rates, js, jump, factors=None, window=1,
                bodies_share=None):
    """Extrapolate each worn counter-part's wear per cycle in the last
    measurement (of ``window`` resolved cycles, ``before_parts`` the arrays
    at its start) over ``jump`` more cycles, each vertex's relieved by its
    factor of ``factors`` (per per-vertex surface: (factor, relative error)
    or None, :func:`meshwear.jumps.counter_factors`; None: explicit) (its
    vertices moved to their new depth, their faces' frames and the face
    tree renewed); return per part ``{name: (array at the jump's start, at
    its end)}`` for depth, volume, work and vertices. ``bodies_share``: the
    bodies' jumped volume over their volume in a cycle of the measurement
    (the part's own over the jump is its cycle's times that), or None."""
    spans = []
    for k, ((j, part), (_, volume0, work0), rate) in enumerate(
            zip(parts, before_parts, part_rates)):
        surface = model.surfaces.per_vertex[j]
        span = {name: getattr(part, name).copy() for name in PART_JUMPED}
        scale = np.full(len(rate), float(jump))
        relative = None
        if factors is not None and factors[j] is not None:
            scale = jump * factors[j][0]
            relative = factors[j][1]
            if bodies_share is not None:
                # the same contacts wear both parts: over the jump the part
                # wears the bodies' jumped volume times its share of it in
                # the measurement (its factors, carried from the bodies'
                # vertices over it at one phase, set where; a gear's wheel,
                # most of its flanks out of mesh at that phase, outwore the
                # pinion by a third)
                cycle = (part.volume - volume0) / window
                planned = float(scale @ cycle)
                if planned > 0.0:
                    scale = scale * (bodies_share * float(cycle.sum()) / planned)
        part.depth += scale * rate
        part.volume += scale / window * (part.volume - volume0)
        part.work += scale / window * (part.work - work0)
        moved = scale * rate != 0.0
        part.vertices[moved] = (surface.reference_vertices[moved]
                                - part.depth[moved, None] * surface.vertex_normals[moved])
        # the faces round the vertices the jump moved get their frames again
        # (a fine flat's scar is a few per cent of its faces)
        around = moved[surface.faces].any(axis=1)
        part.frames[around] = face_frames(part.vertices, surface.faces[around])
        surface.rebin()
        previous = js.part_rate[k]
        # the errors so far relax where the part wears (implicit jumps:
        # js.relax is the contact's time; explicit, none)
        _relax_part(js, k, rate > 0.0, jump)
        if relative is not None:
            js.part_error[k] += jump * rate * relative      # the bodies' implicit step's
        else:
            js.part_error[k] += _slope_error(rate, previous, js.gap, jump)
        if js.part_noise[k] is not None:
            # the noise of one measurement's rate, times the jump: random
            # from jump to jump, so the jumps' errors add in quadrature
            js.part_noise_var[k] += (jump * js.part_noise[k]) ** 2
        spans.append({name: (span[name], getattr(part, name).copy()) for name in PART_JUMPED})
    return spans


def _noise_bound(noise, variance, wearing, tolerance, deepest, fastest, relax, most):
    """The longest jump, at most ``most`` cycles, after which a worn
    counter-part's random errors of depth stay within the tolerance of the
    depth it will have, ``tol (deepest + J r)`` (``fastest`` its fastest
    rate r): per vertex, ``J`` times the noise ``noise`` (m per cycle) of
    the rate the jump extrapolates, random from jump to jump, so the jumps'
    errors add in quadrature (``variance`` so far, m^2), and the contact
    relaxes them over ``relax`` cycles (the inverse of its wear per cycle
    per unit penetration) where the part wears (``wearing``).

    Where the part does not wear, its errors so far stay as they are: no
    resolved cycle relaxes them, so waiting cannot bring one over the
    tolerance back within it (a vertex the scar's edge has left, its
    error admitted against a depth the jump did not quite reach), and
    such a vertex counts its errors so far up to the tolerance of today's
    depth only (:func:`_settled`); the jump adds to them its noise, if it
    has any."""
    frozen = _settled(variance, ~wearing, tolerance, deepest)

    def total(jump):
        decay = _decay(jump, relax)
        kept = np.where(wearing, variance * decay * decay, frozen)
        return float(np.sqrt((kept + (jump * noise) ** 2).max(initial=0.0)))

    return _within(total, tolerance, deepest, fastest, most)


def _settled(variance, still, tolerance, deepest):
    """``variance`` (m^2) of the random errors of depth, each of the
    vertices ``still`` (mask: out of contact, no resolved cycle relaxes
    them) counted up to the tolerance of today's depth ``deepest`` only.

    A jump's errors are admitted against the depth it plans (``deepest + J
    r``); where it deepens less (a contact's transient after a jump reads a
    faster ``r``) a vertex can be left over the tolerance, and once the
    contact has left it, refusing jumps cannot mend its error: held by it,
    a fretting run resolved 396 cycles in a row. The error itself stays
    in the estimate (:func:`error_estimate`)."""
    return np.where(still, np.minimum(variance, (tolerance * deepest) ** 2), variance)


def _relaxation(measures):
    """The cycles over which the contact relaxes an error of depth (the
    inverse of the median, over the vertices in contact, of their own and
    their counter-part's wear per cycle per unit penetration); inf when
    nothing wears."""
    rates = [_relax_rate(m)[m.member & (m.alpha > 0.0) & (m.mean > 0.0)]
             for m in measures or ()]
    rates = np.concatenate(rates) if rates else np.zeros(0)
    middle = float(np.median(rates)) if len(rates) else 0.0
    return 1.0 / middle if middle > 0.0 else np.inf


def _counter_noise(js, k, rate, t):
    """The sampling noise of worn counter-part ``k``'s wear per cycle (V,)
    (m): each vertex's scatter (:func:`_local_scatter`) of its rate
    ``rate`` (the one it settles to, :func:`meshwear.jumps.settled_rates`:
    the departure from it its own depth's error makes is no sampling noise)
    in this measurement (its middle at ``t``, cycles) and the ones
    before at the same window about their trend (the rates of a contact
    that widens fall cycle after cycle, and those of a vertex it reaches
    rise to their own: that is no noise). None before three measurements."""
    past = [(time, rates[k]) for time, _, rates in js.history if rates[k] is not None]
    if len(past) < 2:
        return None
    return _local_scatter(np.array([time for time, _ in past] + [t]),
                          np.vstack([r for _, r in past] + [rate]))


def _local_scatter(times, values):
    """(n,) the scatter of each column of ``values`` (K, n; K >= 3) measured
    at ``times`` (K,, increasing) about a trend that need not be a straight
    line: each inner measurement's distance from the line through its two
    neighbours, over the spread that distance has for independent
    measurements of one scatter (1 + a^2 + b^2 its variance, a and b the
    neighbours' weights), in quadrature over the inner measurements. A
    straight line through all of them (:func:`_fit`) would count as noise
    the bend of a trend over the measurements' span: a counter vertex that
    the widening contact reaches has its wear per cycle rise over tens of
    cycles and settle, and the measurements, a jump apart, span hundreds."""
    t0, t1, t2 = times[:-2], times[1:-1], times[2:]
    a, b = ((t2 - t1) / (t2 - t0))[:, None], ((t1 - t0) / (t2 - t0))[:, None]
    off = values[1:-1] - a * values[:-2] - b * values[2:]
    return np.sqrt((off * off / (1.0 + a * a + b * b)).mean(axis=0))


#: the arrays of a worn counter-part a jump extrapolates
PART_JUMPED = ("depth", "volume", "work", "vertices")


def _fresh_area(body, s, fresh, normal):
    """The area (m^2) over which the vertices ``fresh`` (mask) of ``body``
    (state ``s``) wear, pressed by the surfaces of world ``normal`` (n, 3):
    their area vectors across it."""
    local = normal[fresh] @ quaternion_matrix(s.pose[3:7])
    return np.maximum(-np.einsum("ij,ij->i", body.area_vectors[fresh, 0:3], local), 0.0)


def _wear_fresh(body, s, fresh, wear, normal, work_per_volume):
    """The worn volume and friction work of the wear ``wear[fresh]`` of
    vertices with no cycle increments to scale, pressed by the surfaces of
    world ``normal`` (n, 3) (their move is :func:`meshwear.jump_geometry.displacement`'s)."""
    depth = wear[fresh]
    volume = depth * _fresh_area(body, s, fresh, normal)
    s.wear_volume[fresh] += volume
    s.friction_work[fresh] += work_per_volume * volume


def _bodies_drift(js, bodies):
    """The largest drift error of depth of the bodies ``bodies`` (states),
    a vertex's plus the common part, over each one's deepest wear."""
    out = 0.0
    for k, s in enumerate(bodies):
        deepest = s.wear_depth.max() if len(s.wear_depth) else 0.0
        if deepest > 0.0 and k < len(js.drift) and len(js.drift[k]):
            common = abs(float(js.bias[k][0])) if k < len(js.bias) else 0.0
            out = max(out, float((js.drift[k].max() + common) / deepest))
    return out


def _largest(error, variances, k, drift=None, bias=None):
    """The largest error of depth (m) of a part: a vertex's step doubling
    ``error`` and drift's (``drift[k]``) plus the root of its variance
    (``variances[k]``: (n,), or a float of an older checkpoint), plus its
    common part (``bias[k]``)."""
    total = error + np.sqrt(variances[k] if k < len(variances) else 0.0)
    if drift is not None and k < len(drift) and len(drift[k]) == len(error):
        total = total + drift[k]
    common = _common(bias[k]) if bias is not None and k < len(bias) else 0.0
    return float(total.max(initial=0.0)) + common


def error_estimate(state):
    """Estimated relative error of the wear depth from the jumps (0 without)."""
    js = state.jump
    if js is None:
        return 0.0
    worst = 0.0
    for k, (error, s) in enumerate(zip(js.error, state.bodies)):
        deepest = s.wear_depth.max() if len(s.wear_depth) else 0.0
        if deepest > 0.0:
            worst = max(worst, _largest(error, js.noise_var, k, js.drift, js.bias) / deepest)
    # a worn counter-part, worn by the same contacts, has the bodies'
    # relative drift error besides its own
    worn = [p.depth for p in state.parts if p is not None]
    bodies = _bodies_drift(js, state.bodies) if worn else 0.0
    for k, (error, depth) in enumerate(zip(js.part_error, worn)):
        deepest = depth.max() if len(depth) else 0.0
        if deepest > 0.0:
            worst = max(worst, _largest(error, js.part_noise_var, k) / deepest + bodies)
    return worst
