"""An observer that keeps every history sample in memory (scripts and tests)."""

import numpy as np

from .fields import body_totals


class MemoryHistory:
    """Observer that keeps every sample in memory, for scripts and tests.

    After a run, ``rows[name]`` is a dict of arrays per body: ``time``,
    ``pose`` (k, 13), ``origin`` (k, 3), ``wrench`` (k, 6), ``friction_work``,
    ``wear_volume``, ``max_wear_depth``, ``wear_depth`` (k, n) and
    ``contact_points``; with a mechanism, its joint and actuator columns
    (``spin.v``, ``press.force``: docs/outputs.md).
    """

    def __init__(self):
        self._rows = {}

    def on_sample(self, model, state):
        for body, s in zip(model.bodies, state.bodies):
            q = body_totals(body, s)
            r = self._rows.setdefault(body.name, {k: [] for k in (
                "time", "pose", "origin", "wrench", "friction_work", "wear_volume",
                "max_wear_depth", "wear_depth", "contact_points", "active", "resolved")})
            r["time"].append(state.time)
            r["pose"].append(s.pose.copy())
            r["origin"].append(q["origin"])
            r["wrench"].append(s.wrench.copy())
            r["friction_work"].append(q["total_friction_work"])
            r["wear_volume"].append(q["wear_volume"])
            r["max_wear_depth"].append(q["max_wear_depth"])
            r["wear_depth"].append(s.wear_depth.copy())
            r["contact_points"].append(q["contact_points"])
            r["active"].append(len(s.active))
            r["resolved"].append(bool(state.resolved))
            for key, value in model.dynamics.columns().items():
                r.setdefault(key, []).append(value)

    def on_frame(self, model, state):
        pass

    @property
    def rows(self):
        return {name: {k: np.asarray(v) for k, v in r.items()} for name, r in self._rows.items()}
