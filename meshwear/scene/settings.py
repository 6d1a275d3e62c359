"""The scene-wide tables ``[run]``, ``[contact]`` and ``[wear]`` as frozen dataclasses.

:class:`RunConfig` (mode, duration, step, frames, history, gravity, series),
:class:`ContactConfig` (penalty contact and friction, one law for all pairs,
or the elastic half-space) and :class:`WearConfig` (law, coefficient,
direction, cycle jumps), each checking its values in ``__post_init__``
(docs/scene-format.md, "[run]", "[contact]", "[wear]"; docs/model.md,
"Stiffness and damping per point or per area"), with the choices they take.
"""

import importlib.util
from dataclasses import dataclass

from ..kernels.laws import LAWS
from .checks import (SceneError, _choice, _coefficient, _exclusive, _integer, _length,
                     _nonnegative, _positive, _real, _set, _set_optional, _show, _vector,
                     winkler_stiffness)

MODES = ("dynamic", "quasi-static")
WEAR_DIRECTIONS = ("contact_normal", "vertex_normal")
ACCELERATIONS = ("none", "cycle_jump")
JUMPS = ("implicit", "explicit")
#: how a part's frames are written: a .pvd collection of .vtp files, or one VTKHDF file
SERIES = ("pvd", "vtkhdf")
CONTACT_MODELS = ("winkler", "half-space")
#: largest frame and history counts: a file per frame, a row per history time
MAX_FRAMES, MAX_HISTORY = 100_000, 10_000_000


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
