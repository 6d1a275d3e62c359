"""Wear of a mesh counter-part: each contact's wear on the face under it.

The contact points stay the worn body's vertices (docs/model.md, "Worn
counter-surfaces"). After the contact kernel, each pair of the step that
touches a worn counter mesh wears it by its law's volume on the counter's
own coefficient (:mod:`meshwear.kernels.laws`), from the same dissipated
energy, load and slip distance as the body's wear. The volume goes to the
three vertices of the face under the contact by the barycentric weights of
the contact point and, where the bodies' vertices stand for more area than
the counter's faces, on from each of them over the counter vertices around
it (its *spread*: the area the contact stands for, see ``spread`` below);
it becomes depth over each vertex's tributary area, and the vertex moves by
its depth along its inward normal; the faces around a moved vertex get their
frames again. So the counter's worn volume is its coefficient times the
pairs' load times slip (or energy), exactly.

A vertex moves once the depth it took since it last moved (its lag) reaches
:data:`LAG_FRACTION` of the smallest penetration of the pairs that wore it
since: a step wears a fine counter a thousandth of a contact's penetration
or less, and fitting its faces anew after every step cost more than the
face lookups (docs/model.md, "Worn counter-surfaces"). So a contact's
penetration is off by at most that fraction of itself; the depth, volume and
work are exact at every step, and :func:`settle_counter` moves every lagging
vertex (the runs call it before each output and at the end of every stretch
of steps, so outputs and jumps see the counter where its depth puts it).

Arrays (float64 unless said otherwise) besides those of
:mod:`meshwear.kernels.contact`:

planes : (n, 3, 3)
    The body's ``vertex_planes`` row of this surface (point, normal, velocity).
hint : (n,) int64
    The face under each vertex (``-1``: none).
rotation, frame : (3, 3), (4, 3)
    The surface's frame at the step (:func:`meshwear.kernels.frames.surface_frame`).
part : tuple
    The counter-part (:data:`PART_FIELDS`): law code and coefficient (2,),
    faces (F, 3) int64, reference vertices, outward unit vertex normals
    (V, 3), tributary areas (V,), local spacing (V,: the shortest edge at the
    vertex), the faces at each vertex (``starts`` (V + 1,) and ``items``
    int64), then what wear changes: vertices (V, 3), face frames (F, 4, 4),
    wear depth, worn volume, friction work (V,), each vertex's lag (V,:
    the depth it took since it last moved; zeros when settled), the
    lagging vertices (V,) int64, the lag at which each moves (V,; inf
    when not lagging), scratch (V,) int64, the number of lagging
    vertices (1,) int64 and each vertex's stiffness (V,, or (0,): not
    kept): the sum over the pairs that wore it of ``w^2 dV / (delta A)``
    (``w`` its weight, ``dV`` the pair's volume, ``delta`` its
    penetration, ``A`` the vertex's tributary area), by how much its wear in
    the step falls per unit of its own depth (docs/model.md, "Long
    durations"), then where each vertex is in the lagging list (V,) int64,
    -1 when it does not lag, so that one that moves leaves it at once,
    and its ``spread``, a tuple: ``starts`` (V + 1,) int64 and ``items``
    int32 (a face whose first corner ``k`` has more than one entry,
    ``items[starts[k]:starts[k + 1]]``, spreads over them), an empty
    array, each vertex's weight on itself in an even spread (V,), the
    spread's radius (1,) (m), each face's unworn area (F,),
    then what waits to be spread: ``pending`` (9, F) (the volume, m³, and
    energy, J, put on each face since it last spread, and the pairs'
    penetration, directions of sliding and contact points in the counter's
    frame, each times the volume it put there), the faces with some
    (F,) int64, each one's place among them (F,) int64,
    -1 for none, and their count (1,) int64; all empty where each vertex
    keeps its share (:meth:`meshwear.surfaces.MeshSurface.spread_over`).

A spreading part keeps each pair's wear waiting on the face under it (with
the point it was put at, weighed by volume) and spreads a face's waiting
wear from that point over the vertices around it once its depth there
reaches :data:`PENDING_FRACTION` of the lag at which a vertex moves (and
every face's in :func:`settle_counter`): a pair's wear is a thousandth of a
contact's penetration or less, and spreading each at once over its tens of
neighbours cost ten times the step; spread from the face's corners instead
of that point, the rows of body vertices beat against the counter's and
left the counter's depth 5 % uneven in stripes a few rows wide.
"""

import numpy as np
from numba import prange

from .jit import njit

from .contact import NO_CONTACT, SLIP, _named_copy, pieces, rotation_entries
from .laws import wear_increment
from .nearest import closest_on_triangle

PART_FIELDS = ("law", "faces", "reference", "normals", "tributary", "spacing", "starts", "items",
               "vertices", "frames", "depth", "volume", "work", "added", "touched", "limit",
               "due", "count", "stiffness", "place", "spread")

#: the part tuple of a surface that does not wear
NO_PART = (np.array([-1.0, 0.0]), np.zeros((0, 3), np.int64), np.zeros((0, 3)), np.zeros((0, 3)),
           np.zeros(0), np.zeros(0), np.zeros(1, np.int64), np.zeros(0, np.int64),
           np.zeros((0, 3)), np.zeros((0, 4, 4)), np.zeros(0), np.zeros(0), np.zeros(0),
           np.zeros(0), np.zeros(0, np.int64), np.zeros(0), np.zeros(0, np.int64),
           np.zeros(1, np.int64), np.zeros(0), np.zeros(0, np.int64),
           (np.zeros(0, np.int64), np.zeros(0, np.int32), np.zeros(0), np.zeros(0),
            np.zeros(1), np.zeros(0), np.zeros((9, 0)), np.zeros(0, np.int64),
            np.zeros(0, np.int64), np.zeros(1, np.int64)))

#: a counter vertex may sink by at most this fraction of its shortest edge in
#: one step; deeper, its faces could fold over
SPACING_FRACTION = 0.5

#: a counter vertex moves once its lag reaches this fraction of the smallest
#: penetration of the pairs that wore it since it last moved (or of its
#: shortest edge, if smaller)
LAG_FRACTION = 1e-2

#: a counter vertex takes a share of a spread only if its unworn normal is
#: within 60 degrees of the spread's (not across a crease or a thin wall)
SPREAD_FACING = 0.5

#: a spread along the direction its pairs slid in reaches this fraction of
#: its radius across it
ALONG = 0.18

#: a spreading part's vertex spreads what waits on it once its depth there
#: reaches this fraction of the lag at which a vertex moves
PENDING_FRACTION = 5.0

#: active vertices from which the pairs' shares are computed on threads
PARALLEL_PAIRS = 2048

#: moved counter vertices from which their faces are fitted anew on threads
#: (a fine worn flat under a pad: 5 000 vertices, 12 000 faces a step)
PARALLEL_REFIT = 32


@njit(cache=True, inline="always")
def _edge_line(frames, f, row, px, py, pz, qx, qy, qz, nx, ny, nz):
    """Row ``row`` of face ``f``'s frame: the in-plane unit normal of edge
    p -> q pointing out of the triangle, and its offset."""
    ex, ey, ez = qx - px, qy - py, qz - pz
    mx, my, mz = ey * nz - ez * ny, ez * nx - ex * nz, ex * ny - ey * nx
    length = np.sqrt(mx * mx + my * my + mz * mz)
    mx, my, mz = mx / length, my / length, mz / length
    frames[f, row, 0], frames[f, row, 1], frames[f, row, 2] = mx, my, mz
    frames[f, row, 3] = mx * px + my * py + mz * pz


@njit(cache=True, inline="always")
def _face_frame(vertices, faces, f, frames):
    """Frame of face ``f`` (:func:`meshwear.kernels.nearest.face_frames`), in place."""
    a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
    ax, ay, az = vertices[a, 0], vertices[a, 1], vertices[a, 2]
    bx, by, bz = vertices[b, 0], vertices[b, 1], vertices[b, 2]
    cx, cy, cz = vertices[c, 0], vertices[c, 1], vertices[c, 2]
    ux, uy, uz = bx - ax, by - ay, bz - az
    vx, vy, vz = cx - ax, cy - ay, cz - az
    nx, ny, nz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
    length = np.sqrt(nx * nx + ny * ny + nz * nz)
    nx, ny, nz = nx / length, ny / length, nz / length
    frames[f, 0, 0], frames[f, 0, 1], frames[f, 0, 2] = nx, ny, nz
    frames[f, 0, 3] = nx * ax + ny * ay + nz * az
    _edge_line(frames, f, 1, ax, ay, az, bx, by, bz, nx, ny, nz)
    _edge_line(frames, f, 2, bx, by, bz, cx, cy, cz, nx, ny, nz)
    _edge_line(frames, f, 3, cx, cy, cz, ax, ay, az, nx, ny, nz)


def _pairs(body_vertices, pose, active, area, law, contact_state, normal_force, planes, hint,
           rotation, frame, counter_law, faces, vertices, at, pairs):
    """Each pair's share of the step's wear on the counter, by slot of
    ``active``: ``at`` the face under it (-1: it wears nothing) and ``pairs``
    (m, 12) the barycentric weights of its contact point on that face, its
    dissipated energy (J), its worn volume (m³), its signed distance to the
    plane (m), the unit direction of its slip in the counter's frame (0 in
    stick) and its contact point there (m). Each pair on its own: the threaded build computes them on
    threads, and :func:`wear_counter` adds them up in slot order."""
    code, k_counter = int(counter_law[0]), counter_law[1]
    f, dt = law[0], law[4]
    dt0, dt1 = law[11], law[12]
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rotation_entries(pose[3:7])
    cx, cy, cz = pose[0], pose[1], pose[2]
    vx, vy, vz = pose[7], pose[8], pose[9]
    wx, wy, wz = pose[10], pose[11], pose[12]
    for slot in range(active.shape[0]):
        at[slot] = -1
        i = active[slot]
        state = contact_state[i]
        load = normal_force[i]
        face = hint[i]
        if state == NO_CONTACT or load <= 0.0 or face < 0:
            continue
        nx, ny, nz = planes[i, 1, 0], planes[i, 1, 1], planes[i, 1, 2]
        # the vertex, its foot on the plane and the contact area (as the
        # contact kernel has them)
        bx, by, bz = body_vertices[i, 0], body_vertices[i, 1], body_vertices[i, 2]
        rx = r00 * bx + r01 * by + r02 * bz
        ry = r10 * bx + r11 * by + r12 * bz
        rz = r20 * bx + r21 * by + r22 * bz
        px, py, pz = cx + rx, cy + ry, cz + rz
        delta = ((px - planes[i, 0, 0]) * nx + (py - planes[i, 0, 1]) * ny
                 + (pz - planes[i, 0, 2]) * nz)
        ax, ay, az = px - delta * nx, py - delta * ny, pz - delta * nz
        mx = r00 * nx + r10 * ny + r20 * nz
        my = r01 * nx + r11 * ny + r21 * nz
        mz = r02 * nx + r12 * ny + r22 * nz
        a = -(mx * area[i, 0] + my * area[i, 1] + mz * area[i, 2])
        if a <= 0.0:
            continue
        # slip velocity: the point's velocity relative to the surface there
        gx = vx + wy * rz - wz * ry - planes[i, 2, 0]
        gy = vy + wz * rx - wx * rz - planes[i, 2, 1]
        gz = vz + wx * ry - wy * rx - planes[i, 2, 2]
        rate = gx * nx + gy * ny + gz * nz
        sx, sy, sz = gx - rate * nx, gy - rate * ny, gz - rate * nz
        speed2 = sx * sx + sy * sy + sz * sz
        # the pair's dissipated energy and slip distance in the step
        speed = 0.0
        if state == SLIP:
            speed = np.sqrt(speed2)
            energy = f * load * speed * dt
            slip = speed * dt
        else:
            energy = (dt0 + dt1 * a) * speed2 * dt
            slip = 0.0
        dv = wear_increment(code, k_counter, energy, load, slip, a)[1]
        if dv <= 0.0 and energy <= 0.0:
            continue
        # the contact point in the counter's frame, its weights on the face
        ex, ey, ez = ax - frame[0, 0], ay - frame[0, 1], az - frame[0, 2]
        qx = rotation[0, 0] * ex + rotation[1, 0] * ey + rotation[2, 0] * ez
        qy = rotation[0, 1] * ex + rotation[1, 1] * ey + rotation[2, 1] * ez
        qz = rotation[0, 2] * ex + rotation[1, 2] * ey + rotation[2, 2] * ez
        j0, j1, j2 = faces[face, 0], faces[face, 1], faces[face, 2]
        weights = closest_on_triangle(
            qx, qy, qz, vertices[j0, 0], vertices[j0, 1], vertices[j0, 2],
            vertices[j1, 0], vertices[j1, 1], vertices[j1, 2],
            vertices[j2, 0], vertices[j2, 1], vertices[j2, 2])[3:6]
        at[slot] = face
        pairs[slot, 0], pairs[slot, 1], pairs[slot, 2] = weights
        pairs[slot, 3], pairs[slot, 4], pairs[slot, 5] = energy, dv, delta
        # its slip's direction in the counter's frame (0 in stick)
        if slip > 0.0:
            ux, uy, uz = sx / speed, sy / speed, sz / speed
            pairs[slot, 6] = rotation[0, 0] * ux + rotation[1, 0] * uy + rotation[2, 0] * uz
            pairs[slot, 7] = rotation[0, 1] * ux + rotation[1, 1] * uy + rotation[2, 1] * uz
            pairs[slot, 8] = rotation[0, 2] * ux + rotation[1, 2] * uy + rotation[2, 2] * uz
        else:
            pairs[slot, 6] = pairs[slot, 7] = pairs[slot, 8] = 0.0
        pairs[slot, 9], pairs[slot, 10], pairs[slot, 11] = qx, qy, qz


_pairs_serial = njit(cache=True)(_named_copy(_pairs, "_pairs_serial"))


def _pairs_threaded(body_vertices, pose, active, area, law, contact_state, normal_force, planes,
                    hint, rotation, frame, counter_law, faces, vertices, at, pairs):
    """:func:`_pairs` on pieces of ``active`` in threads (as the contact
    kernel's: :func:`meshwear.kernels.contact._threaded`)."""
    n = active.shape[0]
    chunks = pieces(n)
    for c in prange(chunks):
        lo, hi = c * n // chunks, (c + 1) * n // chunks
        _pairs_serial(body_vertices, pose, active[lo:hi], area, law, contact_state, normal_force,
                      planes, hint, rotation, frame, counter_law, faces, vertices, at[lo:hi],
                      pairs[lo:hi])


_pairs_parallel = njit(cache=True, parallel=True)(_named_copy(_pairs_threaded,
                                                              "_pairs_parallel"))


@njit(cache=True)
def wear_counter(body_vertices, pose, active, area, law, contact_state, normal_force, planes,
                 hint, rotation, frame, part, surface, log_index, log_value, log_count):
    """Wear the counter-part ``part`` by every pair of the step just taken
    (``contact_state``, ``normal_force``: this surface's rows), and move the
    vertices whose lag reached their limit. Returns -1, or the first counter
    vertex that sank deeper than :data:`SPACING_FRACTION` of its spacing
    since it last moved (the step is done all the same: the caller stops the
    run).

    While ``log_count[1]`` is 1 each pair's share of each counter vertex is
    logged, for the jumps (:func:`meshwear.longrun.jumps.pair_log`): row
    ``log_count[0]`` of ``log_index`` (per-vertex surface ``surface``, the
    body vertex, the counter vertex) and of ``log_value`` (the pair's
    normal force times its weight on the counter vertex, N);
    ``log_count[0]`` counts on past the rows (then the log is incomplete)."""
    (counter_law, faces, reference, normals, tributary, spacing, starts, items, vertices, frames,
     depth, volume, work, added, touched, limit, due, lagging, stiffness, place, spread) = part
    keep_stiffness = stiffness.shape[0] > 0
    spreading = spread[0].shape[0] > 0
    pending, pending_list, pending_place, pending_count = spread[6], spread[7], spread[8], spread[9]
    m = active.shape[0]
    at = np.empty(m, np.int64)
    pairs = np.empty((m, 12))
    if m >= PARALLEL_PAIRS:
        _pairs_parallel(body_vertices, pose, active, area, law, contact_state, normal_force,
                        planes, hint, rotation, frame, counter_law, faces, vertices, at, pairs)
    else:
        _pairs_serial(body_vertices, pose, active, area, law, contact_state, normal_force,
                      planes, hint, rotation, frame, counter_law, faces, vertices, at, pairs)
    # the lagging vertices' count, the moving ones', and whether one sank too deep
    count_moving = np.zeros(3, np.int64)
    count_moving[0] = lagging[0]
    logging = log_count[1] == 1
    rows = log_index.shape[0]
    for slot in range(m):
        face = at[slot]
        if face < 0:
            continue
        weights = (pairs[slot, 0], pairs[slot, 1], pairs[slot, 2])
        energy, dv, delta = pairs[slot, 3], pairs[slot, 4], pairs[slot, 5]
        for corner in range(3):
            k = faces[face, corner]
            weight = weights[corner]
            if weight <= 0.0:
                continue
            if logging:
                row = log_count[0]
                if row < rows:
                    log_index[row, 0] = surface
                    log_index[row, 1] = active[slot]
                    log_index[row, 2] = k
                    log_value[row] = weight * normal_force[active[slot]]
                log_count[0] = row + 1
            if not spreading or spread[0][faces[face, 0] + 1] - spread[0][faces[face, 0]] <= 1:
                _deposit(k, weight, energy, dv, delta, face, faces, weights, tributary, spacing,
                         depth, volume, work, added, touched, limit, due, stiffness, place,
                         keep_stiffness, count_moving)
            elif keep_stiffness and dv > 0.0 and delta < 0.0:
                # (what it keeps of its own share: its weight on itself)
                stiffness[k] -= weight * weight * dv * spread[3][k] / (delta * tributary[k])
        if spreading and spread[0][faces[face, 0] + 1] - spread[0][faces[face, 0]] > 1:
            _wait(face, pairs, slot, part, count_moving)
    count, moving, deep = count_moving[0], count_moving[1], count_moving[2] > 0
    worst = -1
    if deep:
        for c in range(count):
            j = touched[c]
            if added[j] > SPACING_FRACTION * spacing[j]:
                worst = j
                break
    # the moving vertices leave the lagging list (the last one takes each
    # one's place), so a step's bookkeeping is on its own pairs, not on all
    # the lagging vertices
    for c in range(moving):
        j = due[c]
        count -= 1
        last = touched[count]
        touched[place[j]] = last
        place[last] = place[j]
        place[j] = -1
    lagging[0] = count
    _move(part, moving)
    return worst


@njit(cache=True, inline="always")
def _deposit(j, share, energy, dv, delta, face, faces, weights, tributary, spacing, depth, volume,
             work, added, touched, limit, due, stiffness, place, keep_stiffness, count_moving):
    """Counter vertex ``j``'s ``share`` of a pair's energy ``energy`` (J) and
    volume ``dv`` (m³), the pair pressing ``delta`` (m, < 0) into ``face``
    at ``weights``: its work, volume, depth, lag (a vertex starts lagging, or
    is due to move once its lag reaches its limit) and stiffness; updates
    ``count_moving`` (the lagging and moving vertices' counts, and 1 in its
    last entry once a vertex sank deeper than SPACING_FRACTION of its
    spacing)."""
    work[j] += share * energy
    if dv > 0.0:
        volume[j] += share * dv
        sink = share * dv / tributary[j]
        depth[j] += sink
        if place[j] < 0:
            # it starts lagging
            place[j] = count_moving[0]
            touched[count_moving[0]] = j
            count_moving[0] += 1
        added[j] += sink
        # (-delta: the pair's penetration; none, and it moves now)
        lag = LAG_FRACTION * min(-delta, spacing[j])
        if lag < limit[j]:
            limit[j] = lag
        if added[j] >= limit[j] and limit[j] > -np.inf:
            # its lag reached its limit: it moves after the step
            # (limit -inf marks it for _refit)
            due[count_moving[1]] = j
            count_moving[1] += 1
            limit[j] = -np.inf
        if added[j] > SPACING_FRACTION * spacing[j]:
            count_moving[2] = 1
        if keep_stiffness and delta < 0.0:
            # its depth changes the pair's penetration by its own weight on
            # the face (0 off the face: a spread share)
            own = 0.0
            for corner in range(3):
                if faces[face, corner] == j:
                    own = weights[corner]
            stiffness[j] -= own * sink / delta


@njit(cache=True, inline="always")
def _wait(face, pairs, slot, part, count_moving):
    """Pair ``slot`` of ``pairs`` puts its wear on ``face`` of a spreading
    counter-part to wait there (volume, energy, its penetration, direction
    of sliding and contact point, each weighed by the volume), and the face
    spreads it once its depth there reaches :data:`PENDING_FRACTION` of the
    lag at which a vertex moves (:func:`_spread_face`)."""
    spacing, spread = part[5], part[20]
    face_area = spread[5]
    pending, pending_list, pending_place, pending_count = spread[6], spread[7], spread[8], spread[9]
    energy, dv, delta = pairs[slot, 3], pairs[slot, 4], pairs[slot, 5]
    if pending_place[face] < 0:
        pending_place[face] = pending_count[0]
        pending_list[pending_count[0]] = face
        pending_count[0] += 1
    pending[1, face] += energy
    if dv <= 0.0:
        return
    pending[0, face] += dv
    pending[2, face] -= dv * delta
    # the direction it slid in (either way along it: the sign that agrees
    # with the sum so far)
    ux, uy, uz = pairs[slot, 6], pairs[slot, 7], pairs[slot, 8]
    if ux * pending[3, face] + uy * pending[4, face] + uz * pending[5, face] < 0.0:
        ux, uy, uz = -ux, -uy, -uz
    pending[3, face] += dv * ux
    pending[4, face] += dv * uy
    pending[5, face] += dv * uz
    pending[6, face] += dv * pairs[slot, 9]
    pending[7, face] += dv * pairs[slot, 10]
    pending[8, face] += dv * pairs[slot, 11]
    faces = part[1]
    least = min(spacing[faces[face, 0]], spacing[faces[face, 1]], spacing[faces[face, 2]])
    if (pending[0, face] >= PENDING_FRACTION * LAG_FRACTION * face_area[face]
            * min(pending[2, face] / pending[0, face], least)):
        _spread_face(face, part, count_moving)


@njit(cache=True)
def _spread_face(face, part, count_moving):
    """Spread what waits on ``face`` of a spreading counter-part over the
    vertices around the point it was put at (the contact points weighed by
    volume; :func:`_deposit`, no stiffness: it was counted at the face's
    corners), and take it off the pending list. Vertex ``j`` at ``d_par,
    d_perp`` from that point along and across the pairs' mean direction of
    sliding takes ``(1 - d_perp²/R² - d_par²/R_par²)² A_j``, normalised
    (``R_par`` :data:`ALONG` times ``R``, or, if more, the mean of the face's
    mean and longest edges:
    the sliding spreads the wear along it; the spread is for the rows of body
    vertices across it); ``d²/R²`` in every direction where no direction is
    known (energy in stick); the face's corners by the point's weights where
    no vertex is within reach."""
    (_, faces, reference, _, tributary, spacing, _, _, _, _, depth, volume, work, added,
     touched, limit, due, _, stiffness, place, spread) = part
    starts, items, radius = spread[0], spread[1], spread[4][0]
    pending, pending_list, pending_place, pending_count = spread[6], spread[7], spread[8], spread[9]
    dv, energy = pending[0, face], pending[1, face]
    # (the pairs' penetration, weighed by the volume they put there)
    delta = -pending[2, face] / dv if dv > 0.0 else 0.0
    a, b, c = faces[face, 0], faces[face, 1], faces[face, 2]
    if dv > 0.0:
        px, py, pz = pending[6, face] / dv, pending[7, face] / dv, pending[8, face] / dv
    else:
        px = (reference[a, 0] + reference[b, 0] + reference[c, 0]) / 3.0
        py = (reference[a, 1] + reference[b, 1] + reference[c, 1]) / 3.0
        pz = (reference[a, 2] + reference[b, 2] + reference[c, 2]) / 3.0
    ux, uy, uz = pending[3, face], pending[4, face], pending[5, face]
    length = np.sqrt(ux * ux + uy * uy + uz * uz)
    along = radius
    if length > 0.0:
        ux, uy, uz = ux / length, uy / length, uz / length
        edges, longest = 0.0, 0.0
        for p, q in ((a, b), (b, c), (c, a)):
            e = np.sqrt((reference[p, 0] - reference[q, 0]) ** 2
                        + (reference[p, 1] - reference[q, 1]) ** 2
                        + (reference[p, 2] - reference[q, 2]) ** 2)
            edges += e
            longest = max(longest, e)
        along = max(ALONG * radius, 0.5 * (edges / 3.0 + longest))
    first, last = starts[a], starts[a + 1]
    total = 0.0
    shares = np.empty(last - first)
    for e in range(first, last):
        shares[e - first] = _weight(reference, tributary, items[e], px, py, pz, ux, uy, uz,
                                    length > 0.0, radius, along)
        total += shares[e - first]
    if total > 0.0:
        for e in range(first, last):
            share = shares[e - first] / total
            if share > 0.0:
                _deposit(items[e], share, energy, dv, delta, -1, faces, (0.0, 0.0, 0.0),
                         tributary, spacing, depth, volume, work, added, touched, limit, due,
                         stiffness, place, False, count_moving)
    else:
        weights = _corner_weights(reference, a, b, c, px, py, pz)
        for corner in range(3):
            if weights[corner] > 0.0:
                _deposit(faces[face, corner], weights[corner], energy, dv, delta, -1, faces,
                         (0.0, 0.0, 0.0), tributary, spacing, depth, volume, work, added, touched,
                         limit, due, stiffness, place, False, count_moving)
    for row in range(pending.shape[0]):
        pending[row, face] = 0.0
    # (the last one takes its place)
    pending_count[0] -= 1
    last = pending_list[pending_count[0]]
    pending_list[pending_place[face]] = last
    pending_place[last] = pending_place[face]
    pending_place[face] = -1


@njit(cache=True, inline="always")
def _weight(reference, tributary, j, px, py, pz, ux, uy, uz, directed, radius, along):
    """Vertex ``j``'s weight in a spread from ``p`` (:func:`_spread_face`;
    the list it is on holds only vertices whose normals are within 60
    degrees of its vertex's, :meth:`MeshSurface.spread_over`)."""
    dx, dy, dz = reference[j, 0] - px, reference[j, 1] - py, reference[j, 2] - pz
    d2 = dx * dx + dy * dy + dz * dz
    if directed:
        par = dx * ux + dy * uy + dz * uz
        r2 = (d2 - par * par) / (radius * radius) + par * par / (along * along)
    else:
        r2 = d2 / (radius * radius)
    return (1.0 - r2) * (1.0 - r2) * tributary[j] if r2 < 1.0 else 0.0


@njit(cache=True, inline="always")
def _corner_weights(reference, a, b, c, px, py, pz):
    """Barycentric weights of the closest point of triangle ``abc`` to ``p``."""
    return closest_on_triangle(px, py, pz, reference[a, 0], reference[a, 1], reference[a, 2],
                               reference[b, 0], reference[b, 1], reference[b, 2],
                               reference[c, 0], reference[c, 1], reference[c, 2])[3:6]


@njit(cache=True)
def settle_counter(part):
    """Spread whatever waits on a spreading counter-part's vertices, then
    move every lagging vertex of counter-part ``part`` to its depth (its
    faces fitted anew): the counter where its depth puts it. Returns -1, or
    a vertex the spreading sank deeper than :data:`SPACING_FRACTION` of its
    spacing since it last moved."""
    spread = part[20]
    count_moving = np.zeros(3, np.int64)
    count_moving[0] = part[17][0]
    while spread[9][0] > 0:
        _spread_face(spread[7][spread[9][0] - 1], part, count_moving)
    part[17][0] = count_moving[0]
    worst = -1
    if count_moving[2] > 0:
        for c in range(count_moving[0]):
            j = part[14][c]
            if part[13][j] > SPACING_FRACTION * part[5][j]:
                worst = j
                break
    touched, limit, due, lagging, place = part[14], part[15], part[16], part[17], part[19]
    count = lagging[0]
    for c in range(count):
        j = touched[c]
        due[c] = j
        limit[j] = -np.inf           # (marks the vertices moving now for _refit)
        place[j] = -1
    lagging[0] = 0
    _move(part, count)
    return worst


@njit(cache=True)
def _move(part, moving):
    """Move the first ``moving`` vertices of ``due`` (their limit -inf) to
    their depth and fit their faces anew."""
    (_, faces, reference, normals, _, _, starts, items, vertices, frames, depth, _, _, added,
     _, limit, due, _, _, _, _) = part
    if moving >= PARALLEL_REFIT:
        _refit_parallel(due, moving, limit, reference, depth, normals, vertices, faces,
                        frames, starts, items)
    elif moving > 0:
        _refit_serial(due, moving, limit, reference, depth, normals, vertices, faces, frames,
                      starts, items)
    for c in range(moving):
        j = due[c]
        added[j] = 0.0
        limit[j] = np.inf


def _refit(touched, count, marks, reference, depth, normals, vertices, faces, frames, starts,
           items):
    """Move the ``count`` vertices of ``touched`` to their depth along their
    normal, then fit the faces round them anew, each once: by its first
    moved corner (``marks`` below 0; a face under a patch has all three
    moved), so no two threads write one face."""
    for c in prange(count):
        j = touched[c]
        for col in range(3):
            vertices[j, col] = reference[j, col] - depth[j] * normals[j, col]
    for c in prange(count):
        j = touched[c]
        for e in range(starts[j], starts[j + 1]):
            face = items[e]
            first = j
            for corner in range(3):
                k = faces[face, corner]
                if marks[k] < 0.0 and k < first:
                    first = k
            if first == j:
                _face_frame(vertices, faces, face, frames)


_refit_serial = njit(cache=True)(_named_copy(_refit, "_refit_serial"))
_refit_parallel = njit(cache=True, parallel=True)(_named_copy(_refit, "_refit_parallel"))
