"""Mesh counter-surfaces, moving counter-bodies and the active set (docs/model.md).

The mesh surface gives each vertex the plane of its nearest face, so a mesh
whose faces lie in a plane must reproduce the plane's results; most checks
below compare the two, the rest compare with closed forms.
"""

import math
import numpy as np
import pytest
import trimesh

import reference
from meshwear.kernels import nearest
from meshwear.scene.reader import load_scene
from meshwear.step.simulate import run_scene

RTOL = 1e-12


def _close(a, b):
    scale = max(np.abs(b[np.isfinite(b)]).max(initial=0.0), 1e-300)
    same_inf = np.isinf(a) == np.isinf(b)
    fa, fb = np.where(np.isfinite(a), a, 0.0), np.where(np.isfinite(b), b, 0.0)
    return bool(same_inf.all() and np.all(np.abs(fa - fb) <= RTOL * (np.abs(fb) + scale)))


def _bumpy_mesh(rng):
    """A closed, dented sphere (curved, concave and convex places)."""
    m = trimesh.creation.icosphere(subdivisions=3, radius=0.01)
    v = m.vertices * (1.0 + 0.08 * rng.standard_normal((len(m.vertices), 1)).clip(-2, 2))
    return np.ascontiguousarray(v), np.ascontiguousarray(m.faces, dtype=np.int64)


def _rotation(rng):
    q = rng.normal(size=4)
    return np.array(reference.quaternion_matrix(q / np.linalg.norm(q)))


# ------------------------------------------------------------- the query kernel

@pytest.mark.parametrize("smooth", [False, True])
def test_nearest_planes_match_brute_force_twin(smooth):
    """Grid query against every face by brute force (trimesh closest points),
    on a moving, turning dented sphere, with tracked and untracked vertices."""
    rng = np.random.default_rng(3)
    V, F = _bumpy_mesh(rng)
    normals = trimesh.Trimesh(V, F, process=False).face_normals.copy()
    vnormals = (nearest.corner_normals(V, F, normals) if smooth else np.zeros((0, 3, 3)))
    reach = 2e-3
    from meshwear.kernels import tree

    grid = (np.array([reach, 0.0]), *tree.build(V, F, 1e-12), tree.face_neighbours(F))
    rotation = _rotation(rng)
    motion = np.array([[0.001, -0.002, 0.003], [0.1, 0.0, -0.05], [0.0, 3.0, 10.0],
                       [0.0, 0.001, 0.0]])
    # body points around the surface (inside and outside), the body turned too
    n = 600
    directions = rng.normal(size=(n, 3))
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    world = motion[0] + (directions * rng.uniform(0.006, 0.0125, (n, 1))) @ rotation.T
    pose = np.zeros(13)
    pose[3:7] = [np.cos(0.3), 0.0, np.sin(0.3), 0.0]
    pose[0:3] = [0.002, 0.0, -0.001]
    R = reference.quaternion_matrix(pose[3:7])
    body = np.ascontiguousarray((world - pose[0:3]) @ R)
    active = np.flatnonzero(rng.random(n) < 0.8)
    out = np.zeros((n, 3, 3))
    # half of the vertices had a plane last step: a random normal near the
    # surface's outward direction there
    tracked = rng.random(n) < 0.5
    guess = directions @ rotation.T + rng.normal(scale=0.4, size=(n, 3))
    out[tracked, 1] = (guess / np.linalg.norm(guess, axis=1)[:, None])[tracked]
    twin_out, distance, twin_distance = out.copy(), np.full(n, -1.0), np.full(n, -1.0)
    hint, twin_hint = np.full(n, -1), np.full(n, -1)
    frames = nearest.face_frames(V, F)
    nearest.nearest_planes(body, pose, active, rotation, motion, V, F, frames, vnormals, *grid,
                           out, distance, hint)
    reference.nearest_planes(body, pose, active, rotation, motion, V, F, normals, vnormals, reach,
                             twin_out, twin_distance, twin_hint)
    assert _close(out, twin_out)
    assert _close(distance, twin_distance)
    assert (hint == twin_hint).all()
    found = np.isfinite(distance[active])
    assert 0.3 < found.mean() < 1.0, "the case must have vertices in and out of reach"
    inactive = np.setdiff1d(np.arange(n), active)
    assert (distance[inactive] == -1.0).all()
    # the next step, the body moved a little: each vertex keeps the face it
    # had while it is over it; the surface did not turn, so it may keep the
    # normal it holds (fixed)
    fixed_out, fixed_twin = out.copy(), out.copy()
    fixed_hint, fixed_twin_hint = hint.copy(), hint.copy()
    moved = pose.copy()
    moved[0:3] += [3e-4, -2e-4, 1e-4]
    nearest.nearest_planes(body, moved, active, rotation, motion, V, F, frames, vnormals, *grid,
                           fixed_out, distance, fixed_hint, True)
    reference.nearest_planes(body, moved, active, rotation, motion, V, F, normals, vnormals,
                             reach, fixed_twin, twin_distance, fixed_twin_hint)
    assert _close(fixed_out, fixed_twin) and _close(distance, twin_distance)
    assert (fixed_hint == fixed_twin_hint).all()
    # the surface does not move either (steady): a vertex that keeps its flat
    # face keeps the point of the plane it holds, no longer its foot; the
    # same plane, and the velocity at the foot
    steady_out, steady_hint = fixed_out.copy(), fixed_hint.copy()
    moved[0:3] += [2e-4, 1e-4, -1e-4]
    nearest.nearest_planes(body, moved, active, rotation, motion, V, F, frames, vnormals, *grid,
                           steady_out, distance, steady_hint, True, True)
    reference.nearest_planes(body, moved, active, rotation, motion, V, F, normals, vnormals,
                             reach, fixed_twin, twin_distance, fixed_twin_hint)
    assert _close(distance, twin_distance) and (steady_hint == fixed_twin_hint).all()
    assert _close(steady_out[:, 1], fixed_twin[:, 1])
    n_ = fixed_twin[:, 1]
    assert _close(np.einsum("ij,ij->i", steady_out[:, 0], n_),
                  np.einsum("ij,ij->i", fixed_twin[:, 0], n_))
    assert _close(steady_out[:, 2], fixed_twin[:, 2])
    kept = np.isfinite(distance) & (steady_hint >= 0)
    moved_foot = np.linalg.norm(steady_out[kept, 0] - fixed_twin[kept, 0], axis=1) > 1e-5
    assert moved_foot.any() != smooth, "flat faces keep their plane; smooth ones are rewritten"
    # and, a third of them starting from a wrong face, without that promise
    pose[0:3] += [3e-4, -2e-4, 1e-4]
    stale = rng.random(n) < 0.3
    hint[stale] = rng.integers(0, len(F), stale.sum())
    twin_hint = hint.copy()
    nearest.nearest_planes(body, pose, active, rotation, motion, V, F, frames, vnormals, *grid,
                           out, distance, hint)
    reference.nearest_planes(body, pose, active, rotation, motion, V, F, normals, vnormals, reach,
                             twin_out, twin_distance, twin_hint)
    assert _close(out, twin_out)
    assert _close(distance, twin_distance)
    assert (hint == twin_hint).all()


def _leaf_faces(boxes, nodes, order, p, reach):
    """The faces of every leaf whose box comes within ``reach`` of ``p``
    (what the kernel's search can reach), by a walk of the whole tree."""
    listed, stack = set(), [0]
    while stack:
        k = stack.pop()
        gap = np.maximum(np.maximum(boxes[k, 0:3] - p, p - boxes[k, 3:6]), 0.0)
        if gap @ gap > reach * reach:
            continue
        first, count = nodes[k]
        if count:
            listed.update(order[first:first + count].tolist())
        else:
            stack += [first, first + 1]
    return listed


@pytest.mark.parametrize("start", [0, 1])
def test_a_vertex_pressed_under_a_fold_between_two_faces_finds_its_face_by_the_walk(start):
    """Two faces meeting at a shallow valley (a worn flat's faces lean by
    10^-3 rad): under their shared edge lies a strip whose points have their
    foot beyond the edge on both faces. A vertex pressed in there, tracked
    on either face, walks onto the other and finds the edge behind it: it
    is over both, and takes the one its twin takes (equally near: the one
    whose plane separates more), without a search: the tree is left empty
    here (before, the walk went back and forth and only a search found a
    face; without a tree, none)."""
    from meshwear.kernels import tree

    # the shared edge along y at x = z = 0; face 0 rises towards -x by 2e-3,
    # face 1 towards +x by 1e-3; the vertex 1 um under the edge
    V = np.array([[0.0, -1e-3, 0.0], [0.0, 1e-3, 0.0], [-1e-3, 0.0, 2e-6], [1e-3, 0.0, 1e-6]])
    F = np.array([[0, 1, 2], [1, 0, 3]], dtype=np.int64)
    normals = trimesh.Trimesh(V, F, process=False).face_normals.copy()
    assert (normals[:, 2] > 0.99).all()
    reach = 1e-4
    boxes, nodes, order = tree.build(V, F, 1e-12)
    grid = (np.array([reach, 0.0]), boxes[:0], nodes[:0], order, tree.face_neighbours(F))
    frames = nearest.face_frames(V, F)
    body = np.array([[0.0, 0.0, -1e-6]])
    pose = np.zeros(13)
    pose[3] = 1.0
    rotation, motion = np.eye(3), np.zeros((4, 3))
    beyond = [frames[f, 1:4, 0:3] @ body[0] - frames[f, 1:4, 3] for f in (0, 1)]
    assert min(b.max() for b in beyond) > 0.0, "the foot must lie beyond the edge on both faces"
    out = np.zeros((1, 3, 3))
    out[0, 1] = [0.0, 0.0, 1.0]          # it had a plane: tracked
    twin_out, distance, twin_distance = out.copy(), np.zeros(1), np.zeros(1)
    hint, twin_hint = np.full(1, start), np.full(1, start)
    nearest.nearest_planes(body, pose, np.array([0]), rotation, motion, V, F, frames,
                           np.zeros((0, 3, 3)), *grid, out, distance, hint)
    reference.nearest_planes(body, pose, np.array([0]), rotation, motion, V, F, normals,
                             np.zeros((0, 3, 3)), reach, twin_out, twin_distance, twin_hint)
    # face 0 leans more, so the vertex under the edge is less deep under its plane
    assert hint[0] == twin_hint[0] == 0
    assert _close(out, twin_out) and _close(distance, twin_distance)
    assert out[0, 1] @ normals[0] == pytest.approx(1.0, abs=1e-15)


def test_face_tree_holds_every_face_once_in_boxes_that_hold_them():
    """The properties the kernel's search relies on, on long thin slanted
    triangles (a CAD tessellation): every face in one leaf, each box holding
    its faces and its children, so the leaves whose boxes come within reach
    of a point list every face within reach of it."""
    from meshwear.kernels import tree

    rng = np.random.default_rng(1)
    V = rng.uniform(-0.05, 0.05, (60, 3))
    F = rng.integers(0, 60, (80, 3))
    F = F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 0] != F[:, 2])]
    boxes, nodes, order = tree.build(V, F, 0.0)
    assert sorted(order.tolist()) == list(range(len(F)))
    leaves = nodes[:, 1] > 0
    assert nodes[leaves, 1].sum() == len(F) and nodes[leaves, 1].max() <= tree.LEAF
    for k in np.flatnonzero(leaves):
        first, count = nodes[k]
        tri = V[F[order[first:first + count]]].reshape(-1, 3)
        assert (tri >= boxes[k, 0:3]).all() and (tri <= boxes[k, 3:6]).all()
    for k in np.flatnonzero(~leaves):
        for c in nodes[k, 0] + np.arange(2):
            assert c > k
            assert (boxes[c, 0:3] >= boxes[k, 0:3]).all() and (boxes[c, 3:6] <= boxes[k, 3:6]).all()
    reach = 0.004
    tri = V[F]
    for p in rng.uniform(-0.055, 0.055, (300, 3)):
        d = np.linalg.norm(trimesh.triangles.closest_point(tri, np.repeat(p[None], len(F), 0)) - p,
                           axis=1)
        assert set(np.flatnonzero(d <= reach).tolist()) <= _leaf_faces(boxes, nodes, order, p,
                                                                       reach)


def test_face_neighbours_are_the_faces_across_each_edge():
    from meshwear.kernels import tree

    m = trimesh.creation.icosphere(subdivisions=2)
    F = np.asarray(m.faces, dtype=np.int64)
    nb = tree.face_neighbours(F)
    assert (nb >= 0).all()                        # closed: every edge has its other face
    for f in range(len(F)):
        for k in range(3):
            edge = {F[f, k], F[f, (k + 1) % 3]}
            assert edge <= set(F[nb[f, k]].tolist()) and nb[f, k] != f
    open_strip = np.array([[0, 1, 2], [2, 1, 3]])
    assert tree.face_neighbours(open_strip).tolist() == [[-1, 1, -1], [0, -1, -1]]


# --------------------------------------------------- a mesh floor is a plane

BLOCK = """format = 1
[run]
duration = {duration}
dt = 1e-5
frames = 0
history = {history}

[contact]
stiffness = 1e6
damping = 20.0
tangential_damping = 0.0
friction = 0.3
{margin}

[wear]
law = "energy"
coefficient = 1e-6

[[body]]
name = "block"
shape = {{ type = "box", size = [0.01, 0.01, 0.005] }}
density = 7850.0
position = [0.0, 0.0, 0.0025]
force = [0.0, 0.0, -10.0]
motion = "guided"
[body.path]
{path}
free_axis = [0.0, 0.0, 1.0]

[[surface]]
name = "floor"
{floor}
"""
PLANE = 'type = "plane"'
BOX_FLOOR = ('type = "mesh"\nshape = { type = "box", size = [0.05, 0.05, 0.01] }\n'
             'position = [0.0, 0.0, -0.005]')
OSCILLATION = 'oscillation = { axis = [1.0, 0.0, 0.0], amplitude = 5e-6, frequency = 10.0 }'


def _run(tmp_path, text, name):
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return run_scene(load_scene(path))


def test_box_mesh_floor_gives_the_plane_s_jenkins_loop(tmp_path, measured):
    """Reciprocating block (δ = 5 µm) on a plane and on the top face of a box
    mesh: the friction energy per cycle agrees within 0.5 % (issue target),
    and both with 4μN(δ − μN/K_t)."""
    rows = {}
    for name, floor in (("plane", PLANE), ("mesh", BOX_FLOOR)):
        model, state, history = _run(tmp_path, BLOCK.format(duration=0.3, history=31, margin="",
                                                            path=OSCILLATION, floor=floor), name)
        rows[name] = history.rows["block"]
    load = model.bodies[0].mass * 9.81 + 10.0
    expected = 4 * 0.3 * load * (5e-6 - 0.3 * load / 4e6)
    for name, h in rows.items():
        i, j = np.searchsorted(h["time"], [0.2 - 1e-12, 0.3 - 1e-12])
        per_cycle = h["friction_work"][j] - h["friction_work"][i]
        measured(f"energy/cycle, {name} floor (J)", per_cycle, expected, 5e-3)
        assert per_cycle == pytest.approx(expected, rel=5e-3)
    plane, mesh = rows["plane"]["friction_work"][-1], rows["mesh"]["friction_work"][-1]
    measured("friction work, mesh floor vs plane", mesh, plane, 5e-3)
    assert mesh == pytest.approx(plane, rel=5e-3)


# ------------------------------------------------------------ turning disc

PIN_ON_DISC = """format = 1
[run]
mode = "quasi-static"
duration = {duration}
dt = 1e-3
frames = 0
history = 11

[contact]
stiffness_per_area = 1e13
tangential_stiffness_per_area = 1e13
friction = 0.4

[wear]
law = "archard"
coefficient = 1e-12

[[body]]
name = "pin"
shape = {{ type = "cylinder", radius = 0.002, height = 0.006, sections = 32 }}
resolution = 3e-4
density = 7850.0
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


def test_pin_on_a_turning_disc_mesh_wears_k_load_distance(tmp_path, measured):
    """Issue target: a flat pin (R = 2 mm, 10 N) 30 mm off the axis of a disc
    mesh turning at 10 rad/s wears V = k P s within 2 %, s = ω r t; the
    friction force opposes the disc's motion under the pin (−y here)."""
    duration = 0.5
    model, state, history = _run(tmp_path, PIN_ON_DISC.format(duration=duration), "disc")
    s = state.bodies[0]
    load = 10.0 + model.bodies[0].mass * 9.81
    distance = 10.0 * 0.03 * duration
    expected = 1e-12 * load * distance
    volume = history.rows["pin"]["wear_volume"][-1]
    measured("pin on turning disc mesh: volume (m³)", volume, expected, 2e-2)
    assert volume == pytest.approx(expected, rel=2e-2)
    # the disc surface moves at +y under the pin: it drags the pin along +y
    assert s.wrench[1] == pytest.approx(0.4 * load, rel=1e-2)
    assert abs(s.wrench[0]) < 1e-2 * 0.4 * load
    # only the pin's end face is refined (resolution where it can touch)
    body = model.bodies[0]
    z = body.reference_vertices[:, 2]
    assert (z <= z.min() + 1e-9).sum() > 100
    assert (z > z.min() + 1e-9).sum() < 100


# ------------------------------------------------------------ hard cases

def test_a_vertex_pressed_in_near_the_edge_of_the_counter_mesh_stays_on_the_top_face(tmp_path):
    """The block's corners stand 1 µm inside the edge of a box floor and sink
    ~2.6 µm into it: the side face is nearer than the top face, but a vertex
    that came down on the top face keeps it, so the forces are the plane's
    (no sideways push)."""
    x = 0.025 - 0.005 - 1e-6
    results = {}
    for name, floor in (("plane", PLANE), ("mesh", BOX_FLOOR)):
        text = BLOCK.format(duration=0.05, history=6, margin="", path="", floor=floor)
        text = text.replace("position = [0.0, 0.0, 0.0025]", f"position = [{x}, 0.0, 0.0025]")
        model, state, history = _run(tmp_path, text, name)
        results[name] = state.bodies[0]
    plane, mesh = results["plane"], results["mesh"]
    assert mesh.normal_force.sum() == pytest.approx(plane.normal_force.sum(), rel=1e-9)
    assert np.abs(mesh.wrench[0:2]).max() < 1e-9 * mesh.wrench[2]
    assert mesh.pose[2] == pytest.approx(plane.pose[2], abs=1e-12)


def test_a_body_that_leaves_contact_and_comes_back(tmp_path):
    """A block lifted 1 mm off a box floor and put back down (prescribed
    path): the active set empties while it is away and fills again; the
    contact forces are the plane's throughout."""
    path = "oscillation = { axis = [0.0, 0.0, 1.0], amplitude = 5e-4, frequency = 10.0 }"
    rows, states = {}, {}
    for name, floor in (("plane", PLANE), ("mesh", BOX_FLOOR)):
        text = BLOCK.format(duration=0.2, history=201, margin="margin = 1e-4", path=path,
                            floor=floor)
        text = text.replace('motion = "guided"', 'motion = "prescribed"')
        text = text.replace("force = [0.0, 0.0, -10.0]", "")
        text = text.replace("free_axis = [0.0, 0.0, 1.0]", "")
        # start 2 µm into the floor, so the bottom of each cycle presses 2 µm
        text = text.replace("position = [0.0, 0.0, 0.0025]", "position = [0.0, 0.0, 0.002998]")
        model, state, history = _run(tmp_path, text, name)
        rows[name], states[name] = history.rows["block"], state
    fz_plane, fz_mesh = rows["plane"]["wrench"][:, 2], rows["mesh"]["wrench"][:, 2]
    assert fz_plane.max() > 1.0 and (fz_plane == 0.0).sum() > 100
    np.testing.assert_allclose(fz_mesh, fz_plane, rtol=1e-9, atol=1e-12)
    for name in rows:
        active = rows[name]["active"]
        assert rows[name]["contact_points"].max() == 4
        # away: no vertex within the margin; down: the four bottom corners
        assert active.min() == 0 and active.max() == 4


def test_a_fast_body_does_not_tunnel_through_a_thin_counter_mesh(tmp_path):
    """A cube falls at 5 m/s on a 0.2 mm thick plate mesh with dt = 1e-4 s: it
    moves 0.5 mm per step, more than the plate is thick, and its corners
    sink further than the plate's half-thickness before the contact stops
    them. Handed the nearest face, they would be pushed out through the
    bottom; they keep the top face and bounce as off a plane."""
    text = """format = 1
[run]
duration = 0.02
dt = 1e-4
frames = 0
history = 21
gravity = [0.0, 0.0, 0.0]

[contact]
stiffness = 3e5
damping = 0.0
friction = 0.0

[wear]
law = "energy"
coefficient = 0.0

[[body]]
name = "cube"
shape = {{ type = "box", size = [0.02, 0.02, 0.02] }}
density = 7850.0
position = [0.0, 0.0, 0.0102]
velocity = [0.0, 0.0, -5.0]

[[surface]]
name = "plate"
{floor}
"""
    plate = ('type = "mesh"\nshape = { type = "box", size = [0.1, 0.1, 0.0002] }\n'
             'position = [0.0, 0.0, -0.0001]')
    ends = {}
    for name, floor in (("plane", PLANE), ("mesh", plate)):
        model, state, history = _run(tmp_path, text.format(floor=floor), name)
        ends[name] = state.bodies[0].pose.copy()
    # the plane: an elastic bounce, up at 5 m/s
    assert ends["plane"][9] == pytest.approx(5.0, rel=1e-2)
    assert ends["mesh"][2] > 0.0
    np.testing.assert_allclose(ends["mesh"], ends["plane"], rtol=1e-9, atol=1e-12)


def _write(tmp_path, name, vertices, faces):
    path = tmp_path / name
    trimesh.Trimesh(vertices, faces, process=False).export(path)
    return path


def test_an_open_sheet_counter_mesh_works_and_a_wrongly_wound_one_is_refused(tmp_path):
    """An open counter mesh (a square sheet, two triangles) is a surface whose
    face normals say which side the bodies are on: wound upward it is the
    plane; wound downward the block stands on its solid side, refused with
    the key and a hint."""
    square = np.array([[-0.05, -0.05, 0.0], [0.05, -0.05, 0.0], [0.05, 0.05, 0.0],
                       [-0.05, 0.05, 0.0]])
    up = np.array([[0, 1, 2], [0, 2, 3]])
    _write(tmp_path, "up.stl", square, up)
    _write(tmp_path, "down.stl", square, up[:, ::-1])
    text = BLOCK.format(duration=0.3, history=31, margin="", path=OSCILLATION,
                        floor='type = "mesh"\nmesh = "MESH"')
    _, plane_state, plane = _run(tmp_path, BLOCK.format(duration=0.3, history=31, margin="",
                                                         path=OSCILLATION, floor=PLANE), "plane")
    _, state, sheet = _run(tmp_path, text.replace("MESH", "up.stl"), "up")
    assert sheet.rows["block"]["friction_work"][-1] == pytest.approx(
        plane.rows["block"]["friction_work"][-1], rel=1e-9)
    from meshwear.scene.checks import SceneError
    with pytest.raises(SceneError, match=r"body\[0\].position.*inside surface 'floor'"):
        _run(tmp_path, text.replace("MESH", "down.stl"), "down")


def test_a_degenerate_counter_mesh_is_refused_naming_the_key(tmp_path):
    from meshwear.scene.checks import SceneError

    line = np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.02, 0.0, 0.0]])
    path = tmp_path / "flat.obj"
    path.write_text("".join(f"v {x} {y} {z}\n" for x, y, z in line) + "f 1 2 3\n")
    text = BLOCK.format(duration=0.01, history=2, margin="", path=OSCILLATION,
                        floor='type = "mesh"\nmesh = "flat.obj"')
    with pytest.raises(SceneError, match=r"surface\[0\]\.mesh.*(degenerate|extent)"):
        _run(tmp_path, text, "flat")


def test_a_ball_pressed_into_a_ring_bore_has_the_conforming_winkler_approach(tmp_path, measured):
    """Concave counter-surface: a ball (R = 5 mm) pressed with P = 10 N
    against the wall of a bore (R_b = 10 mm, smoothed normals). On a Winkler
    foundation the gap is A y² + B z² with A = 1/2R − 1/2R_b, B = 1/2R, so
    P = K π δ² / (2 √(AB)): δ = √(2 P √(AB) / (π K)). Every loaded vertex is
    pushed towards the bore's axis."""
    bore = trimesh.creation.annulus(r_min=0.01, r_max=0.015, height=0.02, sections=2048)
    bore.export(tmp_path / "bore.stl")
    text = """format = 1
[run]
mode = "quasi-static"
duration = 2e-3
dt = 1e-3
frames = 0
history = 3
gravity = [0.0, 0.0, 0.0]

[contact]
stiffness_per_area = 1e13
friction = 0.3

[wear]
law = "archard"
coefficient = 0.0

[[body]]
name = "ball"
shape = { type = "sphere", radius = 0.005, subdivisions = 6 }
density = 7850.0
position = [0.005, 0.0, 0.0]
force = [10.0, 0.0, 0.0]
motion = "guided"
[body.path]
free_axis = [1.0, 0.0, 0.0]

[[surface]]
name = "bore"
type = "mesh"
mesh = "bore.stl"
smooth_normals = true
"""
    model, state, history = _run(tmp_path, text, "bore")
    s = state.bodies[0]
    A, B = 1 / (2 * 0.005) - 1 / (2 * 0.01), 1 / (2 * 0.005)
    expected = np.sqrt(2 * 10.0 * np.sqrt(A * B) / (np.pi * 1e13))
    approach = s.pose[0] - 0.005
    measured("ball in a ring bore: approach (m)", approach, expected, 2e-2)
    assert approach == pytest.approx(expected, rel=2e-2)
    # in balance (to the smoothed normals' change over the last settling move)
    assert s.wrench[0] == pytest.approx(-10.0, rel=1e-6)
    assert abs(s.wrench[1]) < 1e-6 and abs(s.wrench[2]) < 1e-6
    loaded = s.normal_force[0] > 0.0
    normals = s.vertex_planes[0][loaded, 1]
    points = s.vertex_planes[0][loaded, 0]
    towards_axis = -points[:, 0:2] / np.linalg.norm(points[:, 0:2], axis=1)[:, None]
    assert np.all(np.einsum("ij,ij->i", normals[:, 0:2], towards_axis) > 1 - 1e-6)
    assert loaded.sum() > 30


def test_smoothed_normals_blend_across_facets_but_not_across_creases():
    """A 64-sided cylinder: wall corners get the radial direction (their two
    facets blended; the caps at 90° left out), cap corners stay axial."""
    m = trimesh.creation.cylinder(radius=0.01, height=0.02, sections=64)
    V, F = np.asarray(m.vertices), np.asarray(m.faces, dtype=np.int64)
    normals = np.asarray(m.face_normals)
    corners = nearest.corner_normals(V, F, normals)
    wall = np.abs(normals[:, 2]) < 1e-9
    p = V[F[wall]]
    radial = p[..., 0:2] / np.linalg.norm(p[..., 0:2], axis=2)[..., None]
    assert np.abs(corners[wall][..., 2]).max() < 1e-12
    assert np.abs(corners[wall][..., 0:2] - radial).max() < 1e-9
    assert np.abs(np.abs(corners[~wall][..., 2]) - 1.0).max() < 1e-12


# ------------------------------------------------- runs, outputs and resume

def test_turning_disc_cycle_jump_resumes_to_the_same_wear_and_writes_its_series(tmp_path):
    """Cycle jumping takes its period from the disc's turn (2π/10 s); a run
    stopped at a checkpoint and resumed gives the same wear; the CLI writes
    the moving disc as its own series, one frame per frame."""
    import dataclasses
    import json
    import xml.etree.ElementTree as ET

    from meshwear.longrun import checkpoint
    from meshwear.cli import main
    from meshwear.model.build import build_model, initial_state
    from meshwear.step.simulate import run

    path = tmp_path / "disc.toml"
    path.write_text(PIN_ON_DISC.format(duration=30.0)
                    .replace('law = "archard"', 'law = "archard"\nacceleration = "cycle_jump"')
                    .replace("coefficient = 1e-12", "coefficient = 1e-14")
                    .replace("history = 11", "history = 3"))
    scene = load_scene(path)
    model = build_model(scene)
    assert model.cycle_steps == math.ceil(2 * np.pi / 10 / 1e-3)  # dt never above the asked
    full = run(model, initial_state(model))
    assert full.jump.jumps > 0

    class Stop(Exception):
        pass

    class KillAt:
        def on_sample(self, model, state):
            if state.time >= 14.0:
                raise Stop

        def on_frame(self, model, state):
            pass

    saver = checkpoint.Checkpointer(tmp_path, every=0.0)
    with pytest.raises(Stop):
        run(model, initial_state(model), observers=[KillAt()], checkpoint=saver)
    resumed = initial_state(model)
    checkpoint.load(saver.path, model, resumed)
    assert 0.0 < resumed.time < 15.0 and resumed.jump.jumps > 0
    run(model, resumed)
    w, w_full = resumed.bodies[0].wear_depth, full.bodies[0].wear_depth
    assert np.abs(w - w_full).max() <= 1e-9 * w_full.max()
    load = 10.0 + model.bodies[0].mass * 9.81
    volume = resumed.bodies[0].wear_volume.sum()
    assert volume == pytest.approx(1e-14 * load * 0.3 * model.n_steps * model.dt, rel=2e-2)
    assert full.jump.resolved_steps < model.n_steps / 4

    short = tmp_path / "short.toml"
    short.write_text(PIN_ON_DISC.format(duration=0.2).replace("frames = 0", "frames = 3"))
    out = tmp_path / "out"
    assert main(["run", str(short), "-o", str(out), "-q"]) == 0
    frames = ET.parse(out / "disc.pvd").getroot().findall(".//DataSet")
    assert len(frames) == 3 and all((out / f.get("file")).is_file() for f in frames)
    summary = json.loads((out / "summary.json").read_text())
    pin = summary["bodies"]["pin"]
    assert 0 < pin["contact_points"] <= pin["active_vertices"] < pin["vertices"]
    del dataclasses


#: the tossed cube's plate as a mesh counter-surface (a 150 mm box, top at z = 0)
MESH_PLATE = """[[surface]]
name = "plate"
type = "mesh"
shape = { type = "box", size = [0.15, 0.15, 0.01] }
position = [0.0, 0.0, -0.005]
"""


@pytest.mark.parametrize("plate", ["plane", "mesh"])
def test_the_active_set_changes_no_result(tmp_path, plate):
    """The tossed cube (free, tumbling, corners and edges landing) with and
    without the active set, on an analytic plane and on a mesh plate: the
    same numbers, while most steps process few vertices."""
    import dataclasses

    from meshwear.model.build import build_model, initial_state
    from meshwear.output.memory import MemoryHistory
    from meshwear.step.simulate import run

    root = __import__("pathlib").Path(__file__).resolve().parents[1]
    source = root / "examples" / "cube_toss.toml"
    if plate == "mesh":
        text = source.read_text().replace('"../meshes/', f'"{(root / "meshes").as_posix()}/')
        text = text[:text.index("[[surface]]")] + MESH_PLATE
        source = tmp_path / "cube_on_a_mesh_plate.toml"
        source.write_text(text)
    scene = load_scene(source)
    scene = dataclasses.replace(scene, run=dataclasses.replace(scene.run, duration=0.15,
                                                               frames=0, history=16))
    model = build_model(scene)
    assert (len(model.surfaces.per_vertex) == 1) == (plate == "mesh")
    results = {}
    for cull in (True, False):
        m = dataclasses.replace(model, cull=cull)
        history = MemoryHistory()
        state = run(m, initial_state(m), observers=[history])
        results[cull] = (state.bodies[0], history.rows["cube"])
    (on, rows_on), (off, rows_off) = results[True], results[False]
    assert on.wear_depth.max() > 0.0 and rows_on["contact_points"].max() > 0
    for name in ("pose", "wear_depth", "friction_work", "normal_force"):
        np.testing.assert_allclose(getattr(on, name), getattr(off, name), rtol=1e-9, atol=1e-15)
    n = len(on.wear_depth)
    assert rows_off["active"].min() == n
    assert np.median(rows_on["active"]) < 0.5 * n


def test_cad_part_example_refines_only_where_it_can_touch_and_wears_k_load_distance():
    """examples/cad_part.toml: the CAD shoe (58 vertices, slivers up to aspect
    ~40) is refined to 0.5 mm on its running face and chamfers only; a few
    strokes on the rail mesh wear V = k P s (gross sliding)."""
    import dataclasses

    from meshwear.geometry.meshes import face_normals, load_mesh
    from meshwear.model.build import build_model, initial_state
    from meshwear.step.simulate import run

    root = __import__("pathlib").Path(__file__).resolve().parents[1]
    scene = load_scene(root / "examples" / "cad_part.toml")
    raw_vertices, raw_faces = load_mesh(root / "meshes" / "slider_shoe_mm.stl", "mm")
    scene = dataclasses.replace(
        scene, wear=dataclasses.replace(scene.wear, acceleration="none"),
        run=dataclasses.replace(scene.run, duration=2.0, frames=0, history=3))
    model = build_model(scene)
    body = model.bodies[0]
    V, F = body.reference_vertices, body.faces
    normals = face_normals(V, F)
    area = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    edges = np.linalg.norm(V[F] - V[np.roll(F, 1, axis=1)], axis=2).max(axis=1)
    facing = normals[:, 2] < -1e-3
    # the faces that face the rail are refined to 0.5 mm; the crown keeps its
    # 12 mm facets (a few split where the closure of the refinement reaches)
    assert edges[facing].max() <= 5e-4 * (1 + 1e-9)
    crown = normals[:, 2] > 0.5
    assert np.median(edges[crown]) > 0.01 and crown.sum() < 2 * 2 * 24
    assert len(V) > 20 * len(raw_vertices)
    # the running face and chamfers carry the vertices; the area is all there
    assert area[facing].sum() == pytest.approx(0.036 * 0.012 + 2 * 0.012 * np.hypot(0.002, 0.001),
                                               rel=1e-9)
    state = run(model, initial_state(model))
    s = state.bodies[0]
    load = 200.0 + body.mass * 9.81
    distance = 4 * 0.01 * 2.0
    assert s.wear_volume.sum() == pytest.approx(1e-16 * load * distance, rel=1e-2)
    assert 0 < len(s.active) < len(V)


def test_the_collision_manager_names_the_mesh_surfaces_a_body_comes_near(tmp_path):
    """Three mesh surfaces, a block over one of them and near the edge of a
    second: the fcl broad phase admits those two, within the margin only."""
    text = BLOCK.format(duration=0.01, history=2, margin="", path=OSCILLATION, floor=BOX_FLOOR)
    text += ('\n[[surface]]\nname = "far"\ntype = "mesh"\n'
             'shape = { type = "box", size = [0.01, 0.01, 0.01] }\nposition = [0.5, 0.0, 0.0]\n'
             '\n[[surface]]\nname = "beside"\ntype = "mesh"\n'
             'shape = { type = "box", size = [0.01, 0.01, 0.01] }\n'
             'position = [0.0, 0.0102, 0.0075]\n')
    path = tmp_path / "three.toml"
    path.write_text(text)
    from meshwear.model.build import build_model

    model = build_model(load_scene(path))
    body = model.bodies[0]
    pose = body.initial_pose
    def near(margin):
        return [m.name for m in model.surfaces.meshes_within(body, pose, 0.0, margin)]

    assert near(1e-4) == ["floor"]
    assert near(3e-4) == ["floor", "beside"]
    assert len(near(1.0)) == 3


@pytest.mark.parametrize("name", ["cad_part", "pin_on_turning_disc"])
def test_mesh_surface_examples_check(name, capsys):
    from meshwear.cli import main

    root = __import__("pathlib").Path(__file__).resolve().parents[1]
    assert main(["check", str(root / "examples" / f"{name}.toml")]) == 0
    out = capsys.readouterr().out
    assert "within reach of a surface" in out


def test_a_floor_mesh_on_a_path_drags_the_block_and_wears_it_k_load_distance(tmp_path):
    """A box floor sliding at 0.1 m/s along x under a block held in place
    (guided, free along z): the slip is the floor's velocity, so friction
    pulls the block along +x with μN and Archard wears k P v t."""
    floor = BOX_FLOOR + "\n[surface.path]\nvelocity = [0.1, 0.0, 0.0]"
    text = BLOCK.format(duration=0.1, history=11, margin="", path="", floor=floor)
    text = text.replace('law = "energy"\ncoefficient = 1e-6', 'law = "archard"\ncoefficient = 1e-12')
    model, state, history = _run(tmp_path, text, "moving_floor")
    s = state.bodies[0]
    load = model.bodies[0].mass * 9.81 + 10.0
    assert s.wrench[0] == pytest.approx(0.3 * load, rel=1e-6)
    assert abs(s.wrench[1]) < 1e-9 * load
    # the stick phase at the start (the springs load over c_t-sized slips) is
    # a few micrometres of the 10 mm slid: 1e-3
    assert s.wear_volume.sum() == pytest.approx(1e-12 * load * 0.1 * 0.1, rel=1e-3)


def test_the_active_set_changes_no_result_on_a_turning_mesh_in_mesh():
    """The gear pair (examples/gear_pair.toml): the pinion's flanks come into
    mesh with the turning wheel's from a margin of ten steps' motion away.
    The steps' lookups reach a few steps' motion (a vertex arriving from
    farther away takes its face then, as without the active set); they used
    to reach the whole margin, and the wheel's faces a vertex took there made
    the worn volume after a quarter revolution 0.6 % off the run without it."""
    import dataclasses

    from meshwear.step import stepper
    from meshwear.model.build import build_model, initial_state

    root = __import__("pathlib").Path(__file__).resolve().parents[1]
    model = build_model(load_scene(root / "examples" / "gear_pair.toml"))
    results = {}
    for cull in (True, False):
        m = dataclasses.replace(model, cull=cull)
        for surface in m.surfaces.per_vertex:        # each run bins its own grids
            surface.reach, surface.grid, surface.far, surface._compiled = 0.0, None, None, None
        state = initial_state(m)
        stepper.advance(m, state, 300)
        results[cull] = state
    on, off = results[True], results[False]
    assert len(on.bodies[0].active) < 0.2 * len(on.bodies[0].wear_depth)
    assert on.bodies[0].wear_volume.sum() > 0.0
    for name in ("pose", "wear_depth", "wear_volume", "friction_work", "normal_force"):
        np.testing.assert_allclose(getattr(on.bodies[0], name), getattr(off.bodies[0], name),
                                   rtol=1e-9, atol=1e-22)
    (wheel_on,), (wheel_off,) = ([p for p in r.parts if p is not None] for r in (on, off))
    assert wheel_on.depth.max() > 0.0
    np.testing.assert_allclose(wheel_on.depth, wheel_off.depth, rtol=1e-9, atol=1e-22)


STROKE = """format = 1
[run]
mode = "quasi-static"
duration = 1.0
dt = 0.05
frames = 0
history = 2
gravity = [0.0, 0.0, 0.0]
[contact]
stiffness_per_area = 1e13
friction = 0.3
margin = 1e-4
[wear]
law = "archard"
coefficient = 1e-15
[[body]]
name = "pad"
shape = {{ type = "box", size = [0.002, 0.002, 0.001] }}
position = [0.0, 0.0, 0.0005]
force = [0.0, 0.0, -5.0]
motion = "guided"
[body.path]
oscillation = {{ axis = [1.0, 0.0, 0.0], amplitude = 0.001, frequency = 1.0 }}
free_axis = [0.0, 0.0, 1.0]
[[surface]]
name = "flat"
type = "mesh"
shape = {{ type = "box", size = [0.01, 0.01, 0.002] }}
position = [0.0, 0.0, -0.001]
resolution = {resolution}
wear = true
"""


def test_a_worn_surface_is_refined_only_where_a_body_reaches_it(tmp_path):
    """The flat under a pad rubbed by +-1 mm is refined to the resolution
    under the stroke and the margin around it (every face some pad vertex
    comes within the margin of, at any instant of the cycle), not all over:
    its sides and the rest of its top keep their triangles."""
    from meshwear.model.build import build_model

    path = tmp_path / "stroke.toml"
    path.write_text(STROKE.format(resolution=5e-4))
    model = build_model(load_scene(path))
    flat = model.surfaces.meshes[0]
    info = flat.refinement
    top = np.abs(flat.vertices[:, 2] - 0.001) < 1e-12       # its own frame: top at +1 mm
    # the top refined all over would hold (10 / 0.5 + 1)^2 = 441 vertices
    assert info["refined_vertices"] < 0.4 * 441 and top.sum() < 0.5 * 441
    V, F = flat.vertices, flat.faces
    edges = np.linalg.norm(V[F] - np.roll(V[F], 1, axis=1), axis=2).max(axis=1)
    body = model.bodies[0]
    pose = body.initial_pose.copy()
    tri = V[F]
    reached = np.zeros(len(F), bool)
    for t in np.linspace(0.0, 1.0, 201):
        body.motion.place(pose, t)
        x = pose[0:3] + body.reference_vertices @ reference.quaternion_matrix(pose[3:7]).T
        x = x - [0.0, 0.0, -0.001]                            # the flat's frame
        for p in x[x[:, 2] < 0.001 + 1e-4]:
            d = np.linalg.norm(trimesh.triangles.closest_point(tri, np.repeat(p[None], len(F), 0))
                               - p, axis=1)
            reached |= d <= 1e-4
    assert reached.sum() > 50
    assert np.all(edges[reached] <= 5e-4 * (1 + 1e-9)), "every face a body reaches is refined"
    assert edges[~reached].max() > 4e-3, "faces nothing reaches keep their size"


@pytest.mark.parametrize("stem,share", [("shaft_in_worn_bushing", 0.5),
                                        ("cylinder_on_worn_flat", 0.5)])
def test_the_early_refusal_counts_only_surface_the_refined_bodies_reach(stem, share):
    """Before any part is refined, a worn surface's resolution is refused
    from the surface within a lower bound of the reach of the bodies' sweep
    (meshwear.model.reach.refuse_early): that of their vertices as given, and of
    points drawn on the faces their resolution refines, allowing for how
    far the refined vertices may lie from those points. Every point of the
    surface it counts is one the refined bodies' sweep reaches
    (surface_faces_to_refine, after the bodies are refined), and it counts
    at least ``share`` of those: a turning shaft's coarse vertices lie on
    its rims, beyond the shorter bushing's bore, and counted none of it
    (the refusal then waited for the shaft's 81 550 faces). At the size
    default of the margin, 1 % of the body's size: a bound on points drawn
    on coarse faces holds little of a margin a few µm wide, as a
    contact-sized one is (docs/model.md, "Active set"), whose refined area
    is small anyway."""
    import dataclasses

    from meshwear import surfaces
    from meshwear.geometry import meshes
    from meshwear.model import build as model_, reach

    scene = load_scene(f"examples/{stem}.toml")
    built = [surfaces.build_surface(s) for s in scene.surfaces]
    unrefined = surfaces.SurfaceSet(built)
    coarse = model_._build_bodies(scene, unrefined, coarse=True)
    size = surfaces.MARGIN_FRACTION * float(np.linalg.norm(np.ptp(coarse[0].reference_vertices,
                                                                  axis=0)))
    scene = dataclasses.replace(scene, contact=dataclasses.replace(scene.contact, margin=size))
    coarse = model_._build_bodies(scene, unrefined, coarse=True)
    drawn = [reach.refined_faces(scene, c, b, unrefined) for b, c in zip(coarse, scene.bodies)]
    refined = model_._build_bodies(scene, unrefined)
    surface, periods = built[0], model_._periods(scene)
    sweeps = reach._coarsest(scene, surface, coarse, reach._window(scene, periods))
    low, high = surface.vertices.min(axis=0), surface.vertices.max(axis=0)
    early = reach._early_within(sweeps, low, high, drawn)[0]
    reached = reach.surface_faces_to_refine(scene, surface, refined, periods, 1.0).within
    rng = np.random.default_rng(1)
    V, F = surface.vertices, surface.faces
    areas = meshes._doubled_areas(V, F)
    pick = np.minimum(np.searchsorted(np.cumsum(areas), rng.random(100_000) * areas.sum()),
                      len(F) - 1)
    u, v = rng.random((2, len(pick)))
    s = np.sqrt(u)[:, None]
    tri = V[F[pick]]
    points = (1 - s) * tri[:, 0] + s * ((1 - v)[:, None] * tri[:, 1] + v[:, None] * tri[:, 2])
    counted, real = early(points), reached(points)
    assert real.sum() > 1000
    assert not np.any(counted & ~real), "the early count is a lower bound"
    assert counted.sum() >= share * real.sum()
