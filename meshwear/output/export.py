"""Worn parts out of a run's folder as mesh files (``meshwear export``, docs/outputs.md).

A frame of a worn part holds its mesh in the world with the part's pose as
field data (``origin``, ``orientation``); undoing the pose gives the worn
mesh in the part's own frame (the mesh file's axes and origin), which CAD
and FE tools can take.
"""

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

#: file formats written, by suffix
FORMATS = ("stl", "ply", "obj")
#: metres per unit of the written files
UNITS = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "um": 1e-6, "in": 0.0254}


class ExportError(ValueError):
    """A part, frame or folder that cannot be exported (one line)."""


#: suffixes of a part's series: a .pvd collection of .vtp frames, or one VTKHDF file
SERIES_SUFFIXES = (".pvd", ".vtkhdf")


def series_path(out_dir, name):
    """The series file of ``name`` in ``out_dir`` (``.pvd`` or ``.vtkhdf``;
    the ``.pvd`` path when there is none)."""
    for suffix in SERIES_SUFFIXES[::-1]:
        path = Path(out_dir) / f"{name}{suffix}"
        if path.is_file():
            return path
    return Path(out_dir) / f"{name}.pvd"


def series_frames(out_dir, name):
    """``[(time, frame), ...]`` of the frames of series ``name`` in
    ``out_dir``; :func:`read_frame` reads a ``frame``."""
    path = series_path(out_dir, name)
    if path.suffix == ".vtkhdf":
        from .vtkhdf import read_frames

        try:
            return read_frames(path)
        except (OSError, KeyError, IndexError) as err:
            raise ExportError(f"{path}: not a readable VTKHDF series ({err})") from None
    try:
        root = ET.parse(path).getroot()
    except FileNotFoundError:
        raise ExportError(f"{path}: no such series") from None
    except ET.ParseError as err:
        raise ExportError(f"{path}: not a readable .pvd ({err})") from None
    return [(float(d.get("timestep")), Path(out_dir) / d.get("file"))
            for d in root.iter("DataSet")]


def read_frame(frame):
    """A frame of :func:`series_frames` as a ``pyvista.PolyData`` with its
    point and field data."""
    if callable(frame):
        try:
            return frame()
        except (OSError, KeyError, IndexError, ValueError) as err:
            raise ExportError(f"cannot read the frame ({err})") from None
    import pyvista

    try:
        return pyvista.read(frame)
    except (FileNotFoundError, OSError, ValueError) as err:
        raise ExportError(f"{frame}: cannot read the frame ({err})") from None


def worn_parts(out_dir):
    """Names of the worn parts (bodies and worn counter-surfaces) in ``out_dir``:
    the series whose frames carry a pose."""
    out_dir = Path(out_dir)
    names = []
    stems = sorted({p.stem for suffix in SERIES_SUFFIXES for p in out_dir.glob(f"*{suffix}")})
    for stem in stems:
        frames = series_frames(out_dir, stem)
        if frames and _pose(read_frame(frames[0][1])) is not None:
            names.append(stem)
    return names


def chosen_parts(out_dir, names):
    """``names`` (default: every worn part of ``out_dir``), each checked to
    be one of them (ExportError naming ``--part``)."""
    available = worn_parts(out_dir)
    if not available:
        raise ExportError(f"{out_dir}: no worn part's series here (a meshwear run's folder?)")
    names = list(names) if names else available
    for name in names:
        if name not in available:
            raise ExportError(f"--part {name}: not a worn part of {out_dir} "
                              f"(there: {', '.join(available)})")
    return names


def part_mesh(out_dir, name, frame=-1):
    """The worn mesh of part ``name`` at frame number ``frame`` (negative:
    from the end), in its own frame.

    Returns
    -------
    vertices : (n, 3) float, m
    faces : (m, 3) int
    time : float
    """
    frames = series_frames(out_dir, name)
    if not frames:
        raise ExportError(f"{series_path(out_dir, name)}: the series has no frames")
    if not -len(frames) <= frame < len(frames):
        raise ExportError(f"--frame {frame}: {name!r} has {len(frames)} frames "
                          f"(0 to {len(frames) - 1}, or -1 for the last)")
    time, source = frames[frame]
    mesh = read_frame(source)
    pose = _pose(mesh)
    if pose is None:
        raise ExportError(f"{series_path(out_dir, name)}: {name!r} is not a worn part (its frames carry no pose); "
                          "export takes bodies and surfaces with wear = true")
    origin, q = pose
    R = _rotation(q)
    vertices = (np.asarray(mesh.points, float) - origin) @ R
    faces = np.asarray(mesh.regular_faces, dtype=np.int64)
    return vertices, faces, time


def export(out_dir, names=None, frame=-1, fmt="stl", units="m", dest=None):
    """Write the worn parts ``names`` (default: all of them) at ``frame`` as
    ``fmt`` files in ``units``; return the paths written.

    ``dest`` is a folder (default ``out_dir``); files are named
    ``<part>_<frame number>.<fmt>``.
    """
    import trimesh

    out_dir = Path(out_dir)
    if not out_dir.is_dir():
        raise ExportError(f"{out_dir}: no such output folder")
    if fmt not in FORMATS:
        raise ExportError(f"--format {fmt}: expected one of {', '.join(FORMATS)}")
    if units not in UNITS:
        raise ExportError(f"--units {units}: expected one of {', '.join(UNITS)}")
    names = chosen_parts(out_dir, names)
    dest = Path(dest) if dest is not None else out_dir
    dest.mkdir(parents=True, exist_ok=True)
    written = []
    for name in names:
        vertices, faces, _ = part_mesh(out_dir, name, frame)
        number = frame if frame >= 0 else len(series_frames(out_dir, name)) + frame
        mesh = trimesh.Trimesh(vertices / UNITS[units], faces, process=False)
        path = dest / f"{name}_{number:05d}.{fmt}"
        mesh.export(path)
        written.append(path)
    return written


def _pose(mesh):
    if "origin" not in mesh.field_data or "orientation" not in mesh.field_data:
        return None
    return (np.asarray(mesh.field_data["origin"], float),
            np.asarray(mesh.field_data["orientation"], float))


def _rotation(q):
    from ..kernels.contact import rotation_entries

    q = q / np.linalg.norm(q)
    return np.array(rotation_entries(q)).reshape(3, 3)
