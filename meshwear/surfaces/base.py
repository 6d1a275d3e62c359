"""The counter-surface interface: what every kind of counter-surface provides.

A counter-surface is what a worn body's vertices press on. It does not wear
and moves as a rigid body (:class:`SurfaceMotion`: a steady turn and a path).
Each kind gives every vertex of a worn body a plane (a point, the normal out
of the solid, the surface's velocity there), and the contact kernel applies
the point-plane contact of docs/model.md to it. Two ways:

uniform
    An analytic plane is the same plane for every vertex: one row of the
    kernel's ``planes`` (P, 4, 3) array (:meth:`CounterSurface.plane_row`).
per vertex
    Any other surface fills the plane under each active vertex into the
    body's ``vertex_planes`` (:meth:`CounterSurface.fill`), through the
    kernel its ``kind`` names in :mod:`meshwear.kernels.counter`.

A new kind is one subclass of :class:`CounterSurface` (registered in
:data:`meshwear.surfaces.TYPES`) and, if it is per vertex, one kernel. A
subclass sets, in ``__init__``:

``name``, ``motion``
    Its name (output files) and its :class:`SurfaceMotion`.
``uniform`` / ``kind``
    True for a uniform plane; else the kernel code of
    :mod:`meshwear.kernels.counter`.
``invariant``
    Its motion leaves its shape unchanged (a surface of revolution turning
    about its own axis, a plane moving within itself): its frame then leaves
    the turn out and only the velocity field keeps it, so the active set
    needs no refresh for it and a mesh's face lookups stay put.
``deviation``
    How far (m) its turn can change its shape although it counts as
    invariant (a faceted mesh ring: its facets' sagitta), 0 when exact.

and implements :meth:`bounds` (how far it can come towards a body),
:meth:`geometry` (its kernel's arrays) and :meth:`drawing` (a mesh to draw it
in ParaView).
"""

import numpy as np

from ..kernels.frames import (BOUNDS_SIZE, CONSTANT, LEVER, NORMAL, PROJECTION, RATE, UNIFORM,
                              surface_frame)
from ..kernels.contact import rotation_entries
from ..kernels.counter_wear import NO_PART
from ..motion.motions import Path


def quaternion_matrix(q):
    """(3, 3) rotation matrix of a unit quaternion (w, x, y, z)."""
    return np.array(rotation_entries(np.asarray(q, float))).reshape(3, 3)


def axis_rotation(axis, angle):
    """(3, 3) rotation by ``angle`` (rad) about the unit ``axis``."""
    x, y, z = axis
    c, s = np.cos(angle), np.sin(angle)
    K = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + s * K + (1.0 - c) * (K @ K)


def distance_to_line(point, line_point, direction):
    """Distance (m) of ``point`` from the line through ``line_point`` along unit ``direction``."""
    d = np.asarray(point, float) - np.asarray(line_point, float)
    return float(np.linalg.norm(d - (d @ direction) * direction))


class SurfaceMotion:
    """A counter-surface's rigid motion: its frame at rest (``R0``, ``position``),
    a steady turn (``rotation``: axis, rate, center) and a ``path``.

    A point ``y`` of the surface's frame is at time ``t`` at
    ``Rot(t) (R0 y + position - center) + center + path(t)``
    (:func:`meshwear.kernels.frames.surface_frame`).
    """

    def __init__(self, R0=None, position=(0.0, 0.0, 0.0), rotation=None, path=None):
        self.R0 = np.eye(3) if R0 is None else np.asarray(R0, float)
        self.position = np.asarray(position, float)
        if rotation is not None:
            self.axis = np.asarray(rotation.axis, float)
            self.rate = float(rotation.rate)
            self.center = np.asarray(rotation.center, float)
        else:
            self.axis, self.rate, self.center = np.array([0.0, 0.0, 1.0]), 0.0, np.zeros(3)
        self.path = Path(path)
        #: (19,) the kernels' ``motion`` array
        self.array = np.concatenate([self.R0.ravel(), self.position, self.axis, [self.rate],
                                     self.center])
        self.buffer = np.zeros((2, 3))

    @property
    def terms(self):
        """(k, 9) the path's terms."""
        return self.path.terms

    @property
    def moving(self):
        return self.rate != 0.0 or bool(self.path.terms.size)

    @property
    def period(self):
        """Cycle length (s) of the motion: the longer of the path's and the turn's."""
        periods = [p for p in (self.path.period,
                               2.0 * np.pi / abs(self.rate) if self.rate else None) if p]
        return max(periods) if periods else None

    def frame(self, t, frozen=False):
        """(3, 3) rotation and (4, 3) frame (origin, velocity, angular velocity,
        turn centre) at ``t``; ``frozen`` leaves the turn out of the pose."""
        rotation, frame = np.zeros((3, 3)), np.zeros((4, 3))
        surface_frame(self.array, self.terms, float(t), frozen, self.buffer, rotation, frame)
        return rotation, frame

    def path_directions(self):
        """(k, 3) unit directions the path moves along (an oscillation's axis,
        a velocity, the two axes of a circle)."""
        rows = []
        for term in self.path.terms:
            for v in (term[1:4], term[4:7]):
                if np.linalg.norm(v) > 0.0:
                    rows.append(v / np.linalg.norm(v))
        return np.array(rows).reshape(-1, 3)


class CounterSurface:
    """Base of every counter-surface kind (see the module docstring for the contract)."""

    uniform = False
    kind = None
    #: it wears (a mesh with ``wear = true``: :meth:`MeshSurface.make_worn`)
    worn = False

    def __init__(self, name, motion):
        self.name = name
        self.motion = motion
        self.invariant = False
        self.deviation = 0.0
        self._compiled = None

    # ---------------------------------------------------------- motion
    @property
    def static(self):
        """It never moves."""
        return not self.motion.moving

    @property
    def frozen(self):
        """Queries leave its turn out (it moves, but not its shape; a worn
        surface's wear turns with it, so its queries do too)."""
        return self.invariant and self.motion.rate != 0.0 and not self.worn

    @property
    def period(self):
        return self.motion.period

    def frame(self, t):
        """Its frame at ``t`` as the contact sees it (frozen when invariant)."""
        return self.motion.frame(t, self.frozen)

    def bounds(self):
        """(16,) how far it can come towards a body (:mod:`meshwear.kernels.frames`)."""
        raise NotImplementedError

    def _bounds(self, constant=0.0, lever=0.0, projection=None, normal=None):
        out = np.zeros(BOUNDS_SIZE)
        out[CONSTANT] = constant
        out[LEVER] = lever
        out[RATE] = abs(self.motion.rate) if lever > 0.0 else 0.0
        out[PROJECTION] = (np.eye(3) if projection is None else projection).ravel()
        if normal is not None:
            out[UNIFORM] = 1.0
            out[NORMAL] = normal
        return out

    def describe(self):
        """How it moves, in a few words (``meshwear check``)."""
        m = self.motion
        if getattr(self, "rider", False):
            return "on a mechanism body (MuJoCo moves it)"
        if self.static:
            return "fixed"
        parts = []
        if m.rate:
            parts.append(f"turning at {m.rate:g} rad/s")
        if m.path.terms.size:
            parts.append("on a path")
        text = " and ".join(parts)
        if self.invariant and m.rate:
            exact = (f"within {self.deviation:.3g} m" if self.deviation > 0.0 else "exactly")
            text += f" about its own axis (a surface of revolution {exact}): "
            text += ("its active set stays put, its face lookups follow its wear round"
                     if self.worn else "static in shape")
        return text

    # ---------------------------------------------------------- planes
    def plane_row(self, t, out):
        """Uniform planes: fill the (4, 3) row of the kernel's ``planes`` at ``t``."""
        raise NotImplementedError

    def part_tuple(self):
        """Its wear as :func:`meshwear.kernels.counter_wear.wear_counter` takes
        it: none (law code -1) unless a worn mesh overrides this."""
        return NO_PART

    def geometry(self):
        """Per-vertex kinds: ``geometry`` (g,) and the mesh arrays of a surface
        tuple (:data:`meshwear.kernels.counter.SURFACE_FIELDS`), as a dict."""
        raise NotImplementedError

    def compiled(self):
        """The surface tuple :func:`meshwear.kernels.counter.fill_planes` takes."""
        if self._compiled is None:
            g = {"counter_vertices": np.zeros((0, 3)), "faces": np.zeros((0, 3), np.int64),
                 "frames": np.zeros((0, 4, 4)), "corner_normals": np.zeros((0, 3, 3)),
                 "search": np.zeros(2), "boxes": np.zeros((0, 6)),
                 "nodes": np.zeros((0, 2), np.int64), "order": np.zeros(0, np.int64),
                 "neighbours": np.zeros((0, 3), np.int64)}
            g.update(self.geometry())
            self._compiled = (np.int64(self.kind), np.ascontiguousarray(g["geometry"], float),
                              self.motion.array, np.ascontiguousarray(self.motion.terms),
                              bool(self.frozen), g["counter_vertices"], g["faces"], g["frames"],
                              g["corner_normals"], g["search"], g["boxes"], g["nodes"],
                              g["order"], g["neighbours"], self.part_tuple())
        return self._compiled

    def fill(self, body_vertices, pose, active, out, distance, hint, t):
        """Per-vertex kinds: the plane under each ``active`` vertex at ``t``
        (:func:`meshwear.kernels.counter.fill_planes`)."""
        from ..kernels.counter import NAMES, PARALLEL_THRESHOLD, fill_planes_for

        # (the build of this kind only: a first run compiles no other kind's kernels)
        fill_planes = fill_planes_for((NAMES[self.kind],), len(active) >= PARALLEL_THRESHOLD)
        fill_planes(self.compiled(), float(t), body_vertices, pose, active, out, distance, hint,
                    self.motion.buffer, np.zeros((3, 3)), np.zeros((4, 3)))

    def planes_at(self, body_vertices, pose, t, reach):
        """(n, 3, 3) planes and (n,) distances under every vertex, untracked,
        finding mesh faces up to ``reach`` (m) away (placing checks, before
        any active set exists)."""
        from ..kernels.contact import all_vertices

        n = len(body_vertices)
        out, distance = np.zeros((n, 3, 3)), np.full(n, np.inf)
        self.fill(body_vertices, pose, all_vertices(n), out, distance, np.full(n, -1), t)
        return out, distance

    def candidates(self, surface_set, body, pose, x, t, margin):
        """Indices of the vertices (world positions ``x`` (n, 3)) a refresh of
        the active set must query: all of them by default."""
        return np.arange(len(x))

    def ensure_reach(self, reach):
        """Make queries find the surface up to ``reach`` (m) away (meshes bin faces)."""

    def fill_within(self, reach, body_vertices, pose, active, out, distance, hint, t):
        """:meth:`fill` finding the surface up to ``reach`` (m) away (the
        active set's refresh)."""
        self.ensure_reach(reach)
        self.fill(body_vertices, pose, active, out, distance, hint, t)

    # ---------------------------------------------------------- drawing
    def drawing(self, extent):
        """(vertices, faces) to draw it, in its own frame; ``extent`` (m) sizes
        unbounded surfaces."""
        raise NotImplementedError

    def world_vertices(self, vertices, t):
        """Drawing ``vertices`` (its own frame) in the world at ``t``, turned (not frozen)."""
        rotation, frame = self.motion.frame(t)
        return vertices @ rotation.T + frame[0]
