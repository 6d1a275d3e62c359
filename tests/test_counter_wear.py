"""Worn counter-surfaces (docs/model.md, "Worn counter-surfaces"): the wear
of a mesh counter-part from the same pairs as the body's, its kernel against
the numpy twin, conservation, the chord law of a pin's track on a turning
disc, outputs, checkpoints and refusals."""

import copy
import json

import numpy as np
import pytest
import pyvista

import cases
import reference
from meshwear.longrun import checkpoint, jumps
from meshwear.cli import main
from meshwear.kernels import counter_wear
from meshwear.kernels.counter_wear import settle_counter, wear_counter
from meshwear.model.build import build_model, initial_state
from meshwear.scene.reader import load_scene
from meshwear.scene.checks import SceneError
from meshwear.step.simulate import NumericalError, run

#: a flat pin (radius a = 1 mm) held R = 5 mm off the axis of a disc turning
#: at 10 rad/s, pressed by P = 10 N (quasi-static, Archard); both wear, the
#: disc twice as fast. Two turns.
PIN_ON_WORN_DISC = """format = 1
[run]
mode = "quasi-static"
duration = {duration}
dt = {dt}
frames = 3
history = 5
[contact]
stiffness_per_area = 1e13
friction = 0.4
[wear]
law = "archard"
coefficient = 1e-13
[[body]]
name = "pin"
shape = {{ type = "cylinder", radius = 0.001, height = 0.003, sections = 24 }}
resolution = 1.5e-4
position = [0.005, 0.0, 0.0015]
force = [0.0, 0.0, -10.0]
motion = "guided"
density = 7850.0
[body.path]
free_axis = [0.0, 0.0, 1.0]
[[surface]]
name = "disc"
type = "mesh"
shape = {{ type = "cylinder", radius = 0.008, height = 0.002, sections = 64 }}
resolution = 3e-4
position = [0.0, 0.0, -0.001]
rotation = {{ axis = [0.0, 0.0, 1.0], rate = 10.0, center = [0.0, 0.0, 0.0] }}
wear = true
coefficient = {coefficient}
"""
P, A, R, OMEGA, K_PIN, K_DISC = 10.0, 1e-3, 5e-3, 10.0, 1e-13, 2e-13
TWO_TURNS = 4.0 * np.pi / OMEGA


def _scene(tmp_path, duration=TWO_TURNS, coefficient=K_DISC, extra="", dt=2e-3,
           disc_resolution=3e-4):
    path = tmp_path / "pin_on_worn_disc.toml"
    text = PIN_ON_WORN_DISC.format(duration=duration, coefficient=coefficient, dt=dt)
    path.write_text(text.replace("resolution = 3e-4", f"resolution = {disc_resolution!r}")
                    + extra)
    return path


@pytest.fixture(scope="module")
def two_turns(tmp_path_factory):
    model = build_model(load_scene(_scene(tmp_path_factory.mktemp("disc"))))
    return model, run(model, initial_state(model))


@pytest.mark.parametrize("disc_resolution", [3e-4, 6e-5])
def test_kernel_matches_its_numpy_twin(tmp_path, disc_resolution):
    """On a disc as coarse as the pin, each pair wears the face under its
    foot; on a finer one, the spread of each of its corners too."""
    # (on the fine disc the disc wears faster, so that its vertices lag and
    # move within a few steps of the twin)
    model = build_model(load_scene(_scene(
        tmp_path, duration=0.1, disc_resolution=disc_resolution,
        coefficient=K_DISC if disc_resolution > 1e-4 else 100 * K_DISC)))
    state = run(model, initial_state(model))
    disc, part, s, body = model.surfaces.per_vertex[0], state.parts[0], state.bodies[0], \
        model.bodies[0]
    assert (s.normal_force[0, s.active] > 0.0).sum() > 100, "the case must have pairs"
    rotation, frame = disc.frame(state.time)
    part.stiffness = np.zeros(len(part.depth))      # (as cycle jumps keep it)
    twin = copy.deepcopy(part)
    args = (s.vertices, s.pose, s.active, body.area_vectors, model.law, s.contact_state[0],
            s.normal_force[0], s.vertex_planes[0], s.hint[0], rotation, frame)
    depth0 = part.depth.copy()
    twin_tuple = (disc.law, disc.faces, disc.reference_vertices, disc.vertex_normals,
                  disc.tributary, disc.spacing, None, None, twin.vertices, twin.frames,
                  twin.depth, twin.volume, twin.work, twin.added, twin.touched, twin.limit,
                  twin.due, twin.count, twin.stiffness, twin.place,
                  (*disc.spread, twin.pending, twin.pending_list, twin.pending_place,
                   twin.pending_count))

    def same():
        for name in ("depth", "volume", "work", "vertices", "added", "limit", "stiffness"):
            np.testing.assert_allclose(getattr(part, name), getattr(twin, name), rtol=1e-12,
                                       atol=1e-12 * np.abs(getattr(twin, name)).max(
                                           where=np.isfinite(getattr(twin, name)),
                                           initial=0.0))
        touched = np.unique(disc.faces[np.isin(disc.faces, np.flatnonzero(part.depth > depth0))
                                       .any(axis=1)].ravel())
        faces = np.flatnonzero(np.isin(disc.faces, touched).any(axis=1))
        np.testing.assert_allclose(part.frames[faces], twin.frames[faces], rtol=0, atol=1e-12)

    # the same step taken over and over: vertices lag, then move once their
    # lag reaches LAG_FRACTION of their pairs' penetration
    lagged = moved = False
    # the pairs' log (implicit jumps): each pair's share of each counter vertex
    rows = 3 * len(s.active)
    log = (np.zeros((rows, 3), np.int64), np.zeros(rows), np.array([0, 1]))
    twin_log = (np.zeros((rows, 3), np.int64), np.zeros(rows), np.array([0, 1]))
    for step in range(400):
        log[2][0] = twin_log[2][0] = 0
        assert wear_counter(*args, disc.part_tuple(), 0, *log) == -1
        assert len(reference.wear_counter(*args, twin_tuple, 0, twin_log)) == 0
        same()
        if step == 0:
            count = log[2][0]
            assert count == twin_log[2][0] > 100
            np.testing.assert_array_equal(log[0][:count], twin_log[0][:count])
            np.testing.assert_allclose(log[1][:count], twin_log[1][:count], rtol=1e-12,
                                       atol=1e-12 * np.abs(twin_log[1][:count]).max())
            # each pair's rows share its normal force among the corners of
            # the face under it: they add up to the force of every vertex
            # over a face
            i = log[0][:count, 1]
            over = np.unique(i)
            np.testing.assert_allclose(np.bincount(i, log[1][:count])[over],
                                       s.normal_force[0, over], rtol=1e-12)
            assert (s.normal_force[0, over] > 0.0).all()
        lagging = part.added > 0.0
        lagged |= lagging.any()
        at_depth = np.all(part.vertices == disc.reference_vertices
                          - part.depth[:, None] * disc.vertex_normals, axis=1)
        moved |= (at_depth & (part.depth > depth0)).any()
        # a lagging vertex is where its depth less its lag puts it
        np.testing.assert_allclose(part.vertices[lagging], disc.reference_vertices[lagging]
                                   - (part.depth - part.added)[lagging, None]
                                   * disc.vertex_normals[lagging], rtol=0, atol=1e-15)
        assert set(part.touched[:part.count[0]]) == set(np.flatnonzero(lagging))
        # each lagging vertex knows its place in the list (a moving one leaves it)
        lagging_list = part.touched[:part.count[0]]
        np.testing.assert_array_equal(part.place[lagging_list], np.arange(part.count[0]))
        assert (part.place[~lagging] == -1).all()
        if lagged and moved:
            break
    assert (part.depth > depth0).sum() > 10
    assert lagged and moved, "the case must have vertices that lag and that move"
    settle_counter(disc.part_tuple())
    reference.settle_counter(twin_tuple)
    same()
    assert part.pending_count[0] == 0 and (part.pending_place == -1).all()
    # a vertex's stiffness is what its depth does to the pairs pressing on
    # it: every vertex of a face under a pair has one; a spread wears others
    # too
    stiff, worn = part.stiffness > 0.0, part.depth > depth0
    if disc_resolution > 1e-4:
        assert not len(disc.spread[0])
        np.testing.assert_array_equal(stiff, worn)
    else:
        assert len(disc.spread[0]) and stiff.sum() > 10 and not (stiff & ~worn).any()
        assert worn.sum() > 2 * stiff.sum()

    assert part.count[0] == 0 and not part.added.any() and np.isinf(part.limit).all()
    assert (part.place == -1).all()
    np.testing.assert_allclose(part.vertices, disc.reference_vertices
                               - part.depth[:, None] * disc.vertex_normals, rtol=0, atol=1e-15)


def test_the_threaded_builds_give_the_serial_numbers_bit_for_bit(tmp_path):
    """The pairs' shares and the refit of moved vertices are computed on
    threads above a size (counter_wear.PARALLEL_PAIRS, PARALLEL_REFIT); both
    builds give the same numbers to the last bit."""
    model = build_model(load_scene(_scene(tmp_path, duration=0.1)))
    state = run(model, initial_state(model))
    disc, part, s, body = model.surfaces.per_vertex[0], state.parts[0], state.bodies[0], \
        model.bodies[0]
    rotation, frame = disc.frame(state.time)
    args = (s.vertices, s.pose, s.active, body.area_vectors, model.law, s.contact_state[0],
            s.normal_force[0], s.vertex_planes[0], s.hint[0], rotation, frame, disc.law,
            disc.faces, part.vertices)
    shares = []
    for kernel in (counter_wear._pairs_serial, counter_wear._pairs_parallel):
        at, pairs = np.full(len(s.active), -7), np.full((len(s.active), 12), np.nan)
        kernel(*args, at, pairs)
        shares.append((at, pairs[at >= 0]))
    assert (shares[0][0] >= 0).sum() > 100, "the case must have pairs"
    np.testing.assert_array_equal(shares[0][0], shares[1][0])
    np.testing.assert_array_equal(shares[0][1], shares[1][1])
    # every worn vertex moved to its depth again, its faces fitted anew
    moved = np.flatnonzero(part.depth > 0.0)
    assert len(moved) > counter_wear.PARALLEL_REFIT
    marks = np.full(len(part.depth), np.inf)
    marks[moved] = -1.0
    fitted = []
    for kernel in (counter_wear._refit_serial, counter_wear._refit_parallel):
        vertices, frames = disc.reference_vertices.copy(), np.zeros_like(part.frames)
        kernel(moved, len(moved), marks, disc.reference_vertices, part.depth,
               disc.vertex_normals, vertices, disc.faces, frames, disc.vertex_face_starts,
               disc.vertex_face_items)
        fitted.append((vertices, frames))
    np.testing.assert_array_equal(fitted[0][0], fitted[1][0])
    np.testing.assert_array_equal(fitted[0][1], fitted[1][1])
    assert np.abs(fitted[0][1]).sum() > 0.0


def test_both_parts_wear_their_coefficient_times_load_times_sliding(two_turns, measured):
    """Each part's worn volume = its k P s (Archard); s is the mean sliding
    distance of the pin's face, omega t (R + a²/8R) for a uniform pressure."""
    model, state = two_turns
    s = OMEGA * state.time * (R + A * A / (8.0 * R))
    pin, disc = state.bodies[0].wear_volume.sum(), state.parts[0].volume.sum()
    assert measured("pin on worn disc: pin volume (m³)", pin, K_PIN * P * s, 5e-3) <= 5e-3
    assert measured("pin on worn disc: disc volume (m³)", disc, K_DISC * P * s, 5e-3) <= 5e-3
    # the same pairs wear both: the volumes are in the ratio of the coefficients
    assert disc / pin == pytest.approx(K_DISC / K_PIN, rel=1e-12)
    # and dissipate one friction work, counted once on each part
    assert state.parts[0].work.sum() == pytest.approx(state.bodies[0].friction_work.sum(),
                                                      rel=1e-12)


def test_the_disc_track_follows_the_chord_law(two_turns, measured):
    """A disc point at offset u from the track's centre line spends the arc
    c(u) of its circle under the pin per turn (:func:`cases.arc_chord`; the
    chord 2 sqrt(a² - u²) for R >> a): its depth is k p c(u) per turn,
    p = P / pi a² (uniform: the track stays far shallower than the elastic
    approach p / K), projected on the disc mesh."""
    model, state = two_turns
    disc, part = model.surfaces.per_vertex[0], state.parts[0]
    p = P / (np.pi * A * A)
    turns = OMEGA * state.time / (2.0 * np.pi)
    centre = K_DISC * p * 2.0 * A * turns
    assert centre < 0.02 * p / 1e13
    expected, u = cases.disc_track(disc.reference_vertices, disc.faces, 0.001, R, A, p, K_DISC,
                                   turns)
    track = (np.abs(disc.reference_vertices[:, 2] - 0.001) < 1e-9) & (np.abs(u) < 0.8 * A)
    assert track.sum() > 500
    error = np.abs(part.depth[track] - expected[track]).max() / centre
    assert measured("disc track vs chord law (of centre depth)", error, 0.0, 5e-2) <= 5e-2


def _disc_track(model, state):
    """(depth, chord law's depth, offset u) of the worn disc's running face,
    and the chord law's depth at the centre line."""
    disc, part = model.surfaces.per_vertex[0], state.parts[0]
    p = P / (np.pi * A * A)
    turns = OMEGA * state.time / (2.0 * np.pi)
    expected, u = cases.disc_track(disc.reference_vertices, disc.faces, 0.001, R, A, p, K_DISC,
                                   turns)
    face = np.abs(disc.reference_vertices[:, 2] - 0.001) < 1e-9
    return part.depth[face], expected[face], u[face], K_DISC * p * 2.0 * A * turns


def test_a_disc_four_times_finer_than_the_pin_wears_a_smooth_track(tmp_path, measured):
    """The pin's vertices 0.15 mm apart (its refined end face; spacing h_b
    90 um) on a disc refined to 37.5 um: each contact's wear spreads over the
    disc vertices around its foot (docs/model.md, "The area a contact stands
    for"), where one face's corners took it before and left spots 236 % off
    the chord law. Its volume is k P s, its depth along the track's centre
    line even, and within the track's inner part (|u| < 0.6 a) it follows
    the chord law within 5 %; the spread rounds the track's flanks (7.7 %
    off at |u| < 0.8 a, docs/model.md)."""
    model = build_model(load_scene(_scene(tmp_path, disc_resolution=3.75e-5)))
    state = run(model, initial_state(model))
    assert model.surfaces.per_vertex[0].spread[0].size > 0, "the disc must spread"
    s = OMEGA * state.time * (R + A * A / (8.0 * R))
    volume = state.parts[0].volume.sum()
    assert measured("pin on a 4x finer disc: disc volume (m³)", volume, K_DISC * P * s,
                    5e-3) <= 5e-3
    depth, expected, u, centre = _disc_track(model, state)
    line = np.abs(u) < 0.05 * A
    assert line.sum() > 200
    even = (depth[line].max() - depth[line].min()) / centre
    assert measured("4x finer disc: centre line's depth range (of its depth)", even, 0.0,
                    5e-2) <= 5e-2
    inner = np.abs(u) < 0.6 * A
    error = np.abs(depth[inner] - expected[inner]).max() / centre
    assert measured("4x finer disc: track |u| < 0.6 a vs chord law (of centre depth)", error,
                    0.0, 5e-2) <= 5e-2


def test_a_counter_far_finer_than_the_bodies_spreads_over_a_shorter_radius(tmp_path, caplog,
                                                                           monkeypatch):
    """Its spread lists would outgrow memory: the radius shrinks to fit
    them, with a notice naming the surface, and the volume stays exact."""
    from meshwear.surfaces import mesh

    monkeypatch.setattr(mesh, "SPREAD_ENTRIES", 200_000)
    with caplog.at_level("WARNING", logger="meshwear"):
        model = build_model(load_scene(_scene(tmp_path, duration=0.1, disc_resolution=6e-5)))
    spread = model.surfaces.per_vertex[0].spread
    # (the estimate counts each disc by the vertex's own area: within a few %)
    assert spread[0].size > 0 and len(spread[1]) <= 1.5 * 200_000
    assert any("disc: its vertices are" in r.getMessage() and "finer resolution" in
               r.getMessage() for r in caplog.records)
    state = run(model, initial_state(model))
    assert state.parts[0].volume.sum() == pytest.approx(
        K_DISC / K_PIN * state.bodies[0].wear_volume.sum(), rel=1e-9)


def test_compiled_loop_matches_the_python_step_on_a_worn_disc(tmp_path):
    model = build_model(load_scene(_scene(tmp_path, duration=0.1)))
    a = run(model, initial_state(model))
    parts_a = copy.deepcopy(a.parts[0])
    b = run(model, initial_state(model), compiled=False)
    assert np.array_equal(parts_a.depth, b.parts[0].depth)
    assert np.array_equal(parts_a.vertices, b.parts[0].vertices)
    assert np.array_equal(a.bodies[0].wear_depth, b.bodies[0].wear_depth)


def test_outputs_of_a_worn_surface(tmp_path):
    out = tmp_path / "out"
    assert main(["run", str(_scene(tmp_path, duration=0.1)), "-o", str(out), "-q"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    disc, pin = summary["surfaces"]["disc"], summary["bodies"]["pin"]
    assert disc["wear_volume"] > 0.0 and disc["max_wear_depth"] > 0.0
    assert disc["friction_work"] == pytest.approx(pin["friction_work"], rel=1e-12)
    # the contact forces on the two parts are equal and opposite
    np.testing.assert_allclose(disc["contact_force"], -np.array(pin["contact_force"]),
                               rtol=1e-9, atol=1e-12)
    rows = (out / "history.csv").read_text().splitlines()
    assert sum(line.split(",")[1] == "disc" for line in rows[1:]) == 5
    frames = sorted((out / "disc").glob("*.vtp"))
    assert len(frames) == 3 and (out / "disc.pvd").is_file()
    last = pyvista.read(frames[-1])
    for field in ("wear_depth", "normal_force", "friction_force", "pressure", "contact_state",
                  "friction_work"):
        assert field in last.point_data
    # the pairs' normal forces, shared among the disc's vertices: the load
    # (along the worn faces' normals, a few 1e-7 rad off the axis)
    assert last.point_data["normal_force"].sum() == pytest.approx(pin["contact_force"][2],
                                                                  rel=1e-5)


def test_a_checkpoint_carries_the_counter_wear(tmp_path):
    model = build_model(load_scene(_scene(tmp_path, duration=0.1)))
    full = run(model, initial_state(model))
    depth = full.parts[0].depth.copy()
    half = initial_state(model)
    from meshwear.step.simulate import advance
    advance(model, half, model.n_steps // 2)
    checkpoint.save(tmp_path / "c.npz", model, half, 0.0)
    resumed = initial_state(model)
    checkpoint.load(tmp_path / "c.npz", model, resumed)
    assert resumed.parts[0].depth.max() > 0.0
    run(model, resumed)
    assert np.abs(resumed.parts[0].depth - depth).max() <= 1e-9 * depth.max()


def test_a_counter_worn_faster_than_its_mesh_can_follow_stops(tmp_path):
    model = build_model(load_scene(_scene(tmp_path, duration=0.1, coefficient=1e-3)))
    with pytest.raises(NumericalError, match="surface 'disc'.*shortest edge"):
        run(model, initial_state(model))


@pytest.mark.parametrize("extra, key, text", [
    ('[[surface]]\nname = "floor"\ntype = "plane"\nwear = true\n', "wear",
     'does not apply to a type = "plane"'),
])
def test_wear_applies_to_mesh_surfaces_only(tmp_path, extra, key, text):
    with pytest.raises(SceneError, match=text):
        load_scene(_scene(tmp_path, extra=extra))


def test_a_law_without_wear_is_refused(tmp_path):
    path = _scene(tmp_path)
    path.write_text(path.read_text().replace("wear = true\ncoefficient = 2e-13",
                                             'law = "energy"'))
    with pytest.raises(SceneError, match="surface\\[0\\].law.*add wear = true"):
        load_scene(path)


#: the step of the jumped runs: a disc vertex near the track's edge passes
#: under the pin in a few steps of 2 ms, and the wear one cycle deposits on it
#: varies by some percent with how the steps fall (a jump multiplies one
#: cycle's); in steps of 0.5 ms it stays within the tolerance
JUMPED_DT = 5e-4


def _jumped(tmp_path, turns, jump="implicit"):
    """The pin on the worn disc over ``turns`` turns, cycle-jumped."""
    path = _scene(tmp_path, duration=turns * 2.0 * np.pi / OMEGA, dt=JUMPED_DT)
    path.write_text(path.read_text().replace(
        'law = "archard"', f'law = "archard"\nacceleration = "cycle_jump"\njump = "{jump}"'))
    return path


def test_explicit_jumps_over_a_worn_surface_are_refused(tmp_path):
    with pytest.raises(SceneError, match="surface\\[0\\].wear.*implicit jumps only"):
        build_model(load_scene(_jumped(tmp_path, 10, "explicit")))


@pytest.fixture(scope="module")
def ten_turns(tmp_path_factory):
    """The pin on the worn disc over ten turns, resolved and cycle-jumped."""
    folder = tmp_path_factory.mktemp("ten")
    resolved = build_model(load_scene(_scene(folder, duration=10 * 2.0 * np.pi / OMEGA,
                                             dt=JUMPED_DT)))
    jumped = build_model(load_scene(_jumped(folder, 10)))
    return (resolved, run(resolved, initial_state(resolved)),
            jumped, run(jumped, initial_state(jumped)))


def test_cycle_jumps_carry_both_parts_wear(ten_turns, measured):
    """Both parts' wear jumped together: each volume its k P s, and both
    depth fields within the run's tolerance of the resolved run, in half
    the turns resolved."""
    resolved_model, resolved, model, state = ten_turns
    js = state.jump
    assert js.jumps >= 2 and js.resolved_steps <= 0.6 * model.n_steps
    s = OMEGA * state.time * (R + A * A / (8.0 * R))
    pin, disc = state.bodies[0].wear_volume.sum(), state.parts[0].volume.sum()
    assert measured("jumped pin on worn disc: pin volume", pin, K_PIN * P * s, 5e-3) <= 5e-3
    assert measured("jumped pin on worn disc: disc volume", disc, K_DISC * P * s, 5e-3) <= 5e-3
    tolerance = model.scene.wear.tolerance
    for label, got, want in (
            ("pin", state.bodies[0].wear_depth, resolved.bodies[0].wear_depth),
            ("disc", state.parts[0].depth, resolved.parts[0].depth)):
        error = np.abs(got - want).max() / want.max()
        assert measured(f"jumped vs resolved, {label} depth (of its deepest)", error, 0.0,
                        tolerance) <= tolerance


def _relaxations(monkeypatch, model):
    """Run ``model`` jumped and return, per measurement, the contact's
    relaxation time and what it is over the vertices in contact (pressing
    in the cycle): the median of 1 / alpha and of 1 / (alpha + gamma), and
    how many press of how many may touch (gamma None: not yet known)."""
    from meshwear.longrun import wear

    seen = []
    relaxation = wear._relaxation

    def spy(measures):
        out = relaxation(measures)
        m = measures[0]
        may = m.member & (m.alpha > 0.0)
        pressed = may & (m.mean > 0.0)
        both = None if m.gamma is None else 1.0 / np.median((m.alpha + m.gamma)[pressed])
        seen.append(dict(relax=out, alone=1.0 / np.median(m.alpha[pressed]), both=both,
                         pressed=int(pressed.sum()), may=int(may.sum())))
        return out

    monkeypatch.setattr(wear, "_relaxation", spy)
    run(model, initial_state(model))
    return seen


def test_a_worn_counter_part_s_errors_relax_at_both_parts_wear(tmp_path, monkeypatch):
    """An error of depth relaxes at the body vertex's own and its worn
    counter-part's wear per cycle per unit penetration, alpha + gamma
    (docs/model.md, "Long durations"), over the resolved cycles too, and the
    counter-part's own errors at the median of those: each measurement
    knows the counter's wear under its vertices (gamma) before the
    relaxation is taken (it was taken from alpha alone: on the fretting
    example the flat's errors relaxed over 210-260 cycles where the contact
    relaxes them over 73-110)."""
    seen = _relaxations(monkeypatch, build_model(load_scene(_jumped(tmp_path, 6))))
    assert len(seen) >= 2
    for m in seen:
        assert m["both"] is not None
        assert m["relax"] < 0.9 * m["alone"]
        assert m["relax"] == pytest.approx(m["both"], rel=1e-12)


def test_the_contact_s_relaxation_is_the_median_over_the_vertices_in_contact(monkeypatch):
    """The cylinder on a worn flat, jumped: of the 3 200 vertices that may
    touch, 370 press; the relaxation is the median of alpha + gamma over
    those (over all of them, it was alpha alone: gamma is zero where the
    flat is not worn)."""
    import meshwear
    from cases import EXAMPLES

    scene = meshwear.load(EXAMPLES / "cylinder_on_worn_flat.toml",
                          {"run.duration": 30.0, "wear.acceleration": "cycle_jump",
                           "run.frames": 0})
    seen = _relaxations(monkeypatch, build_model(scene))
    assert len(seen) >= 3
    for m in seen:
        assert m["pressed"] < 0.5 * m["may"]
        assert m["relax"] == pytest.approx(m["both"], rel=1e-12)


def _stiff_vertex(jumps_per_g, settled, cycles=40):
    """A counter vertex of stiffness g = 0.1 a cycle following a contact
    that sinks rc a cycle: behind it by ``e`` (m), it wears ``rc + g e``
    (``e`` relaxes as ``e^(-g t)``). Measured over one resolved cycle
    between jumps of ``jumps_per_g / g`` cycles and jumped by ``J (r_c +
    phi (r - r_c))``, ``r_c`` from :func:`settled_rates` (``settled``) or
    the mean of the last two rates: its error (in rc / g) after each jump."""
    g, rc = 0.1, 1.0
    jump = jumps_per_g / g
    t, depth = 0.0, -0.3 * rc / g                      # it starts behind the contact
    past, previous, out = [], None, []
    for _ in range(cycles):
        behind = rc * t - depth
        rate = np.array([rc + behind * -np.expm1(-g)])   # the resolved cycle, exact
        middle, mid_depth = t + 0.5, np.array([depth + 0.5 * rate[0]])
        t, depth = t + 1.0, depth + rate[0]
        stiffness = np.array([g])
        if settled:
            target = jumps.settled_rates(rate, stiffness, mid_depth, middle, past)[0]
        else:
            target = rate[0] if previous is None else 0.5 * (rate[0] + previous)
        past, previous = (past + [(middle, mid_depth, rate, stiffness)])[-8:], rate[0]
        share = float(jumps.relaxed_share(jump * g))
        t, depth = t + jump, depth + jump * (target + share * (rate[0] - target))
        out.append(abs(rc * t - depth) * g / rc)
    return np.array(out)


@pytest.mark.parametrize("jumps_per_g", [0.5, 3.0, 10.0, 30.0])
def test_a_stiff_vertex_jumped_at_its_settled_rate_follows_its_contact(jumps_per_g):
    """The linear model of a stiff counter vertex (docs/model.md, "Long
    durations"): jumped by ``J (r_c + phi (r - r_c))`` with the settled rate
    from its depth's and rate's change between measurements, its error
    decays whatever ``J g``; from the mean of its last two rates instead
    (this model's own instability) it stops decaying once ``J g`` reaches
    about 2 (it stays at a third at 3) and grows beyond."""
    error = _stiff_vertex(jumps_per_g, settled=True)
    assert error[-1] < 1e-6 and error[-1] <= error[0]
    if jumps_per_g >= 3.0:
        assert _stiff_vertex(jumps_per_g, settled=False)[-1] > 0.1


def test_the_settled_rate_is_measured_at_least_one_relaxation_back():
    """A vertex takes the latest earlier measurement at least 1 / g cycles
    before; one untouched since (g = 0 then), or never stiff, keeps its
    rate."""
    rate, g = np.array([3.0, 3.0, 3.0]), np.array([0.1, 0.1, 0.0])
    depth = np.array([100.0, 100.0, 100.0])
    past = [(0.0, np.array([60.0, 60.0, 60.0]), np.array([5.0, 5.0, 5.0]),
             np.array([0.1, 0.0, 0.1])),
            (15.0, np.array([90.0, 90.0, 90.0]), np.array([1.0, 1.0, 1.0]),
             np.array([0.1, 0.1, 0.1]))]
    out = jumps.settled_rates(rate, g, depth, 20.0, past)
    # vertex 0: 15 is 5 cycles back (g T = 0.5): from 0, 20 back
    assert out[0] == pytest.approx((40.0 + (3.0 - 5.0) / 0.1) / 20.0)
    # vertex 1: untouched at 0, so none far enough back: its rate
    assert out[1] == 3.0 and out[2] == 3.0
    # never below zero (here it sank 1 in 20 cycles while its rate fell by 2)
    assert jumps.settled_rates(rate, g, np.full(3, 61.0), 20.0, past)[0] == 0.0


def test_a_counter_vertex_barely_worn_at_the_cycle_s_end_takes_a_held_vertex_s_relief():
    """Four counter vertices on a line. At the cycle's end one body vertex
    is over vertex 0 (its jump wears it as its rate says: factor 1) and one,
    wearing a millionth as much, over vertex 2 (its jump wears it 50 times
    its rate: a vertex just entering the contact). Vertex 3, worn in the
    cycle but under no body at its end, is nearest vertex 2; vertex 1 is
    worn by neither. Vertices 2 and 3 take vertex 0's relief (the gear
    pair's wheel took 2.89 from such a vertex on eleven teeth), not 50;
    vertex 1 keeps its rate."""
    from types import SimpleNamespace

    surface = SimpleNamespace(reference_vertices=np.array([[0.0, 0, 0], [1.0, 0, 0],
                                                           [2.0, 0, 0], [2.4, 0, 0]]))
    model = SimpleNamespace(surfaces=SimpleNamespace(per_vertex=[surface]))
    state = SimpleNamespace(bodies=[SimpleNamespace(hint=[np.array([0, 1])])])
    corners = np.array([[0, 1, 2], [2, 1, 0]])
    weights = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    m = SimpleNamespace(index=np.array([0, 1]), counter=np.array([1.0, 1.0]),
                        feet={0: (weights, corners)})
    rate = np.array([1.0, 1e-6])
    jump = 10.0
    wear = np.array([1.0, 50.0]) * rate * jump
    results = [(wear, None, np.zeros(2))]
    increment = np.array([1.0, 0.0, 1.0, 1.0])
    (factor, _), = jumps.counter_factors(model, state, [m], results, [rate], jump,
                                          [increment], 0.0)
    np.testing.assert_allclose(factor, [1.0, 1.0, 1.0, 1.0], rtol=1e-12)


def test_a_stiff_counter_vertex_jumps_at_the_rate_it_settles_to(monkeypatch):
    """A cylinder fretting on a worn flat, jumped: each measurement hands
    the jump each flat vertex's own stiffness (its wear's fall per unit of
    its own depth, summed in the wear kernel, positive wherever the
    cylinder wore it while pressing) and the rate it settles to; a vertex
    jumps by ``J (f r_c + phi (r - r_c))`` (f the factor carried from the
    bodies), its own rate where it has no settled rate."""
    seen = []
    factors = jumps.counter_factors

    def spy(model, state, measures, results, rates, jump, increments, t, stiffness=None,
            settled=None):
        out = factors(model, state, measures, results, rates, jump, increments, t,
                      stiffness, settled)
        plain = factors(model, state, measures, results, rates, jump, increments, t)
        seen.append((jump, increments[0].copy(), stiffness[0].copy(), settled[0].copy(),
                     out[0][0], plain[0][0]))
        return out

    monkeypatch.setattr(jumps, "counter_factors", spy)
    import meshwear
    from cases import EXAMPLES

    model = build_model(meshwear.load(EXAMPLES / "cylinder_on_worn_flat.toml",
                                      {"run.duration": 3000.0, "run.frames": 0,
                                       "wear.acceleration": "cycle_jump"}))
    run(model, initial_state(model))
    assert len(seen) >= 2
    moved = []
    for jump, rate, stiffness, settled, factor, plain in seen:
        worn = rate > 0.0
        assert (stiffness[worn] > 0.0).mean() > 0.9 and not stiffness[~worn].any()
        stiff = worn & (stiffness > 0.0)
        share = jumps.relaxed_share(jump * stiffness)
        settle = np.where(stiff, settled / np.where(worn, rate, 1.0), 1.0)
        expected = np.where(stiff, np.maximum(plain * settle + share * (1.0 - settle), 0.0),
                            plain)
        np.testing.assert_allclose(factor, expected, rtol=1e-12, atol=1e-15)
        off = stiff & (share < 0.85)
        if off.any():
            moved.append(float(np.abs(settle[off] - 1.0).max()))
    # the case has vertices that relax faster than a jump, off their settled rate
    assert moved and max(moved) > 1e-3


def test_every_history_row_of_a_jumped_run_has_both_parts_forces_balance(tmp_path):
    """Rows filled from a jump carry the resolved cycle's contact at the same
    phase for the worn disc too: in every row, resolved or filled, the pin's
    contact force and the disc's sum to zero (they alternated between the
    pin's reaction and zero where a filled row was not also a frame)."""
    import meshwear

    scene = meshwear.load(_jumped(tmp_path, 10), {"run.history": 97, "run.frames": 7})
    result = meshwear.run(scene)
    pin, disc = result.parts["pin"].history, result.parts["disc"].history
    assert len(pin["fz"]) == len(disc["fz"]) == 97
    filled = pin["resolved"] == 0
    assert filled.sum() > 30 and (disc["resolved"] == pin["resolved"]).all()
    assert np.all(pin["fz"][1:] > 0.5 * P)         # pressed all along (t = 0: not yet)
    for axis in ("fx", "fy", "fz"):
        assert np.abs(pin[axis] + disc[axis]).max() <= 1e-6 * P


def test_a_checkpoint_inside_a_jumped_run_resumes_it(tmp_path):
    """A jumped run saved after a jump and resumed ends where the whole run
    does: the counter-part's wear and the jump controller's memory of it
    are in the checkpoint."""
    model = build_model(load_scene(_jumped(tmp_path, 10)))
    saved = []

    def save(model, state):
        if state.jump.jumps == 1 and not saved:
            checkpoint.save(tmp_path / "c.npz", model, state, 0.0)
            saved.append(state.step)

    full = run(model, initial_state(model), checkpoint=save)
    assert saved and full.jump.jumps >= 2
    resumed = initial_state(model)
    checkpoint.load(tmp_path / "c.npz", model, resumed)
    assert resumed.step == saved[0] and resumed.jump.part_rate[0] is not None
    assert resumed.jump.part_past[0] and len(resumed.jump.part_past[0][-1]) == 4
    run(model, resumed)
    for got, want in ((resumed.parts[0].depth, full.parts[0].depth),
                      (resumed.bodies[0].wear_depth, full.bodies[0].wear_depth)):
        assert np.abs(got - want).max() <= 1e-9 * want.max()


def test_a_surface_frame_s_orientation_is_its_turn():
    """The history and summary give a worn surface's orientation as a
    quaternion of its frame's rotation (near half turns included)."""
    from meshwear.output.fields import _matrix_quaternion
    from meshwear.surfaces.base import axis_rotation, quaternion_matrix

    rng = np.random.default_rng(5)
    for k in range(200):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        angle = np.pi - rng.uniform(0.0, 1e-3) if k % 2 else rng.uniform(0.0, np.pi)
        rotation = axis_rotation(axis, angle)
        q = _matrix_quaternion(rotation)
        assert q[0] >= 0.0 and abs(np.linalg.norm(q) - 1.0) < 1e-12
        np.testing.assert_allclose(quaternion_matrix(q), rotation, atol=1e-12)


#: two-body fretting in gross slip: a cylinder (R = 6 mm, 4 mm long, axis
#: along y) pressed by 20 N on a flat that wears three times as fast, rubbed
#: by ±0.5 mm at 1 Hz for two cycles (quasi-static, Archard)
CYLINDER_ON_WORN_FLAT = """format = 1
[run]
mode = "quasi-static"
duration = 2.0
dt = 5e-3
frames = 0
history = 2
gravity = [0.0, 0.0, 0.0]
[contact]
stiffness_per_area = 1e13
friction = 0.5
[wear]
law = "archard"
coefficient = 1e-13
[[body]]
name = "cylinder"
shape = { type = "cylinder", radius = 0.006, height = 0.004, sections = 128 }
resolution = 1e-4
density = 7850.0
orientation = [0.70710678, 0.70710678, 0.0, 0.0]
position = [0.0, 0.0, 0.006]
force = [0.0, 0.0, -20.0]
motion = "guided"
[body.path]
oscillation = { axis = [1.0, 0.0, 0.0], amplitude = 5e-4, frequency = 1.0 }
free_axis = [0.0, 0.0, 1.0]
[[surface]]
name = "flat"
type = "mesh"
shape = { type = "box", size = [0.004, 0.006, 0.001] }
resolution = 1.5e-4
position = [0.0, 0.0, -0.0005]
wear = true
coefficient = 3e-13
"""


def test_two_body_fretting_wears_each_part_its_k_load_sliding(tmp_path, measured):
    """Gross slip: each part's worn volume is its k P s, s = 4 A per cycle
    (less the few tenths of a micron the contact sticks at each turning
    point); the flat wears only along the stroke."""
    path = tmp_path / "fretting.toml"
    path.write_text(CYLINDER_ON_WORN_FLAT)
    model = build_model(load_scene(path))
    state = run(model, initial_state(model))
    s = 4.0 * 5e-4 * 2.0
    cylinder, flat = state.bodies[0].wear_volume.sum(), state.parts[0].volume.sum()
    assert measured("cylinder on worn flat: cylinder volume", cylinder, 1e-13 * 20.0 * s,
                    5e-3) <= 5e-3
    assert measured("cylinder on worn flat: flat volume", flat, 3e-13 * 20.0 * s, 5e-3) <= 5e-3
    assert flat / cylinder == pytest.approx(3.0, rel=1e-12)
    worn = model.surfaces.per_vertex[0].reference_vertices[state.parts[0].depth > 0.0]
    # the stroke, the contact's half width (0.17 mm) and one mesh spacing
    assert np.abs(worn[:, 0]).max() <= 5e-4 + 1.7e-4 + 1.5e-4
    assert np.abs(worn[:, 0]).max() >= 5e-4


SHAFT_IN_WORN_BUSHING = """format = 1
[run]
mode = "quasi-static"
duration = 0.15708
dt = 5e-4
frames = 0
history = 2
gravity = [0.0, 0.0, 0.0]
[contact]
stiffness_per_area = 1e13
friction = 0.3
[wear]
law = "archard"
coefficient = 1e-13
[[body]]
name = "shaft"
shape = { type = "cylinder", radius = 0.005, height = 0.005, sections = 256 }
resolution = 2.5e-4
density = 7850.0
force = [-20.0, 0.0, 0.0]
motion = "guided"
[body.path]
free_axis = [1.0, 0.0, 0.0]
rotation = { axis = [0.0, 0.0, 1.0], rate = 10.0, center = [0.0, 0.0, 0.0] }
[[surface]]
name = "bushing"
type = "mesh"
mesh = "bushing.stl"
wear = true
coefficient = 3e-13
"""


def test_a_shaft_turning_in_a_worn_bushing(tmp_path, measured):
    """A shaft (R = 5 mm) turning at 10 rad/s in a bushing (bore 5.05 mm,
    1024 facets), pressed by 20 N across its axis: each part's worn volume is
    its k P s, s = omega R t (a quarter turn), and the bushing wears on the
    loaded side only."""
    import trimesh

    trimesh.creation.annulus(r_min=0.00505, r_max=0.008, height=0.003,
                             sections=1024).export(tmp_path / "bushing.stl")
    path = tmp_path / "shaft.toml"
    path.write_text(SHAFT_IN_WORN_BUSHING)
    model = build_model(load_scene(path))
    state = run(model, initial_state(model))
    s = 10.0 * 5e-3 * state.time
    shaft, bushing = state.bodies[0].wear_volume.sum(), state.parts[0].volume.sum()
    assert measured("shaft in worn bushing: shaft volume", shaft, 1e-13 * 20.0 * s, 5e-3) <= 5e-3
    assert measured("shaft in worn bushing: bushing volume", bushing, 3e-13 * 20.0 * s,
                    5e-3) <= 5e-3
    worn = model.surfaces.per_vertex[0].reference_vertices[state.parts[0].depth > 0.0]
    assert len(worn) > 10 and (worn[:, 0] < -0.004).all()
    # the shaft turned by omega t about its axis, its centre pressed onto the bore
    half = 0.5 * 10.0 * state.time
    assert state.bodies[0].pose[3:7] == pytest.approx([np.cos(half), 0.0, 0.0, np.sin(half)],
                                                      abs=1e-12)
    assert -5.2e-5 < state.bodies[0].pose[0] < -5.0e-5


@pytest.mark.parametrize("law, coefficient", [("energy_density", 3e-9), ("energy", 2e-3)])
def test_a_counter_s_own_energy_law_conserves(tmp_path, law, coefficient):
    """A worn surface's own law: ``energy_density`` wears the volume k E,
    ``energy`` the depth k E at each contact (its volume k E times the
    contact's area), E the friction work of the pairs (the body's)."""
    path = _scene(tmp_path, duration=0.1)
    path.write_text(path.read_text().replace(
        "coefficient = 2e-13", f'law = "{law}"\ncoefficient = {coefficient}'))
    model = build_model(load_scene(path))
    state = run(model, initial_state(model))
    part, body = state.parts[0], state.bodies[0]
    work = body.friction_work.sum()
    assert part.work.sum() == pytest.approx(work, rel=1e-12)
    if law == "energy_density":
        assert part.volume.sum() == pytest.approx(coefficient * work, rel=1e-9)
    else:
        # k E per contact times its area: between k E times the smallest and
        # the largest contact area of the pin's vertices
        areas = -model.bodies[0].area_vectors[body.normal_force[0] > 0.0, 2]
        assert coefficient * work * areas.min() <= part.volume.sum()
        assert part.volume.sum() <= coefficient * work * areas.max()
    # the pin keeps its own Archard wear: k_pin P s
    s = OMEGA * state.time * (R + A * A / (8.0 * R))
    assert body.wear_volume.sum() == pytest.approx(K_PIN * P * s, rel=5e-3)


DISC_OVER_A_WORN_PIN = """format = 1
[run]
mode = "quasi-static"
duration = 0.1
dt = 2e-3
frames = 0
history = 2
gravity = [0.0, 0.0, 0.0]
[contact]
stiffness_per_area = 1e13
friction = 0.4
[wear]
law = "archard"
coefficient = 2e-13
[[body]]
name = "disc"
shape = { type = "cylinder", radius = 0.008, height = 0.002, sections = 64 }
resolution = 3e-4
density = 7850.0
position = [0.0, 0.0, 0.001]
force = [0.0, 0.0, -10.0]
motion = "guided"
[body.path]
free_axis = [0.0, 0.0, 1.0]
rotation = { axis = [0.0, 0.0, 1.0], rate = 10.0, center = [0.0, 0.0, 0.0] }
[[surface]]
name = "pin"
type = "mesh"
shape = { type = "cylinder", radius = 0.001, height = 0.003, sections = 24 }
resolution = 1.5e-4
position = [0.005, 0.0, -0.0015]
wear = true
coefficient = 1e-13
"""


def test_a_turning_body_swept_over_a_counter_part_s_edge_rests_on_its_top(tmp_path):
    """The pin-on-disc the other way round: the disc is the turning body,
    pressed on a worn pin. Its vertices sweep in over the pin's edge at the
    depth of the elastic approach, nearer the side face at first; deep under
    it, they let go of it for the top face (nearest.RELEASE), so the disc
    stays in balance on the pin's top (it sank through the pin before). A
    vertex that came in this very step may still be nearer the side than
    RELEASE allows (the pin's side is exact, the vertex 0.3 um under the
    top and up to 16 times that inside the side): it pushes on the side
    for that step only (slipping at once, the disc turning over it), with
    a fraction of the load."""
    from meshwear.kernels.contact import SLIP

    path = tmp_path / "disc_over_pin.toml"
    path.write_text(DISC_OVER_A_WORN_PIN)
    model = build_model(load_scene(path))
    state = run(model, initial_state(model))
    s = state.bodies[0]
    touching = s.normal_force[0] > 0.0
    sliding = touching & (s.contact_state[0] == SLIP)
    assert sliding.sum() > 30
    on_top = s.vertex_planes[0][:, 1, 2] > 0.999
    assert (sliding & ~on_top).sum() <= 0.05 * sliding.sum()
    on_side = touching & (s.vertex_planes[0][:, 1, 2] < 0.999)
    assert s.normal_force[0][on_side].sum() < 0.01 * s.normal_force[0].sum()
    assert 0.000999 < s.pose[2] < 0.001
    # the wear-volume identity (docs/physics-tests.md: 1e-9): to 1e-11 here, the
    # vertices on the side face pressing with their area facing down
    assert state.parts[0].volume.sum() / s.wear_volume.sum() == pytest.approx(0.5, rel=1e-9)


def test_counter_noise_is_the_scatter_about_the_rates_drift():
    """A counter vertex's sampling noise is the scatter of its wear per
    cycle about a straight line through the measurements at the same
    window: a drift (a widening contact's rates fall cycle after cycle,
    however long the jumps between the measurements) is no noise; a vertex
    touched every other cycle, or whose rate scatters, is; fewer than three
    measurements, not yet measured."""
    from meshwear.longrun.wear import JumpState
    from meshwear.longrun.jump_errors import _counter_noise

    base = np.array([1.0e-9, 2.0e-9, 0.0])
    drifting = [(t, None, [base * (1.0 - 0.002 * t)]) for t in (10.0, 50.0, 51.0)]
    js = JumpState(history=drifting)
    np.testing.assert_allclose(_counter_noise(js, 0, base * (1.0 - 0.002 * 300.0), 300.0), 0.0,
                               atol=1e-22)
    # each vertex's own: alternating by +-10 % about its rate
    flicker = [(t, None, [base * (1.0 + 0.1 * (-1) ** t)]) for t in range(3)]
    sigma = _counter_noise(JumpState(history=flicker), 0, base * 0.9, 3.0)
    assert np.all((0.05 * base < sigma) & (sigma < 0.2 * base) | (base == 0.0))
    assert sigma[2] == 0.0
    assert _counter_noise(JumpState(history=drifting[:1]), 0, base, 60.0) is None


def test_a_counter_vertex_the_contact_reaches_settles_without_noise():
    """A counter vertex that a widening contact reaches has its wear per
    cycle rise and settle over tens of cycles, r = r_inf (1 - e^(-t/40));
    eight measurements a jump (17 cycles) apart bend over that span. Its
    noise is its scatter about that trend, each measurement against the
    line through its neighbours: 2 % of r_inf, where a straight line
    through all eight would count the bend as 10 % (measured on the
    fretting example: a flat vertex at the scar's corner given a noise 1.6
    times its rate, 40 times what eight resolved cycles in a row scatter,
    held the jumps). Independent scatter is still counted."""
    from meshwear.longrun.jump_errors import _fit, _local_scatter

    t = 4000.0 + 17.0 * np.arange(8)
    settling = 1e-9 * (1.0 - np.exp(-(t - 3990.0) / 40.0))
    local, line = _local_scatter(t, settling[:, None])[0], _fit(t, settling[:, None])[1][0]
    assert local < 0.025e-9 and line > 0.1e-9
    rng = np.random.default_rng(5)
    noisy = 1e-9 * (1.0 + 0.1 * rng.standard_normal((400, 1)))
    times = np.cumsum(rng.uniform(5.0, 40.0, 400))
    assert _local_scatter(times, noisy)[0] == pytest.approx(0.1e-9, rel=0.15)


def test_an_error_the_contact_has_left_over_the_tolerance_does_not_refuse_every_jump():
    """A counter vertex the scar's edge has left keeps its random error of
    depth (no resolved cycle relaxes it). Admitted against the depth a jump
    planned but did not quite reach, it can stand over the tolerance of
    today's depth; refusing jumps cannot mend it (the fretting example
    resolved 396 cycles in a row, held by one such vertex). It counts up to
    that tolerance: a jump that adds nothing to it passes, one that adds
    its noise is bounded, and a wearing vertex over it still refuses (the
    resolved cycles relax it)."""
    from meshwear.longrun.jump_errors import _noise_bound

    tol, deepest, fastest, relax = 0.01, 3.2e-6, 5e-10, 300.0
    over = (1.1 * tol * deepest) ** 2
    wearing = np.array([True, False])          # the contact has left the second
    quiet = np.zeros(2)
    assert _noise_bound(quiet, np.array([0.0, over]), wearing, tol, deepest, fastest, relax,
                        200) == 200
    noisy = np.array([0.0, 0.5 * fastest])
    bound = _noise_bound(noisy, np.array([0.0, over]), wearing, tol, deepest, fastest, relax, 200)
    # tol (D + J r) >= sqrt((tol D)^2 + (J sigma)^2): J <= 2 tol^2 D r / (sigma^2 - tol^2 r^2)
    most = 2 * tol * tol * deepest * fastest / ((0.5 * fastest) ** 2 - (tol * fastest) ** 2)
    assert 3 <= 0.8 * most - 1 <= bound <= most
    assert _noise_bound(quiet, np.array([(3 * tol * deepest) ** 2, 0.0]), wearing, tol, deepest,
                        fastest, relax, 200) == 0


def test_a_worn_surface_s_tree_is_fitted_anew_only_once_its_wear_passes_the_slack(tmp_path):
    """A worn counter mesh grows its tree's boxes by a slack: while no vertex
    has sunk farther than that since they were fitted (the gear pair's
    wheel over 10^5 revolutions), every box still holds its faces and the
    boxes are kept; past it, they are fitted anew (in place, O(F))."""
    from meshwear.surfaces.mesh import WEAR_SLACK

    model = build_model(load_scene(_scene(tmp_path)))
    state = initial_state(model)
    j = next(k for k, p in enumerate(state.parts) if p is not None)
    surface, part = model.surfaces.per_vertex[j], state.parts[j]
    surface.ensure_reach(5e-4)
    boxes, nodes, order = surface.tree
    slack = WEAR_SLACK * surface.reach
    assert surface.pad == slack and surface.search[0] == surface.reach
    fitted = boxes.copy()
    rng = np.random.default_rng(0)
    part.depth[:] = rng.uniform(0.0, slack, len(part.depth))        # unevenly, within it
    part.vertices[:] = surface.reference_vertices - part.depth[:, None] * surface.vertex_normals
    surface.rebin()
    assert np.array_equal(boxes, fitted)

    def held():
        for k in np.flatnonzero(nodes[:, 1] > 0):
            first, count = nodes[k]
            tri = part.vertices[surface.faces[order[first:first + count]]].reshape(-1, 3)
            if not ((tri >= boxes[k, 0:3]).all() and (tri <= boxes[k, 3:6]).all()):
                return False
        return True

    assert held()
    part.depth[:] *= 2.0                                               # past it
    part.vertices[:] = surface.reference_vertices - part.depth[:, None] * surface.vertex_normals
    assert not held(), "the case must move faces out of their boxes"
    surface.rebin()
    assert surface.tree[0] is boxes and held()
    assert np.array_equal(surface.fitted_depth, part.depth)


def test_a_worn_surface_attached_to_a_new_state_is_queried_there_at_every_reach(tmp_path):
    """A worn mesh queries the part state it is attached to, on the steps'
    reach and at the active-set refresh's farther one (a second
    run of the same model, as ``meshwear check``'s trials do)."""
    from meshwear.kernels.nearest import face_frames

    model = build_model(load_scene(_scene(tmp_path)))
    initial_state(model)
    j = next(k for k, p in enumerate(model.surfaces.per_vertex) if p.worn)
    surface = model.surfaces.per_vertex[j]
    surface.ensure_reach(2e-4)
    points = np.array([[0.004, 0.0, 0.0005], [0.0, 0.005, 0.0008], [-0.003, -0.003, 0.0012]])
    pose = np.zeros(13)
    pose[3] = 1.0

    def distances(reach):
        n = len(points)
        out, distance = np.zeros((n, 3, 3)), np.full(n, np.inf)
        surface.fill_within(reach, points, pose, np.arange(n), out, distance,
                            np.full(n, -1), 0.0)
        return distance

    near, far = distances(1e-4), distances(2e-3)       # the steps' reach, then farther
    assert np.isinf(near[1:]).all()
    np.testing.assert_allclose(far, points[:, 2], rtol=1e-9)
    state = initial_state(model)                        # a new run: a new part state
    part = state.parts[j]
    top = surface.reference_vertices[:, 2] > 0.0       # its top face sinks by 0.1 mm
    part.depth[top] = 1e-4
    part.vertices[:] = surface.reference_vertices - part.depth[:, None] * surface.vertex_normals
    part.frames[:] = face_frames(part.vertices, surface.faces)
    np.testing.assert_allclose(distances(2e-3), points[:, 2] + 1e-4, rtol=1e-9)
    points[:, 2] = 1e-4                               # and at the steps' reach
    np.testing.assert_allclose(distances(1e-4), 2e-4, rtol=1e-9)
