"""Geometry: meshes in, plain arrays out (docs/index.md, "Code map").

- :mod:`.meshes`: loading, units, cleaning, primitives, face normals;
- :mod:`.properties`: vertex areas and normals, inverted faces, mass properties;
- :mod:`.remesh`: conforming refinement, and the spacing of two parts where they touch.

Imports only :mod:`meshwear.kernels`. The names below are the old
``meshwear.geometry`` module's, kept here.
"""

from .meshes import (TRIMESH_FORMATS, STEP_FORMATS, STEP_LINEAR_TOLERANCE, STEP_ANGULAR_TOLERANCE,
                     CAD_EXTRA, UNITS, MERGE_TOLERANCE, DEGENERATE_RATIO, MeshError, load_mesh,
                     load_part, MIN_EXTENT, MAX_COORDINATE, check_scale, clean, spatial_order,
                     primitive, SIDE, snap_to_primitive, facet_sag, face_normals, plane_patch)
from .properties import (tributary_areas, area_vectors, vertex_normals, inverted_faces,
                         mass_properties, mesh_info)

__all__ = ["TRIMESH_FORMATS", "STEP_FORMATS", "STEP_LINEAR_TOLERANCE", "STEP_ANGULAR_TOLERANCE",
           "CAD_EXTRA", "UNITS", "MERGE_TOLERANCE", "DEGENERATE_RATIO", "MeshError", "load_mesh",
           "load_part", "MIN_EXTENT", "MAX_COORDINATE", "check_scale", "clean", "spatial_order",
           "primitive", "SIDE", "snap_to_primitive", "facet_sag", "face_normals", "plane_patch",
           "tributary_areas", "area_vectors", "vertex_normals", "inverted_faces", "mass_properties",
           "mesh_info"]
