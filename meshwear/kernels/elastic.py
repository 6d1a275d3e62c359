"""The gaps of a body's vertices against its one counter-surface, for the
half-space model (:mod:`meshwear.contact.elastic`): one pass over the active set.

Arrays as in :mod:`meshwear.kernels.contact`; the outputs, per active
vertex ``k`` (vertex ``active[k]``): ``gap`` (m, along the normal of the
plane under it; +inf where its surface does not face that plane or no
face is within reach), ``normal`` (k, 3: that plane's unit normal, world),
``contact_area`` (m², the vertex's area vector projected on the plane),
``offset`` (k, 3: the vertex from the centre of mass, world) and
``velocity`` (k, 3: the vertex's velocity relative to the surface under
it, world).
"""

import numpy as np
from .jit import njit

from .contact import FACING, rotation_entries


@njit(cache=True)
def gaps(body_vertices, pose, planes, vertex_planes, active, area, gap, normal, contact_area,
         offset, velocity):
    """Fill the outputs (module docstring) against ``planes[0]`` if there
    is a plane, else against ``vertex_planes[0]``."""
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rotation_entries(pose[3:7])
    use_plane = planes.shape[0] > 0
    for k in range(active.shape[0]):
        i = active[k]
        bx, by, bz = body_vertices[i, 0], body_vertices[i, 1], body_vertices[i, 2]
        rx = r00 * bx + r01 * by + r02 * bz
        ry = r10 * bx + r11 * by + r12 * bz
        rz = r20 * bx + r21 * by + r22 * bz
        offset[k, 0], offset[k, 1], offset[k, 2] = rx, ry, rz
        px, py, pz = pose[0] + rx, pose[1] + ry, pose[2] + rz
        if use_plane:
            ox, oy, oz = planes[0, 0, 0], planes[0, 0, 1], planes[0, 0, 2]
            nx, ny, nz = planes[0, 1, 0], planes[0, 1, 1], planes[0, 1, 2]
            svx, svy, svz = planes[0, 2, 0], planes[0, 2, 1], planes[0, 2, 2]
        else:
            ox, oy, oz = vertex_planes[0, i, 0, 0], vertex_planes[0, i, 0, 1], vertex_planes[0, i, 0, 2]
            nx, ny, nz = vertex_planes[0, i, 1, 0], vertex_planes[0, i, 1, 1], vertex_planes[0, i, 1, 2]
            svx, svy, svz = vertex_planes[0, i, 2, 0], vertex_planes[0, i, 2, 1], vertex_planes[0, i, 2, 2]
        d = (px - ox) * nx + (py - oy) * ny + (pz - oz) * nz
        if use_plane:
            wx, wy, wz = planes[0, 3, 0], planes[0, 3, 1], planes[0, 3, 2]
            if wx != 0.0 or wy != 0.0 or wz != 0.0:
                # a turning plane: its velocity at the vertex's foot
                kx, ky, kz = px - d * nx - ox, py - d * ny - oy, pz - d * nz - oz
                svx += wy * kz - wz * ky
                svy += wz * kx - wx * kz
                svz += wx * ky - wy * kx
        ax = r00 * area[i, 0] + r01 * area[i, 1] + r02 * area[i, 2]
        ay = r10 * area[i, 0] + r11 * area[i, 1] + r12 * area[i, 2]
        az = r20 * area[i, 0] + r21 * area[i, 1] + r22 * area[i, 2]
        a = -(ax * nx + ay * ny + az * nz)
        facing = a > FACING * area[i, 3] and (nx != 0.0 or ny != 0.0 or nz != 0.0)
        gap[k] = d if facing else np.inf
        normal[k, 0], normal[k, 1], normal[k, 2] = nx, ny, nz
        contact_area[k] = a
        wx, wy, wz = pose[10], pose[11], pose[12]
        velocity[k, 0] = pose[7] + wy * rz - wz * ry - svx
        velocity[k, 1] = pose[8] + wz * rx - wx * rz - svy
        velocity[k, 2] = pose[9] + wx * ry - wy * rx - svz
