"""Where a counter-surface is at time ``t``, and how far it can have come.

Every counter-surface is given in its own frame and moves as a rigid body: a
steady turn about an axis and a path (docs/model.md, "Counter-surfaces"). A
point ``y`` of its frame is at time ``t`` in the world at

    x = Rot(t) (R0 y + position - center) + center + path(t),

``Rot(t)`` the turn by ``rate t`` about the unit ``axis`` through ``center``.
A surface whose turn does not change its shape (a ring about its own axis) is
*frozen*: its frame ignores the turn, its velocity field keeps it.

Arrays (C-contiguous float64):

motion : (19,)
    ``R0`` row by row (9), ``position`` (3), ``axis`` (3), ``rate`` (rad/s),
    ``center`` (3).
terms : (k, 9)
    The path (:func:`meshwear.kernels.rigid.path_point`).
rotation : (3, 3), frame : (4, 3)
    Frame -> world rotation at ``t``; world position of the frame's origin,
    translational velocity, angular velocity and the point the turn is about
    (the arrays :mod:`meshwear.kernels.nearest` and
    :mod:`meshwear.kernels.analytic` take).
bounds : (16,)
    How far a surface can come towards a body between two times
    (:func:`shape_shift`): a constant (m), a lever arm (m) and the turn rate
    (rad/s), a (3, 3) projection of the path's displacement (9), a flag (1 for
    an analytic plane, whose distance to a body counts along its normal only)
    and the plane's unit normal (3).
"""

import numpy as np
from .jit import njit

from .rigid import path_point

MOTION_SIZE = 19
BOUNDS_SIZE = 16
#: slots of ``bounds``
CONSTANT, LEVER, RATE, PROJECTION, UNIFORM, NORMAL = 0, 1, 2, slice(3, 12), 12, slice(13, 16)


@njit(cache=True, inline="always")
def _turn(axis0, axis1, axis2, angle):
    """Rotation by ``angle`` about a unit axis, row by row (Rodrigues)."""
    c, s = np.cos(angle), np.sin(angle)
    t = 1.0 - c
    return (c + t * axis0 * axis0, t * axis0 * axis1 - s * axis2, t * axis0 * axis2 + s * axis1,
            t * axis0 * axis1 + s * axis2, c + t * axis1 * axis1, t * axis1 * axis2 - s * axis0,
            t * axis0 * axis2 - s * axis1, t * axis1 * axis2 + s * axis0, c + t * axis2 * axis2)


@njit(cache=True, inline="always")
def offset(r, pose, body_vertices, i, frame):
    """World offset of vertex ``i`` of a body at ``pose`` (``r`` its rotation,
    :func:`meshwear.kernels.contact.rotation_entries`) from the origin of a
    surface's ``frame``."""
    bx, by, bz = body_vertices[i, 0], body_vertices[i, 1], body_vertices[i, 2]
    return (pose[0] + r[0] * bx + r[1] * by + r[2] * bz - frame[0, 0],
            pose[1] + r[3] * bx + r[4] * by + r[5] * bz - frame[0, 1],
            pose[2] + r[6] * bx + r[7] * by + r[8] * bz - frame[0, 2])


@njit(cache=True, inline="always")
def to_frame(rotation, ex, ey, ez):
    """A world offset in a surface's frame: ``rotation^T e``."""
    return (rotation[0, 0] * ex + rotation[1, 0] * ey + rotation[2, 0] * ez,
            rotation[0, 1] * ex + rotation[1, 1] * ey + rotation[2, 1] * ez,
            rotation[0, 2] * ex + rotation[1, 2] * ey + rotation[2, 2] * ez)


@njit(cache=True)
def surface_frame(motion, terms, t, frozen, buffer, rotation, frame):
    """Fill ``rotation`` (3, 3) and ``frame`` (4, 3) with a surface's pose and
    velocity at ``t``; ``frozen`` leaves the turn out of the pose (not out of
    the velocity). ``buffer`` is (2, 3) scratch."""
    path_point(terms, t, buffer)
    rate = motion[15]
    angle = 0.0 if frozen else rate * t
    k = _turn(motion[12], motion[13], motion[14], angle)
    for r in range(3):
        for c in range(3):
            rotation[r, c] = (k[3 * r] * motion[c] + k[3 * r + 1] * motion[3 + c]
                              + k[3 * r + 2] * motion[6 + c])
    for r in range(3):
        lever = 0.0
        for c in range(3):
            lever += k[3 * r + c] * (motion[9 + c] - motion[16 + c])
        frame[0, r] = lever + motion[16 + r] + buffer[0, r]
        frame[1, r] = buffer[1, r]
        frame[2, r] = rate * motion[12 + r]
        frame[3, r] = motion[16 + r] + buffer[0, r]


@njit(cache=True)
def shape_shift(bounds, terms, t0, t1, buffer):
    """Upper bound (m) on how far any point of a (non-plane) surface's shape
    has moved between ``t0`` and ``t1``: the constant, the chord the turn
    sweeps at the lever arm, and the projected path displacement."""
    path_point(terms, t0, buffer)
    d0, d1, d2 = buffer[0, 0], buffer[0, 1], buffer[0, 2]
    path_point(terms, t1, buffer)
    d0, d1, d2 = buffer[0, 0] - d0, buffer[0, 1] - d1, buffer[0, 2] - d2
    turn = min(np.pi, bounds[RATE] * abs(t1 - t0))
    return (bounds[CONSTANT] + 2.0 * np.sin(0.5 * turn) * bounds[LEVER]
            + _projected_norm(bounds, d0, d1, d2))


@njit(cache=True, inline="always")
def _projected_norm(bounds, d0, d1, d2):
    p = bounds[PROJECTION]
    x = p[0] * d0 + p[1] * d1 + p[2] * d2
    y = p[3] * d0 + p[4] * d1 + p[5] * d2
    z = p[6] * d0 + p[7] * d1 + p[8] * d2
    return np.sqrt(x * x + y * y + z * z)


@njit(cache=True)
def shape_speed(bounds, terms, t, buffer):
    """Upper bound (m/s) on how fast any point of a surface's shape moves
    towards a body at ``t`` (for an analytic plane: along its normal)."""
    path_point(terms, t, buffer)
    return (_projected_norm(bounds, buffer[1, 0], buffer[1, 1], buffer[1, 2])
            + bounds[RATE] * bounds[LEVER])


@njit(cache=True)
def step_motion(pose, radius, bounds, terms, t, dt, buffer):
    """Upper bound (m) on how far a vertex of a body (``radius`` its largest
    distance from its centre of mass) moves relative to any surface in one step."""
    v = np.sqrt(pose[7] ** 2 + pose[8] ** 2 + pose[9] ** 2)
    v += np.sqrt(pose[10] ** 2 + pose[11] ** 2 + pose[12] ** 2) * radius
    fastest = 0.0
    for s in range(bounds.shape[0]):
        fastest = max(fastest, shape_speed(bounds[s], terms[s], t, buffer))
    return (v + fastest) * dt


@njit(cache=True)
def moved_since_refresh(pose, cull, radius, bounds, terms, t, wear_depth, active, active_wear,
                        buffer):
    """Upper bound (m) on how far any vertex of a body has come towards any
    surface since its active set was refreshed (``cull``: margin, time, pose
    then), its wear included. O(active vertices).

    ``cull`` is (9,): margin, time, then the pose's position and quaternion.
    Against an analytic plane only the relative motion along its normal
    counts; against any other surface the body's whole displacement and the
    surface's :func:`shape_shift`. A body's turn by angle ``a`` moves its
    vertices by at most ``2 sin(a / 2) radius``.
    """
    t0 = cull[1]
    c = abs(pose[3] * cull[5] + pose[4] * cull[6] + pose[5] * cull[7] + pose[6] * cull[8])
    spin = 2.0 * np.sin(0.5 * min(np.pi, 2.0 * np.arccos(min(1.0, c)))) * radius
    s0, s1, s2 = pose[0] - cull[2], pose[1] - cull[3], pose[2] - cull[4]
    body_shift = np.sqrt(s0 * s0 + s1 * s1 + s2 * s2)
    bound = 0.0
    for s in range(bounds.shape[0]):
        b = bounds[s]
        if b[UNIFORM] > 0.0:
            # a plane: the body's and the plane's displacements along its normal
            path_point(terms[s], t0, buffer)
            a0, a1, a2 = buffer[0, 0], buffer[0, 1], buffer[0, 2]
            path_point(terms[s], t, buffer)
            n = b[NORMAL]
            along = (n[0] * (s0 - buffer[0, 0] + a0) + n[1] * (s1 - buffer[0, 1] + a1)
                     + n[2] * (s2 - buffer[0, 2] + a2))
            bound = max(bound, abs(along) + spin)
        else:
            bound = max(bound, body_shift + spin + shape_shift(b, terms[s], t0, t, buffer))
    worn = 0.0
    for k in range(active.shape[0]):
        worn = max(worn, wear_depth[active[k]] - active_wear[k])
    return bound + worn


@njit(cache=True)
def plane_rows(motion, terms, normal0, point0, t, buffer, out):
    """An analytic plane's row of the contact kernel's ``planes`` (4, 3) at
    ``t``: its point (``point0`` moved with the surface), its normal, the
    velocity of the surface at that point, and its angular velocity."""
    path_point(terms, t, buffer)
    rate = motion[15]
    k = _turn(motion[12], motion[13], motion[14], rate * t)
    for r in range(3):
        p = 0.0
        n = 0.0
        for c in range(3):
            p += k[3 * r + c] * (point0[c] - motion[16 + c])
            n += k[3 * r + c] * normal0[c]
        out[0, r] = p + motion[16 + r] + buffer[0, r]
        out[1, r] = n
        out[3, r] = rate * motion[12 + r]
    # velocity of the surface at its point: the path's plus the turn's
    for r in range(3):
        a, b = (r + 1) % 3, (r + 2) % 3
        out[2, r] = (buffer[1, r] + out[3, a] * (out[0, b] - motion[16 + b] - buffer[0, b])
                     - out[3, b] * (out[0, a] - motion[16 + a] - buffer[0, a]))


__all__ = ["MOTION_SIZE", "BOUNDS_SIZE", "surface_frame", "shape_shift", "shape_speed",
           "step_motion", "moved_since_refresh", "plane_rows", "offset", "to_frame"]
