"""Which faces a part's ``resolution`` refines (docs/scene-format.md,
"resolution"): a body's where it can meet a surface, a mesh surface's where
a body can reach it over the run.

Each selection is handed to :func:`meshwear.remesh.refine`, with what it
surely refines (``surely``: faces; ``within``: points), so that a resolution
too fine for the machine is refused from an estimate before the passes that
would fill the memory (docs/outputs.md, "Limits checked before any work").
"""

import numpy as np

from . import geometry, remesh, surfaces
from .kernels.contact import rotation_entries
from .motion import Path
from .surfaces.base import quaternion_matrix

#: a face of a body that is not free can come into contact where it faces a
#: surface within this fraction of the body's bounding-box diagonal
REFINE_REACH = 0.1
#: a worn surface's reach is sampled at this many instants at least, and at
#: most at this many: denser until no body vertex moves farther than the
#: margin between two of them
REACH_SAMPLES = (64, 4096)
#: points of the bodies' sweep kept at most; a larger sweep (a finely refined
#: body sampled at thousands of instants: 10^8 points and more) is thinned to
#: one point per cell of :data:`THIN_CELL` margins, its reach grown by the
#: half-diagonal of a cell
CLOUD_POINTS = 2**22
THIN_CELL = 0.25
#: points of the coarsest samples the early refusal looks at, at most (a
#: body's every k-th vertex beyond: a lower bound still)
EARLY_POINTS = 2**19
#: points of the sweep transformed at once (memory: 24 B each, a few times)
CHUNK_POINTS = 2**20


def faces_to_refine(scene, body, vertices, faces, surface_set):
    """Faces ``resolution`` refines: all of a free body (it may land on any
    face); of a guided, prescribed or fixed one (which only translates) the
    faces that face a surface within :data:`REFINE_REACH` of its size at the
    start (its path's displacement included); all of one that turns.

    With ``resolution_reach`` given, the faces within it, chosen anew at
    each pass of the refinement (:func:`meshwear.remesh.refine`) on the
    part's true surface (a primitive's vertices put on it, each face's sag
    allowed for): the faces of a coarse sphere are a millimetre wide, and
    taken whole a 10 mm ball with a 20 µm reach had 200 000 vertices refined
    to 7 µm over 9 mm² where its cap within reach is 1.3 mm²."""
    if body.motion in ("free", "mechanism") or (body.path is not None
                                                and body.path.rotation is not None):
        return None
    R = np.array(rotation_entries(np.asarray(body.orientation, float))).reshape(3, 3)
    offset = np.asarray(body.position, float) + Path(body.path).displacement(0.0)
    reach = body.resolution_reach
    if reach is None:
        reach = REFINE_REACH * float(np.linalg.norm(np.ptp(vertices, axis=0)))
        return surfaces.contact_faces(vertices @ R.T + offset, faces, surface_set, reach)

    def select(vertices, faces, every=False):
        true = geometry.snap_to_primitive(body.shape, vertices, faces)
        sag = None if every else geometry.facet_sag(body.shape, true, faces)
        return surfaces.contact_faces(true @ R.T + offset, faces, surface_set, reach, sag,
                                      every)

    # (the faces wholly within reach are surely refined: too fine a
    # resolution is refused from them at each pass, not after the passes
    # have filled the memory)
    select.surely = lambda vertices, faces: select(vertices, faces, every=True)
    return select


def surface_faces_to_refine(scene, surface, bodies, periods, resolution):
    """Which faces of a mesh surface ``resolution`` (m) refines, as a
    selection made anew at each pass of the refinement: those within the
    active-set margin of a body at some instant of the run (sampled over one
    cycle when the moving parts share one period, else over the run, until
    no vertex moves more than the margin between samples; their spacing
    added to the margin). None (all faces) if a body is free (it may land
    anywhere) or moves too fast to sample. ``periods`` (s): the cycles of
    the scene's motions.

    The selection's ``within(points)`` says which points of the surface lie
    within that reach: every face holding one is refined whatever the
    passes, the area :func:`meshwear.remesh.refine` estimates its size from.
    The same estimate from the coarsest samples refuses too fine a
    resolution before the finer ones are taken.

    Raises
    ------
    geometry.MeshError
        For a resolution too fine for this machine."""
    from scipy.spatial import cKDTree

    if any(b.motion.dynamic_axes == "all" for b in bodies) or getattr(surface, "rider", False):
        return None
    window = _window(scene, periods)
    low, high = surface.vertices.min(axis=0), surface.vertices.max(axis=0)
    sweeps = _coarsest(scene, surface, bodies, window)
    _refuse_early(surface, sweeps, low, high, resolution)
    clouds, reach = [], 0.0
    for b, margin, moves in sweeps:
        n = REACH_SAMPLES[0]
        while True:
            step = _largest_step(b.reference_vertices, *moves)
            if step <= margin or n >= REACH_SAMPLES[1]:
                break
            n *= 2
            moves = _relative_moves(b, surface, np.linspace(0.0, window, n + 1))
        if step > 4.0 * margin:
            return None
        r = margin + 0.5 * step
        cloud, grown = _swept_cloud(b.reference_vertices, *moves, low - r, high + r,
                                    THIN_CELL * margin)
        clouds.append(cloud)
        reach = max(reach, r + grown)
    cloud = np.concatenate(clouds)
    if not len(cloud):
        return np.zeros(len(surface.faces), bool)
    index = cKDTree(cloud, balanced_tree=False, compact_nodes=False)

    def select(vertices, faces):
        # a face is within reach of a point if its centre is within reach
        # and the face's own size of it
        tri = vertices[faces]
        centre = tri.mean(axis=1)
        size = np.linalg.norm(tri - centre[:, None], axis=2).max(axis=1)
        return _within(index, centre, reach + size)

    # (a face holding such a point has its centre within reach + size of it)
    select.within = lambda points: index.query(points, distance_upper_bound=reach)[0] <= reach
    return select


def _window(scene, periods):
    """The time (s) the bodies' sweep is sampled over: one cycle when the
    moving parts share one period, else the run."""
    periods = {round(p, 12) for p in periods}
    window = scene.run.duration
    if len(periods) == 1:
        window = min(window, periods.pop())
    return window


def _coarsest(scene, surface, bodies, window):
    """``(body, margin, moves)`` of each body at the coarsest samples of its sweep."""
    return [(b, surfaces.margin_of(scene, b),
             _relative_moves(b, surface, np.linspace(0.0, window, REACH_SAMPLES[0] + 1)))
            for b in bodies]


def refuse_early(scene, surface, bodies, periods, resolution):
    """Refuse a mesh surface's ``resolution`` (m) too fine for this machine
    before any part is refined, from the coarsest samples of ``bodies``'
    sweep (their meshes as given: the vertices of a refined body include
    them, its margin is no smaller): :func:`_refuse_early`. Nothing to refuse
    where :func:`surface_faces_to_refine` takes every face (its refinement
    checks their whole area at once).

    Raises
    ------
    geometry.MeshError
        For a resolution too fine for this machine."""
    if any(b.motion.dynamic_axes == "all" for b in bodies) or getattr(surface, "rider", False):
        return
    low, high = surface.vertices.min(axis=0), surface.vertices.max(axis=0)
    _refuse_early(surface, _coarsest(scene, surface, bodies, _window(scene, periods)), low,
                  high, resolution)


def _refuse_early(surface, sweeps, low, high, resolution):
    """Refuse ``resolution`` from the coarsest samples of the bodies' sweeps
    (``(body, margin, moves)``): the surface within the smallest margin of
    their vertices at those instants (of :data:`EARLY_POINTS` at most) is
    within reach of the finer samples too (the instants are among theirs),
    so refined whatever the passes do."""
    from scipy.spatial import cKDTree

    near = min(margin for _, margin, _ in sweeps)
    clouds = []
    for b, _, (M, c) in sweeps:
        vertices = b.reference_vertices
        vertices = vertices[::max(1, -(-len(vertices) * len(c) // EARLY_POINTS))]
        clouds.append(_swept_cloud(vertices, M, c, low - near, high + near, None)[0])
    cloud = np.concatenate(clouds)
    if not len(cloud):
        return
    index = cKDTree(cloud, balanced_tree=False, compact_nodes=False)
    tri = surface.vertices[surface.faces]
    lo, hi = cloud.min(axis=0) - near, cloud.max(axis=0) + near
    faces = surface.faces[np.all((tri.max(axis=1) >= lo) & (tri.min(axis=1) <= hi), axis=1)]
    area = remesh.sampled_area(
        surface.vertices, faces,
        lambda points: index.query(points, distance_upper_bound=near)[0] <= near,
        np.random.default_rng(0))
    remesh.check_area(area, resolution)


def _within(index, points, bound):
    """(k,) bool: whether each of ``points`` has a point of the tree
    ``index`` within its ``bound`` (m). Asked in groups of bounds within a
    factor 2, each no farther than its largest: a search with no bound from
    a point far from the cloud (the centre of a face a kilometre long) goes
    through much of the tree."""
    out = np.zeros(len(points), bool)
    if not len(points):
        return out
    group = np.floor(np.log2(np.maximum(bound, np.finfo(float).tiny))).astype(np.int64)
    for g in np.unique(group):
        take = np.flatnonzero(group == g)
        # (a bound the search may take as strict: one ulp farther)
        far = float(np.nextafter(bound[take].max(), np.inf))
        out[take] = index.query(points[take], distance_upper_bound=far)[0] <= bound[take]
    return out


def _relative_moves(body, surface, times):
    """Where ``body`` is in ``surface``'s frame at ``times``: a body vertex
    ``v`` (body frame) is at ``v @ M[i] + c[i]`` there, with ``M`` (k, 3, 3)
    and ``c`` (k, 3)."""
    pose = body.initial_pose.copy()
    M, c = np.empty((len(times), 3, 3)), np.empty((len(times), 3))
    for i, t in enumerate(times):
        body.motion.place(pose, t)
        rotation, frame = surface.motion.frame(t)
        M[i] = quaternion_matrix(pose[3:7]).T @ rotation
        c[i] = (pose[0:3] - frame[0]) @ rotation
    return M, c


def _chunks(vertices, count):
    """Slices of instants of about :data:`CHUNK_POINTS` points of ``vertices`` each."""
    size = max(1, CHUNK_POINTS // max(len(vertices), 1))
    return [slice(i, min(i + size, count)) for i in range(0, count, size)]


def _largest_step(vertices, M, c):
    """The farthest (m) any of ``vertices`` moves between two instants."""
    dM, dc = np.diff(M, axis=0), np.diff(c, axis=0)
    step = 0.0
    for part in _chunks(vertices, len(dc)):
        moved = np.matmul(vertices, dM[part]) + dc[part, None, :]
        step = max(step, float(np.sqrt(np.einsum("tvk,tvk->tv", moved, moved).max())))
    return step


def _swept_cloud(vertices, M, c, low, high, cell):
    """The points of ``vertices`` at every instant within the box ``low`` ..
    ``high``, and how much (m) the reach must grow for them: 0, or beyond
    :data:`CLOUD_POINTS` the half-diagonal of the ``cell`` (m) they are
    thinned to (one point per cell, at its centre; None: never thinned)."""
    kept, count, thinned = [], 0, False
    for part in _chunks(vertices, len(c)):
        points = (np.matmul(vertices, M[part]) + c[part, None, :]).reshape(-1, 3)
        points = points[np.all((points >= low) & (points <= high), axis=1)]
        if cell is not None and (thinned or count + len(points) > CLOUD_POINTS):
            if not thinned:
                kept, thinned = [_thin(np.concatenate(kept + [points]), low, cell)], True
            else:
                kept = [_thin(np.concatenate(kept + [points]), low, cell)]
            count = len(kept[0])
        else:
            kept.append(points)
            count += len(points)
    cloud = np.concatenate(kept) if kept else np.zeros((0, 3))
    return cloud, (0.5 * np.sqrt(3.0) * cell if thinned else 0.0)


def _thin(points, origin, cell):
    """One point per occupied cube of side ``cell`` (m), at its centre (the
    points' cells counted from ``origin``)."""
    cell = max(cell, 2.0**-40 * float(np.ptp(points, axis=0).max(initial=0.0)))  # keys in int64
    keys = np.unique(np.floor((points - origin) / cell).astype(np.int64), axis=0)
    return origin + (keys + 0.5) * cell
