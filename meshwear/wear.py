"""Long durations: cycle jumping with error control (docs/model.md, "Long durations").

Resolve one cycle of the motion with the ordinary step, measure each
vertex's wear in that cycle, extrapolate it over ``J`` cycles, then resolve
again. The extrapolation (``wear.jump``) is

implicit (default)
    a backward-Euler step in which each vertex's pressure is relieved by its
    own wear and a guided body's load re-balanced (:mod:`meshwear.jumps`):
    stable for any ``J``. ``J`` is the largest one whose error, estimated by
    step doubling (one jump of ``J`` against two of ``J / 2``) and by the
    drift of the wear per unit penetration between resolved cycles, stays
    under ``tolerance`` times the depth the jump adds where wear is fastest;
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
both: :func:`meshwear.jumps.counter_factors`), ``J`` bounded by the bodies'
implicit step, by the sampling noise of the counter's wear per cycle and by
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

from . import jumps
from .kernels.contact import ANCHOR
from .kernels.counter_wear import SPACING_FRACTION
from .kernels.nearest import face_frames
from .output import filled
from .surfaces import contact_areas, quaternion_matrix, slot_normals

#: largest wear in one explicit jump, as a fraction of a vertex's elastic penetration
THETA = 0.3
#: a jump is at most this many times the previous one, plus one
GROWTH = 2.0
#: vertices wearing less than this fraction of the fastest one per cycle do not
#: limit the jump (their rates are round-off or contact-edge flicker)
SIGNIFICANT = 1e-3


@dataclass
class JumpState:
    """The controller's memory, saved with checkpoints."""

    rate: list = field(default_factory=list)       # per body (n,) wear per cycle, last measured
    gap: float = 0.0                                # cycles between the last two measurements
    last_jump: int = 0
    jumps: int = 0
    resolved_steps: int = 0
    error: list = field(default_factory=list)      # per body (n,) estimated error of w (m)
    settling: bool = False                          # dynamic: the next cycle only settles
    alpha: list = field(default_factory=list)      # per body (n,) implicit: wear per cycle per
                                                    # unit penetration, last measured (0: none)
    limits: dict = field(default_factory=lambda: {"accuracy": 0, "growth": 0, "end": 0})
    part_rate: list = field(default_factory=list)  # per worn counter-part (V,) wear per
                                                    # cycle, last measured (or None)
    part_error: list = field(default_factory=list)  # per worn counter-part (V,) estimated
                                                     # error of its depth (m)
    part_noise: list = field(default_factory=list)  # per worn counter-part: the sampling
                                                     # noise of its wear per cycle (m), as
                                                     # last measured (None: not yet)
    # not saved with checkpoints: what the run has done since it (re)started,
    # for meshwear check's estimate
    last_limit: str | None = None                   # the bound that set the latest jump,
                                                    # or refused the latest cycle's
    fill_seconds: float = 0.0                       # wall time filling outputs from jumps
    filled_outputs: int = 0                         # outputs filled from jumps
    taken: list = field(default_factory=list)       # the jumps taken: (cycle it starts at,
                                                    # cycles, the bound that set it)
    cycle_start: int = 0                            # the step the cycle being resolved began at


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
    for body, s in zip(model.bodies, state.bodies):
        if s.load.shape[1] != len(s.wear_depth):
            s.load = np.zeros((2, len(s.wear_depth)))
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
        stop = min(start + n_c, model.n_steps)
        # the cycles a jump after this one may cover: the outputs in them are
        # filled from the states of this cycle at the same phase
        end_limit = max(0, (model.n_steps - stop - 1) // n_c)
        could = 0 if js.settling or forced_jump == 0 else min(
            end_limit, forced_jump if forced_jump is not None else int(GROWTH * js.last_jump + 1))
        snapshots = filled.record(model, state, start, stop, could, observers, progress,
                                  advance)
        js.resolved_steps += stop - start
        if stop - start < n_c or state.step >= model.n_steps:
            break
        if js.settling:
            js.settling = False
            continue
        rates = [s.wear_depth - b[0] for s, b in zip(state.bodies, before)]
        part_rates = [p.depth - b[0] for (_, p), b in zip(parts, before_parts)]
        measures = ([jumps.measure(model, body, s, rate, start)
                     for body, s, rate, start in zip(model.bodies, state.bodies, rates, starts)]
                    if implicit else None)
        part_limit, part_which = float("inf"), None
        if parts:
            increments = [None] * len(state.parts)
            for (j, _), rate in zip(parts, part_rates):
                increments[j] = rate
            for s, m in zip(state.bodies, measures):
                jumps.counter_relief(model, s, m, increments, state.time)
            if forced_jump is None:
                part_limit, part_which = _part_limit(model, parts, part_rates, js, measures,
                                                     tolerance, end_limit, implicit)
        if implicit:
            jump, which, results = _choose_implicit(measures, rates, js, end_limit,
                                                    int(min(could, part_limit)), tolerance,
                                                    forced_jump)
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
            results = [(jump * rate, 0.0, _slope_error(rate, previous, js.gap, jump))
                       for rate, previous in zip(rates, js.rate)]
        if jump > 0:
            for error, (_, _, estimate) in zip(js.error, results):
                error += estimate
            js.limits[which] = js.limits.get(which, 0) + 1
            js.last_limit = which
            factors = None
            if parts and implicit:
                # (before the jump moves the bodies: the feet at the cycle's end)
                factors = jumps.counter_factors(model, state, measures, results, rates, jump,
                                                increments, state.time)
            spans = _jump(model, state, before, rates, jump, results, measures)
            part_spans = _jump_parts(model, parts, before_parts, part_rates, js, jump, factors)
            before_fill = time.perf_counter()
            js.filled_outputs += filled.write(model, state, stop, jump, snapshots, spans,
                                              observers, check, part_spans)
            js.fill_seconds += time.perf_counter() - before_fill
            js.jumps += 1
            js.taken.append((stop / n_c, jump, which))
            js.settling = not model.quasi_static
        js.last_jump = jump
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
        js.gap = jump + 1.0 + (1.0 if js.settling else 0.0)
        if checkpoint is not None:
            checkpoint(model, state)
    return state


def _slope_error(rate, previous, gap, jump):
    """(n,) the slope criterion's estimate of an explicit jump's error (m)."""
    if previous is None:
        return np.zeros(len(rate))
    return 0.5 * np.abs(rate - previous) / max(gap, 1.0) * jump * jump


def _choose_implicit(measures, rates, js, end, could, tolerance, forced=None):
    """Cycles to jump over with implicit jumps, which bound set it, and per
    body the jump's ``(wear, move, error estimate)``.

    Bounds: ``end`` (the run ends with a resolved cycle), ``could`` (the
    growth bound the snapshots were taken for, or a forced jump), the drift
    of each vertex's wear per unit penetration between the last two
    measurements (``rho_alpha pbar J^2 / 2 <= tol J r_max``), and step
    doubling (the jump's estimated error ``<= tol J r_max``)."""
    fastest = max(float(r.max()) if len(r) else 0.0 for r in rates)
    if forced is not None:
        jump = min(end, could)
        return jump, "forced", _spread(measures, rates, jump)
    if fastest <= 0.0 or any(a is None for a in js.alpha):
        return 0, "accuracy", None
    bounds = {"end": float(end), "growth": float(could)}
    # per body, each measured vertex's drift of its wear per cycle, rho_i pbar_i
    drifts = []
    for m, previous in zip(measures, js.alpha):
        previous = previous[m.index]
        both = (m.mean > 0.0) & (previous > 0.0) & (m.alpha > 0.0)
        rate = np.zeros(len(m.index))
        rate[both] = np.abs(m.alpha[both] - previous[both]) / max(js.gap, 1.0) * m.mean[both]
        drifts.append(rate)
    drift = max(float(d.max(initial=0.0)) for d in drifts)
    if drift > 0.0:
        bounds["drift"] = 2.0 * tolerance * fastest / drift
    which = min(bounds, key=bounds.get)
    jump = int(np.floor(bounds[which]))
    for _ in range(12):
        if jump < 1:
            return 0, "accuracy", None
        results = [jumps.implicit(m, jump) for m in measures]
        worst = max(float(e.max(initial=0.0)) for _, _, e in results) / (tolerance * jump
                                                                          * fastest)
        if worst <= 1.0:
            # the error estimate: step doubling's, and the drift's over the jump
            results = [(w, z, e + 0.5 * d * jump * jump)
                       for (w, z, e), d in zip(results, drifts)]
            return jump, which, _spread(measures, rates, jump, results)
        # the error grows like J^2, its allowance like J
        jump, which = int(jump * min(0.9 / worst, 0.5 if worst > 2.0 else 0.9)), "accuracy"
    return 0, "accuracy", None


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


def _jump(model, state, before, rates, jump, results, measures=None):
    """Extrapolate the last resolved cycle over ``jump`` more cycles, each
    body's wear and move along its axis given by ``results``; return per body
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
        # vertex relieved by the jump wears, and dissipates, less
        factor = np.full(len(rate), float(jump))
        wearing = rate > 0.0
        factor[wearing] = wear[wearing] / rate[wearing]
        work = s.friction_work - work0
        volume = s.wear_volume - volume0
        s.vertices += factor[:, None] * (s.vertices - vertices0)
        s.wear_volume += factor * volume
        s.friction_work += factor * work
        fresh = ~wearing & (wear > 0.0)
        if fresh.any() and normal is not None:
            # a vertex the jump brought into contact had no cycle to scale:
            # it moves along its surface's normal, wears its depth times its
            # contact area, and dissipates what the contact does per volume
            _wear_fresh(body, s, fresh, wear, normal,
                        work[wearing].sum() / max(volume[wearing].sum(), 1e-300))
        s.wear_depth += wear
        span = {name: (span[name], getattr(s, name).copy()) for name in JUMPED}
        span["shift"] = z * body.motion.axis if z else np.zeros(3)
        spans.append(span)
    state.step += jump * model.cycle_steps
    state.time = state.step * model.dt
    state.resolved = False
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


def _part_limit(model, parts, part_rates, js, measures, tolerance, end, implicit=False):
    """The most cycles the worn counter-parts allow a jump, and the bound
    that sets it: a part vertex sinking by at most SPACING_FRACTION of its
    spacing per jump, the sampling noise of its wear per cycle within the
    tolerance, and, for explicit extrapolation, their slope criterion and
    the counter's wear under each body vertex within :data:`THETA` of its
    penetration. ``implicit``: the jump relieves the counter's wear as the
    body's (:func:`meshwear.jumps.counter_factors`): the bodies' implicit
    step bounds its accuracy and stability."""
    bounds = {}
    for k, ((j, part), rate, previous) in enumerate(zip(parts, part_rates, js.part_rate)):
        if rate.max(initial=0.0) <= 0.0:
            continue
        if previous is None:
            return 0, "counter accuracy"
        # a counter vertex's wear in one cycle is sampled by the steps of the
        # passes over it, and differs from cycle to cycle by that sampling
        # (a pass over a track's edge takes a few steps); a jump multiplies
        # one cycle's, so it is taken only where that noise stays within the
        # tolerance
        if _counter_noise(js, k, rate, previous) > tolerance * rate.max():
            return 0, "counter noise"
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


def _jump_parts(model, parts, before_parts, part_rates, js, jump, factors=None):
    """Extrapolate each worn counter-part's wear in the last resolved cycle
    over ``jump`` more cycles, each vertex's relieved by its factor of
    ``factors`` (per per-vertex surface: (factor, relative error) or None,
    :func:`meshwear.jumps.counter_factors`; None: explicit) (its vertices
    moved to their new depth, their faces' frames and the face tree
    renewed); return per part ``{name: (array at the jump's start, at its
    end)}`` for depth, volume, work and vertices."""
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
        part.depth += scale * rate
        part.volume += scale * (part.volume - volume0)
        part.work += scale * (part.work - work0)
        part.vertices[:] = (surface.reference_vertices
                            - part.depth[:, None] * surface.vertex_normals)
        part.frames[:] = face_frames(part.vertices, surface.faces)
        surface.rebin()
        previous = js.part_rate[k]
        if relative is not None:
            js.part_error[k] += jump * rate * relative      # the bodies' implicit step's
        else:
            js.part_error[k] += _slope_error(rate, previous, js.gap, jump)
        if previous is not None:
            js.part_error[k] += jump * _counter_noise(js, k, rate, previous)
        spans.append({name: (span[name], getattr(part, name).copy()) for name in PART_JUMPED})
    return spans


def _noise(rate, previous):
    """Half the largest change of a counter vertex's wear per cycle between
    two measurements: the sampling noise of one cycle's wear, at most."""
    return 0.5 * float(np.abs(rate - previous).max())


def _counter_noise(js, k, rate, previous):
    """The sampling noise of worn counter-part ``k``'s wear per cycle
    (:func:`_noise`), measured between two consecutive resolved cycles.
    Across a jump the change between the two measurements also holds the
    drift of the wear rate over the jumped cycles (the slope criterion's
    part), which grows with the jump: taken for noise, it refused jumps
    once they were long and the controller fell back to jumps of a few
    cycles (the gear pair past a few thousand revolutions). There the noise
    last measured between consecutive cycles stands."""
    if js.gap <= 1.0 or js.part_noise[k] is None:
        js.part_noise[k] = _noise(rate, previous)
    return js.part_noise[k]


#: the arrays of a worn counter-part a jump extrapolates
PART_JUMPED = ("depth", "volume", "work", "vertices")


def _wear_fresh(body, s, fresh, wear, normal, work_per_volume):
    """Wear ``wear[fresh]`` of vertices with no cycle increments to scale,
    pressed by the surfaces of world ``normal`` (n, 3)."""
    R = quaternion_matrix(s.pose[3:7])
    local = normal[fresh] @ R                    # the normal in the body frame
    direction = body.wear_direction[fresh] if len(body.wear_direction) else local
    depth = wear[fresh]
    s.vertices[fresh] += depth[:, None] * direction
    area = -np.einsum("ij,ij->i", body.area_vectors[fresh, 0:3], local)
    volume = depth * np.maximum(area, 0.0)
    s.wear_volume[fresh] += volume
    s.friction_work[fresh] += work_per_volume * volume


def error_estimate(state):
    """Estimated relative error of the wear depth from the jumps (0 without)."""
    js = state.jump
    if js is None:
        return 0.0
    worst = 0.0
    worn = [p.depth for p in state.parts if p is not None]
    for error, depth in zip(js.error + js.part_error, [s.wear_depth for s in state.bodies] + worn):
        deepest = depth.max() if len(depth) else 0.0
        if deepest > 0.0:
            worst = max(worst, float(error.max() / deepest))
    return worst
