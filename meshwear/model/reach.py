"""Which faces a part's ``resolution`` refines (docs/scene-format.md,
"resolution"): a body's where it can meet a surface, a mesh surface's where
a body can reach it over the run.

Each selection is handed to :func:`meshwear.geometry.remesh.refine`, with what it
surely refines (``surely``: faces; ``within``: points), so that a resolution
too fine for the machine is refused from an estimate before the passes that
would fill the memory (docs/outputs.md, "Limits checked before any work").
"""

import numpy as np

from .. import geometry, surfaces
from ..geometry import meshes, remesh
from ..kernels.contact import rotation_entries
from ..motion.motions import Path
from ..surfaces.base import quaternion_matrix

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
#: points drawn on a refined body's faces for the early refusal, at most,
#: over the coarsest samples' instants (its coarse vertices can all lie
#: beyond a surface's reach: a shaft's two rims, a bushing shorter than it)
FACE_POINTS = 2**17
#: the drawn points nearest a point of the surface that it is tried against
FACE_NEIGHBOURS = 16


def faces_to_refine(scene, body, vertices, faces, surface_set):
    """Faces ``resolution`` refines: all of a free body (it may land on any
    face); of a guided, prescribed or fixed one (which only translates) the
    faces that face a surface within :data:`REFINE_REACH` of its size at the
    start (its path's displacement included); all of one that turns.

    With ``resolution_reach`` given, the faces within it, chosen anew at
    each pass of the refinement (:func:`meshwear.geometry.remesh.refine`) on the
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
    passes, the area :func:`meshwear.geometry.remesh.refine` estimates its size from.
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


def refuse_early(scene, surface, bodies, periods, resolution, drawn=None):
    """Refuse a mesh surface's ``resolution`` (m) too fine for this machine
    before any part is refined, from the coarsest samples of ``bodies``'
    sweep (their meshes as given: the vertices of a refined body include
    them, its margin is no smaller) and from ``drawn``, each body's
    :func:`refined_faces` (None where it is not refined):
    :func:`_refuse_early`. Nothing to refuse where
    :func:`surface_faces_to_refine` takes every face (its refinement checks
    their whole area at once).

    Raises
    ------
    geometry.MeshError
        For a resolution too fine for this machine."""
    if any(b.motion.dynamic_axes == "all" for b in bodies) or getattr(surface, "rider", False):
        return
    low, high = surface.vertices.min(axis=0), surface.vertices.max(axis=0)
    _refuse_early(surface, _coarsest(scene, surface, bodies, _window(scene, periods)), low,
                  high, resolution, drawn)


def refined_faces(scene, config, body, surface_set):
    """What body ``config``'s ``resolution`` surely makes of its mesh as
    given (``body``, its :class:`meshwear.model.BodyModel` unrefined), for
    :func:`refuse_early`; None without a resolution: ``(faces, spacing,
    snap)``. ``faces`` (k, 3): the faces it refines whatever its passes do
    (:func:`faces_to_refine`: all, those facing a surface, those wholly
    within ``resolution_reach``); every point of one lies within
    ``spacing`` (m) of a vertex of the refined mesh in the face's own plane
    (a triangle with edges <= e has no point farther than e / sqrt 3 from
    its corners; bisection and the flips between coplanar faces keep the
    faces' planes); ``snap`` (m): how far such a vertex may then move onto
    a sphere's or cylinder's true surface (the facets' depth under it)."""
    if config.resolution is None:
        return None
    faces = body.faces
    given = body.reference_vertices - body.origin          # the mesh's own frame
    select = faces_to_refine(scene, config, given, faces, surface_set)
    if callable(select):
        faces = faces[select.surely(given, faces)]
    elif select is not None:
        faces = faces[select]
    snap = 0.0
    shape = config.shape
    if shape is not None and shape.type in ("sphere", "cylinder") and len(faces):
        # a facet's plane is |n . v| from the centre (a sphere) or the axis
        # (a cylinder's side; its caps' vertices move only on the rim)
        normals = geometry.face_normals(given, faces)
        depth = shape.radius - np.abs(np.einsum("ij,ij->i", normals, given[faces[:, 0]]))
        if shape.type == "cylinder":
            depth = depth[np.abs(normals[:, 2]) < geometry.SIDE]
        snap = float(max(depth.max(initial=0.0), 0.0))
    return faces, float(config.resolution) / np.sqrt(3.0), snap


def _reach_at_least(sweeps):
    """A lower bound (m) of the reach :func:`surface_faces_to_refine` finds
    from the bodies of ``sweeps`` (``(body, margin, moves)`` at the coarsest
    samples) or finer ones holding their vertices: each body's margin and
    half its largest step between instants, and that step is at least the
    one of these vertices at the coarsest samples when it stops there, and
    more than half the margin when it doubles them (the step over one
    interval of n is at most twice that over one of 2n)."""
    return max(margin + 0.5 * min(_largest_step(_early_vertices(b, c), M, c), 0.5 * margin)
               for b, margin, (M, c) in sweeps)


def _early_vertices(body, instants):
    """``body``'s vertices, every k-th of them beyond :data:`EARLY_POINTS`
    over ``instants``: what the early refusal looks at (the step and the
    reach of fewer vertices are no larger)."""
    vertices = body.reference_vertices
    return vertices[::max(1, -(-len(vertices) * len(instants) // EARLY_POINTS))]


def _refuse_early(surface, sweeps, low, high, resolution, drawn=None):
    """Refuse ``resolution`` from the coarsest samples of the bodies' sweeps
    (``(body, margin, moves)``): the surface within :func:`_reach_at_least`
    of their vertices at those instants (of :data:`EARLY_POINTS` at most)
    is within reach of the finer samples too (the instants are among
    theirs), so refined whatever the passes do. So is the surface near a
    refined body's faces (``drawn``: each body's :func:`refined_faces` or
    None): :func:`_near_faces`."""
    found = _early_within(sweeps, low, high, drawn)
    if found is None:
        return
    within, lo, hi = found
    tri = surface.vertices[surface.faces]
    faces = surface.faces[np.all((tri.max(axis=1) >= lo) & (tri.min(axis=1) <= hi), axis=1)]
    area = remesh.sampled_area(surface.vertices, faces, within, np.random.default_rng(0))
    remesh.check_area(area, resolution)


def _early_within(sweeps, low, high, drawn=None):
    """``(within, lo, hi)`` of :func:`_refuse_early`: ``within(points)``
    ((k,) bool) says which points are surely within the reach of the bodies'
    sweep; none lies outside the box ``lo`` .. ``hi``. None if no part of
    the sweep comes near the box ``low`` .. ``high``."""
    from scipy.spatial import cKDTree

    near = _reach_at_least(sweeps)
    drawn = drawn or [None] * len(sweeps)
    clouds, faces_near = [], []
    for (b, _, (M, c)), made in zip(sweeps, drawn):
        clouds.append(_swept_cloud(_early_vertices(b, c), M, c, low - near, high + near,
                                   None)[0])
        if made is not None:
            faces_near.append(_drawn_cloud(b.reference_vertices, *made, M, c, low - near,
                                           high + near, near))
    cloud = np.concatenate(clouds)
    drawn_cloud = [np.concatenate(parts) for parts in zip(*faces_near)] if faces_near else None
    every = cloud if drawn_cloud is None else np.concatenate([cloud, drawn_cloud[0]])
    if not len(every):
        return None
    index = cKDTree(cloud, balanced_tree=False, compact_nodes=False) if len(cloud) else None
    near_faces = _near_faces(*drawn_cloud, near) if drawn_cloud and len(drawn_cloud[0]) else None

    def within(points):
        out = np.zeros(len(points), bool)
        if index is not None:
            out |= index.query(points, distance_upper_bound=near)[0] <= near
        if near_faces is not None:
            out |= near_faces(points)
        return out

    return within, every.min(axis=0) - near, every.max(axis=0) + near


def _drawn_cloud(vertices, faces, spacing, snap, M, c, low, high, reach):
    """Points drawn by area on a body's ``faces`` (of ``vertices``, its
    frame; :data:`FACE_POINTS` over all the instants of ``M``, ``c``), at
    each instant, with their faces' normals there, within the box ``low`` ..
    ``high``: ``(points, normals, spacing, room)``, each point's
    ``spacing`` (m) and the reach left once the refined vertex near it
    has moved by ``snap`` (``room``, m)."""
    per = max(1, FACE_POINTS // len(c))
    areas = 0.5 * meshes._doubled_areas(vertices, faces)
    total = float(areas.sum())
    empty = np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0)
    if not (total > 0.0 and reach > snap):
        return empty
    drawn, pick = remesh.points_on_faces(vertices, faces, areas, per, np.random.default_rng(0))
    normals = geometry.face_normals(vertices, faces[pick])
    points = (np.matmul(drawn, M) + c[:, None, :]).reshape(-1, 3)
    turned = np.matmul(normals, M).reshape(-1, 3)
    keep = np.all((points >= low) & (points <= high), axis=1)
    k = int(keep.sum())
    return points[keep], turned[keep], np.full(k, spacing), np.full(k, reach - snap)


def _near_faces(points, normals, spacing, room, reach):
    """``within(q)`` for the drawn points of refined faces (:func:`_drawn_cloud`):
    whether a point ``q`` is within ``reach`` of a vertex of the refined
    mesh, sure from one drawn point ``p`` of normal ``n`` near it. That
    vertex lies within ``spacing`` of ``p`` in its face's plane, then moves
    by the snap, ``reach`` less ``room``: it is at most
    sqrt(d_n² + (d_t + spacing)²) + snap from ``q``, d_n and d_t the parts
    of ``q - p`` along ``n`` and across it, so within reach where the root
    is within ``room`` (the plain distance would ask for spacing + snap
    less than the reach: a 0.25 mm shaft's spacing 0.14 mm of a 0.19 mm
    reach, 50 µm from the bore)."""
    from scipy.spatial import cKDTree

    index = cKDTree(points, balanced_tree=False, compact_nodes=False)
    k = min(FACE_NEIGHBOURS, len(points))

    def within(q):
        _, found = index.query(q, k=k, distance_upper_bound=reach)
        found = found.reshape(len(q), k)
        valid = found < len(points)
        at = np.where(valid, found, 0)
        d = q[:, None, :] - points[at]
        normal = np.einsum("ijk,ijk->ij", d, normals[at])
        across = np.sqrt(np.maximum(np.einsum("ijk,ijk->ij", d, d) - normal**2, 0.0))
        return np.any(valid & (normal**2 + (across + spacing[at])**2 <= room[at]**2), axis=1)

    return within


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
    keys = np.floor((points - origin) / cell).astype(np.int64)
    if len(keys) and keys.min() >= 0 and keys.max() < 2**21:
        # three keys in one int64, in the same order (numpy's unique of rows
        # sorts them as records: 11 s for a refined shaft's 10^7 points)
        packed = np.unique((keys[:, 0] << 42) | (keys[:, 1] << 21) | keys[:, 2])
        keys = np.stack([packed >> 42, (packed >> 21) & (2**21 - 1), packed & (2**21 - 1)],
                        axis=1)
    else:
        keys = np.unique(keys, axis=0)
    return origin + (keys + 0.5) * cell
