"""A cycle jump never folds the mesh it moves (docs/model.md, "Long durations":
the bounds ``reach`` and ``fold``, :mod:`meshwear.longrun.jump_geometry`)."""

import numpy as np
import pytest

import cases
from meshwear import geometry
from meshwear.longrun import jump_geometry, wear
from meshwear.model.build import build_model, initial_state
from meshwear.scene.reader import load_scene
from meshwear.step.simulate import inverted, run

#: a 10 mm ball fretting +-0.1 mm under 50 N on a plane, archard, cycle jumping
#: to a cap 1.69 mm deep: the reported 2e4 cycles at k = 1e-10 shortened to
#: 4000 at 5e-10 (the same cap); 40 steps a cycle, so the active set's margin
#: is the ball's own (1 % of its size, 0.17 mm), not ten steps' stroke
DEEP_BALL = """\
format = 1

[run]
mode = "quasi-static"
duration = 4000.0
dt = 0.025
frames = 0
history = 3
gravity = [0.0, 0.0, 0.0]

[contact]
stiffness_per_area = 1e12
tangential_stiffness_per_area = 1e15    # stiff tangentially: the whole stroke slides
friction = 0.5

[wear]
law = "archard"
coefficient = 5e-10
acceleration = "cycle_jump"

[[body]]
name = "ball"
shape = { type = "sphere", radius = 0.005, subdivisions = 5 }
density = 7850.0
orientation = [0.96193836, 0.27326653, 0.0, 0.0]
position = [0.0, 0.0, 0.005]
force = [0.0, 0.0, -50.0]
motion = "guided"

[body.path]
oscillation = { axis = [1.0, 0.0, 0.0], amplitude = 1e-4, frequency = 1.0 }
free_axis = [0.0, 0.0, 1.0]

[[surface]]
name = "flat"
type = "plane"
"""


def _enclosed(vertices, faces):
    """The volume (m^3) a closed mesh encloses."""
    t = vertices[faces]
    return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum()) / 6.0


def test_a_deep_fretting_ball_jumps_to_the_closed_form_cap(tmp_path, monkeypatch, measured):
    """Jumps of thousands of cycles moved the ball down by 2.5 times its
    active set's margin, onto vertices at the cap's rim that their
    measurement had not seen: those did not wear, the measured ones beside
    them wore to the plane and passed them, and the run stopped with 215
    folded faces (exit 3), its cap 0.7 % too deep. Bounded by the reach of
    what they measured and by the faces they move, the jumps wear the
    closed-form cap (V = k P s, pi h^2 (R - h/3) = V), every face upright
    after every jump, each vertex moved as the bounds read it."""
    path = tmp_path / "ball.toml"
    path.write_text(DEEP_BALL)
    model = build_model(load_scene(path))
    body = model.bodies[0]
    state = initial_state(model)
    taken = []
    jump = wear._jump

    def watched(model, state, before, rates, J, results, measures=None, window=1):
        s = state.bodies[0]
        start = s.vertices.copy()
        normal = np.zeros((len(s.vertices), 3))
        normal[measures[0].index] = measures[0].normal
        planned = jump_geometry.displacement(body, s, before[0][1], rates[0], results[0][0],
                                             normal, window)
        spans = jump(model, state, before, rates, J, results, measures, window)
        np.testing.assert_allclose(s.vertices - start, planned, rtol=0.0, atol=1e-15)
        folded = geometry.inverted_faces(body.reference_face_normals, s.vertices, body.faces)
        taken.append((J, len(folded)))
        return spans

    monkeypatch.setattr(wear, "_jump", watched)
    run(model, state)

    s = state.bodies[0]
    R, k, P = 0.005, 5e-10, 50.0
    volume = k * P * 4 * 1e-4 * 4000          # s = 4 x amplitude x cycles
    h = cases.cap_depth(volume, R)
    depth = float(s.wear_depth.max())
    measured("deep ball, jumped: cap depth", depth, h, 1e-2)
    assert depth == pytest.approx(h, rel=1e-2)
    assert float(s.wear_volume.sum()) == pytest.approx(volume, rel=1e-2)
    lost = _enclosed(body.reference_vertices, body.faces) - _enclosed(s.vertices, body.faces)
    measured("deep ball, jumped: volume the mesh lost", lost, volume, 1e-2)
    assert lost == pytest.approx(volume, rel=1e-2)
    assert len(geometry.inverted_faces(body.reference_face_normals, s.vertices, body.faces)) == 0
    assert taken and all(folded == 0 for _, folded in taken)
    # the regime: jumps long enough that the geometry bounded some of them
    limits = state.jump.limits
    assert limits.get("reach", 0) + limits.get("fold", 0) > 0, limits
    assert state.jump.resolved_steps < 0.05 * model.n_steps


def _ball(subdivisions=2):
    """An icosphere of radius 1 and its unworn face normals."""
    vertices, faces = geometry.primitive("sphere", radius=1.0, subdivisions=subdivisions)
    return vertices, faces, geometry.face_normals(vertices, faces)


class _Body:
    """What :func:`meshwear.longrun.jump_geometry.fold_room` reads of a body."""

    def __init__(self, faces, normals):
        self.faces, self.reference_face_normals = faces, normals


def test_fold_room_is_the_first_multiple_of_the_moves_that_folds_a_face():
    """Random moves of a few vertices of a sphere, each scaled by the room
    found: a little short of it no face is folded, a little past it one is."""
    vertices, faces, normals = _ball()
    body = _Body(faces, normals)
    rng = np.random.default_rng(3)
    for _ in range(20):
        move = np.zeros_like(vertices)
        chosen = rng.choice(len(vertices), 4, replace=False)
        move[chosen] = rng.normal(size=(4, 3)) * 0.05
        room = jump_geometry.fold_room(body, vertices, move)
        assert np.isfinite(room) and room > 0.0
        assert len(geometry.inverted_faces(normals, vertices + 0.999 * room * move, faces)) == 0
        assert len(geometry.inverted_faces(normals, vertices + 1.001 * room * move, faces)) > 0


def test_fold_room_of_a_vertex_pushed_through_its_neighbours():
    """A vertex of an icosahedron pushed inwards along its normal folds a
    face of its five (the run's check: its area along its unworn normal
    goes negative) as it passes the plane through the face's opposite edge
    along that normal: its room is the distance to that plane. A move of
    every vertex alike folds nothing."""
    vertices, faces, normals = _ball(0)
    body = _Body(faces, normals)
    apex = 0
    axis = vertices[apex] / np.linalg.norm(vertices[apex])
    around = np.flatnonzero((faces == apex).any(axis=1))
    assert len(around) == 5
    distance = np.inf
    for f in around:
        r1, r2 = [vertices[v] for v in faces[f] if v != apex]
        across = np.cross(r2 - r1, normals[f])
        distance = min(distance, float((vertices[apex] - r1) @ across / (axis @ across)))
    move = np.zeros_like(vertices)
    move[apex] = -1e-3 * axis
    assert jump_geometry.fold_room(body, vertices, move) == pytest.approx(distance / 1e-3,
                                                                          rel=1e-9)
    # further than to the plane of its neighbours (where a resolved run is
    # far from folding it)
    ring = np.setdiff1d(faces[around], [apex])
    assert distance > float((vertices[apex] - vertices[ring[0]]) @ axis)
    assert jump_geometry.fold_room(body, vertices, np.full_like(vertices, 0.3)) == np.inf


def test_a_jump_is_cut_to_the_share_its_mesh_allows():
    """:func:`meshwear.longrun.jump_geometry.cut` on a jump of an icosahedron whose
    vertex wore inwards in the measured cycle: its fold bound is
    :data:`meshwear.longrun.jump_geometry.FOLD` of the room the jump's moves leave,
    and a move of the body along its axis past the reach of the vertices
    measured is cut to the reach, whichever is shorter."""
    from types import SimpleNamespace

    vertices, faces, normals = _ball(0)
    body = SimpleNamespace(faces=faces, reference_face_normals=normals,
                           wear_direction=np.zeros((0, 3)))
    apex = 0
    axis = vertices[apex] / np.linalg.norm(vertices[apex])
    start = vertices.copy()
    start[apex] += 1e-3 * axis                # a cycle ago, 1 mm further out
    rate = np.zeros(len(vertices))
    rate[apex] = 1e-3
    s = SimpleNamespace(vertices=vertices)
    model = SimpleNamespace(bodies=[body])
    room = jump_geometry.fold_room(body, vertices, vertices - start)   # in cycles
    assert np.isfinite(room)
    jump = 4.0 * room
    results = [(jump * rate, 0.5, None)]
    which, share = jump_geometry.cut(model, [s], [(None, start)], [rate], results, None, 1,
                                     [np.inf])
    assert which == "fold" and share == pytest.approx(jump_geometry.FOLD * room / jump)
    which, share = jump_geometry.cut(model, [s], [(None, start)], [rate], results, None, 1,
                                     [0.01])
    assert which == "reach" and share == pytest.approx(0.01 / 0.5)
    short = [(0.1 * room * rate, 0.001, None)]
    assert jump_geometry.cut(model, [s], [(None, start)], [rate], short, None, 1, [0.01]) is None


def test_the_message_of_folded_faces_says_what_folded_them():
    """Faces folded by steps: the mesh cannot follow the wear (refine it,
    shorten the run); reached by a cycle jump: the jump (lower the
    tolerance or resolve every cycle)."""
    vertices, faces, normals = _ball(1)

    class Body:
        name = "ball"
        reference_vertices = vertices

    class State:
        time, resolved = 1.5, True

    s = type("S", (), {"wear_depth": np.full(len(vertices), 2e-4)})()
    message = inverted(Body, s, faces[:3], State)
    assert "inverted 3 triangle(s)" in message and "refine the mesh" in message
    assert "0.0002 m" in message
    State.resolved = False
    message = inverted(Body, s, faces[:3], State)
    assert "cycle jump" in message and "wear.tolerance" in message
    assert "refine" not in message
