"""Analytic planes: a uniform counter-surface, one row of the contact kernel's ``planes``."""

import numpy as np

from ..kernels.frames import plane_rows
from ..geometry.meshes import plane_patch
from .base import CounterSurface, SurfaceMotion


class Plane(CounterSurface):
    """The plane through ``point`` with unit ``normal`` (out of the solid, into
    the worn bodies), possibly turning about its normal (a disc: ``rotation``
    with an axis along the normal) and on a ``path``.

    A turn about the normal and a path within the plane leave it where it is
    (``invariant``); a path with a component along the normal moves it. Its
    point is taken on the turn's axis, so the surface velocity under a vertex
    is the path's plus ``omega x (foot - point)``.
    """

    uniform = True

    def __init__(self, name, point, normal, size=None, rotation=None, path=None):
        normal = np.asarray(normal, float)
        point = np.asarray(point, float)
        motion = SurfaceMotion(rotation=rotation, path=path)
        if motion.rate:
            # the point of the plane on the turn's axis
            point = motion.center - ((motion.center - point) @ normal) * normal
        super().__init__(name, motion)
        self.point, self.normal, self.size = point, normal, size
        directions = motion.path_directions()
        self.invariant = not len(directions) or bool(np.all(np.abs(directions @ normal) <= 1e-12))

    @classmethod
    def from_config(cls, config):
        return cls(config.name, config.point, config.normal, config.size, config.rotation,
                   config.path)

    def plane_row(self, t, out):
        plane_rows(self.motion.array, self.motion.terms, self.normal, self.point, float(t),
                   self.motion.buffer, out)

    def bounds(self):
        # only the motion along its normal brings it nearer a body
        return self._bounds(projection=np.outer(self.normal, self.normal), normal=self.normal)

    def describe(self):
        if getattr(self, "rider", False) or self.static:
            return super().describe()
        parts = []
        if self.motion.rate:
            parts.append(f"turning about its normal at {self.motion.rate:g} rad/s")
        if self.motion.path.terms.size:
            parts.append("moving within itself" if self.invariant else "moving along its normal")
        return " and ".join(parts) + (": static in shape" if self.invariant else "")

    def drawing(self, extent):
        return plane_patch(self.point, self.normal, self.size or extent)
