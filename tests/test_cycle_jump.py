"""Cycle jumping (docs/model.md, "Long durations"): the jump controller, its accuracy against
fully resolved runs, and the hard case a volume check cannot see."""

import dataclasses

import numpy as np
import pytest

import cases
from meshwear.model.build import build_model, initial_state
from meshwear.scene.reader import load_scene
from meshwear.step.simulate import run, run_scene
from meshwear.longrun.jump_choice import GROWTH, THETA, choose_jump
from meshwear.longrun.jump_errors import error_estimate
from meshwear.longrun.wear import _grows_from


# ---------------------------------------------------------------- controller

def test_first_measurement_never_jumps():
    rate = np.full(4, 1e-9)
    assert choose_jump(rate, None, 1.0, np.full(4, 1e-6), 0.01, 0, 100)[0] == 0


def test_stability_bound_keeps_each_jump_under_theta_of_the_penetration():
    rate = np.array([1e-9, 2e-9, 1e-12])          # wear per cycle (m)
    pen = np.array([1e-6, 1e-6, 1e-9])            # elastic penetration (m)
    jump, which = choose_jump(rate, rate.copy(), 1.0, pen, 0.01, 10_000, 10_000)
    assert which == "stability"
    # the fastest of the significant vertices sets it: 0.3 x 1e-6 / 2e-9 = 150
    assert jump == int(THETA * 1e-6 / 2e-9)


def test_accuracy_bound_follows_the_change_of_the_rate():
    previous = np.array([1.0e-9, 1.0e-9])
    rate = np.array([1.0e-9, 1.1e-9])             # 1e-10 per cycle over 1 cycle
    jump, which = choose_jump(rate, previous, 1.0, np.full(2, 1.0), 0.01, 10_000, 10_000)
    assert which == "accuracy"
    assert jump == int(2 * 0.01 * 1.1e-9 / 1e-10)   # 2 tol r_max / |rho| = 0.22 -> 0
    jump, _ = choose_jump(rate, previous, 100.0, np.full(2, 1.0), 0.01, 10_000, 10_000)
    assert jump == int(2 * 0.01 * 1.1e-9 / 1e-12)   # the same change over 100 cycles: 22


def test_growth_and_end_bounds():
    rate = np.full(3, 1e-9)
    steady = dict(previous=rate.copy(), gap=1.0, penetration_=np.full(3, 1.0), tolerance=0.01)
    assert choose_jump(rate, last_jump=7, limit=10_000, **steady) == (int(GROWTH * 7 + 1), "growth")
    assert choose_jump(rate, last_jump=7, limit=3, **steady) == (3, "end")


def test_jumps_grow_on_after_a_cycle_that_measured_a_transient():
    """A measurement refused by a bound the next resolved cycle mends lets
    the jumps after it grow from the last one taken: the budget's (the
    cycle relaxes the errors so far) and the volume's (right after a long
    jump the implicit step missed the measured volume at every length down
    to one cycle, and the cycle after it did not: on the fretting example
    growth started again from one cycle after every 255-cycle try, 1, 3, 7,
    ..., 127, 35 times). Any other refusal starts growth again from one."""
    assert _grows_from(0, "volume", 127) == 127
    assert _grows_from(0, "counter noise", 127) == 127
    assert _grows_from(0, "accuracy", 127) == 0
    assert _grows_from(0, "counter accuracy", 127) == 0
    assert _grows_from(9, "volume", 127) == 9


def test_implicit_jumps_have_no_stability_bound():
    rate = np.array([1e-9, 2e-9, 1e-12])
    pen = np.array([1e-6, 1e-6, 1e-9])
    # the explicit bound would cut the jump short (the stiff third vertex)
    jump, which = choose_jump(rate, rate.copy(), 1.0, pen, 0.01, 10_000, 10_000)
    assert which == "stability" and jump < 10_000
    # implicit: only growth and the run's end bound it
    jump, which = choose_jump(rate, rate.copy(), 1.0, pen, 0.01, 10_000, 10**9, stability=False)
    assert (jump, which) == (int(GROWTH * 10_000 + 1), "growth")
    jump, which = choose_jump(rate, rate.copy(), 1.0, pen, 0.01, 10_000, 10_000, stability=False)
    assert (jump, which) == (10_000, "end")


# ---------------------------------------------------------------- against resolved runs

def _scene(path, **wear):
    scene = load_scene(path)
    return dataclasses.replace(scene, wear=dataclasses.replace(scene.wear, **wear))


@pytest.fixture(scope="module")
def punch():
    """The tilted punch with a 0.5 mm cycle (k K s per cycle = 0.05), slid
    0.5 m (10 s), resolved and jumped: adaptive, and forced explicit jumps of
    50 cycles (J k K s = 2.5) and implicit ones of 500 (J k K s = 25)."""
    out = {}
    for duration in (1.0, 10.0):
        scene = _scene(cases.VALIDATION / "tilted_punch.toml", acceleration="cycle_jump",
                       period=0.01, tolerance=0.01)
        scene = dataclasses.replace(scene, run=dataclasses.replace(scene.run, duration=duration,
                                                                     frames=0, history=3))
        reference = build_model(dataclasses.replace(scene, wear=dataclasses.replace(
            scene.wear, acceleration="none")))
        out[f"ref {duration:g}"] = (reference, run(reference, initial_state(reference)))
        for label, forced, method in (("adaptive", None, "implicit"), ("forced", 50, "explicit"),
                                      ("implicit", 500, "implicit")):
            model = build_model(dataclasses.replace(scene, wear=dataclasses.replace(
                scene.wear, jump=method)))
            state = initial_state(model)
            run(model, state, forced_jump=forced)
            out[f"{label} {duration:g}"] = (model, state)
    return out


def _spread(model, state):
    body, s = model.bodies[0], state.bodies[0]
    face = body.reference_vertices[:, 2] < body.reference_vertices[:, 2].min() + 1e-12
    p = s.normal_force[0][face] / cases._contact_area(body, s.pose)[face]
    return p.max() - p.min()


def test_adaptive_jumps_follow_the_resolved_profile(punch, measured):
    (_, ref), (model, state) = punch["ref 10"], punch["adaptive 10"]
    error = np.abs(state.bodies[0].wear_depth - ref.bodies[0].wear_depth).max()
    relative = error / ref.bodies[0].wear_depth.max()
    measured("punch, jumped: profile error / max depth", relative, 0.0, 1e-2)
    assert relative < model.scene.wear.tolerance
    assert state.jump.resolved_steps < 0.3 * model.n_steps
    assert 0.0 < error_estimate(state) < model.scene.wear.tolerance


def _profile_error(state, ref):
    w, w_ref = state.bodies[0].wear_depth, ref.bodies[0].wear_depth
    return np.abs(w - w_ref).max() / w_ref.max()


def test_forced_large_explicit_jumps_oscillate_while_the_volume_looks_right(punch, measured):
    """Explicit jumps of J k K s = 2.5: each overshoots the pressure relief, so
    the tilt of the pressure flips and grows instead of decaying as
    exp(-k K s); the worn volume stays k P s because the load is always P."""
    (ref_model, ref), (model, state) = punch["ref 1"], punch["forced 1"]
    k, load = model.scene.wear.coefficient, 10.0
    distance = 0.05 * model.duration
    volume = state.bodies[0].wear_volume.sum()
    assert volume == pytest.approx(k * load * distance, rel=1e-6)          # the volume is fine
    initial = 1e13 * 5e-7 * 0.01       # K x tilt x face width
    assert _spread(ref_model, ref) < 0.01 * initial                         # resolved: decayed
    assert _spread(model, state) > 0.5 * initial                            # forced: it did not
    profile = _profile_error(state, ref)
    measured("explicit J=50 (want >5%): profile", profile, 0.0, 5e-2)
    assert profile > 0.05


def test_forced_implicit_jumps_ten_times_longer_stay_within_the_tolerance(punch, measured):
    """The hard case of the explicit jump, ten times harder: implicit jumps
    of J k K s = 25 relax each vertex's pressure by 1 / (1 + J k K s) instead
    of overshooting it, so the tilt decays, the profile stays within the
    tolerance of the resolved one and the volume is k P s."""
    (_, ref), (model, state) = punch["ref 10"], punch["implicit 10"]
    k, load = model.scene.wear.coefficient, 10.0
    assert 500 * k * 1e13 * 0.0005 == pytest.approx(25.0)
    assert state.jump.jumps == 2 and state.jump.last_jump >= 400
    volume = state.bodies[0].wear_volume.sum()
    assert volume == pytest.approx(k * load * 0.05 * model.duration, rel=1e-6)
    initial = 1e13 * 5e-7 * 0.01
    assert _spread(model, state) < 0.01 * initial
    profile = _profile_error(state, ref)
    measured("implicit J k K s = 25: profile error", profile, 0.0, 1e-2)
    assert profile < model.scene.wear.tolerance


def test_quasi_static_fretting_jumped_against_resolved(measured):
    scene = _scene(cases.VALIDATION / "sphere_pin.toml", coefficient=6e-14,
                   acceleration="cycle_jump", period=0.1, tolerance=0.01)
    scene = dataclasses.replace(scene, run=dataclasses.replace(scene.run, duration=60.0,
                                                                 frames=3, history=7))
    resolved = dataclasses.replace(scene, wear=dataclasses.replace(scene.wear,
                                                                   acceleration="none"))
    _, ref, ref_history = run_scene(resolved)
    model, state, history = run_scene(scene)
    w, w_ref = state.bodies[0].wear_depth, ref.bodies[0].wear_depth
    measured("ball, jumped: max depth vs resolved", w.max(), w_ref.max(), 1e-2)
    assert w.max() == pytest.approx(w_ref.max(), rel=1e-2)
    assert np.abs(w - w_ref).max() < 1e-2 * w_ref.max()
    assert state.bodies[0].wear_volume.sum() == pytest.approx(6e-14 * 10.0 * 60.0, rel=1e-3)
    # the history rows land at the times asked
    np.testing.assert_allclose(history.rows["ball"]["time"], ref_history.rows["ball"]["time"],
                               rtol=0, atol=1e-12)
    assert state.jump.resolved_steps * 3 < model.n_steps


def test_dynamic_guided_block_jumped_against_resolved(measured):
    """The reciprocating block with inertia: after each jump one cycle settles
    the contact, the next is measured."""
    scene = load_scene(cases.EXAMPLES / "reciprocating_block.toml")
    scene = dataclasses.replace(scene, run=dataclasses.replace(scene.run, duration=1.0, frames=0,
                                                                 history=3))
    _, ref, _ = run_scene(scene)
    jumped = dataclasses.replace(scene, wear=dataclasses.replace(scene.wear,
                                                                 acceleration="cycle_jump"))
    model, state, _ = run_scene(jumped)
    depth, depth_ref = state.bodies[0].wear_depth.max(), ref.bodies[0].wear_depth.max()
    measured("block (dynamic), jumped: max depth", depth, depth_ref, 1e-2)
    assert depth == pytest.approx(depth_ref, rel=1e-2)
    assert state.jump.jumps > 0 and state.jump.resolved_steps < 0.7 * model.n_steps


def test_outputs_inside_jumps_are_filled_from_them_and_marked(tmp_path, measured):
    """241 history rows and 13 frames over 600 cycles cost no resolved
    cycle each: the rows and frames inside jumps are filled (wear on the
    jump's extrapolation, pose and forces from the resolved cycle at the
    same phase) and marked resolved = 0; they agree with the fully resolved
    run at the same times."""
    import csv

    import pyvista

    from meshwear.output.recorder import RunRecorder, summary

    scene = _scene(cases.VALIDATION / "sphere_pin.toml", coefficient=6e-14,
                   acceleration="cycle_jump", period=0.1, tolerance=0.01)
    scene = dataclasses.replace(scene, run=dataclasses.replace(scene.run, duration=60.0,
                                                                 frames=13, history=241))
    resolved = dataclasses.replace(scene, wear=dataclasses.replace(scene.wear,
                                                                   acceleration="none"))
    _, _, ref = run_scene(resolved)
    model = build_model(scene)
    recorder = RunRecorder(tmp_path, model)
    state = run(model, initial_state(model), observers=[recorder])
    recorder.close(summary(model, state, 0.0))
    with open(tmp_path / "history.csv") as f:
        rows = list(csv.DictReader(f))
    marks = np.array([int(r["resolved"]) for r in rows])
    resolved_cycles = state.jump.resolved_steps / model.cycle_steps
    assert resolved_cycles < 0.5 * len(rows)          # outputs force no resolved cycle
    assert 0 < marks.sum() < len(rows) and marks[0] == 1 and marks[-1] == 1
    r = ref.rows["ball"]
    times = np.array([float(row["time"]) for row in rows])
    np.testing.assert_allclose(times, r["time"], rtol=0, atol=1e-9)
    volume = np.array([float(row["wear_volume"]) for row in rows])
    depth = np.array([float(row["max_wear_depth"]) for row in rows])
    filled_rows = marks == 0
    volume_error = np.abs(volume - r["wear_volume"])[filled_rows].max() / r["wear_volume"][-1]
    depth_error = np.abs(depth - r["max_wear_depth"])[filled_rows].max() / r["max_wear_depth"][-1]
    measured("filled rows: volume error / final", volume_error, 0.0, 1e-2)
    measured("filled rows: depth error / final", depth_error, 0.0, 1e-2)
    assert volume_error < 1e-2 and depth_error < 1e-2
    assert np.all(np.diff(volume) >= 0.0) and np.all(np.diff(depth) >= 0.0)
    # the pose follows the path at the row's time; the force carries the load
    x = np.array([float(row["x"]) for row in rows])
    np.testing.assert_allclose(x, r["origin"][:, 0], rtol=0, atol=1e-9)
    fz = np.array([float(row["fz"]) for row in rows])
    np.testing.assert_allclose(fz[1:], r["wrench"][1:, 2], rtol=1e-3)
    # every frame is written, at its time, and says whether it was resolved
    series = pyvista.get_reader(tmp_path / "ball.pvd")
    assert len(series.time_values) == 13
    frame_marks = []
    for k in range(13):
        series.set_active_time_point(k)
        frame = series.read()[0]
        frame_marks.append(int(frame.field_data["resolved"][0]))
        assert frame.point_data["wear_depth"].max() <= depth[-1] * (1 + 1e-12)
    assert 0 in frame_marks and frame_marks[0] == 1


#: a disc turning at 10 rad/s pressed (10 N, guided along z) on a ball off its
#: axis: each vertex of its track touches the ball for a few steps of the 157
#: of a turn, as a gear flank touches its mate. Soft contact (K = 1e10 N/m³,
#: 0.15 mm approach, 2 mm contact radius over 0.6 mm vertex spacing); the
#: track wears 0.5 % of the approach a turn, 30 turns.
DISC_ON_A_BALL = """format = 1
[run]
mode = "quasi-static"
duration = 18.84955592153876
dt = 4e-3
frames = 0
history = 2
gravity = [0.0, 0.0, 0.0]
[contact]
stiffness_per_area = 1e10
friction = 0.3
[wear]
law = "archard"
coefficient = 2e-10
acceleration = "cycle_jump"
tolerance = 0.01
[[body]]
name = "disc"
shape = { type = "cylinder", radius = 0.008, height = 0.002, sections = 48 }
resolution = 6e-4
density = 7850.0
position = [0.0, 0.0, 0.001]
force = [0.0, 0.0, -10.0]
motion = "guided"
[body.path]
free_axis = [0.0, 0.0, 1.0]
rotation = { axis = [0.0, 0.0, 1.0], rate = 10.0, center = [0.0, 0.0, 0.0] }
[[surface]]
name = "ball"
type = "sphere"
radius = 0.01
center = [0.005, 0.0, -0.01]
"""


def _resolved_and_jumped(path, text):
    """The model of scene ``text`` (written to ``path``) and its final
    states resolved at every cycle and jumped by the controller."""
    path.write_text(text)
    runs = {}
    for name, forced in (("resolved", 0), ("jumped", None)):
        model = build_model(load_scene(path))
        runs[name] = run(model, initial_state(model), forced_jump=forced)
    return model, runs


def test_a_track_touched_once_a_turn_jumps_as_resolved(tmp_path, measured):
    """Intermittent contact (docs/model.md, "Implicit jumps"): each track
    vertex's wear per unit of its penetration *while in contact*, its relief
    and the body's sinking as the whole track wears carry the jumps. Against
    the same run resolved at the same step (the sampling of each pass is
    locked to the turn), within the tolerance, in under half the cycles."""
    model, runs = _resolved_and_jumped(tmp_path / "disc_on_ball.toml", DISC_ON_A_BALL)
    w_ref = runs["resolved"].bodies[0].wear_depth
    w = runs["jumped"].bodies[0].wear_depth
    assert runs["resolved"].jump.resolved_steps == model.n_steps
    assert runs["jumped"].jump.resolved_steps < 0.5 * model.n_steps
    error = np.abs(w - w_ref).max() / w_ref.max()
    measured("disc touched once a turn, jumped: profile error", error, 0.0, 1e-2)
    assert error < model.scene.wear.tolerance
    assert 0.0 < error_estimate(runs["jumped"]) < model.scene.wear.tolerance
    # the whole track wears (not only the vertices on the ball when a jump starts)
    track = w_ref > 0.5 * w_ref.max()
    assert track.sum() > 100 and np.all(w[track] > 0.95 * w_ref[track])


#: a disc turning at 10 rad/s about z, pressed (10 N, guided along x) against
#: a wall across its axis, as a pinion is pressed into its wheel along the
#: line of centres: each rim vertex touches the wall for a few steps of the
#: 157 of a turn, at the end of a cycle facing any way round. Soft contact
#: (K = 1e10 N/m³, 0.2 mm approach), 30 turns: the ball's run, contact and
#: wear.
DISC_ON_A_WALL = DISC_ON_A_BALL[:DISC_ON_A_BALL.index("[[body]]")] + """[[body]]
name = "disc"
shape = { type = "cylinder", radius = 0.008, height = 0.002, sections = 96 }
density = 7850.0
position = [0.0, 0.0, 0.0]
force = [10.0, 0.0, 0.0]
motion = "guided"
[body.path]
free_axis = [1.0, 0.0, 0.0]
rotation = { axis = [0.0, 0.0, 1.0], rate = 10.0, center = [0.0, 0.0, 0.0] }
[[surface]]
name = "wall"
type = "plane"
point = [0.008, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
"""


def test_a_rim_pressed_across_its_turning_axis_jumps_as_resolved(tmp_path, measured):
    """A vertex touched in the cycle but not at its end is relieved by the
    body's move along its free axis as much as that axis lies along the
    force that pressed it (docs/model.md, "Implicit jumps"), not along the
    way it faces when the cycle ends: half a turn from the wall, a rim
    vertex faces away from it, and taken so its jumps wore the rim 9 % of
    its depth unevenly and 5 % off the resolved run. Within the tolerance
    of the run resolved at the same step, the rim as even as there."""
    model, runs = _resolved_and_jumped(tmp_path / "disc_on_wall.toml", DISC_ON_A_WALL)
    w_ref = runs["resolved"].bodies[0].wear_depth
    w = runs["jumped"].bodies[0].wear_depth
    assert runs["jumped"].jump.resolved_steps < 0.5 * model.n_steps
    rim = w_ref > 0.5 * w_ref.max()
    assert rim.sum() == 192                     # both rims, all round
    error = np.abs(w - w_ref).max() / w_ref.max()
    measured("disc pressed across its turning axis, jumped: profile error", error, 0.0, 1e-2)
    assert error < model.scene.wear.tolerance
    spread = np.ptp(w[rim]) / w_ref.max()
    assert spread < np.ptp(w_ref[rim]) / w_ref.max() + model.scene.wear.tolerance


def test_an_implicit_jump_s_errors_hold_its_drift_and_relax_as_the_contact_does():
    """Implicit jumps hold each vertex's wear per unit penetration alpha at
    its measured value, so its drift rho_i pbar_i makes the jump wrong by
    rho_i pbar_i J^2 / 2, bounded by rho_i pbar_i J^2 / 2 <= tol J r_max
    (each jump's, as step doubling is bounded), or, once worn in, by the
    drift errors of the jumps so far, as the contact has relaxed them, within
    tol (deepest + J r_max). The jump adds its drift's and its step
    doubling's errors to each vertex's (without the drift's the gear pair's
    10^5 revolutions estimated half the error measured against a tighter
    run), the errors of the jumps before decay by e^(-alpha J) (the contact
    relaxes them: a vertex worn too little carries more and wears more),
    and their stiffness-weighted mean, the drift's signed, which the relief
    does not take off, is kept apart (docs/model.md, "Long durations")."""
    from meshwear.longrun.jumps import BodyJump, implicit
    from meshwear.longrun.wear import JumpState
    from meshwear.longrun.jump_choice import _choose_implicit

    k, p = 3, 1e-6
    alpha = np.full(k, 1e-3)                        # wear per cycle per unit penetration
    m = BodyJump(index=np.arange(k), alpha=alpha.copy(), depth=np.full(k, p),
                 mean=np.full(k, p), now=np.full(k, p), normal=np.tile([0.0, 0.0, 1.0], (k, 1)),
                 stiffness=np.ones(k), member=np.ones(k, bool), touched=np.zeros(k, bool),
                 beta=np.zeros(k), load=0.0, guided=False)
    previous = alpha.copy()
    previous[0] *= 1.001                            # vertex 0's fell by 0.1 % over 10 cycles
    before = np.array([0.0, 0.0, 2e-12])            # vertex 2's error of the jumps before
    js = JumpState(alpha=[previous], gap=10.0, history=[(0.0, [previous], [])],
                   error=[before.copy()], drift=[np.zeros(k)], noise_var=[np.zeros(k)],
                   bias=[np.zeros(2)])
    rate = alpha * p                                # 1e-9 m per cycle
    jump, which, results = _choose_implicit([m], [rate], js, 10**6, 100, 0.01, t=10.0)
    assert (jump, which) == (100, "growth")         # the drift allows 200 here
    _, _, doubling = implicit(m, jump)
    drift = 0.5 * (1e-3 * 1e-3 / 10.0) * p * jump ** 2
    np.testing.assert_allclose(results[0][2], doubling, rtol=1e-12)
    relaxed = before * np.exp(-1e-3 * jump)
    np.testing.assert_allclose(js.error[0], doubling + relaxed, rtol=1e-9)
    np.testing.assert_allclose(js.drift[0], [drift, 0.0, 0.0], rtol=1e-9)
    np.testing.assert_allclose(js.bias[0], [-drift / 3.0, doubling.mean()], rtol=1e-9, atol=1e-30)
    # the drift bound itself: twice that drift holds the jump under the growth
    js = JumpState(alpha=[previous], gap=10.0, history=[(0.0, [2.0 * previous - alpha], [])],
                   error=[np.zeros(k)], drift=[np.zeros(k)], noise_var=[np.zeros(k)],
                   bias=[np.zeros(2)])
    jump, which, _ = _choose_implicit([m], [rate], js, 10**6, 200, 0.01, t=10.0)
    assert (jump, which) == (100, "drift")          # 2 tol r / (rho pbar), each jump's
    # worn in (deepest 1e-6 m), the relaxed errors allow longer jumps
    js = JumpState(alpha=[previous], gap=10.0, history=[(0.0, [2.0 * previous - alpha], [])],
                   error=[np.zeros(k)], drift=[np.zeros(k)], noise_var=[np.zeros(k)],
                   bias=[np.zeros(2)])
    jump, which, _ = _choose_implicit([m], [rate], js, 10**6, 200, 0.01, t=10.0,
                                      deepest=[1e-6])
    assert jump == 200


def test_jumps_of_a_loaded_pad_keep_archard_s_volume_when_both_parts_wear(monkeypatch, measured):
    """In gross slip Archard's law wears k P s per cycle whatever the
    contact's shape. On a worn flat the pad's wear per unit penetration
    spreads (small at the scar's edges, in contact for part of the stroke),
    and the implicit step, holding it fixed, moves the load to the vertices
    that wear least per unit of it: forced jumps of 40 cycles kept 0.87 k P s.
    A load-carrying body's jumps keep the volume its measurements give
    (docs/model.md, "Long durations", bound "volume"); the counter-part
    wears the same volume."""
    from pathlib import Path

    from meshwear.longrun import wear

    path = Path(__file__).resolve().parents[1] / "examples" / "cylinder_on_flat_fretting.toml"
    settings = [("run.duration", 200.0), ("body[0].resolution", 4e-5),
                ("surface[0].resolution", 4e-5), ("run.frames", 0), ("run.history", 2)]
    expected = 2.75e-14 * 18.5 * 4 * 2.5e-5 * 200              # k P 4A N

    def volumes(keep):
        model = build_model(load_scene(path, settings))
        state = initial_state(model)
        with monkeypatch.context() as patch:
            if not keep:
                patch.setattr(wear, "_keep_volume", lambda *args, **kw: args[5])
            run(model, state, forced_jump=40)
        return (float(state.bodies[0].wear_volume.sum()),
                float(next(p for p in state.parts if p is not None).volume.sum()))

    pad, flat = volumes(keep=True)
    measured("pad on worn flat, jumps of 40: volume / k P s", pad, expected, 1e-3)
    assert pad == pytest.approx(expected, rel=1e-3)
    assert flat == pytest.approx(pad, rel=1e-9)
    alone, _ = volumes(keep=False)
    measured("same, the implicit step's volume / k P s", alone, expected, 0.2)
    assert alone < 0.9 * expected                  # what the keeping mends


def test_the_implicit_step_kernel_matches_its_numpy_twin(monkeypatch):
    """meshwear.kernels.balance.implicit_step against its numpy twin, to the
    last bit, on the measurements of jumped runs (a cylinder and its worn
    flat: guided, the counter's gamma; a pin on a worn disc), at jumps of
    1 to 10^4 cycles, and without a free axis or members."""
    import reference
    from meshwear.longrun import jumps
    from meshwear.kernels.balance import implicit_step

    seen = []
    measure = jumps.measure

    def spy(*args, **kwargs):
        seen.append(measure(*args, **kwargs))
        return seen[-1]

    monkeypatch.setattr(jumps, "measure", spy)
    import meshwear

    for name, duration in (("cylinder_on_worn_flat.toml", 300.0), ("pin_on_worn_disc.toml", 5.0)):
        model = build_model(meshwear.load(cases.EXAMPLES / name,
                                          {"run.duration": duration, "run.frames": 0,
                                           "wear.acceleration": "cycle_jump"}))
        run(model, initial_state(model))
    assert len(seen) >= 4 and any(m.guided and m.gamma is not None for m in seen)
    compared = 0
    for m in seen:
        gamma = m.gamma if m.gamma is not None else np.zeros(len(m.alpha))
        for jump in (1.0, 7.5, 100.0, 1e4):
            for guided in (m.guided, False):
                for member in (m.member, np.zeros_like(m.member)):
                    args = (jump, m.alpha, gamma, member, m.touched, m.beta, m.stiffness,
                            m.depth, m.now, float(m.load), guided)
                    got, want = implicit_step(*args), reference.implicit_step(*args)
                    assert got[1] == want[1]
                    for a, b in ((got[0], want[0]), (got[2], want[2])):
                        assert np.array_equal(a, b)
                    compared += 1
    assert compared >= 64


def test_a_jump_keeps_its_volume_along_the_change_of_every_alpha_alike():
    """A load-carrying body's jump reaches its measured volume by taking
    every vertex's wear per unit penetration (1 + lambda) times larger with
    the balance held (docs/model.md, "Long durations", bound "volume"):
    _volume_direction's first-order change of each vertex's wear and of the
    move is the backward-Euler step's own (central differences of
    single_step over alpha). Where J alpha is small it is each vertex's wear
    scaled alike; where it is large, a sink of the body: every vertex
    pressed along the axis wears the same more, keeping the shape the jump
    wore (scaling every vertex's wear there left the block-on-ring scar's
    edge 4.2 % of its depth off the ring's arc)."""
    from meshwear.longrun.jumps import BodyJump, single_step
    from meshwear.longrun.jump_volume import _volume_direction

    p = np.array([1.0, 1.2, 0.8, 1.1]) * 1e-6
    c = np.full(4, 1e6)

    def measure(alpha):
        return BodyJump(index=np.arange(4), alpha=alpha, depth=p.copy(), mean=p.copy(),
                        now=p.copy(), normal=np.tile([0.0, 0.0, 1.0], (4, 1)), stiffness=c,
                        member=np.ones(4, bool), touched=np.zeros(4, bool), beta=np.ones(4),
                        load=float(c @ p), guided=True, gamma=np.array([0.0, 5e-4, 0.0, 0.0]))

    alpha = np.array([1e-3, 2e-3, 5e-4, 1e-3])
    eps = 1e-6
    for jump in (10.0, 1e5):
        wear, z = single_step(measure(alpha), jump)
        grow, sink = _volume_direction(measure(alpha), wear, jump)
        up, z_up = single_step(measure(alpha * (1.0 + eps)), jump)
        down, z_down = single_step(measure(alpha * (1.0 - eps)), jump)
        np.testing.assert_allclose(grow, (up - down) / (2.0 * eps), rtol=1e-5)
        assert sink == pytest.approx((z_up - z_down) / (2.0 * eps), rel=1e-5)
        if jump == 10.0:                 # J alpha <= 0.02: a scale
            np.testing.assert_allclose(grow, wear, rtol=0.03)
        else:                            # J alpha >= 50: a sink, alike on every vertex
            own = grow[[0, 2, 3]]        # (vertex 1's counter-part takes a share)
            assert np.ptp(own) < 1e-3 * own.mean()
            assert -sink == pytest.approx(own.mean(), rel=0.02)


def test_a_vertex_touched_but_not_at_the_cycle_s_end_wears_at_most_twice_its_measured_rate():
    """A guided body moving along its axis over a jump presses the vertices
    in the balance deeper; one touched in the cycle but not at its end may
    touch where a path of contact ends and is not pressed so (a gear's
    face-end tip corners, touched at nanometres in one revolution of several,
    wore 0.19 µm at tolerance 0.01 against 0.04 µm at 0.003 when the jump
    pressed them by the pinion's whole approach): over a jump its wear per
    cycle at most doubles (TOUCHED_GROWTH), its relief still slowing it
    (docs/model.md, "Long durations")."""
    from meshwear.longrun.jumps import TOUCHED_GROWTH, BodyJump, _step, implicit

    k, p, load = 3, 1e-6, 2.0
    # vertices 0 and 1 carry the load along -z; vertex 2 touched the mate in
    # the cycle at 4 nm, along the same normal, but is out of contact now
    m = BodyJump(index=np.arange(k), alpha=np.full(k, 1e-4), depth=np.array([p, p, -1e-7]),
                 mean=np.array([p, p, 4e-9]), now=np.array([p, p, 4e-9]),
                 normal=np.tile([0.0, 0.0, 1.0], (k, 1)), stiffness=np.full(k, 1e6),
                 member=np.array([True, True, False]), touched=np.array([False, False, True]),
                 beta=np.ones(k), load=load, guided=True)
    m.rest = _step(m, 0.0, m.depth, m.now)[1]
    jump = 10_000
    wear, z, _ = implicit(m, jump)
    # the members wear and the body follows them (-beta z: a micrometre
    # more penetration), which would press the touched vertex by as much
    assert wear[0] > 0.5 * jump * 1e-4 * p / (1 + jump * 1e-4) and z < -0.5 * p
    # the touched vertex: twice its measured rate times the jump, not the
    # approach's hundred times more
    cap = TOUCHED_GROWTH * jump * 1e-4 * 4e-9
    assert wear[2] == pytest.approx(cap, rel=1e-12)
    # pressed across the axis (no approach) and relieved by its counter
    # wearing under it as fast as itself, it wears less than its rate
    m.beta[2], m.gamma = 0.0, np.array([0.0, 0.0, 1e-4])
    relieved, _, _ = implicit(m, jump)
    assert 0.0 < relieved[2] < 0.6 * jump * 1e-4 * 4e-9


def test_a_touched_vertex_takes_its_counter_s_wear_where_it_pressed():
    """A vertex touched in the cycle but not at its end takes, as its
    counter's relief, the counter's wear at the points it pressed (the
    cycle's pair log, weighted by its force there), not under its foot at
    the cycle's end: a gear's teeth in mesh then took the mate's wear where
    they had turned to, the others none, and wore 2-3 % of the deepest less
    (docs/model.md, "Worn counter-surfaces")."""
    from types import SimpleNamespace

    from meshwear.longrun.jumps import BodyJump, counter_relief, pair_log, start_log

    # vertex 0 in contact at the cycle's end, vertex 1 touched in the cycle
    # only; neither over a face of the counter at the cycle's end (their feet
    # give no relief), both in the log
    m = BodyJump(index=np.array([0, 1]), alpha=np.full(2, 1e-4), depth=np.array([1e-6, -1e-6]),
                 mean=np.array([1e-6, 2e-7]), now=np.array([1e-6, 2e-7]),
                 normal=np.tile([0.0, 0.0, 1.0], (2, 1)), stiffness=np.ones(2),
                 member=np.array([True, False]), touched=np.array([False, True]),
                 beta=np.zeros(2), load=0.0, guided=False)
    increment = np.array([1e-10, 1e-10, 1e-10, 4e-10, 8e-10])     # counter wear in the cycle
    s = SimpleNamespace(log_index=np.zeros((0, 3), np.int64), log_value=np.zeros(0),
                        log_count=np.zeros(2, np.int64), log_from=-1, active=np.arange(2),
                        normal_force=np.ones((1, 2)), hint=[np.array([-1, -1])])
    start_log(s, 40, 40)
    assert len(s.log_index) >= 240 and s.log_count[1] == 1
    # the kernel's rows: vertex 0 pressed counter vertices 0-2; vertex 1
    # pressed counter vertex 3 with 1 N and vertex 4 with 3 N
    rows = [(0, 0, 0, 1.0), (0, 0, 1, 1.0), (0, 0, 2, 1.0), (0, 1, 3, 1.0), (0, 1, 4, 3.0)]
    for r, (surface, vertex, corner, force) in enumerate(rows):
        s.log_index[r], s.log_value[r] = (surface, vertex, corner), force
    s.log_count[0] = len(rows)
    assert pair_log(s, 0) is None                   # not the cycle it was started at
    s.log_count[1] = 1
    log = pair_log(s, 40)
    assert len(log[0]) == len(rows) and s.log_count[1] == 0     # read, and stopped
    model = SimpleNamespace(surfaces=SimpleNamespace(per_vertex=[SimpleNamespace()]))
    counter_relief(model, s, m, [increment], 1.0, log)
    # the touched vertex: (1 * 4 + 3 * 8) / 4 = 7e-10 per cycle, over its mean
    assert m.counter[1] == pytest.approx(7e-10, rel=1e-12)
    assert m.gamma[1] == pytest.approx(7e-10 / 2e-7, rel=1e-12)
    # the vertex in contact at the end: under its foot (none here), not the log
    assert m.counter[0] == 0.0
    # a full log (the rows overflowed): the feet for every vertex
    s.log_count[:] = len(s.log_index) + 1, 1
    assert pair_log(s, 40) is None
    counter_relief(model, s, m, [increment], 1.0, None)
    assert m.counter[1] == 0.0
