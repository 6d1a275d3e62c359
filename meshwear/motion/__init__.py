"""How bodies move (docs/model.md, "Rigid-body motion"): paths, the free,
guided, balanced, turning, prescribed and fixed motions, and the dynamics seam
every way of moving fills.

- :mod:`.motions`: paths and the motions of meshwear's own bodies;
- :mod:`.dynamics`: the seam every way of moving fills, and meshwear's own motions behind it;
- :mod:`.packing`: a body and its motion as the compiled step loops take them.

Imports only :mod:`meshwear.kernels` (the MuJoCo mechanism, which also moves
bodies, is :mod:`meshwear.mechanism`, above the contact models it needs).
"""

from .motions import (Path, NO_SCALE, Motion, FreeMotion, PrescribedMotion, GuidedMotion,
                      BalancedMotion, TurningMotion, FixedMotion, MechanismMotion)

__all__ = ["Path", "NO_SCALE", "Motion", "FreeMotion", "PrescribedMotion", "GuidedMotion",
           "BalancedMotion", "TurningMotion", "FixedMotion", "MechanismMotion"]
