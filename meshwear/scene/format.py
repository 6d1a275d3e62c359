"""Scene files (TOML, format 1) → frozen, validated dataclasses.

The TOML tables map one to one onto the dataclasses below (docs/scene-format.md).
Every value is checked in the dataclass's ``__post_init__``, so
``dataclasses.replace`` makes a checked variant for sweeps; the parser only
checks the key names, resolves mesh paths and builds nested tables. Bad input
raises :class:`SceneError`, one line naming the file, the key and what is wrong::

    scene.toml: contact.stifness: unknown key (did you mean 'stiffness'?)

Keys of bodies and surfaces are written by index: ``body[0].density``,
``surface[1].normal`` (0-based, in file order).
"""

import copy
import dataclasses
import importlib.util
import math
import numbers
import os
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from ..geometry.meshes import STEP_FORMATS
from ..kernels.laws import LAWS
from .checks import (SceneError, _boolean, _choice, _coefficient, _did_you_mean, _direction,
                     _exclusive, _instance, _integer, _length, _name, _nonnegative, _place,
                     _positive, _real, _set, _set_optional, _show, _vector, winkler_stiffness)

FORMAT = 1
MODES = ("dynamic", "quasi-static")
WEAR_DIRECTIONS = ("contact_normal", "vertex_normal")
ACCELERATIONS = ("none", "cycle_jump")
JUMPS = ("implicit", "explicit")
UNITS = ("m", "mm", "cm", "um", "in")
#: how a part's frames are written: a .pvd collection of .vtp files, or one VTKHDF file
SERIES = ("pvd", "vtkhdf")
MOTIONS = ("free", "guided", "prescribed", "fixed", "mechanism")
CONTACT_MODELS = ("winkler", "half-space")
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
#: largest scene file read (bytes)
MAX_SCENE_BYTES = 16 * 2**20
#: files of a run's output folder that no part's outputs may take
RESERVED_NAMES = ("history.csv", "summary.json", "checkpoint.npz")
#: largest frame and history counts: a file per frame, a row per history time
MAX_FRAMES, MAX_HISTORY = 100_000, 10_000_000
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


def _poisson(key, value):
    nu = _real(key, value)
    if not 0.0 <= nu < 0.5:
        raise SceneError("", key, f"must be in [0, 0.5), got {nu!r}")
    return nu


def _pair(key, value, check):
    """One value for both parts, or [worn body, counter-surface]: a pair."""
    if isinstance(value, (list, tuple)):
        if len(value) != 2:
            raise SceneError("", key, f"expected one value or two [body, surface], got "
                             f"{_show(value)}")
        return (check(key, value[0]), check(key, value[1]))
    v = check(key, value)
    return (v, v)


# ------------------------------------------------------------------ dataclasses

@dataclass(frozen=True, kw_only=True)
class RunConfig:
    """``[run]``: mode, duration (s), step dt (s, or "auto": see
    :func:`meshwear.model.auto_time_step`), frames, history rows, gravity (m/s²),
    series ("pvd" or "vtkhdf": the frames' file format).

    ``frames = 0`` writes no VTK frames, 1 only t = 0; ``history >= 2``.
    """

    mode: str = "dynamic"
    duration: float = 1.0
    dt: float | str = "auto"
    frames: int = 51
    history: int = 1001
    gravity: tuple = (0.0, 0.0, -9.81)
    series: str = "pvd"

    def __post_init__(self):
        _set(self, "mode", _choice, MODES)
        _set(self, "duration", _positive)
        if self.dt != "auto":
            if isinstance(self.dt, str):
                raise SceneError("", "dt", f'expected a step in seconds or "auto", got {self.dt!r}')
            _set(self, "dt", _positive)
        if self.dt != "auto" and self.dt > self.duration:
            raise SceneError("", "dt", f"{self.dt!r} s is longer than duration = {self.duration!r} s")
        _set(self, "frames", _integer, 0, MAX_FRAMES)
        _set(self, "history", _integer, 2, MAX_HISTORY)
        _set(self, "gravity", _vector)
        _set(self, "series", _choice, SERIES)
        if self.series == "vtkhdf" and importlib.util.find_spec("h5py") is None:
            raise SceneError("", "series", "'vtkhdf' needs h5py, the optional hdf extra: "
                             "pip install 'meshwear[hdf]'")


@dataclass(frozen=True, kw_only=True)
class ContactConfig:
    """``[contact]``: penalty contact and friction, one law for all pairs.

    Each coefficient is given per point (N/m, N·s/m) or per area (N/m³,
    N·s/m³), never both. After construction the fields hold resolved values:
    ``stiffness = 1e6`` and ``damping = 20.0`` when neither form is given,
    ``static_friction = friction`` when omitted. ``tangential_*`` left at None
    mean "same as the normal coefficient" (see :attr:`tangential`). A sweep
    with ``dataclasses.replace`` that switches form sets the other to None.
    """

    stiffness: float | None = None
    stiffness_per_area: float | None = None
    damping: float | None = None
    damping_per_area: float | None = None
    friction: float = 0.3
    static_friction: float | None = None
    tangential_stiffness: float | None = None
    tangential_stiffness_per_area: float | None = None
    tangential_damping: float | None = None
    tangential_damping_per_area: float | None = None
    #: m: vertices farther than this from every surface are skipped (active
    #: set); None: 1 % of each body's bounding-box diagonal
    margin: float | None = None
    #: ``{youngs_modulus, poissons_ratio, thickness}``: the normal stiffness
    #: per area of an elastic layer (a Winkler foundation), instead of giving it
    layer: dict | None = None
    #: "winkler" (a spring per vertex: the coefficients above) or
    #: "half-space" (elastic bodies, docs/model.md "Elastic half-space")
    model: str = "winkler"
    #: Pa, and -: the half-space model's elastic constants, one value for the
    #: worn bodies and the counter-surfaces alike or [worn body, counter-surface]
    youngs_modulus: float | tuple | None = None
    poissons_ratio: float | tuple | None = None

    def __post_init__(self):
        _set_optional(self, "margin", _length)
        _set(self, "model", _choice, CONTACT_MODELS)
        if self.model == "half-space":
            for other in ("stiffness", "stiffness_per_area", "layer", "tangential_stiffness",
                          "tangential_stiffness_per_area"):
                if getattr(self, other) is not None:
                    raise SceneError("", other, "does not apply to model = 'half-space' (its "
                                     "stiffness follows from youngs_modulus and poissons_ratio)")
            if self.youngs_modulus is None:
                raise SceneError("", "youngs_modulus", "missing; model = 'half-space' needs the "
                                 "Young's modulus of the parts (Pa): one value or [body, surface]")
            object.__setattr__(self, "youngs_modulus", _pair("youngs_modulus", self.youngs_modulus,
                                                             _positive))
            object.__setattr__(self, "poissons_ratio", _pair(
                "poissons_ratio", 0.3 if self.poissons_ratio is None else self.poissons_ratio,
                _poisson))
            # the Winkler foundation stands in where a reasoning needs one
            # (the start's placement, a cycle jump's re-balance): E* over a
            # length, replaced by the one equivalent to each solve
            object.__setattr__(self, "stiffness_per_area", 1.0)
        else:
            for key in ("youngs_modulus", "poissons_ratio"):
                if getattr(self, key) is not None:
                    raise SceneError("", key, "applies to model = 'half-space' only (an elastic "
                                     "layer on a Winkler foundation: layer = { youngs_modulus, "
                                     "poissons_ratio, thickness })")
        if self.layer is not None:
            for other in ("stiffness", "stiffness_per_area"):
                if getattr(self, other) is not None:
                    raise SceneError("", "layer", f"give either layer or {other}, not both")
            object.__setattr__(self, "stiffness_per_area", winkler_stiffness("layer", self.layer))
        for base, check in (("stiffness", _positive), ("damping", _nonnegative),
                            ("tangential_stiffness", _positive), ("tangential_damping", _nonnegative)):
            _exclusive(self, base, base + "_per_area")
            _set_optional(self, base, check)
            _set_optional(self, base + "_per_area", check)
        if self.stiffness is None and self.stiffness_per_area is None:
            object.__setattr__(self, "stiffness", 1e6)
        if self.damping is None and self.damping_per_area is None:
            object.__setattr__(self, "damping", 20.0)
        _set(self, "friction", _nonnegative)
        if self.static_friction is None:
            object.__setattr__(self, "static_friction", self.friction)
        _set(self, "static_friction", _nonnegative)
        if self.static_friction < self.friction:
            raise SceneError("", "static_friction", f"{self.static_friction!r} is below friction = "
                             f"{self.friction!r}; static friction must be >= friction")

    @property
    def tangential(self):
        """Resolved tangential coefficients ``((c_t, c_t_per_area), (d_t, d_t_per_area))``,
        exactly one of each pair not None."""
        def pair(base, normal):
            given = (getattr(self, "tangential_" + base), getattr(self, f"tangential_{base}_per_area"))
            return given if given != (None, None) else normal
        return (pair("stiffness", (self.stiffness, self.stiffness_per_area)),
                pair("damping", (self.damping, self.damping_per_area)))


@dataclass(frozen=True, kw_only=True)
class WearConfig:
    """``[wear]``: law, coefficient (m/J, m³/J or 1/Pa), direction, acceleration.

    ``period`` (s) is the cycle length for ``cycle_jump`` (None: from the
    motion's frequency); ``tolerance`` the relative error allowed on wear depth;
    ``jump`` how a jump extrapolates the wear: ``"implicit"`` (backward Euler,
    the pressure re-balanced against the worn geometry; stable for any jump)
    or ``"explicit"`` (the last cycle's wear times the jump, bounded for
    stability).
    """

    law: str = "energy"
    #: in the law's SI unit, or ``"<number> <unit>"`` (``"2e-6 mm3/(N m)"``)
    coefficient: float | str = 1e-9
    direction: str = "contact_normal"
    acceleration: str = "none"
    period: float | None = None
    tolerance: float = 0.01
    jump: str = "implicit"

    def __post_init__(self):
        _set(self, "law", _choice, tuple(LAWS))
        _set(self, "coefficient", _coefficient, LAWS[self.law].unit)
        _set(self, "direction", _choice, WEAR_DIRECTIONS)
        _set(self, "acceleration", _choice, ACCELERATIONS)
        _set(self, "jump", _choice, JUMPS)
        _set_optional(self, "period", _positive)
        _set(self, "tolerance", _real)
        if not 0.0 < self.tolerance < 1.0:
            raise SceneError("", "tolerance", f"must be between 0 and 1 (exclusive), got {self.tolerance!r}")


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


@dataclass(frozen=True, kw_only=True)
class Scene:
    """A whole scene: ``format`` (must be 1), where it came from, and its tables.

    ``source`` names the file in error messages; ``base_dir`` is the folder
    mesh paths were resolved against.
    """

    format: int
    source: str = "<scene>"
    base_dir: Path = Path(".")
    run: RunConfig = field(default_factory=RunConfig)
    contact: ContactConfig = field(default_factory=ContactConfig)
    wear: WearConfig = field(default_factory=WearConfig)
    bodies: tuple = ()
    surfaces: tuple = ()
    #: the MuJoCo model the parts with a ``mechanism_body`` ride on
    mechanism: MechanismConfig | None = None
    #: (key, value) pairs set over the file's (``--set``), part of its identity
    overrides: tuple = ()
    #: the parsed TOML it was built from (None if built in code): :meth:`set` edits a copy
    data: dict | None = field(default=None, repr=False, compare=False)

    def __post_init__(self):
        def fail(key, message):
            raise SceneError(self.source, key, message)

        try:
            _check_format(self.format)
            _set(self, "run", _instance, RunConfig)
            _set(self, "contact", _instance, ContactConfig)
            _set(self, "wear", _instance, WearConfig)
        except SceneError as err:
            fail(err.key, err.message)
        object.__setattr__(self, "base_dir", Path(self.base_dir))
        object.__setattr__(self, "bodies", tuple(self.bodies))
        object.__setattr__(self, "surfaces", tuple(self.surfaces))
        # a worn surface's coefficient with units and [wear]'s law
        surfaces = list(self.surfaces)
        for j, s in enumerate(surfaces):
            if isinstance(s, SurfaceConfig) and isinstance(s.coefficient, str):
                try:
                    value = _coefficient("coefficient", s.coefficient, LAWS[self.wear.law].unit)
                except SceneError as err:
                    fail(f"surface[{j}].{err.key}", err.message)
                surfaces[j] = dataclasses.replace(s, coefficient=value)
        object.__setattr__(self, "surfaces", tuple(surfaces))
        if not self.bodies:
            fail("body", "no bodies; add at least one [[body]] table")
        items = ([(f"body[{i}]", b, BodyConfig) for i, b in enumerate(self.bodies)]
                 + [(f"surface[{j}]", s, SurfaceConfig) for j, s in enumerate(self.surfaces)])
        # each name owns the output paths <name>.pvd, <name>.vtkhdf and <name>/; no two may
        # clash, nor with history.csv / summary.json, ignoring case (as
        # Windows and macOS file systems do)
        taken = {name: name for name in RESERVED_NAMES}
        names = {}
        for key, item, cls in items:
            if not isinstance(item, cls):
                fail(key, f"expected a {cls.__name__}, got {_show(item)}")
            if item.name in names:
                fail(key + ".name", f"{item.name!r} is already the name of {names[item.name]}")
            names[item.name] = key
            paths = (item.name.casefold(), item.name.casefold() + ".pvd",
                     item.name.casefold() + ".vtkhdf")
            for path in paths:
                if path in taken:
                    fail(key + ".name", f"{item.name!r}: its output files would clash with "
                         f"{taken[path]} (case is ignored); choose another name")
            for path in paths:
                taken[path] = f"those of {key}"
        if self.run.mode == "quasi-static":
            for i, b in enumerate(self.bodies):
                if b.motion == "free":
                    fail(f"body[{i}].motion", "'free' is not allowed with run.mode = "
                         "'quasi-static'; use guided, prescribed or fixed")
        if self.contact.model == "half-space":
            if self.run.mode != "quasi-static":
                fail("contact.model", "'half-space' solves quasi-static contacts; set "
                     "run.mode = 'quasi-static'")
            if len(self.surfaces) != 1:
                fail("contact.model", f"'half-space' takes one counter-surface, the scene has "
                     f"{len(self.surfaces)}")
        riders = [(f"{kind}[{i}]", x) for kind, group in (("body", self.bodies),
                                                          ("surface", self.surfaces))
                  for i, x in enumerate(group) if x.mechanism_body is not None]
        if riders and self.mechanism is None:
            fail(riders[0][0] + ".mechanism_body", "there is no [mechanism] table; add one "
                 'with model = "file.xml" (a MuJoCo model)')
        if self.mechanism is not None:
            if not riders:
                fail("mechanism", "no part rides on it; give a body or surface a "
                     "mechanism_body")
            if self.run.mode == "quasi-static":
                fail("run.mode", "'quasi-static' does not apply to a scene with a "
                     "[mechanism]: MuJoCo integrates it in time; use 'dynamic'")
            if self.wear.acceleration == "cycle_jump" and self.wear.period is None:
                fail("wear.period", "missing; 'cycle_jump' with a [mechanism] needs its "
                     "cycle length (a driven crank's turn: 2 pi / speed)")
        if self.wear.acceleration == "cycle_jump" and self.wear.period is None and not any(
                (x.path is not None and x.path.periodic)
                or (getattr(x, "rotation", None) is not None and x.rotation.rate != 0.0)
                for x in self.bodies + self.surfaces):
            fail("wear.period", "missing; 'cycle_jump' needs a cycle length: set wear.period "
                 "or give a path with an oscillation or a circle")


    def set(self, key, value=None):
        """A copy with keys set by their dotted names, checked like a file's.

        ``scene.set("wear.coefficient", 1e-13)`` or ``scene.set({"wear.coefficient":
        1e-13, "body[0].force": [0, 0, -20]})`` (or a sequence of pairs): the names the errors print and
        ``--set`` takes (:func:`set_key`). Values are TOML-like: numbers,
        strings, booleans, lists (numpy arrays and scalars are converted),
        tables as dicts. The settings join :attr:`overrides`.

        Raises
        ------
        SceneError
            Naming the key, for a bad key or value; for a scene built in code
            (``data`` is None: use :func:`dataclasses.replace`).
        """
        values = ([(key, value)] if isinstance(key, str)
                  else list(key.items()) if isinstance(key, dict) else list(key))
        if self.data is None:
            raise SceneError(self.source, values[0][0] if values else "",
                             "this scene was not read from TOML; use dataclasses.replace")
        values = [(k, _plain(v)) for k, v in values]
        data = copy.deepcopy(self.data)
        for k, v in values:
            set_key(data, k, v, self.source)
        scene = parse_scene(data, self.source, self.base_dir)
        object.__setattr__(scene, "overrides", tuple(self.overrides) + tuple(values))
        return scene


def _plain(value):
    """``value`` with numpy arrays and scalars turned into Python lists and numbers."""
    if hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


def _check_format(value):
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise SceneError("", "format", f"expected the integer {FORMAT}, got {_show(value)}")
    if value != FORMAT:
        raise SceneError("", "format", f"version {value} is not supported; "
                                       f"this meshwear reads format = {FORMAT}")


# ------------------------------------------------------------------ parser

def load_scene(path, overrides=()) -> Scene:
    """Read and validate a scene file.

    Parameters
    ----------
    path : str or os.PathLike
        TOML file; mesh paths in it are relative to its folder.
    overrides : sequence of (key, value)
        Keys to set before validation, by their dotted names (the names the
        errors print: ``wear.coefficient``, ``body[0].force``,
        ``surface[1].path.oscillation.amplitude``); values as parsed TOML
        values (:func:`parse_override` turns ``KEY=VALUE`` text into one).

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        Missing or unreadable file, TOML syntax error (key = its line and
        column), or any invalid key or value.
    """
    path = Path(path)
    source = str(path)
    try:
        with open(path, "rb") as file:
            raw = file.read(MAX_SCENE_BYTES + 1)
        if len(raw) > MAX_SCENE_BYTES:
            raise SceneError(source, "", f"larger than {MAX_SCENE_BYTES // 2**20} MiB; a scene "
                                         "file names its meshes, it does not hold them")
        text = raw.decode("utf-8-sig")
    except FileNotFoundError:
        raise SceneError(source, "", "file not found") from None
    except IsADirectoryError:
        raise SceneError(source, "", "is a folder, not a scene file") from None
    except OSError as err:
        raise SceneError(source, "", f"cannot read: {err.strerror or err}") from None
    except UnicodeDecodeError:
        raise SceneError(source, "", "not a UTF-8 text file") from None
    try:
        data = tomllib.loads(text)
    except RecursionError:
        raise SceneError(source, "", "TOML syntax error: tables or lists nested too "
                                     "deeply") from None
    except tomllib.TOMLDecodeError as err:
        message = str(err)
        where = re.search(r"\s*\(at (line \d+, column \d+|end of document)\)$", message)
        location = where.group(1) if where else ""
        message = message[:where.start()] if where else message
        raise SceneError(source, location, f"TOML syntax error: {message}") from None
    for key, value in overrides:
        set_key(data, key, value, source)
    scene = parse_scene(data, source, path.resolve().parent)
    object.__setattr__(scene, "overrides", tuple(overrides))
    return scene


_PART = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)(?:\[(\d+)\])?$")


def parse_override(text):
    """``KEY=VALUE`` (the command line's ``--set``) as ``(key, value)``: the
    value is read as a TOML value (``1e-13``, ``[0, 0, -10]``, ``true``,
    ``"archard"``, ``{ axis = [0, 0, 1], rate = 10 }``), or else taken as a
    bare string (``quasi-static``).

    Raises
    ------
    SceneError
        For text without ``=`` or an empty key.
    """
    key, sep, value = text.partition("=")
    key = key.strip()
    if not sep or not key:
        raise SceneError("--set", text, "expected KEY=VALUE, e.g. wear.coefficient=1e-13")
    try:
        parsed = tomllib.loads(f"v = {value.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        parsed = value.strip()
    return key, parsed


def set_key(data, key, value, source="<scene>"):
    """Set ``key`` (dotted, with ``[i]`` for the i-th body or surface) in the
    parsed TOML ``data`` to ``value``, creating the tables on the way.

    Raises
    ------
    SceneError
        Naming the key: an index past the bodies or surfaces there are, or a
        part of the path that is not a table.
    """
    node = data
    parts = key.split(".")
    for n, part in enumerate(parts):
        match = _PART.match(part)
        if not match:
            raise SceneError(source, key, f"--set: {part!r} is not a key name or name[index]")
        name, index = match.group(1), match.group(2)
        last = n == len(parts) - 1
        where = ".".join(parts[:n + 1])
        if not isinstance(node, dict):
            raise SceneError(source, key, f"--set: {'.'.join(parts[:n])} is not a table")
        if index is not None:
            items = node.get(name)
            if not isinstance(items, list) or int(index) >= len(items):
                count = len(items) if isinstance(items, list) else 0
                raise SceneError(source, key, f"--set: there is no {name}[{index}]; the scene "
                                              f"has {count} [[{name}]] table(s)")
            if last:
                items[int(index)] = value
                return
            node = items[int(index)]
        elif last:
            node[name] = value
        else:
            if name not in node:
                node[name] = {}
            node = node[name]
            if not isinstance(node, dict):
                raise SceneError(source, key, f"--set: {where} is not a table")


def parse_scene(data: dict, source: str = "<scene>", base_dir: Path = Path(".")) -> Scene:
    """Validate parsed TOML (a dict of tables) and build the :class:`Scene`.

    Parameters
    ----------
    data : dict
        As returned by ``tomllib``.
    source : str
        Name of the scene in error messages.
    base_dir : path
        Folder that relative mesh paths are resolved against.

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
    """
    base_dir = Path(base_dir)
    if not isinstance(data, dict):
        raise SceneError(source, "", f"expected a table of keys, got {_show(data)}")
    if "format" not in data:
        raise SceneError(source, "format", f"missing; a scene file starts with format = {FORMAT}")
    try:
        _check_format(data["format"])
    except SceneError as err:
        raise SceneError(source, err.key, err.message) from None
    _check_keys(source, data, "",
                ("format", "run", "contact", "wear", "body", "surface", "mechanism"))
    tables = {name: _simple(cls, data.get(name, {}), name, source)
              for name, cls in (("run", RunConfig), ("contact", ContactConfig), ("wear", WearConfig))}
    bodies = _array(source, data.get("body", []), "body")
    if not bodies:
        raise SceneError(source, "body", "no bodies; add at least one [[body]] table")
    bodies = [_body(source, base_dir, raw, f"body[{i}]") for i, raw in enumerate(bodies)]
    surfaces = [_surface(source, base_dir, raw, f"surface[{j}]")
                for j, raw in enumerate(_array(source, data.get("surface", []), "surface"))]
    mechanism = None
    if "mechanism" in data:
        table = _table(source, data["mechanism"], "mechanism", MechanismConfig)
        if isinstance(table.get("model"), str):
            table["model"] = base_dir / table["model"]
        mechanism = _build(MechanismConfig, source, "mechanism", table)
    return Scene(format=data["format"], source=source, base_dir=base_dir, bodies=tuple(bodies),
                 surfaces=tuple(surfaces), mechanism=mechanism, data=copy.deepcopy(data),
                 **tables)


def _array(source, value, key):
    """An array of tables; a single table ``[body]`` counts as one."""
    if isinstance(value, dict):
        return [value]
    if not isinstance(value, list):
        raise SceneError(source, key, f"expected [[{key}]] tables, got {_show(value)}")
    return value


def _check_keys(source, table, prefix, allowed, foreign=(), kind=""):
    """Every key of ``table`` must be in ``allowed``; keys in ``foreign`` belong
    to another ``type`` and get a message saying so."""
    for key in table:
        if key in allowed:
            continue
        full = f"{prefix}.{key}" if prefix else key
        if key in foreign:
            raise SceneError(source, full, f"does not apply to {kind}")
        hint = _did_you_mean(key, allowed) or f"; valid keys: {', '.join(allowed)}"
        raise SceneError(source, full, "unknown key" + hint)


def _table(source, value, prefix, cls, allowed=None, foreign=(), kind=""):
    """Check that ``value`` is a table with known keys and the required ones."""
    if not isinstance(value, dict):
        raise SceneError(source, prefix, f"expected a table, got {_show(value)}")
    names = [f.name for f in dataclasses.fields(cls)]
    _check_keys(source, value, prefix, allowed or names, foreign, kind)
    for f in dataclasses.fields(cls):
        if (f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
                and f.name not in value):
            raise SceneError(source, f"{prefix}.{f.name}", "missing (required)")
    return dict(value)


def _build(cls, source, prefix, kwargs):
    """``cls(**kwargs)``, with the error's key prefixed and the file named."""
    try:
        return cls(**kwargs)
    except SceneError as err:
        if err.source:  # raised by a nested table, already complete
            raise
        raise SceneError(source, f"{prefix}.{err.key}", err.message) from None


def _simple(cls, value, prefix, source):
    return _build(cls, source, prefix, _table(source, value, prefix, cls))


def _typed(source, value, prefix, options, default=None):
    """The ``type`` of a table, checked before its other keys."""
    if not isinstance(value, dict):
        raise SceneError(source, prefix, f"expected a table, got {_show(value)}")
    if "type" not in value and default is None:
        raise SceneError(source, f"{prefix}.type", "missing; one of "
                         + ", ".join(repr(o) for o in options))
    try:
        return _choice("type", value.get("type", default), options)
    except SceneError as err:
        raise SceneError(source, f"{prefix}.type", err.message) from None


def _shape(source, value, prefix):
    kind = _typed(source, value, prefix, tuple(SHAPE_KEYS))
    others = {k for keys in SHAPE_KEYS.values() for k in keys} - set(SHAPE_KEYS[kind])
    table = _table(source, value, prefix, ShapeConfig, ("type",) + SHAPE_KEYS[kind], others,
                   f"a {kind} (its keys: {', '.join(SHAPE_KEYS[kind])})")
    return _build(ShapeConfig, source, prefix, table)


def _path(source, value, prefix):
    table = _table(source, value, prefix, PathConfig)
    for key, cls in (("oscillation", Oscillation), ("circle", Circle),
                     ("rotation", RotationConfig)):
        if key in table:
            table[key] = _simple(cls, table[key], f"{prefix}.{key}", source)
    return _build(PathConfig, source, prefix, table)


def _geometry(source, base_dir, table, prefix):
    """Resolve the mesh path and build the shape and path of a body or surface."""
    if isinstance(table.get("mesh"), str):
        table["mesh"] = base_dir / table["mesh"]
    if "shape" in table:
        table["shape"] = _shape(source, table["shape"], f"{prefix}.shape")
    if "path" in table:
        table["path"] = _path(source, table["path"], f"{prefix}.path")
    return table


def _body(source, base_dir, value, prefix):
    table = _geometry(source, base_dir, _table(source, value, prefix, BodyConfig), prefix)
    if isinstance(value, dict) and "mechanism_body" in value:
        for key in ("motion", "density", "mass"):
            if key in value:
                why = ("MuJoCo moves it" if key == "motion"
                       else "its mass is the MuJoCo body's")
                raise SceneError(source, f"{prefix}.{key}", "does not apply to a part on "
                                 f"mechanism body {value['mechanism_body']!r}: {why}")
    return _build(BodyConfig, source, prefix, table)


def _surface(source, base_dir, value, prefix):
    kind = _typed(source, value, prefix, SURFACE_TYPES, default="plane")
    own = SURFACE_KEYS[kind]
    other = {k for keys in SURFACE_KEYS.values() for k in keys} - set(own)
    table = _table(source, value, prefix, SurfaceConfig, ("name", "type") + own, other,
                   f'a type = "{kind}" surface (its keys: {", ".join(own)})')
    table = _geometry(source, base_dir, table, prefix)
    if "rotation" in table:
        table["rotation"] = _simple(RotationConfig, table["rotation"], f"{prefix}.rotation", source)
    return _build(SurfaceConfig, source, prefix, table)
