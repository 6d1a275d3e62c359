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
    norm = math.hypot(*value)
    if norm == 0.0:
        raise SceneError("", key, f"must be non-zero, got {_show(value)}")
    return tuple(v / norm for v in value)


def _name(key, value):
    if not isinstance(value, str):
        raise SceneError("", key, f"expected a string, got {_show(value)}")
    if not _SAFE_NAME.fullmatch(value) or set(value) == {"."}:
        raise SceneError("", key, f"{value!r} is not usable as a file name; use letters, "
                                  "digits, '_', '-' and '.'")
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
