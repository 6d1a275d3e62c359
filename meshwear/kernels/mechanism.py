"""The reaction of a counter-surface on the MuJoCo body it rides on
(:mod:`meshwear.mechanism`): the force of one contact slot on a worn body,
summed over its active vertices, and its moment about the world origin."""

import numpy as np
from numba import njit

from .contact import FORCE, rotation_entries


@njit(cache=True)
def slot_wrench(pose, vertices, active, normal_force, tangential, planes, vertex_planes, slot,
                out):
    """Fill ``out`` (6,) with the force (N) counter-surface ``slot`` exerts on
    a body (normal force along the plane's normal plus the friction force, at
    each active vertex in contact) and its moment about the world origin
    (N·m, each force at its vertex). Arrays as in
    :func:`meshwear.kernels.contact.contact`; ``planes`` (P, 4, 3) the
    uniform planes (slots ``< P``), ``vertex_planes`` (M, n, 3, 3) the
    others'."""
    for j in range(6):
        out[j] = 0.0
    r = rotation_entries(pose[3:7])
    P = planes.shape[0]
    for a in range(active.shape[0]):
        i = active[a]
        load = normal_force[slot, i]
        if load <= 0.0:
            continue
        if slot < P:
            nx, ny, nz = planes[slot, 1, 0], planes[slot, 1, 1], planes[slot, 1, 2]
        else:
            nx = vertex_planes[slot - P, i, 1, 0]
            ny = vertex_planes[slot - P, i, 1, 1]
            nz = vertex_planes[slot - P, i, 1, 2]
        fx = load * nx + tangential[slot, i, FORCE, 0]
        fy = load * ny + tangential[slot, i, FORCE, 1]
        fz = load * nz + tangential[slot, i, FORCE, 2]
        bx, by, bz = vertices[i, 0], vertices[i, 1], vertices[i, 2]
        x = pose[0] + r[0] * bx + r[1] * by + r[2] * bz
        y = pose[1] + r[3] * bx + r[4] * by + r[5] * bz
        z = pose[2] + r[6] * bx + r[7] * by + r[8] * bz
        out[0] += fx
        out[1] += fy
        out[2] += fz
        out[3] += y * fz - z * fy
        out[4] += z * fx - x * fz
        out[5] += x * fy - y * fx
