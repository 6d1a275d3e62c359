"""What a cycle jump may do to the mesh it moves (docs/model.md, "Long durations").

A jump moves each worn vertex by its extrapolated wear and a guided body
along its axis by the load balance's move, all at once, where a resolved
run moves them step by step and refreshes its contact as it goes. Two
bounds keep a jump within what its measurement can stand for:

reach
    the move brings no vertex into contact that the measurement did not
    see: a vertex outside a body's active set (or beyond the reach of the
    queries for its faces on a mesh surface) is not in the jump, so it
    does not wear there, and a move past its gap buries it under the
    surface while the vertices beside it, measured, wear to the surface
    and pass it (a 10 mm ball fretting to a 1.6 mm cap: a jump of 7 391
    cycles moved it 0.43 mm, 2.5 times its margin, and folded 215 faces
    at the cap's rim);
fold
    no face around the vertices the jump moves is taken more than
    :data:`FOLD` of the way to folding over: the jump's displacements, the
    whole of them over :data:`FOLD`, keep every such face's area along its
    unworn normal positive (what the run's check,
    :func:`meshwear.step.simulate.check`, asks of every worn face).
"""

import numpy as np

from ..surfaces import CULL_MARGIN, moved_since_refresh, quaternion_matrix
from ..surfaces.active import query_reach

#: a jump takes a face at most this fraction of the way to folding over:
#: its displacements, over this fraction, fold none (a vertex at the rim of
#: a cap worn flat on a sphere, its outer neighbour unworn, folds their
#: face only when moved 1 / sin^2(theta) times as far as wearing it flush
#: takes, theta the rim's slope: a jump that wears a rim sloping up to 45
#: degrees to the surface's shape is not cut)
FOLD = 0.5


def reach(model, body, s, t):
    """The least gap (m) of the vertices of ``body`` (state ``s`` at time
    ``t``) that a measurement does not see: those outside its active set,
    at least its margin away when it was refreshed less what the body has
    come towards a surface since
    (:func:`meshwear.surfaces.moved_since_refresh`), and, on a mesh
    surface, those without a face under them, beyond the queries' reach
    (:func:`meshwear.surfaces.active.query_reach`). inf where every vertex is
    measured (no active set)."""
    if not model.cull or len(s.active) == len(s.wear_depth):
        return np.inf
    out = float(s.cull[CULL_MARGIN]) - float(moved_since_refresh(model, body, s, t))
    if model.surfaces.meshes:
        out = min(out, float(query_reach(model, body, s)))
    return max(out, 0.0)


def fresh_direction(body, s, fresh, normal):
    """(k, 3) the direction (body frame) in which the vertices ``fresh``
    (mask) of ``body`` (state ``s``) wear, pressed by the surfaces of world
    ``normal`` (n, 3): the body's wear direction, or that normal."""
    if len(body.wear_direction):
        return body.wear_direction[fresh]
    return normal[fresh] @ quaternion_matrix(s.pose[3:7])


def displacement(body, s, vertices0, rate, wear, normal, window=1):
    """(n, 3) the move (m, body frame) a jump gives each vertex of ``body``
    (state ``s`` at the jump's start, its vertices ``vertices0`` at the
    start of the measurement of ``window`` cycles, in which they wore
    ``rate`` (n,) per cycle): its cycle's move scaled by its jump's
    ``wear`` (n,) over its cycle's wear, or, brought into contact by the
    jump (``normal`` (n, 3) world, or None: none are), its wear along its
    wear direction (:func:`meshwear.longrun.wear._jump` moves them so)."""
    factor = np.zeros(len(rate))
    wearing = rate > 0.0
    factor[wearing] = wear[wearing] / (rate[wearing] * window)
    out = factor[:, None] * (s.vertices - vertices0)
    fresh = ~wearing & (wear > 0.0)
    if fresh.any() and normal is not None:
        out[fresh] = wear[fresh, None] * fresh_direction(body, s, fresh, normal)
    return out


def fold_room(body, vertices, move):
    """The smallest multiple of ``move`` (n, 3) (m, body frame) that folds a
    face of ``body`` round the vertices it moves: at which the face's area
    along its unworn normal, from ``vertices`` (n, 3), comes to zero; inf
    where none does. Faces already folded (a check refuses them) are left
    out.

    Along ``vertices + f move`` a face ``(i, j, k)``, with ``e1 = x_j -
    x_i``, ``e2 = x_k - x_i`` and their moves ``d1``, ``d2``, has the area
    ``n . (e1 + f d1) x (e2 + f d2) / 2``, a quadratic in ``f``: its first
    positive root."""
    moved = np.any(move != 0.0, axis=1)
    around = np.flatnonzero(moved[body.faces].any(axis=1))
    if not len(around):
        return np.inf
    faces = body.faces[around]
    normal = body.reference_face_normals[around]
    x, u = vertices[faces], move[faces]
    e1, e2 = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]
    d1, d2 = u[:, 1] - u[:, 0], u[:, 2] - u[:, 0]
    c = np.einsum("ij,ij->i", np.cross(e1, e2), normal)
    b = np.einsum("ij,ij->i", np.cross(e1, d2) + np.cross(d1, e2), normal)
    a = np.einsum("ij,ij->i", np.cross(d1, d2), normal)
    keep = c > 0.0
    return float(_first_root(a[keep], b[keep], c[keep]).min(initial=np.inf))


def _first_root(a, b, c):
    """(m,) the least positive root of ``a f^2 + b f + c`` (``c`` > 0), inf
    where it has none. The roots as ``q / a`` and ``c / q``, ``q = -(b +
    sign(b) sqrt(b^2 - 4 a c)) / 2``, which lose no digits when ``a`` is
    small (a face whose vertices move nearly alike: the quadratic is a
    line)."""
    disc = b * b - 4.0 * a * c
    real = disc >= 0.0
    q = -0.5 * (b + np.where(b >= 0.0, 1.0, -1.0) * np.sqrt(np.where(real, disc, 0.0)))
    out = np.full(len(c), np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        for root in (np.where(a != 0.0, q / a, np.inf), np.where(q != 0.0, c / q, np.inf)):
            positive = real & (root > 0.0)
            out[positive] = np.minimum(out[positive], root[positive])
    return out


def cut(model, states, before, rates, results, measures, window, reaches=None):
    """Whether a jump's ``results`` (per body ``(wear, move, error)``,
    :func:`meshwear.longrun.jump_choice._choose_implicit`'s) stay within what the mesh
    they move allows: None, or the bound they break and the share of the
    jump it allows (the move and the vertices' moves scaled down alike).
    ``reach``: a guided body's move along its axis past ``reaches`` (per
    body, :func:`reach`); ``fold``: a face taken past :data:`FOLD` of the
    way to folding over. ``states``: the bodies at the jump's start,
    ``before`` their arrays at the start of the measurement of ``window``
    cycles in which they wore ``rates`` (per body (n,), m per cycle);
    ``measures`` their :class:`meshwear.longrun.jumps.BodyJump`, or None (explicit:
    no vertex comes into contact)."""
    worst = None
    for k, (body, s, b, rate, (wear, move, _)) in enumerate(
            zip(model.bodies, states, before, rates, results)):
        allowed = []
        if reaches is not None and move and abs(move) > reaches[k]:
            allowed.append(("reach", reaches[k] / abs(move)))
        normal = None
        if measures is not None:
            normal = np.zeros((len(rate), 3))
            normal[measures[k].index] = measures[k].normal
        room = FOLD * fold_room(body, s.vertices,
                                displacement(body, s, b[1], rate, wear, normal, window))
        if room < 1.0:
            allowed.append(("fold", room))
        for bound in allowed:
            if worst is None or bound[1] < worst[1]:
                worst = bound
    return worst
