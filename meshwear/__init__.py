"""meshwear: wear of rigid triangle-mesh bodies, exported as VTK time series.

The Python interface (docs/api.md)::

    import meshwear

    scene = meshwear.load("examples/pin_on_disc.toml", {"wear.coefficient": 1e-13})
    result = meshwear.run(scene)
    result.parts["pin"].wear_depth.max()
"""

__version__ = "0.1.0"

#: names of the public interface, imported on first use (numba loads then)
_API = {"load": "api", "run": "api", "Result": "api", "Part": "api", "Scene": "scene",
        "SceneError": "scene", "NumericalError": "simulate"}

__all__ = ["__version__", *_API]


def __getattr__(name):
    if name in _API:
        from importlib import import_module

        return getattr(import_module(f".{_API[name]}", __name__), name)
    raise AttributeError(f"module 'meshwear' has no attribute {name!r}")
