"""Mechanisms: worn parts riding on MuJoCo bodies (docs/model.md, "Mechanisms").

Closed forms from docs/physics-tests.md: a pin pressed by a force actuator on
a slide joint against a disc turned by a velocity servo on a hinge wears
``V = k P s`` (Archard), as meshwear's own guided pin on a turning disc does.
"""

import math

import numpy as np
import pytest

import cases
from meshwear.longrun import checkpoint
from meshwear.cli import main
from meshwear.mechanism.coupling import slot_wrench
from meshwear.model.build import build_model, check_time_step, initial_state
from meshwear.output.memory import MemoryHistory
from meshwear.scene.reader import load_scene
from meshwear.scene.checks import SceneError
from meshwear.step.simulate import run
from test_resume import _KillAt, _Stop

pytest.importorskip("mujoco")

PIN_ON_DISC = cases.EXAMPLES / "mechanisms" / "pin_on_disc.toml"
#: short runs of the example, a coarse pin (Archard's volume does not depend on the mesh)
SHORT = [("run.duration", 0.3), ("run.frames", 0), ("run.history", 31),
         ("body[0].resolution", 2e-3)]

K, PRESS, MASS, RADIUS, RATE, G = 1e-12, 10.0, 0.2, 0.03, 10.0, 9.81

OWN = """
format = 1
[run]
duration = 0.3
frames = 0
history = 31
dt = {dt}
[contact]
stiffness_per_area = 1e12
damping_per_area = 5e7
tangential_stiffness_per_area = 1e12
friction = 0.4
[wear]
law = "archard"
coefficient = 1e-12
[[body]]
name = "pin"
shape = {{ type = "cylinder", radius = 0.002, height = 0.006, sections = 32 }}
resolution = 2e-3
mass = 0.2
position = [0.03, 0.0, 0.003]
force = [0.0, 0.0, -10.0]
motion = "guided"
[body.path]
free_axis = [0.0, 0.0, 1.0]
[[surface]]
name = "disc"
type = "mesh"
shape = {{ type = "cylinder", radius = 0.05, height = 0.005, sections = 128 }}
position = [0.0, 0.0, -0.0025]
rotation = {{ axis = [0.0, 0.0, 1.0], rate = 10.0, center = [0.0, 0.0, 0.0] }}
"""


def _run(scene):
    model = build_model(scene)
    history = MemoryHistory()
    state = run(model, initial_state(model), observers=[history])
    return model, state, history.rows


@pytest.fixture(scope="module")
def pin_on_disc():
    return _run(load_scene(PIN_ON_DISC, SHORT))


def test_a_pin_pressed_by_an_actuator_on_a_servo_driven_disc_wears_k_p_s(pin_on_disc):
    model, state, rows = pin_on_disc
    pin = rows["pin"]
    # the sliding distance at the pin's centre, from the hinge's own angle
    turned = pin["spin.q"][-1] - pin["spin.q"][0]
    assert turned == pytest.approx(RATE * 0.3, rel=1e-3)       # the servo holds its speed
    load = PRESS + MASS * G                                       # the press and the pin's weight
    assert pin["press.force"][-1] == pytest.approx(-PRESS)
    assert np.mean(pin["wrench"][5:, 2]) == pytest.approx(load, rel=1e-3)
    expected = K * load * RADIUS * turned
    assert pin["wear_volume"][-1] == pytest.approx(expected, rel=5e-3)


def test_the_mechanism_run_matches_meshwears_own_guided_pin_on_a_turning_disc(pin_on_disc,
                                                                               tmp_path):
    model, state, rows = pin_on_disc
    path = tmp_path / "own.toml"
    path.write_text(OWN.format(dt=model.dt))
    own = _run(load_scene(path))[2]["pin"]
    assert rows["pin"]["wear_volume"][-1] == pytest.approx(own["wear_volume"][-1], rel=5e-3)
    assert rows["pin"]["friction_work"][-1] == pytest.approx(own["friction_work"][-1], rel=5e-3)


def test_the_disc_takes_the_reaction_of_the_pins_contact(pin_on_disc):
    """The reaction pushed to MuJoCo is minus the pin's contact force, and its
    moment about the origin minus the pin's (same contact points)."""
    model, state, rows = pin_on_disc
    s = state.bodies[0]
    slot = model.surfaces.slots.index(model.mechanism.surfaces[0][0])
    w = slot_wrench(model, s, slot)
    assert np.allclose(w[0:3], s.wrench[0:3], rtol=1e-12, atol=1e-9)
    moment = s.wrench[3:6] + np.cross(s.pose[0:3], s.wrench[0:3])
    assert np.allclose(w[3:6], moment, rtol=0.0, atol=1e-9 * np.abs(moment).max())
    # a numpy twin of the kernel
    a = s.active[s.normal_force[slot, s.active] > 0.0]
    P = model.planes.shape[0]
    f = (s.normal_force[slot, a, None] * s.vertex_planes[slot - P, a, 1]
         + s.tangential[slot, a, 2])
    q = s.pose[3:7]
    w_, x_, y_, z_ = q
    R = np.array([[1 - 2 * (y_ * y_ + z_ * z_), 2 * (x_ * y_ - w_ * z_), 2 * (x_ * z_ + w_ * y_)],
                  [2 * (x_ * y_ + w_ * z_), 1 - 2 * (x_ * x_ + z_ * z_), 2 * (y_ * z_ - w_ * x_)],
                  [2 * (x_ * z_ - w_ * y_), 2 * (y_ * z_ + w_ * x_), 1 - 2 * (x_ * x_ + y_ * y_)]])
    x = s.pose[0:3] + s.vertices[a] @ R.T
    twin = np.concatenate([f.sum(0), np.cross(x, f).sum(0)])
    assert np.allclose(w, twin, rtol=0.0, atol=1e-12 * np.abs(twin).max())


def test_a_mechanism_run_resumes_bit_for_bit(tmp_path):
    scene = load_scene(PIN_ON_DISC, [("run.duration", 0.05), ("run.frames", 0),
                                     ("run.history", 11), ("body[0].resolution", 2e-3)])
    model = build_model(scene)
    full = run(model, initial_state(model))
    saver = checkpoint.Checkpointer(tmp_path, every=0.0)
    with pytest.raises(_Stop):
        run(model, initial_state(model), observers=[_KillAt(0.02)], checkpoint=saver)
    resumed = initial_state(model)
    checkpoint.load(saver.path, model, resumed)
    assert 0.0 < resumed.time <= 0.02
    run(model, resumed)
    assert np.array_equal(resumed.bodies[0].wear_depth, full.bodies[0].wear_depth)
    assert np.array_equal(resumed.bodies[0].pose, full.bodies[0].pose)


@pytest.mark.parametrize("key, value, message", [
    ("body[0].mechanism_body", "crank", "'crank' is not a moving body of pin_on_disc.xml"),
    ("surface[0].rotation", {"axis": [0, 0, 1], "rate": 1.0}, "MuJoCo moves it"),
    ("body[0].motion", "guided", "does not apply to a part on mechanism body"),
    ("mechanism.controls.brake", 1.0, "'brake' is not an actuator"),
    ("mechanism.keyframe", "home", "'home' is not a keyframe"),
    ("run.mode", "quasi-static", "does not apply to a scene with a [mechanism]"),
])
def test_a_bad_mechanism_key_is_one_line_naming_it(key, value, message):
    with pytest.raises(SceneError) as err:
        build_model(load_scene(PIN_ON_DISC, [(key, value)]))
    assert key in str(err.value) and message in str(err.value)
    assert "\n" not in str(err.value)


def test_a_model_mujoco_cannot_read_exits_2(tmp_path, capsys):
    text = PIN_ON_DISC.read_text().replace('model = "pin_on_disc.xml"', 'model = "bad.xml"')
    (tmp_path / "scene.toml").write_text(text)
    (tmp_path / "bad.xml").write_text("<mujoco><worldbody><body name='pin'><geom type='blob'/>"
                                      "</body></worldbody></mujoco>")
    assert main(["check", str(tmp_path / "scene.toml")]) == 2
    err = capsys.readouterr().err.strip()
    assert "mechanism.model" in err and "bad.xml" in err and len(err.splitlines()) == 1


def test_a_rider_without_a_mechanism_is_refused(tmp_path):
    text = PIN_ON_DISC.read_text()
    text = text[:text.index("[mechanism]")] + text[text.index("[run]"):]
    (tmp_path / "scene.toml").write_text(text)
    with pytest.raises(SceneError, match=r"body\[0\]\.mechanism_body.*no \[mechanism\] table"):
        load_scene(tmp_path / "scene.toml")


def test_history_carries_the_joints_and_actuators(tmp_path):
    out = tmp_path / "out"
    assert main(["run", str(PIN_ON_DISC), "-o", str(out), "-q", "--set", "run.duration=0.01",
                 "--set", "run.frames=2", "--set", "body[0].resolution=2e-3"]) == 0
    header = (out / "history.csv").read_text().splitlines()[0].split(",")
    for column in ("spin.q", "spin.v", "lift.q", "lift.v", "drive.force", "press.force"):
        assert column in header
    assert math.isfinite(float((out / "history.csv").read_text().splitlines()[-1].split(",")[
        header.index("spin.v")]))


def test_an_unstable_coupled_step_stops_the_run_with_exit_3(tmp_path, capsys):
    """An explicit Euler step of a stiff velocity servo on a light disc blows
    up in MuJoCo, which would reset itself and go on: meshwear stops there."""
    xml = (PIN_ON_DISC.parent / "pin_on_disc.xml").read_text()
    (tmp_path / "pin_on_disc.xml").write_text(xml.replace('integrator="implicitfast"',
                                                          'integrator="Euler"'))
    (tmp_path / "scene.toml").write_text(PIN_ON_DISC.read_text())
    code = main(["run", str(tmp_path / "scene.toml"), "-o", str(tmp_path / "out"), "-q",
                 "--set", "run.duration=0.05", "--set", "body[0].resolution=2e-3"])
    err = capsys.readouterr().err
    assert code == 3 and "non-finite" in err and "implicitfast" in err
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


def _toss_scenes(tmp_path, height=0.011):
    """The cube of examples/cube_toss.toml thrown flat from 1 mm above the
    plate, sliding and spinning (0.3, 0.1) m/s and 3 rad/s: as meshwear's own
    free body, and as a MuJoCo free joint carrying the same mesh."""
    source = (cases.EXAMPLES / "cube_toss.toml").read_text()
    source = source.replace('"../meshes/', f'"{cases.EXAMPLES.parent / "meshes"}/')
    own = (source.replace("position = [-0.04, 0.0, 0.03]", f"position = [-0.04, 0.0, {height}]")
           .replace("orientation = [0.9238795, 0.3826834, 0.0, 0.0]", "orientation = [1, 0, 0, 0]")
           .replace("angular_velocity = [2.0, -3.0, 1.0]", "angular_velocity = [0, 0, 3.0]"))
    (tmp_path / "own.toml").write_text(own)
    (tmp_path / "cube.xml").write_text(f"""<mujoco><worldbody>
      <body name="cube" pos="-0.04 0 {height}"><freejoint name="free"/>
        <geom type="box" size="0.01 0.01 0.01" density="7850"/></body></worldbody>
      <keyframe><key name="toss" qpos="-0.04 0 {height} 1 0 0 0" qvel="0.3 0.1 0 0 0 3"/></keyframe>
    </mujoco>""")
    rider = [line for line in own.splitlines() if not line.startswith(
        ("density", "position", "orientation", "velocity", "angular_velocity"))]
    rider = "\n".join(rider).replace('name = "cube"', 'name = "cube"\nmechanism_body = "cube"')
    rider = rider.replace("[run]", '[mechanism]\nmodel = "cube.xml"\nkeyframe = "toss"\n\n[run]')
    (tmp_path / "rider.toml").write_text(rider)
    return tmp_path / "own.toml", tmp_path / "rider.toml"


def test_a_tossed_cube_integrated_by_mujoco_comes_to_rest_as_meshwears_own(tmp_path):
    results = []
    for path in _toss_scenes(tmp_path):
        model, state, rows = _run(load_scene(path, [("run.duration", 0.6), ("run.frames", 0)]))
        results.append((state.bodies[0].pose.copy(), rows["cube"]))
    (own, own_rows), (mj, mj_rows) = results
    start = own_rows["pose"][0]
    assert np.linalg.norm(own[7:13]) < 1e-6 and np.linalg.norm(mj[7:13]) < 1e-6    # at rest
    travel = np.linalg.norm(own[0:3] - start[0:3])
    assert np.linalg.norm(mj[0:3] - own[0:3]) <= 0.02 * travel
    assert mj[2] == pytest.approx(own[2], abs=1e-7)                    # on a face, same sink
    turned = 2.0 * np.arccos(min(1.0, abs(float(own[3:7] @ mj[3:7]))))
    assert turned <= 0.02                                              # rad
    assert mj_rows["friction_work"][-1] == pytest.approx(own_rows["friction_work"][-1], rel=0.02)


PENDULUM = cases.EXAMPLES / "mechanisms" / "pendulum_in_bushing.toml"


def test_a_pendulum_hung_by_a_worn_pin_loads_its_bushing_as_an_ideal_hinge():
    """The bob m at L on a light rod, the pin m_p at the pivot, released from
    θ0: the hinge reaction is m a_bob + (m + m_p) g (the pin does not move),
    with θ'' = -m g L sin θ / I_p; at the bottom m L θ'^2 + (m + m_p) g,
    θ'^2 = 2 m g L (1 - cos θ0) / I_p. The bushing wears k N ds, ds the
    sliding at the contact: the contact stays on the rod's line, so it
    sweeps the bore (radius r_pin + c) as the pendulum turns."""
    model, state, rows = _run(load_scene(PENDULUM))
    pin = rows["pin"]
    m, m_pin, L, g, r_bob, theta0 = 0.1, 0.02, 0.2, 9.81, 0.005, math.radians(30.0)
    r_bore, mu, k = 0.00505, 0.1, 1e-13
    I_p = m * L * L + 0.4 * m * r_bob * r_bob
    theta, rate = pin["swing.q"], pin["swing.v"]
    assert theta[0] == pytest.approx(theta0) and theta[-1] < 0.0          # past the bottom
    acc = -m * g * L * np.sin(theta) / I_p
    ideal = np.stack([m * L * (acc * np.cos(theta) - rate ** 2 * np.sin(theta)),
                      m * L * (acc * np.sin(theta) + rate ** 2 * np.cos(theta))
                      + (m + m_pin) * g], axis=1)
    measured = pin["wrench"][:, 0:2]
    settled = pin["time"] >= 0.004          # the pin seats in the bore in its first steps
    ratio = np.linalg.norm(measured, axis=1)[settled] / np.linalg.norm(ideal, axis=1)[settled]
    assert np.all(np.abs(ratio - 1.0) <= 0.02)
    bottom = np.argmin(np.abs(theta))
    closed = m * g * (1.0 + 2.0 * m * L * L * (1.0 - math.cos(theta0)) / I_p) + m_pin * g
    assert np.linalg.norm(measured[bottom]) == pytest.approx(closed, rel=0.02)
    # all points slip while it swings: N = |F| / sqrt(1 + mu^2)
    normal = np.linalg.norm(measured, axis=1) / math.hypot(1.0, mu)
    sliding = r_bore * np.abs(np.diff(theta))
    work = np.sum(0.5 * (normal[1:] + normal[:-1]) * sliding)
    bushing = state.parts[0].volume.sum()
    assert bushing == pytest.approx(k * work, rel=0.01)


def test_the_compiled_mechanism_loop_matches_the_python_steps_to_the_last_bit():
    """meshwear.kernels.mechanism.advance_mechanism against Mechanism.step and
    the Python reference step, a worn counter-surface riding too."""
    scene = load_scene(cases.EXAMPLES / "mechanisms" / "slider_crank.toml",
                       [("run.duration", 0.004), ("run.frames", 0), ("run.history", 5)])
    model = build_model(scene)
    assert model.mechanism.calls is not None
    fast = run(model, initial_state(model))
    mujoco_fast = model.mechanism.get_state()
    slow = run(model, initial_state(model), compiled=False)
    for a, b in zip(fast.bodies, slow.bodies):
        for name in ("pose", "wrench", "wear_depth", "vertices", "tangential"):
            assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert np.array_equal(fast.parts[0].depth, slow.parts[0].depth)
    assert np.array_equal(mujoco_fast, model.mechanism.get_state())


@pytest.mark.parametrize("speed, keeps", [(0.3, True), (10.0, False)])
def test_active_sets_are_given_up_only_where_refreshes_come_faster_than_they_pay(
        monkeypatch, speed, keeps):
    """A disc turning slowly under the pin needs a refresh now and then, more
    of them over the run than one trial window allows: the pin keeps its
    active set. Turning fast, the disc's rim crosses the margin every few
    steps: every vertex is checked."""
    from meshwear.mechanism.build import Mechanism
    from meshwear.mechanism.active_sets import TRIAL_REFRESHES, TRIAL_STEPS

    count = []
    refreshed = Mechanism.refreshed
    monkeypatch.setattr(Mechanism, "refreshed",
                        lambda self, b, s: (count.append(1), refreshed(self, b, s)))
    scene = load_scene(PIN_ON_DISC, SHORT + [("run.duration", 1.0),
                                             ("mechanism.controls.drive", speed)])
    model = build_model(scene)
    state = run(model, initial_state(model))
    assert model.cull is keeps
    if keeps:
        assert len(count) > TRIAL_REFRESHES          # more than one window's worth in all
        assert len(state.bodies[0].active) < len(state.bodies[0].vertices)
        assert len(count) * TRIAL_STEPS < TRIAL_REFRESHES * model.n_steps
    else:
        assert len(state.bodies[0].active) == len(state.bodies[0].vertices)


def test_a_step_above_the_every_vertex_bound_runs_while_the_vertices_within_reach_allow_it(
        caplog):
    """The pin's 34 vertices within reach of the disc allow 3.8x the step of
    its 1488 pressing at once: run.dt between the two is taken (a warning
    says so), checked at every refresh, and the pin still wears k P s."""
    scene = load_scene(PIN_ON_DISC, SHORT + [("mechanism.controls.drive", 0.3),
                                             ("run.dt", 1e-4)])
    model = build_model(scene)
    assert model.mechanism.strict < model.dt
    with caplog.at_level("WARNING", logger="meshwear"):
        assert check_time_step(model) >= model.dt
    assert "run.dt" in caplog.text and "at every active-set refresh" in caplog.text
    model, state, rows = _run(scene)
    assert model.cull and model.mechanism.failed is None
    pin = rows["pin"]
    turned = pin["spin.q"][-1] - pin["spin.q"][0]
    load = PRESS + MASS * G
    assert pin["wear_volume"][-1] == pytest.approx(K * load * RADIUS * turned, rel=5e-3)


def test_a_step_above_what_the_vertices_within_reach_allow_is_refused_naming_both_limits(
        capsys):
    code = main(["check", str(PIN_ON_DISC), "--set", "run.dt=5e-4",
                 "--set", "body[0].resolution=2e-3"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1
    assert "run.dt" in err[0] and "every vertex pressing at once" in err[0]
    assert "within reach of a surface at the start" in err[0]


@pytest.mark.parametrize("drive", [None, 10.0])
def test_a_step_the_contact_outgrows_stops_the_run_with_exit_3(tmp_path, capsys, drive):
    """A cube thrown from 1 mm above the plate has no vertex within reach at
    the start, so any step passes the start's check; when it comes down its
    face does, and a step 6x the every-vertex bound stops the run there. A
    pin on a disc turning fast gives its active sets up: every vertex may
    then press, and the step above their bound is refused at once."""
    if drive is None:
        scene = _toss_scenes(tmp_path)[1]
        extra = ["--set", "run.dt=1e-4", "--set", "run.duration=0.3"]
        expected = "over its vertices within reach of a surface now"
    else:
        scene = PIN_ON_DISC
        extra = ["--set", "run.dt=1e-4", "--set", "body[0].resolution=2e-3",
                 "--set", f"mechanism.controls.drive={drive}", "--set", "run.duration=0.05"]
        expected = "gave them up"
    code = main(["run", str(scene), "-o", str(tmp_path / "out"), "-q", *extra])
    err = capsys.readouterr().err
    assert code == 3, err
    assert "run.dt" in err and expected in err


def test_gears_under_torque_touch_on_their_drive_flanks_only_and_share_the_load():
    """examples/mechanisms/gear_pair_torque.toml, 0.02 s: after the start
    the pinion's trailing flanks carry nothing, one or two of its teeth
    carry the load, and over two whole mesh periods the contact's moment on
    the wheel balances the resisting torque (the wheel's speed back where it
    was, within its ring)."""
    scene = load_scene(cases.EXAMPLES / "mechanisms" / "gear_pair_torque.toml",
                       [("run.duration", 0.02), ("run.frames", 0), ("run.history", 801),
                        ("wear.acceleration", "none")])
    model = build_model(scene)
    vertices = model.bodies[0].reference_vertices - model.bodies[0].origin
    phi = np.arctan2(vertices[:, 1], vertices[:, 0])
    pitch = 2.0 * np.pi / 20
    tooth = np.round(phi / pitch).astype(int)
    leading = phi > tooth * pitch
    wheel = model.mechanism.ids["wheel"]
    samples = []

    class Teeth:
        def on_sample(self, model, state):
            force = state.bodies[0].normal_force.sum(axis=0)
            samples.append((state.time, np.bincount(tooth[leading] % 20, force[leading],
                                                    minlength=20),
                            force[~leading].sum(), model.mechanism.data.xfrc_applied[wheel, 5]))

        def on_frame(self, model, state):
            pass

    run(model, initial_state(model), observers=[Teeth()])
    window = [s for s in samples if s[0] >= 0.02 - 2 * pitch / 100.0 - 1e-12]
    per_tooth = np.array([s[1] for s in window])
    total = per_tooth.sum(axis=1)
    assert max(s[2] for s in window) == 0.0                     # single-flank contact
    pairs = (per_tooth > 0.02 * total.mean()).sum(axis=1)
    assert set(pairs) == {1, 2}
    torque = dict(zip(*[[model.mechanism.model.actuator(a).name for a in range(2)],
                       model.mechanism.data.ctrl]))["load"]
    # (measured 9e-4: the wheel's ring, not quite whole periods of it)
    assert np.mean([s[3] for s in window]) == pytest.approx(-torque, rel=0.01)
    # the torque over the base radius; friction (0.1) moves it by 1.3 %
    assert total.mean() == pytest.approx(torque / (0.02 * np.cos(np.radians(20.0))), rel=0.03)


def _geom_pin(tmp_path):
    """pin_on_disc with the pin's mesh from an MJCF mesh geom: the example's
    cylinder written to an STL off its centre (MuJoCo re-centres it on its
    centroid) and placed back by the geom's pos and a quarter turn."""
    import trimesh

    from meshwear.geometry.meshes import primitive

    vertices, faces = primitive("cylinder", radius=0.002, height=0.006, sections=32)
    turn = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])   # -90° about z
    trimesh.Trimesh(vertices @ turn.T + [0.0005, 0.0, 0.0], faces,
                    process=False).export(tmp_path / "pin.stl")
    xml = (PIN_ON_DISC.parent / "pin_on_disc.xml").read_text()
    xml = xml.replace('<geom type="cylinder" size="0.002 0.003" mass="0.2"/>',
                      '<geom name="pin_mesh" type="mesh" mesh="pin" mass="0.2" '
                      'pos="0 -0.0005 0" quat="0.7071067811865476 0 0 0.7071067811865476"/>')
    xml = xml.replace("<worldbody>", '<asset><mesh name="pin" file="pin.stl"/></asset>\n'
                      "  <worldbody>")
    (tmp_path / "pin_on_disc.xml").write_text(xml)
    scene = PIN_ON_DISC.read_text().replace(
        'shape = { type = "cylinder", radius = 0.002, height = 0.006, sections = 32 }\n'
        "resolution = 1e-3", 'mechanism_geom = "pin_mesh"')
    (tmp_path / "scene.toml").write_text(scene)
    return tmp_path / "scene.toml"


def test_a_part_takes_its_mesh_from_a_mesh_geom_where_mujoco_places_it(tmp_path):
    from meshwear.surfaces import quaternion_matrix

    short = [("run.duration", 0.05), ("run.frames", 0), ("run.history", 6)]
    geom = build_model(load_scene(_geom_pin(tmp_path), short))
    shape = build_model(load_scene(PIN_ON_DISC, short + [("body[0].resolution", None)]))
    worlds = []
    for model in (geom, shape):
        b = model.bodies[0]
        world = b.reference_vertices @ quaternion_matrix(b.initial_pose[3:7]).T + b.initial_pose[0:3]
        worlds.append(world[np.lexsort(np.round(world, 9).T)])
    assert worlds[0].shape == worlds[1].shape
    assert np.abs(worlds[0] - worlds[1]).max() < 1e-9                 # float32 in MuJoCo
    results = [run(model, initial_state(model)).bodies[0].wear_volume.sum()
               for model in (geom, shape)]
    assert results[0] == pytest.approx(results[1], rel=1e-4)


@pytest.mark.parametrize("change, key, message", [
    ('mechanism_geom = "pin_pad"', "mechanism_geom",
     "'pin_pad' is not a mesh geom of body 'pin' in pin_on_disc.xml (its mesh geoms: 'pin_mesh')"),
    ('mechanism_geom = "pin_mesh"\nunits = "mm"', "units", "the MJCF file places and scales it"),
    ('mechanism_geom = "pin_mesh"\nmesh = "pin.stl"', "mechanism_geom", "leave mesh out"),
])
def test_a_bad_mechanism_geom_is_one_line_naming_the_key(tmp_path, capsys, change, key, message):
    scene = _geom_pin(tmp_path)
    scene.write_text(scene.read_text().replace('mechanism_geom = "pin_mesh"', change))
    code = main(["check", str(scene)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    assert f"body[0].{key}" in err[0] and message in err[0]
