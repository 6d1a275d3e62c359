"""Physics with known answers (docs/model.md), at the tolerances of docs/physics-tests.md.

Every expected number comes from a closed form, never from an earlier run.
"""

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from reference import FACING, contact_areas, point_coefficients

from meshwear.kernels.contact import rotation_entries
from meshwear.model.build import build_model
from meshwear.model.timestep import stable_time_step
from meshwear.scene.checks import SceneError
from meshwear.scene.reader import load_scene
from meshwear.step.simulate import run_scene

G = 9.81


def scene_file(tmp_path, text, name="scene.toml"):
    path = tmp_path / name
    path.write_text("format = 1\n" + text)
    return load_scene(path)


# ---------------------------------------------------------------- Jenkins loop

JENKINS = """
[run]
duration = 0.3
dt = 1e-5
frames = 0
history = 31

[contact]
stiffness = 1e6
damping = 20.0
tangential_damping = 0.0
friction = 0.3

[wear]
law = "energy"
coefficient = 0.0

[[body]]
name = "block"
shape = {{ type = "box", size = [0.01, 0.01, 0.005] }}
density = 7850.0
position = [0.0, 0.0, 0.0025]
force = [0.0, 0.0, -10.0]
motion = "guided"
[body.path]
oscillation = {{ axis = [1.0, 0.0, 0.0], amplitude = {amplitude}, frequency = 10.0 }}
free_axis = [0.0, 0.0, 1.0]

[[surface]]
name = "floor"
type = "plane"
"""


@pytest.mark.parametrize("amplitude", [5e-6, 2e-6])
def test_reciprocating_block_dissipates_the_jenkins_loop(tmp_path, amplitude, measured):
    scene = scene_file(tmp_path, JENKINS.format(amplitude=amplitude))
    model, state, history = run_scene(scene)
    h = history.rows["block"]
    mass = model.bodies[0].mass
    load = mass * G + 10.0  # total normal load N
    mu, k_t = 0.3, 4 * 1e6  # four bottom corners, c_t = c
    expected = 4 * mu * load * (amplitude - mu * load / k_t)
    t = h["time"]
    work = h["friction_work"]
    for start in (0.1, 0.2):  # the first cycle loads the spring from zero: skip it
        i, j = np.searchsorted(t, [start - 1e-12, start + 0.1 - 1e-12])
        per_cycle = work[j] - work[i]
        measured(f"energy/cycle from {start} s (J)", per_cycle, expected, 5e-3)
        assert per_cycle == pytest.approx(expected, rel=5e-3)


def test_below_slip_amplitude_nothing_slips(tmp_path):
    # mu N / K_t is about 0.75 µm: at 0.5 µm the contact stays in stick
    scene = scene_file(tmp_path, JENKINS.format(amplitude=0.5e-6).replace(
        'tangential_damping = 0.0', 'tangential_damping = 0.0\nstatic_friction = 0.3'))
    model, state, history = run_scene(dataclasses.replace(
        scene, run=dataclasses.replace(scene.run, duration=0.2, history=21)))
    s = state.bodies[0]
    assert (s.contact_state != 2).all()
    assert s.friction_work.sum() == 0.0


# ------------------------------------------------------------ sliding and slopes

BLOCK = """
[run]
duration = {duration}
dt = {dt}
frames = 0
history = {history}
gravity = [0.0, 0.0, -9.81]

[contact]
stiffness = 1e6
damping = 40.0
friction = {f}
static_friction = {f0}
{extra}

[wear]
law = "{law}"
coefficient = {k}

[[body]]
name = "block"
shape = {{ type = "box", size = [0.02, 0.02, 0.01] }}
density = 7850.0
position = {position}
orientation = {orientation}
velocity = {velocity}
motion = "free"

[[surface]]
name = "floor"
type = "plane"
normal = {normal}
"""


def block_scene(tmp_path, *, duration=0.3, dt=2e-5, history=301, f=0.3, f0=0.3, law="energy",
                k=1e-12, theta=0.0, velocity=(0.0, 0.0, 0.0), extra=""):
    """A 20 x 20 x 10 mm steel block resting on a plane tilted by theta about y."""
    normal = [float(np.sin(theta)), 0.0, float(np.cos(theta))]
    mass = 7850.0 * 0.02 * 0.02 * 0.01
    sink = mass * G * np.cos(theta) / 4e6  # static penetration under four corners
    centre = np.array(normal) * (0.005 - sink)
    q = [float(np.cos(theta / 2)), 0.0, float(np.sin(theta / 2)), 0.0]
    text = BLOCK.format(duration=duration, dt=dt, history=history, f=f, f0=f0, law=law, k=k,
                        position=centre.tolist(), orientation=q, velocity=list(velocity),
                        normal=normal, extra=extra)
    return scene_file(tmp_path, text)


def test_sliding_block_stops_after_the_coulomb_distance_and_stays(tmp_path, measured):
    v0, mu = 0.5, 0.3
    scene = block_scene(tmp_path, duration=0.4, velocity=(v0, 0.0, 0.0), f=mu, f0=mu)
    model, state, history = run_scene(scene)
    h = history.rows["block"]
    x = h["origin"][:, 0]
    expected = v0 ** 2 / (2 * mu * G)
    stop_time = v0 / (mu * G)
    stopped = h["time"] > stop_time + 0.05
    measured("stopping distance (m)", x[stopped][0], expected, 1e-2)
    assert x[stopped][0] == pytest.approx(expected, rel=1e-2)
    # then it stays: no creep after it has stopped
    assert np.ptp(x[stopped]) < 1e-6
    assert np.abs(h["pose"][-1, 7:10]).max() < 1e-3


def test_block_on_a_slope_below_static_friction_sticks(tmp_path, measured):
    """f = 0.2 < tan 20° < f0 = 0.6: only the static limit can hold the block.

    The load comes on as a step at t = 0, so a lightly damped tangential spring
    overshoots its static force (up to 2x) and would break the corners loose,
    after which they slide on at f; near-critical tangential damping (per
    corner, 2 sqrt(c_t m/4) = 177 N s/m) loads the springs without overshoot.
    """
    theta = np.radians(20.0)
    scene = block_scene(tmp_path, duration=1.2, dt=1e-5, history=121, f=0.2, f0=0.6,
                        theta=theta, extra="tangential_damping = 180.0")
    model, state, history = run_scene(scene)
    h = history.rows["block"]
    downhill = np.array([np.cos(theta), 0.0, -np.sin(theta)])
    along = h["origin"] @ downhill
    settled = h["time"] >= 0.2 - 1e-12
    # drift over one second after the elastic settling
    drift = abs(along[settled][-1] - along[settled][0])
    measured("drift over 1 s (m), tol abs", drift, 0.0, 1e-6)
    assert drift < 1e-6
    # the elastic deflection itself: 0.342 m g over four 1e6 N/m springs, 26 nm
    mass = 7850.0 * 0.02 * 0.02 * 0.01
    assert np.abs(along - along[0]).max() < 3 * mass * G * np.sin(theta) / 4e6
    # held by friction above f: every touching corner sticks
    touching = state.bodies[0].contact_state[0] != 0
    assert touching.sum() == 4 and np.all(state.bodies[0].contact_state[0][touching] == 1)


def test_block_on_a_slope_above_friction_slides_with_coulomb_acceleration(tmp_path, measured):
    record = measured
    theta, mu = np.radians(20.0), 0.2
    scene = block_scene(tmp_path, duration=0.6, dt=2e-5, history=61, f=mu, f0=mu, theta=theta)
    model, state, history = run_scene(scene)
    h = history.rows["block"]
    downhill = np.array([np.cos(theta), 0.0, -np.sin(theta)])
    speed = h["pose"][:, 7:10] @ downhill
    later = h["time"] >= 0.2 - 1e-12
    rate = np.polyfit(h["time"][later], speed[later], 1)[0]
    expected = G * (np.sin(theta) - mu * np.cos(theta))
    record("acceleration (m/s²)", rate, expected, 1e-2)
    assert rate == pytest.approx(expected, rel=1e-2)


def test_energy_density_wear_volume_identity(tmp_path, measured):
    k = 1e-13  # m³/J
    scene = block_scene(tmp_path, duration=0.2, velocity=(0.3, 0.1, 0.0), law="energy_density", k=k)
    model, state, history = run_scene(scene)
    s, body = state.bodies[0], model.bodies[0]
    assert s.friction_work.sum() > 0.0
    # worn volume: each depth increment times the contact area it wore
    volume = s.wear_volume.sum()
    measured("wear volume (m³)", volume, k * s.friction_work.sum(), 1e-9)
    assert volume == pytest.approx(k * s.friction_work.sum(), rel=1e-9, abs=0.0)
    # with the contact areas of the block standing flat (its area vectors
    # projected on -z), sum w_i A_i is that volume up to the block's small
    # pitch while it slides (cos of ~5e-4 rad)
    flat = np.maximum(-body.area_vectors[:, 2], 0.0)
    assert s.wear_depth @ flat == pytest.approx(volume, rel=1e-6, abs=0.0)
    h = history.rows["block"]
    assert np.all(np.diff(h["wear_depth"], axis=0) >= 0.0)


ARCHARD = """
[run]
duration = 0.2
dt = 1e-5
frames = 0
history = 201

[contact]
stiffness = 1e6
damping = 40.0
friction = 0.3

[wear]
law = "archard"
coefficient = 1e-13

[[body]]
name = "pin"
shape = { type = "box", size = [0.01, 0.01, 0.01] }
density = 7850.0
position = [0.0, 0.0, 0.005]
force = [0.0, 0.0, -20.0]
motion = "guided"
[body.path]
velocity = [0.05, 0.0, 0.0]
free_axis = [0.0, 0.0, 1.0]

[[surface]]
name = "disc"
type = "plane"
"""


def test_archard_wear_volume_is_k_load_distance(tmp_path, measured):
    """A pin pressed by W = mg + 20 N slides at v: Archard's law, V = k W s.

    Along the free axis, m dv = (N(t) - W) dt, so the load integral is
    W t + m (v_z(t) - v_z(0)) whatever the contact bounces; the pin slips
    from the first steps on (its tangential spring reaches f0 N within
    f0 N / (v K_t) = 0.15 ms), so s = v t up to that.
    """
    k, v = 1e-13, 0.05
    model, state, history = run_scene(scene_file(tmp_path, ARCHARD))
    body, s = model.bodies[0], state.bodies[0]
    h = history.rows["pin"]
    load = body.mass * G + 20.0
    later = h["time"] >= 0.05 - 1e-12
    t, vz = h["time"][later], h["pose"][later, 9]
    expected = k * v * (load * (t - t[0]) + body.mass * (vz - vz[0]))
    volume = h["wear_volume"][later] - h["wear_volume"][later][0]
    measured("archard volume after 0.15 s (m³)", volume[-1], expected[-1], 1e-6)
    np.testing.assert_allclose(volume[1:], expected[1:], rtol=1e-6)
    assert np.all(s.contact_state[0][s.contact_state[0] > 0] == 2)


# ------------------------------------------------------------------ tossed cube

CUBE = """
[run]
duration = 1.5
dt = {dt}
frames = 0
history = 1501

[contact]
stiffness = 1e5
damping = 20.0
friction = 0.4

[wear]
law = "energy"
coefficient = 1e-9

[[body]]
name = "cube"
shape = {{ type = "box", size = [0.02, 0.02, 0.02] }}
density = 7850.0
position = [0.0, 0.0, 0.03]
orientation = [0.9238795, 0.3826834, 0.0, 0.0]
velocity = [0.3, 0.1, 0.0]
angular_velocity = [2.0, -3.0, 1.0]

[[surface]]
name = "floor"
type = "plane"
"""


class EnergyProbe:
    """Mechanical energy of every sample: kinetic + gravity + elastic contact."""

    def __init__(self):
        self.energy = []

    def on_frame(self, model, state):
        pass

    def on_sample(self, model, state):
        total = 0.0
        g = np.asarray(model.scene.run.gravity)
        for body, s in zip(model.bodies, state.bodies):
            R = np.array(rotation_entries(s.pose[3:7])).reshape(3, 3)
            omega = s.pose[10:13]
            total += 0.5 * body.mass * s.pose[7:10] @ s.pose[7:10]
            total += 0.5 * omega @ (R @ body.inertia @ R.T) @ omega
            total -= body.mass * g @ s.pose[0:3]
            x = s.pose[0:3] + s.vertices @ R.T
            for j in range(model.planes.shape[0]):
                p, n = model.planes[j, 0], model.planes[j, 1]
                area = contact_areas(body.area_vectors, R, n)
                facing = area > FACING * body.area_vectors[:, 3]
                depth = np.where(facing, np.minimum((x - p) @ n, 0.0), 0.0)
                c, _, ct, _ = point_coefficients(area, model.law)
                total += 0.5 * (c * depth ** 2).sum()
                F = s.tangential[j, :, 2]
                total += 0.5 * ((F * F).sum(1) / ct).sum()
        self.energy.append(total)


def test_tossed_cube_comes_to_rest_on_a_face(tmp_path, measured):
    scene = scene_file(tmp_path, CUBE.format(dt=5e-5))
    probe = EnergyProbe()
    model, state, history = run_scene(scene, observers=[probe])
    h = history.rows["cube"]
    pose = state.bodies[0].pose
    measured("final speed (m/s), tol abs", np.linalg.norm(pose[7:10]), 0.0, 1e-3)
    assert np.linalg.norm(pose[7:10]) < 1e-3
    # tilt: the angle between some body axis and the floor normal
    R = np.array(rotation_entries(pose[3:7])).reshape(3, 3)
    tilt = np.degrees(np.arccos(min(1.0, np.abs(R[2]).max())))
    measured("tilt (degrees), tol abs", tilt, 0.0, 2.0)
    assert tilt < 2.0
    # wear never decreases, per vertex
    assert np.all(np.diff(h["wear_depth"], axis=0) >= 0.0)
    assert h["max_wear_depth"][-1] > 0.0
    # mechanical energy never rises above any earlier value (beyond the
    # integrator's O(dt) ripple, bounded here by 0.1% of the energy dissipated)
    e = np.asarray(probe.energy)
    rise = e[1:] - np.minimum.accumulate(e)[:-1]
    measured("energy rise / dissipated", rise.max() / (e[0] - e[-1]), 0.0, 1e-3)
    assert rise.max() <= 1e-3 * (e[0] - e[-1])


# ------------------------------------------------------------- hard cases

CORNER = """
[run]
duration = 0.3
dt = 2e-5
frames = 0
history = 31

[contact]
stiffness = 1e6
damping = 40.0
friction = 0.3

[[body]]
name = "box"
shape = { type = "box", size = [0.02, 0.02, 0.01] }
density = 7850.0
position = [0.00998, 0.0, 0.00498]
velocity = [-0.05, 0.0, 0.0]

[[surface]]
name = "floor"
type = "plane"

[[surface]]
name = "wall"
type = "plane"
normal = [1.0, 0.0, 0.0]
"""


class CornerProbe:
    """Records whether some vertex pressed on both planes at once."""

    def __init__(self):
        self.both, self.wall_push = 0, 0.0

    def on_frame(self, model, state):
        pass

    def on_sample(self, model, state):
        s = state.bodies[0]
        both = (s.contact_state[0] > 0) & (s.contact_state[1] > 0)
        if both.any():
            self.both += 1
            self.wall_push = max(self.wall_push, s.normal_force[1][both].max())


def test_vertex_touching_two_planes_is_pushed_out_of_both(tmp_path):
    scene = scene_file(tmp_path, CORNER.replace("history = 31", "history = 3001"))
    probe = CornerProbe()
    model, state, history = run_scene(scene, observers=[probe])
    # the corner vertices pressed on the floor and the wall in the same step,
    # and the wall pushed the box back (+x) while the floor carried it (+z)
    assert probe.both > 0 and probe.wall_push > 0.0
    h = history.rows["box"]
    assert h["wrench"][:, 0].max() > 0.0 and h["wrench"][:, 2].max() > 0.0
    assert h["pose"][-1, 7] > 0.0  # moving away from the wall at the end
    s, body = state.bodies[0], model.bodies[0]
    R = np.array(rotation_entries(s.pose[3:7])).reshape(3, 3)
    x = s.pose[0:3] + s.vertices @ R.T
    mass = body.mass
    # floor: only the static sink under gravity remains; wall: nothing pushes, no penetration
    assert x[:, 2].min() > -2 * mass * G / 4e6
    assert x[:, 0].min() > -1e-7
    assert np.all(np.isfinite(s.pose))


def test_dt_above_the_stability_limit_is_refused_and_the_limit_runs(tmp_path):
    scene = scene_file(tmp_path, CUBE.format(dt=5e-5))
    limit, who = stable_time_step(build_model(scene))
    assert who == "cube"
    too_big = dataclasses.replace(scene, run=dataclasses.replace(scene.run, dt=1.5 * limit))
    with pytest.raises(SceneError, match="largest stable dt"):
        run_scene(too_big)
    at_limit = dataclasses.replace(scene, run=dataclasses.replace(scene.run, dt=limit, duration=0.5,
                                                                     history=101))
    probe = EnergyProbe()
    model, state, history = run_scene(at_limit, observers=[probe])
    assert np.all(np.isfinite(state.bodies[0].pose))
    assert max(probe.energy) <= probe.energy[0] * 1.01
    # the bound is conservative (all eight corners, all directions) but not
    # vacuous: six times above it the explicit step pumps energy in
    probe = EnergyProbe()
    run_scene(dataclasses.replace(scene, run=dataclasses.replace(
        scene.run, dt=6 * limit, duration=0.5, history=101)), observers=[probe], check_dt=False)
    assert max(probe.energy) > 1.5 * probe.energy[0]


EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_jenkins_loop_with_turning_points_on_steps_and_many_points(measured):
    """The reciprocating-block example (289 Winkler points, so N_i differ from
    point to point and by round-off from step to step) at a dt that puts every
    turning point exactly on a step: each cycle must still follow the loop."""
    scene = load_scene(EXAMPLES / "reciprocating_block.toml")
    scene = dataclasses.replace(scene, run=dataclasses.replace(
        scene.run, dt=4e-6, duration=0.25, history=26, frames=0))
    model, state, history = run_scene(scene)
    body = model.bodies[0]
    load = body.mass * G + 50.0
    k_t = 1e12 * 0.01 * 0.01  # Winkler: K times the 10 x 10 mm footprint
    mu, amplitude = 0.3, 2e-6
    expected = 4 * mu * load * (amplitude - mu * load / k_t)
    work = history.rows["block"]["friction_work"]
    for cycle in range(1, 5):  # 20 Hz: 5 rows per cycle; the first loads from zero
        per_cycle = work[5 * cycle + 5] - work[5 * cycle]
        measured(f"energy/cycle {cycle + 1}, on-step turns (J)", per_cycle, expected, 5e-3)
        assert per_cycle == pytest.approx(expected, rel=5e-3)
