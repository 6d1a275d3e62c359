"""The half-space patch: the grid a body's contact is solved on (docs/model.md, "In a run").

A :class:`Patch` is one body's solve kept from step to step
(:mod:`meshwear.contact.elastic` runs it). This module owns its geometry:
each vertex's gap, normal and contact area against the counter-surface
(:func:`pair_geometry`); the regular grid in the tangent plane that the
vertices within a band of gaps span, its axes fixed to the body (the first
along the path's stroke), and the vertices' Delaunay triangles that
interpolate their gaps onto the cells (:func:`_build_patch`); whether last
step's grid still fits the vertices (:func:`_locate`); the shear history
moved onto a new grid (:func:`_regrid`); and, after a normal solve, the
fields at the vertices (their pressure and forces, through
:mod:`meshwear.contact.cellfields`) and the window of pressed cells the
tangential problem is solved on (:func:`_new_pressure`).
"""

from dataclasses import dataclass, field

import numpy as np
from scipy import sparse
from scipy.spatial import Delaunay, QhullError
from threadpoolctl import threadpool_limits

from . import halfspace
from .cellfields import bilinear, to_vertices
from ..kernels.elastic import gaps
from ..kernels.rigid import OSCILLATION, STEADY
from ..surfaces.base import quaternion_matrix

#: cells per side at most; a larger patch gets coarser cells
MAX_CELLS = 192
#: the tangential problem is solved on at most about this many cells a side:
#: a wider window merges its cells f x f (the normal one keeps them all)
SHEAR_CELLS = 64


@dataclass(eq=False)
class Patch:
    """One body's solve, kept from step to step (:mod:`meshwear.contact.elastic`)."""

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
    pressure at their points and their forces (:mod:`meshwear.contact.cellfields`), the
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
