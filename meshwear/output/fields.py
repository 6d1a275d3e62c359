"""Per-vertex fields and per-body totals of a state, as recorders write them."""

import numpy as np

from ..contact.elastic import vertex_pressure
from ..kernels.contact import FORCE, rotation_entries
from ..surfaces import contact_areas, slot_normals, vertex_feet


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
    each counter-surface, summed; with the half-space contact the solved
    pressure at its point (:func:`meshwear.contact.elastic.vertex_pressure`).

    Returns
    -------
    dict
        ``points`` (n, 3) world positions, the point-data fields of
        docs/outputs.md and the history totals.
    """
    R = np.array(rotation_entries(s.pose[3:7])).reshape(3, 3)
    normal_force = s.normal_force.sum(axis=0)
    friction_force = s.tangential[:, :, FORCE, :].sum(axis=0)
    if s.elastic is not None:
        # the grid's pressure at each vertex's point, not its force over its
        # area (docs/model.md, "In a run")
        pressure = vertex_pressure(s)
    else:
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


def _spread_matrix(surface, columns):
    """The (V, V) sparse matrix that spreads a per-vertex quantity of a worn
    counter-part as its wear is spread, evenly (:meth:`meshwear.surfaces.MeshSurface.spread_over`):
    column ``k`` of ``columns`` (the vertices that hold some) holds vertex
    ``k``'s weights on the vertices it spreads to; a vertex with none keeps
    its own (1 on the diagonal)."""
    from scipy.sparse import csc_matrix, diags

    from ..surfaces.mesh import spread_weights

    starts, items, radius = surface.spread[0], surface.spread[1], surface.spread[4][0]
    n = len(starts) - 1
    counts = np.diff(starts)
    columns = columns[counts[columns] > 0]
    k = np.repeat(columns, counts[columns])
    j = np.concatenate([items[starts[c]:starts[c + 1]] for c in columns]) if len(columns) else \
        np.zeros(0, np.int64)
    weights = spread_weights(surface.reference_vertices, surface.tributary, k, j, radius)
    weights /= np.bincount(k, weights, minlength=n)[k]
    return (csc_matrix((weights, (j, k)), shape=(n, n))
            + diags((counts == 0).astype(float)))


def _matrix_quaternion(R):
    """Unit quaternion (w, x, y, z), w >= 0, of a rotation matrix."""
    from scipy.spatial.transform import Rotation

    x, y, z, w = Rotation.from_matrix(R).as_quat()
    q = np.array([w, x, y, z])
    return q if w >= 0.0 else -q


def part_quantities(model, state, m):
    """Per-vertex fields and totals of the worn counter-surface of slot
    ``m`` of the per-vertex surfaces, as :func:`body_quantities` gives a
    body's: each pair's normal force and friction force (the reaction on the
    counter-part) shared among the vertices of the face under it by the
    barycentric weights of its contact point; pressure is their normal force
    over their tributary area; contact state the highest of the pairs there.
    Totals: the force and torque (about the surface frame's origin) on it, and
    the frame's pose and velocity."""
    surface = model.surfaces.per_vertex[m]
    part = state.parts[m]
    n = len(part.depth)
    rotation, frame = surface.frame(state.time)
    slot = model.planes.shape[0] + m
    normal_force, friction_force = np.zeros(n), np.zeros((n, 3))
    contact_state = np.zeros(n, np.int32)
    force, torque = np.zeros(3), np.zeros(3)
    for s in state.bodies:
        pairs = s.active[(s.normal_force[slot, s.active] > 0.0) & (s.hint[m, s.active] >= 0)]
        if not len(pairs):
            continue
        foot = vertex_feet(s, m, pairs)
        load = s.normal_force[slot, pairs]
        friction = -s.tangential[slot, pairs, FORCE]
        reaction = -load[:, None] * s.vertex_planes[m, pairs, 1] + friction
        force += reaction.sum(axis=0)
        torque += np.cross(foot - frame[0], reaction).sum(axis=0)
        weights, corners = surface.face_weights(foot, s.hint[m, pairs], state.time)
        for c in range(3):
            np.add.at(normal_force, corners[:, c], weights[:, c] * load)
            np.add.at(friction_force, corners[:, c], weights[:, c, None] * friction)
            np.maximum.at(contact_state, corners[:, c],
                          np.where(weights[:, c] > 0.0, s.contact_state[slot, pairs], 0))
    if len(getattr(surface, "spread", ((),))[0]):
        # the forces spread as the wear is (the area each contact stands for)
        held = np.flatnonzero((normal_force != 0.0) | (np.abs(friction_force) > 0.0).any(axis=1))
        spread = _spread_matrix(surface, held)
        normal_force = spread @ normal_force
        friction_force = spread @ friction_force
    counts = np.bincount(contact_state, minlength=3)
    return {
        "points": surface.world_vertices(part.vertices, state.time),
        "wear_depth": part.depth,
        "normal_force": normal_force,
        "friction_force": friction_force,
        "pressure": normal_force / surface.tributary,
        "contact_state": contact_state,
        "friction_work": part.work,
        "origin": frame[0].copy(),
        "orientation": _matrix_quaternion(rotation),
        "velocity": frame[1].copy(),
        "angular_velocity": frame[2].copy(),
        "wrench": np.concatenate([force, torque]),
        "wear_volume": float(part.volume.sum()),
        "max_wear_depth": float(part.depth.max()),
        "total_friction_work": float(part.work.sum()),
        "contact_points": int(counts[1] + counts[2]),
        "stick_points": int(counts[1]),
        "slip_points": int(counts[2]),
    }
