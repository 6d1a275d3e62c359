"""The involute spur gear generator (meshes/make_gear.py): a closed mesh
whose flanks are involutes of the base circle and whose teeth are pi m / 2
thick on the pitch circle."""

import importlib.util
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("make_gear", ROOT / "meshes" / "make_gear.py")
make_gear = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(make_gear)


@pytest.mark.parametrize("module, teeth, layers", [(2.0, 20, 1), (1.5, 31, 1), (3.0, 12, 1),
                                                  (2.0, 20, 4)])
def test_a_gear_is_a_closed_outward_mesh(module, teeth, layers):
    vertices, faces = make_gear.gear_mesh(module, teeth, 8.0, layers=layers)
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    # the flanks in rows across the face width
    assert np.unique(np.round(vertices[:, 2], 9)).size == layers + 1
    assert mesh.is_watertight and mesh.is_winding_consistent
    # between the root and the tip discs, and outward (positive volume)
    r = 0.5 * module * teeth
    assert np.pi * (r - 1.25 * module) ** 2 * 8.0 < mesh.volume < np.pi * (r + module) ** 2 * 8.0
    assert (mesh.area_faces > 0.0).all()


@pytest.mark.parametrize("module, teeth", [(2.0, 20), (1.5, 31)])
def test_flanks_are_involutes_of_the_base_circle(module, teeth):
    """The normal of an involute at any point is tangent to its base circle:
    the flank's tangent t at P satisfies |P . t| = r_b."""
    ring = make_gear.outline(module, teeth, flank_points=64)
    rb = 0.5 * module * teeth * np.cos(np.radians(20.0))
    rho = np.linalg.norm(ring, axis=1)
    ra = 0.5 * module * teeth + module
    inner = (rho > rb * 1.02) & (rho < ra * 0.995)
    idx = np.flatnonzero(inner[1:-1] & inner[:-2] & inner[2:]) + 1
    tangent = ring[idx + 1] - ring[idx - 1]
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    along = np.abs(np.einsum("ij,ij->i", ring[idx], tangent))
    assert len(idx) > 2 * teeth * 10
    np.testing.assert_allclose(along, rb, rtol=2e-3)


@pytest.mark.parametrize("module, teeth", [(2.0, 20), (1.5, 31), (3.0, 12)])
def test_teeth_are_half_a_pitch_thick_on_the_pitch_circle(module, teeth):
    ring = make_gear.outline(module, teeth, flank_points=64)
    r = 0.5 * module * teeth
    angle = np.arctan2(ring[:, 1], ring[:, 0])
    rho = np.linalg.norm(ring, axis=1)
    # tooth 0, centred on +x: where its flanks cross the pitch circle
    near = np.abs(angle) < np.pi / teeth
    crossings = []
    for j in np.flatnonzero(near[:-1] & near[1:]):
        if (rho[j] - r) * (rho[j + 1] - r) < 0.0:
            f = (r - rho[j]) / (rho[j + 1] - rho[j])
            crossings.append(angle[j] + f * (angle[j + 1] - angle[j]))
    assert len(crossings) == 2
    thickness = r * (max(crossings) - min(crossings))
    assert thickness == pytest.approx(np.pi * module / 2.0, rel=1e-3)


def test_the_script_writes_an_stl_meshwear_loads(tmp_path):
    out = tmp_path / "gear.stl"
    done = subprocess.run([sys.executable, str(ROOT / "meshes" / "make_gear.py"), "--module", "2",
                           "--teeth", "18", "--width", "6", "-o", str(out)],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "watertight True" in done.stdout
    from meshwear import geometry

    vertices, faces = geometry.load_mesh(out, units="mm")
    assert np.ptp(vertices[:, 2]) == pytest.approx(0.006, rel=1e-9)
    assert np.ptp(vertices[:, 0]) == pytest.approx(0.002 * (18 / 2 + 1) * 2, rel=1e-2)
