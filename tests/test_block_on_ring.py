"""Block on ring (examples/block_on_ring.toml), its 3000 m on a coarser face:
the scar takes the ring's arc, its volume is k P s, its depth that of the
circular segment of that volume, and an analytic ring and a mesh ring
agree (docs/examples/block_on_ring.md). The full example is measured by
benchmarks/block_on_ring.py."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from meshwear.model.build import build_model, initial_state
from meshwear.scene.reader import load_scene
from meshwear.step.simulate import run

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
R, P, K, WIDTH = 0.0175, 10.0, 4e-14, 0.01
#: s: the example's 3000 m at 0.5 m/s. Jumps that kept the volume by scaling
#: every vertex's wear left the scar on the arc at 300 m; after jumps of
#: thousands of turns, at 3000 m, its edge was 1.5 % of the depth off it
DURATION = 6000.0


def _short(path):
    scene = load_scene(path)
    body = dataclasses.replace(scene.bodies[0], resolution=1.5e-4)
    return dataclasses.replace(
        scene, bodies=(body,),
        run=dataclasses.replace(scene.run, duration=DURATION, frames=0, history=11))


def _scar(path):
    scene = _short(path)
    model = build_model(scene)
    state = run(model, initial_state(model))
    body, s = model.bodies[0], state.bodies[0]
    z = body.reference_vertices[:, 2]
    face = z <= z.min() + 1e-9
    return scene, model, state, body.reference_vertices[face, 0], s.wear_depth[face]


def _segment_depth(volume):
    def area(h):
        return R * R * np.arccos(1.0 - h / R) - (R - h) * np.sqrt(2.0 * R * h - h * h)
    return brentq(lambda h: area(h) * WIDTH - volume, 1e-12, R)


@pytest.fixture(scope="module")
def scars():
    return {name: _scar(EXAMPLES / f"{name}.toml") for name in ("block_on_ring",
                                                                "block_on_ring_mesh")}


def test_the_scar_takes_the_ring_s_arc_and_k_load_distance(scars, measured):
    scene, model, state, x, w = scars["block_on_ring"]
    volume = state.bodies[0].wear_volume.sum()
    expected = K * P * 0.5 * DURATION
    measured("block on ring (3000 m): volume / k P s", volume, expected, 5e-3)
    assert volume == pytest.approx(expected, rel=5e-3)
    h = w.max()
    measured("block on ring: depth vs segment of k P s", h, _segment_depth(expected), 1e-2)
    assert h == pytest.approx(_segment_depth(expected), rel=1e-2)
    arc = np.maximum(h - (R - np.sqrt(R * R - x * x)), 0.0)
    error = np.abs(w - arc).max() / h
    measured("block on ring: scar vs the ring's arc", error, 0.0, 1e-2)
    assert error < 1e-2
    # the scar is as wide as the arc allows, and cycles were jumped over
    assert np.abs(x[w > 0.0]).max() == pytest.approx(np.sqrt(2.0 * R * h), abs=2e-4)
    assert state.jump.resolved_steps < 0.05 * model.n_steps


def test_a_mesh_ring_wears_the_scar_of_the_analytic_ring(scars, measured):
    _, _, _, x, w = scars["block_on_ring"]
    _, model, state, xm, wm = scars["block_on_ring_mesh"]
    assert np.array_equal(x, xm)
    assert model.surfaces.per_vertex[0].invariant
    error = np.abs(wm - w).max() / w.max()
    measured("block on ring: mesh ring vs analytic", error, 0.0, 1e-2)
    assert error < 1e-2


@pytest.mark.parametrize("name", ["block_on_ring", "block_on_ring_mesh"])
def test_check_says_the_ring_is_static_in_shape(name, capsys):
    from meshwear.cli import main

    assert main(["check", str(EXAMPLES / f"{name}.toml")]) == 0
    out = capsys.readouterr().out
    assert "static in shape" in out and "implicit jumps" in out
