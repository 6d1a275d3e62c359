"""Areas, normals, mass properties and summaries of plain-array meshes
(:mod:`meshwear.geometry.meshes` makes them).
"""

import logging

import numpy as np

from .meshes import MeshError, _arrays, _doubled_areas, _edge_keys, _edge_lengths, load_mesh

log = logging.getLogger(__name__)

# ------------------------------------------------- areas, normals, checks

def tributary_areas(vertices, faces):
    """(n,) float: each vertex's barycentric share (m²), a third of each adjacent face's area."""
    V, F = _arrays(vertices, faces)
    third = _doubled_areas(V, F) / 6.0
    return np.bincount(F.ravel(), weights=np.repeat(third, 3), minlength=len(V))


def area_vectors(vertices, faces):
    """(n, 4) float: each vertex's area vector (m²): a third of each adjacent
    face's area times its outward unit normal, summed; then its length.

    Projected on a direction ``-n``, the vector gives the vertex's share of
    the surface's projection on a plane of normal ``n``: its contact area
    there. Its length is at most the tributary area.
    """
    V, F = _arrays(vertices, faces)
    tri = V[F]
    third = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]) / 6.0   # area/3 · normal
    out = np.zeros((len(V), 4))
    for k in range(3):
        out[:, k] = np.bincount(F.ravel(), weights=np.repeat(third[:, k], 3), minlength=len(V))
    out[:, 3] = np.linalg.norm(out[:, 0:3], axis=1)
    return out



def vertex_normals(vertices, faces):
    """(n, 3) float: unit outward vertex normals, area-weighted over adjacent faces."""
    V, F = _arrays(vertices, faces)
    tri = V[F]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])   # 2 · area · normal
    summed = np.zeros_like(V)
    for k in range(3):
        np.add.at(summed, F[:, k], cross)
    norm = np.linalg.norm(summed, axis=1, keepdims=True)
    return np.ascontiguousarray(np.divide(summed, norm, out=np.zeros_like(summed), where=norm > 0.0))


def inverted_faces(reference_normals, vertices, faces, reference_areas=None):
    """(k,) int: faces whose current normal flipped or collapsed against the reference.

    A face is flagged when its area projected on its reference normal is
    negative (flipped) or below 1e-12 of its reference area (collapsed). Without
    ``reference_areas`` the collapse test is relative to the face's longest
    edge squared. Faces with a zero reference normal are never flagged.

    Parameters
    ----------
    reference_normals : (m, 3) float
        Unit normals of the unworn faces (:func:`face_normals`).
    vertices : (n, 3) float
        Current (worn) vertices, same frame as the reference.
    faces : (m, 3) int
    reference_areas : (m,) float, optional
    """
    V, F = _arrays(vertices, faces)
    ref = np.asarray(reference_normals, np.float64)
    tri = V[F]
    projected = 0.5 * np.einsum("ij,ij->i", np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), ref)
    if reference_areas is not None:
        scale = np.asarray(reference_areas, np.float64)
    else:
        scale = _edge_lengths(V, F).max(axis=1) ** 2
    valid = np.einsum("ij,ij->i", ref, ref) > 0.0
    return np.flatnonzero(valid & (projected <= 1e-12 * scale))


# ---------------------------------------------------------- mass, info

def mass_properties(vertices, faces, density=None, mass=None, source="mesh"):
    """Mass, centre of mass and inertia of the solid a closed mesh encloses.

    Exact polyhedral integrals (trimesh), evaluated about the bounding-box
    centre to keep precision for meshes far from their origin. A closed mesh
    with inverted winding (negative volume) is accepted as if flipped.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    density : float, optional
        kg/m³.
    mass : float, optional
        kg, instead of density (the inertia is scaled to it). Neither: density 1.
    source : str
        Named in errors.

    Returns
    -------
    mass : float
        kg.
    center_of_mass : (3,) float
        In the mesh frame (m).
    inertia : (3, 3) float
        About the centre of mass, mesh axes (kg·m²).
    """
    import trimesh

    if density is not None and mass is not None:
        raise ValueError("give density or mass, not both")
    for name, value in (("density", density), ("mass", mass)):
        if value is not None and not (np.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be positive, got {value!r}")
    V, F = _arrays(vertices, faces)
    mesh = trimesh.Trimesh(V, F, process=False)
    if not mesh.is_watertight:
        raise MeshError(f"{source}: open mesh ({_boundary_edges(F)} boundary edges): "
                        "give the body a closed mesh")
    if not mesh.is_winding_consistent:
        raise MeshError(f"{source}: inconsistent face winding: give the body a consistently oriented closed mesh")
    shift = 0.5 * (V.min(axis=0) + V.max(axis=0))
    props = trimesh.triangles.mass_properties(V[F] - shift, density=1.0)
    volume = float(props.volume)
    if volume < 0.0:
        log.warning("%s: faces wound inwards (negative volume); using the flipped mesh", source)
        props = trimesh.triangles.mass_properties(V[F[:, ::-1]] - shift, density=1.0)
        volume = float(props.volume)
    if not volume > 0.0:
        raise MeshError(f"{source}: the mesh encloses no volume")
    rho = (mass / volume) if mass is not None else (1.0 if density is None else float(density))
    inertia = np.ascontiguousarray(props.inertia * rho)
    return rho * volume, np.asarray(props.center_mass, np.float64) + shift, inertia


def _boundary_edges(F):
    _, count = np.unique(_edge_keys(F, int(F.max()) + 1), return_counts=True)
    return int((count != 2).sum())


def mesh_info(path, units="m"):
    """Summary of a mesh file after loading and cleaning (plain Python values, SI).

    Returns
    -------
    dict
        ``vertices``, ``faces``, ``watertight``, ``extents`` [3], ``area`` (m²),
        ``volume`` (m³, None if open), ``bounds`` [[min], [max]].
    """
    import trimesh

    V, F = load_mesh(path, units)
    mesh = trimesh.Trimesh(V, F, process=False)
    watertight = bool(mesh.is_watertight and mesh.is_winding_consistent)
    return {
        "vertices": len(V),
        "faces": len(F),
        "watertight": watertight,
        "extents": np.ptp(V, axis=0).tolist(),
        "area": float(_doubled_areas(V, F).sum() / 2.0),
        "volume": abs(float(mesh.volume)) if watertight else None,
        "bounds": [V.min(axis=0).tolist(), V.max(axis=0).tolist()],
    }
