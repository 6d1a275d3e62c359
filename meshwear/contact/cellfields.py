"""Fields of a half-space patch's grid read at its vertices (docs/model.md, "In a run").

The elastic solve (:mod:`meshwear.contact.halfspace`) gives tractions on a regular
grid of cells; the vertices of the body's mesh need a pressure, a force, a
shear and a friction energy each. A vertex reads a field at its point on the
contact plane, bilinearly between the four cell centres around it
(:func:`bilinear`): that is its pressure. What it carries (a force, an
energy) is that density times its contact area, the one-point quadrature of
the field over the area the wear divides by, scaled alike at every vertex so
that the vertices carry the cells' total exactly (:func:`to_vertices`): the
force over the area is the pressure at the point but for that one factor,
the quadrature's error (5e-4 and 6e-4 on the two Hertz balls of
docs/validation.md).

(A vertex's share of the cells by the transposed gap weights, the vertex's
hat function sampled at the cell centres, integrates the pressure over an
area that follows the Delaunay triangles and the cells it happens to hold,
not its contact area: on an irregular refined mesh 0.5 to 2 times it.)
"""

import numpy as np
from scipy import sparse


def bilinear(coords, origin, spacing, shape):
    """Sparse (k, cells) weights that read a field of the grid's cells
    (``shape``, the first centred at ``origin``, ``spacing`` m apart) at the
    points ``coords`` (k, 2; m): bilinear between the four cell centres
    around each point, cells beyond the grid taken as zero (the contact
    never reaches its border cells)."""
    u = (coords - origin) / spacing
    corner = np.floor(u).astype(np.int64)
    frac = u - corner
    rows, cols, values = [], [], []
    for di in (0, 1):
        for dj in (0, 1):
            w = (frac[:, 0] if di else 1.0 - frac[:, 0]) * (frac[:, 1] if dj else 1.0 - frac[:, 1])
            i, j = corner[:, 0] + di, corner[:, 1] + dj
            ok = (i >= 0) & (i < shape[0]) & (j >= 0) & (j < shape[1]) & (w > 0.0)
            rows.append(np.flatnonzero(ok))
            cols.append(i[ok] * shape[1] + j[ok])
            values.append(w[ok])
    return sparse.csr_matrix((np.concatenate(values), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(len(coords), shape[0] * shape[1]))


def to_vertices(B, areas, T, density, area_cell):
    """What the vertices carry of a field of the cells of ``density`` (>= 0;
    Pa, J/m^2) (k,): each vertex's ``areas`` times the density at its point
    (``B``, :func:`bilinear`), all scaled alike to the cells' total
    ``sum density * area_cell`` (the one-point quadrature of each vertex's
    area, its sum corrected for the quadrature's error). Where no vertex's
    point sees the cells (a contact narrower than a cell), their shares by
    the transposed gap weights ``T`` instead."""
    total = float(density.sum()) * area_cell
    if total <= 0.0:
        return np.zeros(B.shape[0])
    point = areas * (B @ density)
    seen = float(point.sum())
    if seen > 0.0:
        return point * (total / seen)
    return T @ (density * area_cell)


def signed_to_vertices(B, areas, T, density, area_cell):
    """:func:`to_vertices` of a field of either sign (a shear): its
    positive and negative parts each carried whole."""
    return (to_vertices(B, areas, T, np.maximum(density, 0.0), area_cell)
            - to_vertices(B, areas, T, np.maximum(-density, 0.0), area_cell))
