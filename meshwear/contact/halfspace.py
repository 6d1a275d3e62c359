"""Elastic half-space contact on a regular grid (docs/model.md, "Elastic half-space").

Two elastic bodies whose contact patch is small against their radii of
curvature touch as two half-spaces do: the normal displacement of the
surfaces is the pressure convolved with Boussinesq's influence function, the
tangential one the shear convolved with Cerruti's. On a regular grid of
cells (uniform traction over each), the influence coefficients are Love's
closed forms for a rectangle, the convolution is a discrete convolution that
the FFT evaluates without wrap-around error on a grid padded to at least
2 n - 1 cells a side, the next size the FFT is fast at (DC-FFT: Liu, Wang
and Liu, Wear 243 (2000) 101-111), and the contact
conditions are solved by the constrained conjugate gradient of Polonsky and
Keer (Wear 231 (1999) 206-219): pressure ``p >= 0``, gap ``g >= 0``,
``p g = 0`` and the total load given; its directions preconditioned by
the inverse of the half-space's Fourier symbol, ``|k|`` up to a factor
(Vollebregt, J. Comput. Phys. 257 (2014) 333-351), so that the iterations
hardly grow with the grid.

Normal and tangential problems are uncoupled (Goodman's approximation:
exact for bodies of the same material, ``(1 - 2 nu) / G`` equal; otherwise
it neglects the normal displacement that shear causes). The tangential
problem of a contact loaded along x (Cattaneo-Mindlin) is the normal one in
disguise: with the stick reserve ``w = mu p - q`` (``q`` the shear along the
slip), the stick zone is where ``w > 0`` and the surfaces move as one, the
slip zone where ``w = 0``; ``w`` is found by the same solver with Cerruti's
kernel, on the contact cells only, its total ``mu P - Q``
(:func:`solve_shear`).

Every function works on 1-D grids (plane strain: a line contact, per unit
length) and 2-D grids (a patch) alike; lengths in m, pressures in Pa.
"""

from dataclasses import dataclass, field

import numpy as np
from scipy import fft


def contact_modulus(youngs, poisson):
    """The contact modulus ``E*`` (Pa) of two bodies:
    ``1 / E* = (1 - nu1^2) / E1 + (1 - nu2^2) / E2``."""
    return 1.0 / sum((1.0 - nu * nu) / e for e, nu in zip(youngs, poisson))


def _love(x, y, shear_nu=None):
    """Antiderivative of ``1 / r`` (``shear_nu`` None) or of Cerruti's
    ``(1 - nu) / r + nu x^2 / r^3`` over x and y, at (x, y)."""
    r = np.hypot(x, y)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = np.where(x == 0.0, 0.0, x * np.log(np.where(y + r > 0.0, y + r, 1.0)))
        b = np.where(y == 0.0, 0.0, y * np.log(np.where(x + r > 0.0, x + r, 1.0)))
    return a + b if shear_nu is None else (1.0 - shear_nu) * a + b


def _cell_integral(x, y, hx, hy, shear_nu=None):
    """Integral over the cell ``[-hx, hx] x [-hy, hy]`` of the kernel seen
    from (x, y)."""
    return (_love(x + hx, y + hy, shear_nu) - _love(x - hx, y + hy, shear_nu)
            - _love(x + hx, y - hy, shear_nu) + _love(x - hx, y - hy, shear_nu))


def _strip_integral(x, hx):
    """Integral of ``-ln |s|`` over ``s`` in ``[x - hx, x + hx]`` (the
    plane-strain line load's displacement, up to a constant)."""
    def f(s):
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(s == 0.0, 0.0, s * np.log(np.abs(s))) - s
    return -(f(x + hx) - f(x - hx))


@dataclass
class Grid:
    """A regular grid of ``shape`` cells of ``spacing`` (m) centred on the
    origin (1-D or 2-D), and the Fourier transforms of its influence
    kernels on the padded grid (DC-FFT)."""

    shape: tuple
    spacing: tuple
    normal: np.ndarray           # rfftn of the normal kernel (m/Pa)
    shear: np.ndarray            # rfftn of the tangential (x) kernel (m/Pa), or None
    #: the padded grid the FFT runs on: per axis at least 2 n - 1 cells, the
    #: next size the FFT is fast at (scipy.fft.next_fast_len)
    padded: tuple = None
    #: the preconditioner's grid (per axis the next fast size from n) and its
    #: multiplier, the wavenumber |k| (1/m; the smallest at k = 0)
    periodic: tuple = field(init=False, repr=False)
    wavenumber: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        self.periodic = tuple(fft.next_fast_len(n, real=True) for n in self.shape)
        k = [2.0 * np.pi * fft.fftfreq(m, h) for m, h in zip(self.periodic, self.spacing)]
        k[-1] = 2.0 * np.pi * fft.rfftfreq(self.periodic[-1], self.spacing[-1])
        k = np.sqrt(sum(kk * kk for kk in np.meshgrid(*k, indexing="ij", sparse=True)))
        k.flat[0] = 2.0 * np.pi / max(m * h for m, h in zip(self.periodic, self.spacing))
        self.wavenumber = k

    @property
    def cell_area(self):
        """Area of a cell (m^2; per unit length in 1-D: its width, m)."""
        return float(np.prod(self.spacing))

    @property
    def centres(self):
        """Coordinates of the cell centres along each axis (m)."""
        return [h * (np.arange(n) - 0.5 * (n - 1)) for n, h in zip(self.shape, self.spacing)]

    def convolve(self, traction, kernel="normal"):
        """The displacement (m) the ``traction`` (Pa) on the cells causes at
        each cell's centre, by the ``normal`` (Boussinesq) or ``shear``
        (Cerruti, along x) kernel."""
        spectrum = self.normal if kernel == "normal" else self.shear
        return self._inverse(self._forward(traction) * spectrum)

    def precondition(self, gap):
        """An approximate inverse of the convolution, up to a factor: the
        ``gap`` (m) times |k| in Fourier space on the cells' own grid,
        periodic (Boussinesq's displacement is the pressure times
        2 / (E* |k|), Cerruti's the shear times that within a factor
        1 - nu), the preconditioner of :func:`_iterate`'s conjugate
        gradient (Vollebregt, J. Comput. Phys. 257 (2014) 333-351)."""
        out = fft.irfftn(fft.rfftn(gap, self.periodic) * self.wavenumber, self.periodic,
                         overwrite_x=True)
        return out[tuple(slice(0, n) for n in self.shape)]

    def _forward(self, traction):
        """rfftn of ``traction`` zero-padded to :attr:`padded`. In 2-D the
        real transform runs along the rows the cells fill only (the padding's
        rows are zero: half the real stage's work), then the complex one
        along the columns."""
        traction = np.asarray(traction, float)
        if len(self.shape) == 1:
            return fft.rfft(traction, self.padded[0])
        rows = fft.rfft(traction, self.padded[1], axis=1)
        return fft.fft(rows, self.padded[0], axis=0, overwrite_x=True)

    def _inverse(self, spectrum):
        """The cells' part of the inverse of :meth:`_forward` (``spectrum``
        is overwritten): in 2-D the complex transform along the columns,
        then the real one along the cells' rows only (the padding's rows
        are thrown away)."""
        if len(self.shape) == 1:
            return fft.irfft(spectrum, self.padded[0], overwrite_x=True)[:self.shape[0]]
        rows = fft.ifft(spectrum, axis=0, overwrite_x=True)[:self.shape[0]]
        return np.ascontiguousarray(fft.irfft(rows, self.padded[1], axis=1)[:, :self.shape[1]])


def make_grid(shape, spacing, youngs, poisson):
    """A :class:`Grid` of ``shape`` cells (1-D: plane strain, or 2-D) of
    ``spacing`` (m) for two bodies of Young's moduli ``youngs`` (Pa) and
    Poisson's ratios ``poisson`` (pairs)."""
    shape = tuple(int(n) for n in np.atleast_1d(shape))
    spacing = tuple(float(h) for h in np.broadcast_to(spacing, (len(shape),)))
    padded = tuple(fft.next_fast_len(2 * n - 1, real=True) for n in shape)
    # the kernel on the padded grid in wrap-around order: offsets 0 .. n-1
    # first, -(n-1) .. -1 last (those between multiply the padding only)
    offsets = []
    for n, h, m in zip(shape, spacing, padded):
        i = np.arange(m)
        d = np.where(i < n, i, i - m).astype(float) * h
        offsets.append(d)
    normal_compliance = sum((1.0 - nu * nu) / e for e, nu in zip(youngs, poisson))
    if len(shape) == 1:
        # plane strain: u = -(2 / (pi E*)) integral p ln|x - s| ds + const
        k = 2.0 * normal_compliance / np.pi * _strip_integral(offsets[0], 0.5 * spacing[0])
        return Grid(shape, spacing, fft.rfftn(k), None, padded)
    x, y = np.meshgrid(offsets[0], offsets[1], indexing="ij")
    hx, hy = 0.5 * spacing[0], 0.5 * spacing[1]
    k = normal_compliance / np.pi * _cell_integral(x, y, hx, hy)
    shear = sum(1.0 / (2.0 * np.pi * e / (2.0 * (1.0 + nu)))
                * _cell_integral(x, y, hx, hy, shear_nu=nu) for e, nu in zip(youngs, poisson))
    return Grid(shape, spacing, fft.rfftn(k), fft.rfftn(shear), padded)


@dataclass
class Solution:
    """A solved contact: ``traction`` (Pa) on the cells, the rigid approach
    (m; the load-controlled problem's Lagrange multiplier), the cells'
    ``gap`` (m, zero where they touch), the iterations taken and the
    residual reached."""

    traction: np.ndarray
    approach: float
    gap: np.ndarray
    iterations: int
    residual: float


def solve(grid, gap, load, mask=None, kernel="normal", start=None, tol=1e-10,
          max_iterations=2000, approach=None):
    """The traction ``p >= 0`` of total ``load`` (N; N/m in 1-D) on the
    cells with ``grid``'s ``kernel``, under the initial ``gap`` (m) of the
    surfaces before any approach: ``gap + u(p) - approach >= 0``, zero
    where ``p > 0`` (Polonsky and Keer's constrained conjugate gradient).
    ``mask`` (bool): the cells that may carry traction (default all);
    ``start``: a traction to start from (a warm start: the last step's).
    With ``approach`` (m) given instead of ``load`` (pass None), the
    displacement-controlled problem: the traction the given approach
    needs, its total whatever it comes to.
    """
    h = np.asarray(gap, float)
    allowed = np.ones(h.shape, bool) if mask is None else np.asarray(mask, bool)
    area = grid.cell_area
    if approach is not None:
        return _solve_approach(grid, h, float(approach), allowed, kernel, start, tol,
                               max_iterations)
    if load <= 0.0 or not allowed.any():
        return Solution(np.zeros_like(h), float(h[allowed].min()) if allowed.any() else 0.0,
                        h.copy(), 0, 0.0)
    if start is not None and np.any(start[allowed] > 0.0):
        p = np.where(allowed, np.maximum(start, 0.0), 0.0)
    else:
        p = allowed.astype(float)         # uniform, as Polonsky and Keer start
    p *= load / (p.sum() * area)
    p, u, iteration, residual = _iterate(grid, h, allowed, kernel, p, tol, max_iterations, load)
    g = u + h
    touching = p > 0.0
    approach = float(g[touching].mean())
    return Solution(p, approach, np.where(allowed, g - approach, np.inf), iteration, residual)


def _solve_approach(grid, h, approach, allowed, kernel, start, tol, max_iterations):
    """:func:`solve` at a given ``approach``: the same conjugate gradient
    without the load's constraint (:func:`_iterate`)."""
    if start is not None and np.any(start[allowed] > 0.0):
        p = np.where(allowed, np.maximum(start, 0.0), 0.0)
    else:
        # each cell's interference over its own influence coefficient
        unit = np.zeros(h.shape)
        unit[(0,) * h.ndim] = 1.0
        own = float(grid.convolve(unit, kernel)[(0,) * h.ndim])
        p = np.where(allowed, np.maximum(approach - h, 0.0) / own, 0.0)
    if not p.any():
        return Solution(p, approach, np.where(allowed, h - approach, np.inf), 0, 0.0)
    p, u, iteration, residual = _iterate(grid, h, allowed, kernel, p, tol, max_iterations,
                                         approach=approach)
    return Solution(p, approach, np.where(allowed, u + h - approach, np.inf), iteration, residual)


def _dot(a, b):
    """The dot product of two flat arrays by numpy's own loop: BLAS's
    (``a @ b``) wakes its threads for it, which on a busy machine wait
    milliseconds for a product of microseconds."""
    return float(np.einsum("i,i->", a, b))


def _iterate(grid, h, allowed, kernel, p, tol, max_iterations, load=None, approach=0.0):
    """Polonsky and Keer's constrained conjugate gradient from the traction
    ``p``: with ``load``, the total kept (the mean gap of the cells in
    contact removed, the traction rescaled at each iteration), else at the
    given ``approach``. Returns the traction, its displacement ``u``, the
    iterations and the residual (the traction's relative change in the last
    iteration).

    The directions are preconditioned: the gap on the contact times |k|
    (:meth:`Grid.precondition`, an approximate inverse of the compliance),
    which keeps the iterations from growing with the grid. An iteration
    convolves its direction ``t`` only: where no cell was clipped or added
    the new traction is the old one moved along ``t`` (and rescaled), so its
    displacement follows by linearity, ``u - tau K t``; a full convolution of
    the traction is left to the iterations that change the contact. The work
    is done in place on flat arrays (the cells in contact as a 0/1 array, to
    take dot products with)."""
    shape = h.shape
    area = grid.cell_area
    h = np.ascontiguousarray(h, float).ravel()
    allowed = np.ascontiguousarray(allowed).ravel()
    p = np.array(p, float).ravel()

    def convolve(x):
        return grid.convolve(x.reshape(shape), kernel).ravel()

    u = convolve(p)
    g, gt, t, touching, new, work = (np.empty_like(h) for _ in range(6))
    t[:] = 0.0
    bad = np.empty(h.shape, bool)
    g_old, conjugate, exact = 1.0, False, True
    iteration, residual = 0, np.inf
    for iteration in range(1, max_iterations + 1):
        np.add(u, h, out=g)
        np.greater(p, 0.0, out=touching)             # 1.0 in contact, 0.0 off
        count = float(touching.sum())
        if count == 0.0:
            break
        g -= _dot(g, touching) / count if load is not None else approach
        np.multiply(g, touching, out=gt)
        # the preconditioned gap on the contact (less its mean: the load's
        # constraint)
        z = grid.precondition(gt.reshape(shape)).ravel()
        z *= touching
        if load is not None:
            z -= float(z.sum()) / count
            z *= touching
        G = _dot(gt, z)
        if conjugate:
            t *= G / g_old
            t += z
            t *= touching
        else:
            t[:] = z
        g_old = G
        r = convolve(t)
        denominator = _dot(r, t)
        if load is not None:
            # r less its mean over the contact, in the dot product only
            denominator -= _dot(r, touching) / count * float(t.sum())
        tau = _dot(g, t) / denominator if denominator != 0.0 else 0.0
        np.multiply(t, -tau, out=new)
        new += p
        clipped = float(new.min()) < 0.0
        np.maximum(new, 0.0, out=new)
        # cells off the contact with a negative gap join it
        np.less(g, 0.0, out=bad)
        bad &= allowed
        bad &= new == 0.0
        conjugate = not bad.any()
        if not conjugate:
            new[bad] -= tau * g[bad]
        scale = 1.0
        if load is not None:
            scale = load / (float(new.sum()) * area)
            new *= scale
        np.subtract(new, p, out=work)
        change = float(np.abs(work, out=work).sum())
        p, new = new, p
        if conjugate and not clipped:
            # the displacement by linearity: one convolution an iteration
            r *= -tau
            u += r
            if scale != 1.0:
                u *= scale
            exact = False
        else:
            u, exact = convolve(p), True
        if load is not None:
            residual = change * area / load
        else:
            total = float(p.sum())
            residual = change / total if total > 0.0 else 0.0
        if residual < tol:
            break
    if not exact:
        u = convolve(p)      # the displacement afresh, free of the updates' rounding
    return p.reshape(shape), u.reshape(shape), iteration, residual


def shear_at_shift(grid, pressure, friction, shift, turn=None, turn_shift=0.0, start=None,
                   tol=1e-10):
    """Cattaneo-Mindlin partial slip along x at a given tangential ``shift``
    (m, the bodies' far points relative to each other; displacement control,
    as a guided body's path imposes it), reached monotonically from the
    shear ``turn`` at ``turn_shift`` (the segment's turning point: Mindlin
    and Deresiewicz; default none, at 0). Returns the shear ``q`` (Pa), the
    stick cells and the stick reserve ``w`` (a warm start for the next call
    of the same segment: ``start``). The stick reserve
    ``w = mu p - s q >= 0`` (``s`` the segment's direction) solves
    :func:`solve` with Cerruti's kernel at the approach ``-s (shift -
    turn_shift)`` (:func:`solve_shear` gives the force-controlled twin)."""
    contact = pressure > 0.0
    limit = friction * pressure
    q0 = np.zeros_like(limit) if turn is None else np.asarray(turn, float)
    change = shift - turn_shift
    if change == 0.0:
        return q0.copy(), contact & (np.abs(q0) < limit * (1.0 - 1e-9)), limit - np.abs(q0)
    sign = 1.0 if change > 0.0 else -1.0
    gap = -grid.convolve(limit, "shear") + sign * grid.convolve(q0, "shear")
    reserve = solve(grid, gap, None, mask=contact, kernel="shear", start=start, tol=tol,
                    approach=-sign * change)
    w = np.minimum(reserve.traction, 2.0 * limit)
    return sign * (limit - w), w > 0.0, w


def solve_shear(grid, pressure, friction, force, previous=None, previous_force=0.0,
                previous_shift=0.0, tol=1e-10):
    """Cattaneo-Mindlin partial slip along x under the ``pressure`` (Pa)
    solved before: the shear ``q`` (Pa) on the cells at tangential ``force``
    (N), reached monotonically from the shear ``previous`` at
    ``previous_force`` and tangential shift ``previous_shift`` (default:
    none, at 0; a load reversed is a new segment from where it turned:
    Mindlin and Deresiewicz). Returns ``q``, the stick cells (bool) and the
    tangential shift (m) of the bodies, the displacement of the points far
    from the contact relative to each other (NaN in gross slip).

    In a segment of direction ``s = sign(force - previous_force)`` the slip
    cells carry ``s mu p`` and the stick cells move on together by the
    shift's increment ``d``, so the stick reserve ``w = mu p - s q >= 0``
    solves :func:`solve` with Cerruti's kernel on the contact: its "gap"
    ``-mu u_x(p) + s u_x(q0)`` (``q0`` = ``previous``), its total
    ``mu P - s Q``, its approach ``-s d``."""
    contact = pressure > 0.0
    limit = friction * pressure
    q0 = np.zeros_like(limit) if previous is None else np.asarray(previous, float)
    if force == previous_force:
        return q0.copy(), contact & (np.abs(q0) < limit * (1.0 - 1e-9)), previous_shift
    sign = 1.0 if force > previous_force else -1.0
    reserve_load = float(limit.sum() * grid.cell_area) - sign * force
    if reserve_load <= 0.0:
        return sign * limit, np.zeros(pressure.shape, bool), float("nan")
    gap = -grid.convolve(limit, "shear") + sign * grid.convolve(q0, "shear")
    reserve = solve(grid, gap, reserve_load, mask=contact, kernel="shear", tol=tol)
    q = sign * (limit - reserve.traction)
    return q, reserve.traction > 0.0, previous_shift - sign * reserve.approach
