"""Mechanisms: worn parts riding on MuJoCo bodies (docs/model.md, "Mechanisms").

Closed forms from docs/physics-tests.md: a pin pressed by a force actuator on
a slide joint against a disc turned by a velocity servo on a hinge wears
``V = k P s`` (Archard), as meshwear's own guided pin on a turning disc does.
"""

import math

import numpy as np
import pytest

import cases
from meshwear import checkpoint
from meshwear.cli import main
from meshwear.mechanism import slot_wrench
from meshwear.model import build_model, initial_state
from meshwear.output.memory import MemoryHistory
from meshwear.scene import SceneError, load_scene
from meshwear.simulate import run

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
        run(model, initial_state(model), observers=[_StopAt(0.02)], checkpoint=saver)
    resumed = initial_state(model)
    checkpoint.load(saver.path, model, resumed)
    assert 0.0 < resumed.time <= 0.02
    run(model, resumed)
    assert np.array_equal(resumed.bodies[0].wear_depth, full.bodies[0].wear_depth)
    assert np.array_equal(resumed.bodies[0].pose, full.bodies[0].pose)


class _Stop(Exception):
    pass


class _StopAt:
    def __init__(self, time_):
        self.time = time_

    def on_frame(self, model, state):
        pass

    def on_sample(self, model, state):
        if state.time >= self.time:
            raise _Stop


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
