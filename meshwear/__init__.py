"""meshwear: wear of rigid triangle-mesh bodies, exported as VTK time series.

The Python interface (docs/api.md)::

    import meshwear

    scene = meshwear.load("examples/pin_on_disc.toml", {"wear.coefficient": 1e-13})
    result = meshwear.run(scene)
    result.parts["pin"].wear_depth.max()
"""

import os as _os

__version__ = "0.1.0"


from .kernels import cachedir as _cachedir  # no numba import there

_cache = _cachedir.choose()
if _cache is not None:
    _os.environ["NUMBA_CACHE_DIR"] = _cache
    import sys as _sys

    if "numba" in _sys.modules:              # numba read its settings already
        _sys.modules["numba"].config.CACHE_DIR = _cache

from ._moved import install as _install_moved  # noqa: E402  old module paths, deprecated

_install_moved()

#: names of the public interface, imported on first use (numba loads then)
_API = {"load": "api", "run": "api", "Result": "api", "Part": "api", "Scene": "scene",
        "SceneError": "scene", "NumericalError": "step.simulate"}

__all__ = ["__version__", *_API]


def __getattr__(name):
    if name in _API:
        from importlib import import_module

        return getattr(import_module(f".{_API[name]}", __name__), name)
    raise AttributeError(f"module 'meshwear' has no attribute {name!r}")
