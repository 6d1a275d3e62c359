"""Choosing a cycle jump: how many cycles to jump over, and which bound
set it (docs/model.md, "Long durations").

An explicit jump (:func:`choose_jump`) is bounded by the slope criterion, by
stability (no vertex wearing more than :data:`THETA` of its elastic
:func:`penetration`), by growth (:data:`GROWTH`) and by the run's end; an
implicit one (:func:`_choose_implicit`) by growth and the end, by the drift
and the noise of each vertex's wear per unit penetration and by step
doubling (their errors: :mod:`meshwear.longrun.jump_errors`), by the volume
its measurements give (:mod:`meshwear.longrun.jump_volume`) and by what it
does to the mesh (:mod:`meshwear.longrun.jump_geometry`). Worn counter-parts
bound either (:func:`_part_limit`). The controller that asks for the jump
and takes it is :mod:`meshwear.longrun.wear`.
"""

import numpy as np

from . import jumps
from ..kernels.counter_wear import SPACING_FRACTION
from ..surfaces import contact_areas, slot_normals
from .jump_errors import (_after, _alone, _drift_after, _drift_total, _noise_after,
                          _noise_bound, _relax_rate, _settled, _trend, _within)

#: largest wear in one explicit jump, as a fraction of a vertex's elastic penetration
THETA = 0.3
#: a jump is at most this many times the previous one, plus one
GROWTH = 2.0
#: vertices wearing less than this fraction of the fastest one per cycle do not
#: limit the jump (their rates are round-off or contact-edge flicker)
SIGNIFICANT = 1e-3


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
    with the volume kept (:func:`meshwear.longrun.jump_volume._keep_volume`)
    or None where the jump is too long; and ``fits(results)``, the mesh the jump moves
    (:func:`meshwear.longrun.jump_geometry.cut`: None, or the bound the results
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
                # penetration to hold (jump_volume._keep_volume)
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


def _part_limit(model, parts, part_rates, js, measures, tolerance, end, implicit=False,
                most=None):
    """The most cycles the worn counter-parts allow a jump, and the bound
    that sets it: a part vertex sinking by at most SPACING_FRACTION of its
    spacing per jump, the sampling noise of its wear per cycle within the
    tolerance, and, for explicit extrapolation, their slope criterion and
    the counter's wear under each body vertex within :data:`THETA` of its
    penetration. ``implicit``: the jump relieves the counter's wear as the
    body's (:func:`meshwear.longrun.jumps.counter_factors`): the bodies' implicit
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
