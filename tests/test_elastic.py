"""The half-space contact model in a scene (docs/model.md, "Elastic half-space"):
a steel ball pressed on a steel flat, its mesh's vertices mapped onto the
grid and back, against Hertz, Cattaneo-Mindlin and Mindlin-Deresiewicz."""

import numpy as np
import pytest

from meshwear.halfspace import contact_modulus
from meshwear.model import build_model, initial_state
from meshwear.scene import SceneError, load_scene
from meshwear.simulate import NumericalError, step

E, NU, R, LOAD, MU = 210e9, 0.3, 0.005, 10.0, 0.5
E_STAR = contact_modulus((E, E), (NU, NU))
G = E / (2.0 * (1.0 + NU))
A = (3.0 * LOAD * R / (4.0 * E_STAR)) ** (1.0 / 3.0)        # 69 µm
P0 = 3.0 * LOAD / (2.0 * np.pi * A * A)
APPROACH = A * A / R
#: Mindlin's tangential compliance of the pair, sum (2 - nu_i) / G_i
C_T = 2.0 * (2.0 - NU) / G
#: the stroke at which the whole contact slips
GROSS = 3.0 * MU * LOAD * C_T / (16.0 * A)

SCENE = """
format = 1
[run]
mode = "quasi-static"
duration = {duration}
dt = {dt}
frames = 0
history = 3
gravity = [0.0, 0.0, 0.0]
[contact]
model = "half-space"
youngs_modulus = {E}
poissons_ratio = {NU}
friction = {MU}
margin = 1e-5
[wear]
law = "energy_density"
coefficient = {k}
[[body]]
name = "ball"
shape = {{ type = "sphere", radius = {R}, subdivisions = 4 }}
resolution = 1e-5
resolution_reach = 2e-5
position = [0.0, 0.0, {R}]
motion = "{motion}"
{force}
[body.path]
oscillation = {{ axis = [1.0, 0.0, 0.0], amplitude = {stroke}, frequency = 20.0 }}
{free_axis}
[[surface]]
name = "flat"
type = "plane"
size = 0.004
"""


def ball(tmp_path, stroke=0.0, k=0.0, duration=0.1, dt=2.5e-3, motion="guided", extra=None):
    path = tmp_path / "ball.toml"
    free_axis = "free_axis = [0.0, 0.0, 1.0]" if motion == "guided" else ""
    force = f"force = [0.0, 0.0, -{LOAD}]" if motion == "guided" else ""
    path.write_text(SCENE.format(duration=duration, dt=dt, E=E, NU=NU, MU=MU, R=R, LOAD=LOAD,
                                 k=k, stroke=max(stroke, 1e-300), motion=motion, force=force,
                                 free_axis=free_axis))
    scene = load_scene(path)
    return scene.set(extra) if extra else scene


def _radius(r2, values):
    """The radius of an ellipse ``values^2 = c (1 - r^2 / radius^2)``,
    fitted on the cells where it is positive."""
    pos = values > 0.0
    slope, intercept = np.polyfit(r2[pos], values[pos] ** 2, 1)
    return np.sqrt(-intercept / slope), np.sqrt(intercept)


def _cell_r2(patch):
    h = patch.grid.spacing[0]
    x = patch.origin[0] + h * np.arange(patch.grid.shape[0])
    y = patch.origin[1] + h * np.arange(patch.grid.shape[1])
    X, Y = np.meshgrid(x, y, indexing="ij")
    return X * X + Y * Y


@pytest.fixture(scope="module")
def pressed(tmp_path_factory):
    model = build_model(ball(tmp_path_factory.mktemp("hertz"), duration=0.01))
    state = initial_state(model)
    return model, state


def test_hertz_in_a_scene_pressure_radius_and_approach(pressed):
    model, state = pressed
    s = state.bodies[0]
    patch = s.elastic
    # the vertices carry the load exactly
    assert s.normal_force.sum() == pytest.approx(LOAD, rel=1e-12)
    assert s.wrench[2] == pytest.approx(LOAD, rel=1e-12)
    radius, peak = _radius(_cell_r2(patch), patch.pressure)
    assert radius == pytest.approx(A, rel=0.01)
    assert peak == pytest.approx(P0, rel=0.01)
    assert patch.pressure.max() == pytest.approx(P0, rel=0.015)
    assert patch.approach - patch.heights.min() == pytest.approx(APPROACH, rel=0.01)
    # the vertices' pressure (their force over their contact area), Hertz's
    b = model.bodies[0]
    x = s.vertices @ np.eye(3)
    r = np.hypot(x[:, 0], x[:, 1])
    loaded = s.normal_force[0] > 0.0
    inner = loaded & (r < 0.8 * A)
    pressure = s.normal_force[0, inner] / b.area_vectors[inner, 3]
    hertz = P0 * np.sqrt(1.0 - (r[inner] / A) ** 2)
    # (each vertex's share of the cells follows its triangles, its area the
    # mesh's barycentric one: a few per cent apart, vertex by vertex)
    assert np.percentile(np.abs(pressure / hertz - 1.0), 90) < 0.05
    assert np.average(pressure / hertz, weights=b.area_vectors[inner, 3]) == pytest.approx(1.0, abs=0.01)
    assert r[loaded].max() == pytest.approx(A, rel=0.1)


def _fretting(scene):
    model = build_model(scene)
    state = initial_state(model)
    force, work = [], []
    while state.step < model.n_steps:
        step(model, state)
        s = state.bodies[0]
        force.append(-s.wrench[0])
        work.append(s.friction_work.sum())
    return model, state, np.array(force), np.array(work)


@pytest.mark.parametrize("share", [0.35, 0.7])
def test_mindlin_in_a_scene_force_and_energy_per_cycle(tmp_path, share):
    """A ball rubbed by +-stroke below gross slip: the largest tangential
    force is Mindlin's, Q* = mu P [1 - (1 - stroke / gross)^(3/2)], and the
    friction work of the second cycle is Mindlin and Deresiewicz's loop."""
    stroke = share * GROSS
    model, state, force, work = _fretting(ball(tmp_path, stroke=stroke))
    x = 1.0 - (1.0 - share) ** 1.5
    second = force[len(force) // 2:]
    assert second.max() == pytest.approx(x * MU * LOAD, rel=0.01)
    assert second.min() == pytest.approx(-x * MU * LOAD, rel=0.01)
    loop = 0.9 * (MU * LOAD) ** 2 * C_T / A * (
        1.0 - (1.0 - x) ** (5.0 / 3.0) - 5.0 * x / 6.0 * (1.0 + (1.0 - x) ** (2.0 / 3.0)))
    assert work[-1] - work[len(work) // 2 - 1] == pytest.approx(loop, rel=0.03)


def test_the_stick_zone_at_mindlins_radius_stays_unworn(tmp_path):
    """Fretting in partial slip: at the stroke's end the stick reserve is
    Mindlin's, of radius c = a (1 - Q*/mu P)^(1/3); the vertices inside c
    never slip and never wear, the annulus out to a wears."""
    share = 0.7
    scene = ball(tmp_path, stroke=share * GROSS, k=1e-12, duration=0.0625)
    model = build_model(scene)
    state = initial_state(model)
    while state.step < model.n_steps:
        step(model, state)
        if state.step == 5:                     # a quarter cycle: x = +stroke, first loading
            patch = state.bodies[0].elastic
            reserve = MU * patch.pressure - patch.shear
            c, _ = _radius(_cell_r2(patch), reserve)
    x = 1.0 - (1.0 - share) ** 1.5
    stick = A * (1.0 - x) ** (1.0 / 3.0)
    assert c == pytest.approx(stick, rel=0.03)
    s = state.bodies[0]
    r = np.hypot(s.vertices[:, 0], s.vertices[:, 1])
    inside = r < 0.9 * stick
    ring = (r > 1.15 * stick) & (r < 0.9 * A)
    assert inside.sum() > 20 and ring.sum() > 20
    assert np.all(s.wear_depth[inside] == 0.0)
    assert np.all(s.wear_depth[ring] > 0.0)


def test_a_sliding_ball_dissipates_mu_p_v(tmp_path):
    """A steady slide: gross slip, friction mu P, work mu P times the
    distance but for the partial slip of the stroke's start."""
    scene = ball(tmp_path, duration=0.01, dt=1e-3,
                 extra={"body[0].path": {"velocity": [0.01, 0.0, 0.0],
                                         "free_axis": [0.0, 0.0, 1.0]}})
    model = build_model(scene)
    state = initial_state(model)
    while state.step < model.n_steps:
        step(model, state)
    s = state.bodies[0]
    assert -s.wrench[0] == pytest.approx(MU * LOAD, rel=1e-9)
    # (less the stick of the first GROSS of the stroke, Mindlin's loading)
    assert MU * LOAD * (1e-4 - GROSS) < s.friction_work.sum() < MU * LOAD * 1e-4


def test_a_prescribed_ball_takes_the_load_of_its_overlap(tmp_path):
    """Displacement control: a ball held at its Hertz approach carries P."""
    scene = ball(tmp_path, duration=0.01, motion="prescribed",
                 extra={"body[0].position": [0.0, 0.0, R - APPROACH]})
    model = build_model(scene)
    state = initial_state(model)
    assert state.bodies[0].normal_force.sum() == pytest.approx(LOAD, rel=0.02)


@pytest.mark.parametrize("key, value, words", [
    ("contact.stiffness_per_area", 1e12, "does not apply to model = 'half-space'"),
    ("contact.youngs_modulus", [1e9, 2e9, 3e9], "expected one value or two"),
    ("contact.poissons_ratio", 0.5, "must be in [0, 0.5)"),
    ("run.mode", "dynamic", "quasi-static"),
    ("contact.model", "hertz", "hertz"),
])
def test_half_space_keys_are_checked(tmp_path, key, value, words):
    with pytest.raises(SceneError) as err:
        ball(tmp_path).set(key, value)
    assert words in str(err.value)


def test_youngs_modulus_needs_the_half_space_model(tmp_path):
    with pytest.raises(SceneError, match="applies to model = 'half-space' only"):
        ball(tmp_path).set({"contact.model": "winkler", "contact.stiffness_per_area": 1e12})


def test_a_conforming_contact_is_refused(tmp_path):
    """A ball pressed into a bowl of nearly its own radius touches over a
    cap of tens of degrees: not a half-space contact."""
    scene = ball(tmp_path, duration=0.01).set({
        "body[0].force": [0.0, 0.0, -600.0],
        "contact.youngs_modulus": 1e8, "contact.margin": 0.004})
    with pytest.raises((SceneError, NumericalError), match="not a half-space one"):
        model = build_model(scene)
        state = initial_state(model)
        step(model, state)
