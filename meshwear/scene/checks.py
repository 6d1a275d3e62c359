"""Value checks for scene dataclasses, and :class:`SceneError`.

Each check takes ``(key, value, ...)`` and returns the normalised value or
raises a :class:`SceneError` whose key is relative to its dataclass; the
parser in :mod:`meshwear.scene` adds the prefix (``body[0].``) and the file.
"""

import difflib
import math
import numbers
import re

_SAFE_NAME = re.compile(r"[A-Za-z0-9_.\-]+")
#: longest part name: its frames are ``<name>/<name>_00000.vtp``, within the
#: 255 bytes a file name may have on common file systems, with room to spare
NAME_LENGTH = 100


class SceneError(ValueError):
    """Bad scene input. ``str(err)`` is one line: ``<file>: <key>: <what is wrong>``.

    Parameters
    ----------
    source : str
        The scene file ("" when unknown, e.g. a dataclass built in a script).
    key : str
        Full key path (``run.dt``, ``body[0].path.free_axis``), or "".
    message : str
        What is wrong, and what is allowed.
    """

    def __init__(self, source: str, key: str, message: str):
        self.source, self.key, self.message = source, key, message
        text = ": ".join(part for part in (source, key, message) if part)
        super().__init__(re.sub(r"\s*\n\s*", " ", text))

    def __reduce__(self):
        return type(self), (self.source, self.key, self.message)


# ------------------------------------------------------------------ value checks
# Each takes (key, value, ...), returns the normalised value or raises a
# SceneError with the key relative to its dataclass; the parser adds the prefix.

def _show(value):
    """Short description of a value for messages."""
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, bool):
        return "true" if value else "false"
    text = repr(list(value) if isinstance(value, tuple) else value)
    return text if len(text) <= 60 else text[:57] + "..."


def _did_you_mean(word, options):
    match = difflib.get_close_matches(str(word), list(options), n=1)
    return f" (did you mean {match[0]!r}?)" if match else ""


def _real(key, value):
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise SceneError("", key, f"expected a number, got {_show(value)}")
    value = float(value)
    if not math.isfinite(value):
        raise SceneError("", key, f"must be a finite number, got {value!r}")
    return value


def _positive(key, value):
    value = _real(key, value)
    if value <= 0.0:
        raise SceneError("", key, f"must be > 0, got {value!r}")
    return value


def _nonnegative(key, value):
    value = _real(key, value)
    if value < 0.0:
        raise SceneError("", key, f"must be >= 0, got {value!r}")
    return value


#: longest length and farthest coordinate a scene may give (m): beyond
#: them, squares and products of lengths leave double precision's range
MAX_LENGTH = 1e6


def _length(key, value, zero=False):
    """A length in metres: > 0 (>= 0 with ``zero``) and at most :data:`MAX_LENGTH`."""
    value = _nonnegative(key, value) if zero else _positive(key, value)
    if value > MAX_LENGTH:
        raise SceneError("", key, f"{value!r} m is longer than {MAX_LENGTH:g} m "
                                  "(check the units: metres)")
    return value


def _place(key, value):
    """A point (m): three numbers, none farther than :data:`MAX_LENGTH` from 0."""
    value = _vector(key, value)
    if max(abs(v) for v in value) > MAX_LENGTH:
        raise SceneError("", key, f"{_show(value)} lies farther than {MAX_LENGTH:g} m from "
                                  "the origin (check the units: metres)")
    return value


def _boolean(key, value):
    if not isinstance(value, bool):
        raise SceneError("", key, f"expected true or false, got {_show(value)}")
    return value


def _integer(key, value, low, high=None):
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise SceneError("", key, f"expected an integer, got {_show(value)}")
    value = int(value)
    if value < low or (high is not None and value > high):
        allowed = f"between {low} and {high}" if high is not None else f">= {low}"
        raise SceneError("", key, f"must be {allowed}, got {value}")
    return value


def _choice(key, value, options):
    if not isinstance(value, str):
        raise SceneError("", key, f"expected a string, got {_show(value)}")
    if value not in options:
        listed = ", ".join(repr(o) for o in options)
        raise SceneError("", key, f"{value!r} is not one of {listed}{_did_you_mean(value, options)}")
    return value


def _vector(key, value, n=3):
    """Tuple of ``n`` finite floats (a list, tuple or numpy array is accepted)."""
    if hasattr(value, "tolist") and not isinstance(value, numbers.Number):
        value = value.tolist()
    if (not isinstance(value, (list, tuple)) or len(value) != n
            or any(isinstance(v, bool) or not isinstance(v, numbers.Real) for v in value)):
        raise SceneError("", key, f"expected a list of {n} numbers, got {_show(value)}")
    value = tuple(float(v) for v in value)
    if not all(math.isfinite(v) for v in value):
        raise SceneError("", key, f"must be finite numbers, got {_show(value)}")
    return value


def _direction(key, value, n=3):
    """Unit vector (or unit quaternion for n = 4) along a non-zero ``value``."""
    value = _vector(key, value, n)
    largest = max(abs(v) for v in value)
    if largest == 0.0:
        raise SceneError("", key, f"must be non-zero, got {_show(value)}")
    norm = math.hypot(*value)
    if not 1e-150 < norm < math.inf:       # 1e308 components, subnormal ones: scaled first
        value = [v / largest for v in value]
        norm = math.hypot(*value)
    return tuple(v / norm for v in value)


def _name(key, value):
    if not isinstance(value, str):
        raise SceneError("", key, f"expected a string, got {_show(value)}")
    if not _SAFE_NAME.fullmatch(value) or value.startswith("."):
        raise SceneError("", key, f"{_show(value)} is not usable as a file name; use letters, "
                                  "digits, '_', '-' and '.' (not first)")
    if len(value) > NAME_LENGTH:
        raise SceneError("", key, f"{_show(value)} is {len(value)} characters long; at most "
                                  f"{NAME_LENGTH}")
    return value


def _instance(key, value, cls):
    if not isinstance(value, cls):
        raise SceneError("", key, f"expected a {cls.__name__}, got {_show(value)}")
    return value


def _set(obj, name, check, *args):
    """Check field ``name`` of a frozen dataclass and store the normalised value."""
    object.__setattr__(obj, name, check(name, getattr(obj, name), *args))


def _set_optional(obj, name, check, *args):
    if getattr(obj, name) is not None:
        _set(obj, name, check, *args)


def _exclusive(obj, a, b):
    if getattr(obj, a) is not None and getattr(obj, b) is not None:
        raise SceneError("", b, f"give either {a} or {b}, not both")


#: units a wear coefficient may be written in, as ``"<number> <unit>"``: the
#: factor to SI and the SI unit (1/Pa = m³/(N·m) = m³/J: Archard's and the
#: volume energy law's; m/J: the depth energy law's)
COEFFICIENT_UNITS = {
    "1/Pa": (1.0, "m³/J"), "m3/J": (1.0, "m³/J"), "m3/(N m)": (1.0, "m³/J"),
    "mm3/J": (1e-9, "m³/J"), "mm3/(N m)": (1e-9, "m³/J"),
    "m/J": (1.0, "m/J"), "mm/J": (1e-3, "m/J"), "um/J": (1e-6, "m/J"),
}
#: the SI unit of each law's coefficient, as COEFFICIENT_UNITS names it
LAW_DIMENSIONS = {"1/Pa": "m³/J", "m³/J": "m³/J", "m/J": "m/J"}


def _unit_text(unit):
    """A unit's spelling normalised: ``mm^3/(N*m)``, ``mm³/(N·m)`` and
    ``mm3/Nm`` are ``mm3/(N m)``; ``µm/J`` is ``um/J``."""
    text = unit.strip().replace("³", "3").replace("^3", "3").replace("µ", "u").replace("μ", "u")
    text = re.sub(r"\s*[*·]\s*", " ", text).replace("(Nm)", "(N m)").replace("/Nm", "/(N m)")
    text = re.sub(r"/N m$", "/(N m)", text)
    return re.sub(r"\s+", " ", text)


def _coefficient(key, value, law_unit):
    """A wear coefficient (>= 0) in SI: a number, or ``"<number> <unit>"``
    with a unit of :data:`COEFFICIENT_UNITS` that fits the law's
    (``law_unit``, the law's :attr:`~meshwear.kernels.laws.WearLaw.unit`)."""
    if not isinstance(value, str):
        return _nonnegative(key, value)
    number, _, unit = value.strip().partition(" ")
    try:
        number = float(number)
    except ValueError:
        raise SceneError("", key, f'expected a number or "<number> <unit>" such as '
                                  f'"2e-6 mm3/(N m)", got {_show(value)}') from None
    spelled = _unit_text(unit)
    if spelled not in COEFFICIENT_UNITS:
        raise SceneError("", key, f"unknown unit {unit.strip()!r}; one of "
                                  f"{', '.join(COEFFICIENT_UNITS)}")
    factor, dimension = COEFFICIENT_UNITS[spelled]
    wanted = LAW_DIMENSIONS[law_unit]
    if dimension != wanted:
        raise SceneError("", key, f"{unit.strip()!r} is a {dimension} unit; this law's "
                                  f"coefficient is in {law_unit}")
    return _nonnegative(key, number * factor)


def winkler_stiffness(key, layer):
    """Normal stiffness per area (N/m³) of an elastic layer on a rigid base,
    ``{youngs_modulus, poissons_ratio = 0.3, thickness}`` (Pa, -, m): its
    constrained modulus over its thickness, E (1 - nu) / ((1 + nu)(1 - 2 nu) h)
    (the Winkler foundation of a thin layer; docs/scene-format.md)."""
    if not isinstance(layer, dict):
        raise SceneError("", key, f"expected a table {{ youngs_modulus, poissons_ratio, "
                                  f"thickness }}, got {_show(layer)}")
    unknown = set(layer) - {"youngs_modulus", "poissons_ratio", "thickness"}
    if unknown:
        raise SceneError("", f"{key}.{sorted(unknown)[0]}", "unknown key (expected "
                         "youngs_modulus, poissons_ratio, thickness)")
    for name in ("youngs_modulus", "thickness"):
        if name not in layer:
            raise SceneError("", f"{key}.{name}", "missing")
    E = _positive(f"{key}.youngs_modulus", layer["youngs_modulus"])
    h = _positive(f"{key}.thickness", layer["thickness"])
    nu = _real(f"{key}.poissons_ratio", layer.get("poissons_ratio", 0.3))
    if not 0.0 <= nu < 0.5:
        raise SceneError("", f"{key}.poissons_ratio", f"must be in [0, 0.5), got {nu!r}")
    value = E * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu) * h)
    if not math.isfinite(value):
        raise SceneError("", key, f"the stiffness E (1 - nu) / ((1 + nu)(1 - 2 nu) h) "
                                  f"overflows ({_show(layer)})")
    return value
