"""Counter-surfaces: analytic planes and meshes, and the active set of each body.

Planes stay analytic (the contact kernel reads their point and normal). A mesh
counter-surface is a rigid triangle mesh, possibly moving (a steady rotation
about an axis and a path, as a body's). For each vertex of a worn body it
gives the plane of the nearest counter face (:mod:`meshwear.kernels.nearest`),
so the same point-plane contact applies.

Active set. A worn body's vertices that are farther than a margin ``m`` from
every surface cannot touch one until the body or a surface has moved by
``m`` relative to the other, or the body has worn by it; the contact kernel
skips them. :func:`update` refreshes the set only when that bound (from the
poses and the wear of the active vertices, so O(active vertices) per step) is
reached, and the per-step cost follows the contact region, not the mesh size.

python-fcl finds whether a worn body can meet a counter mesh at all: one BVH
per mesh, built once from the unworn meshes (a worn body lies inside its unworn
mesh, so the unworn distance is a lower bound), queried at each refresh
through a collision manager. The per-vertex planes are computed by our own
kernel, since fcl's mesh queries are per triangle pair, not per vertex.
"""

from dataclasses import dataclass

import fcl
import numpy as np

from . import geometry
from .kernels.contact import FORCE, NO_CONTACT, rotation_entries
from .kernels.nearest import build_grid, corner_normals, face_frames, nearest_planes
from .motion import Path

#: default active-set margin, as a fraction of a body's bounding-box diagonal
MARGIN_FRACTION = 0.01

#: the margin is at least this many times the largest relative motion of one
#: step, so a vertex always meets a surface within reach before it touches
STEPS_IN_MARGIN = 10.0

#: slots of :attr:`meshwear.model.BodyState.cull`
CULL_MARGIN, CULL_TIME, CULL_POSE = 0, 1, slice(2, 9)
CULL_SIZE = 9


def _bvh(vertices, faces):
    model = fcl.BVHModel()
    model.beginModel(len(vertices), len(faces))
    model.addSubModel(vertices, faces)
    model.endModel()
    return model


def _quaternion_matrix(q):
    return np.array(rotation_entries(np.asarray(q, float))).reshape(3, 3)


def _axis_rotation(axis, angle):
    """Rotation matrix of ``angle`` (rad) about unit ``axis``."""
    x, y, z = axis
    c, s = np.cos(angle), np.sin(angle)
    K = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + s * K + (1.0 - c) * (K @ K)


class MeshSurface:
    """A rigid counter mesh: its faces in its own frame, the grid of its faces,
    its fcl BVH, and where it is at time ``t``.

    World position of a mesh point ``y`` at time ``t``:
    ``Rot(t) (R0 y + position - center) + center + path(t)``, ``Rot(t)`` the
    rotation by ``rate t`` about ``axis`` through ``center`` (none without
    ``rotation``), ``R0`` the ``orientation``.
    """

    def __init__(self, name, vertices, faces, position, orientation, rotation=None,
                 path=None, smooth_normals=False):
        self.name = name
        self.vertices, self.faces = geometry._arrays(vertices, faces)
        self.face_normals = np.ascontiguousarray(geometry.face_normals(self.vertices, self.faces))
        self.frames = face_frames(self.vertices, self.faces)
        self.corner_normals = (corner_normals(self.vertices, self.faces, self.face_normals)
                               if smooth_normals else np.zeros((0, 3, 3)))
        self.position = np.asarray(position, float)
        self.R0 = _quaternion_matrix(orientation)
        if rotation is not None:
            self.axis = np.asarray(rotation.axis, float)
            self.rate = float(rotation.rate)
            self.center = np.asarray(rotation.center, float)
        else:
            self.axis, self.rate, self.center = np.array([0.0, 0.0, 1.0]), 0.0, np.zeros(3)
        self.path = Path(path)
        #: largest distance of a mesh point from the rotation centre at rest (m)
        self.radius = float(np.linalg.norm(self.vertices @ self.R0.T + self.position - self.center,
                                           axis=1).max())
        self.reach = 0.0
        self.grid = None
        self.geometry = _bvh(self.vertices, self.faces)
        self.bvh = fcl.CollisionObject(self.geometry, fcl.Transform())
        self.rotation = np.eye(3)
        self.motion = np.zeros((4, 3))
        #: a surface that stays put: its frame is computed once
        self.static = self.rate == 0.0 and not self.path.terms.size
        self._frame_time = None

    @property
    def period(self):
        """Cycle length (s) of the surface's motion, None if it is steady."""
        periods = [p for p in (self.path.period,
                               2.0 * np.pi / abs(self.rate) if self.rate else None) if p]
        return max(periods) if periods else None

    def ensure_reach(self, reach):
        """(Re)bin the faces if queries must find faces ``reach`` (m) away."""
        if reach > self.reach:
            self.reach = 1.5 * reach
            self.grid = build_grid(self.vertices, self.faces, self.face_normals, self.reach)

    def frame(self, t):
        """Set :attr:`rotation` (3, 3) and :attr:`motion` (4, 3) to the
        surface's pose and velocity at time ``t`` (arrays of
        :mod:`meshwear.kernels.nearest`); return them."""
        if self.static and self._frame_time is not None:
            return self.rotation, self.motion
        self._frame_time = t
        turn = _axis_rotation(self.axis, self.rate * t)
        shift = self.path.displacement(t)
        self.rotation[:] = turn @ self.R0
        self.motion[0] = turn @ (self.position - self.center) + self.center + shift
        self.motion[1] = self.path.velocity(t)
        self.motion[2] = self.rate * self.axis
        self.motion[3] = self.center + shift
        return self.rotation, self.motion

    def world_vertices(self, t):
        rotation, motion = self.frame(t)
        return self.vertices @ rotation.T + motion[0]

    def displacement_bound(self, t0, t1):
        """Upper bound (m) on how far any point of the surface moves from ``t0`` to ``t1``."""
        if self.static:
            return 0.0
        turn = min(np.pi, abs(self.rate) * abs(t1 - t0))
        shift = np.linalg.norm(self.path.displacement(t1) - self.path.displacement(t0))
        return float(shift + 2.0 * np.sin(0.5 * turn) * self.radius)

    def speed_bound(self, t):
        """Upper bound (m/s) on the speed of any point of the surface at ``t``."""
        if self.static:
            return 0.0
        return float(np.linalg.norm(self.path.velocity(t)) + abs(self.rate) * self.radius)

    def query(self, vertices, pose, active, out, distance, t):
        """Nearest-face planes of the ``active`` vertices at ``t`` into ``out``
        (see :func:`meshwear.kernels.nearest.nearest_planes`)."""
        rotation, motion = self.frame(t)
        grid, keys, starts, items = self.grid
        nearest_planes(vertices, pose, active, rotation, motion, self.vertices, self.faces,
                       self.frames, self.corner_normals, grid, keys, starts, items,
                       out, distance)

    def transform(self, t):
        rotation, motion = self.frame(t)
        return fcl.Transform(rotation.copy(), motion[0].copy())


def build_mesh_surface(config):
    """A :class:`MeshSurface` from a validated ``[[surface]]`` of type mesh.

    Raises
    ------
    geometry.MeshError
        For a mesh the engine cannot use (unreadable, empty, NaN, all faces
        degenerate); the caller adds the key.
    """
    if config.mesh is not None:
        vertices, faces = geometry.load_mesh(config.mesh, config.units)
    else:
        s = config.shape
        vertices, faces = geometry.primitive(s.type, size=s.size, radius=s.radius,
                                             subdivisions=s.subdivisions, height=s.height,
                                             sections=s.sections)
    if config.resolution is not None:
        vertices, faces = geometry.refine(vertices, faces, config.resolution)
    return MeshSurface(config.name, vertices, faces, config.position, config.orientation,
                       config.rotation, config.path, config.smooth_normals)


class SurfaceSet:
    """Every counter-surface of a model, and the fcl collision manager of the
    mesh ones. ``planes`` is the kernel's (P, 3, 3) array."""

    def __init__(self, planes, meshes):
        self.planes = planes
        self.meshes = tuple(meshes)
        self.manager = None
        self.body_bvh = {}

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
        """Indices of the mesh surfaces that the unworn ``body`` at ``pose``
        comes within ``margin`` of (fcl broad phase, then BVH distances)."""
        if not self.meshes:
            return []
        key = id(body)
        if key not in self.body_bvh:
            geometry_ = _bvh(body.reference_vertices, body.faces)
            self.body_bvh[key] = (geometry_, fcl.CollisionObject(geometry_, fcl.Transform()))
        obj = self.body_bvh[key][1]
        obj.setTransform(fcl.Transform(_quaternion_matrix(pose[3:7]), pose[0:3].copy()))
        manager = self._manager(t)
        # the manager hands the callback fresh wrappers of its objects; the
        # geometries of a distance result are ours, so they name the surface
        index = {id(m.geometry): j for j, m in enumerate(self.meshes)}
        found = set()

        def near(o1, o2, data):
            result = fcl.DistanceResult()
            d = fcl.distance(o1, o2, fcl.DistanceRequest(), result)
            if d <= margin:
                found.update(index[id(g)] for g in (result.o1, result.o2) if id(g) in index)
            return False, margin   # go on with every pair whose boxes are within the margin

        manager.distance(obj, None, near)
        return sorted(found)


@dataclass
class Cull:
    """Scratch arrays of a body's active-set refresh."""

    distance: np.ndarray
    planes: np.ndarray


def body_margin(model, body):
    """Active-set margin (m) of ``body``: ``contact.margin`` or a fraction of its size."""
    given = model.scene.contact.margin
    if given is not None:
        return float(given)
    return MARGIN_FRACTION * float(np.linalg.norm(np.ptp(body.reference_vertices, axis=0)))


def _rotation_angle(q0, q1):
    c = min(1.0, abs(float(np.dot(q0, q1))))
    return 2.0 * np.arccos(c)


def _step_motion(model, body, s, t):
    """Upper bound (m) on how far a vertex of ``body`` moves relative to any
    surface in one step."""
    v = float(np.linalg.norm(s.pose[7:10]) + np.linalg.norm(s.pose[10:13]) * body.radius)
    v += max((m.speed_bound(t) for m in model.surfaces.meshes), default=0.0)
    return v * model.dt


def moved_since_refresh(model, body, s, t):
    """Upper bound (m) on how far any vertex of ``body`` has come towards any
    surface since the active set was refreshed, wear included. O(active
    vertices): it is checked every step."""
    cull = s.cull
    pose0, t0 = cull[CULL_POSE], cull[CULL_TIME]
    turn = _rotation_angle(s.pose[3:7], pose0[3:7])
    spin = 2.0 * np.sin(0.5 * min(np.pi, turn)) * body.radius
    shift = s.pose[0:3] - pose0[0:3]
    planes = model.surfaces.planes
    # against a plane only the motion along its normal counts
    bound = float(np.abs(planes[:, 1] @ shift).max()) + spin if len(planes) else 0.0
    if model.surfaces.meshes:
        body_motion = float(np.linalg.norm(shift)) + spin
        bound = max(bound, body_motion + max(m.displacement_bound(t0, t)
                                             for m in model.surfaces.meshes))
    # only active vertices wear: the largest wear since the refresh among them
    worn = float((s.wear_depth[s.active] - s.active_wear).max()) if len(s.active) else 0.0
    return bound + worn


def refresh(model, body, s, t):
    """Recompute the active set of ``body`` at time ``t``: every vertex within
    the margin of a plane or a mesh surface. Pairs of vertices that leave it
    are cleared (they are out of reach, so in no contact)."""
    surfaces = model.surfaces
    margin = max(body_margin(model, body), STEPS_IN_MARGIN * _step_motion(model, body, s, t))
    R = _quaternion_matrix(s.pose[3:7])
    x = s.pose[0:3] + s.vertices @ R.T
    near = np.zeros(len(x), dtype=bool)
    for p in surfaces.planes:
        near |= (x - p[0]) @ p[1] < margin
    for j in surfaces.meshes_within(body, s.pose, t, margin):
        mesh = surfaces.meshes[j]
        mesh.ensure_reach(margin)
        rotation, motion = mesh.frame(t)
        y = (x - motion[0]) @ rotation
        lo, hi = mesh.vertices.min(axis=0) - margin, mesh.vertices.max(axis=0) + margin
        candidates = np.flatnonzero(np.all((y >= lo) & (y <= hi), axis=1))
        scratch = s.cull_scratch
        scratch.planes[candidates] = 0.0
        mesh.query(s.vertices, s.pose, candidates, scratch.planes, scratch.distance, t)
        near[candidates[scratch.distance[candidates] < margin]] = True
    active = np.flatnonzero(near)
    left = np.setdiff1d(s.active, active, assume_unique=True)
    if len(left):
        s.contact_state[:, left] = NO_CONTACT
        s.normal_force[:, left] = 0.0
        s.tangential[:, left, FORCE] = 0.0
        s.vertex_planes[:, left] = 0.0
    s.active = active
    s.cull[CULL_MARGIN] = margin
    s.cull[CULL_TIME] = t
    s.cull[CULL_POSE] = s.pose[0:7]
    s.active_wear = s.wear_depth[active]


def update(model, body, s, t):
    """Before a step at time ``t``: refresh the active set of ``body`` if its
    bound is reached, then give its active vertices the planes of the mesh
    surfaces at ``t``."""
    if model.cull and (s.cull[CULL_MARGIN] == 0.0
                       or moved_since_refresh(model, body, s, t) + _step_motion(model, body, s, t)
                       >= s.cull[CULL_MARGIN]):
        refresh(model, body, s, t)
    query_meshes(model, body, s, t)


def query_meshes(model, body, s, t):
    """The planes of the mesh surfaces under the active vertices at ``t``."""
    for j, mesh in enumerate(model.surfaces.meshes):
        if mesh.grid is None:
            mesh.ensure_reach(max(body_margin(model, body), s.cull[CULL_MARGIN]))
        mesh.query(s.vertices, s.pose, s.active, s.vertex_planes[j], s.cull_scratch.distance, t)


def initial_planes(surface_set, body, pose, reach):
    """Planes of every mesh surface under every vertex of the unworn ``body``
    at ``pose`` and t = 0, finding faces up to ``reach`` (m) away: (M, n, 3, 3)
    planes and (M, n) distances. For the placing checks and the first load
    balance, before any active set exists."""
    return _planes_at(body.reference_vertices, pose, surface_set.meshes, reach)


def _planes_at(body_vertices, pose, meshes, reach):
    from .kernels.contact import all_vertices

    n = len(body_vertices)
    out = np.zeros((len(meshes), n, 3, 3))
    distance = np.full((len(meshes), n), np.inf)
    for j, mesh in enumerate(meshes):
        grid, keys, starts, items = build_grid(mesh.vertices, mesh.faces, mesh.face_normals, reach)
        rotation, motion = mesh.frame(0.0)
        nearest_planes(body_vertices, pose, all_vertices(n), rotation, motion, mesh.vertices,
                       mesh.faces, mesh.frames, mesh.corner_normals, grid, keys, starts,
                       items, out[j], distance[j])
    return out, distance


def contact_faces(points, faces, surface_set, reach):
    """(m,) bool: the faces of a body (``points`` its vertices in the world at
    the start) that can come into contact: they face a plane or the nearest
    face of a mesh surface, and a vertex of theirs lies within ``reach`` (m)
    of it. For refining a CAD part where it can touch, not everywhere."""
    from .kernels.contact import FACING

    normals = geometry.face_normals(points, faces)
    mask = np.zeros(len(faces), dtype=bool)
    for p in surface_set.planes:
        near = (points - p[0]) @ p[1] <= reach
        mask |= (normals @ p[1] < -FACING) & near[faces].any(axis=1)
    identity = np.zeros(13)
    identity[3] = 1.0
    planes, distance = _planes_at(np.ascontiguousarray(points), identity, surface_set.meshes, reach)
    for vp, d in zip(planes, distance):
        # a face faces the mesh where one of its vertices near it does
        for corner in range(3):
            v = faces[:, corner]
            facing = np.einsum("ij,ij->i", normals, vp[v, 1]) < -FACING
            mask |= facing & (d[v] <= reach)
    return mask


def slot_normals(model, s):
    """Contact normal of each counter-surface slot of body state ``s``: (3,)
    for a plane, (n, 3) per vertex for a mesh surface (zero where no face)."""
    return [p[1] for p in model.planes] + [vp[:, 1] for vp in s.vertex_planes]


def contact_areas(body, s, normal):
    """(n,) contact area of each vertex of ``body`` (state ``s``) against a
    plane of ``normal`` ((3,) or (n, 3)): the area vector projected on it."""
    R = _quaternion_matrix(s.pose[3:7])
    world = body.area_vectors[:, 0:3] @ R.T
    return -np.einsum("ij,ij->i", world, np.broadcast_to(normal, world.shape))
