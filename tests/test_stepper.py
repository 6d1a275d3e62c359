"""The compiled step loop (meshwear/kernels/loop.py) against the Python step
it replaces (meshwear.step.simulate.step): the same numbers to the last bit, on
every kind of motion and surface, with active-set refreshes on the way."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from meshwear.longrun.jumps import LOAD_ROWS
from meshwear.model.build import build_model, initial_state
from meshwear.scene.reader import load_scene
from meshwear.step.simulate import run

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

SLIDING_ON_A_MESH = """format = 1
[run]
duration = 0.02
dt = 1e-5
frames = 0
history = 5

[contact]
stiffness_per_area = 1e11
damping_per_area = 1e5
friction = 0.3

[wear]
law = "archard"
coefficient = 1e-13

[[body]]
name = "block"
shape = { type = "box", size = [0.01, 0.01, 0.005] }
resolution = 0.001
position = [0.0, 0.0, 0.0025]
force = [0.0, 0.0, -10.0]
motion = "guided"
[body.path]
velocity = [0.2, 0.0, 0.0]
free_axis = [0.0, 0.0, 1.0]

[[surface]]
name = "floor"
type = "mesh"
shape = { type = "box", size = [0.05, 0.05, 0.01] }
resolution = 0.004
position = [0.0, 0.0, -0.005]
"""

RING = """format = 1
[run]
mode = "quasi-static"
duration = 0.05
dt = 1e-3
frames = 0
history = 3
gravity = [0.0, 0.0, 0.0]

[contact]
stiffness_per_area = 1e12
friction = 0.3

[wear]
law = "archard"
coefficient = 1e-11

[[body]]
name = "block"
shape = { type = "box", size = [0.004, 0.004, 0.002] }
resolution = 2e-4
position = [0.0, 0.0, 0.011]
force = [0.0, 0.0, -5.0]
motion = "guided"
[body.path]
oscillation = { axis = [0.0, 1.0, 0.0], amplitude = 1e-4, frequency = 20.0 }
free_axis = [0.0, 0.0, 1.0]

[[surface]]
name = "ring"
type = "cylinder"
radius = 0.01
axis = [0.0, 1.0, 0.0]
rotation = { axis = [0.0, 1.0, 0.0], rate = 30.0 }

[[surface]]
name = "belt"
type = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
path = { velocity = [0.0, 0.0, 1e-3] }
"""


def _shortened(path, duration):
    scene = load_scene(path)
    return dataclasses.replace(scene, run=dataclasses.replace(
        scene.run, duration=duration, frames=0, history=3))


def _scenes(tmp_path):
    sliding = tmp_path / "sliding.toml"
    sliding.write_text(SLIDING_ON_A_MESH)
    ring = tmp_path / "ring.toml"
    ring.write_text(RING)
    return {
        "free cube, plane": _shortened(EXAMPLES / "cube_toss.toml", 0.12),
        "guided block, dynamic": _shortened(EXAMPLES / "reciprocating_block.toml", 0.02),
        "pin, turning disc mesh": _shortened(EXAMPLES / "pin_on_turning_disc.toml", 0.05),
        "ball fretting, quasi-static": _shortened(EXAMPLES / "sphere_on_flat_fretting.toml",
                                                  0.05),
        "block sliding over a mesh (refreshes)": load_scene(sliding),
        "block on a turning cylinder under a rising plane": load_scene(ring),
    }


FIELDS = ("pose", "vertices", "wear_depth", "wear_volume", "friction_work", "contact_state",
          "tangential", "normal_force", "wrench", "vertex_planes", "hint", "active", "cull",
          "load")


def test_the_compiled_loop_gives_the_python_step_s_numbers_bit_for_bit(tmp_path, monkeypatch):
    from meshwear.surfaces import active

    for name, scene in _scenes(tmp_path).items():
        states, refreshes = [], []
        for compiled in (False, True):
            calls = []
            original = active.refresh
            monkeypatch.setattr(active, "refresh",
                                lambda *a, calls=calls, original=original: (calls.append(a[3]),
                                                                            original(*a))[1])
            model = build_model(scene)
            state = initial_state(model)
            for s in state.bodies:
                # the sums a measured cycle keeps (meshwear.longrun.jumps.LOAD_ROWS)
                s.load = np.zeros((LOAD_ROWS, len(s.wear_depth)))
            state = run(model, state, compiled=compiled)
            monkeypatch.undo()
            states.append(state)
            refreshes.append(calls)
        python, compiled = states
        assert compiled.step == python.step == model.n_steps, name
        for a, b in zip(python.bodies, compiled.bodies):
            for field in FIELDS:
                assert np.array_equal(getattr(a, field), getattr(b, field)), (name, field)
        assert refreshes[0] == refreshes[1], name
        if "refreshes" in name:
            assert len(refreshes[0]) > 10
        assert python.bodies[0].friction_work.sum() > 0.0, name
        assert np.abs(python.bodies[0].load[2:5]).sum() > 0.0, name


def test_a_load_nothing_carries_stops_the_compiled_loop_as_the_python_step(tmp_path):
    """A finite ring slides out from under the block along its axis: the
    block's vertices pass its end, no contact is left to carry the load, and
    the quasi-static balance has no solution."""
    from meshwear.step.simulate import NumericalError

    path = tmp_path / "away.toml"
    text = RING[:RING.index('[[surface]]\nname = "belt"')]
    text = text.replace("rotation = { axis", 'length = 0.004\npath = { velocity = [0.0, 1.0, 0.0] }\n'
                                            "rotation = { axis")
    path.write_text(text)
    messages = []
    for compiled in (False, True):
        model = build_model(load_scene(path))
        with pytest.raises(NumericalError, match="no contact carries its load") as err:
            run(model, initial_state(model), compiled=compiled)
        messages.append(str(err.value))
    assert messages[0] == messages[1]


def test_a_first_run_compiles_the_loop_its_scene_needs(tmp_path):
    """Each scene steps in the build of the loop that has only what it uses
    (docs/performance.md, "The first run compiles"): free bodies on one
    plane, dynamic (the demo), leave out the paths and the quasi-static
    step; a guided body on one plane keeps its path; a turning mesh disc
    brings the mesh kernels and no other kind's; none of them the threaded
    kernels (too few vertices) nor the worn counter's."""
    from meshwear.kernels import loop

    scenes = _scenes(tmp_path)
    builds = {name: loop.scene_build(build_model(scenes[name])) for name in
              ("free cube, plane", "guided block, dynamic", "pin, turning disc mesh")}
    assert builds["free cube, plane"] == dict(kinds=(), worn=False, threaded=False,
                                              case=loop.ONE_PLANE, dynamic=True, free=True)
    assert builds["guided block, dynamic"] == dict(kinds=(), worn=False, threaded=False,
                                                   case=loop.ONE_PLANE, dynamic=True, free=False)
    assert builds["pin, turning disc mesh"] == dict(kinds=("mesh",), worn=False, threaded=False,
                                                    case=loop.ONE_SURFACE, dynamic=False,
                                                    free=False)
    # one build per kind of scene, made once
    assert loop.loop_for(build_model(scenes["free cube, plane"])) is loop.loop_build(
        **builds["free cube, plane"])
    assert loop.loop_build() is loop.advance_body
