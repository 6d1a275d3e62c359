"""The counter-surfaces of a model, and each body's active set.

Active set. A worn body's vertices that are farther than a margin ``m`` from
every surface cannot touch one until the body or a surface has moved by ``m``
relative to the other, or the body has worn by it; the contact kernel skips
them. :func:`update` refreshes the set only when that bound
(:func:`meshwear.kernels.frames.moved_since_refresh`, O(active vertices) per
step) is reached, so the per-step cost follows the contact region, not the
mesh size. A surface that moves only within its own shape (a ring turning
about its own axis, a plane sliding in itself) adds nothing to the bound.

python-fcl finds whether a worn body can meet a counter mesh at all: one BVH
per mesh, built once from the unworn meshes (a worn body lies inside its
unworn mesh, so the unworn distance is a lower bound), queried at each refresh
through a collision manager.
"""

from dataclasses import dataclass

import fcl
import numpy as np
import numba
from numba.typed import List

from ..kernels.jit import njit
from ..kernels.contact import FACING, FORCE, NO_CONTACT
from ..kernels.frames import (BOUNDS_SIZE, MOTION_SIZE, moved_since_refresh as _moved,
                              step_motion as _step)
from .base import quaternion_matrix
from .mesh import MeshSurface, bvh

#: default active-set margin, as a fraction of a body's bounding-box diagonal
MARGIN_FRACTION = 0.01

#: the margin is at least this many times the largest relative motion of one
#: step, so a vertex always meets a surface within reach before it touches
STEPS_IN_MARGIN = 10.0
#: the steps' queries look this fraction of the active set's margin away
#: (:func:`query_reach`): a vertex with no face within the reach has no
#: plane (the refresh's own look goes the whole margin)
QUERY_FRACTION = 0.3

#: slots of :attr:`meshwear.model.BodyState.cull`
CULL_MARGIN, CULL_TIME, CULL_POSE = 0, 1, slice(2, 9)
CULL_SIZE = 9


class SurfaceSet:
    """Every counter-surface of a model in contact-slot order: the uniform
    planes (rows of the kernel's ``planes``, (P, 4, 3)), then the per-vertex
    surfaces (slots ``P + j`` of a body's ``vertex_planes``); their
    ``bounds`` (P + M, 16) and padded path ``terms`` (P + M, K, 9)
    (:mod:`meshwear.kernels.frames`); and the fcl collision manager of the
    mesh ones."""

    def __init__(self, surfaces):
        self.uniform = tuple(s for s in surfaces if s.uniform)
        self.per_vertex = tuple(s for s in surfaces if not s.uniform)
        self.meshes = tuple(s for s in self.per_vertex if isinstance(s, MeshSurface))
        self.planes = np.zeros((len(self.uniform), 4, 3))
        self.moving_planes = any(not p.static for p in self.uniform)
        for j, p in enumerate(self.uniform):
            p.plane_row(0.0, self.planes[j])
        self.manager = None
        self.body_bvh = {}
        self._near = None
        self._compiled_planes = None
        self.refresh_bounds()

    @property
    def slots(self):
        """Contact slots of every body: the uniform planes, then the others."""
        return self.uniform + self.per_vertex

    def refresh_bounds(self):
        """Gather each surface's bounds and path terms (after their shape
        invariance is settled)."""
        slots = self.slots
        k = max([1] + [len(s.motion.terms) for s in slots])
        self.bounds = np.zeros((len(slots), BOUNDS_SIZE))
        # zero rows add nothing to a path (an oscillation of amplitude 0)
        self.terms = np.zeros((len(slots), k, 9))
        for j, s in enumerate(slots):
            self.bounds[j] = s.bounds()
            self.terms[j, :len(s.motion.terms)] = s.motion.terms
            if getattr(s, "rider", False) and not s.uniform:
                # a mechanism moves it: its moves since a refresh are
                # measured, not foreseen (meshwear.mechanism.rider_shift)
                self.bounds[j] = 0.0
                self.terms[j] = 0.0
        self._compiled_planes = None

    def compiled_planes(self):
        """The ``planes`` tuple of :mod:`meshwear.kernels.loop`: the kernel's
        array and, per plane, its motion, path terms, normal and point at
        rest, and whether it moves."""
        if getattr(self, "_compiled_planes", None) is None:
            p = self.uniform
            self._compiled_planes = (
                self.planes,
                np.array([s.motion.array for s in p]).reshape(-1, MOTION_SIZE),
                np.ascontiguousarray(self.terms[:len(p)]),
                np.array([s.normal for s in p], dtype=float).reshape(-1, 3),
                np.array([s.point for s in p], dtype=float).reshape(-1, 3),
                np.array([not s.static for s in p], dtype=np.bool_))
        return self._compiled_planes

    def compiled_list(self):
        """The per-vertex surfaces' tuples as the compiled loop takes them
        (rebuilt when one changed: a face tree built): a tuple of them (it
        needs no compile, a typed list of them does: 5 s on a first run), or
        a numba typed list where their types differ."""
        tuples = [s.compiled() for s in self.per_vertex]
        # the tuples themselves are kept (not their ids: a freed tuple's id
        # can come back for the next one, a worn surface attached anew)
        held = getattr(self, "_list_tuples", None)
        if held is None or len(held) != len(tuples) or any(
                a is not b for a, b in zip(held, tuples)):
            # built by cached compiled functions: a typed list built from
            # Python compiles its methods anew in every process (1 s here)
            if len({numba.typeof(t) for t in tuples}) == 1:
                self._list = tuple(tuples)
            elif tuples:
                self._list = _list_of(tuples[0])
                for t in tuples[1:]:
                    _append(self._list, t)
            else:
                # the loop's builds for planes only never read it
                # (meshwear.kernels.loop.loop_build): no typed list to compile
                self._list = ()
            self._list_tuples = tuples
        return self._list

    def mechanism_moved(self, t):
        """Surfaces on a mechanism body had their motion rewritten
        (:meth:`meshwear.mechanism.Mechanism.place`): copy it where the
        kernels read it, and put the planes at ``t``."""
        compiled = getattr(self, "_compiled_planes", None)
        for j, s in enumerate(self.slots):
            if getattr(s, "rider", False) and s.uniform:
                self.terms[j, :1] = s.motion.terms
                if j < len(self.uniform) and compiled is not None:
                    compiled[1][j] = s.motion.array
        self.set_planes(t)

    def set_planes(self, t):
        """Put the moving uniform planes where they are at ``t``."""
        if self.moving_planes:
            for j, p in enumerate(self.uniform):
                if not p.static:
                    p.plane_row(t, self.planes[j])

    # ---------------------------------------------------------- fcl broad phase
    def _manager(self, t):
        if self.manager is None:
            self.manager = fcl.DynamicAABBTreeCollisionManager()
            self.manager.registerObjects([m.bvh for m in self.meshes])
            self.manager.setup()
        for m in self.meshes:
            m.bvh.setTransform(m.transform(t))
        self.manager.update()
        return self.manager

    def meshes_within(self, body, pose, t, margin):
        """The mesh surfaces that the unworn ``body`` at ``pose`` comes within
        ``margin`` (m) of at ``t`` (fcl broad phase, then BVH distances)."""
        if not self.meshes:
            return []
        key = (id(body), pose[0:7].tobytes(), float(t), float(margin))
        if self._near is not None and self._near[0] == key:
            return self._near[1]
        if id(body) not in self.body_bvh:
            geometry_ = bvh(body.reference_vertices, body.faces)
            self.body_bvh[id(body)] = (geometry_, fcl.CollisionObject(geometry_, fcl.Transform()))
        obj = self.body_bvh[id(body)][1]
        obj.setTransform(fcl.Transform(quaternion_matrix(pose[3:7]), pose[0:3].copy()))
        manager = self._manager(t)
        # the manager hands the callback fresh wrappers of its objects; the
        # geometries of a distance result are ours, so they name the surface
        index = {id(m.bvh_geometry): j for j, m in enumerate(self.meshes)}
        found = set()

        def near(o1, o2, data):
            result = fcl.DistanceResult()
            d = fcl.distance(o1, o2, fcl.DistanceRequest(), result)
            if d <= margin:
                found.update(index[id(g)] for g in (result.o1, result.o2) if id(g) in index)
            return False, margin   # go on with every pair whose boxes are within the margin

        manager.distance(obj, None, near)
        out = [self.meshes[j] for j in sorted(found)]
        self._near = (key, out)
        return out


@njit(cache=True)
def _list_of(item):
    """A typed list holding ``item``."""
    out = List()
    out.append(item)
    return out


@njit(cache=True)
def _append(items, item):
    items.append(item)


@dataclass
class Cull:
    """Scratch arrays of a body's active-set refresh and plane queries."""

    distance: np.ndarray
    planes: np.ndarray
    hint: np.ndarray


def body_margin(model, body):
    """Active-set margin (m) of ``body``: ``contact.margin`` or a fraction of its size."""
    return margin_of(model.scene, body)


def margin_of(scene, body):
    """:func:`body_margin` from the scene, before the model exists."""
    given = scene.contact.margin
    if given is not None:
        return float(given)
    if body.margin > 0.0:       # sized by its contact where it can be (surfaces/margin.py)
        return body.margin
    return MARGIN_FRACTION * float(np.linalg.norm(np.ptp(body.reference_vertices, axis=0)))


def query_reach(model, body, s):
    """How far (m) the steps' queries look for the surfaces under the active
    vertices: the body's margin, at least :data:`QUERY_FRACTION` of the
    active set's (three steps' motion: a vertex has its face a few steps
    before it can touch, and one pressed in is far less deep). Beyond it a
    vertex has no plane, so no contact."""
    return max(body_margin(model, body), QUERY_FRACTION * s.cull[CULL_MARGIN])


def step_motion(model, body, s, t):
    """Upper bound (m) on how far a vertex of ``body`` moves relative to any
    surface in one step."""
    surfaces = model.surfaces
    return _step(s.pose, body.radius, surfaces.bounds, surfaces.terms, float(t), model.dt,
                 np.zeros((2, 3)))


def moved_since_refresh(model, body, s, t):
    """Upper bound (m) on how far any vertex of ``body`` has come towards any
    surface since the active set was refreshed, wear included
    (:func:`meshwear.kernels.frames.moved_since_refresh`)."""
    surfaces = model.surfaces
    return _moved(s.pose, s.cull, body.radius, surfaces.bounds, surfaces.terms, float(t),
                  s.wear_depth, s.active, s.active_wear, np.zeros((2, 3)))


def refresh(model, body, s, t):
    """Recompute the active set of ``body`` at time ``t``: every vertex within
    the margin of a surface. Pairs of vertices that leave it are cleared (they
    are out of reach, so in no contact)."""
    surfaces = model.surfaces
    margin = max(body_margin(model, body), STEPS_IN_MARGIN * step_motion(model, body, s, t))
    surfaces.set_planes(t)
    R = quaternion_matrix(s.pose[3:7])
    x = s.pose[0:3] + s.vertices @ R.T
    near = np.zeros(len(x), dtype=bool)
    for p in surfaces.planes:
        near |= (x - p[0]) @ p[1] < margin
    scratch = s.cull_scratch
    for surface in surfaces.per_vertex:
        # a worn surface moving within itself (turning, sliding) brings its
        # less worn parts under a vertex: nearer by at most its deepest wear
        reach = margin + (float(surface.part.depth.max()) if surface.worn else 0.0)
        if surface.worn:
            surface.rebin()     # if its wear since its boxes were fitted passed their slack
        candidates = surface.candidates(surfaces, body, s.pose, x, t, reach)
        if not len(candidates):
            continue
        scratch.planes[candidates] = 0.0
        scratch.hint[candidates] = -1
        surface.fill_within(reach, s.vertices, s.pose, candidates, scratch.planes,
                            scratch.distance, scratch.hint, t)
        near[candidates[scratch.distance[candidates] < reach]] = True
    active = np.flatnonzero(near)
    left = np.setdiff1d(s.active, active, assume_unique=True)
    if len(left):
        s.contact_state[:, left] = NO_CONTACT
        s.normal_force[:, left] = 0.0
        s.tangential[:, left, FORCE] = 0.0
        s.vertex_planes[:, left] = 0.0
        s.hint[:, left] = -1
    s.active = active
    s.cull[CULL_MARGIN] = margin
    s.cull[CULL_TIME] = t
    s.cull[CULL_POSE] = s.pose[0:7]
    s.active_wear = s.wear_depth[active]


def needs_refresh(model, body, s, t):
    """Whether the active set of ``body`` must be refreshed before a step at ``t``."""
    return model.cull and (s.cull[CULL_MARGIN] == 0.0
                           or moved_since_refresh(model, body, s, t)
                           + step_motion(model, body, s, t) >= s.cull[CULL_MARGIN])


def update(model, body, s, t):
    """Before a step at time ``t``: refresh the active set of ``body`` if its
    bound is reached, put the planes where they are at ``t``, and give its
    active vertices the planes of the per-vertex surfaces."""
    if needs_refresh(model, body, s, t):
        refresh(model, body, s, t)
    model.surfaces.set_planes(t)
    query(model, body, s, t)


def query(model, body, s, t):
    """The planes of the per-vertex surfaces under the active vertices at ``t``."""
    reach = query_reach(model, body, s)
    for j, surface in enumerate(model.surfaces.per_vertex):
        surface.ensure_reach(reach)
        surface.fill(s.vertices, s.pose, s.active, s.vertex_planes[j], s.cull_scratch.distance,
                     s.hint[j], t)


def initial_planes(surface_set, body, pose, reach):
    """Planes of every per-vertex surface under every vertex of the unworn
    ``body`` at ``pose`` and t = 0, finding mesh faces up to ``reach`` (m)
    away: (M, n, 3, 3) planes and (M, n) distances. For the placing checks and
    the first load balance, before any active set exists."""
    n = len(body.reference_vertices)
    out = np.zeros((len(surface_set.per_vertex), n, 3, 3))
    distance = np.full((len(surface_set.per_vertex), n), np.inf)
    for j, surface in enumerate(surface_set.per_vertex):
        out[j], distance[j] = surface.planes_at(body.reference_vertices, pose, 0.0, reach)
    return out, distance


def contact_faces(points, faces, surface_set, reach, sag=None, every=False):
    """(m,) bool: the faces of a body (``points`` its vertices in the world at
    the start) that can come into contact: they face a plane or the nearest
    point of another surface, and a vertex of theirs lies within ``reach`` (m)
    of it, or within ``reach`` plus the face's ``sag`` ((m,) m, None: 0),
    how far the part's true surface over the face may bulge out of it (a
    facet of a sphere); with ``every``, all three of its vertices (faces
    surely refined: a lower bound of the refinement's size). For refining a
    CAD part where it can touch, not everywhere."""
    from .. import geometry

    normals = geometry.face_normals(points, faces)
    allowed = reach if sag is None else reach + sag
    mask = np.zeros(len(faces), dtype=bool)
    for p in surface_set.planes:
        gap = (points - p[0]) @ p[1]
        corners = gap[faces].max(axis=1) if every else gap[faces].min(axis=1)
        mask |= (normals @ p[1] < -FACING) & (corners <= allowed)
    identity = np.zeros(13)
    identity[3] = 1.0
    points = np.ascontiguousarray(points)
    for surface in surface_set.per_vertex:
        vp, d = surface.planes_at(points, identity, 0.0, float(np.max(allowed, initial=reach)))
        # a face faces the surface where one of its vertices near it does
        # (all of them, with every)
        near = np.ones(len(faces), dtype=bool) if every else np.zeros(len(faces), dtype=bool)
        for corner in range(3):
            v = faces[:, corner]
            facing = np.einsum("ij,ij->i", normals, vp[v, 1]) < -FACING
            near = near & facing & (d[v] <= allowed) if every else near | facing & (d[v] <= allowed)
        mask |= near
    return mask


def slot_normals(model, s):
    """Contact normal of each counter-surface slot of body state ``s``: (3,)
    for a plane, (n, 3) per vertex for the others (zero where none)."""
    return [p[1] for p in model.planes] + [vp[:, 1] for vp in s.vertex_planes]


def vertex_feet(s, m, index):
    """(k, 3) world feet of the vertices ``index`` of body state ``s`` on
    the planes per-vertex surface ``m`` gives them."""
    planes = s.vertex_planes[m][index]
    R = quaternion_matrix(s.pose[3:7])
    x = s.pose[0:3] + s.vertices[index] @ R.T
    normal = planes[:, 1]
    return x - np.einsum("ij,ij->i", x - planes[:, 0], normal)[:, None] * normal


def contact_areas(body, s, normal):
    """(n,) contact area of each vertex of ``body`` (state ``s``) against a
    plane of ``normal`` ((3,) or (n, 3)): the area vector projected on it."""
    R = quaternion_matrix(s.pose[3:7])
    world = body.area_vectors[:, 0:3] @ R.T
    return -np.einsum("ij,ij->i", world, np.broadcast_to(normal, world.shape))
