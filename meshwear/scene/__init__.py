"""Scene files (TOML, format 1) in, frozen and validated dataclasses out (docs/scene-format.md).

- :mod:`.checks`: value checks and :class:`SceneError`;
- :mod:`.settings`: the scene-wide tables ``[run]``, ``[contact]``, ``[wear]``;
- :mod:`.parts`: ``[[body]]`` and ``[[surface]]`` (mesh or shape, path,
  rotation) and the ``[mechanism]`` they ride on;
- :mod:`.reader`: the whole :class:`Scene`, :func:`load_scene`,
  :func:`parse_scene` and the ``--set`` overrides (:func:`set_key`).

Imports only :mod:`meshwear.geometry` and :mod:`meshwear.kernels`.
"""

from .checks import (NAME_LENGTH, SceneError, MAX_LENGTH, COEFFICIENT_UNITS, LAW_DIMENSIONS,
                     winkler_stiffness)
from .settings import (MODES, WEAR_DIRECTIONS, ACCELERATIONS, JUMPS, SERIES, CONTACT_MODELS,
                       RunConfig, ContactConfig, WearConfig)
from .parts import (UNITS, MOTIONS, SURFACE_TYPES, SIDES, SHAPE_KEYS, SHAPE_REQUIRED, SURFACE_KEYS,
                    MAX_SECTIONS, PARALLEL, ShapeConfig, Oscillation, Circle, PathConfig,
                    RotationConfig, MechanismConfig, BodyConfig, SurfaceConfig)
from .reader import (FORMAT, MAX_SCENE_BYTES, RESERVED_NAMES, Scene, load_scene, parse_override,
                     set_key, parse_scene)

__all__ = ["NAME_LENGTH", "SceneError", "MAX_LENGTH", "COEFFICIENT_UNITS", "LAW_DIMENSIONS",
           "winkler_stiffness", "FORMAT", "MODES", "WEAR_DIRECTIONS", "ACCELERATIONS", "JUMPS",
           "UNITS", "SERIES", "MOTIONS", "CONTACT_MODELS", "SURFACE_TYPES", "SIDES", "SHAPE_KEYS",
           "SHAPE_REQUIRED", "SURFACE_KEYS", "MAX_SCENE_BYTES", "RESERVED_NAMES", "MAX_SECTIONS",
           "PARALLEL", "RunConfig", "ContactConfig", "WearConfig", "ShapeConfig", "Oscillation",
           "Circle", "PathConfig", "RotationConfig", "MechanismConfig", "BodyConfig",
           "SurfaceConfig", "Scene", "load_scene", "parse_override", "set_key", "parse_scene"]
