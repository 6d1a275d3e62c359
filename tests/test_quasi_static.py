"""Quasi-static mode: the load balance holds at every step, t = 0 included."""

import dataclasses

import numpy as np
import pytest

import cases
from meshwear.model.build import build_model, initial_state
from meshwear.model.timestep import stable_time_step
from meshwear.scene.reader import load_scene
from meshwear.step.simulate import run_scene


def test_contacts_carry_the_load_at_every_sample_from_t0():
    scene = load_scene(cases.EXAMPLES / "pin_on_disc.toml")
    scene = dataclasses.replace(scene, run=dataclasses.replace(scene.run, duration=0.5, history=51,
                                                                 frames=0))
    samples = cases.Samples()
    model, state, _ = run_scene(scene, observers=[samples])
    load = model.bodies[0].mass * 9.81 + 20.0
    wrench = samples.arrays()["wrench"]
    assert samples.time[0] == 0.0
    np.testing.assert_allclose(wrench[:, 2], load, rtol=1e-12)
    # friction opposes the sliding, at f N once the face slips
    speed = samples.arrays()["pose"][1:, 7:9]   # in the plane of the disc
    along = np.einsum("ij,ij->i", wrench[1:, 0:2], speed) / np.linalg.norm(speed, axis=1)
    np.testing.assert_allclose(along[2:], -0.5 * load, rtol=1e-9)


def test_quasi_static_has_no_stability_limit_and_no_damping():
    model = build_model(load_scene(cases.EXAMPLES / "pin_on_disc.toml"))
    assert stable_time_step(model)[0] == np.inf
    assert model.quasi_static and not model.law[[7, 8, 11, 12]].any()


def test_a_prescribed_body_follows_its_path_with_increment_velocities(tmp_path):
    text = (cases.VALIDATION / "flat_pin.toml").read_text()
    text = text.replace('motion = "guided"', 'motion = "prescribed"').replace(
        'force = [0.0, 0.0, -20.0]   # P, N', '').replace(
        "free_axis = [0.0, 0.0, 1.0]", "").replace("position = [0.0, 0.0, 0.005]",
                                                    "position = [0.0, 0.0, 0.004999]")
    path = tmp_path / "pressed.toml"
    path.write_text(text)
    model, state, history = run_scene(load_scene(path))
    h = history.rows["pin"]
    np.testing.assert_allclose(h["origin"][:, 0], h["time"] * 1.0, atol=1e-15)
    # 1 µm into a 1e12 N/m³ foundation on the 48-gon: N = K A (1 µm)
    face = 0.5 * 48 * 0.003 ** 2 * np.sin(2 * np.pi / 48)
    assert h["wrench"][0, 2] == pytest.approx(1e12 * face * 1e-6, rel=1e-9)  # at t = 0, unworn


def test_t0_contacts_are_in_stick_with_nothing_worn():
    model = build_model(load_scene(cases.VALIDATION / "flat_pin.toml"))
    state = initial_state(model)
    s = state.bodies[0]
    touching = s.contact_state[0] > 0
    assert touching.sum() == 49 and np.all(s.contact_state[0][touching] == 1)
    assert s.friction_work.sum() == 0.0 and s.wear_depth.sum() == 0.0
    assert s.wrench[2] == pytest.approx(20.0, rel=1e-12)
