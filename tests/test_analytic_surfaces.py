"""Analytic counter-surfaces (cylinder, sphere, turning plane) and shape-invariant motion.

The kernels against their numpy twins; then closed forms (docs/model.md):
Winkler line contact of a cylinder on a flat, a shaft in a conforming bore,
k P s under turning surfaces; then the detection of a turning mesh that is a
surface of revolution, and what it saves (no active-set refreshes).
"""

from pathlib import Path

import numpy as np
import pytest

import reference
from meshwear import geometry
from meshwear.kernels import analytic, frames
from meshwear.model.build import build_model, initial_state
from meshwear.scene.reader import load_scene
from meshwear.scene.parts import RotationConfig
from meshwear.step.simulate import run_scene, step
from meshwear.surfaces import MeshSurface

ROOT = Path(__file__).resolve().parents[1]

RTOL = 1e-12


def _close(a, b):
    scale = max(np.abs(b[np.isfinite(b)]).max(initial=0.0), 1e-300)
    same_inf = np.isinf(a) == np.isinf(b)
    fa, fb = np.where(np.isfinite(a), a, 0.0), np.where(np.isfinite(b), b, 0.0)
    return bool(same_inf.all() and np.all(np.abs(fa - fb) <= RTOL * (np.abs(fb) + scale)))


def _unit(v):
    return v / np.linalg.norm(v)


def _random_motion(rng):
    """A surface motion with every part set: a tilted frame, a turn about an
    off-centre axis, and a path of an oscillation, a velocity and a circle."""
    q = _unit(rng.normal(size=4))
    motion = np.concatenate([reference.quaternion_matrix(q).ravel(), rng.normal(size=3) * 0.01,
                             _unit(rng.normal(size=3)), [7.0], rng.normal(size=3) * 0.01])
    e1 = _unit(np.cross(_unit(rng.normal(size=3)), [0.0, 0.0, 1.0]))
    e2 = np.cross([0.0, 0.0, 1.0], e1)
    terms = np.array([[0, *_unit(rng.normal(size=3)), 0, 0, 0, 1e-3, 30.0],
                      [1, 0.1, -0.2, 0.05, 0, 0, 0, 0, 0],
                      [2, *e1, *e2, 0.004, 3.0]])
    return motion, terms


@pytest.mark.parametrize("frozen", [False, True])
def test_surface_frame_matches_numpy_twin(frozen):
    rng = np.random.default_rng(1)
    motion, terms = _random_motion(rng)
    for t in (0.0, 0.37, 2.9):
        rotation, frame = np.zeros((3, 3)), np.zeros((4, 3))
        frames.surface_frame(motion, terms, t, frozen, np.zeros((2, 3)), rotation, frame)
        twin_rotation, twin_frame = reference.surface_frame(motion, terms, t, frozen)
        assert _close(rotation, twin_rotation) and _close(frame, twin_frame)


KERNELS = [
    ("cylinder", analytic.cylinder_planes_serial, [0.01, 0.004, 0.0]),     # finite shaft
    ("cylinder", analytic.cylinder_planes_parallel, [0.01, np.inf, 1.0]),  # infinite bore
    ("cylinder", analytic.cylinder_planes_serial, [0.01, np.inf, 0.0]),
    ("sphere", analytic.sphere_planes_serial, [0.01, 0.0, 0.0]),           # ball
    ("sphere", analytic.sphere_planes_parallel, [0.01, 1.0, 0.0]),         # cup
]


@pytest.mark.parametrize("kind,kernel,geometry_", KERNELS)
def test_analytic_planes_match_numpy_twin(kind, kernel, geometry_):
    """Vertices in and around the surface (some beyond a finite cylinder's
    ends, one on its axis), a turned body, a moving and turning surface."""
    rng = np.random.default_rng(7)
    n = 500
    motion, terms = _random_motion(rng)
    rotation, frame = np.zeros((3, 3)), np.zeros((4, 3))
    frames.surface_frame(motion, terms, 0.21, False, np.zeros((2, 3)), rotation, frame)
    local = rng.normal(size=(n, 3)) * 0.008
    world = local @ rotation.T + frame[0]
    pose = np.zeros(13)
    pose[0:3] = [0.001, -0.002, 0.003]
    pose[3:7] = _unit(rng.normal(size=4))
    body = np.ascontiguousarray((world - pose[0:3]) @ reference.quaternion_matrix(pose[3:7]))
    active = np.flatnonzero(rng.random(n) < 0.8)
    geometry_ = np.array(geometry_)
    out, distance = np.full((n, 3, 3), -1.0), np.full(n, -1.0)
    twin_out, twin_distance = out.copy(), distance.copy()
    kernel(body, pose, active, rotation, frame, geometry_, out, distance)
    twin = reference.cylinder_planes if kind == "cylinder" else reference.sphere_planes
    twin(body, pose, active, rotation, frame, geometry_, twin_out, twin_distance)
    assert _close(out, twin_out) and _close(distance, twin_distance)
    inactive = np.setdiff1d(np.arange(n), active)
    assert (distance[inactive] == -1.0).all()
    found = np.isfinite(distance[active])
    assert found.mean() > 0.3
    if kind == "cylinder" and np.isfinite(geometry_[1]):
        assert found.mean() < 0.9                    # some beyond its ends
    # the normal is a unit vector, and the point lies on the surface
    normals = out[active[found], 1]
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0, rtol=0, atol=1e-12)
    points = (out[active[found], 0] - frame[0]) @ rotation
    radius = (np.hypot(points[:, 0], points[:, 1]) if kind == "cylinder"
              else np.linalg.norm(points, axis=1))
    assert np.allclose(radius, geometry_[0], rtol=1e-12)
    # a vertex on the axis (at the centre) has no closest point, hence no plane
    identity = np.zeros(13)
    identity[3] = 1.0
    one, gap = np.ones((1, 3, 3)), np.zeros(1)
    kernel(np.array([[0.0, 0.0, 0.001 if kind == "cylinder" else 0.0]]), identity,
           np.zeros(1, np.int64), np.eye(3), np.zeros((4, 3)), geometry_, one, gap)
    assert not one.any() and gap[0] == np.inf


# ------------------------------------------------------------ closed forms

LINE_CONTACT = """format = 1
[run]
mode = "quasi-static"
duration = 0.002
dt = 1e-3
frames = 0
history = 2
gravity = [0.0, 0.0, 0.0]

[contact]
stiffness_per_area = {K}
friction = 0.3

[wear]
law = "archard"
coefficient = 0.0

[[body]]
name = "block"
shape = {{ type = "box", size = [0.001, {L}, 0.0005] }}
resolution = 1.25e-5
position = [0.0, 0.0, {z}]
force = [0.0, 0.0, -{P}]
motion = "guided"
[body.path]
free_axis = [0.0, 0.0, 1.0]

[[surface]]
name = "roller"
type = "cylinder"
radius = {R}
axis = [0.0, 1.0, 0.0]
point = [0.0, 0.0, 0.0]
"""


def test_a_cylinder_on_a_flat_has_the_winkler_line_contact_approach(tmp_path, measured):
    """A flat block pressed by P on a cylinder (radius R, contact length L) on
    a Winkler foundation K: p = K (delta - x^2 / 2R) over |x| < b = sqrt(2 R delta),
    so P = (4/3) K L b delta and delta = (3 P / (4 K L sqrt(2R)))^(2/3)."""
    K, R, L, P = 1e12, 0.01, 1e-3, 1.0
    path = tmp_path / "line.toml"
    path.write_text(LINE_CONTACT.format(K=K, R=R, L=L, P=P, z=R + 0.00025))
    model = build_model(load_scene(path))
    state = initial_state(model)
    body, s = model.bodies[0], state.bodies[0]
    lowest = (s.pose[0:3] + s.vertices @ reference.quaternion_matrix(s.pose[3:7]).T)[:, 2].min()
    approach = R - lowest
    expected = (3 * P / (4 * K * L * np.sqrt(2 * R))) ** (2.0 / 3.0)
    measured("cylinder on flat: approach (m)", approach, expected, 1e-2)
    assert approach == pytest.approx(expected, rel=1e-2)
    # the half-width of the loaded strip: sqrt(2 R delta)
    loaded = s.normal_force[0] > 0.0
    x = body.reference_vertices[loaded, 0]
    width = 0.5 * (x.max() - x.min())
    spacing = 1.25e-5
    assert abs(width - np.sqrt(2 * R * expected)) < 1.5 * spacing
    # the balance is solved on the tangent planes found before the settling
    # move (1e-7 of the load here, docs/model.md)
    assert s.wrench[2] == pytest.approx(P, rel=1e-5)


BORE = """format = 1
[run]
mode = "quasi-static"
duration = {duration}
dt = 1e-3
frames = 0
history = 3
gravity = [0.0, 0.0, 0.0]

[contact]
stiffness_per_area = {K}
tangential_stiffness_per_area = {K}
friction = 0.3

[wear]
law = "archard"
coefficient = {k}

[[body]]
name = "shaft"
shape = {{ type = "cylinder", radius = {R}, height = {L}, sections = 256 }}
force = [0.0, -{P}, 0.0]
motion = "guided"
[body.path]
free_axis = [0.0, 1.0, 0.0]

[[surface]]
name = "bushing"
type = "cylinder"
radius = {R}
axis = [0.0, 0.0, 1.0]
side = "inside"
{rotation}
"""


def test_a_shaft_in_a_conforming_bore_has_the_winkler_approach(tmp_path, measured):
    """A shaft of radius R and length L in a bore of the same radius, pressed
    by P: the penetration is delta cos(theta) over the loaded half, so
    P = K delta R L pi/2 and delta = 2 P / (pi K R L)."""
    K, R, L, P = 1e12, 0.01, 0.01, 100.0
    path = tmp_path / "bore.toml"
    path.write_text(BORE.format(K=K, R=R, L=L, P=P, k=0.0, duration=0.002, rotation=""))
    model = build_model(load_scene(path))
    state = initial_state(model)
    approach = -state.bodies[0].pose[1]
    expected = 2 * P / (np.pi * K * R * L)
    measured("shaft in bore: approach (m)", approach, expected, 1e-2)
    assert approach == pytest.approx(expected, rel=1e-2)


def test_a_shaft_in_a_turning_bore_wears_four_over_pi_k_load_distance(tmp_path, measured):
    """The bore turns about its own axis at omega: every loaded point of the
    shaft slips at omega R against it, and Archard wear removes k p |ds| dA,
    so V = k s * (sum of the normal forces) = (4/pi) k P omega R t (the normal
    forces of the cosine distribution add up to 4P/pi). The turning bore
    keeps its shape: the active set is never refreshed after the start."""
    K, R, L, P, k, omega, duration = 1e12, 0.01, 0.01, 100.0, 1e-12, 10.0, 0.5
    rotation = f"rotation = {{ axis = [0.0, 0.0, 1.0], rate = {omega} }}"
    path = tmp_path / "turning_bore.toml"
    path.write_text(BORE.format(K=K, R=R, L=L, P=P, k=k, duration=duration, rotation=rotation))
    model, state, history = run_scene(load_scene(path))
    assert model.surfaces.per_vertex[0].invariant
    volume = history.rows["shaft"]["wear_volume"][-1]
    expected = 4 / np.pi * k * P * omega * R * duration
    measured("shaft in turning bore: volume (m³)", volume, expected, 5e-3)
    assert volume == pytest.approx(expected, rel=5e-3)
    # the bushing drags the shaft's surface along its turn: a torque about z
    torque = state.bodies[0].wrench[5]
    assert torque == pytest.approx(0.3 * 4 / np.pi * P * R, rel=1e-2)
    # the wear is on the loaded side (-y) only
    s, body = state.bodies[0], model.bodies[0]
    worn = s.wear_depth > 0.0
    assert (body.reference_vertices[worn, 1] < 1e-12).all()
    assert state.bodies[0].cull[1] == 0.0           # refreshed at t = 0 only


PIN_ON_PLANE = """format = 1
[run]
mode = "quasi-static"
duration = 0.5
dt = 1e-3
frames = 0
history = 11

[contact]
stiffness_per_area = 1e13
tangential_stiffness_per_area = 1e13
friction = 0.4

[wear]
law = "archard"
coefficient = 1e-12

[[body]]
name = "pin"
shape = { type = "cylinder", radius = 0.002, height = 0.006, sections = 32 }
resolution = 3e-4
density = 7850.0
position = [0.03, 0.0, 0.003]
force = [0.0, 0.0, -10.0]
motion = "guided"
[body.path]
free_axis = [0.0, 0.0, 1.0]

[[surface]]
name = "disc"
type = "plane"
rotation = { axis = [0.0, 0.0, 1.0], rate = 10.0, center = [0.0, 0.0, 0.0] }
"""


def test_a_pin_on_a_turning_analytic_disc_wears_k_load_distance(tmp_path, measured):
    """The disc as an analytic plane turning about its normal: V = k P omega r t,
    and the friction force drags the pin along the disc's motion (+y)."""
    path = tmp_path / "pin.toml"
    path.write_text(PIN_ON_PLANE)
    model, state, history = run_scene(load_scene(path))
    load = 10.0 + model.bodies[0].mass * 9.81
    expected = 1e-12 * load * 10.0 * 0.03 * 0.5
    volume = history.rows["pin"]["wear_volume"][-1]
    measured("pin on turning plane: volume (m³)", volume, expected, 5e-3)
    assert volume == pytest.approx(expected, rel=5e-3)
    assert state.bodies[0].wrench[1] == pytest.approx(0.4 * load, rel=1e-3)
    assert model.surfaces.uniform[0].invariant and state.bodies[0].cull[1] == 0.0


# ------------------------------------------------------------ shape invariance

def _ring(sections, center=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0)):
    v, f = geometry.primitive("cylinder", radius=0.02, height=0.01, sections=sections)
    return MeshSurface("ring", v, f, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0),
                       rotation=RotationConfig(axis=axis, rate=5.0, center=center))


def test_a_turning_mesh_ring_deviates_from_its_surface_of_revolution_by_its_sagitta():
    ring = _ring(360)
    sagitta = 0.02 * (1.0 - np.cos(np.pi / 360))
    deviation = ring.revolution_deviation(1e-3)
    assert 0.5 * sagitta <= deviation <= 1.01 * sagitta
    # turned about an axis 1 mm off its own, or about a diameter: not invariant
    assert ring.revolution_deviation(1e-3) < 1e-3
    assert _ring(360, center=(0.001, 0.0, 0.0)).revolution_deviation(1e-4) == np.inf
    assert _ring(360, axis=(1.0, 0.0, 0.0)).revolution_deviation(1e-4) == np.inf
    # a coarse ring: its facets' sagitta (0.38 mm) against a 0.1 mm margin
    coarse = _ring(16)
    coarse.settle_invariance(1e-4)
    assert not coarse.invariant
    fine = _ring(360)
    fine.settle_invariance(1e-4)
    assert fine.invariant and 0.5 * sagitta <= fine.deviation <= 1.01 * sagitta


def test_a_cylinder_shape_turning_about_its_axis_deviates_by_its_facets_sag():
    """A cylinder ``shape`` (refined or not) turning about its own axis
    deviates from itself by its side facets' sag (docs/model.md), taken
    without sampling: no less than the sampled deviation, and answered at
    once for 20 000 sections, whose caps are fans of slivers round their
    centres, each query near a centre meeting all their boxes (sampled:
    O(sections²), 5-9 s for 10 000). Off its axis it is sampled as before."""
    import time

    from meshwear.scene.parts import ShapeConfig

    def shaped(sections, **kwargs):
        ring = _ring(sections, **kwargs)
        ring.shape = ShapeConfig(type="cylinder", radius=0.02, height=0.01, sections=sections)
        return ring

    for sections in (16, 64, 360):
        sagitta = 0.02 * (1.0 - np.cos(np.pi / sections))
        sampled = _ring(sections).revolution_deviation(np.inf)
        assert shaped(sections).revolution_deviation(np.inf) == pytest.approx(sagitta, rel=1e-9)
        assert sampled <= sagitta * (1.0 + 1e-9)
    assert shaped(360, center=(0.001, 0.0, 0.0)).revolution_deviation(1e-4) == np.inf
    assert shaped(360, axis=(1.0, 0.0, 0.0)).revolution_deviation(1e-4) == np.inf
    # refined where a pin can reach it: its side's facets, some split, on the cylinder
    model = build_model(load_scene(ROOT / "examples" / "pin_on_turning_disc.toml",
                                   (("surface[0].resolution", 1e-3),)))
    disc = model.surfaces.meshes[0]
    assert disc.invariant and disc.refinement is not None
    own = disc.deviation
    disc.shape = None
    assert disc.revolution_deviation(np.inf) <= own * (1.0 + 1e-9)
    big = shaped(20_000)
    start = time.perf_counter()
    big.settle_invariance(1e-4)
    assert time.perf_counter() - start < 1.0
    assert big.invariant and big.deviation == pytest.approx(0.02 * (1.0 - np.cos(np.pi / 20_000)))


def test_check_says_a_turning_disc_mesh_is_static_in_shape(capsys):
    from meshwear.cli import main

    root = __import__("pathlib").Path(__file__).resolve().parents[1]
    assert main(["check", str(root / "examples" / "pin_on_turning_disc.toml")]) == 0
    out = capsys.readouterr().out
    assert "static in shape" in out and "turning at 10 rad/s" in out


def test_a_turning_disc_mesh_costs_no_refresh_and_keeps_the_slip_velocity(tmp_path,
                                                                          monkeypatch):
    """The pin on the turning disc mesh: the active set is built once and
    holds only the pin's end face; each vertex keeps its face; the contact
    still slips at the disc's speed under it (the friction drags along +y)."""
    from meshwear.surfaces import active

    calls = []
    original = active.refresh
    monkeypatch.setattr(active, "refresh", lambda *a: (calls.append(a[3]), original(*a))[1])
    root = __import__("pathlib").Path(__file__).resolve().parents[1]
    model = build_model(load_scene(root / "examples" / "pin_on_turning_disc.toml"))
    state = initial_state(model)
    for _ in range(200):
        step(model, state)
    assert calls == [0.0]
    s, body = state.bodies[0], model.bodies[0]
    z = body.reference_vertices[:, 2]
    assert len(s.active) == int((z <= z.min() + 1e-9).sum())
    load = 10.0 + body.mass * 9.81
    assert s.wrench[1] == pytest.approx(0.4 * load, rel=1e-2)
