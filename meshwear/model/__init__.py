"""Model (frozen: what a scene is) and State (what changes while it runs): the compile
of a scene into the plain arrays the step takes.

- :mod:`.state`: :class:`Model`, :class:`State` and their bodies' and parts' records;
- :mod:`.build`: :func:`build_model`, :func:`initial_state`, :func:`check_time_step`;
- :mod:`.timestep`: the stable step, the step ``run.dt = "auto"`` stands for, whole steps;
- :mod:`.reach`: which faces a part's ``resolution`` refines.

Imports the stages below it (scene, geometry, motion, surfaces, contact,
mechanism, kernels); never the step, the long run or the outputs. What runs
at every step is not here: a body's Winkler contact is
:func:`meshwear.contact.winkler.body_contact`, the worn counter-surfaces'
wear :mod:`meshwear.step.counters`; their old paths here
(``meshwear.model.wear_counters``) work with a :class:`DeprecationWarning`
until the release after 0.1.
"""

import importlib
import warnings

from .state import OWN_MOTIONS, BodyModel, Model, BodyState, PartState, State
from .timestep import (AUTO_STEPS_PER_CYCLE, AUTO_STEPS_PER_RUN, auto_time_step,
                       auto_time_step_why, MAX_STEPS, MIN_CYCLE_STEPS, stable_time_step)
from .build import (build_model, SPREAD, SPREAD_BELOW, contact_spacing, IMPACT_DEPTH,
                    START_PENETRATION, initial_state, check_time_step)

__all__ = ["OWN_MOTIONS", "AUTO_STEPS_PER_CYCLE", "AUTO_STEPS_PER_RUN", "BodyModel", "Model",
           "BodyState", "PartState", "State", "build_model", "auto_time_step", "auto_time_step_why",
           "MAX_STEPS", "MIN_CYCLE_STEPS", "SPREAD", "SPREAD_BELOW", "contact_spacing",
           "IMPACT_DEPTH", "START_PENETRATION", "initial_state", "stable_time_step",
           "check_time_step"]

#: the names that left the model stage: name -> the module it is in now (by
#: its name, imported when asked for: the model never imports the step)
_MOVED = {"body_contact": "meshwear.contact.winkler",
          "settle_counters": "meshwear.step.counters",
          "wear_counters": "meshwear.step.counters"}


def __getattr__(name):
    """A name that left the model stage, from its new module, with a warning."""
    new = _MOVED.get(name)
    if new is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    warnings.warn(f"meshwear.model.{name} is now {new}.{name}; the old path goes in the next "
                  "release", DeprecationWarning, stacklevel=2)
    return getattr(importlib.import_module(new), name)
