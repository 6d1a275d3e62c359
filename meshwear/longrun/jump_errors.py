"""The errors of cycle jumps, and how the contact relaxes them
(docs/model.md, "Long durations").

A jump holds each vertex's wear per unit penetration at its measured value:
its drift makes the jump wrong by ``rho_i pbar_i J^2 / 2``, its noise by
``J sigma_i``, random from jump to jump (:func:`_after`); an explicit jump's
change of rate by the slope criterion's (:func:`_slope_error`). The drift
and the noise are read from the measurements at one window by straight-line
fits (:func:`_trend`, :func:`_fit`), a worn counter-part's noise as the
scatter about a trend that may bend (:func:`_counter_noise`). The contact
relaxes an error of depth at its wear per cycle per unit penetration
(:func:`_relax_rate`, :func:`_relaxation`); :func:`_within` and
:func:`_noise_bound` find the longest jump whose errors stay within the
tolerance, and :func:`error_estimate` gives what the jumps have left, for
the run's summary.
"""

import numpy as np

def _slope_error(rate, previous, gap, jump):
    """(n,) the slope criterion's estimate of an explicit jump's error (m)."""
    if previous is None:
        return np.zeros(len(rate))
    return 0.5 * np.abs(rate - previous) / max(gap, 1.0) * jump * jump


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
    ``rate`` (the one it settles to, :func:`meshwear.longrun.jumps.settled_rates`:
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
