"""VTK time series for ParaView (docs/outputs.md): a ``.pvd`` collection of ``.vtp`` frames.

``OUT/<name>.pvd`` lists ``OUT/<name>/<name>_NNNNN.vtp``. The collection is
rewritten atomically (temporary file, then ``os.replace``) after every frame, so
a run stopped at any moment leaves a series ParaView opens.
"""

import re
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from .folder import ensure_space
from .tables import write_text_atomic


def series_name_and_faces(name, faces):
    """A series' name (no path separators) and its (m, 3) int64 triangles,
    checked; shared by :class:`PVDSeries` and the VTKHDF series."""
    name = str(name)
    if not name or name in (".", "..") or re.search(r"[/\\\x00]", name):
        raise ValueError(f"series name {name!r}: must be non-empty and contain no path separators")
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    if faces.ndim != 2 or faces.shape[1] != 3:
        raise ValueError(f"faces have shape {faces.shape}, expected (m, 3)")
    return name, faces


def frame_arrays(points, faces, point_data):
    """A frame's ``(points, point_data)`` checked against ``faces``: (n, 3)
    float64 points and C-contiguous (n,) or (n, k) arrays, bool as uint8."""
    points = np.ascontiguousarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3:
        raise ValueError(f"points have shape {points.shape}, expected (n, 3)")
    n = len(points)
    if len(faces) and faces.max() >= n:
        raise ValueError(f"{n} points, but the faces refer to point {faces.max()}")
    data = {}
    for key, value in point_data.items():
        value = np.asarray(value)
        if value.dtype == bool:
            value = value.astype(np.uint8)
        if value.shape[0] != n or value.ndim > 2:
            raise ValueError(f"point data {key!r} has shape {value.shape}, expected ({n},) "
                             f"or ({n}, k)")
        data[key] = np.ascontiguousarray(value)
    return points, data


def resume_limit(until):
    """The last frame time a series resumed at ``until`` (s) keeps: ``until``
    up to rounding."""
    return until + 1e-12 * max(1.0, abs(until))


class PVDSeries:
    """One body's (or surface's) series: ``OUT/<name>.pvd`` + ``OUT/<name>/<name>_NNNNN.vtp``.

    The mesh connectivity is fixed; each frame gives new point positions and
    point data. Opening a series replaces an older one of the same name (its
    ``.pvd`` and its numbered frames).

    Parameters
    ----------
    out_dir : str or Path
    name : str
        Series name, used for file names (no path separators).
    faces : (m, 3) int
    """

    def __init__(self, out_dir, name, faces, resume_until=None):
        name, faces = series_name_and_faces(name, faces)
        self.out_dir = Path(out_dir)
        self.name = name
        self.faces = faces
        self.frame_dir = self.out_dir / name
        self.pvd_path = self.out_dir / f"{name}.pvd"
        self.frame_dir.mkdir(parents=True, exist_ok=True)
        # resuming keeps the frames up to ``resume_until`` (s) of the stopped run
        self._entries = self._read_entries(resume_until) if resume_until is not None else []
        remove_frames(self.out_dir, name, keep={Path(f).name for _, f in self._entries})
        # an older run's series of this name in the other format
        (self.out_dir / f"{name}.vtkhdf").unlink(missing_ok=True)
        self._closed = False
        self._last_size = 0
        self._write_pvd()           # an empty collection replaces any older series

    def write_frame(self, time, points, point_data, field_data=None):
        """Write one frame and list it in the ``.pvd``.

        Parameters
        ----------
        time : float
            s.
        points : (n, 3) float
            World coordinates (m).
        point_data : dict of str -> (n,) or (n, k) array
            Scalars or vectors per point; bool is stored as uint8.
        field_data : dict of str -> scalar or array, optional
            Values for the whole frame (``resolved``: 0 for a frame filled
            from a cycle jump).

        Returns
        -------
        Path
            The ``.vtp`` written.
        """
        if self._closed:
            raise RuntimeError(f"series {self.name!r} is closed")
        import pyvista

        points, data = frame_arrays(points, self.faces, point_data)
        mesh = pyvista.PolyData.from_regular_faces(points, self.faces)
        for key, value in data.items():
            mesh.point_data[key] = value
        mesh.field_data["TimeValue"] = np.array([float(time)])   # read by ParaView for a lone frame
        for key, value in (field_data or {}).items():
            mesh.field_data[key] = np.atleast_1d(np.asarray(value))
        index = len(self._entries)
        relative = f"{self.name}/{self.name}_{index:05d}.vtp"
        path = self.out_dir / relative
        # as large as the last frame, or (the first) as its arrays uncompressed
        ensure_space(self.frame_dir, self._last_size or mesh.actual_memory_size * 1024)
        mesh.save(path, binary=True, compression="zlib")
        self._last_size = path.stat().st_size
        #: what the last frame added to the series (B)
        self.frame_bytes = self._last_size
        self._entries.append((float(time), relative))
        self._write_pvd()
        return path

    def _read_entries(self, until):
        import xml.etree.ElementTree as ET

        if not self.pvd_path.is_file():
            raise ValueError(f"{self.pvd_path}: the stopped run's series is missing")
        limit = resume_limit(until)
        try:
            entries = [(float(d.get("timestep")), d.get("file"))
                       for d in ET.parse(self.pvd_path).getroot().iter("DataSet")]
        except (ET.ParseError, TypeError, ValueError) as err:
            raise ValueError(f"{self.pvd_path}: damaged series file ({err})") from None
        return [(t, f) for t, f in entries if t <= limit and (self.out_dir / f).is_file()]

    def _write_pvd(self):
        lines = ['<?xml version="1.0"?>',
                 '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
                 "  <Collection>"]
        lines += [f'    <DataSet timestep="{t!r}" group="" part="0" file={quoteattr(f)}/>'
                  for t, f in self._entries]
        lines += ["  </Collection>", "</VTKFile>", ""]
        write_text_atomic(self.pvd_path, "\n".join(lines))

    @property
    def times(self):
        """list of float: times of the frames written so far."""
        return [t for t, _ in self._entries]

    def close(self):
        """Finish the series (the ``.pvd`` is already complete after every frame)."""
        self._closed = True

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def remove_frames(out_dir, name, keep=()):
    """Delete the numbered ``.vtp`` frames of series ``name`` in ``out_dir``
    (those not in ``keep``, a set of file names)."""
    folder = Path(out_dir) / name
    if not folder.is_dir():
        return
    stale = re.compile(re.escape(name) + r"_\d{5,}\.vtp")
    for old in folder.iterdir():
        if stale.fullmatch(old.name) and old.name not in keep:
            old.unlink()
