"""``run.series = "vtkhdf"``: one VTKHDF temporal file per part
(docs/outputs.md). VTK's own reader (what ParaView uses) sees every frame
with its points, point and field data; a run writes the same frames as its
.pvd twin; export and plot read it; resuming keeps the frames up to the
checkpoint and a resumed run ends with the frames of a run never stopped."""

import json
import signal
import time

import h5py
import numpy as np
import pytest
import vtk
from vtk.util.numpy_support import vtk_to_numpy

from meshwear.longrun import checkpoint
from meshwear.cli import main
from meshwear.output.export import part_mesh, series_frames
from meshwear.output.vtkhdf import VTKHDFSeries, read_frames
from meshwear.scene.reader import load_scene
from meshwear.scene.checks import SceneError
from test_resume import _block_scene, _meshwear, _rows

FACES = np.array([[0, 1, 2], [0, 2, 3], [1, 3, 2]])


def frames(k):
    rng = np.random.default_rng(k)
    return (rng.random((4, 3)), {"wear_depth": rng.random(4), "contact_state": rng.random(4) > .5},
            {"resolved": k % 2, "origin": rng.random(3), "orientation": rng.random(4)})


def vtk_read(path, t):
    reader = vtk.vtkHDFReader()
    reader.SetFileName(str(path))
    reader.UpdateTimeStep(t)
    return reader.GetOutput()


def test_vtk_reads_every_frame_written(tmp_path):
    times = [0.0, 0.25, 0.5, 1.5]
    with VTKHDFSeries(tmp_path, "pin", FACES) as series:
        for k, t in enumerate(times):
            series.write_frame(t, *frames(k))
        assert series.times == times
    reader = vtk.vtkHDFReader()
    reader.SetFileName(str(tmp_path / "pin.vtkhdf"))
    reader.UpdateInformation()
    key = vtk.vtkStreamingDemandDrivenPipeline.TIME_STEPS()
    assert list(reader.GetOutputInformation(0).Get(key)) == times
    for k, t in enumerate(times):
        points, data, fields = frames(k)
        out = vtk_read(tmp_path / "pin.vtkhdf", t)
        np.testing.assert_array_equal(vtk_to_numpy(out.GetPoints().GetData()), points)
        polys = vtk_to_numpy(out.GetPolys().GetConnectivityArray()).reshape(-1, 3)
        np.testing.assert_array_equal(polys, FACES)
        np.testing.assert_array_equal(vtk_to_numpy(out.GetPointData().GetArray("wear_depth")),
                                      data["wear_depth"])
        np.testing.assert_array_equal(vtk_to_numpy(out.GetPointData().GetArray("contact_state")),
                                      data["contact_state"].astype(np.uint8))
        for name, value in fields.items():
            np.testing.assert_array_equal(vtk_to_numpy(out.GetFieldData().GetArray(name)),
                                          np.atleast_1d(value))
        # meshwear's own reader agrees
        mesh = read_frames(tmp_path / "pin.vtkhdf")[k][1]()
        np.testing.assert_array_equal(mesh.points, points)
        np.testing.assert_array_equal(mesh.regular_faces, FACES)


def test_resuming_keeps_the_frames_up_to_the_checkpoint(tmp_path):
    with VTKHDFSeries(tmp_path, "pin", FACES) as series:
        for k in range(5):
            series.write_frame(0.1 * k, *frames(k))
    with VTKHDFSeries(tmp_path, "pin", FACES, resume_until=0.2) as series:
        assert series.times == [0.0, 0.1, 0.2]
        series.write_frame(0.3, *frames(7))
    out = vtk_read(tmp_path / "pin.vtkhdf", 0.3)
    np.testing.assert_array_equal(vtk_to_numpy(out.GetPoints().GetData()), frames(7)[0])
    assert [t for t, _ in read_frames(tmp_path / "pin.vtkhdf")] == [0.0, 0.1, 0.2, 0.3]
    # a fresh run replaces it
    with VTKHDFSeries(tmp_path, "pin", FACES) as series:
        assert series.times == []


def test_a_frame_cut_short_is_dropped_on_resume(tmp_path):
    series = VTKHDFSeries(tmp_path, "pin", FACES)
    series.write_frame(0.0, *frames(0))
    # a run killed while appending frame 1: its points are in, its step is not counted
    series._append(series._file["VTKHDF/Points"], frames(1)[0])
    series.close()
    assert [t for t, _ in read_frames(tmp_path / "pin.vtkhdf")] == [0.0]
    with VTKHDFSeries(tmp_path, "pin", FACES, resume_until=0.0) as series:  # --resume
        series.write_frame(0.5, *frames(2))
    out = vtk_read(tmp_path / "pin.vtkhdf", 0.5)
    np.testing.assert_array_equal(vtk_to_numpy(out.GetPoints().GetData()), frames(2)[0])
    with h5py.File(tmp_path / "pin.vtkhdf", "r") as f:   # the cut rows are gone
        assert f["VTKHDF/Points"].shape == (2 * len(frames(0)[0]), 3)


def test_a_run_writes_the_frames_of_its_pvd_twin(tmp_path, capsys):
    scene = _block_scene(tmp_path, duration=0.01)
    pvd, hdf = tmp_path / "pvd", tmp_path / "hdf"
    common = ["--set", "run.frames=5", "-q"]
    assert main(["run", str(scene), "-o", str(pvd), *common]) == 0
    assert main(["run", str(scene), "-o", str(hdf), "--set", "run.series=vtkhdf", *common]) == 0
    assert not (hdf / "block.pvd").exists() and (hdf / "block.vtkhdf").is_file()
    assert (hdf / "plate.vtkhdf").is_file()
    a, b = series_frames(pvd, "block"), series_frames(hdf, "block")
    assert [t for t, _ in a] == [t for t, _ in b] and len(a) == 5
    for k in (0, -1):
        va, fa, _ = part_mesh(pvd, "block", k)
        vb, fb, _ = part_mesh(hdf, "block", k)
        np.testing.assert_array_equal(va, vb)
        np.testing.assert_array_equal(fa, fb)
    assert main(["export", str(hdf), "--format", "stl"]) == 0
    assert (hdf / "block_00004.stl").is_file()


def test_without_h5py_the_key_names_the_extra(tmp_path, monkeypatch):
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "h5py" else real(name, *a))
    scene = _block_scene(tmp_path, duration=0.01)
    with pytest.raises(SceneError, match=r"run\.series: 'vtkhdf' needs h5py.*meshwear\[hdf\]"):
        load_scene(scene, [("run.series", "vtkhdf")])


def test_sigterm_then_resume_gives_the_frames_of_a_run_never_stopped(tmp_path):
    scene = _block_scene(tmp_path, duration=0.3)
    full, cut = tmp_path / "full", tmp_path / "cut"
    args = ["--set", "run.series=vtkhdf", "--set", "run.frames=31"]
    assert _meshwear("run", scene, "-o", full, "-q", *args).wait(timeout=300) == 0
    job = _meshwear("run", scene, "-o", cut, *args)
    deadline = time.time() + 120
    # the file is locked while written: wait on the history rows instead
    while not (cut / "history.csv").exists() or len(_rows(cut / "history.csv")) < 40:
        assert job.poll() is None, "the run ended before it could be stopped"
        assert time.time() < deadline
        time.sleep(0.05)
    job.send_signal(signal.SIGTERM)
    _, err = job.communicate(timeout=120)
    assert job.returncode == 143, err
    assert (cut / checkpoint.FILE_NAME).exists()
    stopped = len(read_frames(cut / "block.vtkhdf"))
    assert 1 <= stopped < 31
    resumed = _meshwear("run", scene, "-o", cut, "--resume", "-q", *args)
    _, err = resumed.communicate(timeout=300)
    assert resumed.returncode == 0, err
    a, b = read_frames(full / "block.vtkhdf"), read_frames(cut / "block.vtkhdf")
    assert [t for t, _ in a] == [t for t, _ in b]
    for (_, fa), (_, fb) in zip(a, b):
        ma, mb = fa(), fb()
        np.testing.assert_allclose(mb.points, ma.points, rtol=0, atol=1e-15)
        np.testing.assert_allclose(mb.point_data["wear_depth"], ma.point_data["wear_depth"],
                                   rtol=1e-9, atol=0)
    summary = json.loads((cut / "summary.json").read_text())
    assert summary["status"] == "ok"
