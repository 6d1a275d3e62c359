"""Counter-surfaces: analytic planes, cylinders and spheres, and meshes; the active set.

Every kind implements :class:`CounterSurface` (:mod:`meshwear.surfaces.base`
states the contract) and is named in :data:`TYPES`, the scene's
``[[surface]] type``. docs/model.md ("Counter-surfaces") describes the model.
"""

from .active import (CULL_MARGIN, CULL_POSE, CULL_SIZE, CULL_TIME, MARGIN_FRACTION, STEPS_IN_MARGIN,
                     Cull, SurfaceSet, body_margin, contact_areas, contact_faces, initial_planes,
                     margin_of, moved_since_refresh, needs_refresh, query, refresh, slot_normals,
                     step_motion, update, vertex_feet)
from .analytic import Cylinder, Sphere
from .base import CounterSurface, SurfaceMotion, quaternion_matrix
from .mesh import MeshSurface
from .plane import Plane

#: ``[[surface]] type`` -> the class that builds it from its config (``from_config``)
TYPES = {"plane": Plane, "cylinder": Cylinder, "sphere": Sphere, "mesh": MeshSurface}


def build_surface(config, mechanism=None, loaded=None):
    """The counter-surface of a validated ``[[surface]]`` table (a mesh one
    may take its mesh from a geom of the ``mechanism``; ``loaded``: the mesh
    files read so far, :func:`meshwear.geometry.load_part`).

    Raises
    ------
    meshwear.geometry.MeshError
        For a mesh the engine cannot use; the caller adds the key.
    """
    if config.type == "mesh":
        return MeshSurface.from_config(config, mechanism, loaded)
    return TYPES[config.type].from_config(config)


__all__ = ["TYPES", "build_surface", "CounterSurface", "SurfaceMotion", "Plane", "Cylinder",
           "Sphere", "MeshSurface", "SurfaceSet", "Cull", "body_margin", "contact_areas",
           "contact_faces", "initial_planes", "margin_of", "moved_since_refresh",
           "needs_refresh", "query", "refresh", "slot_normals", "step_motion", "update",
           "vertex_feet",
           "quaternion_matrix", "CULL_MARGIN", "CULL_POSE", "CULL_SIZE", "CULL_TIME",
           "MARGIN_FRACTION", "STEPS_IN_MARGIN"]
