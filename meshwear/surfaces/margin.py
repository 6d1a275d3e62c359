"""The active-set margin a body gets when the scene gives none.

The margin (docs/model.md, "Active set") decides how many vertices each step
processes and how far a worn counter mesh is refined around a body's sweep.
It changes no contact force, only the cost, as long as it covers how far the
body can come towards its counter-surfaces over the run. By default it is
:data:`~meshwear.surfaces.active.MARGIN_FRACTION` of the body's size, which
for a fretting pad 6 mm in radius is 0.12 mm: a strip 2.4 mm wide is refined
and checked for a contact 70 µm wide.

A quasi-static guided body pressed by a known load ``N`` on its
counter-surfaces has a contact whose scale is known before the run
(:func:`contact_margin`): the approach ``δ`` its foundation and its wear can
reach, both found on the contact's own geometry, the gap ``d_i`` of each
body vertex to the nearest surface at the start (its contact area there
``A_i``, the vertex's area vector projected on that surface's normal):

- elastic: ``K Σ A_i max(0, δ_e - d_i) = N`` (per-point stiffness ``c``:
  ``c Σ max(0, δ_e - d_i) = N``);
- wear: ``Σ A_i max(0, δ_w - d_i) = V``, ``V`` the volume the wear laws give
  for the load over the run's sliding distance ``s`` (the body's law and
  every worn counter-surface's, all of it taken from the body: the sliding
  distance is the path of the body's leading vertex relative to each
  surface, sampled over a cycle).

The margin is :data:`APPROACHES` ``(δ_e + δ_w)``, no more than the size
default. For the pad above it is 11 µm (``V`` the 1.8·10⁻¹² m³ the run
wears, an approach of 5.4 µm). Other bodies (free, turning, dynamic,
half-space contact, no load, or a counter mesh that turns) keep the size
default: their contact is not known before the run.
"""

import numpy as np

from ..kernels.laws import LAWS
from ..kernels.rigid import BALANCED
from .active import MARGIN_FRACTION
from .base import quaternion_matrix

#: the margin over the approach a body's load and wear can reach
APPROACHES = 2.0
#: instants of a cycle at which the sliding distance is sampled
SLIDE_SAMPLES = 512


def size_margin(vertices):
    """The size default (m): :data:`MARGIN_FRACTION` of the bounding-box diagonal."""
    return MARGIN_FRACTION * float(np.linalg.norm(np.ptp(vertices, axis=0)))


def contact_margin(scene, config, vertices, area_vectors, pose, motion, surface_set):
    """The default active-set margin (m) of a body and why, one line.

    Parameters
    ----------
    scene : meshwear.scene.Scene
    config : meshwear.scene.BodyConfig
    vertices, area_vectors : (n, 3), (n, 4) float
        The body's vertices and area vectors, body frame (m, m²).
    pose : (13,) float
        Its pose at t = 0 (on its path, before any load balance).
    motion : meshwear.motion.Motion
        A :class:`~meshwear.motion.BalancedMotion` has the ``carried`` load.
    surface_set : meshwear.surfaces.SurfaceSet

    Returns
    -------
    (float, str)
    """
    size = size_margin(vertices)
    fallback = (size, f"{MARGIN_FRACTION:g} of the body's size")
    c = scene.contact
    # a quasi-static guided body (meshwear.motion.BalancedMotion) carries a load
    load = abs(float(motion.carried)) if motion.kind == BALANCED else 0.0
    if load <= 0.0 or motion.turn_rate != 0.0 or c.model == "half-space" or not surface_set.slots:
        return fallback
    # a turning mesh's shape invariance is judged against the margin
    # (MeshSurface.settle_invariance): a ring faceted by more than a quarter
    # of a contact-sized margin would be followed as it turns, at a cost
    if any(getattr(s.motion, "rate", 0.0) != 0.0 for s in surface_set.meshes):
        return fallback
    gap, area = _gaps(vertices, area_vectors, pose, surface_set, 2.0 * size)
    touching = np.isfinite(gap) & (area > 0.0)
    if not touching.any():
        return fallback
    lead = int(np.flatnonzero(touching)[np.argmin(gap[touching])])
    d = np.where(touching, gap - gap[lead], np.inf)
    if c.stiffness_per_area:
        elastic = _approach(d, area, load / c.stiffness_per_area)
    elif c.stiffness:
        elastic = _approach(d, np.where(touching, 1.0, 0.0), load / c.stiffness)
    else:
        return fallback
    slide = _sliding(scene, vertices[lead], pose, motion, surface_set)
    volume = _worn_volume(scene, load, slide, area[touching & (d <= size)])
    worn = _approach(d, area, volume)
    margin = APPROACHES * (elastic + worn)
    if not np.isfinite(margin) or margin >= size:
        return fallback
    return margin, (f"{APPROACHES:g} x the approach its load and wear reach "
                    f"({elastic + worn:.3g} m: {load:.3g} N, {volume:.3g} m3 worn over "
                    f"{slide:.3g} m of sliding)")


def _gaps(vertices, area_vectors, pose, surface_set, reach):
    """(n,) gap (m) of each vertex to its nearest surface at t = 0 along
    that surface's normal, and (n,) its contact area there (m², 0 where the
    vertex faces away)."""
    R = quaternion_matrix(pose[3:7])
    x = pose[0:3] + vertices @ R.T
    a = area_vectors[:, 0:3] @ R.T
    gap = np.full(len(vertices), np.inf)
    area = np.zeros(len(vertices))
    candidates = [((x - p[0]) @ p[1], np.broadcast_to(p[1], x.shape))
                  for p in surface_set.planes]
    for surface in surface_set.per_vertex:
        planes, distance = surface.planes_at(vertices, pose, 0.0, reach)
        g = np.einsum("ij,ij->i", x - planes[:, 0], planes[:, 1])
        candidates.append((np.where(np.isfinite(distance), g, np.inf), planes[:, 1]))
    for g, normal in candidates:
        closer = g < gap
        gap[closer] = g[closer]
        area[closer] = np.maximum(0.0, -np.einsum("ij,ij->i", a[closer], normal[closer]))
    return gap, area


def _approach(d, weight, target):
    """The smallest ``δ`` with ``Σ weight_i max(0, δ - d_i) = target``
    (piecewise linear and increasing in ``δ``); inf if the weights cannot."""
    if target <= 0.0:
        return 0.0
    use = np.isfinite(d) & (weight > 0.0)
    order = np.argsort(d[use])
    ds, ws = d[use][order], weight[use][order]
    if not len(ds):
        return np.inf
    # between breakpoints k and k+1: sum_{j<=k} w_j (δ - d_j) = W_k δ - M_k
    W, M = np.cumsum(ws), np.cumsum(ws * ds)
    at_next = W[:-1] * ds[1:] - M[:-1]          # the sum when δ reaches d_{k+1}
    k = int(np.searchsorted(at_next, target))   # the piece holding the target
    return float((target + M[k]) / W[k])


def _sliding(scene, lead, pose, motion, surface_set):
    """The sliding distance (m) over the run of the body's vertex ``lead``
    (body frame) relative to the surface it moves most against, from its path
    sampled over a cycle (or the whole run when nothing repeats)."""
    period = scene.wear.period or motion.path.period
    for s in surface_set.slots:
        if s.period is not None:
            period = max(period or 0.0, s.period)
    window = min(period, scene.run.duration) if period else scene.run.duration
    times = np.linspace(0.0, window, SLIDE_SAMPLES + 1)
    placed = pose.copy()
    world = np.empty((len(times), 3))
    for i, t in enumerate(times):
        motion.place(placed, t)
        world[i] = placed[0:3] + quaternion_matrix(placed[3:7]) @ lead
    slide = 0.0
    for s in surface_set.slots:
        local = np.empty_like(world)
        for i, t in enumerate(times):
            rotation, frame = s.motion.frame(t)
            local[i] = (world[i] - frame[0]) @ rotation
        moves = np.diff(local, axis=0)
        slide = max(slide, float(np.linalg.norm(moves, axis=1).sum()))
    return slide * scene.run.duration / window


def _worn_volume(scene, load, slide, areas):
    """The volume (m³) the body's wear law and every worn counter-surface's
    give for ``load`` (N) over ``slide`` (m), each part in full slip
    (friction energy ``mu N s``); ``areas`` (m²) the vertex areas of the
    contact (a depth law wears each of them)."""
    energy = scene.contact.friction * load * slide
    area = float(np.mean(areas)) if len(areas) else 0.0
    parts = [(scene.wear.law, scene.wear.coefficient)]
    parts += [(s.law or scene.wear.law,
               scene.wear.coefficient if s.coefficient is None else s.coefficient)
              for s in scene.surfaces if getattr(s, "wear", False)]
    return float(sum(LAWS[law].twin(k, energy, load, slide, area)[1] for law, k in parts))

