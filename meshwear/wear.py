"""Long durations: cycle jumping with error control (DESIGN.md §4).

Resolve one cycle of the motion with the ordinary step, measure each
vertex's wear in that cycle, extrapolate it over ``J`` cycles (wear depth,
worn volume, friction work and the vertex displacement all grow ``J`` times
what the cycle gave), then resolve again. ``J`` is chosen before every jump
from two bounds, and never fixed:

stability
    no vertex may wear by more than a fraction :data:`THETA` of its elastic
    penetration at the end of the resolved cycle in one jump. Past that the
    extrapolated wear opens a gap where the contact was carrying load, the
    next cycle finds the load elsewhere, and the worn profile oscillates from
    jump to jump while the worn volume still looks right.
accuracy (slope criterion)
    the change of each vertex's wear rate between the last two resolved
    cycles, ``rho`` per cycle, makes a linear extrapolation over ``J`` cycles
    wrong by about ``rho J^2 / 2``; ``J`` keeps that under ``tolerance`` times
    the depth the jump adds where wear is fastest, so the errors of all jumps
    add up to at most ``tolerance`` times the deepest wear.

``J`` also grows by at most a factor :data:`GROWTH` from one jump to the
next, and never steps over an output time: frames and history rows land at
the times asked, inside resolved cycles. In the dynamic mode the cycle after
a jump only lets the contact settle and the next one is measured.
"""

from dataclasses import dataclass, field

import numpy as np

from .kernels.contact import ANCHOR
from .surfaces import contact_areas, slot_normals

#: largest wear in one jump, as a fraction of a vertex's elastic penetration
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
                                                   "output": 0})


def penetration(model, body, s):
    """(n,) elastic penetration of each vertex at the end of the last step (m):
    its normal force over its normal stiffness, the largest over the planes."""
    out = np.zeros(len(s.wear_depth))
    for j, normal in enumerate(slot_normals(model, s)):
        area = contact_areas(body, s, normal)
        c = model.law[5] + model.law[6] * area
        loaded = (s.normal_force[j] > 0.0) & (c > 0.0)
        out[loaded] = np.maximum(out[loaded], s.normal_force[j][loaded] / c[loaded])
    return out


def choose_jump(rate, previous, gap, penetration_, tolerance, last_jump, limit, theta=THETA):
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
    """
    fastest = rate.max() if len(rate) else 0.0
    if fastest <= 0.0 or previous is None:
        return 0, "accuracy"
    active = rate > SIGNIFICANT * fastest
    bounds = {"output": float(limit), "growth": GROWTH * last_jump + 1.0}
    # stability: J r_i <= theta p_i
    pressed = active & (penetration_ > 0.0)
    if pressed.any():
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

    ``forced_jump`` replaces the controller by a fixed jump (still stopping at
    output times): the fixed-factor scheme of finite-element wear codes, for
    comparisons and tests.
    """
    from .simulate import advance

    n_c = model.cycle_steps
    tolerance = model.scene.wear.tolerance
    if state.jump is None:
        state.jump = JumpState(rate=[None] * len(model.bodies),
                               error=[np.zeros(len(b.tributary_area)) for b in model.bodies])
    js = state.jump
    while state.step < model.n_steps:
        start = state.step
        before = [(s.wear_depth.copy(), s.vertices.copy(), s.wear_volume.copy(),
                   s.friction_work.copy()) for s in state.bodies]
        stop = min(start + n_c, model.n_steps)
        advance(model, state, stop, observers, progress, compiled=compiled)
        js.resolved_steps += stop - start
        if stop - start < n_c or state.step >= model.n_steps:
            break
        if js.settling:
            js.settling = False
            continue
        rates = [s.wear_depth - b[0] for s, b in zip(state.bodies, before)]
        # the next output must fall inside (or at the end of) a resolved cycle
        following = model.output_steps[np.searchsorted(model.output_steps, state.step,
                                                        side="right")]
        limit = (following - state.step - 1) // n_c
        jump, which = limit, "output"
        if forced_jump is not None:
            jump, which = min(limit, forced_jump), "forced"
        else:
            for body, s, rate, previous in zip(model.bodies, state.bodies, rates, js.rate):
                j, w = choose_jump(rate, previous, js.gap, penetration(model, body, s),
                                   tolerance, js.last_jump, limit)
                if j < jump:
                    jump, which = j, w
        if jump > 0:
            # the slope criterion's own estimate of this jump's error, per vertex
            for error, rate, previous in zip(js.error, rates, js.rate):
                if previous is not None:
                    error += 0.5 * np.abs(rate - previous) / max(js.gap, 1.0) * jump * jump
            js.limits[which] = js.limits.get(which, 0) + 1
            _jump(model, state, before, rates, jump)
            js.jumps += 1
            js.settling = not model.quasi_static
        js.last_jump = jump
        js.rate = rates
        js.gap = jump + 1.0 + (1.0 if js.settling else 0.0)
        if checkpoint is not None:
            checkpoint(model, state)
    return state


def _jump(model, state, before, rates, jump):
    """Extrapolate the last resolved cycle over ``jump`` more cycles."""
    for s, b, rate in zip(state.bodies, before, rates):
        _, vertices0, volume0, work0 = b
        s.vertices += jump * (s.vertices - vertices0)
        s.wear_volume += jump * (s.wear_volume - volume0)
        s.friction_work += jump * (s.friction_work - work0)
        s.wear_depth += jump * rate
    state.step += jump * model.cycle_steps
    state.time = state.step * model.dt
    # put every body where its path is at the new time (a steady sliding path
    # has moved on; a periodic one is back in phase), and carry the stick
    # anchors along, so the next step does not see the jump as a slide
    for body, s in zip(model.bodies, state.bodies):
        start = s.pose[0:3].copy()
        body.motion.place(s.pose, state.time)
        moved = s.pose[0:3] - start
        for j, n in enumerate(slot_normals(model, s)):
            n = np.broadcast_to(n, s.tangential[j, :, ANCHOR].shape)
            s.tangential[j, :, ANCHOR] += moved - np.einsum("ij,j->i", n, moved)[:, None] * n


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
