"""One VTKHDF temporal file per part (``run.series = "vtkhdf"``, docs/outputs.md).

``OUT/<name>.vtkhdf`` holds every frame of a part in one HDF5 file in the
VTKHDF format (version 2.2, type PolyData, temporal; ParaView >= 5.13 opens
it as a time series). The triangles are written once and shared by every
step (each step's cell offsets point at them); each frame appends its
points, point data and field data. After every frame the step count is
updated last and the file flushed, so a run stopped at any moment leaves
a file ParaView opens, with every frame written so far (``--resume`` drops
the rows of a frame cut short). HDF5 does not let
a file be read while it is written: the run holds HDF5's file lock, and
the file is opened after the run ends or stops (use .pvd to watch a run).

Needs h5py (the ``hdf`` extra).
"""

from pathlib import Path

import numpy as np

from .folder import ensure_space
from .vtk import frame_arrays, remove_frames, resume_limit, series_name_and_faces

#: how to install the writer, named by the error when h5py is missing
HDF_EXTRA = "pip install 'meshwear[hdf]'"
VERSION = (2, 2)
#: HDF5 filters of the per-frame arrays (points, point data): byte shuffle and
#: zlib at its fastest level, which VTK's reader (and any HDF5) decodes
COMPRESSION = {"compression": "gzip", "compression_opts": 1, "shuffle": True}
#: cell kinds of a VTKHDF PolyData, in the order the offsets arrays list them
CELL_KINDS = ("Vertices", "Lines", "Polygons", "Strips")


def _h5py():
    try:
        import h5py
    except ImportError:
        raise ValueError("run.series = 'vtkhdf' needs h5py, the optional hdf extra: "
                         f"{HDF_EXTRA}") from None
    return h5py


class VTKHDFSeries:
    """One part's series as ``OUT/<name>.vtkhdf``: the interface of
    :class:`meshwear.output.vtk.PVDSeries` (``write_frame``, ``times``,
    ``close``), opened with the same arguments.

    Resuming (``resume_until``) keeps the steps up to that time and drops
    the rest; otherwise an older file of the same name is replaced.
    """

    suffix = ".vtkhdf"

    def __init__(self, out_dir, name, faces, resume_until=None):
        h5py = _h5py()
        name, faces = series_name_and_faces(name, faces)
        self.out_dir = Path(out_dir)
        self.out_dir.mkdir(parents=True, exist_ok=True)
        self.name = name
        self.faces = faces
        self.path = self.out_dir / f"{name}{self.suffix}"
        self._closed = False
        if resume_until is not None:
            if not self.path.is_file():
                raise ValueError(f"{self.path}: the stopped run's series is missing")
            try:
                self._file = h5py.File(self.path, "r+")
                self._truncate(resume_until)
            except (OSError, KeyError) as err:
                raise ValueError(f"{self.path}: damaged series file ({err})") from None
        else:
            # an older run's .pvd series of this name
            (self.out_dir / f"{name}.pvd").unlink(missing_ok=True)
            remove_frames(self.out_dir, name)
            self._file = h5py.File(self.path, "w")
            self._create()

    # ---------------------------------------------------------------- layout

    def _create(self):
        h5py = _h5py()
        root = self._file.create_group("VTKHDF")
        root.attrs["Version"] = np.array(VERSION, dtype=np.int64)
        kind = b"PolyData"
        root.attrs.create("Type", kind, dtype=h5py.string_dtype("ascii", len(kind)))
        m = len(self.faces)
        for cell in CELL_KINDS:
            g = root.create_group(cell)
            connectivity = self.faces.ravel() if cell == "Polygons" else np.zeros(0, np.int64)
            offsets = (np.arange(m + 1, dtype=np.int64) * 3 if cell == "Polygons"
                       else np.zeros(1, np.int64))
            g.create_dataset("Connectivity", data=connectivity)
            g.create_dataset("Offsets", data=offsets)
            # per step: the counts of the shared cells
            self._growing(g, "NumberOfCells", ())
            self._growing(g, "NumberOfConnectivityIds", ())
        self._growing(root, "NumberOfPoints", ())
        self._growing(root, "Points", (3,), np.float64, rows=max(1, int(self.faces.max(initial=0)) + 1))
        for group in ("PointData", "CellData", "FieldData"):
            root.create_group(group)
        steps = root.create_group("Steps")
        steps.attrs["NSteps"] = np.int64(0)
        self._growing(steps, "Values", (), np.float64)
        for key in ("PartOffsets", "NumberOfParts", "PointOffsets"):
            self._growing(steps, key, ())
        self._growing(steps, "CellOffsets", (4,))
        self._growing(steps, "ConnectivityIdOffsets", (4,))
        for group in ("PointDataOffsets", "CellDataOffsets", "FieldDataOffsets", "FieldDataSizes"):
            steps.create_group(group)
        self._file.flush()

    @staticmethod
    def _growing(group, key, shape, dtype=np.int64, rows=None):
        """An empty dataset that grows by rows; ``rows`` (a frame's point
        count) makes it one compressed chunk per frame."""
        chunking = {"chunks": True} if rows is None else {"chunks": (rows,) + shape, **COMPRESSION}
        return group.create_dataset(key, shape=(0,) + shape, maxshape=(None,) + shape,
                                    dtype=dtype, **chunking)

    @staticmethod
    def _append(dataset, rows):
        rows = np.asarray(rows, dtype=dataset.dtype).reshape((-1,) + dataset.shape[1:])
        start = dataset.shape[0]
        dataset.resize(start + len(rows), axis=0)
        dataset[start:] = rows
        return start

    # ---------------------------------------------------------------- frames

    def write_frame(self, time, points, point_data, field_data=None):
        """Append one frame (the arguments of :meth:`PVDSeries.write_frame`);
        return the file's path."""
        if self._closed:
            raise RuntimeError(f"series {self.name!r} is closed")
        points, data = frame_arrays(points, self.faces, point_data)
        n = len(points)
        ensure_space(self.out_dir, points.nbytes + sum(v.nbytes for v in data.values()))
        size_before = self.path.stat().st_size
        root, steps = self._file["VTKHDF"], self._file["VTKHDF/Steps"]
        step = int(steps.attrs["NSteps"])
        fields = {"TimeValue": np.array([float(time)])}
        fields.update({k: np.atleast_1d(np.asarray(v)) for k, v in (field_data or {}).items()})
        offset = self._append(root["Points"], points)
        self._append(root["NumberOfPoints"], [n])
        for cell in CELL_KINDS:
            m = len(self.faces) if cell == "Polygons" else 0
            self._append(root[cell]["NumberOfCells"], [m])
            self._append(root[cell]["NumberOfConnectivityIds"], [3 * m])
        for key, value in data.items():
            shape = value.shape[1:]
            array = root["PointData"].get(key) or self._growing(root["PointData"], key, shape,
                                                                 value.dtype, rows=n)
            start = self._append(array, value)
            offsets = (steps["PointDataOffsets"].get(key)
                       or self._growing(steps["PointDataOffsets"], key, ()))
            self._append(offsets, [start])
        for key, value in fields.items():
            value = value.ravel()
            array = root["FieldData"].get(key) or self._growing(root["FieldData"], key, (),
                                                                value.dtype)
            start = self._append(array, value)
            offsets = (steps["FieldDataOffsets"].get(key)
                       or self._growing(steps["FieldDataOffsets"], key, ()))
            self._append(offsets, [start])
            sizes = (steps["FieldDataSizes"].get(key)
                     or self._growing(steps["FieldDataSizes"], key, (2,)))
            self._append(sizes, [[1, len(value)]])  # components, tuples
        self._append(steps["Values"], [float(time)])
        self._append(steps["PartOffsets"], [step])
        self._append(steps["NumberOfParts"], [1])
        self._append(steps["PointOffsets"], [offset])
        self._append(steps["CellOffsets"], [[0, 0, 0, 0]])           # the shared triangles
        self._append(steps["ConnectivityIdOffsets"], [[0, 0, 0, 0]])
        steps.attrs["NSteps"] = np.int64(step + 1)                    # the frame counts from here
        self._file.flush()
        #: what the last frame added to the file (B)
        self.frame_bytes = max(0, self.path.stat().st_size - size_before)
        return self.path

    def _cut(self, keep):
        """Shorten every per-step dataset to ``keep`` steps and the data
        arrays to what those steps use."""
        root, steps = self._file["VTKHDF"], self._file["VTKHDF/Steps"]
        points = int(steps["PointOffsets"][keep - 1] + root["NumberOfPoints"][keep - 1]) if keep else 0
        per_step = [root["NumberOfPoints"], steps["Values"], steps["PartOffsets"],
                    steps["NumberOfParts"], steps["PointOffsets"], steps["CellOffsets"],
                    steps["ConnectivityIdOffsets"]]
        per_step += [root[c][k] for c in CELL_KINDS for k in ("NumberOfCells",
                                                               "NumberOfConnectivityIds")]
        for dataset in per_step:
            dataset.resize(min(dataset.shape[0], keep), axis=0)
        root["Points"].resize(points, axis=0)
        for key in list(root["PointData"]):
            root["PointData"][key].resize(points, axis=0)
            steps["PointDataOffsets"][key].resize(keep, axis=0)
        for key in list(root["FieldData"]):
            offsets, sizes = steps["FieldDataOffsets"][key], steps["FieldDataSizes"][key]
            end = int(offsets[keep - 1] + sizes[keep - 1, 1]) if keep else 0
            root["FieldData"][key].resize(end, axis=0)
            offsets.resize(keep, axis=0)
            sizes.resize(keep, axis=0)
        steps.attrs["NSteps"] = np.int64(keep)

    def _truncate(self, until):
        """Keep the steps up to ``until`` (s), and drop the rows of a frame
        cut short before its step was counted."""
        self._cut(int(np.searchsorted(self.times, resume_limit(until), side="right")))
        self._file.flush()

    @property
    def times(self):
        """list of float: times of the frames written so far."""
        steps = self._file["VTKHDF/Steps"]
        return [float(t) for t in steps["Values"][:int(steps.attrs["NSteps"])]]

    def close(self):
        """Finish the series and close the file."""
        if not self._closed:
            self._closed = True
            self._file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def read_frames(path):
    """``[(time, load), ...]`` of a ``.vtkhdf`` series; ``load()`` gives the
    frame as a ``pyvista.PolyData`` with its point and field data."""
    h5py = _h5py()
    with h5py.File(path, "r") as f:
        steps = f["VTKHDF/Steps"]
        times = [float(t) for t in steps["Values"][:int(steps.attrs["NSteps"])]]
    return [(t, (lambda k=k: read_frame(path, k))) for k, t in enumerate(times)]


def read_frame(path, step):
    """Frame ``step`` of a ``.vtkhdf`` series as a ``pyvista.PolyData``."""
    import pyvista

    h5py = _h5py()
    with h5py.File(path, "r") as f:
        root, steps = f["VTKHDF"], f["VTKHDF/Steps"]
        start, n = int(steps["PointOffsets"][step]), int(root["NumberOfPoints"][step])
        polygons = root["Polygons"]
        cells = int(steps["CellOffsets"][step, 2])
        ids = int(steps["ConnectivityIdOffsets"][step, 2])
        m = int(polygons["NumberOfCells"][step])
        offsets = polygons["Offsets"][cells:cells + m + 1]
        connectivity = polygons["Connectivity"][ids + offsets[0]:ids + offsets[-1]]
        faces = connectivity.reshape(-1, 3)
        mesh = pyvista.PolyData.from_regular_faces(root["Points"][start:start + n], faces)
        for key in root["PointData"]:
            at = int(steps["PointDataOffsets"][key][step])
            mesh.point_data[key] = root["PointData"][key][at:at + n]
        for key in root["FieldData"]:
            at = int(steps["FieldDataOffsets"][key][step])
            size = int(np.prod(steps["FieldDataSizes"][key][step]))
            mesh.field_data[key] = root["FieldData"][key][at:at + size]
    return mesh
