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

Arrays as in :mod:`meshwear.kernels.contact` (``area`` the (n, 4) area vectors,
``law`` the contact law; damping plays no part here).
"""

import numpy as np
from numba import njit

from .contact import FACING, rotation_entries

#: iterations of the bracketed Newton solve before giving up (never reached in
#: practice: a piecewise-linear function needs a few)
MAX_ITERATIONS = 200


@njit(cache=True)
def _pairs(body_vertices, pose, axis, planes, vertex_planes, active, area, law, scale, breakpoint,
           weight):
    """Fill ``breakpoint`` (z_j) and ``weight`` (w_j, signed as beta, times
    ``scale[i]`` of its vertex if ``scale`` is not empty) of every pair that
    can touch; return how many."""
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rotation_entries(pose[3:7])
    c0, c1 = law[5], law[6]
    n_planes = planes.shape[0]
    count = 0
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
            breakpoint[count] = -delta / beta
            weight[count] = c * beta * beta * (1.0 if beta > 0.0 else -1.0)
            if scale.shape[0]:
                weight[count] *= scale[i]
            count += 1
    return count


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
    ``scale[i]`` (a wear jump: :mod:`meshwear.wear`).

    Returns NaN when no contact can push the way ``load`` needs (no plane
    faces the body along the axis, or the load pulls it away from every
    plane). ``guess`` (m) warm-starts the iteration: the previous step's
    offset is usually within one linear piece of the answer. ``scratch`` is a
    (2, k S) work array (``k`` active vertices, ``S`` surfaces), so a step
    allocates nothing. A mesh surface's planes are those of ``vertex_planes``
    (the faces under the vertices before the move).
    """
    breakpoint, weight = scratch[0], scratch[1]
    count = _pairs(body_vertices, pose, axis, planes, vertex_planes, active, area, law, scale,
                   breakpoint, weight)
    return solve(breakpoint, weight, count, load, guess)


@njit(cache=True)
def solve(breakpoint, weight, count, load, guess):
    """The ``z`` at which ``g(z) = load`` for the first ``count`` pairs of
    ``breakpoint`` (z_j, m) and ``weight`` (w_j, N/m, signed as beta): the
    bracketed Newton iteration of :func:`balance_offset`; NaN when no pair
    pushes the way the load needs."""
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
        lo = hi - step
        while _force(lo, breakpoint, weight, count)[0] < load:
            step *= 2.0
            lo = hi - step
    else:
        lo = edge
        hi = lo + step
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
