"""Quasi-static load balance of a guided body along its free axis.

With no inertia and no damping, a guided body sits where the normal forces of
its contacts balance the applied load. Moving the body by ``z`` along the unit
free axis ``e`` changes the penetration of vertex ``i`` on plane ``s`` by
``z beta`` (``beta = e . n_s``), so the contact force along ``e`` is

    g(z) = sum over touching pairs of  w_j (z_j - z),
    w_j = c_j beta_j**2,   z_j = -Delta_j / beta_j,

a pair touching while ``z < z_j`` (``beta > 0``) or ``z > z_j`` (``beta < 0``).
``g`` is piecewise linear and never increases with ``z``, so ``g(z) = L`` has a
solution whenever some pair can push the way the load needs, and a bracketed
Newton iteration finds it: Newton steps are exact within one linear piece, and
a step leaving the bracket falls back to bisection, so it never diverges.

Only the pairs that can touch near the answer are iterated on: one pass
over every pair gives the breakpoints and ``g`` at the guess (the previous
step's offset), which bounds the answer from one side (``g`` at the guess, or
a Newton step from it, verified); the pairs that cannot touch beyond that
bound add nothing there and are set aside before the iteration. A body
pressed on a curved part has many active vertices within the active set's
margin but only its contact patch touching: the iteration costs the patch.

Arrays as in :mod:`meshwear.kernels.contact` (``area`` the (n, 4) area vectors,
``law`` the contact law; damping plays no part here).
"""

import numpy as np
from .jit import njit

from .contact import FACING, rotation_entries

#: iterations of the bracketed Newton solve before giving up (never reached in
#: practice: a piecewise-linear function needs a few)
MAX_ITERATIONS = 200


@njit(cache=True)
def _pairs(body_vertices, pose, axis, planes, vertex_planes, active, area, law, scale, guess,
           breakpoint, weight):
    """Fill ``breakpoint`` (z_j) and ``weight`` (w_j, signed as beta, times
    ``scale[i]`` of its vertex if ``scale`` is not empty) of every pair that
    can touch; return how many, and g and its slope magnitude at ``guess``
    (:func:`_force`, in the same pass)."""
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rotation_entries(pose[3:7])
    c0, c1 = law[5], law[6]
    n_planes = planes.shape[0]
    count = 0
    g = 0.0
    slope = 0.0
    for s in range(n_planes + vertex_planes.shape[0]):
        m = s - n_planes
        for k in range(active.shape[0]):
            i = active[k]
            # the plane's point and normal, read as scalars (a view per pair
            # would cost a reference count)
            if s < n_planes:
                ox, oy, oz = planes[s, 0, 0], planes[s, 0, 1], planes[s, 0, 2]
                nx, ny, nz = planes[s, 1, 0], planes[s, 1, 1], planes[s, 1, 2]
            else:
                ox, oy = vertex_planes[m, i, 0, 0], vertex_planes[m, i, 0, 1]
                oz = vertex_planes[m, i, 0, 2]
                nx, ny = vertex_planes[m, i, 1, 0], vertex_planes[m, i, 1, 1]
                nz = vertex_planes[m, i, 1, 2]
            beta = axis[0] * nx + axis[1] * ny + axis[2] * nz
            if beta == 0.0:
                continue
            mx = r00 * nx + r10 * ny + r20 * nz
            my = r01 * nx + r11 * ny + r21 * nz
            mz = r02 * nx + r12 * ny + r22 * nz
            a = -(mx * area[i, 0] + my * area[i, 1] + mz * area[i, 2])
            if a <= FACING * area[i, 3]:
                continue
            c = c0 + c1 * a
            if c <= 0.0:
                continue
            bx, by, bz = body_vertices[i, 0], body_vertices[i, 1], body_vertices[i, 2]
            px = pose[0] + r00 * bx + r01 * by + r02 * bz
            py = pose[1] + r10 * bx + r11 * by + r12 * bz
            pz = pose[2] + r20 * bx + r21 * by + r22 * bz
            delta = (px - ox) * nx + (py - oy) * ny + (pz - oz) * nz
            z = -delta / beta
            w = c * beta * beta * (1.0 if beta > 0.0 else -1.0)
            if scale.shape[0]:
                w *= scale[i]
            breakpoint[count] = z
            weight[count] = w
            if (w > 0.0 and guess < z) or (w < 0.0 and guess > z):
                g += abs(w) * (z - guess)
                slope += abs(w)
            count += 1
    return count, g, slope


@njit(cache=True, inline="always")
def _near(breakpoint, weight, count, load, guess, g, slope):
    """Move to the front of ``breakpoint`` and ``weight`` the pairs that can
    touch on the side of the answer that ``g`` (its value at ``guess``, and
    its slope magnitude there) bounds, and return how many, with the bound:
    a ``z`` at which ``g`` is no less (load > 0) or no more (load < 0) than
    ``load``. The others add nothing on that side. Returns ``count`` and NaN
    when no such bound is found (the load is zero, or nothing touches at the
    guess); the pairs are only reordered.

    The bound is the guess itself when ``g`` there already carries the load;
    else a Newton step from it (exact on the guess's linear piece, beyond
    the answer where ``g`` is convex), kept only if ``g`` of the pairs kept
    carries the load there (the others add nothing, so ``g`` does too).
    Either is taken a little short (10^-9 of the load's whole compliance),
    so that the rounding of the sums does not refuse it."""
    if load == 0.0 or not slope > 0.0:
        return count, np.nan
    sign = 1.0 if load > 0.0 else -1.0
    cut = guess if (g - load) * sign >= 0.0 else guess + (g - load) / slope
    # a little short of it, where g carries the load whatever the rounding of
    # the sums (a Newton step from the answer's own piece lands on it)
    cut -= sign * (1e-9 * abs(load) / slope + 1e-6 * abs(cut - guess))
    # the pairs pushing the load's way that touch beyond the cut, and every
    # pair pushing the other way, to the front
    kept = 0
    for j in range(count):
        if weight[j] * sign < 0.0 or (breakpoint[j] - cut) * sign > 0.0:
            breakpoint[kept], breakpoint[j] = breakpoint[j], breakpoint[kept]
            weight[kept], weight[j] = weight[j], weight[kept]
            kept += 1
    if (_force(cut, breakpoint, weight, kept)[0] - load) * sign < 0.0:
        return count, np.nan
    return kept, cut


@njit(cache=True)
def _force(z, breakpoint, weight, count):
    """g(z) and its slope magnitude (the stiffness of the touching pairs)."""
    g = 0.0
    slope = 0.0
    for j in range(count):
        w = weight[j]
        if (w > 0.0 and z < breakpoint[j]) or (w < 0.0 and z > breakpoint[j]):
            w = abs(w)
            g += w * (breakpoint[j] - z)
            slope += w
    return g, slope


@njit(cache=True)
def balance_offset(body_vertices, pose, axis, planes, vertex_planes, active, area, law, load,
                   guess, scratch, scale):
    """Offset ``z`` (m) along ``axis`` at which the contact normal forces on
    the body at ``pose`` add up to ``load`` (N) along ``axis``; with a
    non-empty ``scale`` (n,), the contact stiffness of vertex ``i`` times
    ``scale[i]`` (a wear jump: :mod:`meshwear.longrun.wear`).

    Returns NaN when no contact can push the way ``load`` needs (no plane
    faces the body along the axis, or the load pulls it away from every
    plane). ``guess`` (m) warm-starts the iteration: the previous step's
    offset is usually within one linear piece of the answer. ``scratch`` is a
    (2, k S) work array (``k`` active vertices, ``S`` surfaces), so a step
    allocates nothing. A mesh surface's planes are those of ``vertex_planes``
    (the faces under the vertices before the move).
    """
    breakpoint, weight = scratch[0], scratch[1]
    count, g, slope = _pairs(body_vertices, pose, axis, planes, vertex_planes, active, area, law,
                             scale, guess, breakpoint, weight)
    count, bound = _near(breakpoint, weight, count, load, guess, g, slope)
    return solve(breakpoint, weight, count, load, guess, bound)


@njit(cache=True)
def solve(breakpoint, weight, count, load, guess, bound):
    """The ``z`` at which ``g(z) = load`` for the first ``count`` pairs of
    ``breakpoint`` (z_j, m) and ``weight`` (w_j, N/m, signed as beta): the
    bracketed Newton iteration of :func:`balance_offset`; NaN when no pair
    pushes the way the load needs. ``bound``, unless NaN, is a ``z`` known
    to end the bracket on its side (``g`` no less than a positive load
    there, no more than a negative one)."""
    # the side that must carry the load: pairs pushing along +axis for a
    # positive load (beta > 0), along -axis for a negative one
    edge = np.nan
    push = 0.0
    for j in range(count):
        if (load >= 0.0) == (weight[j] > 0.0):
            push += abs(weight[j])
            if load >= 0.0:
                edge = breakpoint[j] if not edge >= breakpoint[j] else edge
            else:
                edge = breakpoint[j] if not edge <= breakpoint[j] else edge
    if push == 0.0:
        return np.nan
    # bracket [lo, hi] with g(lo) >= load >= g(hi): at the first touch on the
    # carrying side, then steps that double away from it
    step = max(abs(load) / push, 1e-300)
    if load >= 0.0:
        hi = edge
        lo = min(bound, hi) if bound == bound else hi - step
        while _force(lo, breakpoint, weight, count)[0] < load:
            step *= 2.0
            lo = hi - step
    else:
        lo = edge
        hi = max(bound, lo) if bound == bound else lo + step
        while _force(hi, breakpoint, weight, count)[0] > load:
            step *= 2.0
            hi = lo + step
    z = min(max(guess, lo), hi)
    tolerance = 1e-13 * max(abs(load), 1e-300)
    for _ in range(MAX_ITERATIONS):
        g, slope = _force(z, breakpoint, weight, count)
        if abs(g - load) <= tolerance:
            return z
        if g > load:
            lo = z
        else:
            hi = z
        if hi - lo <= 4e-16 * max(abs(lo), abs(hi)):
            return z
        trial = z + (g - load) / slope if slope > 0.0 else 0.5 * (lo + hi)
        z = trial if lo < trial < hi else 0.5 * (lo + hi)
    return z


@njit(cache=True)
def implicit_step(jump, alpha, gamma, member, touched, beta, stiffness, depth, now, load, guided):
    """One backward-Euler step of ``jump`` cycles of a body's jump
    (:func:`meshwear.longrun.jumps.implicit`; docs/model.md, "Long durations"), from
    the penetrations at the end of the cycle ``depth`` and while in contact
    ``now`` (k,): its wear (k,), the move ``z`` along the free axis (0
    unless ``guided``, or when no pair carries the load) and the
    penetration (k,) the step takes off (its own and the counter-parts'
    wear). Per vertex ``alpha`` and ``gamma`` (its and the counter's wear
    per cycle per unit penetration, 1 / cycle), ``beta`` the free axis along
    its normal, ``stiffness`` (N/m); ``member`` (the balance's pairs) and
    ``touched`` (touched during the cycle, not at its end) masks; ``load``
    (N) the balance's."""
    n = alpha.shape[0]
    z = 0.0
    if guided:
        # a member's end penetration after the step, (ahead - beta z) relief
        breaks, weights = np.empty(n), np.empty(n)
        count = 0
        for i in range(n):
            if member[i]:
                rate = alpha[i] + gamma[i]
                relief = 1.0 / (1.0 + jump * rate)
                ahead = depth[i] + jump * rate * (depth[i] - now[i])
                k = stiffness[i] * relief
                b = beta[i]
                if b != 0.0 and k > 0.0 and np.isfinite(ahead):
                    breaks[count] = ahead / b
                    weights[count] = k * b * abs(b)
                    count += 1
        if count:
            z = solve(breaks, weights, count, load, 0.0, np.nan)
            if not np.isfinite(z):
                z = 0.0
    # the penetration the step leaves (relieved), for members and touched
    # ones: the move takes the same off a touched vertex's penetration
    wear, taken = np.zeros(n), np.zeros(n)
    for i in range(n):
        if member[i] or touched[i]:
            rate = alpha[i] + gamma[i]
            relief = 1.0 / (1.0 + jump * rate)
            left = max(0.0, now[i] - beta[i] * z) * relief
            wear[i] = jump * alpha[i] * left
            taken[i] = jump * rate * left
    return wear, z, taken
