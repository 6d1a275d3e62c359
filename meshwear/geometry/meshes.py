"""Meshes in, plain arrays out: loading, units, cleaning, primitives and face
normals (areas, vertex normals and mass properties: :mod:`.properties`;
refinement: :mod:`.remesh`).

trimesh is used here for reading files and building primitives only; every
function returns plain arrays, ``vertices : (n, 3) float64`` (C-contiguous) and
``faces : (m, 3) int64`` with counter-clockwise (outward) winding.
"""

import importlib
import logging
from pathlib import Path

import numpy as np

from ..kernels.tree import morton_codes

log = logging.getLogger(__name__)

#: file extensions read by trimesh; anything else goes to meshio (Gmsh .msh,
#: Abaqus .inp, VTK .vtu/.vtk, ...)
TRIMESH_FORMATS = {".stl", ".obj", ".ply", ".off", ".glb", ".gltf", ".3mf", ".dae", ".stl_ascii"}
#: CAD files read by trimesh through cascadio (OpenCASCADE), the ``cad`` extra
STEP_FORMATS = {".step", ".stp"}
#: tessellation of STEP surfaces: chord error relative to each edge's length and
#: angle between neighbouring facets' normals (rad), about 60 facets round a circle
STEP_LINEAR_TOLERANCE = 1e-3
STEP_ANGULAR_TOLERANCE = 0.1
#: how to install the STEP reader, named by the error when it is missing
CAD_EXTRA = "pip install 'meshwear[cad]'"
#: metres per unit of a mesh file
UNITS = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "um": 1e-6, "in": 0.0254}

#: vertices closer than this fraction of the bounding-box diagonal are merged
MERGE_TOLERANCE = 1e-9
#: a face is degenerate when twice its area is below this times its longest edge squared
DEGENERATE_RATIO = 1e-12


class MeshError(ValueError):
    """Bad mesh input; ``str(err)`` is one line naming the file and what is wrong."""


def _arrays(vertices, faces):
    return (np.ascontiguousarray(vertices, dtype=np.float64),
            np.ascontiguousarray(faces, dtype=np.int64).reshape(-1, 3))


# ---------------------------------------------------------------- loading

def load_mesh(path, units="m"):
    """Read a triangle mesh file (STL, OBJ, PLY, OFF, GLB, STEP, ...) in metres, cleaned.

    STEP files carry their own length unit and are tessellated by OpenCASCADE
    (through trimesh and cascadio, the ``cad`` extra) into metres; their
    ``units`` must be left at ``"m"``.

    Parameters
    ----------
    path : str or Path
    units : str
        Units of the file, a key of :data:`UNITS`.

    Returns
    -------
    vertices : (n, 3) float
        Metres.
    faces : (m, 3) int

    Raises
    ------
    MeshError
        Unknown units, unreadable file, no faces, non-finite vertices, a STEP
        file without the ``cad`` extra installed.
    """
    path = Path(path)
    if not isinstance(units, str) or units not in UNITS:
        raise MeshError(f"{path}: units {units!r}: expected one of {', '.join(UNITS)}")
    scale = UNITS[units]
    if not path.is_file():
        raise MeshError(f"{path}: {_not_a_file(path)}")
    suffix = path.suffix.lower()
    if suffix in STEP_FORMATS and units != "m":
        raise MeshError(f"{path}: units {units!r}: a STEP file carries its own length unit "
                        "(read in metres); leave units out")
    try:
        if suffix in STEP_FORMATS:
            vertices, faces = _read_step(path)
        elif suffix in TRIMESH_FORMATS:
            vertices, faces = _read_trimesh(path)
        else:
            vertices, faces = _read_meshio(path)
    except MeshError:
        raise
    except Exception as err:  # readers raise anything from KeyError to struct.error
        reason = str(err).splitlines()[0] if str(err) else type(err).__name__
        raise MeshError(f"{path}: cannot read a mesh ({reason})") from None
    if faces.size == 0 or vertices.size == 0:
        raise MeshError(f"{path}: no triangle faces found (empty, or not a mesh file)")
    return clean(vertices * scale, faces, source=str(path))


def load_part(config, mechanism=None, loaded=None):
    """The mesh of a body or mesh surface config: its ``mesh`` file (in its
    ``units``), its ``shape`` primitive, or the mesh geom of the
    ``mechanism`` it names (``mechanism_geom``, in its body's frame);
    (vertices, faces). ``loaded``: a dict of the mesh files read so far by
    their path and units (one model's build: a gear pair's two gears read
    one file, a refined body's is read for the early checks and again),
    filled here; each call gets its own copy."""
    if getattr(config, "mechanism_geom", None) is not None:
        vertices, faces = mechanism.geom_mesh(config.mechanism_geom, config.mechanism_body)
        return clean(vertices, faces, source=f"geom {config.mechanism_geom!r}")
    if config.mesh is not None:
        if loaded is None:
            return load_mesh(config.mesh, config.units)
        key = (str(config.mesh), config.units)
        if key not in loaded:
            loaded[key] = load_mesh(config.mesh, config.units)
        return tuple(a.copy() for a in loaded[key])
    s = config.shape
    vertices, faces = primitive(s.type, size=s.size, radius=s.radius,
                                subdivisions=s.subdivisions, height=s.height,
                                sections=s.sections)
    source = f"shape {s.type}"
    check_scale(vertices, source)
    if len(faces) == 0 or not _doubled_areas(vertices, faces).min() > 0.0:
        raise MeshError(f"{source}: its dimensions are too unequal for triangles of "
                        "non-zero area (a radius or size far smaller than the rest)")
    return vertices, faces


def _not_a_file(path):
    """Why ``path``, which is not a regular file, cannot be read."""
    if path.is_dir():
        return "a folder, not a mesh file"
    return "not a regular file" if path.exists() else "mesh file not found"


def _read_trimesh(path):
    import trimesh

    return _trimesh_arrays(trimesh.load(str(path), force="mesh", process=False))


def _trimesh_arrays(mesh):
    """(vertices, faces) of what trimesh loaded (empty when it is no mesh)."""
    return (np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), dtype=np.float64),
            np.asarray(getattr(mesh, "faces", np.zeros((0, 3))), dtype=np.int64))


def _read_step(path):
    """Triangles of a STEP file's solids, tessellated by OpenCASCADE, in metres."""
    try:
        importlib.import_module("cascadio")  # trimesh's STEP loader needs it
    except ImportError:
        raise MeshError(f"{path}: reading STEP files needs the optional cad extra: "
                        f"{CAD_EXTRA}") from None
    import trimesh

    return _trimesh_arrays(trimesh.load(str(path), file_type="step", force="mesh",
                                        process=False, tol_linear=STEP_LINEAR_TOLERANCE,
                                        tol_relative=True, tol_angular=STEP_ANGULAR_TOLERANCE))


def _read_meshio(path):
    """Surface triangles (quads split in two) of an FE mesh file read by meshio."""
    import meshio

    mesh = meshio.read(str(path))
    faces = []
    for block in mesh.cells:
        if block.type == "triangle":
            faces.append(block.data)
        elif block.type == "quad":
            q = block.data
            faces += [q[:, [0, 1, 2]], q[:, [0, 2, 3]]]
    if not faces:
        kinds = ", ".join(sorted({b.type for b in mesh.cells})) or "none"
        raise MeshError(f"{path}: no triangle or quad surface cells (cells: {kinds})")
    return (np.asarray(mesh.points, dtype=np.float64)[:, :3] if mesh.points.shape[1] >= 3
            else np.pad(np.asarray(mesh.points, float), ((0, 0), (0, 3 - mesh.points.shape[1]))),
            np.concatenate(faces).astype(np.int64))


#: a part's extent (m) is at least this (a shape or units mistake below)
MIN_EXTENT = 1e-9
#: and its coordinates are at most this far from its origin (m)
MAX_COORDINATE = 1e6


def check_scale(vertices, source="<mesh>"):
    """Refuse (MeshError) vertices that are not finite, farther than
    :data:`MAX_COORDINATE` from the origin or spanning less than
    :data:`MIN_EXTENT`: sizes no part has, which would overflow or vanish in
    the contact's arithmetic (a units mistake, usually)."""
    vertices = np.asarray(vertices, dtype=np.float64)
    if not np.all(np.isfinite(vertices)):
        bad = int((~np.isfinite(vertices).all(axis=1)).sum())
        raise MeshError(f"{source}: {bad} vertex(es) have NaN or infinite coordinates")
    if vertices.size == 0:
        return
    far = float(np.abs(vertices).max())
    if far > MAX_COORDINATE:
        raise MeshError(f"{source}: a vertex lies {far:.3g} m from the origin, beyond "
                        f"{MAX_COORDINATE:g} m (check the units)")
    extent = float(np.ptp(vertices, axis=0).max())
    if extent < MIN_EXTENT:
        raise MeshError(f"{source}: the part spans {extent:.3g} m, less than {MIN_EXTENT:g} m "
                        "(check the units)")


def clean(vertices, faces, source="<mesh>"):
    """Merge duplicate vertices, drop degenerate and duplicate faces and unused vertices.

    Duplicate vertices (STL seams) are merged within ``MERGE_TOLERANCE`` of the
    bounding-box diagonal. A zero-area face whose three vertices are collinear
    is removed by splitting the neighbour across its longest edge at its middle
    vertex, so a closed mesh stays closed; other degenerate faces are dropped.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    source : str
        Named in log lines and errors.

    Returns
    -------
    vertices : (k, 3) float
    faces : (l, 3) int
    """
    vertices, faces = _arrays(vertices, faces)
    n0, m0 = len(vertices), len(faces)
    if vertices.ndim != 2 or vertices.shape[1] != 3:
        raise MeshError(f"{source}: vertices have shape {vertices.shape}, expected (n, 3)")
    check_scale(vertices, source)
    if m0 and (faces.min() < 0 or faces.max() >= n0):
        raise MeshError(f"{source}: faces refer to vertices that do not exist")
    diagonal = float(np.linalg.norm(np.ptp(vertices, axis=0))) if n0 else 0.0
    if m0 == 0 or not diagonal > 0.0:
        raise MeshError(f"{source}: no faces with a non-zero extent")
    vertices, faces = _merge_vertices(vertices, faces, MERGE_TOLERANCE * diagonal)
    merged = n0 - len(vertices)

    faces = faces[(faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 2] != faces[:, 0])]
    collapsed = m0 - len(faces)
    faces, slivers, split = _remove_slivers(vertices, faces)
    degenerate = collapsed + slivers
    if len(faces) == 0:
        raise MeshError(f"{source}: every face is degenerate (zero area)")
    _, first = np.unique(np.sort(faces, axis=1), axis=0, return_index=True)
    duplicate = len(faces) - len(first)
    faces = faces[np.sort(first)]

    used = np.zeros(len(vertices), dtype=bool)
    used[faces] = True
    remap = np.cumsum(used) - 1
    unused = int((~used).sum())
    vertices, faces = _arrays(vertices[used], remap[faces])
    if _is_closed(faces) and _signed_volume(vertices, faces) < 0.0:
        # normals must point out of the body: contact and wear directions depend on it
        log.warning("%s: faces were wound inwards (negative volume); flipped", source)
        faces = np.ascontiguousarray(faces[:, ::-1])
    if merged:
        log.info("%s: merged %d duplicate vertices", source, merged)
    if degenerate or duplicate or unused:
        log.warning("%s: removed %d degenerate face(s) (%d neighbour(s) split to keep the surface closed), "
                    "%d duplicate face(s), %d unused vertex(es)", source, degenerate, split, duplicate, unused)
    return vertices, faces


def _is_closed(faces):
    """True if every edge has exactly two faces, traversing it in opposite directions."""
    n = int(faces.max()) + 1
    directed = (faces * n + np.roll(faces, -1, axis=1)).ravel()
    _, count = np.unique(_edge_keys(faces, n), return_counts=True)
    return bool(np.all(count == 2) and len(np.unique(directed)) == len(directed))


def _signed_volume(vertices, faces):
    tri = vertices[faces] - vertices.mean(axis=0)
    return float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0)


def _merge_vertices(vertices, faces, tolerance):
    """Vertices closer than ``tolerance`` become one (the first of each cluster)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    # the exact copies first (an STL file has each vertex once per face):
    # the search for near ones then sees each point once, six times fewer
    unique, first, of_unique = _exact_copies(vertices)
    pairs = cKDTree(unique).query_pairs(tolerance, output_type="ndarray")
    if len(pairs) == 0 and len(unique) == len(vertices):
        return vertices, faces
    n = len(unique)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    count, label = connected_components(graph, directed=False)
    # each cluster's first vertex, the clusters in the order of their first vertices
    cluster_first = np.full(count, len(vertices))
    np.minimum.at(cluster_first, label, first)
    order = np.argsort(cluster_first)
    rank = np.empty_like(order)
    rank[order] = np.arange(count)
    return _arrays(vertices[cluster_first[order]], rank[label[of_unique.ravel()]][faces])


def _exact_copies(vertices):
    """What ``np.unique(vertices, axis=0, return_index=True,
    return_inverse=True)`` gives, its rows in another order (the clusters
    made of them are the same): the distinct rows, the first index of
    each, and each row's distinct one. Sorted by a lexsort of the columns,
    ten times faster than numpy's sort of the rows as records (0.08 s for
    an STL gear's 56 000 vertices)."""
    order = np.lexsort(vertices.T[::-1])        # stable: a row's first copy comes first
    rows = vertices[order]
    new = np.ones(len(rows), bool)
    new[1:] = np.any(rows[1:] != rows[:-1], axis=1)
    inverse = np.empty(len(rows), np.int64)
    inverse[order] = np.cumsum(new) - 1
    return rows[new], order[new], inverse


def _doubled_areas(vertices, faces):
    tri = vertices[faces]
    return np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)


def _edge_lengths(vertices, faces):
    """(m, 3) float: length of edge k = (faces[:, k], faces[:, k+1])."""
    tri = vertices[faces]
    return np.linalg.norm(np.roll(tri, -1, axis=1) - tri, axis=2)


def _slivers(vertices, faces):
    """(m,) bool: faces whose height is below DEGENERATE_RATIO of their longest edge."""
    lengths = _edge_lengths(vertices, faces)
    return _doubled_areas(vertices, faces) <= DEGENERATE_RATIO * lengths.max(axis=1) ** 2


def _remove_slivers(vertices, faces, passes=16):
    """Remove zero-area faces; returns (faces, slivers removed, neighbours split)."""
    m0, split = len(faces), 0
    n = len(vertices)
    for _ in range(passes):
        sliver = _slivers(vertices, faces)
        if not sliver.any():
            break
        # the sliver's middle vertex c is opposite its longest edge (a, b); the
        # neighbour across (a, b) holds the directed edge (b, a)
        idx = np.flatnonzero(sliver)
        k = _edge_lengths(vertices, faces[idx]).argmax(axis=1)
        a, b, c = faces[idx, k], faces[idx, (k + 1) % 3], faces[idx, (k + 2) % 3]
        key = (faces * n + np.roll(faces, -1, axis=1)).ravel()
        order = np.argsort(key)
        pos = np.minimum(np.searchsorted(key, b * n + a, sorter=order), len(key) - 1)
        neighbour = order[pos] // 3
        ok = (key[order[pos]] == b * n + a) & ~sliver[neighbour]
        _, first = np.unique(neighbour[ok], return_index=True)   # one sliver per neighbour per pass
        pick = np.flatnonzero(ok)[first]
        if len(pick) == 0:
            break
        nb = neighbour[pick]
        d = faces[nb].sum(axis=1) - a[pick] - b[pick]            # the neighbour's third vertex
        children = np.concatenate([np.stack([b[pick], c[pick], d], axis=1),
                                   np.stack([c[pick], a[pick], d], axis=1)])
        keep = np.ones(len(faces), bool)
        keep[idx[pick]] = False
        keep[nb] = False
        faces = np.concatenate([faces[keep], children])
        split += len(pick)
    faces = np.ascontiguousarray(faces[~_slivers(vertices, faces)])
    return faces, m0 - len(faces), split


# ------------------------------------------------------------- space order

def spatial_order(vertices, faces):
    """The same mesh with its vertices and its faces each sorted along a
    Morton curve (vertices near in space near in memory: a query walking
    from face to face, or a loop over the vertices of a contact patch, then
    reads memory nearby), and the faces' new order (the old index of each)."""
    faces = np.asarray(faces, dtype=np.int64)
    by_vertex = np.argsort(morton_codes(vertices), kind="stable")
    rank = np.empty(len(by_vertex), np.int64)
    rank[by_vertex] = np.arange(len(by_vertex))
    faces = rank[faces]
    vertices = vertices[by_vertex]
    tri = vertices[faces]
    by_face = np.argsort(morton_codes(0.5 * (tri.min(axis=1) + tri.max(axis=1))), kind="stable")
    return np.ascontiguousarray(vertices), np.ascontiguousarray(faces[by_face]), by_face


# ------------------------------------------------------------- primitives

def primitive(kind, *, size=None, radius=None, subdivisions=3, height=None, sections=32):
    """A closed primitive centred at the origin.

    Parameters
    ----------
    kind : {"box", "sphere", "cylinder"}
    size : float or (3,) float
        Box edge lengths (m).
    radius : float
        Sphere or cylinder radius (m).
    subdivisions : int
        Icosphere subdivisions (20·4^s faces).
    height : float
        Cylinder height (m), along z.
    sections : int
        Cylinder facets around the axis.
    """
    import trimesh

    def positive(name, value):
        if value is None or not np.all(np.asarray(value, float) > 0):
            raise ValueError(f"{kind}: {name} must be given and positive, got {value!r}")

    if kind == "box":
        positive("size", size)
        mesh = trimesh.creation.box(extents=np.broadcast_to(np.asarray(size, float), 3))
    elif kind == "sphere":
        positive("radius", radius)
        mesh = trimesh.creation.icosphere(subdivisions=int(subdivisions), radius=float(radius))
    elif kind == "cylinder":
        positive("radius", radius)
        positive("height", height)
        return _cylinder(float(radius), float(height), int(sections))
    else:
        raise ValueError(f"primitive {kind!r}: expected one of box, sphere, cylinder")
    return _arrays(mesh.vertices, mesh.faces)


def _cylinder(radius, height, sections):
    """A closed cylinder along z: a fan on each cap round its centre, two
    triangles per side facet (trimesh's layout, without its dropping of cap
    triangles it finds small: a slender pin stays closed)."""
    theta = 2.0 * np.pi * np.arange(sections) / sections
    z = 0.5 * height
    vertices = np.zeros((2 * sections + 2, 3))
    vertices[0, 2], vertices[3, 2] = -z, z            # the caps' centres
    bottom = np.r_[1, 2 * np.arange(1, sections) + 2]
    top = bottom + 1
    top[0] = 2
    for rim, height_z in ((bottom, -z), (top, z)):
        vertices[rim, 0] = radius * np.cos(theta)
        vertices[rim, 1] = radius * np.sin(theta)
        vertices[rim, 2] = height_z
    b_next, t_next = np.roll(bottom, -1), np.roll(top, -1)
    faces = np.stack([np.stack([bottom, np.zeros_like(bottom), b_next], axis=1),
                      np.stack([bottom, b_next, top], axis=1),
                      np.stack([top, b_next, t_next], axis=1),
                      np.stack([top, t_next, np.full_like(top, 3)], axis=1)], axis=1)
    return _arrays(vertices, faces.reshape(-1, 3))


#: a cylinder's face is on its side (not a cap) where its normal is this
#: close to perpendicular to the axis (cap faces: |n_z| = 1, side faces 0)
SIDE = 0.5


def snap_to_primitive(shape, vertices, faces):
    """The vertices of a refined ``sphere`` or ``cylinder`` primitive (its
    own frame, as :func:`primitive` makes it) put on its exact surface: all
    of a sphere's at its radius; a cylinder's on its side (those of a face
    whose normal is perpendicular to the axis, the rims included) at its
    radius from the axis, keeping their height. Refining splits the flat
    facets, so without this the new vertices sag towards the axis by up to
    R (1 - cos(pi / sections)). Other shapes and mesh files: unchanged."""
    if shape is None or shape.type not in ("sphere", "cylinder"):
        return vertices
    vertices = np.array(vertices, dtype=float)
    if shape.type == "sphere":
        vertices *= shape.radius / np.linalg.norm(vertices, axis=1)[:, None]
        return vertices
    side = np.zeros(len(vertices), bool)
    side[faces[np.abs(face_normals(vertices, faces)[:, 2]) < SIDE].ravel()] = True
    radial = np.linalg.norm(vertices[side, 0:2], axis=1)
    vertices[side, 0:2] *= (shape.radius / radial)[:, None]
    return vertices


def facet_sag(shape, vertices, faces):
    """(m,) how far (m) each face of a ``sphere`` or ``cylinder`` primitive
    lies inside its exact surface (largest at its edges' midpoints and its
    centre); None for other shapes (a box is exact) and mesh files (their
    surface is their facets)."""
    if shape is None or shape.type not in ("sphere", "cylinder"):
        return None
    tri = vertices[faces]
    points = np.concatenate([0.5 * (tri + np.roll(tri, -1, axis=1)),
                             tri.mean(axis=1, keepdims=True)], axis=1)       # (m, 4, 3)
    if shape.type == "sphere":
        return shape.radius - np.linalg.norm(points, axis=2).min(axis=1)
    sag = shape.radius - np.linalg.norm(points[..., 0:2], axis=2).min(axis=1)
    side = np.abs(face_normals(vertices, faces)[:, 2]) < SIDE
    return np.where(side, sag, 0.0)


def _edge_keys(F, n):
    """(m·3,) int: undirected key min·n + max of edge k = (F[:, k], F[:, k+1])."""
    G = np.roll(F, -1, axis=1)
    return (np.minimum(F, G) * n + np.maximum(F, G)).ravel()

def face_normals(vertices, faces):
    """(m, 3) float: unit outward face normals; zero-area faces give zeros."""
    V, F = _arrays(vertices, faces)
    tri = V[F]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norm = np.linalg.norm(cross, axis=1, keepdims=True)
    return np.divide(cross, norm, out=np.zeros_like(cross), where=norm > 0.0)


def plane_patch(point, normal, size, divisions=1):
    """A square patch of a plane, centred at ``point``, for drawing an analytic plane.

    Parameters
    ----------
    point : (3,) float
        Centre (m).
    normal : (3,) float
        Plane normal (need not be unit); the faces are wound so their normal is +normal.
    size : float or (2,) float
        Side length(s) (m).
    divisions : int
        Cells per side; the patch has 2·divisions² triangles.

    Returns
    -------
    vertices : (n, 3) float
    faces : (m, 3) int
    """
    point = np.asarray(point, np.float64).reshape(3)
    normal = np.asarray(normal, np.float64).reshape(3)
    length = np.linalg.norm(normal)
    if not length > 0:
        raise ValueError(f"normal {normal.tolist()} has zero length")
    normal = normal / length
    width, height = np.broadcast_to(np.asarray(size, np.float64), 2)
    if not (width > 0 and height > 0):
        raise ValueError(f"size {size!r} must be positive")
    divisions = int(divisions)
    if divisions < 1:
        raise ValueError(f"divisions must be >= 1, got {divisions}")
    # in-plane axes u, v with u x v = normal; u from the world axis least aligned with the normal
    u = np.cross(normal, np.eye(3)[np.argmin(np.abs(normal))])
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    s = np.linspace(-0.5, 0.5, divisions + 1)
    su, sv = np.meshgrid(s * width, s * height, indexing="ij")
    vertices = point + su.reshape(-1, 1) * u + sv.reshape(-1, 1) * v
    i, j = np.meshgrid(np.arange(divisions), np.arange(divisions), indexing="ij")
    p00 = (i * (divisions + 1) + j).ravel()
    p10, p01 = p00 + divisions + 1, p00 + 1
    p11 = p10 + 1
    faces = np.concatenate([np.stack([p00, p10, p11], axis=1), np.stack([p00, p11, p01], axis=1)])
    return np.ascontiguousarray(vertices), np.ascontiguousarray(faces, dtype=np.int64)
