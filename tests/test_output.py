"""VTK series, history.csv and JSON outputs (docs/outputs.md)."""

import csv
import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest
import pyvista
import vtk
from vtk.util.numpy_support import vtk_to_numpy

from meshwear import geometry
from meshwear.output.tables import HISTORY_COLUMNS, HistoryWriter, write_json_atomic
from meshwear.geometry import plane_patch
from meshwear.output.vtk import PVDSeries

TIMES = (0.0, 0.1, 0.30000000000000004)


def read_vtp(path):
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(str(path))
    reader.Update()
    return reader.GetOutput()


def test_pvd_series_round_trip(tmp_path):
    vertices, faces = geometry.primitive("sphere", radius=0.01, subdivisions=1)
    n = len(vertices)
    series = PVDSeries(tmp_path, "ball", faces)
    written = []
    for i, t in enumerate(TIMES):
        fields = {
            "wear_depth": np.full(n, 1e-6 * i),
            "normal_force": np.linspace(0, 1, n),
            "friction_force": np.tile([1.0, 2.0, 3.0 * i], (n, 1)),
            "contact_state": np.arange(n, dtype=np.int8) % 3,
        }
        written.append(series.write_frame(t, vertices + [0.0, 0.0, t], fields))
        # after every frame the collection is complete, valid XML
        root = ET.parse(tmp_path / "ball.pvd").getroot()
        datasets = root.findall("./Collection/DataSet")
        assert [float(d.get("timestep")) for d in datasets] == list(TIMES[: i + 1])
        assert datasets[-1].get("file") == f"ball/ball_{i:05d}.vtp"
        assert datasets[-1].get("part") == "0" and datasets[-1].get("group") == ""
    series.close()
    assert [p.name for p in written] == ["ball_00000.vtp", "ball_00001.vtp", "ball_00002.vtp"]
    assert not list(tmp_path.glob(".*.tmp"))

    reader = pyvista.PVDReader(tmp_path / "ball.pvd")
    assert reader.time_values == list(TIMES)
    reader.set_active_time_value(TIMES[2])
    block = reader.read()[0]
    np.testing.assert_allclose(block.points[:, 2], vertices[:, 2] + TIMES[2])
    assert pyvista.read(tmp_path / "ball.pvd").n_blocks == 1

    for i, path in enumerate(written):
        poly = read_vtp(path)
        assert poly.GetNumberOfPoints() == n and poly.GetNumberOfPolys() == len(faces)
        data = poly.GetPointData()
        assert data.GetArray("wear_depth").GetNumberOfComponents() == 1
        assert data.GetArray("friction_force").GetNumberOfComponents() == 3
        assert data.GetArray("contact_state").GetNumberOfTuples() == n
        np.testing.assert_array_equal(vtk_to_numpy(data.GetArray("friction_force"))[0], [1.0, 2.0, 3.0 * i])
        np.testing.assert_array_equal(vtk_to_numpy(poly.GetPoints().GetData()), vertices + [0.0, 0.0, TIMES[i]])
        cells = vtk_to_numpy(poly.GetPolys().GetConnectivityArray()).reshape(-1, 3)
        np.testing.assert_array_equal(cells, faces)
        assert vtk_to_numpy(poly.GetFieldData().GetArray("TimeValue"))[0] == TIMES[i]


def test_pvd_series_replaces_an_older_series_and_checks_input(tmp_path):
    vertices, faces = plane_patch([0, 0, 0], [0, 0, 1], 1.0)
    first = PVDSeries(tmp_path, "floor", faces)
    for t in TIMES:
        first.write_frame(t, vertices, {})
    second = PVDSeries(tmp_path, "floor", faces)
    assert ET.parse(tmp_path / "floor.pvd").getroot().findall("./Collection/DataSet") == []
    assert list((tmp_path / "floor").iterdir()) == []
    second.write_frame(0.5, vertices, {})
    assert pyvista.PVDReader(tmp_path / "floor.pvd").time_values == [0.5]
    with pytest.raises(ValueError, match="point data 'bad'"):
        second.write_frame(1.0, vertices, {"bad": np.zeros(len(vertices) + 1)})
    with pytest.raises(ValueError, match="points have shape"):
        second.write_frame(1.0, vertices[:, :2], {})
    with pytest.raises(ValueError, match="path separators"):
        PVDSeries(tmp_path, "a/b", faces)


def test_series_names_are_escaped_in_xml(tmp_path):
    vertices, faces = plane_patch([0, 0, 0], [0, 0, 1], 1.0)
    series = PVDSeries(tmp_path, 'pin & "disc"', faces)
    series.write_frame(0.0, vertices, {})
    dataset = ET.parse(tmp_path / 'pin & "disc".pvd').getroot().find("./Collection/DataSet")
    assert dataset.get("file") == 'pin & "disc"/pin & "disc"_00000.vtp'


@pytest.mark.parametrize("normal", [[0, 0, 1], [0, 0, -2], [1, 1, 0], [0.3, -0.2, 0.9]])
def test_plane_patch(normal):
    point = np.array([1.0, 2.0, 3.0])
    vertices, faces = plane_patch(point, normal, 0.5, divisions=4)
    unit = np.asarray(normal, float) / np.linalg.norm(normal)
    assert vertices.shape == (25, 3) and faces.shape == (32, 3)
    np.testing.assert_allclose((vertices - point) @ unit, 0.0, atol=1e-15)
    np.testing.assert_allclose(vertices.mean(axis=0), point, atol=1e-15)
    np.testing.assert_allclose(geometry.face_normals(vertices, faces), np.tile(unit, (32, 1)), atol=1e-12)
    assert geometry.tributary_areas(vertices, faces).sum() == pytest.approx(0.25, rel=1e-12)


def test_history_round_trip(tmp_path):
    path = tmp_path / "history.csv"
    writer = HistoryWriter(path, extra_columns=("contact_points",))
    rows = []
    for i, t in enumerate(TIMES):
        for body in ("block", "pin, 2"):
            row = {c: np.float64(0.1 * i + 1e-17 * j) for j, c in enumerate(HISTORY_COLUMNS)}
            row.update(time=t, body=body, contact_points=np.int64(i), x=float("nan"))
            writer.write(row)
            rows.append(row)
        # flushed: a reader sees every complete sample while the run goes on
        assert len(path.read_text().splitlines()) == 1 + 2 * (i + 1)
    with pytest.raises(ValueError, match=r"missing columns \['fx'\]"):
        writer.write({k: v for k, v in rows[0].items() if k != "fx"})
    with pytest.raises(ValueError, match=r"unknown columns \['speed'\]"):
        writer.write({**rows[0], "speed": 1.0})
    writer.close()

    with open(path, newline="") as f:
        read = list(csv.DictReader(f))
    assert tuple(read[0]) == HISTORY_COLUMNS + ("contact_points",)
    assert len(read) == len(rows)
    for got, row in zip(read, rows):
        assert got["body"] == row["body"] and got["contact_points"] == str(int(row["contact_points"]))
        assert np.isnan(float(got["x"]))
        for c in HISTORY_COLUMNS:
            if c not in ("body", "x"):
                assert float(got[c]) == row[c]          # repr precision: exact round trip


def test_write_json_atomic(tmp_path):
    path = tmp_path / "summary.json"
    obj = {
        "format": 1,
        "time": np.float64(0.1),
        "steps": np.int64(10),
        "ok": np.bool_(True),
        "bodies": {"block": {"position": np.array([1.0, 2.0, 1 / 3]), "mass": float("nan")}},
        "cycles": None,
        "path": tmp_path,
    }
    write_json_atomic(path, obj)
    back = json.loads(path.read_text())
    assert back["time"] == 0.1 and back["steps"] == 10 and back["ok"] is True
    assert back["bodies"]["block"]["position"] == [1.0, 2.0, 1 / 3]
    assert back["bodies"]["block"]["mass"] is None and back["cycles"] is None
    assert back["path"] == str(tmp_path)
    write_json_atomic(path, {"format": 1})
    assert json.loads(path.read_text()) == {"format": 1}
    with pytest.raises(TypeError):
        write_json_atomic(path, {"bad": object()})
    assert json.loads(path.read_text()) == {"format": 1}              # untouched by the failure
    assert [p.name for p in tmp_path.iterdir()] == ["summary.json"]    # no temporary left
