"""meshwear: wear of rigid triangle-mesh bodies, exported as VTK time series.

The Python interface (docs/api.md)::

    import meshwear

    scene = meshwear.load("examples/pin_on_disc.toml", {"wear.coefficient": 1e-13})
    result = meshwear.run(scene)
    result.parts["pin"].wear_depth.max()
"""

import os as _os

__version__ = "0.1.0"


def _numba_cache_dir():
    """Where numba caches the compiled kernels. By default next to their
    source (``__pycache__``), else in the user's cache folder; where neither
    can be written (a system-wide or container install, a user without a
    writable HOME) numba refuses to import them, so this picks a writable
    folder first: ``$NUMBA_CACHE_DIR`` if set, else the package folder if
    writable, else ``meshwear-numba`` in the user's cache or the temporary
    folder. None when the package folder will do."""
    if _os.environ.get("NUMBA_CACHE_DIR"):
        return None
    here = _os.path.dirname(_os.path.abspath(__file__))
    if _writable(_os.path.join(here, "kernels", "__pycache__")):
        return None
    import tempfile

    user = _os.environ.get("XDG_CACHE_HOME") or _os.path.join(_os.path.expanduser("~"), ".cache")
    for base in (user, tempfile.gettempdir()):
        folder = _os.path.join(base, f"meshwear-numba-{getattr(_os, 'getuid', lambda: 0)()}")
        if _writable(folder):
            return folder
    return None


def _writable(folder):
    """Whether a file can be made in ``folder`` (made if missing): tried, as
    permissions say nothing of a read-only mount."""
    import tempfile

    try:
        _os.makedirs(folder, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            return True
    except OSError:
        return False


_cache = _numba_cache_dir()
if _cache is not None:
    _os.environ["NUMBA_CACHE_DIR"] = _cache
    import sys as _sys

    if "numba" in _sys.modules:              # numba read its settings already
        _sys.modules["numba"].config.CACHE_DIR = _cache

#: names of the public interface, imported on first use (numba loads then)
_API = {"load": "api", "run": "api", "Result": "api", "Part": "api", "Scene": "scene",
        "SceneError": "scene", "NumericalError": "simulate"}

__all__ = ["__version__", *_API]


def __getattr__(name):
    if name in _API:
        from importlib import import_module

        return getattr(import_module(f".{_API[name]}", __name__), name)
    raise AttributeError(f"module 'meshwear' has no attribute {name!r}")
