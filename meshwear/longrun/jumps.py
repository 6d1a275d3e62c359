"""Implicit (backward-Euler) wear jumps and their error (docs/model.md, "Long durations").

On a Winkler foundation a vertex's pressure is linear in its elastic
penetration, and Archard's and the energy laws make its wear rate linear in
its pressure, so over a resolved cycle ``r_i = alpha_i pbar_i``, ``pbar_i``
its penetration while in contact (its force-weighted mean normal force over
its stiffness: the cycle's penetration whether the vertex touches all the
cycle, a pin's, or for a few steps of it, a gear flank's). Wear and a move
``z`` of a guided body along its axis take the same amount off its
penetration at every step it touches, so a jump of ``J`` cycles solves,
backward Euler,

    w_i = J alpha_i (phat_i - beta_i z - w_i)_+,    sum_i c_i beta_i (p_i - beta_i z - w_i)_+ = L,

``p_i`` the penetration at the end of the cycle on the surface nearest the
vertex, ``phat_i`` its penetration while in contact as of the end of the
cycle (:func:`measure`), ``beta_i`` the free axis along its normal, ``L``
the load: each vertex wears ``J alpha_i (phat_i - beta_i z) / (1 + J
alpha_i)`` (at most its penetration, whatever ``J``), its end penetration
becomes ``(p_i + J alpha_i (p_i - phat_i) - beta_i z) / (1 + J alpha_i)`` and ``z`` is
a 1-D monotone solve (:func:`meshwear.kernels.balance.implicit_step`). A vertex touched during the cycle
but not at its end wears alike, but at most twice its measured wear per
cycle times ``J`` (:func:`touched_cap`), and does not take part in the balance
(its normal, if it faces no surface then, is its own). A vertex out of contact
that the move brings in wears as the contact does on average per unit
penetration, from its gap at the end of the cycle.

A worn counter-part relieves a vertex too: the counter's wear under it in
the cycle, ``r_c,i = gamma_i pbar_i`` (linear in the pressure alike), takes
off its penetration with its own: ``alpha_i`` becomes ``alpha_i + gamma_i``
in the relief above, while the vertex itself wears ``J alpha_i`` times its
relieved penetration (:func:`counter_relief`; the counter-part's own wear is
extrapolated in :mod:`meshwear.longrun.wear`).

A jump is taken as one step of ``J``, two of ``J / 2`` and four of ``J / 4``
(each from the penetrations the one before leaves) and advances with their
Richardson extrapolation (second order), its error estimated from the two
extrapolations (:func:`implicit`).
"""

from dataclasses import dataclass

import numpy as np

from ..contact.elastic import equivalent_depth
from ..kernels.balance import implicit_step
from ..kernels.contact import FACING
from ..motion.motions import BalancedMotion, GuidedMotion, MechanismMotion, TurningMotion
from ..surfaces import quaternion_matrix, vertex_feet


def contact_geometry(model, body, s, index):
    """For the vertices ``index`` (k,) of ``body`` (state ``s``), on the
    surface each is deepest in or nearest to among those it faces: its
    penetration ``-Delta`` (m, negative: a gap; ``-inf`` with no surface),
    that surface's normal (k, 3, world) and the vertex's normal stiffness
    against it (N/m)."""
    R = quaternion_matrix(s.pose[3:7])
    x = s.pose[0:3] + s.vertices[index] @ R.T
    world = body.area_vectors[index, 0:3] @ R.T
    length = body.area_vectors[index, 3]
    n = len(x)
    depth, normal, area = np.full(n, -np.inf), np.zeros((n, 3)), np.zeros(n)
    rows = [(np.broadcast_to(p[0:2], (n, 2, 3)), True) for p in model.planes]
    # a mesh surface's plane rows are kept for the vertices within reach only
    # (the others' are stale)
    within = np.zeros(len(s.wear_depth), dtype=bool)
    within[s.active] = True
    reach = within[index]
    rows += [(vp[index, 0:2], reach) for vp in s.vertex_planes]
    for row, valid in rows:
        point, nrm = row[:, 0], row[:, 1]
        projected = -np.einsum("ij,ij->i", world, nrm)
        facing = (projected > FACING * length) & valid
        d = -np.einsum("ij,ij->i", x - point, nrm)
        better = facing & (d > depth)
        depth[better], normal[better], area[better] = d[better], nrm[better], projected[better]
    if model.elastic is not None:
        depth = equivalent_depth(model, body, s, index, depth, area)
    return depth, normal, model.law[5] + model.law[6] * area


#: rows of a body state's ``load`` while cycles are measured: per vertex, the
#: sum over the cycle's steps of its normal force, of its square, and of its
#: vector along the normals of the slots pressing it (world, three rows)
LOAD_ROWS = 5

#: a vertex the surface it faces sees less than this share of is on a sharp
#: edge: its mean penetration is taken on the share seen (:func:`measure`)
RIM = 0.1


@dataclass
class BodyJump:
    """What one body's jumps need from its last resolved cycle, for the
    vertices ``index`` that touched or can touch (the others do not wear)."""

    index: np.ndarray        # (k,) int64 the vertices (active, or worn in the cycle)
    alpha: np.ndarray        # (k,) wear per cycle per unit of ``mean`` (1 / cycle)
    depth: np.ndarray        # (k,) penetration at the end of the cycle (m)
    mean: np.ndarray         # (k,) penetration while in contact in the cycle (m): the
                             # force-weighted mean force over the stiffness; 0 untouched
    now: np.ndarray          # (k,) that penetration as of the end of the cycle (m): ``mean``
                             # plus half the change of the penetration at the cycle's
                             # phase over the cycle; the end gap for an untouched vertex
    normal: np.ndarray       # (k, 3) normal of the surface the depth is on (world)
    stiffness: np.ndarray    # (k,) normal stiffness there (N/m)
    member: np.ndarray       # (k,) bool: in the balance (touching at the end, or may)
    touched: np.ndarray      # (k,) bool: touched during the cycle but not at its end
    beta: np.ndarray         # (k,) free axis along the normal (0 without a free axis)
    load: float              # load the contacts carry along the free axis (N)
    guided: bool
    rest: float = 0.0        # the balance without a jump (m): moves are from it
    gamma: np.ndarray = None  # (k,) worn counter-parts' wear under it per cycle per unit
                              # of ``mean`` (1 / cycle), or None
    counter: np.ndarray = None  # (k,) that wear per cycle (m), or None
    feet: dict = None        # per worn counter-part j: the barycentric weights (k, 3) of
                             # each vertex's foot at the cycle's end on the face it is
                             # over and that face's corners (k, 3) (rows of vertices over
                             # none: zero), for :func:`counter_factors`


def start_depths(model, body, s):
    """(n,) penetration of each vertex within reach of a surface at the
    start of a cycle (:func:`contact_geometry`; nan for the others), for
    :func:`measure` at its end."""
    out = np.full(len(s.wear_depth), np.nan)
    depth, _, _ = contact_geometry(model, body, s, s.active)
    out[s.active] = np.where(np.isfinite(depth), depth, np.nan)
    return out


def measure(model, body, s, rate, start=None, window=1):
    """The :class:`BodyJump` of ``body`` after ``window`` resolved cycles
    in which it wore ``rate`` (n,) per cycle (m), ``s.load`` holding their
    sums of normal forces and their squares and ``start`` (n,) the
    penetrations at their start (:func:`start_depths`; None: unknown). (A
    measurement averages over more than one cycle where single cycles
    disagree; "the cycle" below is then the window.)

    The penetration while in contact is measured over the cycle, half a
    cycle before its end, and from each step's force, before that step's
    wear: the jump starts from it put after the wear and moved on by half
    its change over the cycle, seen at the same phase (start and end). In a
    steady contact (a pin, a fretting ball) that is the end penetration; in
    one that sweeps over the vertex (a gear flank) the kinematics are
    periodic and only the wear and moves change it."""
    chosen = rate > 0.0
    chosen[s.active] = True
    index = np.flatnonzero(chosen).astype(np.int64)    # sorted, as a union of both
    rate = rate[index]
    depth, normal, stiffness = contact_geometry(model, body, s, index)
    force, square = s.load[0, index], s.load[1, index]
    # the penetration while in contact: the force-weighted mean force over
    # the stiffness (the steps out of contact weigh nothing), the one at the
    # end of the cycle for a vertex pressed then (as its depth is), else that
    # of its whole area: a flank out of mesh or a disc's track away from
    # the pin may face another surface then, or one at a slant. But where
    # the surface it faces sees under a tenth of its area, that area lies
    # mostly on faces that cannot touch (the end face of a pad, at its rim:
    # taken whole, its mean penetration came out a hundred times too small
    # and its jumps' error as large): the part seen is the part that touched
    whole = model.law[5] + model.law[6] * body.area_vectors[index, 3]
    edge = (stiffness > 0.0) & (stiffness < RIM * whole)
    contact = np.where((depth > 0.0) & (stiffness > 0.0) | edge, stiffness, whole)
    touching = (contact > 0.0) & (force > 0.0)
    mean = np.zeros(len(index))
    mean[touching] = square[touching] / force[touching] / contact[touching]
    wearing = (rate > 0.0) & (mean > 0.0)
    alpha = np.zeros(len(rate))
    alpha[wearing] = rate[wearing] / mean[wearing]
    # untouched vertices the move may bring into contact: the contact's mean
    # alpha per unit penetration (their own is unknown)
    fresh = (mean <= 0.0) & np.isfinite(depth)
    area = body.area_vectors[index, 3]
    if wearing.any():
        alpha[fresh] = (rate[wearing] @ area[wearing]) / (mean[wearing] @ area[wearing])
    member = ((depth > 0.0) | fresh) & np.isfinite(depth) & (stiffness > 0.0)
    touched = ~member & (mean > 0.0)
    # as of the end of the cycle: a step's force is that of the penetration
    # before its wear, the depths are after it; the force-weighted wear of a
    # step, rate * sum F^2 / (sum F)^2 (wear in proportion to the force),
    # puts the mean on the depths' footing (a steady contact's equals its depth)
    now = np.where(mean > 0.0, mean, np.where(np.isfinite(depth), depth, 0.0))
    now[touching] -= window * rate[touching] * square[touching] / force[touching] ** 2
    if start is not None:
        change = np.where(np.isfinite(depth), depth, np.nan) - start[index]
        known = (mean > 0.0) & np.isfinite(change)
        now[known] += 0.5 * change[known]
    motion = body.motion
    guided = isinstance(motion, (BalancedMotion, GuidedMotion)) and model.slots > 0
    rider = isinstance(motion, MechanismMotion) and model.slots > 0
    turning = isinstance(motion, TurningMotion) and model.slots > 0
    beta, carried = np.zeros(len(rate)), 0.0
    if guided or rider or turning:
        # a vertex that faces no surface at the end of the cycle was pressed,
        # while in contact, against its own outward normal
        facing = np.where(np.any(normal != 0.0, axis=1)[:, None], normal,
                          -(body.area_vectors[index, 0:3] @ quaternion_matrix(s.pose[3:7]).T)
                          / np.maximum(body.area_vectors[index, 3:4], 1e-300))
        # and one touched in the cycle but not at its end, along the
        # force-weighted mean of the normals that pressed it then: where it
        # will be pressed again, its end place being anywhere (a flank of a
        # turning gear, half a turn from its mate, faced the way it is
        # turned to: the move along the line of centres took off its
        # penetration as much as that direction's share of the axis,
        # different on each flank, and after 10^5 revolutions the two flanks
        # of a tooth were worn up to 12 % of the deepest apart). A unit
        # vector where all pressed one way, shorter where they disagree (a
        # roller pressed from both sides: the move takes off as much as it
        # adds)
        if len(s.load) >= LOAD_ROWS:
            along = touched & (force > 0.0)
            facing[along] = s.load[2:5, index[along]].T / force[along, None]
    if guided:
        beta = facing @ motion.axis
        carried = (motion.carried if isinstance(motion, BalancedMotion)
                else -float(motion.params[19:22] @ motion.axis) / motion.params[0])
    elif turning:
        # a body turning under a torque: its move is a turn, the penetration
        # each vertex loses per radian n . (a x r) (docs/model.md,
        # "Quasi-static mode"); the move is counted as the arc at the
        # body's largest lever (m, beta and the torque over that lever), so
        # the jump's bounds on moves read it as a length
        guided = True
        lever = motion.lever(s.vertices, s.pose)
        x = s.pose[0:3] + s.vertices[index] @ quaternion_matrix(s.pose[3:7]).T
        arm = np.cross(motion.turn_axis, x - motion.center_of(s.pose))
        beta = np.einsum("ij,ij->i", facing, arm) / lever
        carried = motion.carried / lever
        motion.jump_lever = lever
    elif rider:
        # a part on a mechanism body: the mechanism holds its contact force
        # at the end of the cycle (a press, a joint's reaction) while it
        # wears, as a guided body's load along the direction of that force
        pressed = (depth > 0.0) & np.isfinite(depth) & (stiffness > 0.0)
        total = (stiffness[pressed] * depth[pressed]) @ facing[pressed]
        carried = float(np.linalg.norm(total))
        if carried > 0.0:
            guided = True
            beta = facing @ (total / carried)
    m = BodyJump(index, alpha, np.where(np.isfinite(depth), depth, 0.0), mean, now, normal,
                 stiffness, member, touched, beta, carried, guided)
    m.rest = _step(m, 0.0, m.depth, m.now)[1]
    return m


def _step(m, jump, depth, now):
    """One backward-Euler step of ``jump`` cycles from the penetrations at
    the end of the cycle ``depth`` and while in contact ``now``
    (:attr:`BodyJump.now`): (n,) wear, the move z and (n,) the penetration
    the step takes off (its own and the counter-parts' wear), by
    :func:`meshwear.kernels.balance.implicit_step`. The balance solves for
    a member's end penetration after the step, ``(ahead - beta z) relief``;
    a touched vertex's is relieved alike (the body sinks as a disc's whole
    track wears, and presses it again)."""
    gamma = m.gamma if m.gamma is not None else np.zeros(len(m.alpha))
    wear, z, taken = implicit_step(float(jump), m.alpha, gamma, m.member, m.touched, m.beta,
                                   m.stiffness, depth, now, float(m.load), bool(m.guided))
    return wear, float(z), taken


def compile_kernels():
    """Compile (or load from numba's cache) the implicit step's kernel, as
    a jump calls it, before anything is timed: ``meshwear check``'s trial
    counted its first compile as the run's cost."""
    one, yes = np.ones(1), np.ones(1, dtype=bool)
    implicit_step(1.0, one, one, yes, ~yes, one, one, one, one, 1.0, True)


def _steps(m, jump, n):
    """``n`` backward-Euler steps of ``jump / n`` cycles, each from the
    penetrations the one before leaves: (k,) wear and the move z."""
    depth, now = m.depth, m.now
    wear, z = np.zeros(len(depth)), 0.0
    for _ in range(n):
        w, dz, taken = _step(m, jump / n, depth, now)
        # the move and the wear take the same off the penetration at every
        # step in contact
        shift = m.beta * dz + taken
        depth, now = depth - shift, now - shift
        wear, z = wear + w, z + dz
    return wear, z


def single_step(m, jump):
    """One backward-Euler step of ``jump`` cycles: (k,) wear and the move z
    (from the balance without a jump)."""
    wear, z = _steps(m, jump, 1)
    return wear, z - m.rest


def implicit(m, jump):
    """Wear (k,) of the vertices ``m.index``, the body's move along its axis
    (m, from the balance without a jump) and the error estimate (k,) of a
    jump of ``jump`` cycles.

    Backward Euler is first order: the jump as one step, two and four
    differs from the exact by errors in the ratio 4 : 2 : 1, so twice the
    four steps' less the two's (Richardson extrapolation) is second order,
    as is twice the two's less the one's, and the two extrapolations differ
    by three times the error of the first: the jump advances with it and
    that error (as embedded Runge-Kutta pairs advance with the better of
    their two solutions). Its error grows like ``J^3``, so it allows longer jumps
    than the first-order steps' ``J^2``; the extrapolated wear is kept
    within zero and the vertex's four-step wear times two (where a vertex
    leaves the contact within the jump the steps are not smooth)."""
    one, z1 = _steps(m, jump, 1)
    two, z2 = _steps(m, jump, 2)
    four, z4 = _steps(m, jump, 4)
    wear = np.clip(2.0 * four - two, 0.0, 2.0 * four)
    coarse = 2.0 * two - one
    # a vertex touched in the cycle but not at its end wears at most twice
    # the rate it wore then: the move may not press it (:func:`touched_cap`)
    cap = touched_cap(m, jump)
    wear, coarse = np.minimum(wear, cap), np.minimum(coarse, cap)
    return wear, 2.0 * z4 - z2 - m.rest, np.abs(wear - coarse) / 3.0


#: the most a jump may raise the wear per cycle of a vertex touched in the
#: cycle but not at its end, over its measured one (:func:`touched_cap`)
TOUCHED_GROWTH = 2.0


def touched_cap(m, jump):
    """(k,) the most each vertex of body measure ``m`` may wear over a jump
    of ``jump`` cycles: a vertex touched in the cycle but not at its end, not
    in the balance, :data:`TOUCHED_GROWTH` times its measured wear per cycle
    (``alpha_i pbar_i``) times the jump; the others, no limit.

    Such a vertex is pressed where a path of contact ends or a stroke turns,
    and the body's move along its axis need not press it deeper there: it
    may lengthen its contact, or meet the mate where it falls away. Taken as
    deepening its penetration by ``-beta_i z`` at every step it touches, a
    gear pinion's face-end tip corners, touched at 4 nm in one revolution of
    several, were pressed by the whole approach of 1.5 µm over a jump of
    11 000 revolutions: 0.19 µm worn at tolerance 0.01 against 0.04 at 0.003,
    an error growing with the jump that no resolved revolution showed. Its
    relief (its own wear and the counter's under it) still slows it, and a
    rate that rises within that bound (a track touched once a turn whose
    body sinks as it wears, the contact spreading) the jump follows."""
    cap = np.full(len(m.alpha), np.inf)
    cap[m.touched] = TOUCHED_GROWTH * jump * m.alpha[m.touched] * m.mean[m.touched]
    return cap


#: rows of a body's pair log at its first measured cycle, and the most it
#: grows to (a log that overflows is grown for the next cycle; past the
#: most, the jumps take the feet at the cycle's end: :func:`counter_relief`)
LOG_ROWS, LOG_MOST = 1 << 16, 1 << 22


def start_log(s, step, steps):
    """Log the pairs of body state ``s`` from ``step`` (a measured cycle's
    start) on, for ``steps`` steps, with room for the rows the last log
    needed (at first: three per vertex pressed now and step)."""
    needed = int(s.log_count[0])
    if needed == 0 and len(s.active):
        needed = 3 * steps * int((s.normal_force[:, s.active] > 0.0).any(axis=0).sum())
    if len(s.log_index) == 0 or needed > len(s.log_index):
        rows = min(LOG_MOST, max(LOG_ROWS, 1 << int(np.ceil(np.log2(max(1.25 * needed, 1.0))))))
        if rows != len(s.log_index):
            s.log_index = np.zeros((rows, 3), np.int64)
            s.log_value = np.zeros(rows)
    s.log_count[0], s.log_count[1] = 0, 1
    s.log_from = step


def pair_log(s, step):
    """The pairs body state ``s`` logged from ``step`` on (:func:`start_log`),
    and the log stopped: (rows, 3) int64 (per-vertex surface, body vertex,
    counter vertex) and (rows,) the pair's normal force times its weight
    on the counter vertex (N), one row per pair, step and counter vertex;
    None if the log does not hold every pair since ``step`` (not started
    there, or full)."""
    count, logging = int(s.log_count[0]), int(s.log_count[1])
    s.log_count[1] = 0
    if s.log_from != step or logging != 1 or count > len(s.log_index):
        return None
    return s.log_index[:count], s.log_value[:count]


def counter_relief(model, s, m, increments, t, log=None):
    """Set ``m.gamma`` and ``m.counter`` of body measure ``m``: per vertex,
    the wear the worn counter-parts took under it in the cycle (``increments``:
    per per-vertex surface, its (V,) depth increment, or None), and that per
    unit mean penetration. For a vertex in contact at the end of the cycle
    (``t``), that wear interpolated at its foot on the face it is over then;
    for one touched in the cycle but not at its end, with the cycle's
    ``log`` of pairs (:func:`pair_log`), the counter's wear at the points it
    pressed, weighted by its force there (as its mean penetration is). Its
    foot at the cycle's end is wherever it has moved to: a gear's flank
    meets its mate's for a few steps of a revolution, and taken at its foot,
    on whatever face of the mate it was over then (a tooth in mesh) or none
    (the others), the teeth in mesh at the cycle's end wore 2-3 % of the
    deepest less than the others over 10^5 revolutions. Without a log (it
    overflowed), at the foot too."""
    counter = np.zeros(len(m.index))
    m.feet = {}
    logged = None
    if log is not None and m.touched.any():
        logged = np.zeros(len(m.index))
        index, value = log
        n = int(max(m.index.max(initial=-1), index[:, 1].max(initial=-1))) + 1
        for j, increment in enumerate(increments):
            if increment is None:
                continue
            mine = index[:, 0] == j
            vertex, corner, force = index[mine, 1], index[mine, 2], value[mine]
            total = np.bincount(vertex, force, minlength=n)[m.index]
            under = np.bincount(vertex, force * increment[corner], minlength=n)[m.index]
            pressed = total > 0.0
            logged[pressed] += under[pressed] / total[pressed]
    for j, (surface, increment) in enumerate(zip(model.surfaces.per_vertex, increments)):
        if increment is None:
            continue
        face = s.hint[j][m.index]
        on = face >= 0
        if not on.any():
            continue
        weights, corners = surface.face_weights(vertex_feet(s, j, m.index[on]), face[on], t)
        counter[on] += np.einsum("ij,ij->i", weights, increment[corners])
        m.feet[j] = (np.zeros((len(on), 3)), np.zeros((len(on), 3), np.int64))
        m.feet[j][0][on], m.feet[j][1][on] = weights, corners
    if logged is not None:
        counter[m.touched] = logged[m.touched]
    m.counter = counter
    m.gamma = np.where(m.mean > 0.0, counter / np.where(m.mean > 0.0, m.mean, 1.0), 0.0)


def relaxed_share(x):
    """The share (k,) of a rate's departure kept, on average, over a jump
    in which it relaxes at ``x`` (k,) (the jump times its relaxation per
    cycle): ``(1 - e^-x) / x``, 1 at ``x = 0``."""
    x = np.asarray(x, float)
    small = x < 1e-12
    return np.where(small, 1.0, -np.expm1(-x) / np.where(small, 1.0, x))


def settled_rates(rate, stiffness, depth, t, past):
    """(V,) the wear per cycle each counter vertex settles to, the contact's:
    its rate ``rate`` (m per cycle) less the departure the error of its own
    depth makes.

    A vertex of stiffness ``g`` (per cycle, ``stiffness``) that sank by
    ``e`` more than the contact wears ``g e`` less, so between an earlier
    measurement and this one, ``T`` cycles apart, over which its depth at
    the measurements' middles went from ``d0`` to ``depth`` (m) and its rate
    from ``r0`` to ``rate``, ``rate - r0 = -g (depth - d0 - r_c T)`` for a
    settled rate ``r_c`` holding over them:
    ``r_c = (depth - d0 + (rate - r0) / g) / T``, ``g`` the mean of both
    measurements' stiffnesses. ``past``: the earlier measurements, oldest
    first, each ``(time, d0, r0, g0)`` (``t`` and ``time`` their middles,
    cycles); each vertex takes the latest one at least ``1 / g`` cycles
    before (nearer, the rates' scatter over ``g T`` swamps the difference)
    and touched in each one since (``g0 > 0``: where it was not, it was
    deeper than the contact and its rate not linear in its depth). A vertex
    with none keeps its rate. Never below zero."""
    settled = rate.copy()
    todo = stiffness > 0.0
    for time, d0, r0, g0 in reversed(past):
        if not todo.any():
            break
        cycles = t - time
        g = 0.5 * (stiffness + g0)
        use = todo & (g0 > 0.0) & (g * cycles >= 1.0)
        settled[use] = (depth[use] - d0[use] + (rate[use] - r0[use]) / g[use]) / cycles
        todo &= ~use & (g0 > 0.0)
    return np.maximum(settled, 0.0)


#: a counter vertex whose bodies over it at the cycle's end wear less than
#: this fraction of what they wear under the most worn one (a body vertex at
#: the edge of the contact) takes the relief of the nearest one they wear
#: more: its factor is that of a vertex barely in contact, whose jumped wear
#: over its rate is anything (on the gear pair's wheel one of 3.5e-8 of the
#: most had 2.89, and the eleven teeth whose nearest covered vertex it was
#: wore 2.89 times their rate over a jump of 1 023 revolutions)
HELD = 1e-3


def counter_factors(model, state, measures, results, rates, jump, increments, t, stiffness=None,
                    settled=None):
    """Per worn counter-part ``j`` (``increments[j]``: its (V,) wear in the
    resolved cycle, or None), the factor (V,) by which the implicit jump
    relieves its wear over ``jump`` cycles, and the relative error (V,) of
    that wear: the body vertices' own factors (their jumped wear over ``jump``
    times their wear in the cycle) and error estimates carried to the counter
    vertices under them, weighted by each vertex's own wear in the cycle (the
    contact's) and its barycentric weights on the face it is over at ``t``
    (the end of the cycle). The same contact wears both, so the pressure the
    jump relieves relieves the counter's wear as the body's; a counter vertex
    the bodies wore but are not over at ``t``, or barely wear there
    (:data:`HELD`), takes the factor of the nearest one they are over and
    wear, and one they did not wear keeps its rate (factor 1).

    A counter vertex also relaxes on its own, faster than the contact where
    its stiffness ``g`` (``stiffness[j]``, per cycle: how much its wear falls
    per unit of its own depth, summed in the wear kernel) is high: a flat's
    vertex just past a pad's rim, worn by the rim alone. Jumped at its
    measured rate, the error of its depth that rate carries overshoots, and
    the next jump undershoots (its rates alternate). So the part of its rate
    off the rate it settles to (``settled[j]``, :func:`settled_rates`)
    relaxes over the jump as a departure relaxing at ``g`` does
    (:func:`relaxed_share`), the settled rate taking the contact's relief
    (docs/model.md, "Long durations")."""
    out = []
    for j, (surface, increment) in enumerate(zip(model.surfaces.per_vertex, increments)):
        if increment is None:
            out.append(None)
            continue
        weight = np.zeros(len(increment))
        relief = np.zeros(len(increment))
        error = np.zeros(len(increment))
        for s, m, (wear, _, estimate), rate in zip(state.bodies, measures, results, rates):
            index = m.index
            face = s.hint[j][index]
            on = (face >= 0) & (m.counter > 0.0) & (rate[index] > 0.0)
            if not on.any():
                continue
            own = rate[index[on]] * jump
            factor = wear[index[on]] / own
            relative = estimate[index[on]] / own
            if m.feet is not None and j in m.feet:
                # (the feet counter_relief found at the same state)
                weights, corners = m.feet[j][0][on], m.feet[j][1][on]
            else:
                weights, corners = surface.face_weights(vertex_feet(s, j, index[on]), face[on],
                                                        t)
            # each vertex weighs by its own wear in the cycle, which the same
            # contact gave the counter too (by the counter's wear under it, a
            # vertex that barely wore but jumps far, one just entering the
            # contact, carried its factor to the counter's whole wear there:
            # the gear pair's wheel wore twice the pinion's volume)
            share = weights * own[:, None]
            # (summed corner by corner, in order, as np.add.at would: bincount
            # adds in its input's order)
            at = corners.T.ravel()
            for total, values in ((weight, share), (relief, share * factor[:, None]),
                                  (error, share * relative[:, None])):
                total += np.bincount(at, values.T.ravel(), minlength=len(total))
        covered = weight > 0.0
        factor = np.ones(len(increment))
        factor[covered] = relief[covered] / weight[covered]
        relative = np.zeros(len(increment))
        relative[covered] = error[covered] / weight[covered]
        # a vertex the bodies wore during the cycle but are not over at its
        # end (the ends of a stroke, a track behind a pin) was worn by the
        # same contact: it takes the relief of the nearest one they are over
        # (left at its cycle's rate, it outwore its neighbours every jump,
        # and the next cycles relaxed that as a burst of noise), and so does
        # one they are over but barely wear there (:data:`HELD`)
        held = weight >= HELD * weight.max() if covered.any() else covered
        swept = ~held & (increment > 0.0)
        if swept.any() and held.any():
            from scipy.spatial import cKDTree

            where = surface.reference_vertices
            _, nearest = cKDTree(where[held]).query(where[swept])
            factor[swept] = factor[held][nearest]
            relative[swept] = relative[held][nearest]
        own = None if stiffness is None else stiffness[j]
        target = None if settled is None else settled[j]
        if own is not None and target is not None and len(target) == len(increment):
            stiff = (increment > 0.0) & (own > 0.0)
            share = relaxed_share(jump * own[stiff])
            rate = increment[stiff]
            # the jump wears it J (f r_c + phi (r - r_c)): the contact's
            # relief f for the rate it settles to, its own relaxation for the
            # departure
            settle = target[stiff] / rate
            factor[stiff] = np.maximum(factor[stiff] * settle + share * (1.0 - settle), 0.0)
        out.append((factor, relative))
    return out
