"""Model (frozen: what a scene is) and State (what changes while it runs): the compile
of a scene into the plain arrays the step takes.

- :mod:`.state`: :class:`Model`, :class:`State` and their bodies' and parts' records;
- :mod:`.build`: :func:`build_model`, :func:`initial_state`, :func:`check_time_step`;
- :mod:`.timestep`: the stable step, the step ``run.dt = "auto"`` stands for, whole steps;
- :mod:`.reach`: which faces a part's ``resolution`` refines.

Imports the stages below it (scene, geometry, motion, surfaces, contact,
mechanism, kernels); never the step, the long run or the outputs.
"""

from .state import OWN_MOTIONS, BodyModel, Model, BodyState, PartState, State
from .timestep import (AUTO_STEPS_PER_CYCLE, AUTO_STEPS_PER_RUN, auto_time_step,
                       auto_time_step_why, MAX_STEPS, MIN_CYCLE_STEPS, stable_time_step)
from .build import (build_model, SPREAD, SPREAD_BELOW, contact_spacing, IMPACT_DEPTH,
                    START_PENETRATION, initial_state, body_contact, settle_counters,
                    wear_counters, check_time_step)

__all__ = ["OWN_MOTIONS", "AUTO_STEPS_PER_CYCLE", "AUTO_STEPS_PER_RUN", "BodyModel", "Model",
           "BodyState", "PartState", "State", "build_model", "auto_time_step", "auto_time_step_why",
           "MAX_STEPS", "MIN_CYCLE_STEPS", "SPREAD", "SPREAD_BELOW", "contact_spacing",
           "IMPACT_DEPTH", "START_PENETRATION", "initial_state", "body_contact", "settle_counters",
           "wear_counters", "stable_time_step", "check_time_step"]
