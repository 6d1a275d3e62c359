"""The Winkler (penalty) contact model's Python side (docs/model.md,
"Normal force (eq. 1)", "Stiffness and damping per point or per area").

Each vertex presses on the counter-surface under it with a force of its own
penetration alone (a spring per point, or a Winkler foundation per area);
the normal force, friction, energy and wear of a step are compiled in
:func:`meshwear.kernels.contact.contact`, and :func:`body_contact` runs it
on one body's state. The half-space model, in which the vertices press on
one another, is :mod:`.elastic`.
"""

from ..kernels.contact import contact


def body_contact(model, body, s, law=None):
    """One step of the contact kernel for one body (planes and mesh surfaces,
    its active vertices); ``law`` in place of the model's."""
    contact(s.vertices, s.pose, model.planes, s.vertex_planes, s.active, body.area_vectors,
            model.law if law is None else law, body.wear_direction, s.contact_state,
            s.tangential, s.normal_force, s.friction_work, s.wear_depth, s.wear_volume,
            s.wrench)
