"""Scene files (TOML, format 1) in, frozen and validated dataclasses out (docs/scene-format.md).

- :mod:`.format`: the tables and keys of a scene, and :func:`load_scene`;
- :mod:`.checks`: value checks and :class:`SceneError`.

Imports only :mod:`meshwear.geometry` and :mod:`meshwear.kernels`.
"""

from .checks import (NAME_LENGTH, SceneError, MAX_LENGTH, COEFFICIENT_UNITS, LAW_DIMENSIONS,
                     winkler_stiffness)
from .format import (FORMAT, MODES, WEAR_DIRECTIONS, ACCELERATIONS, JUMPS, UNITS, SERIES, MOTIONS,
                     CONTACT_MODELS, SURFACE_TYPES, SIDES, SHAPE_KEYS, SHAPE_REQUIRED, SURFACE_KEYS,
                     MAX_SCENE_BYTES, RESERVED_NAMES, MAX_SECTIONS, PARALLEL, RunConfig,
                     ContactConfig, WearConfig, ShapeConfig, Oscillation, Circle, PathConfig,
                     RotationConfig, MechanismConfig, BodyConfig, SurfaceConfig, Scene, load_scene,
                     parse_override, set_key, parse_scene)

__all__ = ["NAME_LENGTH", "SceneError", "MAX_LENGTH", "COEFFICIENT_UNITS", "LAW_DIMENSIONS",
           "winkler_stiffness", "FORMAT", "MODES", "WEAR_DIRECTIONS", "ACCELERATIONS", "JUMPS",
           "UNITS", "SERIES", "MOTIONS", "CONTACT_MODELS", "SURFACE_TYPES", "SIDES", "SHAPE_KEYS",
           "SHAPE_REQUIRED", "SURFACE_KEYS", "MAX_SCENE_BYTES", "RESERVED_NAMES", "MAX_SECTIONS",
           "PARALLEL", "RunConfig", "ContactConfig", "WearConfig", "ShapeConfig", "Oscillation",
           "Circle", "PathConfig", "RotationConfig", "MechanismConfig", "BodyConfig",
           "SurfaceConfig", "Scene", "load_scene", "parse_override", "set_key", "parse_scene"]
