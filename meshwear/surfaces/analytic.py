"""Analytic counter-surfaces of revolution: cylinders (shafts, rings, bores) and spheres.

Each vertex gets the exact tangent plane at its closest point of the surface
(:mod:`meshwear.kernels.analytic`): no faceting and no face lookup, so a ring
of any radius costs what a plane costs per vertex.
"""

import numpy as np

from ..kernels.counter import CYLINDER, SPHERE
from ..motion.motions import _perpendicular
from .base import CounterSurface, SurfaceMotion, distance_to_line

#: relative tolerance for "parallel" and "on the axis"
ALIGNED = 1e-9
#: sections and subdivisions of the meshes that draw analytic surfaces
DRAW_SECTIONS, DRAW_SUBDIVISIONS = 128, 3

SIDES = ("outside", "inside")


def frame_along(axis):
    """(3, 3) rotation whose third column is the unit ``axis`` (local z -> axis)."""
    axis = np.asarray(axis, float)
    e1 = _perpendicular(axis)
    return np.column_stack([e1, np.cross(axis, e1), axis])


def _tube(radius, length, sections, inward):
    """The lateral surface of a cylinder along z, centred at the origin (open)."""
    angle = 2.0 * np.pi * np.arange(sections) / sections
    ring = np.column_stack([radius * np.cos(angle), radius * np.sin(angle), np.zeros(sections)])
    vertices = np.concatenate([ring + [0.0, 0.0, -0.5 * length], ring + [0.0, 0.0, 0.5 * length]])
    j = np.arange(sections)
    k = (j + 1) % sections
    faces = np.concatenate([np.column_stack([j, k, k + sections]),
                            np.column_stack([j, k + sections, j + sections])])
    if inward:
        faces = faces[:, ::-1]
    return vertices, np.ascontiguousarray(faces, dtype=np.int64)


class Cylinder(CounterSurface):
    """A cylinder of ``radius`` about the line through ``point`` along unit
    ``axis``; ``length`` (m) centred on ``point``, or None for an infinite one.
    ``side = "outside"``: the solid is within the radius (a shaft, a ring);
    ``"inside"``: outside it (a bore, a bushing). Only its lateral surface
    touches: a vertex beyond a finite cylinder's ends has no plane."""

    kind = CYLINDER

    def __init__(self, name, radius, axis, point, length=None, side="outside", rotation=None,
                 path=None):
        self.radius = float(radius)
        self.axis = np.asarray(axis, float)
        self.point = np.asarray(point, float)
        self.length = None if length is None else float(length)
        self.side = side
        super().__init__(name, SurfaceMotion(frame_along(self.axis), self.point, rotation, path))
        m = self.motion
        scale = max(self.radius, float(np.linalg.norm(self.point)), 1e-300)
        parallel = bool(np.linalg.norm(np.cross(m.axis, self.axis)) <= ALIGNED)
        offset = distance_to_line(m.center, self.point, self.axis)
        turn_keeps = m.rate == 0.0 or (parallel and offset <= ALIGNED * scale)
        directions = m.path_directions()
        path_keeps = not len(directions) or (
            self.length is None
            and bool(np.all(np.linalg.norm(np.cross(directions, self.axis), axis=1) <= ALIGNED)))
        self.invariant = turn_keeps and path_keeps
        if m.rate == 0.0 or turn_keeps:
            self.lever = 0.0
        elif parallel:
            self.lever = offset       # an eccentric: its axis circles the turn's
        elif self.length is not None:
            self.lever = float(np.linalg.norm(self.point - m.center)
                               + np.hypot(0.5 * self.length, self.radius))
        else:   # refused by the scene checks: an infinite cylinder tumbling
            raise ValueError(f"surface {name!r}: an infinite cylinder can turn only about an "
                             "axis parallel to its own")

    @classmethod
    def from_config(cls, config):
        return cls(config.name, config.radius, config.axis, config.point, config.length,
                   config.side, config.rotation, config.path)

    def geometry(self):
        half = np.inf if self.length is None else 0.5 * self.length
        return {"geometry": np.array([self.radius, half, float(SIDES.index(self.side))])}

    def bounds(self):
        # an infinite cylinder sliding along its axis stays where it is
        projection = (np.eye(3) - np.outer(self.axis, self.axis) if self.length is None
                      else np.eye(3))
        return self._bounds(lever=self.lever, projection=projection)

    def drawing(self, extent):
        return _tube(self.radius, self.length or extent, DRAW_SECTIONS, self.side == "inside")


class Sphere(CounterSurface):
    """A sphere of ``radius`` about ``center``: ``side = "outside"`` a ball,
    ``"inside"`` a spherical cup (the solid outside the radius)."""

    kind = SPHERE

    def __init__(self, name, radius, center, side="outside", rotation=None, path=None):
        self.radius = float(radius)
        self.center = np.asarray(center, float)
        self.side = side
        super().__init__(name, SurfaceMotion(None, self.center, rotation, path))
        m = self.motion
        scale = max(self.radius, float(np.linalg.norm(self.center)), 1e-300)
        offset = distance_to_line(self.center, m.center, m.axis)
        turn_keeps = m.rate == 0.0 or offset <= ALIGNED * scale
        self.invariant = turn_keeps and not m.path.terms.size
        self.lever = 0.0 if turn_keeps else offset

    @classmethod
    def from_config(cls, config):
        return cls(config.name, config.radius, config.center, config.side, config.rotation,
                   config.path)

    def geometry(self):
        return {"geometry": np.array([self.radius, float(SIDES.index(self.side)), 0.0])}

    def bounds(self):
        return self._bounds(lever=self.lever)

    def drawing(self, extent):
        import trimesh

        m = trimesh.creation.icosphere(subdivisions=DRAW_SUBDIVISIONS, radius=self.radius)
        faces = np.asarray(m.faces, dtype=np.int64)
        if self.side == "inside":
            faces = faces[:, ::-1]
        return np.ascontiguousarray(m.vertices, dtype=float), np.ascontiguousarray(faces)
