"""Mesh counter-surfaces: a rigid triangle mesh, its face grid and its fcl BVH.

Each vertex of a worn body gets the plane of its nearest counter face
(:mod:`meshwear.kernels.nearest`). A mesh turning about an axis that it is a
surface of revolution about (a ring, a disc, a shaft, within the sagitta of
its facets) counts as static in shape: its deviation from that surface,
measured when the run is built, is checked against the active-set margin.
"""

import fcl
import numpy as np

from .. import geometry, remesh
from ..kernels.counter import MESH
from ..kernels.laws import name_of as code_name
from ..kernels.nearest import (build_grid, corner_normals, face_frames, nearest_planes_parallel,
                               nearest_planes_serial)
from .base import CounterSurface, SurfaceMotion, axis_rotation, quaternion_matrix

#: a turning mesh is static in shape when its deviation from a surface of
#: revolution about the turn's axis is at most this fraction of the smallest
#: active-set margin (the rest of the margin is left for the bodies' motion)
INVARIANT_FRACTION = 0.25
#: turns (fractions of a revolution) at which the deviation is sampled: far
#: from the n-fold symmetries of a meshed ring (golden-ratio multiples)
SAMPLE_TURNS = (0.145898, 0.381966, 0.618034, 0.854102)
#: the deviation is sampled at most at this many points (vertices, face centres)
MAX_SAMPLES = 200_000
#: a worn mesh bins its faces this fraction of the reach farther than its
#: queries cut at, so its wear (a vertex sinking along its normal) needs no
#: new binning until some vertex has sunk that far since the last one
WEAR_SLACK = 0.1


def bvh(vertices, faces):
    """An fcl BVH of a triangle mesh (MeshError for one without faces: fcl
    would crash)."""
    if len(faces) == 0 or len(vertices) == 0:
        raise geometry.MeshError("no triangle faces")
    model = fcl.BVHModel()
    model.beginModel(len(vertices), len(faces))
    model.addSubModel(vertices, faces)
    model.endModel()
    return model


class MeshSurface(CounterSurface):
    """A rigid counter mesh: its faces in its own frame, placed by
    ``orientation`` (quaternion) and ``position`` and moved by ``rotation`` and
    ``path`` (:class:`meshwear.surfaces.base.SurfaceMotion`)."""

    kind = MESH

    def __init__(self, name, vertices, faces, position, orientation, rotation=None, path=None,
                 smooth_normals=False):
        super().__init__(name, SurfaceMotion(quaternion_matrix(orientation), position, rotation,
                                             path))
        self.vertices, self.faces = geometry._arrays(vertices, faces)
        self.face_normals = np.ascontiguousarray(geometry.face_normals(self.vertices, self.faces))
        self.frames = face_frames(self.vertices, self.faces)
        self.corner_normals = (corner_normals(self.vertices, self.faces, self.face_normals)
                               if smooth_normals else np.zeros((0, 3, 3)))
        m = self.motion
        world = self.vertices @ m.R0.T + m.position - m.center
        #: largest distance of a mesh point from the turn's axis (m)
        self.lever = float(np.linalg.norm(world - np.outer(world @ m.axis, m.axis), axis=1).max())
        self.reach = 0.0
        self.grid = None
        #: a worn one's wear depth where its faces were last binned (None: not yet)
        self.binned_depth = None
        #: [reach, grid, binned depth, compiled tuple] of the active set's
        #: refresh when it looks farther than the steps' queries (None: not yet)
        self.far = None
        #: the :class:`meshwear.model.PartState` a worn one queries and draws
        self.part = None
        self.bvh_geometry = bvh(self.vertices, self.faces)
        self.bvh = fcl.CollisionObject(self.bvh_geometry, fcl.Transform())

    @classmethod
    def from_config(cls, config):
        """A :class:`MeshSurface` from a validated ``[[surface]]`` of type mesh.

        Raises
        ------
        geometry.MeshError
            For a mesh the engine cannot use; the caller adds the key.
        """
        vertices, faces = geometry.load_part(config)
        if config.resolution is not None:
            vertices, faces = remesh.refine(vertices, faces, config.resolution)
        return cls(config.name, vertices, faces, config.position, config.orientation,
                   config.rotation, config.path, config.smooth_normals)

    # ------------------------------------------------------------ shape invariance
    def settle_invariance(self, margin):
        """Decide whether its turn leaves its shape unchanged, against the
        smallest active-set ``margin`` (m): its deviation from a surface of
        revolution about the turn's axis at most :data:`INVARIANT_FRACTION`
        of it. A worn one keeps the active set of one (a body's vertex is
        never nearer its worn surface than its unworn one, and the refresh
        widens by the wear), but its queries turn with it: its wear does."""
        if self.motion.rate == 0.0:
            return
        limit = INVARIANT_FRACTION * margin
        deviation = self.revolution_deviation(limit)
        self.invariant = deviation <= limit
        self.deviation = deviation if self.invariant else 0.0
        self._compiled = None

    def revolution_deviation(self, limit):
        """Largest distance (m) of the mesh turned about its turn's axis from
        the mesh itself, sampled at its vertices and face centres at
        :data:`SAMPLE_TURNS`; ``inf`` if it exceeds ``limit`` (m)."""
        m = self.motion
        axis = m.R0.T @ m.axis                      # the turn's axis in the mesh frame
        center = m.R0.T @ (m.center - m.position)
        samples = np.concatenate([self.vertices, self.vertices[self.faces].mean(axis=1)])
        if len(samples) > MAX_SAMPLES:
            pick = np.random.default_rng(0).choice(len(samples), MAX_SAMPLES, replace=False)
            samples = samples[np.sort(pick)]
        grid, keys, starts, items = build_grid(self.vertices, self.faces, self.face_normals, limit)
        n = len(samples)
        identity = np.zeros(13)
        identity[3] = 1.0
        active = np.arange(n, dtype=np.int64)
        worst = 0.0
        kernel = nearest_planes_parallel if n >= 2048 else nearest_planes_serial
        for turn in SAMPLE_TURNS:
            turn_matrix = axis_rotation(axis, 2.0 * np.pi * turn)
            turned = np.ascontiguousarray((samples - center) @ turn_matrix.T + center)
            out, distance = np.zeros((n, 3, 3)), np.full(n, np.inf)
            kernel(turned, identity, active, np.eye(3), np.zeros((4, 3)), self.vertices,
                   self.faces, self.frames, self.corner_normals, grid, keys, starts, items, out,
                   distance, np.full(n, -1), True, False)
            worst = max(worst, float(distance.max()))
            if not worst <= limit:
                return np.inf
        return worst

    # ------------------------------------------------------------ wear
    def make_worn(self, law_code, coefficient):
        """Let it wear by law ``law_code`` (:mod:`meshwear.kernels.laws`) with
        ``coefficient``: it keeps its unworn vertices, their outward normals
        (wear moves a vertex against its normal), tributary areas, the
        shortest edge at each vertex and the faces at each vertex."""
        self.law = np.array([float(law_code), float(coefficient)])
        self.reference_vertices = self.vertices.copy()
        self.vertex_normals = geometry.vertex_normals(self.vertices, self.faces)
        self.tributary = geometry.tributary_areas(self.vertices, self.faces)
        edges = np.concatenate([self.faces[:, [0, 1]], self.faces[:, [1, 2]],
                                self.faces[:, [2, 0]]])
        lengths = np.linalg.norm(self.vertices[edges[:, 0]] - self.vertices[edges[:, 1]], axis=1)
        self.spacing = np.full(len(self.vertices), np.inf)
        np.minimum.at(self.spacing, edges.ravel(), np.repeat(lengths, 2))
        corners = self.faces.ravel()
        order = np.argsort(corners, kind="stable")
        self.vertex_face_items = np.ascontiguousarray(order // 3, dtype=np.int64)
        self.vertex_face_starts = np.concatenate(
            [[0], np.cumsum(np.bincount(corners, minlength=len(self.vertices)))]).astype(np.int64)
        self.worn = True
        self.invariant = False
        self._compiled = None

    def attach(self, part):
        """Query and draw the worn geometry of ``part`` (a
        :class:`meshwear.model.PartState`): its vertices and face frames."""
        self.vertices, self.frames, self.part = part.vertices, part.frames, part
        self._compiled = None
        if self.far is not None:
            self.far[3] = None                    # its tuple holds the arrays too

    def face_weights(self, points, face, t):
        """Barycentric weights (k, 3) of world ``points`` (k, 3) at ``t`` on
        the faces ``face`` (k,) (in its frame, as it is worn; projected on the
        face and clipped to it) and those faces' corners (k, 3)."""
        rotation, frame = self.frame(t)
        local = (points - frame[0]) @ rotation
        corners = self.faces[face]
        a, b, c = (self.vertices[corners[:, j]] for j in range(3))
        v0, v1, v2 = b - a, c - a, local - a
        d00, d01, d11 = (np.einsum("ij,ij->i", p, q) for p, q in ((v0, v0), (v0, v1), (v1, v1)))
        d20, d21 = np.einsum("ij,ij->i", v2, v0), np.einsum("ij,ij->i", v2, v1)
        denom = d00 * d11 - d01 * d01
        v = (d11 * d20 - d01 * d21) / denom
        w = (d00 * d21 - d01 * d20) / denom
        weights = np.clip(np.stack([1.0 - v - w, v, w], axis=1), 0.0, None)
        weights /= weights.sum(axis=1, keepdims=True)
        return weights, corners

    def rebin(self):
        """Bin the faces anew where they are now (a worn part after a jump or
        a restart) if some vertex has sunk farther than a grid's slack
        (:data:`WEAR_SLACK` of its reach) since they were binned for it. Binning the gear pair's wheel (18 600 faces, a 3.3 mm
        reach) took 1.5-2 s a jump; its wear over 10^5 revolutions is a few µm."""
        if self.grid is not None and self._sunk(self.binned_depth, self.reach):
            self.grid, self.binned_depth = self._bin(self.reach)
            self._compiled = None
        if self.far is not None and self._sunk(self.far[2], self.far[0]):
            self.far = None                   # binned anew when next asked for

    def _sunk(self, binned_depth, reach):
        """Whether a worn one has sunk past the slack of a grid binned at ``binned_depth``."""
        return (self.part is not None and binned_depth is not None and float(
            np.abs(self.part.depth - binned_depth).max(initial=0.0)) > WEAR_SLACK * reach)

    def _bin(self, reach):
        """A face grid whose cells list every face within ``reach`` (and the
        wear slack, for a worn one) of their points, queries cutting at
        ``reach``; and the wear depth it was binned at (None: it does not wear)."""
        if not self.worn:
            return build_grid(self.vertices, self.faces, self.face_normals, reach), None
        grid = build_grid(self.vertices, self.faces, self.face_normals,
                          (1.0 + WEAR_SLACK) * reach)
        grid[0][7] = reach
        depth = self.part.depth.copy() if self.part is not None else np.zeros(len(self.vertices))
        return grid, depth

    def part_tuple(self):
        """The ``part`` tuple of :func:`meshwear.kernels.counter_wear.wear_counter`."""
        if not self.worn or self.part is None:     # (not attached to a state yet)
            return super().part_tuple()
        part = self.part
        return (self.law, self.faces, self.reference_vertices, self.vertex_normals,
                self.tributary, self.spacing, self.vertex_face_starts, self.vertex_face_items,
                part.vertices, part.frames, part.depth, part.volume, part.work, part.added,
                part.touched)

    # ------------------------------------------------------------ the interface
    def ensure_reach(self, reach):
        """(Re)bin the faces if the per-step queries must find faces ``reach`` (m) away."""
        if reach > self.reach:
            self.reach = 1.5 * reach
            self.grid, self.binned_depth = self._bin(self.reach)
            self._compiled = None

    def fill_within(self, reach, body_vertices, pose, active, out, distance, hint, t):
        """:meth:`fill` finding faces up to ``reach`` (m) away, on a grid of
        its own if that is farther than the per-step queries look: the
        active set's refresh looks ten steps' motion away, the steps' own
        queries a few (their cells list the faces within that reach: the
        gear pair's wheel ~800 a cell at the refresh's 3.3 mm)."""
        if reach <= self.reach:
            self.fill(body_vertices, pose, active, out, distance, hint, t)
            return
        if self.far is None or reach > self.far[0]:
            far_reach = 1.5 * reach
            self.far = [far_reach, *self._bin(far_reach), None]
        near = self.grid, self.reach, self._compiled
        self.reach, self.grid, _, self._compiled = self.far
        try:
            self.fill(body_vertices, pose, active, out, distance, hint, t)
        finally:
            self.far[3] = self._compiled
            self.grid, self.reach, self._compiled = near

    def geometry(self):
        if self.grid is None:
            raise RuntimeError(f"mesh surface {self.name!r}: no face grid yet (ensure_reach)")
        grid, keys, starts, items = self.grid
        return {"geometry": np.zeros(3), "counter_vertices": self.vertices, "faces": self.faces,
                "frames": self.frames, "corner_normals": self.corner_normals, "grid": grid,
                "keys": keys, "starts": starts, "items": items}

    def bounds(self):
        if self.invariant:
            # its turn moves its shape by at most the deviation, whenever
            return self._bounds(constant=2.0 * self.deviation)
        return self._bounds(lever=self.lever)

    def planes_at(self, body_vertices, pose, t, reach):
        saved = self.grid, self.reach, self._compiled
        self.grid, self._compiled = build_grid(self.vertices, self.faces, self.face_normals,
                                               reach), None
        try:
            return super().planes_at(body_vertices, pose, t, reach)
        finally:
            self.grid, self.reach, self._compiled = saved

    def candidates(self, surface_set, body, pose, x, t, margin):
        """The vertices inside its bounding box grown by ``margin``, if the
        fcl broad phase finds the body within ``margin`` of it."""
        if self not in surface_set.meshes_within(body, pose, t, margin):
            return np.zeros(0, dtype=np.int64)
        rotation, frame = self.frame(t)
        y = (x - frame[0]) @ rotation
        lo, hi = self.vertices.min(axis=0) - margin, self.vertices.max(axis=0) + margin
        return np.flatnonzero(np.all((y >= lo) & (y <= hi), axis=1))

    def transform(self, t):
        """Its fcl transform at ``t`` (frozen when static in shape)."""
        rotation, frame = self.frame(t)
        return fcl.Transform(rotation.copy(), frame[0].copy())

    def drawing(self, extent):
        return self.vertices, self.faces

    def describe(self):
        text = super().describe()
        if self.motion.rate and not self.invariant:
            text += " (not a surface of revolution about that axis: its turn changes its shape)"
        if self.worn:
            text += f"; wears ({code_name(int(self.law[0]))}, coefficient {self.law[1]:g})"
        return text
