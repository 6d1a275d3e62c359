"""Analytic counter-surfaces of revolution: the exact tangent plane under each vertex.

A cylinder (a shaft or ring from outside, a bore from inside) and a sphere (a
ball, or a spherical cup from inside) give each active vertex ``i`` the plane
tangent to the surface at the vertex's closest point, as a mesh surface gives
the plane of its nearest face (:mod:`meshwear.kernels.nearest`): same output,
no faceting, no face lookup. The contact kernel then applies the point-plane
contact of docs/model.md unchanged.

Arrays as in :mod:`meshwear.kernels.nearest` and :mod:`meshwear.kernels.frames`
(``rotation`` (3, 3) and ``frame`` (4, 3): the surface's pose and velocity at
the query time), plus

geometry : (3,)
    cylinder: radius (m), half length (m, ``inf`` for an infinite one),
    side (0 outside: the solid is within the radius; 1 inside: a bore, the
    solid is outside the radius). The axis is the frame's z axis through its
    origin.
    sphere: radius (m), side (0 or 1), unused. The centre is the frame's origin.
out : (n, 3, 3)
    Written for the active vertices: the closest surface point, the unit
    normal pointing out of the solid, the surface's velocity there (world).
    Zeros where the surface has no closest point (a vertex on the axis or
    beyond a finite cylinder's ends).
distance : (n,)
    Signed distance of the vertex from the surface along that normal (m,
    negative inside the solid), ``inf`` where ``out`` is zero.
"""

import numpy as np
from numba import prange

from .jit import njit

from .contact import _named_copy, pieces, rotation_entries
from .frames import offset, to_frame

CYLINDER_RADIUS, CYLINDER_HALF_LENGTH, SIDE = 0, 1, 2
SPHERE_RADIUS, SPHERE_SIDE = 0, 1


@njit(cache=True, inline="always")
def _surface_velocity(frame, px, py, pz):
    """Velocity of the surface point p: translation plus the turn about frame[3]."""
    lx, ly, lz = px - frame[3, 0], py - frame[3, 1], pz - frame[3, 2]
    return (frame[1, 0] + frame[2, 1] * lz - frame[2, 2] * ly,
            frame[1, 1] + frame[2, 2] * lx - frame[2, 0] * lz,
            frame[1, 2] + frame[2, 0] * ly - frame[2, 1] * lx)


@njit(cache=True, inline="always")
def _write(out, distance, i, px, py, pz, nx, ny, nz, frame, gap):
    out[i, 0, 0], out[i, 0, 1], out[i, 0, 2] = px, py, pz
    out[i, 1, 0], out[i, 1, 1], out[i, 1, 2] = nx, ny, nz
    out[i, 2, 0], out[i, 2, 1], out[i, 2, 2] = _surface_velocity(frame, px, py, pz)
    distance[i] = gap


@njit(cache=True, inline="always")
def _none(out, distance, i):
    for row in range(3):
        for col in range(3):
            out[i, row, col] = 0.0
    distance[i] = np.inf


def _cylinder_planes(body_vertices, pose, active, rotation, frame, geometry, out, distance):
    pose_rotation = rotation_entries(pose[3:7])
    radius, half, sign = geometry[0], geometry[1], 1.0 - 2.0 * geometry[2]
    for k in range(active.shape[0]):
        i = active[k]
        # the vertex in the cylinder's frame: y = Rc^T (x - origin)
        ex, ey, ez = offset(pose_rotation, pose, body_vertices, i, frame)
        yx, yy, yz = to_frame(rotation, ex, ey, ez)
        r = np.sqrt(yx * yx + yy * yy)
        if abs(yz) > half or r == 0.0:
            _none(out, distance, i)
            continue
        ux, uy = yx / r, yy / r
        # closest point (radius along the radial direction, same axial place)
        # and the normal out of the solid, back in the world
        qx, qy = radius * ux, radius * uy
        px = rotation[0, 0] * qx + rotation[0, 1] * qy + rotation[0, 2] * yz + frame[0, 0]
        py = rotation[1, 0] * qx + rotation[1, 1] * qy + rotation[1, 2] * yz + frame[0, 1]
        pz = rotation[2, 0] * qx + rotation[2, 1] * qy + rotation[2, 2] * yz + frame[0, 2]
        nx = sign * (rotation[0, 0] * ux + rotation[0, 1] * uy)
        ny = sign * (rotation[1, 0] * ux + rotation[1, 1] * uy)
        nz = sign * (rotation[2, 0] * ux + rotation[2, 1] * uy)
        _write(out, distance, i, px, py, pz, nx, ny, nz, frame, sign * (r - radius))


def _sphere_planes(body_vertices, pose, active, rotation, frame, geometry, out, distance):
    pose_rotation = rotation_entries(pose[3:7])
    radius, sign = geometry[0], 1.0 - 2.0 * geometry[1]
    for k in range(active.shape[0]):
        i = active[k]
        # the vertex's offset from the centre (a sphere needs no frame axes)
        ex, ey, ez = offset(pose_rotation, pose, body_vertices, i, frame)
        r = np.sqrt(ex * ex + ey * ey + ez * ez)
        if r == 0.0:
            _none(out, distance, i)
            continue
        ux, uy, uz = ex / r, ey / r, ez / r
        px, py, pz = frame[0, 0] + radius * ux, frame[0, 1] + radius * uy, frame[0, 2] + radius * uz
        _write(out, distance, i, px, py, pz, sign * ux, sign * uy, sign * uz, frame,
               sign * (r - radius))


cylinder_planes_serial = njit(cache=True, fastmath={"contract"})(
    _named_copy(_cylinder_planes, "cylinder_planes_serial"))
sphere_planes_serial = njit(cache=True, fastmath={"contract"})(
    _named_copy(_sphere_planes, "sphere_planes_serial"))

#: the serial build a copy of _threaded runs on each piece
SERIAL_BUILD = None


def _threaded(body_vertices, pose, active, rotation, frame, geometry, out, distance):
    """SERIAL_BUILD on pieces of ``active`` in threads (each piece writes its
    own vertices only: the serial results, bit for bit; the threaded build
    compiles only this loop: :func:`meshwear.kernels.contact._threaded`)."""
    n = active.shape[0]
    chunks = pieces(n)
    for c in prange(chunks):
        SERIAL_BUILD(body_vertices, pose, active[c * n // chunks:(c + 1) * n // chunks],
                     rotation, frame, geometry, out, distance)


cylinder_planes_parallel = njit(cache=True, parallel=True)(
    _named_copy(_threaded, "cylinder_planes_parallel", SERIAL_BUILD=cylinder_planes_serial))
sphere_planes_parallel = njit(cache=True, parallel=True)(
    _named_copy(_threaded, "sphere_planes_parallel", SERIAL_BUILD=sphere_planes_serial))
