"""The counter face under each vertex: nearest-face queries on a mesh counter-surface.

A mesh counter-surface gives each vertex of a worn body the plane of its
nearest face (docs/model.md: then the same point-plane contact). A vertex
still over the face it had keeps it without a search; one that moved off it
walks across edges to the face it is over now and keeps that one alike;
otherwise it searches a bounding-volume tree over the faces
(:mod:`meshwear.kernels.tree`), in the surface's own frame, no farther than
the faces found, so a query costs O(log F) box tests and the faces near the
vertex, whatever the mesh's size and however far it looks. Built once per surface: the surface moves as a rigid body, so its
frame carries the tree; a worn one's boxes are grown by a slack and fitted
anew once its wear passes it.

Arrays (C-contiguous float64 unless said otherwise):

rotation : (3, 3)
    Counter frame -> world rotation at the query time.
motion : (4, 3)
    World position of the counter frame's origin (m), translational velocity
    (m/s), angular velocity (rad/s) and the point the rotation is about (m).
counter_vertices : (V, 3), faces : (F, 3) int64
    The counter mesh in its frame, its faces' normals pointing out of it (into
    the worn bodies).
frames : (F, 4, 4)
    Each face's plane and edge lines (:func:`face_frames`).
corner_normals : (F, 3, 3) or (0, 3, 3)
    Unit normals at each face's corners to interpolate over the face
    (smoothed normals, :func:`corner_normals`), or empty for the face normal.
search : (2,)
    The reach (m): faces farther are not found; unused.
boxes : (N, 6), nodes : (N, 2) int64, order : (F,) int64
    The faces' tree (:mod:`meshwear.kernels.tree`).
neighbours : (F, 3) int64
    The face across each edge (:func:`meshwear.kernels.tree.face_neighbours`).
"""

import numpy as np
from numba import prange

from .jit import njit

from .contact import _named_copy, pieces, rotation_entries  # noqa: F401  (re-exported for twins)
from .frames import to_frame
from .tree import STACK, box_distance2

#: faces a vertex that moved off its face walks across to find the one it is
#: over now (a step of fast sliding on a fine mesh crosses several)
WALK = 32

#: relative tolerance under which two faces count as equally near (a point
#: beyond a shared edge or vertex); the one whose plane separates more wins
TIE = 1e-9

#: a vertex that had a plane last step stays on the faces whose normal is
#: within 60 degrees of it (cos 60° = 0.5) while it is over one of them: a
#: vertex pressed into the top face of a counter-part close to its edge stays
#: on the top face instead of being pushed out sideways through the nearer
#: side face, and one that has gone past the middle of a thin plate is not
#: handed the far face (tunnelling). Faceted curved surfaces turn by far less
#: than 60° between neighbours. Beyond the edge of those faces it takes the
#: nearest face, as an untracked vertex does.
TRACKING = 0.5

#: a vertex lets go of the face it keeps (TRACKING) once it is deeper under
#: that face than this many times its distance to the nearest face: a vertex
#: swept sideways into a counter-part at the depth of the elastic approach
#: (a turning body passing over a pin's edge) came in through the side face
#: but belongs to the top one (hundreds of times deeper under the side than
#: under the top); a vertex pressed into a face near its edge (depth a few
#: times its distance to the edge) or most of the way through a thin plate
#: (94 %) keeps its face. The check costs a scan only where the vertex is
#: deeper under its face than this many times the foot's distance to the
#: face's crease edges (:func:`_to_crease`): an edge to a face that
#: continues the surface (within TRACKING) is no way in, so a vertex pressed
#: into a fine flat right over an edge between two of its faces (a body
#: meshed on the same grid) keeps its face without a search.
RELEASE = 16.0

#: a vertex is over a face when the foot of it on the face's plane lies in
#: the triangle or less than this fraction of the reach outside it (an edge
#: between two faces belongs to both)
OVER = 1e-9


@njit(cache=True, inline="always")
def closest_on_triangle(px, py, pz, ax, ay, az, bx, by, bz, cx, cy, cz):
    """Closest point of triangle abc to p and its barycentric weights
    (Ericson, Real-Time Collision Detection, 5.1.5): (qx, qy, qz, u, v, w)."""
    abx, aby, abz = bx - ax, by - ay, bz - az
    acx, acy, acz = cx - ax, cy - ay, cz - az
    apx, apy, apz = px - ax, py - ay, pz - az
    d1 = abx * apx + aby * apy + abz * apz
    d2 = acx * apx + acy * apy + acz * apz
    if d1 <= 0.0 and d2 <= 0.0:
        return ax, ay, az, 1.0, 0.0, 0.0
    bpx, bpy, bpz = px - bx, py - by, pz - bz
    d3 = abx * bpx + aby * bpy + abz * bpz
    d4 = acx * bpx + acy * bpy + acz * bpz
    if d3 >= 0.0 and d4 <= d3:
        return bx, by, bz, 0.0, 1.0, 0.0
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        v = d1 / (d1 - d3)
        return ax + v * abx, ay + v * aby, az + v * abz, 1.0 - v, v, 0.0
    cpx, cpy, cpz = px - cx, py - cy, pz - cz
    d5 = abx * cpx + aby * cpy + abz * cpz
    d6 = acx * cpx + acy * cpy + acz * cpz
    if d6 >= 0.0 and d5 <= d6:
        return cx, cy, cz, 0.0, 0.0, 1.0
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        w = d2 / (d2 - d6)
        return ax + w * acx, ay + w * acy, az + w * acz, 1.0 - w, 0.0, w
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return bx + w * (cx - bx), by + w * (cy - by), bz + w * (cz - bz), 0.0, 1.0 - w, w
    denom = 1.0 / (va + vb + vc)
    v = vb * denom
    w = vc * denom
    return (ax + abx * v + acx * w, ay + aby * v + acy * w, az + abz * v + acz * w,
            1.0 - v - w, v, w)


@njit(cache=True, inline="always")
def _along(frames, f, row, x, y, z):
    """Signed distance of (x, y, z) past line/plane ``row`` of face ``f``'s frame."""
    return frames[f, row, 0] * x + frames[f, row, 1] * y + frames[f, row, 2] * z - frames[f, row, 3]


@njit(cache=True)
def _to_crease(frames, neighbours, f, x, y, z):
    """Distance (m) from the foot of (x, y, z) on face ``f``'s plane to the
    nearest of its edge lines across which the surface turns by more than
    TRACKING allows (a crease) or ends (a border); inf when it has none."""
    nearest = np.inf
    for e in range(3):
        g = neighbours[f, e]
        if g >= 0 and (frames[f, 0, 0] * frames[g, 0, 0] + frames[f, 0, 1] * frames[g, 0, 1]
                       + frames[f, 0, 2] * frames[g, 0, 2]) >= TRACKING:
            continue
        nearest = min(nearest, max(-_along(frames, f, e + 1, x, y, z), 0.0))
    return nearest


@njit(cache=True, inline="always")
def _released(frames, neighbours, f, delta, outside, x, y, z):
    """A vertex over face ``f`` (``outside`` <= 0: the foot's signed
    distance past its nearest edge), ``delta`` from its plane, lets go of it
    (:data:`RELEASE`): deeper under it than RELEASE times its distance to the
    face's crease edges."""
    if not (delta < 0.0 and -delta > RELEASE * max(-outside, 0.0)):
        return False
    return -delta > RELEASE * _to_crease(frames, neighbours, f, x, y, z)


@njit(cache=True, inline="always")
def _consider(f, yx, yy, yz, frames, faces, counter_vertices, reach2, over, grow, tracked,
              tx, ty, tz, walked, best, best_d2, best_delta, kept, kept_d2, kept_delta):
    """Face ``f`` against the nearest face so far (best) and the nearest the
    vertex can stay on (kept, TRACKING): both, updated. ``walked``: a face
    of the walk from the vertex's last face, which it may stay on however
    far; the others only if no farther than the nearest face or the kept one."""
    delta = _along(frames, f, 0, yx, yy, yz)
    if delta * delta > reach2:
        return best, best_d2, best_delta, kept, kept_d2, kept_delta
    # how far the foot of y on the plane lies outside the triangle's
    # edges: its distance to the face is at least that
    outside = max(_along(frames, f, 1, yx, yy, yz), _along(frames, f, 2, yx, yy, yz),
                  _along(frames, f, 3, yx, yy, yz))
    return _consider_at(f, delta, outside, yx, yy, yz, frames, faces, counter_vertices, reach2,
                        over, grow, tracked, tx, ty, tz, walked, best, best_d2, best_delta, kept,
                        kept_d2, kept_delta)


@njit(cache=True, inline="always")
def _consider_at(f, delta, outside, yx, yy, yz, frames, faces, counter_vertices, reach2, over,
                 grow, tracked, tx, ty, tz, walked, best, best_d2, best_delta, kept, kept_d2,
                 kept_delta):
    """:func:`_consider` given the vertex's signed distance to face ``f``'s
    plane (``delta``) and how far its foot lies past the face's nearest edge
    (``outside``), as the walk has them."""
    plane2 = delta * delta
    if plane2 > reach2:
        return best, best_d2, best_delta, kept, kept_d2, kept_delta
    bound = plane2 + outside * outside if outside > 0.0 else plane2
    if bound > reach2 or (bound > best_d2 * grow
                          and (not (tracked and (walked or kept >= 0)) or bound > kept_d2 * grow)):
        return best, best_d2, best_delta, kept, kept_d2, kept_delta
    if outside <= 0.0:
        d2 = plane2        # the foot is on the face
    else:
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        cx, cy, cz, cu, cv, cw = closest_on_triangle(
            yx, yy, yz,
            counter_vertices[a, 0], counter_vertices[a, 1], counter_vertices[a, 2],
            counter_vertices[b, 0], counter_vertices[b, 1], counter_vertices[b, 2],
            counter_vertices[c, 0], counter_vertices[c, 1], counter_vertices[c, 2])
        d2 = (yx - cx) ** 2 + (yy - cy) ** 2 + (yz - cz) ** 2
        if d2 > reach2:
            return best, best_d2, best_delta, kept, kept_d2, kept_delta
    tie = TIE * max(d2, best_d2 if best >= 0 else d2)
    if best < 0 or d2 < best_d2 - tie or (d2 <= best_d2 + tie and delta > best_delta):
        best, best_d2, best_delta = f, d2, delta
    if (tracked and outside <= over
            and _along(frames, f, 0, tx, ty, tz) + frames[f, 0, 3] >= TRACKING):
        tie = TIE * max(d2, kept_d2 if kept >= 0 else d2)
        if kept < 0 or d2 < kept_d2 - tie or (d2 <= kept_d2 + tie and delta > kept_delta):
            kept, kept_d2, kept_delta = f, d2, delta
    return best, best_d2, best_delta, kept, kept_d2, kept_delta


# (the flags of the queries that call it)
@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def _search_tree(yx, yy, yz, frames, faces, counter_vertices, boxes, nodes, order, reach2, over,
                 grow, tracked, tx, ty, tz, best, best_d2, best_delta, kept, kept_d2, kept_delta):
    """The faces of the tree's nodes whose boxes come within reach and nearer
    than the faces found (:func:`_consider`), nearer child first: best and
    kept, updated. Out of the query's loop (a vertex that walked onto its
    face needs none), so that the loop stays small."""
    stack = np.empty(STACK, np.int64)
    stack[0] = 0
    top = 1
    while top > 0:
        top -= 1
        node = stack[top]
        bound = box_distance2(boxes, node, yx, yy, yz)
        if bound > reach2 or (bound > best_d2 * grow
                              and (kept < 0 or bound > kept_d2 * grow)):
            continue
        first, count = nodes[node, 0], nodes[node, 1]
        if count > 0:
            for e in range(first, first + count):
                best, best_d2, best_delta, kept, kept_d2, kept_delta = _consider(
                    order[e], yx, yy, yz, frames, faces, counter_vertices, reach2,
                    over, grow, tracked, tx, ty, tz, False, best, best_d2,
                    best_delta, kept, kept_d2, kept_delta)
            continue
        near = box_distance2(boxes, first, yx, yy, yz)
        far = box_distance2(boxes, first + 1, yx, yy, yz)
        if near <= far:
            stack[top] = first + 1
            stack[top + 1] = first
        else:
            stack[top] = first
            stack[top + 1] = first + 1
        top += 2
    return best, best_d2, best_delta, kept, kept_d2, kept_delta


# About 200 lines, and on purpose: the loop over the active vertices, with
# the counter frame's motion and the body's pose read once into scalars
# before it (read from the arrays, they would be read again for each vertex
# after each write to ``out``); the face tests and the tree search it falls
# back on are functions of their own (:func:`_consider_at`, :func:`_released`,
# :func:`_search_tree`).
def _nearest_planes(body_vertices, pose, active, rotation, motion, counter_vertices, faces,
                    frames, corner_normals, search, boxes, nodes, order, neighbours, out,
                    distance, hint, fixed, steady):
    r = rotation_entries(pose[3:7])
    smooth = corner_normals.shape[0] > 0
    flat = not smooth
    reach2 = search[0] * search[0]
    over = OVER * search[0]
    grow = 1.0 + 2.0 * TIE
    # the counter frame's origin, velocity, turn and its centre, as scalars
    # (read once, not again after each write to out)
    o0, o1, o2 = motion[0, 0], motion[0, 1], motion[0, 2]
    v0, v1, v2 = motion[1, 0], motion[1, 1], motion[1, 2]
    w0, w1, w2 = motion[2, 0], motion[2, 1], motion[2, 2]
    c0, c1, c2 = motion[3, 0], motion[3, 1], motion[3, 2]
    # and the body's position and the frame's rotation (frames.offset and
    # frames.to_frame, inlined on scalars: read from the arrays, they would be
    # read again for every vertex, after each write to out)
    p0, p1, p2 = pose[0], pose[1], pose[2]
    q00, q01, q02 = rotation[0, 0], rotation[0, 1], rotation[0, 2]
    q10, q11, q12 = rotation[1, 0], rotation[1, 1], rotation[1, 2]
    q20, q21, q22 = rotation[2, 0], rotation[2, 1], rotation[2, 2]
    for k in range(active.shape[0]):
        # unsigned, so that indexing skips numpy's negative-index wrap-around
        i = np.uint64(active[k])
        # world position, then counter frame: y = Rc^T (x - origin)
        bx, by, bz = body_vertices[i, 0], body_vertices[i, 1], body_vertices[i, 2]
        ex = p0 + r[0] * bx + r[1] * by + r[2] * bz - o0
        ey = p1 + r[3] * bx + r[4] * by + r[5] * bz - o1
        ez = p2 + r[6] * bx + r[7] * by + r[8] * bz - o2
        yx = q00 * ex + q10 * ey + q20 * ez
        yy = q01 * ex + q11 * ey + q21 * ez
        yz = q02 * ex + q12 * ey + q22 * ez
        # the normal it was given last step (world), zero if none: a vertex
        # keeps to the faces it came from (TRACKING)
        ox, oy, oz = out[i, 1, 0], out[i, 1, 1], out[i, 1, 2]
        tracked = ox != 0.0 or oy != 0.0 or oz != 0.0
        # the previous normal in the counter frame
        tx, ty, tz = 0.0, 0.0, 0.0
        if tracked and not (fixed and flat):
            tx, ty, tz = to_frame(rotation, ox, oy, oz)
        # the nearest face, and the nearest of the faces the vertex can stay
        # on (within TRACKING of its last normal, and with the vertex over
        # it, not beyond its edges: past a convex edge the vertex lets go)
        best = kept = -1
        best_d2 = kept_d2 = np.inf
        best_delta = kept_delta = -np.inf
        by_hint = onto = False
        h = hint[i]
        # (the foot's distances past the edges of face h, for the walk)
        a0 = a1 = a2 = 0.0
        if tracked and h >= 0:
            # still over the face it had, within reach and TRACKING: it stays
            # there, no search (the search would pick it too, unless the
            # vertex is over two such faces at once, at a concave fold)
            delta = _along(frames, h, 0, yx, yy, yz)
            a0 = _along(frames, h, 1, yx, yy, yz)
            a1 = _along(frames, h, 2, yx, yy, yz)
            a2 = _along(frames, h, 3, yx, yy, yz)
            outside = max(a0, a1, a2)
            # (a flat face of a surface that does not turn in its frame: the
            # normal the vertex holds is that face's own, TRACKING holds)
            if (delta * delta <= reach2 and outside <= over
                    and ((fixed and flat)
                         or _along(frames, h, 0, tx, ty, tz) + frames[h, 0, 3] >= TRACKING)
                    and not _released(frames, neighbours, h, delta, outside, yx, yy, yz)):
                kept, kept_d2, kept_delta = h, delta * delta, delta
                by_hint = True
        if kept < 0:
            if tracked and fixed and flat:
                tx, ty, tz = to_frame(rotation, ox, oy, oz)
            if tracked and h >= 0:
                # it has moved off its face: walk across the edge its foot is
                # farthest beyond, face by face while they keep within
                # TRACKING, to the face it is over now (WALK faces at most)
                f = h
                back, back_beyond = -1, 0.0
                for step in range(WALK):
                    if step > 0:
                        a0 = _along(frames, f, 1, yx, yy, yz)
                        a1 = _along(frames, f, 2, yx, yy, yz)
                        a2 = _along(frames, f, 3, yx, yy, yz)
                    edge, beyond = 0, a0
                    if a1 > beyond:
                        edge, beyond = 1, a1
                    if a2 > beyond:
                        edge, beyond = 2, a2
                    if beyond <= over:
                        # over it: it stays there, as on its own face, if it
                        # may (TRACKING, reach) and is not deep under it
                        best, best_d2, best_delta, kept, kept_d2, kept_delta = _consider_at(
                            f, _along(frames, f, 0, yx, yy, yz), max(a0, a1, a2), yx, yy, yz,
                            frames, faces, counter_vertices, reach2, over, grow, tracked,
                            tx, ty, tz, True, best, best_d2, best_delta, kept, kept_d2,
                            kept_delta)
                        if kept == f and not _released(frames, neighbours, f, kept_delta,
                                                       beyond, yx, yy, yz):
                            onto = True
                        break
                    if neighbours[f, edge] == back:
                        # over the fold between it and the face it came from:
                        # two faces at an angle leave a strip along their
                        # edge (as wide as the vertex's distance times the
                        # angle: nanometres on a worn flat) whose points have
                        # their foot beyond the edge on both. There it is
                        # over both, and takes the nearer (the one whose
                        # plane separates more, as equally near faces), which
                        # way it came whatever
                        for g, past in ((back, back_beyond), (f, beyond)):
                            best, best_d2, best_delta, kept, kept_d2, kept_delta = _consider(
                                g, yx, yy, yz, frames, faces, counter_vertices, reach2,
                                max(over, past), grow, tracked, tx, ty, tz, True, best, best_d2,
                                best_delta, kept, kept_d2, kept_delta)
                        if ((kept == f or kept == back)
                                and not _released(frames, neighbours, kept, kept_delta,
                                                  back_beyond if kept == back else beyond,
                                                  yx, yy, yz)):
                            onto = True
                        break
                    g = neighbours[f, edge]
                    if g < 0 or _along(frames, g, 0, tx, ty, tz) + frames[g, 0, 3] < TRACKING:
                        break                   # a border, or a crease it does not follow
                    back, back_beyond = f, beyond
                    f = g
            walked = kept >= 0
            # the tree's nodes whose boxes come within reach and nearer than
            # the faces found (the face the walk reached, if the vertex can
            # stay on it), nearer child first
            if (not onto and boxes.shape[0] > 0
                    and box_distance2(boxes, 0, yx, yy, yz) <= reach2):
                best, best_d2, best_delta, kept, kept_d2, kept_delta = _search_tree(
                    yx, yy, yz, frames, faces, counter_vertices, boxes, nodes, order, reach2,
                    over, grow, tracked, tx, ty, tz, best, best_d2, best_delta, kept, kept_d2,
                    kept_delta)
            if kept >= 0 and not walked and kept_d2 > best_d2 * grow:
                kept = -1               # not reached by the walk, and not the nearest
        if (kept >= 0 and not by_hint and not onto and kept_delta < 0.0 and best >= 0
                and kept_delta * kept_delta > RELEASE * RELEASE * best_d2):
            kept = -1                    # deep under it, near another face: let go
        if kept >= 0:
            best, best_d2, best_delta = kept, kept_d2, kept_delta
        hint[i] = best
        if best < 0:
            for row in range(3):
                for col in range(3):
                    out[i, row, col] = 0.0
            distance[i] = np.inf
            continue
        # over its face, a vertex's distance to it is its distance to the plane
        distance[i] = abs(best_delta) if by_hint else np.sqrt(best_d2)
        if by_hint and steady and fixed and flat:
            # the same face of a surface that stays where it is: the plane it
            # holds (point, normal) is still right; the velocity is the one at
            # the vertex's foot, which moves with the body
            lx = ex + o0 - best_delta * ox - c0
            ly = ey + o1 - best_delta * oy - c1
            lz = ez + o2 - best_delta * oz - c2
            out[i, 2, 0] = v0 + w1 * lz - w2 * ly
            out[i, 2, 1] = v1 + w2 * lx - w0 * lz
            out[i, 2, 2] = v2 + w0 * ly - w1 * lx
            continue
        hx, hy, hz = frames[best, 0, 0], frames[best, 0, 1], frames[best, 0, 2]
        if smooth:
            # the normal interpolated at the closest point of the face
            a, b, c = faces[best, 0], faces[best, 1], faces[best, 2]
            qx, qy, qz, u, v, w = closest_on_triangle(
                yx, yy, yz,
                counter_vertices[a, 0], counter_vertices[a, 1], counter_vertices[a, 2],
                counter_vertices[b, 0], counter_vertices[b, 1], counter_vertices[b, 2],
                counter_vertices[c, 0], counter_vertices[c, 1], counter_vertices[c, 2])
            cn = corner_normals[best]
            hx = u * cn[0, 0] + v * cn[1, 0] + w * cn[2, 0]
            hy = u * cn[0, 1] + v * cn[1, 1] + w * cn[2, 1]
            hz = u * cn[0, 2] + v * cn[1, 2] + w * cn[2, 2]
            length = np.sqrt(hx * hx + hy * hy + hz * hz)
            hx, hy, hz = hx / length, hy / length, hz / length
        else:
            # the face's plane: the foot of y on it (its closest point when
            # that is inside the face)
            qx, qy, qz = yx - best_delta * hx, yy - best_delta * hy, yz - best_delta * hz
        # back to the world: point, normal, and the counter-surface's velocity there
        if by_hint and fixed and flat:
            # the same face, the same frame: the normal it holds, its foot
            # straight from its world position
            px = ex + o0 - best_delta * ox
            py = ey + o1 - best_delta * oy
            pz = ez + o2 - best_delta * oz
        else:
            px = rotation[0, 0] * qx + rotation[0, 1] * qy + rotation[0, 2] * qz + o0
            py = rotation[1, 0] * qx + rotation[1, 1] * qy + rotation[1, 2] * qz + o1
            pz = rotation[2, 0] * qx + rotation[2, 1] * qy + rotation[2, 2] * qz + o2
            out[i, 1, 0] = rotation[0, 0] * hx + rotation[0, 1] * hy + rotation[0, 2] * hz
            out[i, 1, 1] = rotation[1, 0] * hx + rotation[1, 1] * hy + rotation[1, 2] * hz
            out[i, 1, 2] = rotation[2, 0] * hx + rotation[2, 1] * hy + rotation[2, 2] * hz
        out[i, 0, 0], out[i, 0, 1], out[i, 0, 2] = px, py, pz
        lx, ly, lz = px - c0, py - c1, pz - c2
        out[i, 2, 0] = v0 + w1 * lz - w2 * ly
        out[i, 2, 1] = v1 + w2 * lx - w0 * lz
        out[i, 2, 2] = v2 + w0 * ly - w1 * lx


def face_frames(vertices, faces):
    """(F, 4, 4) per face: its unit normal and offset (``n . y - offset`` is the
    signed distance of y to the plane), then for each edge the unit in-plane
    normal pointing out of the triangle and its offset (positive: the foot of
    y lies beyond that edge, by that much)."""
    tri = vertices[faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.linalg.norm(n, axis=1)[:, None]
    out = np.zeros((len(faces), 4, 4))
    out[:, 0, 0:3] = n
    out[:, 0, 3] = np.einsum("ij,ij->i", n, tri[:, 0])
    for k in range(3):
        p, q = tri[:, k], tri[:, (k + 1) % 3]
        m = np.cross(q - p, n)           # in the plane, away from the triangle (counter-clockwise)
        m /= np.linalg.norm(m, axis=1)[:, None]
        out[:, k + 1, 0:3] = m
        out[:, k + 1, 3] = np.einsum("ij,ij->i", m, p)
    return np.ascontiguousarray(out)


# fastmath "contract" only, as the contact kernel (FMA; IEEE NaN and infinity kept)
nearest_planes_serial = njit(cache=True, fastmath={"contract"}, error_model="numpy")(
    _named_copy(_nearest_planes, "nearest_planes_serial"))


def _nearest_threaded(body_vertices, pose, active, rotation, motion, counter_vertices, faces,
                      frames, corner_normals, search, boxes, nodes, order, neighbours, out,
                      distance, hint, fixed, steady):
    """The serial query on pieces of ``active`` in threads (each piece
    writes its own vertices only: the serial results, bit for bit), so that
    the threaded build compiles this loop only (as the contact kernel's:
    :func:`meshwear.kernels.contact._threaded`)."""
    n = active.shape[0]
    chunks = pieces(n)
    for c in prange(chunks):
        nearest_planes_serial(body_vertices, pose, active[c * n // chunks:(c + 1) * n // chunks],
                              rotation, motion, counter_vertices, faces, frames, corner_normals,
                              search, boxes, nodes, order, neighbours, out, distance, hint, fixed,
                              steady)


nearest_planes_parallel = njit(cache=True, parallel=True)(
    _named_copy(_nearest_threaded, "nearest_planes_parallel"))

#: active vertices from which the threaded query pays for its threads
PARALLEL_THRESHOLD = 2048


def nearest_planes(body_vertices, pose, active, rotation, motion, counter_vertices, faces,
                   frames, corner_normals, search, boxes, nodes, order, neighbours, out, distance,
                   hint, fixed=False, steady=False):
    """For each ``active`` vertex ``i`` of a body at ``pose``, write to
    ``out[i]`` (3, 3) the plane of its nearest counter face within the
    reach (``search[0]``) (a point of it, its normal, and the counter velocity at
    the vertex's foot on it; world), to
    ``distance[i]`` the distance to that face and to ``hint[i]`` (int64) the
    face's index; zeros, ``inf`` and -1 where no face qualifies. A vertex that
    had a plane (``out[i]`` nonzero on entry) keeps to faces whose normal is
    within 60 degrees of the one it had while it is over one of them
    (:data:`TRACKING`), and to face ``hint[i]`` itself while it is over it,
    unless it is :data:`RELEASE` times deeper under it than near another face
    (than its distance to the face's crease edges, :func:`_to_crease`).
    ``fixed``: the surface's ``rotation`` is the one of the call that filled
    ``out`` (a fixed or frozen surface), so a vertex that keeps its face
    keeps the normal it holds. ``steady``: such a surface that does not move
    either (no path; a steady turn frozen out of its frame is allowed): a
    vertex that keeps its flat face keeps the point of the plane it holds
    (no longer its foot); only its velocity, at the foot, is written."""
    kernel = (nearest_planes_parallel if active.shape[0] >= PARALLEL_THRESHOLD
              else nearest_planes_serial)
    kernel(body_vertices, pose, active, rotation, motion, counter_vertices, faces,
           frames, corner_normals, search, boxes, nodes, order, neighbours, out, distance,
           hint, fixed, steady)


#: faces meeting at a vertex at more than 60 degrees are a crease: smoothed
#: normals do not blend across it (a bore's wall and its end face)
CREASE = 0.5


def corner_normals(vertices, faces, normals):
    """(F, 3, 3) smoothed unit normal at each corner of each face: the mean
    normal of the faces around that vertex whose normal is within 60 degrees
    of the face's own (:data:`CREASE`), each weighted by its angle at the
    vertex (so a facet split into two triangles counts once)."""
    tri = vertices[faces]
    e1 = np.roll(tri, -1, axis=1) - tri
    e2 = np.roll(tri, 1, axis=1) - tri
    lengths = np.linalg.norm(e1, axis=2) * np.linalg.norm(e2, axis=2)
    cos = np.einsum("fkj,fkj->fk", e1, e2) / lengths
    angle = np.arccos(np.clip(cos, -1.0, 1.0)).ravel()   # per corner
    corner_vertex = faces.ravel()
    corner_face = np.repeat(np.arange(len(faces)), 3)
    order = np.argsort(corner_vertex, kind="stable")
    first = np.searchsorted(corner_vertex[order], np.arange(len(vertices)))
    last = np.searchsorted(corner_vertex[order], np.arange(len(vertices)), side="right")
    out = np.zeros((len(faces) * 3, 3))
    # every (corner, face around its vertex) pair
    degree = (last - first)[corner_vertex]
    pair_corner = np.repeat(np.arange(len(corner_vertex)), degree)
    offset = np.arange(degree.sum()) - np.repeat(np.cumsum(degree) - degree, degree)
    other_corner = order[first[corner_vertex][pair_corner] + offset]
    other = corner_face[other_corner]
    own = normals[corner_face[pair_corner]]
    keep = np.einsum("ij,ij->i", own, normals[other]) >= CREASE
    np.add.at(out, pair_corner[keep], (angle[other_corner][:, None] * normals[other])[keep])
    out /= np.linalg.norm(out, axis=1)[:, None]
    return np.ascontiguousarray(out.reshape(len(faces), 3, 3))
