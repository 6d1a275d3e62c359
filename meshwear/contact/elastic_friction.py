"""The half-space patch's friction: the tangential problem of a step (docs/model.md, "In a run").

After the normal solve (:mod:`meshwear.contact.elastic`), the loaded
vertices' slip decides the friction. A translation along the grid's first
axis, the same at every point (a fretting stroke, a straight slide), is
Cattaneo-Mindlin partial slip with Mindlin and Deresiewicz's reversals,
solved at the stroke's displacement
(:func:`meshwear.contact.halfspace.shear_at_shift`) on the window of
pressed cells (merged f x f where wider than
:data:`meshwear.contact.elastic_patch.SHEAR_CELLS`), a periodic stroke's
solves cached on an unchanged pressure: stick and slip per cell, each
cell's slip and friction energy from its shear and the relative
displacement of the surfaces, read at the vertices
(:mod:`meshwear.contact.cellfields`). Any other relative motion (a turning
disc, a circle) slides: Coulomb at every vertex, ``mu N_i`` against its
slip velocity.
"""

import numpy as np

from . import halfspace
from .cellfields import signed_to_vertices, to_vertices
from ..kernels.contact import SLIP, STICK

#: the relative tolerance of the tangential conjugate-gradient solve (the
#: traction's change in an iteration), taken at every step of a partial
#: slip from the last step's (Mindlin's force and Mindlin-Deresiewicz's
#: energy agree to 1e-4 and 0.3 % at this and at 1e-8 alike: the
#: validation case mindlin_fretting, tests/cases.py)
SHEAR_TOLERANCE = 1e-4
#: a slip velocity the same at every loaded vertex and along the grid's first
#: axis to this fraction of its speed is a translation: Cattaneo-Mindlin
UNIFORM = 1e-3
#: tangential solves kept for a periodic stroke to repeat
CACHE_STEPS = 1024
#: a vertex whose four cells around its point hold less than this share of
#: slipping cells (of its pressed ones) dissipates nothing: its point sits
#: on a stick cell, a slipping one touching the four's square at a corner
SLIP_READING = 0.01
#: two turning points whose shears differ by less than this fraction of the
#: largest mu p are one (the solves' own tolerance is SHEAR_TOLERANCE)
TURN_MATCH = 1e-3


def _tangential(model, patch, F, slip_v, mu, at_rest):
    """Friction energy (J), force (k, 3, N, on the body) and contact state
    of the patch's loaded vertices (their forces ``F``, slip velocities
    ``slip_v``) in the step: Cattaneo-Mindlin on the grid for a
    uniform slip along its first axis, else Coulomb at every vertex."""
    B, T = patch.interpolation_loaded, patch.transposed_loaded
    areas, area_cell = patch.areas[patch.loaded], patch.grid.cell_area
    if not len(F) or at_rest:
        state = np.full(len(F), STICK, np.int8)
        friction = np.zeros((len(F), 3))
        if patch.shear is not None and len(F):
            friction = -signed_to_vertices(B, areas, T, patch.shear.ravel(), area_cell)[:, None] \
                * patch.e1
        return np.zeros(len(F)), friction, state
    mean_v = slip_v.mean(axis=0)
    speed = float(np.linalg.norm(mean_v))
    # (within UNIFORM of the speed: a worn counter's faces tilt by its wear
    # slopes, and the slip in each one's plane differs by as much)
    uniform = np.abs(slip_v - mean_v).max() <= UNIFORM * speed + 1e-300
    along = abs(mean_v @ patch.e2) <= UNIFORM * speed + 1e-300
    if not (uniform and along and mu > 0.0):
        return _coulomb(model, patch, F, slip_v, mu)
    patch.sliding = False
    move = float(mean_v @ patch.e1) * model.dt
    limit = mu * patch.pressure
    q_old = patch.shear if patch.shear is not None else np.zeros(limit.shape)
    energy = np.zeros(len(F))
    if move == 0.0:
        q = np.clip(q_old, -limit, limit)
        stick = (patch.pressure > 0.0) & (np.abs(q) < limit * (1.0 - 1e-9))
    else:
        q, stick, cell_energy = _partial_slip(patch, move, limit, q_old, mu, area_cell)
    patch.shear = q
    friction = -signed_to_vertices(B, areas, T, q.ravel(), area_cell)[:, None] * patch.e1
    # the state at each vertex's point: stick where the stick cells around
    # it weigh more than half of the pressed ones
    stuck = B @ stick.ravel().astype(float)
    share = B @ (patch.pressure > 0.0).ravel().astype(float)
    state = np.where(stuck > 0.5 * share, STICK, SLIP).astype(np.int8)
    if move != 0.0:
        # each vertex's energy: the cells' energy density at its point times
        # its area, the cells' total kept (the wear reads a vertex's energy
        # over its area: the density at its point). A vertex on the stick
        # zone's rim reads some (its area straddles the rim), whatever its
        # state; one whose reading holds slipping cells only at a corner of
        # its four does not (the majority's state there instead changed
        # the fretting example's scar by a tenth in 2000 cycles and pitted
        # its inner flank: docs/model.md, "In a run")
        density = cell_energy.ravel() / area_cell
        slipping = np.flatnonzero(share - stuck >= SLIP_READING * share)
        energy[slipping] = to_vertices(B[slipping], areas[slipping], T[slipping], density,
                                        area_cell)
        if not energy.any():
            # a slip zone no slipping vertex reads: its energy goes to the
            # vertices around it
            energy = to_vertices(B, areas, T, density, area_cell)
    return energy, friction, state


def _coulomb(model, patch, F, slip_v, mu):
    """Friction energy, force and contact state of the loaded vertices of
    :func:`_tangential` in a slide that is not a translation along the
    grid's first axis: Coulomb at every vertex, ``mu N_i`` against its own
    slip velocity; the patch forgets its Mindlin state."""
    # sliding: Coulomb at every vertex against its own slip velocity
    patch.sliding = True
    patch.shear, patch.direction, patch.gross = None, 0.0, False
    speeds = np.linalg.norm(slip_v, axis=1)
    moving = speeds > 0.0
    friction = np.zeros((len(F), 3))
    friction[moving] = -(mu * F[moving] / speeds[moving])[:, None] * slip_v[moving]
    state = np.where(moving, SLIP, STICK).astype(np.int8)
    return mu * F * speeds * model.dt, friction, state


def _partial_slip(patch, move, limit, q_old, mu, area_cell):
    """Cattaneo-Mindlin on the grid for a step of the stroke by ``move``
    (m, along the grid's first axis; ``limit``: mu p per cell, ``q_old``:
    the last step's shear): the branch of Mindlin and Deresiewicz it is on
    (a turn starts a new one), the shift, and the cells' shear, stick and
    friction energy (J): repeated from the cache where a periodic stroke
    met this step before, every cell at its limit in a gross slip that
    goes on, else solved (:func:`_solve_shear`)."""
    direction = 1.0 if move > 0.0 else -1.0
    if patch.cache_pressure is not patch.pressure:
        # a new pressure: what was solved on the old one does not repeat
        patch.cache, patch.cache_pressure = {}, patch.pressure
        patch.key = patch.turn_key = ("fresh", patch.solves, patch.shift)
    if direction != patch.direction:
        patch.turn, patch.turn_shift = np.clip(q_old, -limit, limit), patch.shift
        patch.direction, patch.reserve, patch.gross = direction, None, False
        # a turning point met before (the same shear at the same shift:
        # Mindlin and Deresiewicz's loop closes after its first cycle)
        # takes that one's place in the cache
        patch.turn_key = patch.key
        seen = patch.cache.setdefault(("turn", round(patch.shift * 1e15)), [])
        close = TURN_MATCH * float(limit.max())
        for key_seen, q_seen in seen:
            if np.abs(q_seen - patch.turn).max() <= close:
                patch.turn_key = patch.key = key_seen
                break
        else:
            seen.append((patch.key, patch.turn))
    patch.shift += move
    # a periodic stroke on an unchanged pressure repeats its steps: the
    # shear of a branch depends on its turning point and the shift only
    # (and each cell's energy on the step's start as well)
    key = (patch.key, direction, round(patch.shift * 1e15))
    hit = patch.cache.get(key)
    if hit is not None:
        q, stick, cell_energy, patch.key = hit
        patch.reserve = None
    elif patch.gross and patch.gross_pressure is patch.pressure:
        # still sliding the same way on the same pressure: every cell
        # stays at its limit and slips by the whole move
        q = direction * limit
        stick = np.zeros(q.shape, bool)
        cell_energy = limit * abs(move) * area_cell
    else:
        q, stick, cell_energy = _solve_shear(patch, move, limit, q_old, mu)
    if hit is None:
        new_key = (patch.turn_key, round(patch.shift * 1e15))
        if len(patch.cache) >= CACHE_STEPS:
            patch.cache.clear()
        patch.cache[key] = (q, stick, cell_energy, new_key)
        patch.key = new_key
    return q, stick, cell_energy


def _solve_shear(patch, move, limit, q_old, mu):
    """The tangential problem of :func:`_partial_slip` solved at the
    stroke's shift (:func:`meshwear.contact.halfspace.shear_at_shift`) on the
    window of pressed cells, merged f x f where it is wide, from the
    branch's last stick reserve: each cell's shear, stick and friction
    energy (J), on the whole grid."""
    patch.turn = np.clip(patch.turn, -limit, limit)
    # on the cells around the contact only (the shear is zero
    # elsewhere), merged f x f where the window is wide
    win, grid, f = patch.window, patch.shear_grid, patch.shear_factor
    p_win = patch.pressure[win]
    p_c = _merge(p_win, f)
    start = patch.reserve
    last = patch.extra.get("last_reserve")
    if start is not None and last is not None and last[0].shape == start.shape:
        # the reserve moves on smoothly along a branch: extrapolated
        # from the last two steps, the solve starts nearer its answer
        start = np.maximum(start + (start - last[0]) * (move / last[1]), 0.0)
    q_c, stick_c, w = halfspace.shear_at_shift(
        grid, p_c, mu, patch.shift, _merge(patch.turn[win], f), patch.turn_shift,
        start=start, tol=SHEAR_TOLERANCE)
    patch.extra["last_reserve"] = (patch.reserve, move) if patch.reserve is not None \
        else None
    patch.reserve = w
    # each cell's slip: the stroke less the surfaces' elastic stretch
    # (a slipping cell's shear is its limit, mu p, all the step)
    q_old_c = _merge(np.clip(q_old, -limit, limit)[win], f)
    slip = move - grid.convolve(q_c - q_old_c, "shear")
    energy_c = np.where(stick_c, 0.0, np.maximum(q_c * slip, 0.0)) * grid.cell_area
    # back to the cells, in proportion to their pressure (f = 1: as is)
    q_win, stick_win = _split(q_c, p_c, p_win, f), _spread_cells(stick_c, f) & (p_win > 0.0)
    q = np.zeros(limit.shape)
    q[win] = q_win
    stick = np.zeros(q.shape, bool)
    stick[win] = stick_win
    cell_energy = np.zeros(limit.shape)
    cell_energy[win] = _split(energy_c / (f * f), p_c, p_win, f)
    patch.gross = not stick_c.any()
    patch.gross_pressure = patch.pressure
    return q, stick, cell_energy


def _merge(values, f):
    """The means of ``values`` (a window) over blocks of f x f cells."""
    if f == 1:
        return values
    a, b = values.shape
    return values.reshape(a // f, f, b // f, f).mean(axis=(1, 3))


def _spread_cells(values, f):
    """Each block's value on its f x f cells."""
    return values if f == 1 else np.repeat(np.repeat(values, f, axis=0), f, axis=1)


def _split(block, pressure_block, pressure, f):
    """A block's mean (a shear, an energy per cell) given to its cells in
    proportion to their pressure: the block's mean kept (``pressure_block``
    is the mean of ``pressure`` over it), a cell's shear within mu times its
    own pressure."""
    if f == 1:
        return block
    share = np.where(pressure_block > 0.0, block / np.where(pressure_block > 0.0,
                                                             pressure_block, 1.0), 0.0)
    return _spread_cells(share, f) * pressure
