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
    """Where numba caches the compiled kernels: a folder named by a digest
    of the kernels' source, so that a change to any kernel compiles every
    kernel anew (numba keys a cached function by its own file only: a loop
    that calls a changed kernel of another file would run the old one).
    In ``kernels/__pycache__`` beside their source if it can be written,
    else in ``meshwear-numba-<uid>`` in the user's cache or the temporary
    folder (a system-wide or container install, a user without a writable
    HOME); folders of other digests there are removed. None when
    ``$NUMBA_CACHE_DIR`` is set (the user's choice stands)."""
    if _os.environ.get("NUMBA_CACHE_DIR"):
        return None
    import hashlib
    import tempfile

    here = _os.path.dirname(_os.path.abspath(__file__))
    kernels = _os.path.join(here, "kernels")
    digest = hashlib.sha1()
    for name in sorted(_os.listdir(kernels)):
        if name.endswith(".py"):
            with open(_os.path.join(kernels, name), "rb") as f:
                digest.update(name.encode() + b"\0" + f.read())
    user = _os.environ.get("XDG_CACHE_HOME") or _os.path.join(_os.path.expanduser("~"), ".cache")
    uid = getattr(_os, "getuid", lambda: 0)()
    for base in (_os.path.join(kernels, "__pycache__"),
                 _os.path.join(user, f"meshwear-numba-{uid}"),
                 _os.path.join(tempfile.gettempdir(), f"meshwear-numba-{uid}")):
        folder = _os.path.join(base, f"numba-{digest.hexdigest()[:16]}")
        if _writable(folder):
            _forget_others(base, folder)
            return folder
    return None


def _forget_others(base, keep):
    """Remove the cache folders of other kernel sources under ``base`` (best effort)."""
    import shutil

    try:
        names = _os.listdir(base)
    except OSError:
        return
    for name in names:
        path = _os.path.join(base, name)
        if name.startswith("numba-") and path != keep:
            shutil.rmtree(path, ignore_errors=True)


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
