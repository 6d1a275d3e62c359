"""The elastic half-space contact model in a run (docs/model.md, "Elastic half-space").

With ``[contact] model = "half-space"`` a quasi-static body's contact
forces come from the elastic solve of :mod:`meshwear.halfspace` instead of
a spring per vertex. At each step, for each body and its counter-surface:

1. Gaps. The body is placed on its path; each vertex facing the surface
   gets its gap ``h_i`` along the contact normal (negative: the rigid
   bodies overlap), as the Winkler kernel measures it.
2. The patch. The vertices within a band of gaps above the smallest span a
   regular grid in the tangent plane (cells of about one vertex's
   contact area, axes fixed to the body, the first along its path's
   stroke). The vertices' Delaunay triangles interpolate the gaps onto the
   cells, linearly. Back on the vertices (:mod:`meshwear.cellfields`),
   the grid's fields are read at each vertex's point, bilinearly between
   the four cell centres around it: its pressure; its force is that
   pressure times its contact area, all scaled alike so that the vertices
   carry exactly the solved load (the same for the shear and the friction
   energy).
3. Normal. A guided body's load gives the load-controlled solve, its
   approach the body's move along its free axis (the load balance); a
   prescribed or fixed body's overlap gives the displacement-controlled
   one. The solve starts from the last pressure. It is skipped while the
   gaps have changed by less than :data:`RESOLVE` of the elastic approach
   since it was last taken (the body's rigid moves excepted): a body
   sliding on a plane changes its gaps only by its wear.
4. Tangential. A translation along the grid's first axis, the same at
   every point (a fretting stroke, a straight slide), is Cattaneo-Mindlin
   partial slip with Mindlin and Deresiewicz's reversals, solved at the
   stroke's displacement (:func:`meshwear.halfspace.shear_at_shift`) on the
   window of pressed cells (merged f x f where wider than
   :data:`SHEAR_CELLS`): stick and slip per cell, each cell's slip and
   friction energy from its shear and the relative displacement of the
   surfaces. Any other relative
   motion (a turning disc, a circle) slides: Coulomb at every vertex,
   ``mu N_i`` against its slip velocity.
5. Wear. Each vertex's energy (the cells' energy density at its point
   times its area, scaled to the cells' total), load and slip go through
   the wear law (:mod:`meshwear.kernels.laws`)
   and the vertex moves as in the Winkler kernel.

The state of the solve (:class:`Patch`) is a cache: a run resumed from a
checkpoint solves it again (a fretting cycle then restarts its
Mindlin-Deresiewicz branch from the shear the wear left).
"""

from dataclasses import dataclass, field

import numpy as np
from scipy import sparse
from scipy.spatial import Delaunay, QhullError
from threadpoolctl import threadpool_limits

from . import halfspace
from .cellfields import bilinear, signed_to_vertices, to_vertices
from ..kernels.contact import FORCE as FORCE_SLOT
from ..kernels.contact import NO_CONTACT, SLIP, STICK
from ..kernels.elastic import gaps
from ..kernels.laws import LAWS, name_of
from ..kernels.rigid import OSCILLATION, STEADY
from ..motion.motions import BalancedMotion, _perpendicular
from ..surfaces.base import quaternion_matrix

#: the normal problem is solved again when the gaps changed (rigid moves
#: aside) by more than this fraction of the elastic approach
RESOLVE = 1e-3
#: relative tolerance of the conjugate-gradient solves (the traction's
#: change in an iteration): the normal one, taken seldom ...
TOLERANCE = 1e-8
#: ... and the tangential one, taken at every step of a partial slip from
#: the last step's (Mindlin's force and Mindlin-Deresiewicz's energy agree
#: to 1e-4 and 0.3 % at this and at 1e-8 alike: the validation case
#: mindlin_fretting, tests/cases.py)
SHEAR_TOLERANCE = 1e-4
#: the band of gaps the first patch spans, in vertices of smallest gap
FIRST_BAND_VERTICES = 64
#: cells per side at most; a larger patch gets coarser cells
MAX_CELLS = 192
#: the band of gaps a patch spans is the elastic approach over this (the
#: contact lies where the gap is below the approach; the rest is margin) ...
BAND_USE = 0.7
#: ... and a patch is built again when the approach passes this fraction of
#: its band, or falls below the next
GROW_BAND, SHRINK_BAND = 0.9, 0.3
#: a slip velocity the same at every loaded vertex and along the grid's first
#: axis to this fraction of its speed is a translation: Cattaneo-Mindlin
UNIFORM = 1e-3
#: the tangential problem is solved on at most about this many cells a side:
#: a wider window merges its cells f x f (the normal one keeps them all)
SHEAR_CELLS = 64
#: tangential solves kept for a periodic stroke to repeat
CACHE_STEPS = 1024
#: a vertex whose four cells around its point hold less than this share of
#: slipping cells (of its pressed ones) dissipates nothing: its point sits
#: on a stick cell, a slipping one touching the four's square at a corner
SLIP_READING = 0.01
#: two turning points whose shears differ by less than this fraction of the
#: largest mu p are one (the solves' own tolerance is SHEAR_TOLERANCE)
TURN_MATCH = 1e-3
#: contact normals of a patch spreading wider than this (rad) are not a
#: half-space contact: check warns ...
WARN_SPREAD = 0.1
#: ... and the run refuses beyond this
REFUSE_SPREAD = 0.5


@dataclass(frozen=True)
class HalfSpace:
    """The model's elastic constants: Young's moduli (Pa) and Poisson's
    ratios of the worn bodies and of the counter-surfaces, and the friction
    coefficient."""

    youngs: tuple
    poisson: tuple
    friction: float

    @property
    def modulus(self):
        """The contact modulus E* (Pa)."""
        return halfspace.contact_modulus(self.youngs, self.poisson)


@dataclass(eq=False)
class Patch:
    """One body's solve, kept from step to step (:mod:`meshwear.elastic`)."""

    e1: np.ndarray                       # (3,) world: the grid's first axis
    e2: np.ndarray
    normal: np.ndarray                   # (3,) world: the contact normal
    band: float = 0.0                    # m: gaps up to min + band are in the patch
    grid: object = None
    origin: np.ndarray = None            # (2,) the first cell's centre (m)
    index: np.ndarray = None             # (k,) the vertices the triangles use
    coords: np.ndarray = None            # (k, 2) their tangent coordinates (m)
    weights: object = None               # sparse (cells, k): vertex gaps -> cells
    interpolation: object = None         # sparse (k, cells): cells -> each vertex's point
    areas: np.ndarray = None             # (k,) contact areas at the last normal solve (m^2)
    point_pressure: np.ndarray = None    # (k,) the pressure at each vertex's point (Pa)
    allowed: np.ndarray = None           # cells inside the triangles
    heights: np.ndarray = None           # (k,) the gaps at the last normal solve
    approach: float = 0.0                # m: the last solve's approach on those gaps
    pressure: np.ndarray = None          # cells (Pa)
    forces: np.ndarray = None            # (k,) N
    spread: float = 0.0                  # rad: the contact normals' spread
    solves: int = 0
    iterations: int = 0
    # Mindlin's state
    shift: float = 0.0                   # m: the stroke so far
    shear: np.ndarray = None             # cells (Pa), along e1
    turn: np.ndarray = None              # the shear at the branch's turning point
    turn_shift: float = 0.0
    direction: float = 0.0               # +1, -1: the branch's; 0: none yet
    reserve: np.ndarray = None           # the branch's last stick reserve (a warm start)
    gross: bool = False                  # the last step slipped everywhere ...
    gross_pressure: np.ndarray = None    # ... on this pressure
    where: np.ndarray = None             # the patch's vertices' positions in the active set
    outside: np.ndarray = None           # the active set's other positions
    transposed: object = None            # weights.T, row-major
    loaded: np.ndarray = None            # the patch's vertices that carry load ...
    transposed_loaded: object = None     # ... and their rows of transposed,
    interpolation_loaded: object = None  # ... of interpolation
    written: np.ndarray = None           # the vertices the last step gave a contact
    counter: tuple = None                # (vertices, force): what a worn counter wears by
    window: tuple = None                 # the cells the tangential problem is solved on
    shear_grid: object = None            # the grid of that window ...
    shear_factor: int = 1                # ... its cells f x f of the patch's
    sliding: bool = False
    # the tangential solves of this pressure, by the step they took (a
    # periodic stroke repeats them)
    cache: dict = field(default_factory=dict)
    cache_pressure: np.ndarray = None
    key: tuple = None                    # the shear's place in the cache ...
    turn_key: tuple = None               # ... and its branch's turning point's
    extra: dict = field(default_factory=dict)


class PatchError(RuntimeError):
    """A contact the half-space model cannot take (too conforming, no
    normal along the load)."""


def _stroke(motion):
    """The direction (3,) of a body's path's first oscillation or steady
    velocity, or None."""
    for row in motion.path.terms:
        if int(row[0]) in (OSCILLATION, STEADY) and np.linalg.norm(row[1:4]) > 0.0:
            return np.asarray(row[1:4], float) / np.linalg.norm(row[1:4])
    return None


def pair_geometry(model, body, s, active):
    """For the ``active`` vertices (k,) against the one counter-surface:
    gap, normal, contact area, offset and velocity relative to the
    surface (:func:`meshwear.kernels.elastic.gaps`)."""
    k = len(active)
    gap, area = np.empty(k), np.empty(k)
    n, r, velocity = np.empty((k, 3)), np.empty((k, 3)), np.empty((k, 3))
    gaps(s.vertices, s.pose, model.planes, s.vertex_planes, active, body.area_vectors, gap, n,
         area, r, velocity)
    return gap, n, area, r, velocity


def _build_patch(patch, active, gap, r, area, hmin):
    """Grid and interpolation weights over the vertices whose gap is within
    the band, and the vertices whose triangles cover the grid's box;
    returns their positions in ``active``."""
    e1, e2 = patch.e1, patch.e2
    near = np.flatnonzero(gap - hmin <= 2.0 * patch.band)
    coords = np.column_stack([r[near] @ e1, r[near] @ e2])
    core = gap[near] - hmin <= patch.band
    spacing = float(np.sqrt(np.median(area[near][core])))
    lo, hi = coords[core].min(axis=0) - 2.0 * spacing, coords[core].max(axis=0) + 2.0 * spacing
    # the vertices whose triangles cover the grid's box
    box = np.all((coords >= lo - 3.0 * spacing) & (coords <= hi + 3.0 * spacing), axis=1)
    take, coords = near[box], coords[box]
    cells = np.ceil((hi - lo) / spacing).astype(int)
    if cells.max() > MAX_CELLS:
        spacing *= cells.max() / MAX_CELLS
        cells = np.ceil((hi - lo) / spacing).astype(int)
    cells = np.maximum(cells, 4)
    origin = lo + 0.5 * spacing
    axes = [origin[j] + spacing * np.arange(cells[j]) for j in range(2)]
    cx, cy = np.meshgrid(*axes, indexing="ij")
    centres = np.column_stack([cx.ravel(), cy.ravel()])
    # (scipy's barycentric transforms are a LAPACK call per triangle: with
    # BLAS's threads, each waited for them on a busy machine, seconds for a
    # thousand triangles where one thread takes milliseconds; a run limits
    # them, but check and the first solve at rest come before it)
    with threadpool_limits(limits=1, user_api="blas"):
        try:
            tri = Delaunay(coords)
        except QhullError:
            raise PatchError(f"the contact patch has too few vertices ({len(take)}) to span "
                             "a grid; refine the body (resolution)") from None
        simplex = tri.find_simplex(centres)
        ok = simplex >= 0
        T = tri.transform[simplex[ok]]
    old = patch.extra.get("old")
    patch.grid = halfspace.make_grid(tuple(cells), spacing, patch.extra["youngs"],
                                     patch.extra["poisson"])
    patch.origin = origin
    b = np.einsum("ijk,ik->ij", T[:, :2, :], centres[ok] - T[:, 2, :])
    bary = np.column_stack([b, 1.0 - b.sum(axis=1)])
    rows = np.repeat(np.flatnonzero(ok), 3)
    cols = tri.simplices[simplex[ok]].ravel()
    weights = sparse.csr_matrix((bary.ravel(), (rows, cols)), shape=(len(centres), len(take)))
    patch.index = active[take]
    patch.where = take
    patch.outside = np.setdiff1d(np.arange(len(active)), take, assume_unique=True)
    patch.coords = coords
    patch.weights = weights
    patch.transposed = weights.T.tocsr()
    patch.interpolation = bilinear(coords, origin, spacing, tuple(cells))
    patch.allowed = ok.reshape(cells)
    patch.pressure = None
    if old is not None:
        # the shear history moves to the new cells
        patch.shear, patch.turn = _regrid(patch.shear, patch, old), _regrid(patch.turn, patch, old)
        patch.reserve = None
    return take


def _locate(patch, active, r):
    """The positions in ``active`` of the patch's vertices, or None where
    the active set or the vertices' tangent coordinates changed."""
    where = patch.where
    if where is None or where.max(initial=-1) >= len(active) or not np.array_equal(
            active[where], patch.index):
        where = np.minimum(np.searchsorted(active, patch.index), len(active) - 1)
        if not np.array_equal(active[where], patch.index):
            return None
        patch.where = where
        patch.outside = np.setdiff1d(np.arange(len(active)), where, assume_unique=True)
    # the loaded vertices' drift in the tangent plane (a turning body, wear
    # along the vertex normals) against a thousandth of a cell
    on = patch.loaded if patch.loaded is not None else slice(None)
    rw = r[where[on]]
    drift = max(np.abs(rw @ patch.e1 - patch.coords[on, 0]).max(initial=0.0),
                np.abs(rw @ patch.e2 - patch.coords[on, 1]).max(initial=0.0))
    return where if drift <= 1e-3 * patch.grid.spacing[0] else None


def step(model, body, s, t, before, at_rest=False):
    """One quasi-static step of ``body`` (state ``s``) at ``t`` with the
    elastic half-space, after :func:`meshwear.simulate._quasi_static_step`
    placed it on its path (``before``: its position at the step's start)
    and updated its surfaces: normal and tangential tractions, the load
    balance, wear. Fills the same state arrays as the Winkler kernel. ``at_rest``:
    a step of no duration (the t = 0 state): nothing slips or wears."""
    elastic = model.elastic
    motion = body.motion
    active = s.active
    gap, n, area, r, velocity = pair_geometry(model, body, s, active)
    if at_rest:
        velocity[:] = 0.0
    patch = s.elastic
    if patch is not None and patch.written is not None:
        # the last step's contacts: this step writes its own
        w = patch.written
        s.normal_force[0, w] = 0.0
        s.tangential[0, w, FORCE_SLOT] = 0.0
        s.contact_state[0, w] = NO_CONTACT
        patch.written = None
    s.wrench[:] = 0.0
    balanced = isinstance(motion, BalancedMotion)
    hmin = float(gap.min()) if len(gap) else np.inf
    if not np.isfinite(hmin):
        if balanced:
            raise PatchError(f"body {body.name!r}: no contact carries its load at t = {t:.6g} s")
        return
    if patch is None:
        normal = n[np.argmin(gap)].copy()
        stroke = _stroke(motion)
        e1 = _perpendicular(normal, stroke)
        patch = s.elastic = Patch(e1=e1, e2=np.cross(normal, e1), normal=normal)
        patch.extra.update(youngs=elastic.youngs, poisson=elastic.poisson)
    beta = float(motion.axis @ patch.normal) if balanced else 1.0
    if balanced and beta <= 0.1:
        raise PatchError(f"body {body.name!r}: its free axis is "
                         f"{np.degrees(np.arccos(max(beta, -1.0))):.0f}° from the contact normal; "
                         "the half-space model balances the load along the normal (give "
                         "free_axis along it)")
    load = motion.carried / beta if balanced else None
    shift_move = 0.0
    for _ in range(8):
        take = None if patch.grid is None else _locate(patch, active, r)
        if take is None:
            if patch.grid is not None:
                _drop_grid(patch)
            if patch.band == 0.0:
                finite = gap[np.isfinite(gap)] - hmin
                k = min(FIRST_BAND_VERTICES, len(finite))
                patch.band = 2.0 * float(np.partition(finite, k - 1)[k - 1]) + 1e-30
            take = _build_patch(patch, active, gap, r, area, hmin)
        heights = gap[take]
        if not np.all(np.isfinite(heights)):
            _drop_grid(patch)
            continue
        outside = float(gap[patch.outside].min(initial=np.inf))
        if patch.pressure is not None:
            change = heights - patch.heights
            # a guided body's rigid move along the normal is balanced away
            common = float(np.median(change[patch.loaded])) if balanced else 0.0
            if (np.abs(change - common).max()
                    <= RESOLVE * max(patch.approach - patch.heights.min(), 0.0)
                    and outside > patch.approach + common):
                # the same contact moved rigidly: the approach follows
                shift_move = common
                break
        cell_gap = (patch.weights @ heights).reshape(patch.allowed.shape)
        cell_gap = np.where(patch.allowed, cell_gap, 0.0)
        solution = halfspace.solve(patch.grid, cell_gap, load, mask=patch.allowed,
                                   start=patch.pressure, tol=TOLERANCE,
                                   approach=None if balanced else 0.0)
        patch.solves += 1
        patch.iterations += solution.iterations
        used = solution.approach - hmin
        pressed = solution.traction > 0.0
        if used > GROW_BAND * patch.band or outside <= solution.approach:
            patch.band = used / BAND_USE
            _drop_grid(patch)
            continue
        if pressed.any() and (pressed[0].any() or pressed[-1].any() or pressed[:, 0].any()
                              or pressed[:, -1].any()):
            patch.band *= 2.0
            _drop_grid(patch)
            continue
        if 0.0 < used < SHRINK_BAND * patch.band and patch.solves > 1:
            # the contact shrank well inside its patch: a smaller grid
            patch.band = used / BAND_USE
            _drop_grid(patch)
            continue
        _new_pressure(patch, solution, heights, area[take])
        patch.spread = _spread(body, s, patch, n[take])
        if patch.spread > REFUSE_SPREAD:
            raise PatchError(
                f"body {body.name!r}: its contact spans {np.degrees(patch.spread):.0f}° of "
                f"surface normal at t = {t:.6g} s: a conforming contact (a shaft in a "
                "bushing), not a half-space one; use contact.model = 'winkler'")
        break
    else:
        raise PatchError(f"body {body.name!r}: the half-space patch did not settle at "
                         f"t = {t:.6g} s")
    # from here on, the vertices that carry load only
    on = patch.loaded
    idx = patch.index[on]
    F = patch.forces[on]
    at = take[on]
    approach = patch.approach + shift_move
    velocity = velocity[at]
    if balanced:
        # the load balance: the body approaches by the solve's approach
        z = -approach / beta
        s.pose[0:3] += z * motion.axis
        if not at_rest:
            s.pose[7:10] = (s.pose[0:3] - before) / model.dt
            velocity += (z / model.dt) * motion.axis
    k_area = area[at]
    normal_world = n[at]
    slip_v = velocity - np.einsum("ij,ij->i", velocity, normal_world)[:, None] * normal_world
    energy, friction, state = _tangential(model, patch, F, slip_v, elastic.friction, at_rest)
    # wear: the law on each vertex's energy, load and slip
    mu = elastic.friction
    law = LAWS[name_of(int(model.law[2]))]
    slip_distance = energy / (mu * F) if mu > 0.0 else np.zeros(len(F))
    dw, dv = law.twin(model.law[3], energy, F, slip_distance, np.where(k_area > 0.0, k_area, 1.0))
    worn = dw > 0.0
    if worn.any():
        R = quaternion_matrix(s.pose[3:7])
        if body.wear_direction.shape[0]:
            direction = body.wear_direction[idx[worn]]
        else:
            direction = normal_world[worn] @ R
        s.vertices[idx[worn]] += dw[worn, None] * direction
        s.wear_depth[idx[worn]] += dw[worn]
        s.wear_volume[idx[worn]] += dv[worn]
    s.friction_work[idx] += energy
    # what a worn counter wears by: each vertex's energy as a slip at its
    # speed (the counter's kernel dissipates f N |v| dt in slip)
    speed = np.linalg.norm(slip_v, axis=1)
    moving = (energy > 0.0) & (speed > 0.0) & (mu > 0.0)
    patch.counter = (idx[moving], energy[moving] / (mu * speed[moving] * model.dt))
    s.normal_force[0, idx] = F
    s.tangential[0, idx, FORCE_SLOT] = friction
    s.contact_state[0, idx] = state
    patch.written = idx
    forces = F[:, None] * normal_world + friction
    s.wrench[0:3] = forces.sum(axis=0)
    s.wrench[3:6] = np.cross(r[at], forces).sum(axis=0)
    if s.load.shape[1]:
        s.load[0, idx] += F
        s.load[1, idx] += F * F
        if len(s.load) > 2:
            s.load[2:5, idx] += (F[:, None] * normal_world).T
    if not patch.extra.get("foundation"):
        # the Winkler foundation equivalent to the first contact, for what
        # reasons with one (a cycle jump's re-balance, its wear per unit of
        # penetration): its load over its overlaps; kept for the run, so
        # that the jumps' measurements compare from cycle to cycle
        overlap = np.maximum(approach - heights[on], 0.0)
        stiff = float(overlap @ (k_area * overlap))
        if len(F) and stiff > 0.0:
            model.law[6] = float(F @ overlap) / stiff
            model.law[5] = 0.0
            patch.extra["foundation"] = True


def vertex_pressure(s):
    """(n,) the pressure (Pa) at the points of the vertices that carry load
    in the last step of a half-space body (state ``s``): the solved
    pressure read bilinearly between the cell centres around each
    (docs/outputs.md, ``pressure``); zero elsewhere. Its force is this
    pressure times its contact area, scaled alike at every vertex by
    ``P / sum(p_j A_j)``: the two differ by the quadrature's error only."""
    out = np.zeros(len(s.wear_depth))
    patch = s.elastic
    if patch is not None and patch.written is not None and patch.point_pressure is not None:
        on = patch.loaded
        # (a contact narrower than a cell, which no vertex's point reads,
        # is carried by the gap weights: its force over its area there)
        out[patch.written] = np.where(patch.point_pressure[on] > 0.0, patch.point_pressure[on],
                                      patch.forces[on] / patch.areas[on])
    return out


def counter_pairs(s):
    """Per slot, the (contact state, normal force) a worn counter-surface
    wears by after a half-space step (:func:`meshwear.model.wear_counters`):
    the vertices that dissipated energy slip, each with the force whose
    Coulomb slip at its speed dissipates that energy; the others nothing."""
    patch = s.elastic
    if patch is None:
        return list(zip(np.zeros_like(s.contact_state), np.zeros_like(s.normal_force)))
    # allocated once, the last step's entries cleared (not the whole arrays)
    if "counter_pairs" not in patch.extra:
        patch.extra["counter_pairs"] = (np.zeros_like(s.contact_state),
                                        np.zeros_like(s.normal_force), np.zeros(0, np.int64))
    state, force, last = patch.extra["counter_pairs"]
    state[0, last], force[0, last] = NO_CONTACT, 0.0
    idx, f = patch.counter if patch.counter is not None else (last[:0], 0.0)
    state[0, idx], force[0, idx] = SLIP, f
    patch.extra["counter_pairs"] = (state, force, idx)
    return list(zip(state, force))


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
        # sliding: Coulomb at every vertex against its own slip velocity
        patch.sliding = True
        patch.shear, patch.direction, patch.gross = None, 0.0, False
        speeds = np.linalg.norm(slip_v, axis=1)
        moving = speeds > 0.0
        friction = np.zeros((len(F), 3))
        friction[moving] = -(mu * F[moving] / speeds[moving])[:, None] * slip_v[moving]
        state = np.where(moving, SLIP, STICK).astype(np.int8)
        return mu * F * speeds * model.dt, friction, state
    patch.sliding = False
    move = float(mean_v @ patch.e1) * model.dt
    limit = mu * patch.pressure
    q_old = patch.shear if patch.shear is not None else np.zeros(limit.shape)
    energy = np.zeros(len(F))
    if move == 0.0:
        q = np.clip(q_old, -limit, limit)
        stick = (patch.pressure > 0.0) & (np.abs(q) < limit * (1.0 - 1e-9))
    else:
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
        if hit is None:
            new_key = (patch.turn_key, round(patch.shift * 1e15))
            if len(patch.cache) >= CACHE_STEPS:
                patch.cache.clear()
            patch.cache[key] = (q, stick, cell_energy, new_key)
            patch.key = new_key
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


def _drop_grid(patch):
    """Forget the grid (the next pass builds one), keeping where it was for
    the shear history."""
    if patch.grid is not None:
        patch.extra["old"] = (patch.grid, patch.origin)
    patch.grid = None


def _spread(body, s, patch, n):
    """The largest angle (rad) between the contact normal and the body's or
    the surface's normal at a vertex that carries load."""
    pressed = patch.forces > 0.0
    if not pressed.any():
        return 0.0
    R = quaternion_matrix(s.pose[3:7])
    idx = patch.index[pressed]
    outward = body.area_vectors[idx, 0:3] @ R.T / body.area_vectors[idx, 3:4]
    cosines = np.concatenate([-(outward @ patch.normal), n[pressed] @ patch.normal])
    return float(np.arccos(np.clip(cosines, -1.0, 1.0)).max())


def _regrid(values, patch, old):
    """``values`` on the grid ``old`` (grid, origin) at the nearest cell of
    ``patch``'s new grid (zero outside)."""
    if values is None:
        return None
    grid, origin = old
    shape = patch.allowed.shape
    h_new, h_old = patch.grid.spacing[0], grid.spacing[0]
    out = np.zeros(shape)
    ii, jj = np.meshgrid(np.arange(shape[0]), np.arange(shape[1]), indexing="ij")
    xi = np.rint((patch.origin[0] + h_new * ii - origin[0]) / h_old).astype(int)
    yj = np.rint((patch.origin[1] + h_new * jj - origin[1]) / h_old).astype(int)
    ok = (xi >= 0) & (xi < values.shape[0]) & (yj >= 0) & (yj < values.shape[1])
    out[ok] = values[xi[ok], yj[ok]]
    return out


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


def _window(lo, hi, size, f):
    """Per axis, the window [lo, hi) widened to a multiple of f cells within
    the grid's ``size`` cells (f = 1 where the grid is too small)."""
    out, factors = [], []
    for a, b, n in zip(lo, hi, size):
        extent = -(-(b - a) // f) * f
        if extent > n:
            extent, factor = b - a, 1
        else:
            factor = f
        b2 = min(a + extent, n)
        out.append(slice(int(b2 - extent), int(b2)))
        factors.append(factor)
    return tuple(out), min(factors)


def _new_pressure(patch, solution, heights, areas):
    """Take the ``solution`` of the normal problem on ``heights`` (the
    patch's vertices' gaps; ``areas`` their contact areas): the vertices'
    pressure at their points and their forces (:mod:`meshwear.cellfields`), the
    loaded vertices, the window of the tangential problem."""
    patch.pressure = solution.traction
    patch.heights = heights.copy()
    patch.approach = solution.approach
    patch.areas = np.asarray(areas, float).copy()
    pressure = solution.traction.ravel()
    patch.point_pressure = patch.interpolation @ pressure
    patch.forces = to_vertices(patch.interpolation, patch.areas, patch.transposed, pressure,
                                patch.grid.cell_area)
    patch.loaded = np.flatnonzero(patch.forces > 0.0)
    patch.transposed_loaded = patch.transposed[patch.loaded]
    patch.interpolation_loaded = patch.interpolation[patch.loaded]
    # the window of cells the tangential problem needs: the pressed ones
    pressed = np.argwhere(solution.traction > 0.0)
    if len(pressed):
        lo, hi = pressed.min(axis=0), pressed.max(axis=0) + 1
        f = max(1, -(-int((hi - lo).max()) // SHEAR_CELLS))
        window, f = _window(lo, hi, solution.traction.shape, f)
        if f > 1 and any((w.stop - w.start) % f for w in window):
            window, f = _window(lo, hi, solution.traction.shape, 1)
        shape = tuple((w.stop - w.start) // f for w in window)
        key = (shape, patch.grid.spacing, f)
        if patch.extra.get("shear_key") != key:
            patch.extra["shear_key"] = key
            patch.shear_grid = halfspace.make_grid(
                shape, tuple(f * h for h in patch.grid.spacing), patch.extra["youngs"],
                patch.extra["poisson"])
        if window != patch.window or f != patch.shear_factor:
            patch.reserve = None
        patch.window, patch.shear_factor = window, f


def describe(model, state):
    """``meshwear check``'s lines on each body's half-space contact at the
    start: the patch and its grid, and how far its contact normals spread
    (the half-space assumption: within :data:`WARN_SPREAD`; a warning
    beyond it)."""
    lines, warnings = [], []
    surface = model.surfaces.slots[0].name
    for body, s in zip(model.bodies, state.bodies):
        patch = s.elastic
        if patch is None or patch.pressure is None:
            lines.append(f"half-space contact of {body.name!r} on {surface!r}: none at the start")
            continue
        h = patch.grid.spacing[0]
        pressed = patch.pressure > 0.0
        radius = np.sqrt(pressed.sum() * h * h / np.pi)
        lines.append(
            f"half-space contact of {body.name!r} on {surface!r}: E* {model.elastic.modulus:.3g} "
            f"Pa, patch of radius {radius:.3g} m ({int((patch.forces > 0.0).sum())} vertices) on "
            f"a {patch.grid.shape[0]} x {patch.grid.shape[1]} grid of {h:.3g} m cells, peak "
            f"pressure {patch.pressure.max():.3g} Pa, contact normals within "
            f"{np.degrees(patch.spread):.2g}°")
        if patch.spread > WARN_SPREAD:
            warnings.append(
                f"body {body.name!r} on {surface!r}: the contact normals spread "
                f"{np.degrees(patch.spread):.2g}°, more than {np.degrees(WARN_SPREAD):.2g}°: "
                "the patch is not small against the radii of curvature (the half-space "
                "assumption); model = 'winkler' may suit a conforming contact better")
    return lines, warnings


def equivalent_depth(model, body, s, index, depth, area):
    """The penetrations a cycle jump reasons with (:func:`meshwear.jumps.contact_geometry`)
    for a half-space contact: a loaded vertex's force over its stiffness on
    the equivalent Winkler foundation, ``N_i / (K A_i)``; an unloaded one in
    the patch, minus its gap after the surfaces deformed (the rigid overlap
    of a vertex just outside an elastic contact, out to sqrt(2) a on a
    ball, carries nothing: taken as a penetration it would carry load and
    wear in the jump); the others' rigid ``depth`` as given."""
    patch = s.elastic
    if patch is None or patch.pressure is None or patch.index is None:
        return depth
    pos = np.minimum(np.searchsorted(patch.index, index), len(patch.index) - 1)
    ours = patch.index[pos] == index
    # the surfaces' displacement at each vertex: its nearest cell's
    u = patch.grid.convolve(patch.pressure)
    cell = np.rint((patch.coords[pos[ours]] - patch.origin) / patch.grid.spacing[0]).astype(int)
    cell = np.clip(cell, 0, np.array(u.shape) - 1)
    displacement = np.zeros(len(index))
    displacement[ours] = u[cell[:, 0], cell[:, 1]]
    force = s.normal_force[0, index]
    stiffness = model.law[5] + model.law[6] * area
    out = depth.copy()
    loaded = ours & (force > 0.0) & (stiffness > 0.0)
    out[loaded] = force[loaded] / stiffness[loaded]
    free = ours & ~loaded & np.isfinite(depth)
    out[free] = np.minimum(depth[free] - displacement[free], 0.0)
    return out
