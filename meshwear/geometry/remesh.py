"""Conforming refinement of triangle meshes (longest-edge bisection), and
the comparison of two parts' spacings where they touch (``meshwear check``'s
notice: :func:`spacing_notices`).

Plain arrays in and out, as in :mod:`meshwear.geometry` (which this module
builds on and which does not import it); :func:`spacing_notices` alone
reads a model.
"""

import numpy as np

from .. import geometry
from .meshes import MeshError, _arrays, _doubled_areas, _edge_keys, _edge_lengths, spatial_order

#: area of the largest triangle whose edges are all <= 1 (equilateral)
_LARGEST_UNIT_TRIANGLE = np.sqrt(3.0) / 4.0

#: faces refined at most, whatever the memory
MAX_FACES = 5_000_000
#: memory a face of a refined part takes while the model is built (B):
#: measured ~650 on a refined pin against a plane (peak RSS of build_model
#: over 0.2-0.9 M faces), with room for more counter-surfaces
BYTES_PER_FACE = 1024


def available_memory():
    """Bytes of memory the system can give without swapping (None if unknown)."""
    try:
        import psutil

        return int(psutil.virtual_memory().available)
    except Exception:  # noqa: BLE001 - psutil missing or unsupported here
        pass
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return None


def face_limit(memory=None):
    """``(faces, why)``: the most faces a refinement may make here, the smaller
    of :data:`MAX_FACES` and what the available memory holds at
    :data:`BYTES_PER_FACE`, and the reason a refusal gives."""
    memory = available_memory() if memory is None else memory
    if memory is not None and memory // BYTES_PER_FACE < MAX_FACES:
        return int(memory // BYTES_PER_FACE), (f"what this machine's {memory / 2**30:.3g} GiB of "
                                               f"available memory holds at about "
                                               f"{BYTES_PER_FACE} B a face")
    return MAX_FACES, "the largest refinement meshwear makes"


def refine(vertices, faces, resolution, face_mask=None, max_faces=None, return_mask=False):
    """Split triangles until every edge of the selected faces is <= ``resolution``.

    Conforming longest-edge bisection (Rivara): a face that needs refining has
    its longest edge split; a selected face that shares a split edge has its
    own longest edge split too (closure), then each face is cut along its split
    edges. An unselected face with one split edge is cut along it, towards its
    opposite corner, and nothing more: the refinement does not grade into the
    faces that cannot touch (a block's side walls keep tall triangles next to
    its worn face, which the wear of that face cannot invert). No T-junctions
    are left, so a closed mesh stays closed. After each pass,
    Delaunay edge flips between coplanar selected faces keep the triangles well
    shaped, so a long thin CAD triangle costs about what a well-shaped face of
    the same area does. The surface itself never changes. The vertices and
    faces of a mesh it refined come out sorted along a Morton curve
    (:func:`meshwear.geometry.spatial_order`: the face lookups and the
    contact loop then read memory nearby).

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    resolution : float
        Largest edge length allowed on selected faces (m).
    face_mask : (m,) bool or callable, optional
        Faces to refine (default all). Children of selected faces stay selected;
        unselected faces are split only where needed to stay conforming. A
        callable ``face_mask(vertices, faces)`` selects anew after each pass
        (a big face of which only a part is to be refined: its children
        away from that part are left); its attributes ``surely(vertices,
        faces)`` (the faces it refines whatever the passes) and
        ``within(points)`` ((k,) bool: points every face holding which it
        refines), if it has them, give the area checked against
        ``max_faces`` before each pass (:func:`_surely_refined_area`).
    max_faces : int, optional
        Refuse (MeshError) rather than build a larger mesh: before a pass
        when the area surely refined alone needs more faces (a triangle with
        edges <= ``resolution`` covers sqrt(3)/4 resolution² at most), or
        the edges of the faces surely refined do (:func:`_edge_faces`: a fan
        of slivers), else as soon as a pass makes more. Default:
        :func:`face_limit` (this machine's available memory, at most
        :data:`MAX_FACES`).
    return_mask : bool
        Also return which faces come from selected ones.

    Returns
    -------
    vertices : (k, 3) float
    faces : (l, 3) int
    mask : (l,) bool, if ``return_mask``
    """
    V, F = _arrays(vertices, faces)
    if not resolution > 0:
        raise ValueError(f"resolution must be positive, got {resolution!r}")
    select = face_mask if callable(face_mask) else None
    mask = (np.ones(len(F), bool) if face_mask is None else select(V, F) if select is not None
            else np.asarray(face_mask, bool).copy())
    if mask.shape != (len(F),):
        raise ValueError(f"face_mask has shape {mask.shape}, expected ({len(F)},)")
    why = "the limit asked"
    if max_faces is None:
        max_faces, why = face_limit()
    rng = np.random.default_rng(0)        # seeded: the same refusal every time
    first_count = len(F)
    while True:
        if select is not None and len(F) > first_count:
            mask = select(V, F)
        # before each pass: the area surely refined needs this many faces at
        # least, and so do the edges of the faces refined whole (a fixed
        # selection's are known before the first; one made anew each pass
        # knows more of them as its faces shrink to the part within reach)
        lengths = _edge_lengths(V, F)
        if select is not None or len(F) == first_count:
            area, whole = _surely_refined_area(V, F, mask, select, rng)
            check_area(area, resolution, max_faces, why, _edge_faces(lengths, whole, resolution))
        need = mask & (lengths.max(axis=1) > resolution)
        if not need.any():
            # a mesh it refined comes out in space order; one it did not, as it was
            if len(F) > first_count:
                V, F, by_face = spatial_order(V, F)
                mask = mask[by_face]
            V, F = _arrays(V, F)
            return (V, F, mask) if return_mask else (V, F)
        longest = lengths.argmax(axis=1)
        edges, eid = np.unique(_edge_keys(F, len(V)), return_inverse=True)
        eid = eid.reshape(-1, 3)
        rows = np.arange(len(F))
        marked = np.zeros(len(edges), bool)
        marked[eid[need, longest[need]]] = True
        while True:
            # closure: a selected face with any split edge has its longest
            # edge split too (Rivara); an unselected one only when two of its
            # edges are split: with one, it is cut along that edge (green)
            count = marked[eid].sum(axis=1)
            bad = (count > (~mask).astype(np.int64)) & ~marked[eid[rows, longest]]
            if not bad.any():
                break
            marked[eid[bad, longest[bad]]] = True
        midpoint = np.full(len(edges), -1, np.int64)
        midpoint[marked] = len(V) + np.arange(marked.sum())
        ends = np.stack(np.divmod(edges[marked], len(V)), axis=1)
        V = np.concatenate([V, 0.5 * (V[ends[:, 0]] + V[ends[:, 1]])])
        F, mask, first_new = _bisect(F, mask, eid, midpoint, marked, longest)
        active = np.zeros(len(F), bool)
        active[first_new:] = True
        F = _flip_coplanar(V, F, mask, active)
        if len(F) > max_faces:
            raise MeshError(f"refining to resolution {resolution:g} m needs more than {max_faces} "
                            f"faces ({why}); give a coarser resolution")


#: points drawn on a selection's faces to estimate the area within its reach
AREA_SAMPLES = 4096


def check_area(area, resolution, max_faces=None, why="the limit asked", faces=0.0):
    """Refuse (MeshError) to refine ``area`` (m²) to ``resolution`` (m) when
    it needs more than ``max_faces`` faces (default: :func:`face_limit`): a
    triangle with edges <= ``resolution`` covers sqrt(3)/4 resolution² at
    most, so no refinement of it makes fewer; nor fewer than ``faces``, a
    bound known otherwise (:func:`_edge_faces`)."""
    if max_faces is None:
        max_faces, why = face_limit()
    cell = _LARGEST_UNIT_TRIANGLE * resolution**2     # 0.0 for a subnormal resolution
    least = max(area / cell if cell > 0.0 else float("inf"), faces)
    if not least <= max_faces:
        raise MeshError(f"refining to resolution {resolution:g} m needs at least {least:.3g} "
                        f"faces, more than {max_faces} ({why}); give a coarser resolution")


def _surely_refined_area(V, F, mask, select, rng):
    """``(area, faces)``: the area (m²) that the refinement refines whatever
    its passes do and the faces ((m,) bool) it refines whole: the selected
    faces (a fixed selection), else what the selection says it surely
    refines: the faces of its ``surely(V, F)``, or the part of the selected
    faces where its ``within(points)`` holds (:func:`sampled_area`: a thin
    band across big faces is missed at first, and seen once the passes have
    cut them near it; no face whole)."""
    if select is None:
        return 0.5 * float(_doubled_areas(V, F[mask]).sum()), mask
    area, whole = 0.0, np.zeros(len(F), bool)
    surely = getattr(select, "surely", None)
    if surely is not None:
        whole = surely(V, F)
        area = 0.5 * float(_doubled_areas(V, F[whole]).sum())
    within = getattr(select, "within", None)
    if within is not None:
        area = max(area, sampled_area(V, F[mask], within, rng))
    return area, whole


def _edge_faces(lengths, whole, resolution):
    """Faces a conforming refinement makes at least, from the edges
    (``lengths`` (m, 3) m) of the faces ``whole`` ((m,) bool) that it
    refines to ``resolution`` (m): such an edge of length L is cut in
    ceil(L / resolution) pieces at least; each piece is an edge of a face
    on either side of it (no T-junctions), and a face has three edges.
    Counted from each face's side (an edge between a face refined whole and
    another counts one piece on the other's: fewer, still a bound). A
    cylinder's cap of n slivers, or its side of n facets, makes about
    4/3 n L / resolution faces where its area asks for a few hundred (a
    shaft of 100 000 sections at 0.25 mm: 5.5 million, refused after 67 s
    at the pass that made more than the limit)."""
    with np.errstate(over="ignore"):
        pieces = np.ceil(lengths[whole] / resolution).sum()
    return float(pieces + 3.0 * np.count_nonzero(~whole)) / 3.0


def points_on_faces(vertices, faces, areas, count, rng):
    """``count`` points drawn uniformly on the faces by their ``areas`` (a
    face by area, then uniform on it: the square root of one uniform for the
    first corner's share): ``(points (count, 3), the face of each)``."""
    pick = np.minimum(np.searchsorted(np.cumsum(areas), rng.random(count) * float(areas.sum())),
                      len(faces) - 1)
    u, v = rng.random((2, count))
    s = np.sqrt(u)[:, None]
    tri = vertices[faces[pick]]
    return ((1.0 - s) * tri[:, 0] + s * ((1.0 - v)[:, None] * tri[:, 1] + v[:, None] * tri[:, 2]),
            pick)


def sampled_area(vertices, faces, within, rng):
    """Area (m²) of the triangles ``faces`` where ``within(points)`` ((k,)
    bool) holds, estimated from :data:`AREA_SAMPLES` points drawn on them
    by area with ``rng`` (a numpy Generator), three standard deviations
    low (hits - 3 sqrt(hits) of them): about a lower bound."""
    areas = 0.5 * _doubled_areas(vertices, faces)
    total = float(areas.sum())
    if not total > 0.0:
        return 0.0
    points, _ = points_on_faces(vertices, faces, areas, AREA_SAMPLES, rng)
    hits = float(np.count_nonzero(within(points)))
    return total * max(hits - 3.0 * np.sqrt(hits), 0.0) / AREA_SAMPLES


def _bisect(F, mask, eid, midpoint, marked, longest):
    """Cut every face along its marked edges (the longest one first; an
    unselected face with one marked edge along that edge).

    Returns the new faces, their mask and the index of the first new face
    (uncut faces come first, unchanged).
    """
    rows = np.arange(len(F))
    has = marked[eid]
    first = np.where(has[rows, longest], longest, has.argmax(axis=1))
    cut = has.any(axis=1)
    k = first[cut]
    f, e = F[cut], eid[cut]
    r = np.arange(len(f))
    a, b, c = f[r, k], f[r, (k + 1) % 3], f[r, (k + 2) % 3]
    m0 = midpoint[e[r, k]]
    m1, m2 = midpoint[e[r, (k + 1) % 3]], midpoint[e[r, (k + 2) % 3]]
    s1, s2 = m1 >= 0, m2 >= 0
    children = [
        np.stack([a, m0, c], axis=1)[~s2],            # (a, m0, c) kept whole
        np.stack([m0, c, m2], axis=1)[s2],            # ... or cut on (c, a)
        np.stack([m0, m2, a], axis=1)[s2],
        np.stack([m0, b, c], axis=1)[~s1],            # (m0, b, c) kept whole
        np.stack([m0, b, m1], axis=1)[s1],            # ... or cut on (b, c)
        np.stack([m0, m1, c], axis=1)[s1],
    ]
    sel = mask[cut]
    child_mask = [sel[~s2], sel[s2], sel[s2], sel[~s1], sel[s1], sel[s1]]
    return (np.concatenate([F[~cut]] + children),
            np.concatenate([mask[~cut]] + child_mask), int((~cut).sum()))


def _flip_coplanar(V, F, mask, active, rounds=100):
    """Delaunay edge flips between coplanar selected faces (the surface is unchanged).

    Bisection alone keeps a thin triangle's children thin; flipping the shared
    edge of two coplanar triangles whose opposite angles sum past pi restores
    well-shaped triangles. Only edges of ``active`` (m,) bool faces are tested,
    then those of the faces just flipped.
    """
    F = F.copy()
    n = len(V)
    for _ in range(rounds):
        key = (F * n + np.roll(F, -1, axis=1)).ravel()            # directed edges
        src = np.flatnonzero(np.repeat(active, 3) & (key // n < key % n))
        order = np.argsort(key)
        u, v = key[src] // n, key[src] % n
        pos = np.minimum(np.searchsorted(key, v * n + u, sorter=order), len(key) - 1)
        twin = order[pos]
        ok = key[twin] == v * n + u
        src, twin = src[ok], twin[ok]
        # an edge (u < v) of an inactive face next to an active one: seen from the active side
        back = np.flatnonzero(np.repeat(active, 3) & (key // n > key % n))
        pos = np.minimum(np.searchsorted(key, (key[back] % n) * n + key[back] // n, sorter=order), len(key) - 1)
        ok = (key[order[pos]] == (key[back] % n) * n + key[back] // n) & ~active[order[pos] // 3]
        src, twin = np.concatenate([src, order[pos][ok]]), np.concatenate([twin, back[ok]])
        f1, k1, f2, k2 = src // 3, src % 3, twin // 3, twin % 3
        ok = mask[f1] & mask[f2] & (f1 != f2)
        f1, k1, f2, k2 = f1[ok], k1[ok], f2[ok], k2[ok]
        a, b = F[f1, k1], F[f1, (k1 + 1) % 3]
        c, d = F[f1, (k1 + 2) % 3], F[f2, (k2 + 2) % 3]
        t1, t2 = V[F[f1]], V[F[f2]]
        n1 = np.cross(t1[:, 1] - t1[:, 0], t1[:, 2] - t1[:, 0])
        n2 = np.cross(t2[:, 1] - t2[:, 0], t2[:, 2] - t2[:, 0])
        coplanar = np.einsum("ij,ij->i", n1, n2) > (1.0 - 1e-12) * np.linalg.norm(n1, axis=1) * np.linalg.norm(n2, axis=1)
        ca, cb, da, db = V[a] - V[c], V[b] - V[c], V[a] - V[d], V[b] - V[d]
        with np.errstate(divide="ignore", invalid="ignore"):
            cot_c = np.einsum("ij,ij->i", ca, cb) / np.linalg.norm(np.cross(ca, cb), axis=1)
            cot_d = np.einsum("ij,ij->i", da, db) / np.linalg.norm(np.cross(da, db), axis=1)
            badness = cot_c + cot_d                              # < 0: not Delaunay
        flip = coplanar & (badness < -1e-9)
        if flip.any():  # the new edge (c, d) must not exist already
            flip &= ~np.isin(np.minimum(c, d) * n + np.maximum(c, d), _edge_keys(F, n))
        if not flip.any():
            return F
        cand = np.flatnonzero(flip)[np.argsort(badness[flip])]  # worst first
        idx = np.arange(len(cand))
        owner = np.full(len(F), len(cand))
        np.minimum.at(owner, f1[cand], idx)
        np.minimum.at(owner, f2[cand], idx)
        cand = cand[(owner[f1[cand]] == idx) & (owner[f2[cand]] == idx)]   # each face in one flip
        F[f1[cand]] = np.stack([c[cand], a[cand], d[cand]], axis=1)
        F[f2[cand]] = np.stack([d[cand], b[cand], c[cand]], axis=1)
        active = np.zeros(len(F), bool)
        active[f1[cand]] = True
        active[f2[cand]] = True
    return F


#: a refined sphere or cylinder has its edges short enough that its facets
#: sag at most this fraction of the resolution
SAG_FRACTION = 0.01


def refine_part(config, vertices, faces, face_mask=None):
    """A body's or mesh surface's mesh refined to its ``resolution`` where
    ``face_mask`` says (all faces by default), a primitive's vertices on its
    exact surface (:func:`meshwear.geometry.snap_to_primitive`), its curved
    faces there (a sphere's, a cylinder's side) with edges short enough to
    sag at most :data:`SAG_FRACTION` of the resolution; and a summary for ``meshwear
    check``: ``refined_vertices`` (the vertices of the refined faces),
    ``vertices``, ``resolution``, ``shape`` (its type, None for a mesh
    file), ``sag`` (m, the largest facet sag where refined) and
    ``sag_elsewhere`` (m; both None but for a sphere or cylinder: mesh files
    keep their facets)."""
    resolution = float(config.resolution)
    vertices, faces, mask = refine(vertices, faces, resolution, face_mask=face_mask,
                                   return_mask=True)
    shape = config.shape
    if shape is not None and shape.type in ("sphere", "cylinder"):
        # a triangle with edges e on a sphere of radius R sags at most
        # rc^2 / (2 R) <= e^2 / (6 R) (rc its circumradius, <= e / sqrt 3):
        # the curved faces (not a cylinder's flat caps) get edges short
        # enough for SAG_FRACTION of the resolution
        fine = float(np.sqrt(6.0 * shape.radius * SAG_FRACTION * resolution))
        curved = mask.copy()
        if shape.type == "cylinder":
            curved &= np.abs(geometry.face_normals(vertices, faces)[:, 2]) < geometry.SIDE
        if fine < resolution and curved.any():
            vertices, faces = refine(vertices, faces, fine, face_mask=curved)
            # the refined faces: those as short as the resolution asks
            mask = _edge_lengths(vertices, faces).max(axis=1) <= resolution * (1.0 + 1e-9)
    vertices = geometry.snap_to_primitive(config.shape, vertices, faces)
    sag = geometry.facet_sag(config.shape, vertices, faces)
    info = {"vertices": len(vertices), "refined_vertices": int(len(np.unique(faces[mask]))),
            "resolution": float(config.resolution), "sag": None, "sag_elsewhere": None,
            "shape": config.shape.type if config.shape is not None else None}
    if sag is not None:
        info["sag"] = float(sag[mask].max(initial=0.0))
        info["sag_elsewhere"] = float(sag[~mask].max(initial=0.0))
    return np.ascontiguousarray(vertices), faces, info


def describe_refinement(info):
    """One line for ``meshwear check`` from :func:`refine_part`'s summary."""
    if not info:
        return ""
    text = (f"refined to {info['resolution']:.3g} m: {info['refined_vertices']} of "
            f"{info['vertices']} vertices")
    if info["sag"] is None:
        return text + (" (a mesh file keeps its facets)" if info["shape"] is None else "")
    return (text + f"; facet sag {info['sag']:.2g} m where refined "
            f"({info['sag'] / info['resolution']:.2g} of the resolution), "
            f"{info['sag_elsewhere']:.2g} m elsewhere")


def spacing_near(vertices, faces, low, high):
    """Median edge length (m) of the edges of ``faces`` with both ends inside
    the box ``low``..``high`` (3,) of ``vertices`` (n, 3), None if none: a
    mesh's spacing where another touches it (:func:`contact_spacings`)."""
    inside = np.all((vertices >= low) & (vertices <= high), axis=1)
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    edges = edges[inside[edges].all(axis=1)]
    if not len(edges):
        return None
    return float(np.median(np.linalg.norm(vertices[edges[:, 0]] - vertices[edges[:, 1]],
                                          axis=1)))


def spacing_ratio(body_vertices, body_faces, active, counter_vertices, counter_faces):
    """``(h_body, h_counter)``, the median edge lengths (m) of a body's
    contact (its ``active`` vertices, world frame) and of a counter mesh
    under it (world frame: its vertices within the body's contact box,
    widened by two of the body's edges), or None where either has no edge
    there. A worn counter much finer or coarser than the body there wears
    in tracks or smooths the body's wear (docs/model.md, "Worn
    counter-surfaces")."""
    if not len(active):
        return None
    points = body_vertices[active]
    low, high = points.min(axis=0), points.max(axis=0)
    h_body = spacing_near(body_vertices, body_faces, low, high)
    if h_body is None:
        return None
    h_counter = spacing_near(counter_vertices, counter_faces, low - 2 * h_body,
                             high + 2 * h_body)
    return None if h_counter is None else (h_body, h_counter)


#: the ratio of two meshes' edge lengths where they touch from which
#: ``check`` gives notice (docs/model.md, "Worn counter-surfaces": a 2:1
#: pad on a flat wore 84 % stripes; a counter coarser than twice the body's
#: spacing does not spread its wear)
SPACING_RATIO = 2.0


def spacing_notices(model, state):
    """One line per body and mesh surface whose edge lengths where they
    touch differ by :data:`SPACING_RATIO` or more."""
    # (surfaces import this module: the rotation from the kernels)
    from ..kernels.contact import rotation_entries

    lines = []
    for body, s in zip(model.bodies, state.bodies):
        R = np.array(rotation_entries(np.asarray(s.pose[3:7], float))).reshape(3, 3)
        world = s.pose[0:3] + s.vertices @ R.T
        for surface in model.surfaces.slots:
            faces = getattr(surface, "faces", None)
            if faces is None or not hasattr(surface, "world_vertices"):
                continue                 # an analytic surface: no spacing of its own
            spacing = spacing_ratio(world, body.faces, s.active,
                                    surface.world_vertices(surface.vertices, 0.0), faces)
            if spacing is None:
                continue
            h_body, h_counter = spacing
            ratio = max(h_body, h_counter) / min(h_body, h_counter)
            if ratio >= SPACING_RATIO:
                finer = h_counter < h_body
                why = "" if not getattr(surface, "worn", False) else (
                    "; a worn counter finer than the body wears in tracks a body vertex apart"
                    if finer else "; a worn counter coarser than the body smooths its wear "
                    "over its own spacing") + " (docs/model.md, \"Worn counter-surfaces\")"
                lines.append(
                    f"body {body.name!r} ({h_body * 1e6:.3g} µm edges where it touches) and "
                    f"mesh surface {surface.name!r} ({h_counter * 1e6:.3g} µm there) differ "
                    f"{ratio:.2g}:1 in resolution{why}")
    return lines
