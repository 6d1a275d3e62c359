"""One entry point for every per-vertex counter-surface: the plane under each vertex.

A counter-surface that is not a uniform analytic plane hands the step loop a
*surface tuple* (:data:`SURFACE_FIELDS`, built by
:meth:`meshwear.surfaces.CounterSurface.compiled`), and :func:`fill_planes`
puts it where it is at ``t`` and calls the kernel its ``kind`` names: the
table of kinds below. Adding a surface type is one kernel with the signature
of :func:`meshwear.kernels.analytic.cylinder_planes_serial`, one code here
and one class in :mod:`meshwear.surfaces`.

A surface tuple holds, in order (unused arrays empty):

kind : int64
    :data:`MESH`, :data:`CYLINDER` or :data:`SPHERE`.
geometry : (g,) float
    The analytic shape (:mod:`meshwear.kernels.analytic`).
motion : (19,) float, terms : (k, 9) float
    Its motion (:mod:`meshwear.kernels.frames`).
frozen : bool
    Its turn leaves its shape unchanged: queries use its frame without the
    turn (the velocity field keeps it).
counter_vertices, faces, frames, corner_normals, search, boxes, nodes, order, neighbours
    A mesh, its reach and its faces' tree (:mod:`meshwear.kernels.nearest`).
part : tuple
    Its wear (:data:`meshwear.kernels.counter_wear.PART_FIELDS`; law code -1:
    it does not wear); wear moves its faces.
"""

from .jit import njit

from .analytic import (cylinder_planes_parallel, cylinder_planes_serial, sphere_planes_parallel,
                       sphere_planes_serial)
from .frames import surface_frame
from .nearest import nearest_planes_parallel, nearest_planes_serial

MESH, CYLINDER, SPHERE = 0, 1, 2
KINDS = {"mesh": MESH, "cylinder": CYLINDER, "sphere": SPHERE}
SURFACE_FIELDS = ("kind", "geometry", "motion", "terms", "frozen", "counter_vertices", "faces",
                  "frames", "corner_normals", "search", "boxes", "nodes", "order", "neighbours",
                  "part")

#: active vertices from which the threaded kernels pay for their threads
PARALLEL_THRESHOLD = 2048


@njit(cache=True)
def fill_planes(surface, t, body_vertices, pose, active, out, distance, hint, buffer, rotation,
                frame):
    """The plane under each ``active`` vertex of a body at ``pose``, at time
    ``t``, into ``out`` (n, 3, 3), ``distance`` (n,) and, for meshes, ``hint``
    (n,) int64 (the face under it). ``buffer`` (2, 3), ``rotation`` (3, 3) and
    ``frame`` (4, 3) are scratch; they hold the surface's frame afterwards."""
    (kind, geometry, motion, terms, frozen, counter_vertices, faces, frames, corner_normals,
     search, boxes, nodes, order, neighbours, part) = surface
    surface_frame(motion, terms, t, frozen, buffer, rotation, frame)
    threads = active.shape[0] >= PARALLEL_THRESHOLD
    if kind == MESH:
        # its faces stay put in its frame: the frame turns only for a
        # turning surface that is not frozen, and wear moves faces
        fixed = (frozen or motion[15] == 0.0) and part[0][0] < 0.0
        # and its frame stays where it was: no path (zero rows add nothing)
        steady = fixed
        for m in range(terms.shape[0]):
            for j in range(1, 9):
                steady = steady and terms[m, j] == 0.0
        if threads:
            nearest_planes_parallel(body_vertices, pose, active, rotation, frame,
                                    counter_vertices, faces, frames, corner_normals, search,
                                    boxes, nodes, order, neighbours, out, distance, hint, fixed,
                                    steady)
        else:
            nearest_planes_serial(body_vertices, pose, active, rotation, frame, counter_vertices,
                                  faces, frames, corner_normals, search, boxes, nodes, order,
                                  neighbours, out, distance, hint, fixed, steady)
    elif kind == CYLINDER:
        if threads:
            cylinder_planes_parallel(body_vertices, pose, active, rotation, frame, geometry, out,
                                     distance)
        else:
            cylinder_planes_serial(body_vertices, pose, active, rotation, frame, geometry, out,
                                   distance)
    elif kind == SPHERE:
        if threads:
            sphere_planes_parallel(body_vertices, pose, active, rotation, frame, geometry, out,
                                   distance)
        else:
            sphere_planes_serial(body_vertices, pose, active, rotation, frame, geometry, out,
                                 distance)
