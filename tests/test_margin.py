"""The default active-set margin, sized by the contact (docs/model.md,
"Active set"): twice the approach a quasi-static guided body's load and wear
reach, on the contact's own geometry, checked against closed forms."""

import math

import numpy as np
import pytest

from meshwear.model.build import build_model
from meshwear.scene.reader import load_scene
from meshwear.surfaces.margin import APPROACHES, _approach

#: the Winkler modulus (N/m³), the load (N) and Archard's coefficient (1/Pa)
K, LOAD, k = 1e12, 20.0, 1e-9


def _scene(tmp_path, shape, orientation, position, path, extra="", motion="guided"):
    force = "" if motion == "prescribed" else f"force = [0.0, 0.0, {-LOAD}]\n"
    text = f"""
format = 1
[run]
mode = "quasi-static"
duration = 2.0
dt = 0.01
frames = 0
history = 2
gravity = [0.0, 0.0, 0.0]
[contact]
stiffness_per_area = {K}
friction = 0.5
{extra}
[wear]
law = "archard"
coefficient = {k}
[[body]]
name = "part"
shape = {shape}
density = 7850.0
orientation = {orientation}
position = {position}
{force}motion = "{motion}"
[body.path]
{path}
[[surface]]
name = "floor"
type = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
"""
    path_ = tmp_path / "scene.toml"
    path_.write_text(text)
    return build_model(load_scene(path_))


def test_the_approach_fills_a_slab_and_a_wedge_exactly():
    # a flat face: the volume over its area
    d, w = np.zeros(4), np.full(4, 0.25)
    assert _approach(d, w, 0.3) == pytest.approx(0.3)
    # steps of area 1 at heights 0, 1, 2: V(1.5) = 1.5 + 0.5 = 2
    assert _approach(np.array([0.0, 1.0, 2.0]), np.ones(3), 2.0) == pytest.approx(1.5)
    assert _approach(np.array([0.0, 1.0, 2.0]), np.ones(3), 0.0) == 0.0
    # past the last breakpoint
    assert _approach(np.array([0.0, 1.0]), np.ones(2), 5.0) == pytest.approx(3.0)


def test_a_flat_pin_gets_twice_its_load_and_wear_over_its_face(tmp_path):
    """A flat-ended pin (radius a) slid in a circle: delta_e = N / (K pi a²),
    delta_w = k N s / (pi a²), s the track's length over the run."""
    a, r, f = 0.003, 0.002, 1.0
    model = _scene(tmp_path, f'{{ type = "cylinder", radius = {a}, height = 0.012, '
                   'sections = 64 }', "[1.0, 0.0, 0.0, 0.0]", "[0.0, 0.0, 0.006]",
                   f"circle = {{ radius = {r}, frequency = {f} }}\nfree_axis = [0.0, 0.0, 1.0]")
    body = model.bodies[0]
    face = 64 / (2 * math.pi) * math.sin(2 * math.pi / 64) * math.pi * a * a   # the polygon's area
    slide = 2 * math.pi * r * f * 2.0
    expected = APPROACHES * (LOAD / (K * face) + k * LOAD * slide / face)
    assert body.margin == pytest.approx(expected, rel=1e-3)
    assert "approach" in body.margin_reason


def test_a_cylinder_on_its_side_gets_the_depth_of_its_worn_segment(tmp_path):
    """A cylinder (R, length L) fretting on its side, stroke ±A at 1 Hz: the
    worn volume V = k N s fills a circular segment of depth delta,
    V = L (4/3) sqrt(2 R) delta^(3/2) (shallow); the same for N / K."""
    R, L, A = 0.006, 0.001, 2.5e-4
    model = _scene(tmp_path, f'{{ type = "cylinder", radius = {R}, height = {L}, '
                   'sections = 1024 }', "[0.70710678, 0.70710678, 0.0, 0.0]",
                   f"[0.0, 0.0, {R}]",
                   f"oscillation = {{ axis = [1.0, 0.0, 0.0], amplitude = {A}, frequency = 1.0 }}\n"
                   "free_axis = [0.0, 0.0, 1.0]")
    body = model.bodies[0]

    def depth(volume):
        return (volume / (L * 4.0 / 3.0 * math.sqrt(2 * R))) ** (2.0 / 3.0)

    slide = 4 * A * 2.0
    expected = APPROACHES * (depth(LOAD / K) + depth(k * LOAD * slide))
    assert body.margin == pytest.approx(expected, rel=0.03)


def test_the_margin_given_or_a_body_whose_contact_is_unknown_keeps_its_size(tmp_path):
    given = _scene(tmp_path, '{ type = "cylinder", radius = 0.003, height = 0.012, '
                   'sections = 32 }', "[1.0, 0.0, 0.0, 0.0]", "[0.0, 0.0, 0.006]",
                   "circle = { radius = 0.02, frequency = 1.0 }\nfree_axis = [0.0, 0.0, 1.0]",
                   extra="margin = 1e-4")
    assert given.bodies[0].margin == 1e-4
    assert given.bodies[0].margin_reason == "contact.margin"
    # prescribed: no load is known, so no approach
    prescribed = _scene(tmp_path, '{ type = "cylinder", radius = 0.003, height = 0.012, '
                        'sections = 32 }', "[1.0, 0.0, 0.0, 0.0]", "[0.0, 0.0, 0.006]",
                        "circle = { radius = 0.02, frequency = 1.0 }", motion="prescribed")
    b = prescribed.bodies[0]
    size = 0.01 * float(np.linalg.norm(np.ptp(b.reference_vertices, axis=0)))
    assert b.margin == pytest.approx(size)
    assert "size" in b.margin_reason
