"""Long durations: cycle jumping with error control (docs/model.md, "Long durations").

Resolve one cycle of the motion with the ordinary step, measure each
vertex's wear in that cycle, extrapolate it over ``J`` cycles, then resolve
again. The extrapolation (``wear.jump``) is

implicit (default)
    a backward-Euler step: a vertex's wear rate is proportional to its
    elastic penetration ``p_i`` (Winkler: pressure is linear in penetration,
    and Archard's or the energy law in pressure), ``r_i = alpha_i p_i``, and
    the jump solves ``w_i = J alpha_i p_i(end)`` with ``p_i(end) = p_i - beta_i z
    - w_i``, ``z`` the move of a guided body along its free axis that keeps its
    load carried by the relieved contacts (the quasi-static balance,
    :func:`meshwear.kernels.balance.balance_offset`, with each vertex's
    stiffness divided by ``1 + J alpha_i``). Each vertex's pressure relaxes
    by ``1 / (1 + J alpha_i)`` instead of ``exp(-J alpha_i)``: stable for any
    ``J``, exact for long ones where the pressure has settled.
explicit
    the cycle's wear times ``J``, with the stability bound below.

``J`` is chosen before every jump from

accuracy (slope criterion)
    the change of each vertex's wear rate between the last two resolved
    cycles, ``rho`` per cycle, makes the extrapolation over ``J`` cycles
    wrong by about ``rho J^2 / 2``; ``J`` keeps that under ``tolerance`` times
    the depth the jump adds where wear is fastest, so the errors of all jumps
    add up to at most ``tolerance`` times the deepest wear.
growth
    ``J`` grows by at most a factor :data:`GROWTH` from one jump to the next.
stability (explicit jumps only)
    no vertex may wear by more than a fraction :data:`THETA` of its elastic
    penetration in one jump. Past that the extrapolated wear opens a gap where
    the contact was carrying load, and the worn profile oscillates from jump
    to jump while the worn volume still looks right.

Outputs falling inside a jumped span are filled from the jump
(:mod:`meshwear.output.filled`), so they cost no resolved cycle. In the
dynamic mode the cycle after a jump only lets the contact settle and the
next one is measured.
"""

from dataclasses import dataclass, field

import numpy as np

from .kernels.balance import balance_offset
from .kernels.contact import ANCHOR
from .motion import BalancedMotion, GuidedMotion
from .output import filled
from .surfaces import contact_areas, quaternion_matrix, slot_normals

#: largest wear in one explicit jump, as a fraction of a vertex's elastic penetration
THETA = 0.3
#: a jump is at most this many times the previous one, plus one
GROWTH = 2.0
#: vertices wearing less than this fraction of the fastest one per cycle do not
#: limit the jump (their rates are round-off or contact-edge flicker)
SIGNIFICANT = 1e-3


@dataclass
class JumpState:
    """The controller's memory, saved with checkpoints."""

    rate: list = field(default_factory=list)       # per body (n,) wear per cycle, last measured
    gap: float = 0.0                                # cycles between the last two measurements
    last_jump: int = 0
    jumps: int = 0
    resolved_steps: int = 0
    error: list = field(default_factory=list)      # per body (n,) estimated error of w (m)
    settling: bool = False                          # dynamic: the next cycle only settles
    limits: dict = field(default_factory=lambda: {"stability": 0, "accuracy": 0, "growth": 0,
                                                   "end": 0})


def penetration(model, body, s):
    """(n,) elastic penetration of each vertex at the end of the last step (m):
    its normal force over its normal stiffness, the largest over the surfaces."""
    out = np.zeros(len(s.wear_depth))
    for j, normal in enumerate(slot_normals(model, s)):
        area = contact_areas(body, s, normal)
        c = model.law[5] + model.law[6] * area
        loaded = (s.normal_force[j] > 0.0) & (c > 0.0)
        out[loaded] = np.maximum(out[loaded], s.normal_force[j][loaded] / c[loaded])
    return out


def cycle_penetration(model, body, s, pressed=None):
    """(n,) the penetration a vertex's wear in the last cycle answers to: its
    elastic penetration at the end of the cycle (``pressed``, computed if not
    given) or, for a vertex that touched during the cycle only, its peak
    normal force over its stiffness."""
    if pressed is None:
        pressed = penetration(model, body, s)
    c = model.law[5] + model.law[6] * body.area_vectors[:, 3]
    peak = np.where(c > 0.0, s.peak / np.where(c > 0.0, c, 1.0), 0.0)
    return np.where(pressed > 0.0, pressed, peak)


def choose_jump(rate, previous, gap, penetration_, tolerance, last_jump, limit, theta=THETA,
                stability=True):
    """Cycles to jump over, and which bound set it.

    Parameters
    ----------
    rate, previous : (n,) float
        Wear per cycle in the last resolved cycle and in the one before
        (``previous`` None after the first).
    gap : float
        Cycles between those two measurements.
    penetration_ : (n,) float
        Elastic penetration at the end of the last resolved cycle (m).
    tolerance : float
        Relative error allowed on wear depth.
    last_jump, limit : int
        The previous jump, and the most cycles that may be jumped here.
    stability : bool
        Bound by :data:`THETA` of the penetration (explicit jumps).
    """
    fastest = rate.max() if len(rate) else 0.0
    if fastest <= 0.0 or previous is None:
        return 0, "accuracy"
    active = rate > SIGNIFICANT * fastest
    bounds = {"end": float(limit), "growth": GROWTH * last_jump + 1.0}
    # stability: J r_i <= theta p_i
    pressed = active & (penetration_ > 0.0)
    if stability and pressed.any():
        bounds["stability"] = float((theta * penetration_[pressed] / rate[pressed]).min())
    # accuracy: rho_i J^2 / 2 <= tol J r_max, the error of each vertex's
    # extrapolation under tol times the depth the jump adds where wear is
    # fastest (the scale of the scar: a vertex just entering the contact
    # changes its rate fast, but its depth is small)
    rho = np.abs(rate - previous) / max(gap, 1.0)
    if rho.max() > 0.0:
        bounds["accuracy"] = float(2.0 * tolerance * fastest / rho.max())
    which = min(bounds, key=bounds.get)
    return max(0, int(np.floor(bounds[which]))), which


def run_cycle_jump(model, state, observers=(), progress=None, checkpoint=None, forced_jump=None,
                   compiled=True):
    """Run ``state`` to the end of ``model``'s duration, jumping over cycles.

    ``forced_jump`` replaces the controller by a fixed jump (still stopping
    at the end): the fixed-factor scheme of finite-element wear codes, for
    comparisons and tests.
    """
    from .simulate import advance

    n_c = model.cycle_steps
    tolerance = model.scene.wear.tolerance
    implicit = model.scene.wear.jump == "implicit"
    if state.jump is None:
        state.jump = JumpState(rate=[None] * len(model.bodies),
                               error=[np.zeros(len(b.tributary_area)) for b in model.bodies])
    js = state.jump
    for body, s in zip(model.bodies, state.bodies):
        if len(s.peak) != len(s.wear_depth):
            s.peak = np.zeros(len(s.wear_depth))
    while state.step < model.n_steps:
        start = state.step
        before = [(s.wear_depth.copy(), s.vertices.copy(), s.wear_volume.copy(),
                   s.friction_work.copy()) for s in state.bodies]
        for s in state.bodies:
            s.peak[:] = 0.0
        stop = min(start + n_c, model.n_steps)
        # the cycles a jump after this one may cover: the outputs in them are
        # filled from the states of this cycle at the same phase
        end_limit = max(0, (model.n_steps - stop - 1) // n_c)
        could = 0 if js.settling or forced_jump == 0 else min(
            end_limit, forced_jump if forced_jump is not None else int(GROWTH * js.last_jump + 1))
        snapshots = filled.record(model, state, start, stop, could, observers, progress,
                                  compiled)
        js.resolved_steps += stop - start
        if stop - start < n_c or state.step >= model.n_steps:
            break
        if js.settling:
            js.settling = False
            continue
        rates = [s.wear_depth - b[0] for s, b in zip(state.bodies, before)]
        jump, which = end_limit, "end"
        if forced_jump is not None:
            jump, which = min(end_limit, forced_jump), "forced"
        else:
            for body, s, rate, previous in zip(model.bodies, state.bodies, rates, js.rate):
                j, w = choose_jump(rate, previous, js.gap, penetration(model, body, s),
                                   tolerance, js.last_jump, end_limit, stability=not implicit)
                if j < jump:
                    jump, which = j, w
        jump = min(jump, could)
        if jump > 0:
            # the slope criterion's own estimate of this jump's error, per vertex
            for error, rate, previous in zip(js.error, rates, js.rate):
                if previous is not None:
                    error += 0.5 * np.abs(rate - previous) / max(js.gap, 1.0) * jump * jump
            js.limits[which] = js.limits.get(which, 0) + 1
            spans = _jump(model, state, before, rates, jump, implicit)
            filled.write(model, state, stop, jump, snapshots, spans, observers)
            js.jumps += 1
            js.settling = not model.quasi_static
        js.last_jump = jump
        js.rate = rates
        js.gap = jump + 1.0 + (1.0 if js.settling else 0.0)
        if checkpoint is not None:
            checkpoint(model, state)
    return state


def _implicit(model, body, s, rate, jump):
    """Backward-Euler wear of one body over ``jump`` cycles: (n,) wear and
    the move ``z`` (m) along a guided body's free axis.

    Three kinds of vertices: pressed at the end of the cycle (their
    penetration answers to ``z``), touched during the cycle only (a gear
    flank: their peak penetration bounds their wear, ``z`` aside), and
    untouched ones that ``z`` may bring into contact (they wear as the
    contact does on average per unit penetration, their own rate unknown).
    A pressed vertex that did not wear (it sticks) keeps ``alpha = 0``.
    """
    pressed = penetration(model, body, s)
    pen = cycle_penetration(model, body, s, pressed)
    wearing = (rate > 0.0) & (pen > 0.0)
    alpha = np.zeros(len(rate))
    alpha[wearing] = rate[wearing] / pen[wearing]
    fresh = pen <= 0.0
    area = body.area_vectors[:, 3]
    if wearing.any():
        alpha[fresh] = (rate[wearing] @ area[wearing]) / (pen[wearing] @ area[wearing])
    relief = 1.0 / (1.0 + jump * alpha)
    depth = pen
    z, beta, normal = 0.0, np.zeros(len(rate)), None
    motion = body.motion
    if isinstance(motion, (BalancedMotion, GuidedMotion)) and len(s.active):
        axis = motion.axis
        carried = (motion.carried if isinstance(motion, BalancedMotion)
                   else -float(motion.params[19:22] @ axis) / motion.params[0])
        scratch = np.zeros((2, len(s.active) * model.slots))
        z = balance_offset(s.vertices, s.pose, axis, model.planes, s.vertex_planes, s.active,
                           body.area_vectors, model.law, carried, 0.0, scratch, relief)
        if not np.isfinite(z):
            z = 0.0
        gap, normal = _nearest(model, body, s)
        moves = (pressed > 0.0) | fresh
        depth = np.where(fresh, gap, pen)
        beta = np.where(moves, normal @ axis, 0.0)
    return jump * alpha * np.maximum(0.0, depth - beta * z) * relief, z, normal


def _nearest(model, body, s):
    """Per vertex, the penetration ``-Delta`` (m, negative: a gap) on the
    surface it is nearest to or deepest in, and that surface's normal there
    (world; zero where no surface faces it)."""
    from .kernels.contact import FACING

    R = quaternion_matrix(s.pose[3:7])
    x = s.pose[0:3] + s.vertices @ R.T
    world = body.area_vectors[:, 0:3] @ R.T
    n_vertices = len(x)
    best, nearest = np.full(n_vertices, -np.inf), np.zeros((n_vertices, 3))
    rows = [np.broadcast_to(p[0:2], (n_vertices, 2, 3)) for p in model.planes]
    rows += [vp[:, 0:2] for vp in s.vertex_planes]
    for row in rows:
        point, normal = row[:, 0], row[:, 1]
        facing = -np.einsum("ij,ij->i", world, normal) > FACING * body.area_vectors[:, 3]
        depth = -np.einsum("ij,ij->i", x - point, normal)
        better = facing & (depth > best)
        best[better] = depth[better]
        nearest[better] = normal[better]
    return best, nearest


#: the per-vertex arrays a jump extrapolates
JUMPED = ("vertices", "wear_depth", "wear_volume", "friction_work")


def _jump(model, state, before, rates, jump, implicit):
    """Extrapolate the last resolved cycle over ``jump`` more cycles; return
    per body ``{name: (array at the jump's start, at its end)}`` for the
    :data:`JUMPED` arrays, and ``shift``, the move of its position."""
    spans = []
    for body, s, b, rate in zip(model.bodies, state.bodies, before, rates):
        _, vertices0, volume0, work0 = b
        span = {name: getattr(s, name).copy() for name in JUMPED}
        if implicit:
            wear, z, normal = _implicit(model, body, s, rate, jump)
        else:
            wear, z, normal = jump * rate, 0.0, None
        # every increment of the cycle scaled like the vertex's wear: a
        # vertex relieved by the jump wears, and dissipates, less
        factor = np.full(len(rate), float(jump))
        wearing = rate > 0.0
        factor[wearing] = wear[wearing] / rate[wearing]
        work = s.friction_work - work0
        volume = s.wear_volume - volume0
        s.vertices += factor[:, None] * (s.vertices - vertices0)
        s.wear_volume += factor * volume
        s.friction_work += factor * work
        fresh = ~wearing & (wear > 0.0)
        if fresh.any():
            # a vertex the jump brought into contact had no cycle to scale:
            # it moves along its surface's normal, wears its depth times its
            # contact area, and dissipates what the contact does per volume
            _wear_fresh(body, s, fresh, wear, normal,
                        work[wearing].sum() / max(volume[wearing].sum(), 1e-300))
        s.wear_depth += wear
        span = {name: (span[name], getattr(s, name).copy()) for name in JUMPED}
        span["shift"] = z * body.motion.axis if z else np.zeros(3)
        spans.append(span)
    state.step += jump * model.cycle_steps
    state.time = state.step * model.dt
    state.resolved = False
    # put every body where its path is at the new time (a steady sliding path
    # has moved on; a periodic one is back in phase), a guided one moved along
    # its axis as the jump's balance has it, and carry the stick anchors
    # along, so the next step does not see the jump as a slide
    for body, s, span in zip(model.bodies, state.bodies, spans):
        start = s.pose[0:3].copy()
        s.pose[0:3] += span["shift"]
        body.motion.place(s.pose, state.time)
        moved = s.pose[0:3] - start
        for j, n in enumerate(slot_normals(model, s)):
            n = np.broadcast_to(n, s.tangential[j, :, ANCHOR].shape)
            s.tangential[j, :, ANCHOR] += moved - np.einsum("ij,j->i", n, moved)[:, None] * n
    return spans


def _wear_fresh(body, s, fresh, wear, normal, work_per_volume):
    """Wear ``wear[fresh]`` of vertices with no cycle increments to scale,
    pressed by the surfaces of world ``normal`` (n, 3)."""
    R = quaternion_matrix(s.pose[3:7])
    local = normal[fresh] @ R                    # the normal in the body frame
    direction = body.wear_direction[fresh] if len(body.wear_direction) else local
    depth = wear[fresh]
    s.vertices[fresh] += depth[:, None] * direction
    area = -np.einsum("ij,ij->i", body.area_vectors[fresh, 0:3], local)
    volume = depth * np.maximum(area, 0.0)
    s.wear_volume[fresh] += volume
    s.friction_work[fresh] += work_per_volume * volume


def error_estimate(state):
    """Estimated relative error of the wear depth from the jumps (0 without)."""
    js = state.jump
    if js is None:
        return 0.0
    worst = 0.0
    for error, s in zip(js.error, state.bodies):
        deepest = s.wear_depth.max() if len(s.wear_depth) else 0.0
        if deepest > 0.0:
            worst = max(worst, float(error.max() / deepest))
    return worst
