"""Numba kernels against their plain-numpy twins (tests/reference.py): 1e-12 relative."""

import numpy as np
import pytest

import reference
from meshwear.kernels import contact, rigid

RTOL = 1e-12
FACING_DOWN = np.array([[0.0, 0.0, -1e-6, 1e-6]])  # area vector of 1 mm², facing -z


@pytest.mark.parametrize("kernel", [contact.contact_serial, contact.contact_parallel])
@pytest.mark.parametrize("wear_law", [contact.ENERGY, contact.ARCHARD])
def test_one_surface_build_matches_numpy_twin(kernel, wear_law):
    """One per-vertex surface and no plane (a mesh or analytic counter-body
    alone) runs the build compiled for that case: the same computation."""
    rng = np.random.default_rng(11 + wear_law)
    vertices, pose, planes, params, law, direction, arrays = _random_case(
        rng, 400, 1, wear_law, False)
    # the plane as a mesh surface would give it: one per vertex, each tilted
    # a little differently, its velocity as given (no turn term)
    vertex_planes = np.repeat(planes[0:1, None, :3], 400, axis=1).copy()
    tilt = vertex_planes[0, :, 1] + rng.normal(scale=0.02, size=(400, 3))
    vertex_planes[0, :, 1] = tilt / np.linalg.norm(tilt, axis=1)[:, None]
    arrays["vertex_planes"] = vertex_planes
    arrays["active"] = np.flatnonzero(np.arange(400) % 5 != 0)
    _step_with_twin(kernel, vertices, pose, np.zeros((0, 4, 3)), params, law, direction, arrays)


def _random_case(rng, n, n_planes, wear_law, along_vertex_normal):
    vertices = rng.uniform(-0.01, 0.01, (n, 3))
    q = rng.normal(size=4)
    pose = np.zeros(13)
    pose[0:3] = [0.0, 0.0, 0.004]
    pose[3:7] = q / np.linalg.norm(q)
    pose[7:10] = rng.normal(scale=0.05, size=3)
    pose[10:13] = rng.normal(scale=2.0, size=3)
    planes = np.zeros((n_planes, 4, 3))
    for s in range(n_planes):
        normal = np.array([0.0, 0.0, 1.0]) + rng.normal(scale=0.3, size=3)
        planes[s, 1] = normal / np.linalg.norm(normal)
        planes[s, 0] = rng.normal(scale=0.002, size=3)
        planes[s, 2] = rng.normal(scale=0.01, size=3)
        planes[s, 3] = rng.normal(scale=5.0) * planes[s, 1]   # turning about its normal
    # area vectors: mostly facing the planes (-z), some sideways or away
    directions = rng.normal(size=(n, 3)) + [0.0, 0.0, -1.5]
    params = np.zeros((n, 4))
    params[:, 0:3] = rng.uniform(1e-6, 4e-6, (n, 1)) * directions / np.linalg.norm(directions, axis=1)[:, None]
    params[:, 3] = np.linalg.norm(params[:, 0:3], axis=1)
    # per-point normal law, Winkler (per-area) tangential law: both paths covered
    law = contact.make_law(friction=0.3, static_friction=0.4, wear_law=wear_law,
                           wear_coefficient=1e-7, dt=1e-5, stiffness=5e4, damping=2.0,
                           tangential_stiffness_per_area=2e10, tangential_damping_per_area=1e6)
    if along_vertex_normal:
        direction = rng.normal(size=(n, 3))
        direction /= np.linalg.norm(direction, axis=1)[:, None]
    else:
        direction = np.zeros((0, 3))
    arrays = dict(
        contact_state=np.zeros((n_planes, n), np.int8),
        tangential=np.zeros((n_planes, n, 4, 3)),
        normal_force=np.zeros((n_planes, n)),
        friction_work=np.zeros(n), wear_depth=np.zeros(n), wear_volume=np.zeros(n),
        wrench=np.zeros(6))
    return vertices, pose, planes, params, law, direction, arrays


def _call(fn, vertices, pose, planes, params, law, direction, a):
    """``fn`` on the arrays of ``a``; its ``vertex_planes`` and ``active``
    default to no mesh surface and every vertex."""
    n = len(vertices)
    vertex_planes = a.get("vertex_planes", contact.no_mesh_planes(n))
    active = a.get("active", contact.all_vertices(n))
    fn(vertices, pose, planes, vertex_planes, active, params, law, direction,
       a["contact_state"], a["tangential"], a["normal_force"], a["friction_work"],
       a["wear_depth"], a["wear_volume"], a["wrench"])


def _close(a, b):
    """Element-wise |a - b| <= RTOL (|b| + max |b|).

    The absolute part covers values that are the small difference of large
    terms (a friction force F0 - c_t e passing through zero): the kernel
    contracts a*b + c into one FMA, the twin rounds twice, so such values
    agree to RTOL of the terms, not of themselves.
    """
    scale = max(np.abs(b).max(), 1e-300)
    return bool(np.all(np.abs(a - b) <= RTOL * (np.abs(b) + scale)))


@pytest.mark.parametrize("kernel", [contact.contact_serial, contact.contact_parallel])
@pytest.mark.parametrize("wear_law", [contact.ENERGY, contact.ENERGY_DENSITY, contact.ARCHARD])
@pytest.mark.parametrize("along_vertex_normal", [False, True])
@pytest.mark.parametrize("n_planes", [1, 2])
def test_contact_matches_numpy_twin(kernel, wear_law, along_vertex_normal, n_planes):
    """Two planes run the general build; one plane and no mesh surface the
    build compiled for that case (the same computation)."""
    rng = np.random.default_rng(7 + wear_law)
    _step_with_twin(kernel, *_random_case(rng, 400, n_planes, wear_law, along_vertex_normal))


def _step_with_twin(kernel, vertices, pose, planes, params, law, direction, arrays):
    """A few steps of ``kernel`` and of the numpy twin from the same case,
    the pose wandering so points enter, stick, slip, reverse and leave;
    every array must agree after each step."""
    twin_vertices = vertices.copy()
    twin_arrays = {k: v.copy() for k, v in arrays.items()}
    seen_states = set()
    for k in range(40):
        pose[0:3] += 2e-4 * np.array([np.sin(k), np.cos(0.7 * k), np.sin(0.3 * k) - 0.2])
        pose[7:10] = 0.05 * np.array([np.cos(0.9 * k), -np.sin(0.5 * k), 0.01])
        _call(kernel, vertices, pose, planes, params, law, direction, arrays)
        _call(reference.contact, twin_vertices, pose, planes, params, law, direction, twin_arrays)
        seen_states |= set(np.unique(arrays["contact_state"]).tolist())
        for name in arrays:
            assert _close(arrays[name], twin_arrays[name]), (k, name)
        assert _close(vertices, twin_vertices), k
    assert seen_states == {0, 1, 2}, "the case must exercise no contact, stick and slip"
    assert arrays["wear_depth"].max() > 0.0


@pytest.mark.parametrize("kernel", [contact.contact_serial, contact.contact_parallel])
def test_mesh_slots_and_active_set_match_numpy_twin(kernel):
    """Per-vertex planes (a mesh surface's faces, moving, some vertices with
    no face in reach) after an analytic plane, on a part of the vertices."""
    rng = np.random.default_rng(5)
    n = 300
    vertices, pose, planes, params, law, direction, arrays = _random_case(
        rng, n, 3, contact.ARCHARD, False)
    vertex_planes = np.repeat(planes[1:, None, :3], n, axis=1).copy()
    tilt = vertex_planes[:, :, 1] + rng.normal(scale=0.05, size=(2, n, 3))
    vertex_planes[:, :, 1] = tilt / np.linalg.norm(tilt, axis=2)[:, :, None]
    vertex_planes[:, :, 2] += rng.normal(scale=0.02, size=(2, n, 3))
    vertex_planes[:, ::7] = 0.0                      # no face within reach
    arrays.update(vertex_planes=vertex_planes, active=np.flatnonzero(rng.random(n) < 0.6))
    planes = planes[:1]
    twin_vertices = vertices.copy()
    twin_arrays = {k: v.copy() for k, v in arrays.items()}
    idle = np.setdiff1d(np.arange(n), arrays["active"])
    seen_states = set()
    for k in range(40):
        pose[0:3] += 2e-4 * np.array([np.sin(k), np.cos(0.7 * k), np.sin(0.3 * k) - 0.2])
        pose[7:10] = 0.05 * np.array([np.cos(0.9 * k), -np.sin(0.5 * k), 0.01])
        _call(kernel, vertices, pose, planes, params, law, direction, arrays)
        _call(reference.contact, twin_vertices, pose, planes, params, law, direction, twin_arrays)
        seen_states |= set(np.unique(arrays["contact_state"][1:]).tolist())
        for name in arrays:
            assert _close(arrays[name], twin_arrays[name]), (k, name)
        assert _close(vertices, twin_vertices), k
    assert seen_states == {0, 1, 2}
    # vertices outside the active set are not touched
    assert not arrays["contact_state"][:, idle].any() and not arrays["wear_depth"][idle].any()
    assert arrays["wear_depth"].max() > 0.0


def test_a_sticking_anchor_moves_with_its_counter_surface():
    """A point stuck to a plane that moves at u along itself, the point moving
    with it: the spring does not stretch (the anchor is the surface's point)."""
    vertices = np.zeros((1, 3))
    pose = np.zeros(13)
    pose[3] = 1.0
    pose[2] = -1e-6
    planes = np.zeros((1, 4, 3))
    planes[0, 1, 2] = 1.0
    planes[0, 2, 0] = 0.2  # the plane moves at 0.2 m/s along x
    law = contact.make_law(friction=0.5, static_friction=0.5, wear_law="energy",
                           wear_coefficient=0.0, dt=1e-4, stiffness=1e6, tangential_stiffness=1e6)
    for kernel in (contact.contact, reference.contact):
        a = dict(contact_state=np.zeros((1, 1), np.int8), tangential=np.zeros((1, 1, 4, 3)),
                 normal_force=np.zeros((1, 1)), friction_work=np.zeros(1), wear_depth=np.zeros(1),
                 wear_volume=np.zeros(1), wrench=np.zeros(6))
        p = pose.copy()
        p[7] = 0.2
        for k in range(50):
            p[0] = 0.2 * k * 1e-4
            _call(kernel, vertices, p, planes, FACING_DOWN, law, np.zeros((0, 3)), a)
            assert a["contact_state"][0, 0] == contact.STICK
        assert np.abs(a["tangential"][0, 0, contact.FORCE]).max() < 1e-9


def test_contact_state_machine_transitions():
    """One point, one plane: stick on touch-down, slip past f0 N, stick on reversal."""
    vertices = np.zeros((1, 3))
    pose = np.zeros(13)
    pose[3] = 1.0
    pose[2] = -1e-6  # 1 µm penetration
    planes = np.zeros((1, 4, 3))
    planes[0, 1, 2] = 1.0
    c = 1e6
    params = FACING_DOWN
    law = contact.make_law(friction=0.5, static_friction=0.5, wear_law="energy",
                           wear_coefficient=0.0, dt=1e-3, stiffness=c, tangential_stiffness=c)
    a = dict(contact_state=np.zeros((1, 1), np.int8), tangential=np.zeros((1, 1, 4, 3)),
             normal_force=np.zeros((1, 1)), friction_work=np.zeros(1), wear_depth=np.zeros(1),
             wear_volume=np.zeros(1), wrench=np.zeros(6))
    N = c * 1e-6
    _call(contact.contact, vertices, pose, planes, params, law, np.zeros((0, 3)), a)
    assert a["contact_state"][0, 0] == contact.STICK
    assert a["normal_force"][0, 0] == pytest.approx(N)
    # drag 0.4 µm: spring force 0.4 N < f0 N = 0.5 N, still stick, force continuous from F0 = 0
    pose[0] = 0.4e-6
    pose[7] = 1e-9
    _call(contact.contact, vertices, pose, planes, params, law, np.zeros((0, 3)), a)
    assert a["contact_state"][0, 0] == contact.STICK
    assert a["tangential"][0, 0, 2, 0] == pytest.approx(-0.4, rel=1e-6)
    # drag to 0.6 µm: past the static limit, slip with F = -f N along the slip velocity
    pose[0] = 0.6e-6
    _call(contact.contact, vertices, pose, planes, params, law, np.zeros((0, 3)), a)
    assert a["contact_state"][0, 0] == contact.SLIP
    assert a["tangential"][0, 0, 2, 0] == pytest.approx(-0.5)
    # reverse: stick again, starting from the slip force (F0 = -0.5 N, no jump)
    pose[7] = -1e-9
    _call(contact.contact, vertices, pose, planes, params, law, np.zeros((0, 3)), a)
    assert a["contact_state"][0, 0] == contact.STICK
    assert a["tangential"][0, 0, 1, 0] == pytest.approx(-0.5)
    # anchored one step back at the turning point: the spring already unloads
    assert a["tangential"][0, 0, 2, 0] == pytest.approx(-0.5 + c * 1e-9 * 1e-3, rel=1e-9)
    # lift off: no contact, no force
    pose[2] = 1e-6
    _call(contact.contact, vertices, pose, planes, params, law, np.zeros((0, 3)), a)
    assert a["contact_state"][0, 0] == contact.NO_CONTACT
    assert a["normal_force"][0, 0] == 0.0 and not a["tangential"][0, 0, 2].any()


def test_free_step_matches_numpy_twin():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(3, 3))
    inertia = A @ A.T + 3 * np.eye(3)
    inverse = np.linalg.inv(inertia)
    pose = np.zeros(13)
    q = rng.normal(size=4)
    pose[3:7] = q / np.linalg.norm(q)
    pose[7:13] = rng.normal(size=6)
    twin = pose.copy()
    for k in range(50):
        wrench = rng.normal(size=6)
        acc = np.array([0.0, 0.0, -9.81])
        rigid.free_step(pose, wrench, 0.5, inertia, inverse, acc, 1e-3)
        reference.free_step(twin, wrench, 0.5, inertia, inverse, acc, 1e-3)
        assert _close(pose, twin), k


def test_free_step_keeps_angular_momentum_without_torque():
    inertia = np.diag([1.0, 2.0, 3.0])
    pose = np.zeros(13)
    pose[3] = 1.0
    pose[10:13] = [1.0, 2.0, 0.5]
    L0 = inertia @ pose[10:13]
    for _ in range(2000):
        rigid.free_step(pose, np.zeros(6), 1.0, inertia, np.linalg.inv(inertia), np.zeros(3), 1e-3)
    R = reference.quaternion_matrix(pose[3:7])
    L = R @ inertia @ R.T @ pose[10:13]
    np.testing.assert_allclose(L, L0, rtol=1e-12, atol=1e-12)


def test_guided_step_matches_numpy_twin():
    rng = np.random.default_rng(11)
    e1 = np.array([1.0, 0.0, 0.0])
    terms = np.array([
        [rigid.OSCILLATION, 0.6, 0.8, 0.0, 0.0, 0.0, 0.0, 5e-5, 2 * np.pi * 10.0],
        [rigid.STEADY, 0.01, -0.02, 0.003, 0.0, 0.0, 0.0, 0.0, 0.0],
        [rigid.CIRCLE, *e1, 0.0, 1.0, 0.0, 0.01, 2 * np.pi * 1.5],
    ])
    axis = np.array([0.0, 0.6, 0.8])
    start = rng.normal(size=3)
    pose = np.zeros(13)
    pose[3] = 1.0
    twin = pose.copy()
    buffer = np.zeros((2, 3))
    acc = np.array([0.0, 0.0, -9.81])
    for k in range(100):
        wrench = rng.normal(size=6)
        rigid.guided_step(pose, wrench, 2.0, acc, axis, start, terms, k * 1e-3, 1e-3, buffer)
        reference.guided_step(twin, wrench, 2.0, acc, axis, start, terms, k * 1e-3, 1e-3)
        assert _close(pose, twin), k
    # the path's own motion across the axis is exact: compare with the closed form
    t = 100e-3
    expected = (start + 5e-5 * np.sin(2 * np.pi * 10.0 * t) * np.array([0.6, 0.8, 0.0])
                + t * np.array([0.01, -0.02, 0.003])
                + 0.01 * np.array([np.cos(3 * np.pi * t), np.sin(3 * np.pi * t), 0.0]))
    across = np.eye(3) - np.outer(axis, axis)
    np.testing.assert_allclose(across @ pose[0:3], across @ expected, rtol=0, atol=1e-15)


def test_reversal_exactly_on_a_step_starts_stick_despite_a_dip_in_load():
    """A turning point on a step leaves only round-off slip velocity; a round-off
    dip of N must not break the new stick (it would skip a whole Jenkins branch)."""
    vertices = np.zeros((1, 3))
    pose = np.zeros(13)
    pose[3] = 1.0
    pose[2] = -1e-6
    planes = np.zeros((1, 4, 3))
    planes[0, 1, 2] = 1.0
    c = 1e6
    law = contact.make_law(friction=0.3, static_friction=0.3, wear_law="energy",
                           wear_coefficient=0.0, dt=1e-5, stiffness=c, tangential_stiffness=c)
    a = dict(contact_state=np.zeros((1, 1), np.int8), tangential=np.zeros((1, 1, 4, 3)),
             normal_force=np.zeros((1, 1)), friction_work=np.zeros(1), wear_depth=np.zeros(1),
             wear_volume=np.zeros(1), wrench=np.zeros(6))
    args = (vertices, pose, planes, FACING_DOWN, law, np.zeros((0, 3)))
    # slide along +x until slipping
    for k in range(10):
        pose[0] = 1e-6 * k
        pose[7] = 1e-3
        _call(contact.contact, *args, a)
    assert a["contact_state"][0, 0] == contact.SLIP
    # turning point: round-off velocity against the motion, and N a hair lower
    pose[2] = -1e-6 * (1 - 1e-12)
    pose[7] = -1e-20
    _call(contact.contact, *args, a)
    assert a["contact_state"][0, 0] == contact.STICK
    twin = {k: v.copy() for k, v in a.items()}
    # and the twin agrees on the same step
    a2 = dict(contact_state=np.zeros((1, 1), np.int8), tangential=np.zeros((1, 1, 4, 3)),
              normal_force=np.zeros((1, 1)), friction_work=np.zeros(1), wear_depth=np.zeros(1),
              wear_volume=np.zeros(1), wrench=np.zeros(6))
    pose[2] = -1e-6
    for k in range(10):
        pose[0] = 1e-6 * k
        pose[7] = 1e-3
        _call(reference.contact, vertices.copy(), pose, planes, FACING_DOWN, law,
              np.zeros((0, 3)), a2)
    pose[2] = -1e-6 * (1 - 1e-12)
    pose[7] = -1e-20
    _call(reference.contact, vertices.copy(), pose, planes, FACING_DOWN, law,
          np.zeros((0, 3)), a2)
    assert a2["contact_state"][0, 0] == contact.STICK
    assert _close(a2["tangential"], twin["tangential"])


@pytest.mark.parametrize("load", [3.0, 0.02, -1.5])
@pytest.mark.parametrize("opposed", [False, True])
@pytest.mark.parametrize("scaled", [False, True])
def test_balance_offset_matches_numpy_twin(load, opposed, scaled):
    """Bracketed Newton against the sorted piecewise-linear solve: a random
    point cloud between planes tilted about the free axis (and, when
    ``opposed``, one facing the other way: g then is not convex)."""
    from meshwear.kernels.balance import balance_offset

    rng = np.random.default_rng(11)
    vertices, pose, planes, params, law, direction, arrays = _random_case(rng, 300, 2, 0, False)
    if opposed:
        planes[1, 1] = -planes[1, 1]
        planes[1, 0, 2] += 0.03
        params[150:, 0:3] = -params[150:, 0:3]   # the upper half faces up
    law[6] = 3e10  # per-area normal stiffness on top of the per-point one
    axis = np.array([0.1, -0.2, 1.0])
    axis /= np.linalg.norm(axis)
    # the second plane as a mesh surface would give it: one plane per vertex,
    # tilted a little differently under each; every third vertex inactive
    vertex_planes = np.repeat(planes[1:2, None, :3], 300, axis=1).copy()
    tilt = vertex_planes[0, :, 1] + rng.normal(scale=0.02, size=(300, 3))
    vertex_planes[0, :, 1] = tilt / np.linalg.norm(tilt, axis=1)[:, None]
    planes = planes[:1]
    active = np.flatnonzero(np.arange(300) % 3 != 0)
    args = (vertices, pose, axis, planes, vertex_planes, active, params, law, load)
    # a wear jump scales each vertex's stiffness by 1 / (1 + J alpha_i)
    scale = 1.0 / (1.0 + rng.uniform(0.0, 30.0, 300)) if scaled else np.zeros(0)
    expected = reference.balance_offset(*args, scale if scaled else None)
    scratch = np.zeros((2, 600))
    if not opposed and load < 0.0:
        # every plane faces the body from below: nothing can pull it down
        assert np.isnan(expected)
        assert np.isnan(balance_offset(*args, 0.0, scratch, scale))
        return
    for guess in (0.0, -0.05, 0.05, expected):
        z = balance_offset(*args, guess, scratch, scale)
        assert z == pytest.approx(expected, rel=1e-12, abs=1e-15)
    if scaled:
        return
    # the force at the solution is the load
    moved = pose.copy()
    moved[0:3] += z * axis
    s = {k: v.copy() for k, v in arrays.items()}
    moved[7:13] = 0.0
    static = law.copy()
    static[[7, 8, 11, 12]] = 0.0   # no damping, and planes at rest: only normal forces
    resting, resting_vertex = planes.copy(), vertex_planes.copy()
    resting[:, 2:4] = resting_vertex[:, :, 2:4] = 0.0   # nor turning: no slip in the step
    s.update(vertex_planes=resting_vertex, active=active)
    _call(reference.contact, vertices.copy(), moved, resting, params, static, direction, s)
    assert s["wrench"][0:3] @ axis == pytest.approx(load, rel=1e-9)


def test_balance_offset_refuses_a_load_nothing_can_carry():
    from meshwear.kernels.balance import balance_offset

    vertices = np.array([[0.0, 0.0, 0.0]])
    pose = np.zeros(13)
    pose[3] = 1.0
    planes = np.zeros((1, 4, 3))
    planes[0, 1, 2] = 1.0
    law = contact.make_law(friction=0.3, static_friction=0.3, wear_law="energy",
                           wear_coefficient=0.0, dt=1e-5, stiffness=1e6)
    up = np.array([0.0, 0.0, 1.0])
    scratch = np.zeros((2, 1))
    none, one = contact.no_mesh_planes(1), contact.all_vertices(1)
    # a plane under the point carries a load pressing down (contact pushes +z) ...
    assert balance_offset(vertices, pose, up, planes, none, one, FACING_DOWN, law, 2.0, 0.0,
                          scratch, np.zeros(0)) == pytest.approx(-2e-6)
    # ... but nothing can pull it down: a load along -z has no carrier
    assert np.isnan(balance_offset(vertices, pose, up, planes, none, one, FACING_DOWN, law, -2.0,
                                   0.0, scratch, np.zeros(0)))
    # and a free axis lying in the plane has no normal-force component at all
    assert np.isnan(balance_offset(vertices, pose, np.array([1.0, 0.0, 0.0]), planes, none, one,
                                   FACING_DOWN, law, 2.0, 0.0, scratch, np.zeros(0)))


def test_a_reversal_step_longer_than_the_unloading_slips_again_at_once():
    """A stiff spring and a coarse step: the step a slip reverses in carries
    the point past the whole stick branch (2 f N / c_t), so it slips again in
    that step, in the new direction, and its slip counts as dissipation."""
    vertices = np.zeros((1, 3))
    pose = np.zeros(13)
    pose[3] = 1.0
    pose[2] = -1e-6
    planes = np.zeros((1, 4, 3))
    planes[0, 1, 2] = 1.0
    c = 1e6
    law = contact.make_law(friction=0.5, static_friction=0.5, wear_law="energy",
                           wear_coefficient=0.0, dt=1e-3, stiffness=c, tangential_stiffness=c)
    a = dict(contact_state=np.zeros((1, 1), np.int8), tangential=np.zeros((1, 1, 4, 3)),
             normal_force=np.zeros((1, 1)), friction_work=np.zeros(1), wear_depth=np.zeros(1),
             wear_volume=np.zeros(1), wrench=np.zeros(6))
    args = (vertices, pose, planes, FACING_DOWN, law, np.zeros((0, 3)))
    for k in range(4):                        # 2 µm steps along +x: slips at f N = 0.5 N
        pose[0], pose[7] = 2e-6 * k, 2e-3
        _call(contact.contact, *args, a)
    assert a["contact_state"][0, 0] == contact.SLIP
    work = a["friction_work"][0]
    pose[0], pose[7] = 3e-6, -3e-3             # back 3 µm: unloading takes 2 f N / c = 1 µm
    _call(contact.contact, *args, a)
    assert a["contact_state"][0, 0] == contact.SLIP
    assert a["tangential"][0, 0, 2, 0] == pytest.approx(0.5)
    assert a["friction_work"][0] - work == pytest.approx(0.5 * 3e-6)
    # a turning point with only round-off motion keeps the stick branch
    pose[7] = 1e-20
    _call(contact.contact, *args, a)
    assert a["contact_state"][0, 0] == contact.STICK


def test_a_steady_turn_matches_its_numpy_twin():
    """rigid.turn: the orientation turned by rate t about the axis, the
    angular velocity rate axis, and the centre of mass carried round the
    turn's centre (less its component along a free axis)."""
    from meshwear.kernels import rigid
    from meshwear.surfaces.base import axis_rotation, quaternion_matrix

    rng = np.random.default_rng(3)
    for free in (np.zeros(3), np.array([0.0, 0.6, 0.8])):
        params = np.zeros(rigid.MOTION_PARAMS)
        q0 = rng.normal(size=4)
        q0 /= np.linalg.norm(q0)
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        start, centre = rng.normal(size=3), rng.normal(size=3)
        params[rigid.ORIENTATION], params[rigid.TURN_AXIS] = q0, axis
        params[rigid.TURN_RATE], params[rigid.TURN_CENTER] = 3.0, centre
        params[rigid.START] = start
        for t in (0.0, 0.4, 1.7):
            pose = np.zeros(13)
            pose[0:3] = start
            rigid.turn(pose, params, free, t)
            R = axis_rotation(axis, 3.0 * t)
            np.testing.assert_allclose(quaternion_matrix(pose[3:7]), R @ quaternion_matrix(q0),
                                       atol=1e-12)
            np.testing.assert_allclose(pose[10:13], 3.0 * axis, atol=1e-15)
            moved = R @ (start - centre) + centre - start
            speed = np.cross(3.0 * axis, R @ (start - centre))
            np.testing.assert_allclose(pose[0:3], start + moved - (moved @ free) * free,
                                       atol=1e-12)
            np.testing.assert_allclose(pose[7:10], speed - (speed @ free) * free, atol=1e-12)


@pytest.mark.parametrize("kernel", [contact.contact_serial, reference.contact])
def test_a_point_touching_down_on_a_sliding_surface_slips_in_its_first_step(kernel):
    """A new contact is anchored where it came into contact, at the step's
    start (docs/model.md, transitions, rule 1): a point touching down on a
    plane that slides under it at v stretches its spring by v dt in that
    step and slips at once, wearing, where c_t v dt > f0 N; one touching
    down at rest holds (no force, no wear)."""
    dt, v, c = 1e-3, 0.01, 1e6                        # c_t v dt = 10 N, f0 N = 0.5 N
    law = contact.make_law(friction=0.4, static_friction=0.5, wear_law="archard",
                           wear_coefficient=1e-13, dt=dt, stiffness=c, tangential_stiffness=c)
    vertices = np.zeros((1, 3))
    params = np.array([[0.0, 0.0, -1e-6, 1e-6]])      # its area faces the plane below
    out = {}
    for speed in (v, 0.0):
        pose = np.zeros(13)
        pose[2], pose[3] = -1e-6, 1.0                  # 1 um into the plane z = 0: N = 1 N
        planes = np.zeros((1, 4, 3))
        planes[0, 1] = [0.0, 0.0, 1.0]
        planes[0, 2] = [speed, 0.0, 0.0]               # the plane slides along x
        a = dict(contact_state=np.zeros((1, 1), np.int8), tangential=np.zeros((1, 1, 4, 3)),
                 normal_force=np.zeros((1, 1)), friction_work=np.zeros(1),
                 wear_depth=np.zeros(1), wear_volume=np.zeros(1), wrench=np.zeros(6))
        _call(kernel, vertices, pose, planes, params, law, np.zeros((0, 3)), a)
        out[speed] = a
    sliding, resting = out[v], out[0.0]
    assert sliding["normal_force"][0, 0] == pytest.approx(1.0)
    assert sliding["contact_state"][0, 0] == contact.SLIP
    assert sliding["tangential"][0, 0, contact.FORCE] == pytest.approx([0.4, 0.0, 0.0])
    assert sliding["wear_depth"][0] > 0.0 and sliding["friction_work"][0] == pytest.approx(
        0.4 * 1.0 * v * dt)
    assert resting["contact_state"][0, 0] == contact.STICK
    assert resting["wear_depth"][0] == 0.0 and not resting["tangential"][0, 0, contact.FORCE].any()


@pytest.mark.parametrize("n_planes", [1, 2])
def test_the_threaded_kernel_gives_the_serial_results_bit_for_bit(n_planes):
    """The threaded kernel runs the serial build on pieces of the active set
    (docs/performance.md, "The first run compiles"): every vertex's results
    are the serial ones to the last bit, over several pieces and steps, and
    the wrench is the sum of the same terms (added piece by piece)."""
    n = 8 * contact.CHUNK + 37                  # eight pieces, of unequal length
    assert contact.pieces(n) == 8
    rng = np.random.default_rng(5 + n_planes)
    vertices, pose, planes, params, law, direction, arrays = _random_case(
        rng, n, n_planes, contact.ENERGY, False)
    arrays["active"] = np.flatnonzero(np.arange(n) % 7 != 3)
    runs = []
    for kernel in (contact.contact_serial, contact.contact_parallel):
        v, a = vertices.copy(), {k: x.copy() for k, x in arrays.items()}
        for _ in range(3):
            _call(kernel, v, pose, planes, params, law, direction, a)
        runs.append((v, a))
    (v0, a0), (v1, a1) = runs
    assert np.count_nonzero(a0["contact_state"]) > n // 10      # many in contact
    assert np.array_equal(v0, v1)
    for name in ("contact_state", "tangential", "normal_force", "friction_work", "wear_depth",
                 "wear_volume"):
        assert np.array_equal(a0[name], a1[name]), name
    assert np.allclose(a1["wrench"], a0["wrench"], rtol=1e-12,
                       atol=1e-12 * np.abs(a0["wrench"]).max())
