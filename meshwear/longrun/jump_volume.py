"""The volume a load-carrying body's implicit jump wears (docs/model.md,
"Long durations", the bound "volume").

Under a load carried along a free axis a cycle wears the load's work against
the sliding, whatever the contact's shape; the implicit step, holding each
vertex's wear per unit penetration fixed, moves the load towards the
vertices that wear least per unit of it and loses volume as the jump grows.
:func:`_keep_volume` brings the jump to the volume its measurements give,
along the way the jump changes as every vertex's wear per unit penetration
grows alike (:func:`_volume_direction`), and refuses a jump more than
:data:`KEEP` off it.
"""

import numpy as np

from .extrapolate import _fresh_area
from .jump_errors import _fit

#: the most a load-carrying body's implicit jump may be off the volume its
#: measurements give (a fraction): the jump is moved to it within this, and
#: halved past it (:func:`_keep_volume`)
KEEP = 0.25


def _keep_volume(bodies, measures, rates, states, before, results, jump, window, volumes,
                 forced=False):
    """The implicit jump's ``results`` with each load-carrying body's wear
    per unit penetration taken larger or smaller alike
    (:func:`_volume_direction`) so that its worn volume over the jump is
    the one its measurements give: its volume per cycle ``volumes`` (the
    last one this measurement's), on the straight line fitted through them
    (:func:`_fit`), over the jump's cycles.

    Under a load carried along a free axis the volume a cycle wears is the
    load's work against the sliding (Archard's ``k L s`` when every point
    slides alike), whatever the contact's shape; the implicit step, which
    holds each vertex's wear per unit penetration fixed, moves the load
    towards the vertices that wear least per unit of it (at a scar's edge,
    in contact for part of the stroke, whose share of the stroke grows as
    they are pressed harder) and loses volume as the jump grows (a cylinder
    on a worn flat kept 0.87 of it at 40 cycles). The jump takes the
    volume of the measurements; None (the jump is too long) where they
    differ by more than :data:`KEEP`, unless the jump is ``forced``.
    Bodies that carry no load along an axis (a prescribed one, whose wear
    relieves its contact) keep the implicit step's volume."""
    times = np.array([t for t, _ in volumes])
    rate = np.vstack([v for _, v in volumes])
    slope = _fit(times, rate)[0] if len(volumes) > 2 else np.zeros(rate.shape[1])
    out = []
    for k, (body, m, r, s, b, (wear, move, error)) in enumerate(
            zip(bodies, measures, rates, states, before, results)):
        target = jump * rate[-1, k] + 0.5 * jump * jump * slope[k]
        if m.guided and m.load != 0.0 and target > 0.0:
            # the volume the jump plans (extrapolate._jump), per unit of each
            # vertex's wear: its volume of the cycle over its wear then, or,
            # brought into contact by the jump, its contact area
            area = np.zeros(len(r))
            wearing = r > 0.0
            area[wearing] = (s.wear_volume[wearing] - b[2][wearing]) / window / r[wearing]
            fresh = ~wearing & (wear > 0.0)
            if fresh.any():
                normal = np.zeros((len(r), 3))
                normal[m.index] = m.normal
                area[fresh] = _fresh_area(body, s, fresh, normal)
            planned = float(wear @ area)
            if abs(planned - target) > KEEP * target and not forced:
                return None
            # every vertex's wear per unit penetration taken a little larger
            # (or smaller) until the volume is the measurements'
            # (:func:`_volume_direction`)
            grow, sink = _volume_direction(m, wear, jump)
            per_unit = float(grow @ area)
            if per_unit > 0.0:
                more = (target - planned) / per_unit
                wear, move = np.maximum(wear + more * grow, 0.0), move + more * sink
        out.append((wear, move, error))
    return out


def _volume_direction(m, wear, jump):
    """How an implicit jump of ``jump`` cycles of body measure ``m`` changes
    as every vertex's wear per unit penetration ``alpha_i`` is taken
    ``(1 + lambda)`` times larger, to first order in ``lambda``: (n,) each
    vertex's wear (``wear`` (n,) the jump's) and the move along the axis,
    from one backward-Euler step with the balance held.

    A vertex wears ``J alpha_i (p_i - beta_i z) / (1 + J (alpha_i +
    gamma_i))``: its own part is ``w_i (1 + J gamma_i) / (1 + J (alpha_i +
    gamma_i))``, and the balance, whose end penetrations fall by ``w_i /
    (1 + J (alpha_i + gamma_i))``, moves the body by ``dz = -sum c_i beta_i
    w_i / (1 + J a_i) / sum c_i beta_i^2 / (1 + J a_i)`` (``a_i = alpha_i +
    gamma_i``, over its pairs in contact), which wears each vertex
    ``J alpha_i beta_i / (1 + J a_i)`` per unit. Where ``J alpha`` is small
    that is every vertex's wear scaled alike; where it is large the jump
    has worn the contact to its mate's shape (a block to a ring's arc) and
    it is a sink of the body that keeps that shape (scaling every vertex's
    wear there left the block-on-ring scar's edge 4.2 % of its depth off
    the arc after jumps of thousands of turns)."""
    n = len(wear)
    gamma = m.gamma if m.gamma is not None else np.zeros(len(m.alpha))
    relief = 1.0 / (1.0 + jump * (m.alpha + gamma))
    w = wear[m.index]
    own = w * (1.0 + jump * gamma) * relief
    pairs = m.member & (w > 0.0) & (m.stiffness > 0.0)
    c = m.stiffness[pairs] * m.beta[pairs] * relief[pairs]
    across = float(c @ m.beta[pairs])
    sink = -float(c @ w[pairs]) / across if across > 0.0 else 0.0
    grow = np.zeros(n)
    grow[m.index] = np.where(w > 0.0, own - sink * jump * m.alpha * m.beta * relief, 0.0)
    return grow, sink
