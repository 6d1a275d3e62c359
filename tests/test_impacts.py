"""Impacts the contact cannot stop (docs/model.md, "Impacts"): a dynamic body
whose vertex in contact goes deeper than a quarter of its thinnest extent
stops the run with exit 3; one whose starting speed carries it that deep in
a single step is refused before the run with exit 2."""

import json
from pathlib import Path

import numpy as np
import pytest

import reference
from meshwear.cli import main
from meshwear.kernels.frames import step_motion
from meshwear.kernels.loop import deepest_penetration, impact_check, use_impact_room
from meshwear.model.build import IMPACT_DEPTH, build_model, initial_state
from meshwear.scene.reader import load_scene
from meshwear.step.simulate import NumericalError, run

ROOT = Path(__file__).resolve().parents[1]
CUBE = str(ROOT / "examples" / "cube_toss.toml")
# the cube (20 mm) falling flat, with no damping, friction or gravity: the
# contact's own natural frequency is sqrt(K A / m) = 3.57e4 rad/s, so a drop
# at v reaches v / 3.57e4 m deep (2.8 mm at 100 m/s, 8.4 mm at 300 m/s)
FLAT_DROP = [("body[0].angular_velocity", [0.0, 0.0, 0.0]),
             ("body[0].orientation", [1.0, 0.0, 0.0, 0.0]),
             ("body[0].position", [0.0, 0.0, 0.0105]), ("run.duration", 0.002),
             ("run.frames", 2), ("run.history", 11), ("contact.friction", 0.0),
             ("contact.damping_per_area", 0.0), ("run.gravity", [0.0, 0.0, 0.0])]


def _drop(speed, dt="auto"):
    return load_scene(CUBE, FLAT_DROP + [("body[0].velocity", [0.0, 0.0, -speed]),
                                         ("run.dt", dt)])


def _sets(speed, dt="auto"):
    out = []
    for key, value in FLAT_DROP + [("body[0].velocity", [0.0, 0.0, -speed]), ("run.dt", dt)]:
        out += ["--set", f"{key}={json.dumps(value)}"]
    return out


@pytest.mark.parametrize("n_planes, n_meshes", [(1, 0), (2, 1), (0, 2)])
def test_deepest_penetration_matches_numpy_twin(n_planes, n_meshes):
    rng = np.random.default_rng(7)
    n = 200
    vertices = rng.normal(size=(n, 3)) * 0.01
    q = rng.normal(size=4)
    pose = np.concatenate([rng.normal(size=3) * 0.001, q / np.linalg.norm(q), np.zeros(6)])
    planes = np.zeros((n_planes, 4, 3))
    planes[:, 0] = rng.normal(size=(n_planes, 3)) * 0.002
    normals = rng.normal(size=(n_planes, 3))
    planes[:, 1] = normals / np.linalg.norm(normals, axis=1)[:, None]
    vertex_planes = np.zeros((n_meshes, n, 3, 3))
    vertex_planes[:, :, 0] = rng.normal(size=(n_meshes, n, 3)) * 0.002
    normals = rng.normal(size=(n_meshes, n, 3))
    vertex_planes[:, :, 1] = normals / np.linalg.norm(normals, axis=2)[..., None]
    active = np.sort(rng.choice(n, 120, replace=False)).astype(np.int64)
    state = rng.integers(0, 3, size=(n_planes + n_meshes, n)).astype(np.int8)
    got = deepest_penetration(vertices, pose, planes, vertex_planes, active, state)
    want = reference.deepest_penetration(vertices, pose, planes, vertex_planes, active, state)
    assert got[1:] == want[1:] and want[1] >= 0
    assert got[0] == pytest.approx(want[0], rel=1e-12)
    # vertices out of contact never count, however deep
    state[:] = 0
    assert deepest_penetration(vertices, pose, planes, vertex_planes, active, state) == (0.0, -1, -1)


def test_the_deepest_vertex_is_measured_only_when_the_motion_may_have_used_the_room():
    """Conservative advancement: after a measurement the room below the limit
    is known; steps take their motion off it; a new measurement comes only
    when it may be used up."""
    model = build_model(_drop(10.0))
    body, state = model.bodies[0], initial_state(model)
    s = state.bodies[0]
    s.pose[2] = 0.01 - 0.001                     # the bottom face 1 mm into the plate
    s.contact_state[:] = 1
    every = np.arange(len(s.vertices), dtype=np.int64)
    args = (s.vertices, s.pose, model.planes, s.vertex_planes, every, s.contact_state,
            body.depth_limit)
    room = np.zeros(1)
    assert impact_check(*args, room) == (-1, -1)
    assert room[0] == pytest.approx(body.depth_limit - 0.001, rel=1e-9)
    buffer = np.zeros((2, 3))
    step = step_motion(s.pose, body.radius, model.surfaces.bounds, model.surfaces.terms, 0.0,
                       model.dt, buffer)
    assert step == pytest.approx(10.0 * model.dt, rel=1e-9)
    before = room[0]
    use_impact_room(room, s.pose, body.radius, model.surfaces.bounds, model.surfaces.terms, 0.0,
                    model.dt, buffer)
    assert room[0] == pytest.approx(before - step, rel=1e-12)
    # with room left nothing is measured, however deep the body is now
    s.pose[2] = -0.01
    assert impact_check(*args, room) == (-1, -1)
    room[0] = 0.0
    assert impact_check(*args, room)[0] == 0


def test_an_impact_the_contact_can_stop_runs_on():
    """At 100 m/s the flat drop goes 2.8 mm deep (14 % of the cube): it runs,
    and bounces back (no damping) at its speed within the step's error."""
    model = build_model(_drop(100.0))
    assert model.bodies[0].depth_limit == pytest.approx(IMPACT_DEPTH * 0.02, rel=1e-9)
    state = run(model, initial_state(model))
    assert state.bodies[0].pose[9] == pytest.approx(100.0, rel=0.05)


def test_an_impact_deeper_than_the_body_can_stand_stops_the_run():
    """At 300 m/s it would go 8.4 mm deep: the compiled loop and the Python
    reference step stop at the same state, with the same message, before the
    cube is more than a quarter of its size (and a step's travel) inside."""
    stopped = []
    for compiled in (True, False):
        model = build_model(_drop(300.0))
        state = initial_state(model)
        with pytest.raises(NumericalError, match=r"body 'cube': vertex \d+ went .* into surface "
                                                 r"'plate' .* an impact faster than the contact"
                           ) as err:
            run(model, state, compiled=compiled)
        stopped.append((str(err.value), state.bodies[0].pose.copy()))
        depth = -(state.bodies[0].pose[2] - 0.01)
        assert IMPACT_DEPTH * 0.02 < depth <= IMPACT_DEPTH * 0.02 + 300.0 * model.dt
    assert stopped[0][0] == stopped[1][0]
    assert np.array_equal(stopped[0][1], stopped[1][1])


def test_the_command_stops_a_too_deep_impact_with_exit_3(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", CUBE, "-o", str(out), "-q", *_sets(300.0)]) == 3
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "an impact faster than the contact can stop" in err[0]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "numerical_error"


def test_check_refuses_a_body_that_crosses_its_limit_in_one_step(capsys):
    """The issue's case: at 1000 m/s the cube moves 16 mm in one stable step."""
    assert main(["check", CUBE, *_sets(1000.0, 1.6e-5)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "body[0].velocity" in err[0] and "in one step" in err[0]
    # with a step short enough for that, check's trial steps meet the impact
    assert main(["check", CUBE, *_sets(1000.0, 1e-7)]) == 3
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "an impact faster than the contact can stop" in err[0]
