"""Per-vertex fields and per-body totals of a state, as recorders write them."""

import numpy as np

from ..kernels.contact import FORCE, rotation_entries
from ..surfaces import contact_areas, slot_normals


def body_totals(body, s):
    """A body's totals for a history row or the summary: its mesh origin in
    the world (3,), worn volume, deepest wear, friction work, and the points
    in contact, sticking and slipping (the highest state over surfaces)."""
    R = np.array(rotation_entries(s.pose[3:7])).reshape(3, 3)
    states = (s.contact_state.max(axis=0) if s.contact_state.shape[0]
              else np.zeros(len(s.wear_depth), np.int8))
    counts = np.bincount(states, minlength=3)
    return {
        "origin": s.pose[0:3] + R @ body.origin,
        "wear_volume": float(s.wear_volume.sum()),
        "max_wear_depth": float(s.wear_depth.max()),
        "total_friction_work": float(s.friction_work.sum()),
        "contact_points": int(counts[1] + counts[2]),
        "stick_points": int(counts[1]),
        "slip_points": int(counts[2]),
    }


def body_quantities(body, s, model):
    """Per-vertex fields and totals of one body, for recorders.

    The pressure of a vertex is its normal force over its contact area on
    each counter-surface, summed.

    Returns
    -------
    dict
        ``points`` (n, 3) world positions, the point-data fields of DESIGN.md
        §5 and the history totals.
    """
    R = np.array(rotation_entries(s.pose[3:7])).reshape(3, 3)
    normal_force = s.normal_force.sum(axis=0)
    friction_force = s.tangential[:, :, FORCE, :].sum(axis=0)
    pressure = np.zeros(len(s.wear_depth))
    for j, normal in enumerate(slot_normals(model, s)):
        loaded = s.normal_force[j] > 0.0
        if loaded.any():
            area = contact_areas(body, s, normal)
            pressure[loaded] += s.normal_force[j][loaded] / area[loaded]
    return {
        "points": s.pose[0:3] + s.vertices @ R.T,
        "origin": s.pose[0:3] + R @ body.origin,
        "wear_depth": s.wear_depth,
        "normal_force": normal_force,
        "friction_force": friction_force,
        "pressure": pressure,
        "contact_state": (s.contact_state.max(axis=0) if s.contact_state.shape[0]
                          else np.zeros(len(s.wear_depth), np.int8)).astype(np.int32),
        "friction_work": s.friction_work,
        "wear_volume": float(s.wear_volume.sum()),
        "max_wear_depth": float(s.wear_depth.max()),
        "total_friction_work": float(s.friction_work.sum()),
    }
