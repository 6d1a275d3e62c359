"""Mechanisms: worn parts riding on the bodies of a MuJoCo model (docs/model.md, "Mechanisms").

:class:`~.build.Mechanism` is one object made of four parts:

- :mod:`.build`: the MuJoCo model compiled, its riders checked and placed;
- :mod:`.coupling`: the step's coupling (contact wrenches pushed, MuJoCo stepped);
- :mod:`.active_sets`: the trial of the riders' active sets and the stable step;
- :mod:`.state`: MuJoCo's state for checkpoints and jumps, and what ``check`` says of it.

Imports the stages below it (scene, motion, surfaces, contact, kernels).
"""

from .active_sets import TRIAL_STEPS, TRIAL_REFRESHES
from .build import Mechanism
from .coupling import slot_wrench

__all__ = ["TRIAL_STEPS", "TRIAL_REFRESHES", "Mechanism", "slot_wrench"]
