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
   cells, linearly; the transposed weights take the cells' forces back to
   the vertices, so the vertices carry exactly the solved load.
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
   stroke's displacement (:func:`meshwear.halfspace.shear_at_shift`): stick
   and slip per cell, each cell's slip and friction energy from its shear
   and the relative displacement of the surfaces. Any other relative
   motion (a turning disc, a circle) slides: Coulomb at every vertex,
   ``mu N_i`` against its slip velocity.
5. Wear. Each vertex's energy (the cells' by the same transposed weights),
   load and slip go through the wear law (:mod:`meshwear.kernels.laws`)
   and the vertex moves as in the Winkler kernel.

The state of the solve (:class:`Patch`) is a cache: a run resumed from a
checkpoint solves it again (a fretting cycle then restarts its
Mindlin-Deresiewicz branch from the shear the wear left).
"""

from dataclasses import dataclass, field

import numpy as np
from scipy import sparse
from scipy.spatial import Delaunay, QhullError

from . import halfspace
from .kernels.contact import FACING, NO_CONTACT, SLIP, STICK
from .kernels.contact import FORCE as FORCE_SLOT
from .kernels.laws import LAWS, name_of
from .kernels.rigid import OSCILLATION, STEADY
from .motion import BalancedMotion
from .surfaces.base import quaternion_matrix

#: the normal problem is solved again when the gaps changed (rigid moves
#: aside) by more than this fraction of the elastic approach
RESOLVE = 1e-3
#: relative tolerance of the conjugate-gradient solves (the traction's change)
TOLERANCE = 1e-8
#: the band of gaps the first patch spans, in vertices of smallest gap
FIRST_BAND_VERTICES = 64
#: cells per side at most; a larger patch gets coarser cells
MAX_CELLS = 192
#: the elastic approach may use this fraction of the band, the rest is margin
BAND_USE = 0.6
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
    window: tuple = None                 # the cells the tangential problem is solved on
    shear_grid: object = None            # the grid of that window
    sliding: bool = False
    extra: dict = field(default_factory=dict)


class PatchError(RuntimeError):
    """A contact the half-space model cannot take (too conforming, no
    normal along the load)."""


def _perpendicular(n, hint):
    e = hint - (hint @ n) * n
    if np.linalg.norm(e) < 1e-9:
        for guess in np.eye(3):
            e = guess - (guess @ n) * n
            if np.linalg.norm(e) > 1e-6:
                break
    return e / np.linalg.norm(e)


def _stroke(motion):
    """The direction (3,) of a body's path's first oscillation or steady
    velocity, or None."""
    for row in motion.path.terms:
        if int(row[0]) in (OSCILLATION, STEADY) and np.linalg.norm(row[1:4]) > 0.0:
            return np.asarray(row[1:4], float) / np.linalg.norm(row[1:4])
    return None


def pair_geometry(model, body, s, index):
    """For the vertices ``index``: their gap (m, along the normal of the
    plane under each; inf where none faces them), the plane's normal
    (k, 3, world), the vertex's contact area on it (m²), its world
    offset from the centre of mass and its velocity relative to the
    surface (k, 3)."""
    R = quaternion_matrix(s.pose[3:7])
    r = s.vertices[index] @ R.T
    x = s.pose[0:3] + r
    P = model.planes.shape[0]
    if P:
        o = np.broadcast_to(model.planes[0, 0], x.shape)
        n = np.broadcast_to(model.planes[0, 1], x.shape)
        v_surface = np.broadcast_to(model.planes[0, 2], x.shape)
    else:
        o = s.vertex_planes[0, index, 0]
        n = s.vertex_planes[0, index, 1]
        v_surface = s.vertex_planes[0, index, 2]
    gap = np.einsum("ij,ij->i", x - o, n)
    if P and np.any(model.planes[0, 3] != 0.0):
        foot = x - gap[:, None] * n
        v_surface = v_surface + np.cross(model.planes[0, 3], foot - model.planes[0, 0])
    world_area = body.area_vectors[index, 0:3] @ R.T
    area = -np.einsum("ij,ij->i", world_area, n)
    facing = (area > FACING * body.area_vectors[index, 3]) & np.any(n != 0.0, axis=1)
    gap = np.where(facing, gap, np.inf)
    velocity = s.pose[7:10] + np.cross(s.pose[10:13], r) - v_surface
    return gap, np.ascontiguousarray(n), area, r, velocity


def _build_patch(patch, body, s, index, gap, r, area, n, hmin):
    """Grid and interpolation weights over the vertices whose gap is within
    the band (the triangles reach twice as far, so the grid's cells are
    all inside them)."""
    e1, e2 = patch.e1, patch.e2
    inside = gap - hmin <= patch.band
    reach = gap - hmin <= 2.0 * patch.band
    coords = np.column_stack([r @ e1, r @ e2])
    spacing = float(np.sqrt(np.median(area[inside])))
    lo, hi = coords[inside].min(axis=0), coords[inside].max(axis=0)
    lo, hi = lo - 2.0 * spacing, hi + 2.0 * spacing
    cells = np.ceil((hi - lo) / spacing).astype(int)
    if cells.max() > MAX_CELLS:
        spacing *= cells.max() / MAX_CELLS
        cells = np.ceil((hi - lo) / spacing).astype(int)
    cells = np.maximum(cells, 4)
    take = np.flatnonzero(reach)
    try:
        tri = Delaunay(coords[take])
    except QhullError:
        raise PatchError(f"body {body.name!r}: its contact patch has too few vertices "
                         f"({len(take)}) to span a grid; refine the body (resolution)") from None
    origin = lo + 0.5 * spacing
    grid = halfspace.make_grid(tuple(cells), spacing, patch.extra["youngs"],
                               patch.extra["poisson"])
    axes = [origin[j] + spacing * np.arange(cells[j]) for j in range(2)]
    cx, cy = np.meshgrid(*axes, indexing="ij")
    centres = np.column_stack([cx.ravel(), cy.ravel()])
    simplex = tri.find_simplex(centres)
    ok = simplex >= 0
    T = tri.transform[simplex[ok]]
    b = np.einsum("ijk,ik->ij", T[:, :2, :], centres[ok] - T[:, 2, :])
    bary = np.column_stack([b, 1.0 - b.sum(axis=1)])
    rows = np.repeat(np.flatnonzero(ok), 3)
    cols = tri.simplices[simplex[ok]].ravel()
    weights = sparse.csr_matrix((bary.ravel(), (rows, cols)),
                                shape=(len(centres), len(take)))
    old = (patch.grid, patch.origin) if patch.grid is not None else patch.extra.get("old")
    patch.grid, patch.origin = grid, origin
    patch.index = index[take]
    patch.coords = coords[take]
    patch.weights = weights
    patch.allowed = ok.reshape(cells)
    patch.pressure = None
    if old is not None:
        # the shear history moves to the new cells
        patch.shear, patch.turn = _regrid(patch.shear, patch, old), _regrid(patch.turn, patch, old)
        patch.reserve = None
    return take


def _same_patch(patch, index, coords):
    return (patch.index is not None and len(index) == len(patch.index)
            and np.array_equal(index, patch.index)
            and np.abs(coords - patch.coords).max() <= 1e-6 * patch.grid.spacing[0])


def step(model, body, s, t, before, at_rest=False):
    """One quasi-static step of ``body`` (state ``s``) at ``t`` with the
    elastic half-space, after :func:`meshwear.simulate._quasi_static_step`
    placed it on its path (``before``: its position at the step's start)
    and updated its surfaces: normal and tangential tractions, the load
    balance, wear. Fills the same state arrays as the Winkler kernel."""
    elastic = model.elastic
    motion = body.motion
    active = s.active
    gap, n, area, r, velocity = pair_geometry(model, body, s, active)
    if at_rest:
        velocity[:] = 0.0
    facing = np.isfinite(gap)
    s.normal_force[:, active] = 0.0
    s.tangential[:, active, FORCE_SLOT] = 0.0
    s.contact_state[:, active] = NO_CONTACT
    s.wrench[:] = 0.0
    if not facing.any():
        if isinstance(motion, BalancedMotion):
            raise PatchError(f"body {body.name!r}: no contact carries its load at t = {t:.6g} s")
        return
    patch = s.elastic
    first = patch is None
    if first:
        normal = n[np.argmin(gap)]
        stroke = _stroke(motion)
        e1 = _perpendicular(normal, stroke if stroke is not None else np.array([1.0, 0, 0]))
        patch = s.elastic = Patch(e1=e1, e2=np.cross(normal, e1), normal=normal)
        patch.extra.update(youngs=elastic.youngs, poisson=elastic.poisson)
    hmin = float(gap[facing].min())
    balanced = isinstance(motion, BalancedMotion)
    beta = float(motion.axis @ patch.normal) if balanced else 1.0
    if balanced and beta <= 0.1:
        raise PatchError(f"body {body.name!r}: its free axis is {np.degrees(np.arccos(max(beta, -1.0))):.0f}° "
                         "from the contact normal; the half-space model balances the load along "
                         "the normal (give free_axis along it)")
    load = motion.carried / beta if balanced else None
    coords = np.column_stack([r @ patch.e1, r @ patch.e2])
    shift_move = 0.0
    solved = False
    for _ in range(8):
        if patch.grid is None:
            if patch.band == 0.0:
                k = min(FIRST_BAND_VERTICES, int(facing.sum()))
                patch.band = 2.0 * float(np.partition(gap[facing] - hmin, k - 1)[k - 1]) + 1e-30
            take = _build_patch(patch, body, s, active, gap, r, area, n, hmin)
            heights = gap[take]
        else:
            where = np.searchsorted(active, patch.index)
            where = np.minimum(where, len(active) - 1)
            if not (np.array_equal(active[where], patch.index)
                    and np.all(np.isfinite(gap[where]))
                    and np.abs(coords[where] - patch.coords).max() <= 1e-6 * patch.grid.spacing[0]):
                _drop_grid(patch)
                continue
            take = where
            heights = gap[take]
        if patch.pressure is not None and not solved:
            change = heights - patch.heights
            # a guided body's rigid move along the normal is balanced away
            common = float(np.median(change)) if balanced else 0.0
            if np.abs(change - common).max() <= RESOLVE * max(patch.approach - patch.heights.min(), 0.0):
                # the same contact moved rigidly: the approach follows
                shift_move = common
                break
        cell_gap = patch.weights @ heights
        cell_gap = cell_gap.reshape(patch.allowed.shape)
        cell_gap = np.where(patch.allowed, cell_gap, np.inf)
        if balanced:
            solution = halfspace.solve(patch.grid, np.where(patch.allowed, cell_gap, 0.0), load,
                                       mask=patch.allowed, start=patch.pressure, tol=TOLERANCE)
        else:
            solution = halfspace.solve(patch.grid, np.where(patch.allowed, cell_gap, 0.0), None,
                                       mask=patch.allowed, start=patch.pressure, tol=TOLERANCE,
                                       approach=0.0)
        patch.solves += 1
        patch.iterations += solution.iterations
        used = solution.approach - hmin if balanced else -hmin
        if used > BAND_USE * patch.band:
            patch.band = used / BAND_USE * 1.5
            _drop_grid(patch)
            continue
        pressed = solution.traction > 0.0
        if pressed.any() and (pressed[0].any() or pressed[-1].any() or pressed[:, 0].any()
                              or pressed[:, -1].any()):
            patch.band *= 2.0
            _drop_grid(patch)
            continue
        if used < 0.15 * patch.band and used > 0.0 and patch.solves > 1:
            # the contact shrank well inside its patch: a smaller grid
            patch.band = used / BAND_USE * 1.5
            _drop_grid(patch)
            continue
        _new_pressure(patch, solution, heights)
        patch.spread = _spread(body, s, patch, take, n)
        if patch.spread > REFUSE_SPREAD:
            raise PatchError(
                f"body {body.name!r}: its contact spans {np.degrees(patch.spread):.0f}° of "
                f"surface normal at t = {t:.6g} s: a conforming contact (a shaft in a "
                "bushing), not a half-space one; use contact.model = 'winkler'")
        solved = True
        shift_move = 0.0
        break
    else:
        raise PatchError(f"body {body.name!r}: the half-space patch did not settle at t = {t:.6g} s")
    idx = patch.index
    F = patch.forces
    approach = patch.approach + shift_move
    if balanced:
        # the load balance: the body approaches by the solve's approach
        z = -approach / beta
        s.pose[0:3] += z * motion.axis
        if not at_rest:
            s.pose[7:10] = (s.pose[0:3] - before) / model.dt
            velocity = velocity + (z / model.dt) * motion.axis
    # the tangential problem
    k_area = area[take]
    normal_world = n[take]
    slip_v = velocity[take] - np.einsum("ij,ij->i", velocity[take], normal_world)[:, None] * normal_world
    mu = elastic.friction
    energy = np.zeros(len(idx))
    friction = np.zeros((len(idx), 3))
    state = np.where(F > 0.0, SLIP, NO_CONTACT).astype(np.int8)
    mean_v = slip_v[F > 0.0].mean(axis=0) if (F > 0.0).any() else np.zeros(3)
    uniform = (np.abs(slip_v[F > 0.0] - mean_v).max(initial=0.0)
               <= 1e-9 * np.linalg.norm(mean_v) + 1e-300)
    along = abs(mean_v @ patch.e2) <= 1e-9 * np.linalg.norm(mean_v) + 1e-300
    area_cell = patch.grid.cell_area
    if uniform and along and mu > 0.0:
        patch.sliding = False
        move = float(mean_v @ patch.e1) * model.dt
        q_old = patch.shear if patch.shear is not None else np.zeros(patch.allowed.shape)
        limit = mu * patch.pressure
        q_old = np.clip(q_old, -limit, limit)
        if move != 0.0:
            direction = 1.0 if move > 0.0 else -1.0
            if direction != patch.direction:
                patch.turn, patch.turn_shift = q_old, patch.shift
                patch.direction, patch.reserve = direction, None
            patch.turn = np.clip(patch.turn, -limit, limit)
            patch.shift += move
            # on the cells around the contact only (the shear is zero elsewhere)
            win, grid = patch.window, patch.shear_grid
            q_win, stick_win, w = halfspace.shear_at_shift(
                grid, patch.pressure[win], mu, patch.shift, patch.turn[win], patch.turn_shift,
                start=patch.reserve, tol=TOLERANCE)
            patch.reserve = w
            # each cell's slip: the stroke less the surfaces' elastic stretch
            slip = move - grid.convolve(q_win - q_old[win], "shear")
            q = np.zeros_like(q_old)
            q[win] = q_win
            stick = np.zeros(q.shape, bool)
            stick[win] = stick_win
            cell_energy = np.zeros_like(q_old)
            # (a slipping cell's shear is its limit, mu p, all the step)
            cell_energy[win] = np.where(stick_win, 0.0, np.maximum(q_win * slip, 0.0)) * area_cell
            energy = patch.weights.T @ cell_energy.ravel()
        else:
            q = q_old
            stick = (patch.pressure > 0.0) & (np.abs(q) < limit * (1.0 - 1e-9))
        patch.shear = q
        shear_force = patch.weights.T @ (q.ravel() * area_cell)
        friction = -shear_force[:, None] * patch.e1
        stuck = patch.weights.T @ (stick.ravel() * 1.0)
        share = patch.weights.T @ ((patch.pressure > 0.0).ravel() * 1.0)
        state = np.where(F > 0.0, np.where(stuck > 0.5 * share, STICK, SLIP), NO_CONTACT)
    else:
        # sliding: Coulomb at every vertex against its own slip velocity
        patch.sliding = True
        patch.shear, patch.direction = None, 0.0
        speed = np.linalg.norm(slip_v, axis=1)
        moving = speed > 0.0
        friction[moving] = -(mu * F[moving] / speed[moving])[:, None] * slip_v[moving]
        energy = mu * F * speed * model.dt
        state = np.where(F > 0.0, np.where(moving, SLIP, STICK), NO_CONTACT)
    # wear: the law on each vertex's energy, load and slip
    law = LAWS[name_of(int(model.law[2]))]
    slip_distance = np.where((F > 0.0) & (mu > 0.0), energy / np.maximum(mu * F, 1e-300), 0.0)
    contact_area = np.where(k_area > 0.0, k_area, 1.0)
    dw, dv = law.twin(model.law[3], energy, F, slip_distance, contact_area)
    dw = np.where(F > 0.0, dw, 0.0)
    dv = np.where(F > 0.0, dv, 0.0)
    R = quaternion_matrix(s.pose[3:7])
    worn = dw > 0.0
    if worn.any():
        if body.wear_direction.shape[0]:
            direction = body.wear_direction[idx[worn]]
        else:
            direction = normal_world[worn] @ R
        s.vertices[idx[worn]] += dw[worn, None] * direction
        s.wear_depth[idx[worn]] += dw[worn]
        s.wear_volume[idx[worn]] += dv[worn]
    s.friction_work[idx] += energy
    s.normal_force[0, idx] = F
    s.tangential[0, idx, FORCE_SLOT] = friction
    s.contact_state[0, idx] = state
    forces = F[:, None] * normal_world + friction
    s.wrench[0:3] = forces.sum(axis=0)
    s.wrench[3:6] = np.cross(r[take], forces).sum(axis=0)
    if s.load.shape[1]:
        s.load[0, idx] += F
        s.load[1, idx] += F * F
    # the Winkler foundation equivalent to this contact, for what reasons
    # with one (a cycle jump's re-balance): the load over the overlaps
    overlap = np.maximum(approach - patch.heights, 0.0)
    if (F > 0.0).any() and float(overlap @ (k_area * overlap)) > 0.0:
        model.law[6] = float(F @ overlap) / float(overlap @ (k_area * overlap))
        model.law[5] = 0.0


def _drop_grid(patch):
    """Forget the grid (the next pass builds one), keeping where it was for
    the shear history."""
    if patch.grid is not None:
        patch.extra["old"] = (patch.grid, patch.origin)
    patch.grid = None


def _spread(body, s, patch, take, n):
    """The largest angle (rad) between the contact normal and the body's or
    the surface's normal at a vertex that carries load."""
    pressed = patch.forces > 0.0
    if not pressed.any():
        return 0.0
    R = quaternion_matrix(s.pose[3:7])
    idx = patch.index[pressed]
    outward = body.area_vectors[idx, 0:3] @ R.T / body.area_vectors[idx, 3:4]
    cosines = np.concatenate([-(outward @ patch.normal), n[take][pressed] @ patch.normal])
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


def _new_pressure(patch, solution, heights):
    patch.pressure = solution.traction
    patch.heights = heights.copy()
    patch.approach = solution.approach
    patch.forces = patch.weights.T @ (solution.traction.ravel() * patch.grid.cell_area)
    # the window of cells the tangential problem needs: the pressed ones
    pressed = np.argwhere(solution.traction > 0.0)
    if len(pressed):
        lo, hi = pressed.min(axis=0), pressed.max(axis=0) + 1
        window = tuple(slice(a, b) for a, b in zip(lo, hi))
        shape = tuple(int(b - a) for a, b in zip(lo, hi))
        key = (shape, patch.grid.spacing)
        if patch.extra.get("shear_key") != key:
            patch.extra["shear_key"] = key
            patch.shear_grid = halfspace.make_grid(shape, patch.grid.spacing,
                                                   patch.extra["youngs"], patch.extra["poisson"])
        if window != patch.window:
            patch.reserve = None
        patch.window = window


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
