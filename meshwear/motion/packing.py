"""The arrays of a body and its motion as the compiled step loops take them
(:mod:`meshwear.kernels.loop`, :mod:`meshwear.kernels.mechanism`)."""

import numpy as np

from ..kernels.rigid import BALANCED, TURNING


def body_arrays(model, body, s):
    """The ``body`` tuple of :mod:`meshwear.kernels.loop`."""
    return (s.vertices, s.pose, body.area_vectors, model.law, body.wear_direction,
            s.contact_state, s.tangential, s.normal_force, s.friction_work, s.wear_depth,
            s.wear_volume, s.wrench, s.vertex_planes, s.hint, s.active, s.active_wear, s.cull,
            s.cull_scratch.distance, s.load, float(body.radius), float(body.depth_limit),
            s.impact_room, s.log_index, s.log_value, s.log_count)


def motion_arrays(model, body, s):
    """The ``motion`` tuple of :mod:`meshwear.kernels.loop`."""
    m = body.motion
    if m.kind in (BALANCED, TURNING) and model.quasi_static:
        scratch = m.ensure_scratch(len(s.active) * model.slots)
    else:
        scratch = np.zeros((2, 0))
    return (int(m.kind), m.params, m.path.terms, m.path.buffer, scratch)
