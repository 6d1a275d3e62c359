"""The parts of a scene as frozen dataclasses: ``[[body]]``, ``[[surface]]`` and what they hold.

A part's mesh file or primitive :class:`ShapeConfig`, its ``path``
(:class:`PathConfig` of an :class:`Oscillation`, a :class:`Circle`, a
velocity and a :class:`RotationConfig`), a surface's steady rotation, and the
``[mechanism]`` table (:class:`MechanismConfig`) whose MuJoCo bodies carry
the parts that name a ``mechanism_body``; :class:`BodyConfig` and
:class:`SurfaceConfig` check in ``__post_init__`` that their keys go together
(docs/scene-format.md, "[[body]]", "[[surface]]", "[mechanism]").
"""

import dataclasses
import math
import numbers
import os
from dataclasses import dataclass, field
from pathlib import Path

from ..geometry.meshes import STEP_FORMATS
from ..kernels.laws import LAWS
from .checks import (SceneError, _boolean, _choice, _coefficient, _direction, _exclusive,
                     _instance, _integer, _length, _name, _place, _positive, _real, _set,
                     _set_optional, _show, _vector)

UNITS = ("m", "mm", "cm", "um", "in")
MOTIONS = ("free", "guided", "prescribed", "fixed", "mechanism")
SURFACE_TYPES = ("plane", "mesh", "cylinder", "sphere")
SIDES = ("outside", "inside")
#: keys of each primitive shape besides ``type``, and the required ones
SHAPE_KEYS = {"box": ("size",), "sphere": ("radius", "subdivisions"),
              "cylinder": ("radius", "height", "sections")}
SHAPE_REQUIRED = {"box": ("size",), "sphere": ("radius",), "cylinder": ("radius", "height")}
#: keys of each ``[[surface]]`` type besides ``name`` and ``type``
SURFACE_KEYS = {
    "plane": ("point", "normal", "size", "rotation", "path", "mechanism_body"),
    "mesh": ("mesh", "shape", "units", "resolution", "position", "orientation", "rotation",
             "path", "smooth_normals", "wear", "law", "coefficient", "mechanism_body",
             "mechanism_geom"),
    "cylinder": ("radius", "axis", "point", "length", "side", "rotation", "path",
                 "mechanism_body"),
    "sphere": ("radius", "center", "side", "rotation", "path", "mechanism_body"),
}
#: most facets round a cylinder
MAX_SECTIONS = 100_000
#: two directions closer than this (|a x b|) count as parallel
PARALLEL = 1e-9


def _check_mesh_or_shape(obj):
    """Shared by bodies and mesh surfaces: exactly one of mesh/shape (or, on
    a mechanism body, mechanism_geom), units."""
    if obj.mesh is not None and obj.shape is not None:
        raise SceneError("", "shape", "give either mesh or shape, not both")
    if obj.mechanism_geom is not None:
        if obj.mesh is not None or obj.shape is not None:
            raise SceneError("", "mechanism_geom", "the part's mesh is that geom's; leave "
                             + ("mesh" if obj.mesh is not None else "shape") + " out")
        if not isinstance(obj.mechanism_geom, str) or not obj.mechanism_geom:
            raise SceneError("", "mechanism_geom", "expected the name of a mesh geom of the "
                             f"[mechanism] model, got {_show(obj.mechanism_geom)}")
        if obj.mechanism_body is None:
            raise SceneError("", "mechanism_geom", "takes the mesh of a geom of the "
                             "[mechanism] model: name the body it is on (mechanism_body) too")
        for key, default in (("units", "m"), ("position", (0.0, 0.0, 0.0)),
                             ("orientation", (1.0, 0.0, 0.0, 0.0))):
            value = getattr(obj, key)
            if value != default and not (isinstance(value, (list, tuple))
                                         and tuple(value) == default):
                raise SceneError("", key, f"does not apply to the mesh of geom "
                                 f"{obj.mechanism_geom!r}: the MJCF file places and scales it")
        _set_optional(obj, "resolution", _length)
        _set_optional(obj, "path", _instance, PathConfig)
        return
    if obj.mesh is None and obj.shape is None:
        raise SceneError("", "mesh", 'missing; give mesh = "file.stl" or shape = { type = ... }'
                         + ('' if obj.mechanism_body is None else
                            ' or mechanism_geom = "a mesh geom of the [mechanism] model"'))
    if obj.mesh is not None:
        if not isinstance(obj.mesh, (str, os.PathLike)):
            raise SceneError("", "mesh", f"expected a file name, got {_show(obj.mesh)}")
        object.__setattr__(obj, "mesh", Path(obj.mesh))
        try:
            found, folder = obj.mesh.is_file(), obj.mesh.is_dir()
        except (OSError, ValueError) as err:  # a name too long, a NUL byte
            raise SceneError("", "mesh", f"not a usable file name: {_show(str(obj.mesh))} "
                                         f"({getattr(err, 'strerror', None) or err})") from None
        if not found:
            why = "a folder, not a mesh file" if folder else "file not found"
            raise SceneError("", "mesh", f"{why}: {obj.mesh}")
    else:
        _set(obj, "shape", _instance, ShapeConfig)
    _set(obj, "units", _choice, UNITS)
    if obj.shape is not None and obj.units != "m":
        raise SceneError("", "units", "applies to mesh files only; shape dimensions are in metres")
    if obj.mesh is not None and obj.mesh.suffix.lower() in STEP_FORMATS and obj.units != "m":
        raise SceneError("", "units", "a STEP file carries its own length unit; leave units out")
    _set_optional(obj, "resolution", _length)
    _set(obj, "position", _place)
    _set(obj, "orientation", _direction, 4)
    _set_optional(obj, "path", _instance, PathConfig)


@dataclass(frozen=True, kw_only=True)
class ShapeConfig:
    """A primitive instead of a mesh file, in metres: ``box`` (size = [x, y, z]),
    ``sphere`` (radius, subdivisions 0..7), ``cylinder`` (radius, height, sections >= 3)."""

    type: str
    size: tuple | None = None
    radius: float | None = None
    subdivisions: int = 3
    height: float | None = None
    sections: int = 32

    def __post_init__(self):
        _set(self, "type", _choice, tuple(SHAPE_KEYS))
        for key in SHAPE_REQUIRED[self.type]:
            if getattr(self, key) is None:
                needs = " and ".join(SHAPE_REQUIRED[self.type])
                raise SceneError("", key, f"missing; a {self.type} needs {needs}")
        for key in ("size", "radius", "height"):
            if key not in SHAPE_KEYS[self.type] and getattr(self, key) is not None:
                raise SceneError("", key, f"does not apply to a {self.type}")
        if self.size is not None:
            _set(self, "size", _vector)
            if min(self.size) <= 0.0:
                raise SceneError("", "size", f"all three must be > 0, got {_show(self.size)}")
            for v in self.size:
                _length("size", v)
        _set_optional(self, "radius", _length)
        _set_optional(self, "height", _length)
        _set(self, "subdivisions", _integer, 0, 7)
        _set(self, "sections", _integer, 3, MAX_SECTIONS)


@dataclass(frozen=True, kw_only=True)
class Oscillation:
    """Displacement ``amplitude·sin(2π·frequency·t)`` (m, Hz) along unit ``axis``."""

    axis: tuple
    amplitude: float
    frequency: float

    def __post_init__(self):
        _set(self, "axis", _direction)
        _set(self, "amplitude", _length, True)
        _set(self, "frequency", _positive)


@dataclass(frozen=True, kw_only=True)
class Circle:
    """A circular track of ``radius`` (m) run at ``frequency`` (Hz) about unit ``normal``."""

    radius: float
    frequency: float
    normal: tuple = (0.0, 0.0, 1.0)

    def __post_init__(self):
        _set(self, "radius", _length)
        _set(self, "frequency", _positive)
        _set(self, "normal", _direction)


@dataclass(frozen=True, kw_only=True)
class PathConfig:
    """``path``: displacement added to the initial position; the components given
    add up. ``velocity`` (m/s) is steady sliding; ``free_axis`` (unit) is the
    free direction of a guided body; ``rotation`` a body's steady turn about
    its ``center`` (carried along the path)."""

    oscillation: Oscillation | None = None
    velocity: tuple | None = None
    circle: Circle | None = None
    free_axis: tuple | None = None
    rotation: "RotationConfig | None" = None

    def __post_init__(self):
        _set_optional(self, "oscillation", _instance, Oscillation)
        _set_optional(self, "velocity", _vector)
        _set_optional(self, "circle", _instance, Circle)
        _set_optional(self, "free_axis", _direction)
        _set_optional(self, "rotation", _instance, RotationConfig)

    @property
    def periodic(self):
        """True when the path has a cycle (an oscillation, a circle or a turn)."""
        return (self.oscillation is not None or self.circle is not None
                or (self.rotation is not None and self.rotation.rate != 0.0))


@dataclass(frozen=True, kw_only=True)
class RotationConfig:
    """Steady rotation of a surface or a body's path: unit ``axis``, ``rate``
    (rad/s), ``center`` (m, a body's carried along its path). ``torque``
    (N·m about ``axis``, right-handed), on a guided body's path only: the
    body turns, besides ``rate``, to where its contacts carry that torque
    (quasi-static runs; docs/model.md, "Quasi-static mode")."""

    axis: tuple
    rate: float
    center: tuple = (0.0, 0.0, 0.0)
    torque: float | None = None

    def __post_init__(self):
        _set(self, "axis", _direction)
        _set(self, "rate", _real)
        _set(self, "center", _place)
        _set_optional(self, "torque", _real)
        if self.torque == 0.0:
            raise SceneError("", "torque", "0: a body under no torque has no balance about its "
                             "axis (it floats between its contacts); give a torque or leave "
                             "the key out")


@dataclass(frozen=True, kw_only=True)
class MechanismConfig:
    """``[mechanism]``: the MuJoCo model (an MJCF or URDF file, resolved
    against the scene's folder) whose bodies carry the parts that name a
    ``mechanism_body`` (docs/model.md, "Mechanisms"). MuJoCo integrates its
    joints, actuators, springs and gravity; meshwear adds the contact forces
    of the worn parts. ``keyframe`` names the MJCF keyframe to start from
    (else the model's reference pose at rest); ``controls`` holds actuator
    inputs constant over the run, by actuator name (a force, a target speed:
    what the actuator's MJCF type takes)."""

    model: Path
    keyframe: str | None = None
    controls: dict = field(default_factory=dict)

    def __post_init__(self):
        if not isinstance(self.model, Path):
            raise SceneError("", "model", f'expected the path of an MJCF file, got {_show(self.model)}')
        if not self.model.is_file():
            why = "a folder, not a file" if self.model.is_dir() else "file not found"
            raise SceneError("", "model", f"{self.model}: {why}")
        if self.keyframe is not None and not isinstance(self.keyframe, str):
            raise SceneError("", "keyframe", f"expected a keyframe name, got {_show(self.keyframe)}")
        if not isinstance(self.controls, dict):
            raise SceneError("", "controls", "expected a table of actuator names and inputs, "
                             f"e.g. {{ drive = 10.0 }}, got {_show(self.controls)}")
        for name, value in self.controls.items():
            if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value):
                raise SceneError("", f"controls.{name}", f"expected a finite number, got {_show(value)}")


@dataclass(frozen=True, kw_only=True)
class BodyConfig:
    """``[[body]]``: a worn rigid body.

    Exactly one of ``mesh`` (a file, resolved against the scene's folder, in
    ``units``) and ``shape``. Exactly one of ``density`` (kg/m³, default 7850)
    and ``mass`` (kg). ``orientation`` is a quaternion (w, x, y, z), stored
    normalised. ``guided`` bodies need a path with ``free_axis``;
    ``prescribed`` ones a path without it; ``free`` and ``fixed`` ones no path.
    Velocities and ``force`` do not apply to prescribed and fixed bodies.
    ``mechanism_body`` names the body of the ``[mechanism]`` model the part
    rides on (its motion is then ``"mechanism"``, from MuJoCo, with MuJoCo's
    mass); ``position`` and ``orientation`` then place the mesh in that
    body's frame. ``mechanism_geom`` (instead of mesh and shape) takes the
    mesh of a mesh geom of that body, placed as MuJoCo places it.
    """

    name: str
    mesh: Path | None = None
    shape: ShapeConfig | None = None
    units: str = "m"
    resolution: float | None = None
    #: m: ``resolution`` refines the faces within this distance of a surface
    #: at the start (None: 10 % of the body's size)
    resolution_reach: float | None = None
    density: float | None = None
    mass: float | None = None
    position: tuple = (0.0, 0.0, 0.0)
    orientation: tuple = (1.0, 0.0, 0.0, 0.0)
    velocity: tuple = (0.0, 0.0, 0.0)
    angular_velocity: tuple = (0.0, 0.0, 0.0)
    force: tuple = (0.0, 0.0, 0.0)
    motion: str = "free"
    path: PathConfig | None = None
    mechanism_body: str | None = None
    mechanism_geom: str | None = None

    def __post_init__(self):
        _set(self, "name", _name)
        _check_mesh_or_shape(self)
        _check_rider(self, ("path",))
        if self.mechanism_body is not None:
            if self.motion == "free":       # the default: the mechanism moves it
                object.__setattr__(self, "motion", "mechanism")
            elif self.motion != "mechanism":
                raise SceneError("", "motion", f"{self.motion!r}: a part on mechanism body "
                                 f"{self.mechanism_body!r} moves with it; leave motion out")
            for key in ("velocity", "angular_velocity", "force"):
                if any(getattr(self, key)):
                    raise SceneError("", key, f"does not apply to a part on mechanism body "
                                     f"{self.mechanism_body!r} (MuJoCo moves it)")
        elif self.motion == "mechanism":
            raise SceneError("", "mechanism_body", "missing; motion = 'mechanism' needs the "
                             "name of the [mechanism] body the part rides on")
        _set_optional(self, "resolution_reach", _length)
        if self.resolution_reach is not None and self.resolution is None:
            raise SceneError("", "resolution_reach", "applies with resolution only")
        _exclusive(self, "density", "mass")
        _set_optional(self, "density", _positive)
        _set_optional(self, "mass", _positive)
        if self.density is None and self.mass is None:
            object.__setattr__(self, "density", 7850.0)
        for key in ("velocity", "angular_velocity", "force"):
            _set(self, key, _vector)
        _set(self, "motion", _choice, MOTIONS)
        if self.motion in ("free", "fixed") and self.path is not None:
            raise SceneError("", "path", f"a {self.motion} body has no path; "
                                         "use motion = \"guided\" or \"prescribed\"")
        if self.motion in ("guided", "prescribed") and self.path is None:
            raise SceneError("", "path", f"missing; a {self.motion} body needs a path")
        torque = (self.path is not None and self.path.rotation is not None
                  and self.path.rotation.torque is not None)
        if torque and self.motion != "guided":
            raise SceneError("", "path.rotation.torque", f"applies to guided bodies only; a "
                             f"{self.motion} body's turn is set, not balanced")
        if torque and self.path.free_axis is not None:
            raise SceneError("", "path.rotation.torque", "a body balanced under a torque "
                             "turns about its axis only: leave path.free_axis out (a balance "
                             "along an axis and about one at once is not supported)")
        if self.motion == "guided" and self.path.free_axis is None and not torque:
            raise SceneError("", "path.free_axis", "missing; a guided body needs the axis "
                                                   "along which it moves freely (or "
                                                   "path.rotation.torque)")
        if torque:
            for key in ("velocity", "angular_velocity", "force"):
                if any(getattr(self, key)):
                    raise SceneError("", key, "does not apply to a body turning under "
                                     "path.rotation.torque (its path sets its motion, the "
                                     "torque its turn)")
        if self.motion == "prescribed" and self.path.free_axis is not None:
            raise SceneError("", "path.free_axis", "applies to guided bodies only; a "
                                                   "prescribed body follows its path exactly")
        if self.motion == "guided" and not torque:
            if any(self.angular_velocity):
                raise SceneError("", "angular_velocity", "does not apply to a guided body "
                                                         "(it does not rotate)")
            axis = self.path.free_axis
            scale = max(1.0, *(abs(v) for v in self.velocity))   # no overflow in hypot
            velocity = [v / scale for v in self.velocity]
            along = sum(v * a for v, a in zip(velocity, axis))
            across = [v - along * a for v, a in zip(velocity, axis)]
            if math.hypot(*across) > 1e-12 * max(1.0 / scale, math.hypot(*velocity)):
                raise SceneError("", "velocity", "only its component along path.free_axis "
                                                 "applies to a guided body (the path sets the rest)")
        if self.motion in ("prescribed", "fixed"):
            for key in ("velocity", "angular_velocity", "force"):
                if any(getattr(self, key)):
                    raise SceneError("", key, f"does not apply to a {self.motion} body "
                                              "(its motion is set, not computed)")


@dataclass(frozen=True, kw_only=True)
class SurfaceConfig:
    """``[[surface]]``: a counter-surface (does not wear). Every type takes an
    optional steady ``rotation`` and a ``path`` (without free_axis).

    ``type = "plane"``: ``point``, unit ``normal`` (pointing into the bodies) and
    an optional ``size`` (m, side of the patch drawn in ParaView); it turns
    about its normal only.
    ``type = "cylinder"``: ``radius`` (m), unit ``axis``, ``point`` on the axis,
    optional ``length`` (m, centred on ``point``; infinite without it) and
    ``side`` ("outside": a shaft or ring, "inside": a bore).
    ``type = "sphere"``: ``radius``, ``center`` and ``side`` (a ball, or a cup).
    ``type = "mesh"``: mesh or shape, units, resolution, position, orientation as
    for a body, and ``smooth_normals``. ``wear = true`` makes it wear too, by
    its own ``law`` and ``coefficient`` (None: those of ``[wear]``).
    """

    name: str
    type: str = "plane"
    point: tuple = (0.0, 0.0, 0.0)
    normal: tuple = (0.0, 0.0, 1.0)
    size: float | None = None
    radius: float | None = None
    axis: tuple | None = None
    length: float | None = None
    side: str = "outside"
    center: tuple = (0.0, 0.0, 0.0)
    mesh: Path | None = None
    shape: ShapeConfig | None = None
    units: str = "m"
    resolution: float | None = None
    position: tuple = (0.0, 0.0, 0.0)
    orientation: tuple = (1.0, 0.0, 0.0, 0.0)
    rotation: RotationConfig | None = None
    path: PathConfig | None = None
    #: interpolate vertex normals over the face under a vertex (curved parts)
    smooth_normals: bool = False
    #: a mesh counter-part that wears, by its own law and coefficient (None:
    #: the [wear] ones, filled in by the Scene)
    wear: bool = False
    law: str | None = None
    coefficient: float | str | None = None
    #: the [mechanism] body it rides on (its motion then comes from MuJoCo),
    #: and the mesh geom of that body that is its mesh (instead of mesh/shape)
    mechanism_body: str | None = None
    mechanism_geom: str | None = None

    def __post_init__(self):
        _set(self, "name", _name)
        _set(self, "type", _choice, SURFACE_TYPES)
        _check_rider(self, ("path", "rotation"))
        _set(self, "smooth_normals", _boolean)
        _set_optional(self, "rotation", _instance, RotationConfig)
        _set_optional(self, "path", _instance, PathConfig)
        if self.path is not None and self.path.free_axis is not None:
            raise SceneError("", "path.free_axis", "applies to guided bodies only; "
                                                   "a surface follows its path exactly")
        if self.path is not None and self.path.rotation is not None:
            raise SceneError("", "path.rotation", "a surface turns by its own rotation key, "
                                                  "not its path's")
        if self.rotation is not None and self.rotation.torque is not None:
            raise SceneError("", "rotation.torque", "applies to a guided body's "
                             "path.rotation only; a surface turns at its rate")
        own = set(SURFACE_KEYS[self.type])
        defaults = {f.name: f.default for f in dataclasses.fields(self)}
        for key in {k for keys in SURFACE_KEYS.values() for k in keys} - own:
            if getattr(self, key) != defaults[key]:
                raise SceneError("", key, f'does not apply to a type = "{self.type}" surface')
        if self.type == "mesh":
            _check_mesh_or_shape(self)
            _set(self, "wear", _boolean)
            _set_optional(self, "law", _choice, tuple(LAWS))
            if self.law is not None or not isinstance(self.coefficient, str):
                # with units and no law of its own, the scene checks it against [wear]'s
                _set_optional(self, "coefficient", _coefficient,
                              LAWS[self.law or "archard"].unit)
            for key in ("law", "coefficient"):
                if getattr(self, key) is not None and not self.wear:
                    raise SceneError("", key, "applies to a worn surface only; "
                                              "add wear = true")
            return
        _set(self, "point", _place)
        _set(self, "center", _place)
        turn = None if self.rotation is None or self.rotation.rate == 0.0 else self.rotation.axis
        if self.type == "plane":
            _set(self, "normal", _direction)
            _set_optional(self, "size", _length)
            if turn is not None and _cross_norm(turn, self.normal) > PARALLEL:
                raise SceneError("", "rotation.axis", f"{_show(turn)}: a plane turns about its "
                                 f"normal {_show(self.normal)} only (a turning disc)")
            return
        if self.radius is None:
            raise SceneError("", "radius", f"missing; a {self.type} needs a radius (m)")
        _set(self, "radius", _length)
        _set(self, "side", _choice, SIDES)
        if self.type == "cylinder":
            if self.axis is None:
                raise SceneError("", "axis", "missing; a cylinder needs the direction of its axis")
            _set(self, "axis", _direction)
            _set_optional(self, "length", _length)
            if (turn is not None and self.length is None
                    and _cross_norm(turn, self.axis) > PARALLEL):
                raise SceneError("", "rotation.axis", f"{_show(turn)}: an infinite cylinder "
                                 f"turns only about an axis parallel to its own "
                                 f"{_show(self.axis)}; give it a length to tumble it")


def _check_rider(obj, moves):
    """A part on a mechanism body takes its motion from MuJoCo only."""
    if obj.mechanism_body is None:
        return
    if not isinstance(obj.mechanism_body, str) or not obj.mechanism_body:
        raise SceneError("", "mechanism_body", f"expected a body name of the [mechanism] "
                         f"model, got {_show(obj.mechanism_body)}")
    for key in moves:
        if getattr(obj, key) is not None:
            raise SceneError("", key, f"does not apply to a part on mechanism body "
                             f"{obj.mechanism_body!r}: MuJoCo moves it")


def _cross_norm(a, b):
    """|a x b| of two unit vectors (0 when parallel)."""
    return math.hypot(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                      a[0] * b[1] - a[1] * b[0])
