"""Mesh counter-surfaces: a rigid triangle mesh, its face tree and its fcl BVH.

Each vertex of a worn body gets the plane of its nearest counter face
(:mod:`meshwear.kernels.nearest`). A mesh turning about an axis that it is a
surface of revolution about (a ring, a disc, a shaft, within the sagitta of
its facets) counts as static in shape: its deviation from that surface,
measured when the run is built, is checked against the active-set margin.
"""

import itertools
import logging

import fcl
import numpy as np

from .. import geometry
from ..geometry import meshes, remesh
from ..kernels import tree
from ..kernels.counter import MESH
from ..kernels.laws import name_of as code_name
from ..kernels.nearest import (corner_normals, face_frames, nearest_planes_parallel,
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
#: a worn mesh grows its face tree's boxes by this fraction of the steps'
#: reach on the side its vertices sink to (not towards the bodies: their
#: queries keep tight bounds), so its wear needs no new fit until some
#: vertex has sunk that far since the last one
WEAR_SLACK = 0.1
#: an unworn mesh grows its boxes by this fraction of its size (rounding)
ROUNDING = 1e-9


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


#: the spread of a worn surface whose vertices keep their shares
NO_SPREAD = (np.zeros(0, np.int64), np.zeros(0, np.int32), np.zeros(0), np.zeros(0), np.zeros(1),
             np.zeros(0))

def spread_weights(vertices, area, k, j, radius):
    """The even spread's weight of vertex ``j`` from vertex ``k`` (arrays of
    pairs): ``(1 - r²/R²)² A_j``, r their distance, R ``radius``, not yet
    normalised (:meth:`MeshSurface.spread_over`)."""
    d = vertices[j] - vertices[k]
    r2 = np.einsum("ij,ij->i", d, d) / (radius * radius)
    return np.where(r2 < 1.0, (1.0 - np.minimum(r2, 1.0)) ** 2, 0.0) * area[j]


#: neighbours whose unworn normals are within 60 degrees share a spread
SPREAD_FACING = 0.5

#: a worn surface's spread lists hold at most this many entries (4 bytes
#: each); a counter far finer than the bodies spreads over a shorter radius
SPREAD_ENTRIES = 100_000_000

#: spreading vertices whose lists are built at once
SPREAD_CHUNK = 4096


class MeshSurface(CounterSurface):
    """A rigid counter mesh: its faces in its own frame, placed by
    ``orientation`` (quaternion) and ``position`` and moved by ``rotation`` and
    ``path`` (:class:`meshwear.surfaces.base.SurfaceMotion`)."""

    kind = MESH

    def __init__(self, name, vertices, faces, position, orientation, rotation=None, path=None,
                 smooth_normals=False):
        super().__init__(name, SurfaceMotion(quaternion_matrix(orientation), position, rotation,
                                             path))
        self.vertices, self.faces = meshes._arrays(vertices, faces)
        self.face_normals = np.ascontiguousarray(geometry.face_normals(self.vertices, self.faces))
        self.frames = face_frames(self.vertices, self.faces)
        self.corner_normals = (corner_normals(self.vertices, self.faces, self.face_normals)
                               if smooth_normals else np.zeros((0, 3, 3)))
        m = self.motion
        world = self.vertices @ m.R0.T + m.position - m.center
        #: largest distance of a mesh point from the turn's axis (m)
        self.lever = float(np.linalg.norm(world - np.outer(world @ m.axis, m.axis), axis=1).max())
        #: how far (m) the steps' queries look, and the array the compiled
        #: tuple reads it from (the refresh and the placing checks look
        #: farther through it)
        self.reach = 0.0
        self.search = np.zeros(2)
        #: (boxes, nodes, order) of the faces (:mod:`meshwear.kernels.tree`)
        #: and the face across each edge
        self.tree = None
        self.neighbours = tree.face_neighbours(self.faces)
        #: what ``resolution`` did (:func:`meshwear.geometry.remesh.refine_part`), or None
        self.refinement = None
        #: a worn one's boxes' slack (m) and its wear depth when they were
        #: last fitted
        self.pad = 0.0
        self.fitted_depth = None
        #: the :class:`meshwear.model.PartState` a worn one queries and draws
        self.part = None
        self._bvh = None
        #: the primitive it was made from (a scene's ``shape``), None for a mesh file
        self.shape = None

    @property
    def bvh(self):
        """Its fcl collision object for the broad phase (:meth:`_fcl`)."""
        return self._fcl()[1]

    @property
    def bvh_geometry(self):
        """The fcl BVH :attr:`bvh` holds."""
        return self._fcl()[0]

    def _fcl(self):
        """Its fcl BVH and collision object, built at the first need from its
        unworn faces: a surface refused, or refined into another, never
        needs them (0.09 s for the gear pair's wheel, 18 600 faces)."""
        if self._bvh is None:
            geometry_ = bvh(getattr(self, "reference_vertices", self.vertices), self.faces)
            self._bvh = (geometry_, fcl.CollisionObject(geometry_, fcl.Transform()))
        return self._bvh

    @classmethod
    def from_config(cls, config, mechanism=None, loaded=None):
        """A :class:`MeshSurface` from a validated ``[[surface]]`` of type
        mesh (its mesh from a geom of the ``mechanism`` if it names one;
        ``loaded``: the mesh files read so far, :func:`meshwear.geometry.load_part`).

        Raises
        ------
        geometry.MeshError
            For a mesh the engine cannot use; the caller adds the key.
        """
        vertices, faces = geometry.load_part(config, mechanism, loaded)
        out = cls(config.name, vertices, faces, config.position, config.orientation,
                  config.rotation, config.path, config.smooth_normals)
        out.shape = config.shape
        return out

    def refined(self, config, face_mask=None):
        """A :class:`MeshSurface` of this mesh refined to ``config.resolution``
        where ``face_mask`` says (:func:`meshwear.geometry.remesh.refine_part`);
        built before it wears.

        Raises
        ------
        geometry.MeshError
            For a refinement the machine cannot hold; the caller adds the key.
        """
        vertices, faces, info = remesh.refine_part(config, self.vertices, self.faces, face_mask)
        out = type(self)(config.name, vertices, faces, config.position, config.orientation,
                         config.rotation, config.path, config.smooth_normals)
        out.refinement = info
        out.shape = config.shape
        return out

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
        :data:`SAMPLE_TURNS`; ``inf`` if it exceeds ``limit`` (m). A
        cylinder ``shape`` turning about its own axis: its facets' sag
        (:meth:`_own_axis_deviation`)."""
        m = self.motion
        axis = m.R0.T @ m.axis                      # the turn's axis in the mesh frame
        center = m.R0.T @ (m.center - m.position)
        own = self._own_axis_deviation(axis, center)
        if own is not None:
            return own if own <= limit else np.inf
        samples = np.concatenate([self.vertices, self.vertices[self.faces].mean(axis=1)])
        if len(samples) > MAX_SAMPLES:
            pick = np.random.default_rng(0).choice(len(samples), MAX_SAMPLES, replace=False)
            samples = samples[np.sort(pick)]
        boxes, nodes, order = self._tree()
        search = np.array([limit, 0.0])
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
                   self.faces, self.frames, self.corner_normals, search, boxes, nodes, order,
                   self.neighbours, out, distance, np.full(n, -1), True, False)
            worst = max(worst, float(distance.max()))
            if not worst <= limit:
                return np.inf
        return worst

    def _own_axis_deviation(self, axis, center):
        """For a cylinder ``shape`` (refined or not) turning about its own
        axis (``axis`` and a point of it, ``center``, in its frame), the
        largest sag of its side's facets under the true cylinder (m), else
        None. Its side's vertices lie on that cylinder and its caps in their
        planes, so the mesh and the mesh turned are radial graphs over the
        same (angle, height) within that sag of the cylinder: no point of
        one is farther from the other. Sampling it instead costs O(n²) in
        its ``sections`` n (its caps are fans of n slivers round their
        centres, and a query near a centre meets all their boxes): 10 000
        sections took 5-9 s, 100 000 more than ten minutes."""
        shape = self.shape
        if shape is None or shape.type != "cylinder":
            return None
        tolerance = 1e-12 * shape.radius
        if (np.linalg.norm(axis[0:2]) > 1e-12 or np.linalg.norm(center[0:2]) > tolerance):
            return None
        return float(geometry.facet_sag(shape, self.vertices, self.faces).max(initial=0.0))

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
        self.spread = NO_SPREAD
        self.worn = True
        self.invariant = False
        self._compiled = None

    def spread_over(self, radius, finer_than):
        """Let the wear of each contact spread over the vertices around the
        point it was put at, within ``radius`` (m) across the direction it
        slid in (docs/model.md, "Worn counter-surfaces"; the kernel,
        :func:`meshwear.kernels.counter_wear.wear_counter`, spreads along that
        direction only :data:`meshwear.kernels.counter_wear.ALONG` as far).
        Nothing spreads where the counter's vertices, those whose edges are
        on average shorter than ``radius``, have a median mean edge of
        ``finer_than`` (m) or more: a counter about as coarse as the bodies,
        or coarser, spreads a contact by its own faces; else those vertices
        spread. Sets ``spread``, ``(starts, items, [], self, radius,
        face_area)``: for each spreading vertex ``k`` the vertices within
        ``radius`` past its longest edge (as far as a spread from a point on
        its faces can reach) whose unworn normals are within 60 degrees of
        ``k``'s (not across a crease or through a thin wall; int32, 4 bytes
        an entry: a counter four times finer than the bodies holds hundreds
        a vertex); ``self`` each vertex's weight on itself in the even
        spread from it (:func:`spread_weights`, normalised: a spread
        vertex's stiffness); each face's unworn area. Every other vertex has no list
        and keeps its shares (its ``self`` 1). Lists of more than
        :data:`SPREAD_ENTRIES` entries in all take a shorter radius, with a
        notice."""
        self.spread = NO_SPREAD
        self._compiled = None
        if not radius > 0.0:
            return
        edges = np.concatenate([self.faces[:, [0, 1]], self.faces[:, [1, 2]],
                                self.faces[:, [2, 0]]])
        lengths = np.linalg.norm(self.reference_vertices[edges[:, 0]]
                                 - self.reference_vertices[edges[:, 1]], axis=1)
        mean_edge = (np.bincount(edges.ravel(), np.repeat(lengths, 2), len(self.tributary))
                     / np.maximum(np.bincount(edges.ravel(), minlength=len(self.tributary)), 1))
        # the counter's spacing where it can be spread on: the median of
        # its vertices' mean edges, of those shorter than the radius
        spreads = mean_edge < radius
        if not spreads.any() or np.median(mean_edge[spreads]) >= finer_than:
            return
        from scipy.spatial import cKDTree

        V, normals, area = self.reference_vertices, self.vertex_normals, self.tributary
        longest = np.zeros(len(V))
        np.maximum.at(longest, edges.ravel(), np.repeat(lengths, 2))
        source = np.flatnonzero(spreads)
        # the lists' size: each vertex's disc over its own area, sum of
        # pi (R + l)² / A, a quadratic in R (before any query: a counter a
        # hundred times finer than the bodies would ask for billions)
        per = np.pi / np.maximum(area[source], 1e-300)
        a, b, c = per.sum(), 2.0 * (per * longest[source]).sum(), (per * longest[source] ** 2).sum()
        if a * radius * radius + b * radius + c > SPREAD_ENTRIES:
            shorter = max((-b + np.sqrt(b * b + 4.0 * a * (SPREAD_ENTRIES - c))) / (2.0 * a), 0.0) \
                if SPREAD_ENTRIES > c else 0.0
            logging.getLogger("meshwear").warning(
                "%s: its vertices are %.3g times finer than the bodies'; a contact's wear "
                "spreads within %.3g m of it instead of %.3g m (memory), and may leave "
                "tracks a body vertex apart: give the bodies a finer resolution "
                "(docs/model.md, \"Worn counter-surfaces\")", self.name, finer_than /
                (2.0 * float(np.median(mean_edge[spreads]))), shorter, radius)
            if not shorter > 0.0:
                return
            radius = shorter
        # (as far as a point on any face at the vertex could spread), in
        # chunks: a query's lists of Python ints take 30 times the arrays
        tree = cKDTree(V)
        counts = np.zeros(len(V), np.int64)
        self_weight = np.ones(len(V))
        lists = []
        for lo in range(0, len(source), SPREAD_CHUNK):
            chunk = source[lo:lo + SPREAD_CHUNK]
            near = tree.query_ball_point(V[chunk], radius + longest[chunk], return_sorted=True)
            n = np.fromiter(map(len, near), np.int64, len(near))
            j = np.fromiter(itertools.chain.from_iterable(near), np.int64, int(n.sum()))
            k = np.repeat(chunk, n)
            keep = np.einsum("ij,ij->i", normals[j], normals[k]) >= SPREAD_FACING
            k, j = k[keep], j[keep]
            lists.append(j.astype(np.int32))
            counts[chunk] = np.bincount(k - chunk[0], minlength=chunk[-1] - chunk[0] + 1)[
                chunk - chunk[0]]
            weight = spread_weights(V, area, k, j, radius)
            own = k == j
            self_weight[chunk] = 0.0
            self_weight[k[own]] = weight[own] / np.bincount(k - chunk[0], weight)[k[own] - chunk[0]]
        # (source ascends, each list sorted; every other vertex has none and
        # keeps its shares)
        items = np.concatenate(lists)
        del lists
        starts = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        tri = self.reference_vertices[self.faces]
        face_area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]),
                                         axis=1)
        self.spread = (starts, items, np.zeros(0), self_weight, np.array([float(radius)]),
                       face_area)

    def attach(self, part):
        """Query and draw the worn geometry of ``part`` (a
        :class:`meshwear.model.PartState`): its vertices and face frames."""
        self.vertices, self.frames, self.part = part.vertices, part.frames, part
        self._compiled = None
        if self.tree is not None:
            self._fit()

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
        """Fit the tree's boxes anew where the faces are now (a worn part
        after a jump or a restart) if some vertex has sunk farther than
        their slack since they were fitted (O(F), in place)."""
        if (self.tree is not None and self.part is not None and self.fitted_depth is not None
                and float(np.abs(self.part.depth - self.fitted_depth).max(initial=0.0))
                > self.pad):
            self._fit()

    def _tree(self):
        """The faces' tree, built at the first need."""
        if self.tree is None:
            self.tree = tree.build(self.vertices, self.faces, *self._growth())
            self.fitted_depth = self._depth()
            self._compiled = None
        return self.tree

    def _growth(self):
        """How far (m) the boxes reach past the faces: rounding all round,
        and for a worn one the slack (:data:`WEAR_SLACK` of the reach) along
        its vertices' inward normals, and those normals."""
        size = float(np.ptp(self.vertices, axis=0).max()) if len(self.vertices) else 0.0
        if not self.worn:
            self.pad = 0.0
            return ROUNDING * size, 0.0, None
        self.pad = WEAR_SLACK * self.reach
        return ROUNDING * size, self.pad, self.vertex_normals

    def _depth(self):
        """A worn one's wear depth now (a copy), None for the others."""
        if not self.worn:
            return None
        return (self.part.depth.copy() if self.part is not None
                else np.zeros(len(self.vertices)))

    def _fit(self):
        """Fit the boxes to the faces where they are now (in place: the
        compiled tuple holds them)."""
        boxes, nodes, order = self.tree
        rounding, slack, sink = self._growth()
        tree.refit(self.vertices, self.faces, nodes, order, rounding, slack,
                   np.zeros((0, 3)) if sink is None else sink, boxes)
        self.fitted_depth = self._depth()

    def part_tuple(self):
        """The ``part`` tuple of :func:`meshwear.kernels.counter_wear.wear_counter`."""
        if not self.worn or self.part is None:     # (not attached to a state yet)
            return super().part_tuple()
        part = self.part
        return (self.law, self.faces, self.reference_vertices, self.vertex_normals,
                self.tributary, self.spacing, self.vertex_face_starts, self.vertex_face_items,
                part.vertices, part.frames, part.depth, part.volume, part.work, part.added,
                part.touched, part.limit, part.due, part.count, part.stiffness,
                part.place, (*self.spread, part.pending, part.pending_list,
                             part.pending_place, part.pending_count))

    # ------------------------------------------------------------ the interface
    def ensure_reach(self, reach):
        """Make the per-step queries find faces ``reach`` (m) away: the reach
        grows by half again when it must grow (a worn one's boxes then get
        the slack of that reach)."""
        if reach > self.reach:
            self.reach = 1.5 * reach
            self.search[0] = self.reach
            if self.tree is None:
                self._tree()
            elif self.worn:
                self._fit()

    def fill_within(self, reach, body_vertices, pose, active, out, distance, hint, t):
        """:meth:`fill` finding faces up to ``reach`` (m) away (the active
        set's refresh looks ten steps' motion away, the steps' own queries a
        few): the tree's search goes as far as asked."""
        self._looking(max(reach, self.reach), self.fill, body_vertices, pose, active, out,
                      distance, hint, t)

    def _looking(self, reach, call, *args):
        """``call(*args)`` with the queries reaching ``reach`` (m)."""
        self._tree()
        saved = self.search[0]
        self.search[0] = reach
        try:
            return call(*args)
        finally:
            self.search[0] = saved

    def geometry(self):
        boxes, nodes, order = self._tree()
        return {"geometry": np.zeros(3), "counter_vertices": self.vertices, "faces": self.faces,
                "frames": self.frames, "corner_normals": self.corner_normals,
                "search": self.search, "boxes": boxes, "nodes": nodes, "order": order,
                "neighbours": self.neighbours}

    def bounds(self):
        if self.invariant:
            # its turn moves its shape by at most the deviation, whenever
            return self._bounds(constant=2.0 * self.deviation)
        return self._bounds(lever=self.lever)

    def planes_at(self, body_vertices, pose, t, reach):
        return self._looking(reach, super().planes_at, body_vertices, pose, t, reach)

    def candidates(self, surface_set, body, pose, x, t, margin):
        """The vertices inside its bounding box grown by ``margin``, if the
        fcl broad phase finds the body within ``margin`` of it."""
        if self not in surface_set.meshes_within(body, pose, t, margin):
            return np.zeros(0, dtype=np.int64)
        rotation, frame = self.frame(t)
        y = (x - frame[0]) @ rotation
        box = self._tree()[0][0]          # the root's: every face, worn ones too
        lo, hi = box[0:3] - margin, box[3:6] + margin
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
