"""Quasi-static rotation under a torque (docs/model.md, "Quasi-static mode"):
a guided body turns about its turn's axis to where its contacts' normal
forces carry the applied torque.

Closed forms: a box held on a plane at lever r under a torque T (the
normal force T / r, up to the spread of the levers over the contact face,
derived below), and a two-footed body whose feet share the torque as
their stiffness times their lever squared. The kernel against a numpy twin
of the balance; the compiled loop against the Python reference; and the
scene's refusals.
"""

import numpy as np
import pytest

from meshwear.kernels import loop
from meshwear.kernels.contact import FACING, all_vertices, rotation_entries
from meshwear.kernels.rigid import TURNING
from meshwear.kernels.turn_balance import balance_angle
from meshwear.model.build import build_model, initial_state
from meshwear.scene.reader import load_scene
from meshwear.scene.checks import SceneError
from meshwear.step.simulate import run, run_scene

from cases import EXAMPLES

#: N/m³, the Winkler foundation
STIFFNESS = 1e12

HEADER = """format = 1
[run]
mode = "{mode}"
duration = {duration}
dt = 0.01
frames = 0
history = {history}
gravity = [0.0, 0.0, 0.0]
[contact]
stiffness_per_area = {stiffness}
friction = 0.3
[wear]
law = "archard"
coefficient = 0.0
"""

#: a box of side h whose bottom face rests on the plane y = 0, its centre
#: at x = r, held (rate 0) about the z axis through the origin
LEVER = """
[[body]]
name = "arm"
shape = {{ type = "box", size = [{h}, {h}, {h}] }}
position = [{r}, {half}, 0.0]
motion = "{motion}"
[body.path]
rotation = {{ axis = {axis}, rate = {rate}, center = [0.0, 0.0, 0.0], torque = {torque} }}
{extra}
[[surface]]
name = "floor"
type = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, {side}, 0.0]
size = 1.0
"""


def lever_scene(tmp_path, h=1e-3, r=0.05, torque=-1.0, rate=0.0, motion="guided", extra="",
                side=1.0, mode="quasi-static", duration=0.05, history=6, axis="[0.0, 0.0, 1.0]",
                lift=0.0):
    text = HEADER.format(mode=mode, duration=duration, history=history,
                         stiffness=STIFFNESS) + LEVER.format(
        h=h, r=r, half=0.5 * h + lift, torque=torque, rate=rate, motion=motion, extra=extra,
        side=side, axis=axis)
    path = tmp_path / "lever.toml"
    path.write_text(text)
    return path


def axial_torque(wrench, pose):
    """Contact torque about the z axis through the origin (N·m): the
    wrench's torque about the centre of mass moved there."""
    force, torque = wrench[0:3], wrench[3:6]
    return torque[2] + pose[0] * force[1] - pose[1] * force[0]


def test_a_lever_arm_carries_the_torque_with_a_normal_force_t_over_r(tmp_path):
    """A box of side h touching the plane y = 0 with its bottom face
    centred at x = r, turned about z by the torque T < 0 (pressing it in).
    Turning by phi sinks the vertex at x by -phi x (beta = n . (z x r) =
    x), so its force is c x |phi| and the balance is |T| = |phi| sum c x^2;
    the normal force is F = |phi| sum c x = |T| / (r + s^2 / r), s^2 the
    stiffness-weighted variance of the levers about r. The box's bottom
    face has its corners at r -+ h/2 with equal stiffness each side (a
    tributary half of the face each), so s = h / 2:
    F = |T| / (r + h^2 / (4 r)), T / r to within h^2 / (4 r^2) = 1e-4."""
    h, r, torque = 1e-3, 0.05, -1.0
    model, state, history = run_scene(load_scene(lever_scene(tmp_path, h, r, torque)))
    rows = history.rows["arm"]
    normal = rows["wrench"][:, 1]
    # (to O(|phi| h / r) = 2e-5: turned by phi = -4e-4, the side faces'
    # thirds of the corners' area vectors tilt into the plane's normal, on
    # one side more than on the other, and move the corners' stiffness by
    # about |phi| of it)
    np.testing.assert_allclose(normal, -torque / (r + h * h / (4 * r)), rtol=2e-5)
    assert normal[0] == pytest.approx(-torque / r, rel=1.1 * h * h / (4 * r * r))
    # the contact torque about the axis balances the applied one, every row
    for wrench, pose in zip(rows["wrench"], rows["pose"]):
        assert axial_torque(wrench, pose) == pytest.approx(-torque, rel=1e-9)
    # it turned clockwise, into the plane, by the penetration over the lever
    angle = model.bodies[0].motion.settled
    assert angle == pytest.approx(-(normal[0] / (STIFFNESS * h * h)) / r, rel=0.01)


def test_two_feet_share_the_torque_as_stiffness_times_lever_squared(tmp_path):
    """Two boxes of one body, at levers r1 and r2 on the plane: the feet
    sink by |phi| r_k, so they carry F_k = K A |phi| r_k and
    |T| = K A |phi| (r1^2 + r2^2) (their face spreads aside, as above):
    F1 / F2 = r1 / r2 and F1 r1 + F2 r2 = |T|, the load shared as two
    tooth pairs in mesh share theirs."""
    import trimesh

    h, r1, r2, torque = 1e-3, 0.02, 0.05, -1.0
    boxes = [trimesh.creation.box([h, h, h]) for _ in range(2)]
    boxes[0].apply_translation([r1, 0.5 * h, 0.0])
    boxes[1].apply_translation([r2, 0.5 * h, 0.0])
    feet = trimesh.util.concatenate(boxes)
    feet.export(tmp_path / "feet.stl")
    text = (HEADER.format(mode="quasi-static", duration=0.03, history=4, stiffness=STIFFNESS)
            + LEVER.format(h=h, r=0.0, half=0.0, torque=torque, rate=0.0, motion="guided",
                           extra="", side=1.0, axis="[0.0, 0.0, 1.0]")).replace(
        'shape = { type = "box", size = [0.001, 0.001, 0.001] }', 'mesh = "feet.stl"')
    path = tmp_path / "feet.toml"
    path.write_text(text)
    model, state, history = run_scene(load_scene(path))
    s = state.bodies[0]
    x = s.vertices @ rotation_entries_matrix(s.pose).T + s.pose[0:3]
    force = s.normal_force[0]
    near, far = force[x[:, 0] < 0.5 * (r1 + r2)].sum(), force[x[:, 0] > 0.5 * (r1 + r2)].sum()
    spread = h * h / 4
    # each foot's force K A |phi| r_k, its torque K A |phi| (r_k^2 + s^2),
    # to O(|phi| h / r1) = 2e-5 (|phi| = 3.4e-4: the tilt of the feet's
    # side faces into the plane's normal, as in the lever arm's test)
    assert near / far == pytest.approx(r1 / r2, rel=2e-5)
    assert near * (r1 + spread / r1) + far * (r2 + spread / r2) == pytest.approx(-torque,
                                                                                 rel=2e-5)
    # and the contact torque about the axis is the applied one, to round-off
    assert axial_torque(s.wrench, s.pose) == pytest.approx(-torque, rel=1e-9)


def rotation_entries_matrix(pose):
    return np.array(rotation_entries(pose[3:7])).reshape(3, 3)


def numpy_balance_angle(vertices, pose, axis, center, plane_point, normal, area, law, load):
    """The numpy twin of :func:`balance_angle` for one plane: the linearised
    contact torque g(phi) = sum c beta max(0, -Delta - phi beta), solved by
    bisection on its monotone graph."""
    rotation = rotation_entries_matrix(pose)
    x = vertices @ rotation.T + pose[0:3]
    projected = -(area[:, 0:3] @ rotation.T) @ normal
    c = np.where(projected > FACING * area[:, 3], law[5] + law[6] * projected, 0.0)
    beta = np.cross(axis, x - center) @ normal
    delta = (x - plane_point) @ normal

    def g(phi):
        return float(np.sum(c * beta * np.maximum(0.0, -delta - phi * beta)))

    lo, hi = -1.0, 1.0
    while g(lo) < load:
        lo *= 2.0
    while g(hi) > load:
        hi *= 2.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if g(mid) > load else (lo, mid)
    return 0.5 * (lo + hi)


def test_the_balance_kernel_agrees_with_its_numpy_twin(tmp_path):
    """A sphere pressed on a tilted plane, off the axis: a curved patch,
    levers of both signs of varying size; the kernel's angle is the
    twin's."""
    rng = np.random.default_rng(4)
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=3, radius=0.01)
    vertices = np.ascontiguousarray(sphere.vertices)
    from meshwear import geometry

    area = geometry.area_vectors(vertices, np.asarray(sphere.faces))
    law = np.zeros(13)
    law[6] = STIFFNESS
    normal = np.array([0.3, 1.0, 0.1])
    normal /= np.linalg.norm(normal)
    for trial in range(5):
        pose = np.zeros(13)
        pose[3] = 1.0
        pose[0:3] = [0.04, 0.0, 0.0] + rng.normal(0, 1e-3, 3)
        axis = np.array([0.0, 0.1 * rng.normal(), 1.0])
        axis /= np.linalg.norm(axis)
        center = rng.normal(0, 1e-3, 3)
        plane_point = pose[0:3] - (0.01 - 1e-5) * normal      # 10 µm into it
        planes = np.zeros((1, 4, 3))
        planes[0, 0], planes[0, 1] = plane_point, normal
        load = (1.0 + trial) * 0.05
        active = all_vertices(len(vertices))
        angle = balance_angle(vertices, pose, axis, center, planes, np.zeros((0, len(vertices),
                              3, 3)), active, area, law, load, np.zeros((2, len(vertices))))
        twin = numpy_balance_angle(vertices, pose, axis, center, plane_point, normal, area, law,
                                   load)
        assert angle == pytest.approx(twin, rel=1e-9, abs=1e-15)


def test_the_compiled_loop_matches_the_python_reference(tmp_path):
    """The spur pair of examples/gear_pair_torque_quasi_static.toml (on a
    coarser mesh of its gear), the pinion turning at 100 rad/s in balance
    under its torque, 40 steps, both wearing: the compiled loop and the
    Python reference give the same numbers, bit for bit."""
    from test_example_outputs import _coarse_gear

    gear = str(_coarse_gear(tmp_path))
    scene = load_scene(EXAMPLES / "gear_pair_torque_quasi_static.toml").set({
        "body[0].mesh": gear, "surface[0].mesh": gear, "run.duration": 40 * 5e-5,
        "run.frames": 0, "run.history": 5, "wear.acceleration": "none",
        "wear.coefficient": 1e-12})
    states, settled = [], []
    for compiled in (True, False):
        model = build_model(scene)
        states.append(run(model, initial_state(model), compiled=compiled))
        settled.append(model.bodies[0].motion.settled)
    a, b = states[0].bodies[0], states[1].bodies[0]
    assert a.normal_force.sum() > 0.0 and a.wear_depth.max() > 0.0
    np.testing.assert_array_equal(a.pose, b.pose)
    np.testing.assert_array_equal(a.normal_force, b.normal_force)
    np.testing.assert_array_equal(a.wear_depth, b.wear_depth)
    assert settled[0] == settled[1] != 0.0


def test_only_a_scene_with_a_torque_compiles_the_torque_balance(tmp_path):
    """loop_build: the torque balance is its own build constant; a scene
    without a torque does not name it (the other tests of builds keep
    theirs)."""
    model = build_model(load_scene(lever_scene(tmp_path)))
    assert model.bodies[0].motion.kind == TURNING
    build = loop.scene_build(model)
    assert build["turns"] is True
    assert loop.loop_for(model) is loop.loop_build(**build)
    assert loop.loop_for(model) is not loop.loop_build(**{**build, "turns": False})
    text = load_scene(loop_scene_without(tmp_path))
    assert "turns" not in loop.scene_build(build_model(text))


def loop_scene_without(tmp_path):
    path = lever_scene(tmp_path, motion="prescribed").read_text().replace(", torque = -1.0", "")
    out = tmp_path / "held.toml"
    out.write_text(path)
    return out


@pytest.mark.parametrize("change, key", [
    (dict(motion="prescribed"), "path.rotation.torque"),
    (dict(extra="free_axis = [0.0, 1.0, 0.0]"), "path.rotation.torque"),
    (dict(mode="dynamic"), "path.rotation.torque"),
    (dict(torque=0.0), "torque"),
    # the torque turns it off the plane: nothing carries it
    (dict(torque=1.0), "path.rotation.torque"),
    # about the plane's normal (a braked disc): no lever, only friction
    # could carry it, and friction is not in the balance
    (dict(axis="[0.0, 1.0, 0.0]"), "path.rotation.torque"),
    # a face 10 mm off the plane: it would have to turn by 0.2 rad to touch,
    # beyond a small turn's balance (a gear out of mesh)
    (dict(extra="", side=1.0, h=1e-3, r=0.05, lift=1e-2), "path.rotation.torque"),
])
def test_bad_torques_are_refused_with_the_key(tmp_path, change, key):
    with pytest.raises(SceneError, match=key.replace(".", r"\.")):
        build_model(load_scene(lever_scene(tmp_path, **change)))


def test_a_worn_lever_keeps_its_torque_through_cycle_jumps(tmp_path):
    """The lever box fretting along the axis (a 0.1 mm stroke along z: no
    change of its levers) and wearing, 500 cycles: with cycle jumps every
    row's contact torque about the axis is the torque, and the worn volume
    is the resolved run's to within the jumps' tolerance (the jump turns
    the body as it balances a free axis's move: without that turn, the
    jumps relieve the contact and it wears 1.5 % less)."""
    h, r, torque, amplitude, frequency = 1e-3, 0.05, -1.0, 1e-4, 10.0
    cycles, k = 500, 1e-12
    extra = (f"oscillation = {{ axis = [0.0, 0.0, 1.0], amplitude = {amplitude}, "
             f"frequency = {frequency} }}")
    volumes = {}
    for acceleration in ("none", "cycle_jump"):
        text = lever_scene(tmp_path, h, r, torque, extra=extra, duration=cycles / frequency,
                           history=51).read_text().replace("dt = 0.01", "dt = 0.0025").replace(
            "coefficient = 0.0", f'coefficient = {k}\nacceleration = "{acceleration}"\n'
            "tolerance = 0.01")
        path = tmp_path / f"worn_lever_{acceleration}.toml"
        path.write_text(text)
        model, state, history = run_scene(load_scene(path))
        rows = history.rows["arm"]
        assert np.all(rows["resolved"]) == (acceleration == "none")
        for wrench, pose in zip(rows["wrench"], rows["pose"]):
            assert axial_torque(wrench, pose) == pytest.approx(-torque, rel=1e-6)
        volumes[acceleration] = state.bodies[0].wear_volume.sum()
    # (abs=0: pytest.approx's default absolute 1e-12 would pass any volume)
    assert volumes["none"] > 0.9 * k * (-torque / r) * 4 * amplitude * cycles  # it wore
    assert volumes["cycle_jump"] == pytest.approx(volumes["none"], rel=2e-3, abs=0.0)


def test_a_turning_body_resumes_to_the_same_wear(tmp_path):
    """The worn lever with cycle jumps, stopped half way at a checkpoint and
    resumed in a new model: the angle it settled to comes back with the
    checkpoint, and the run ends with the uninterrupted one's wear
    (docs/outputs.md, "Checkpoints": 1e-9)."""
    from meshwear.longrun import checkpoint
    from test_resume import _KillAt, _Stop

    extra = "oscillation = { axis = [0.0, 0.0, 1.0], amplitude = 1e-4, frequency = 10.0 }"
    text = lever_scene(tmp_path, extra=extra, duration=30.0, history=31).read_text().replace(
        "dt = 0.01", "dt = 0.0025").replace(
        "coefficient = 0.0", 'coefficient = 1e-12\nacceleration = "cycle_jump"')
    path = tmp_path / "resumed_lever.toml"
    path.write_text(text)
    model = build_model(load_scene(path))
    full = run(model, initial_state(model))
    saver = checkpoint.Checkpointer(tmp_path, every=0.0)
    model = build_model(load_scene(path))
    with pytest.raises(_Stop):
        run(model, initial_state(model), observers=[_KillAt(17.0)], checkpoint=saver)
    model = build_model(load_scene(path))
    resumed = initial_state(model)
    checkpoint.load(saver.path, model, resumed)
    assert 0.0 < resumed.time <= 17.0 and model.bodies[0].motion.settled != 0.0
    run(model, resumed)
    w, w_full = resumed.bodies[0].wear_depth, full.bodies[0].wear_depth
    assert w_full.max() > 0.0
    assert np.abs(w - w_full).max() <= 1e-9 * w_full.max()


def test_turn_pose_agrees_with_scipy_rotations():
    """turn_pose (the settled turn of a pose about an axis through a point)
    against scipy's rotations: the centre of mass turned about the point,
    the orientation composed with the turn."""
    from scipy.spatial.transform import Rotation

    from meshwear.kernels.turn_balance import turn_pose

    rng = np.random.default_rng(7)
    for _ in range(10):
        pose = np.zeros(13)
        pose[0:3] = rng.normal(size=3)
        q = rng.normal(size=4)
        pose[3:7] = q / np.linalg.norm(q)
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        center, angle = rng.normal(size=3), rng.uniform(-1.0, 1.0)
        turned = pose.copy()
        turn_pose(turned, axis, center, angle)
        turn = Rotation.from_rotvec(angle * axis)
        np.testing.assert_allclose(turned[0:3], center + turn.apply(pose[0:3] - center),
                                   rtol=0, atol=1e-14)
        w, x, y, z = pose[3:7]
        expected = (turn * Rotation.from_quat([x, y, z, w])).as_quat()     # x y z w
        got = np.array([*turned[4:7], turned[3]])
        assert min(np.abs(got - expected).max(), np.abs(got + expected).max()) < 1e-14
