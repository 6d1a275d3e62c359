"""The worn counter-surfaces' wear in a step (docs/model.md, "Worn
counter-surfaces").

After a body's step, :func:`wear_counters` wears the counter-surface
vertices under its contacts on the compiled
:func:`meshwear.kernels.counter_wear.wear_counter` (a vertex moves once the
depth it took since it last moved, its lag, is due);
:func:`settle_counters` moves every lagging vertex to its depth between two
stretches of steps (before outputs, checkpoints and cycle jumps). The
counter-surfaces' state is :class:`meshwear.model.PartState`; the half-space
model hands :func:`wear_counters` its own pairs (:mod:`meshwear.contact.elastic`).
"""

from ..kernels.counter_wear import settle_counter, wear_counter


def settle_counters(model):
    """Move every lagging vertex of the worn counter-surfaces to its depth
    (:func:`meshwear.kernels.counter_wear.settle_counter`)."""
    for surface in model.surfaces.per_vertex:
        if surface.worn and surface.part is not None:
            settle_counter(surface.part_tuple())


def wear_counters(model, body, s, t, pairs=None):
    """The wear of the worn counter-surfaces by the step of ``body`` just
    taken at ``t`` (:func:`meshwear.kernels.counter_wear.wear_counter`).
    ``pairs``: per slot, the (contact state, normal force) the counter
    wears by, in place of the body's (the half-space model's: each vertex's
    energy as a slip of its speed, :mod:`meshwear.contact.elastic`). Returns None,
    or ``(surface, vertex)``: a counter vertex that sank deeper than its
    mesh can follow in that step."""
    P = model.planes.shape[0]
    for m, surface in enumerate(model.surfaces.per_vertex):
        if surface.worn:
            rotation, frame = surface.frame(t)
            state, force = (s.contact_state[P + m], s.normal_force[P + m]) if pairs is None \
                else pairs[P + m]
            worst = wear_counter(s.vertices, s.pose, s.active, body.area_vectors, model.law,
                                 state, force,
                                 s.vertex_planes[m], s.hint[m], rotation, frame,
                                 surface.part_tuple(), m, s.log_index, s.log_value, s.log_count)
            if worst >= 0:
                return surface, worst
    return None
