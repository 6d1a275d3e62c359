"""One entry point for every per-vertex counter-surface: the plane under each vertex.

A counter-surface that is not a uniform analytic plane hands the step loop a
*surface tuple* (:data:`SURFACE_FIELDS`, built by
:meth:`meshwear.surfaces.CounterSurface.compiled`), and :func:`fill_planes`
puts it where it is at ``t`` and calls the kernel its ``kind`` names: the
table of kinds below. Adding a surface type is one kernel with the signature
of :func:`meshwear.kernels.analytic.cylinder_planes_serial`, one code here
(and its branch in :func:`_fill_planes` under a ``HAS_`` constant of its
own, so that the builds of :func:`fill_planes_for` compile only the kinds a
scene meets) and one class in :mod:`meshwear.surfaces`.

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
from .contact import _named_copy
from .frames import surface_frame
from .nearest import nearest_planes_parallel, nearest_planes_serial

MESH, CYLINDER, SPHERE = 0, 1, 2
KINDS = {"mesh": MESH, "cylinder": CYLINDER, "sphere": SPHERE}
#: the kinds' names by code
NAMES = {code: name for name, code in KINDS.items()}
SURFACE_FIELDS = ("kind", "geometry", "motion", "terms", "frozen", "counter_vertices", "faces",
                  "frames", "corner_normals", "search", "boxes", "nodes", "order", "neighbours",
                  "part")

#: active vertices from which the threaded kernels pay for their threads
PARALLEL_THRESHOLD = 2048


def _fill_planes(surface, t, body_vertices, pose, active, out, distance, hint, buffer, rotation,
                frame):
    """The plane under each ``active`` vertex of a body at ``pose``, at time
    ``t``, into ``out`` (n, 3, 3), ``distance`` (n,) and, for meshes, ``hint``
    (n,) int64 (the face under it). ``buffer`` (2, 3), ``rotation`` (3, 3) and
    ``frame`` (4, 3) are scratch; they hold the surface's frame afterwards."""
    (kind, geometry, motion, terms, frozen, counter_vertices, faces, frames, corner_normals,
     search, boxes, nodes, order, neighbours, part) = surface
    surface_frame(motion, terms, t, frozen, buffer, rotation, frame)
    threads = active.shape[0] >= PARALLEL_THRESHOLD
    # (each kind and the threaded kernels under a constant of the build, so
    # that a build compiles only the kernels of its kinds: fill_planes_for)
    if HAS_MESH:
        if kind == MESH:
            # its faces stay put in its frame: the frame turns only for a
            # turning surface that is not frozen, and wear moves faces
            fixed = (frozen or motion[15] == 0.0) and part[0][0] < 0.0
            # and its frame stays where it was: no path (zero rows add nothing)
            steady = fixed
            for m in range(terms.shape[0]):
                for j in range(1, 9):
                    steady = steady and terms[m, j] == 0.0
            if THREADED:
                if threads:
                    nearest_planes_parallel(body_vertices, pose, active, rotation, frame,
                                            counter_vertices, faces, frames, corner_normals,
                                            search, boxes, nodes, order, neighbours, out,
                                            distance, hint, fixed, steady)
                    return
            nearest_planes_serial(body_vertices, pose, active, rotation, frame, counter_vertices,
                                  faces, frames, corner_normals, search, boxes, nodes, order,
                                  neighbours, out, distance, hint, fixed, steady)
            return
    if HAS_CYLINDER:
        if kind == CYLINDER:
            if THREADED:
                if threads:
                    cylinder_planes_parallel(body_vertices, pose, active, rotation, frame,
                                             geometry, out, distance)
                    return
            cylinder_planes_serial(body_vertices, pose, active, rotation, frame, geometry, out,
                                   distance)
            return
    if HAS_SPHERE:
        if kind == SPHERE:
            if THREADED:
                if threads:
                    sphere_planes_parallel(body_vertices, pose, active, rotation, frame,
                                           geometry, out, distance)
                    return
            sphere_planes_serial(body_vertices, pose, active, rotation, frame, geometry, out,
                                 distance)
            return


#: the build's constants: the kinds it handles, and the threaded kernels
HAS_MESH = HAS_CYLINDER = HAS_SPHERE = THREADED = True

#: the builds made so far, by :func:`fill_planes_for`'s arguments
_FILLS = {}


def fill_planes_for(kinds, threaded):
    """:func:`fill_planes` compiled for the surface kinds ``kinds`` (names
    of :data:`KINDS`) only, with the threaded kernels if ``threaded``; a
    surface of another kind is left unfilled."""
    kinds = tuple(sorted(set(kinds)))
    key = (kinds, bool(threaded))
    if key not in _FILLS:
        constants = {"HAS_" + k.upper(): k in kinds for k in KINDS}
        name = "fill_planes" + ("" if key == (tuple(sorted(KINDS)), True) else
                                "_" + "".join(k[0] for k in kinds) + ("_threads" if threaded
                                                                       else "_serial"))
        _FILLS[key] = njit(cache=True)(_named_copy(_fill_planes, name, THREADED=bool(threaded),
                                                   **constants))
    return _FILLS[key]


#: every kind, threaded or not
fill_planes = fill_planes_for(KINDS, True)
