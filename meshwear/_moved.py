"""Old import paths of the modules that moved into the stage packages
(docs/index.md, "Code map"): ``import meshwear.simulate`` still gives the
module, now :mod:`meshwear.step.simulate`, with a :class:`DeprecationWarning`.
The old paths go in the release after 0.1.

A finder on :data:`sys.meta_path` hands the new module itself to the import
system under the old name, so code that patches the old path patches the
module that runs.
"""

import importlib
import importlib.abc
import importlib.util
import sys
import warnings

#: old module -> the module it is now
MOVED = {
    "meshwear.remesh": "meshwear.geometry.remesh",
    "meshwear.scene_checks": "meshwear.scene.checks",
    "meshwear.dynamics": "meshwear.motion.dynamics",
    "meshwear.packing": "meshwear.motion.packing",
    "meshwear.elastic": "meshwear.contact.elastic",
    "meshwear.halfspace": "meshwear.contact.halfspace",
    "meshwear.cellfields": "meshwear.contact.cellfields",
    "meshwear.stability": "meshwear.contact.stability",
    "meshwear.reach": "meshwear.model.reach",
    "meshwear.simulate": "meshwear.step.simulate",
    "meshwear.stepper": "meshwear.step.stepper",
    "meshwear.estimate": "meshwear.step.estimate",
    "meshwear.wear": "meshwear.longrun.wear",
    "meshwear.jumps": "meshwear.longrun.jumps",
    "meshwear.jump_geometry": "meshwear.longrun.jump_geometry",
    "meshwear.checkpoint": "meshwear.longrun.checkpoint",
}


class _Loader(importlib.abc.Loader):
    def __init__(self, new):
        self.new = new
        self.spec = None

    def create_module(self, spec):
        warnings.warn(f"{spec.name} is now {self.new}; the old path goes in the next release",
                      DeprecationWarning, stacklevel=2)
        module = importlib.import_module(self.new)
        self.spec = module.__spec__
        return module

    def exec_module(self, module):
        # the import system stamped the old name's spec on it: give its own back
        module.__spec__ = self.spec


class _Finder(importlib.abc.MetaPathFinder):
    def find_spec(self, fullname, path=None, target=None):
        new = MOVED.get(fullname)
        if new is None:
            return None
        return importlib.util.spec_from_loader(fullname, _Loader(new))


def install():
    """Put the finder on :data:`sys.meta_path` (once)."""
    if not any(isinstance(f, _Finder) for f in sys.meta_path):
        sys.meta_path.insert(0, _Finder())
