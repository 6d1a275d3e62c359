"""Mechanisms: worn parts riding on the bodies of a MuJoCo model (docs/mechanisms.md).

Imports the stages below it (scene, motion, surfaces, contact, kernels).
"""

from .active_sets import TRIAL_STEPS, TRIAL_REFRESHES
from .build import Mechanism
from .coupling import slot_wrench

__all__ = ["TRIAL_STEPS", "TRIAL_REFRESHES", "Mechanism", "slot_wrench"]
