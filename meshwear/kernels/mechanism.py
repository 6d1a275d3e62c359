"""The coupling of worn parts with a MuJoCo mechanism (:mod:`meshwear.mechanism`),
on MuJoCo's own arrays (``xpos``, ``xquat``, ``xmat``, ``cvel``,
``subtree_com``, ``xipos``, ``xfrc_applied``, ``body_rootid``): the parts
placed where their bodies are, the contact wrenches applied to the bodies,
and the reaction of a counter-surface (the force of one contact slot on a
worn body, summed over its active vertices, and its moment about the world
origin). Twins in tests/test_mechanism.py."""

import numpy as np
from .jit import njit

from .contact import FORCE, _named_copy, rotation_entries
from .frames import moved_since_refresh, step_motion
from .loop import DONE, REFRESH, advance_body
from .rigid import STEADY, quaternion_product


@njit(cache=True)
def slot_wrench(pose, vertices, active, normal_force, tangential, planes, vertex_planes, slot,
                out):
    """Fill ``out`` (6,) with the force (N) counter-surface ``slot`` exerts on
    a body (normal force along the plane's normal plus the friction force, at
    each active vertex in contact) and its moment about the world origin
    (N·m, each force at its vertex). Arrays as in
    :func:`meshwear.kernels.contact.contact`; ``planes`` (P, 4, 3) the
    uniform planes (slots ``< P``), ``vertex_planes`` (M, n, 3, 3) the
    others'."""
    for j in range(6):
        out[j] = 0.0
    r = rotation_entries(pose[3:7])
    P = planes.shape[0]
    for a in range(active.shape[0]):
        i = active[a]
        load = normal_force[slot, i]
        if load <= 0.0:
            continue
        if slot < P:
            nx, ny, nz = planes[slot, 1, 0], planes[slot, 1, 1], planes[slot, 1, 2]
        else:
            nx = vertex_planes[slot - P, i, 1, 0]
            ny = vertex_planes[slot - P, i, 1, 1]
            nz = vertex_planes[slot - P, i, 1, 2]
        fx = load * nx + tangential[slot, i, FORCE, 0]
        fy = load * ny + tangential[slot, i, FORCE, 1]
        fz = load * nz + tangential[slot, i, FORCE, 2]
        bx, by, bz = vertices[i, 0], vertices[i, 1], vertices[i, 2]
        x = pose[0] + r[0] * bx + r[1] * by + r[2] * bz
        y = pose[1] + r[3] * bx + r[4] * by + r[5] * bz
        z = pose[2] + r[6] * bx + r[7] * by + r[8] * bz
        out[0] += fx
        out[1] += fy
        out[2] += fz
        out[3] += y * fz - z * fy
        out[4] += z * fx - x * fz
        out[5] += x * fy - y * fx


@njit(cache=True, inline="always")
def _body_velocity(xpos, cvel, subtree_com, rootid, body):
    """Velocity of the origin of MuJoCo body ``body``'s frame and its angular
    velocity (world), from MuJoCo's com-based velocities ``cvel`` (rotation,
    translation at the centre of mass of the body's kinematic tree)."""
    root = rootid[body]
    wx, wy, wz = cvel[body, 0], cvel[body, 1], cvel[body, 2]
    dx = xpos[body, 0] - subtree_com[root, 0]
    dy = xpos[body, 1] - subtree_com[root, 1]
    dz = xpos[body, 2] - subtree_com[root, 2]
    return (cvel[body, 3] + wy * dz - wz * dy, cvel[body, 4] + wz * dx - wx * dz,
            cvel[body, 5] + wx * dy - wy * dx, wx, wy, wz)


@njit(cache=True)
def place_body(xpos, xquat, xmat, cvel, subtree_com, rootid, body, placement, pose):
    """``pose`` (13,) of a part placed at ``placement`` (13,: its centre of
    mass and orientation in the frame of MuJoCo body ``body``) where MuJoCo's
    last kinematics have that body: centre of mass, quaternion, velocity and
    angular velocity, world frame."""
    vx, vy, vz, wx, wy, wz = _body_velocity(xpos, cvel, subtree_com, rootid, body)
    px, py, pz = placement[0], placement[1], placement[2]
    ax = xmat[body, 0] * px + xmat[body, 1] * py + xmat[body, 2] * pz
    ay = xmat[body, 3] * px + xmat[body, 4] * py + xmat[body, 5] * pz
    az = xmat[body, 6] * px + xmat[body, 7] * py + xmat[body, 8] * pz
    pose[0] = xpos[body, 0] + ax
    pose[1] = xpos[body, 1] + ay
    pose[2] = xpos[body, 2] + az
    qw, qx, qy, qz = quaternion_product(xquat[body, 0], xquat[body, 1], xquat[body, 2],
                                        xquat[body, 3], placement[3], placement[4],
                                        placement[5], placement[6])
    norm = np.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
    pose[3], pose[4], pose[5], pose[6] = qw / norm, qx / norm, qy / norm, qz / norm
    pose[7] = vx + wy * az - wz * ay
    pose[8] = vy + wz * ax - wx * az
    pose[9] = vz + wx * ay - wy * ax
    pose[10], pose[11], pose[12] = wx, wy, wz


@njit(cache=True)
def place_surface(xpos, xmat, cvel, subtree_com, rootid, body, rest, t, motion, terms, world):
    """Write a counter-surface's ``motion`` (19,) and path ``terms`` (1, 9)
    (:mod:`meshwear.kernels.frames`) so its frame at ``t``, and the velocity
    field about it, are those of MuJoCo body ``body`` with the surface at
    ``rest`` (12,: rotation row by row, then position, in the body's frame):
    a steady turn at the body's angular velocity and a steady velocity; and
    ``world`` (12,) its frame at ``t`` (rotation row by row, origin)."""
    vx, vy, vz, wx, wy, wz = _body_velocity(xpos, cvel, subtree_com, rootid, body)
    R = xmat[body]
    # the surface's frame in the world: Rw = R Rc, origin p + R pc
    px, py, pz = rest[9], rest[10], rest[11]
    ax = R[0] * px + R[1] * py + R[2] * pz
    ay = R[3] * px + R[4] * py + R[5] * pz
    az = R[6] * px + R[7] * py + R[8] * pz
    ux = vx + wy * az - wz * ay
    uy = vy + wz * ax - wx * az
    uz = vz + wx * ay - wy * ax
    rate = np.sqrt(wx * wx + wy * wy + wz * wz)
    if rate > 0.0:
        ex, ey, ez = wx / rate, wy / rate, wz / rate
    else:
        ex, ey, ez = 0.0, 0.0, 1.0
    # R0 = Rot(e, -rate t) Rw, so that Rot(e, rate t) R0 = Rw at t
    c, s = np.cos(-rate * t), np.sin(-rate * t)
    k = 1.0 - c
    turn = (c + k * ex * ex, k * ex * ey - s * ez, k * ex * ez + s * ey,
            k * ex * ey + s * ez, c + k * ey * ey, k * ey * ez - s * ex,
            k * ex * ez - s * ey, k * ey * ez + s * ex, c + k * ez * ez)
    for r in range(3):
        for col in range(3):
            motion[3 * r + col] = (R[3 * r] * rest[col] + R[3 * r + 1] * rest[3 + col]
                                   + R[3 * r + 2] * rest[6 + col])
    for j in range(9):
        world[j] = motion[j]
    for col in range(3):
        a0, a1, a2 = motion[col], motion[3 + col], motion[6 + col]
        for r in range(3):
            motion[3 * r + col] = turn[3 * r] * a0 + turn[3 * r + 1] * a1 + turn[3 * r + 2] * a2
    world[9], world[10], world[11] = xpos[body, 0] + ax, xpos[body, 1] + ay, xpos[body, 2] + az
    sx = xpos[body, 0] + ax - ux * t
    sy = xpos[body, 1] + ay - uy * t
    sz = xpos[body, 2] + az - uz * t
    motion[9], motion[10], motion[11] = sx, sy, sz
    motion[12], motion[13], motion[14] = ex, ey, ez
    motion[15] = rate
    motion[16], motion[17], motion[18] = sx, sy, sz
    for j in range(9):
        terms[0, j] = 0.0
    terms[0, 0] = STEADY
    terms[0, 1], terms[0, 2], terms[0, 3] = ux, uy, uz


@njit(cache=True)
def rider_shift(world, ref, levers, rows, row_terms, dt):
    """Upper bound (m) on how far a point of any counter-surface riding on
    the mechanism has moved since a body's active set was refreshed (its
    frames then, ``ref`` (S, 12), against ``world`` (S, 12) now; ``levers``
    (S,) the farthest of its points from its frame's origin), plus one step
    of its motion (``rows``, ``row_terms``: its angular and linear velocity):
    the origin's displacement plus the lever times the rotation's change
    (its Frobenius norm bounds how far it moves a unit vector)."""
    out = 0.0
    for r in range(world.shape[0]):
        d0 = world[r, 9] - ref[r, 9]
        d1 = world[r, 10] - ref[r, 10]
        d2 = world[r, 11] - ref[r, 11]
        turned = 0.0
        for j in range(9):
            turned += (world[r, j] - ref[r, j]) ** 2
        u = row_terms[r, 0]
        speed = np.sqrt(u[1] * u[1] + u[2] * u[2] + u[3] * u[3]) + abs(rows[r, 15]) * levers[r]
        out = max(out, np.sqrt(d0 * d0 + d1 * d1 + d2 * d2) + levers[r] * np.sqrt(turned)
                  + speed * dt)
    return out


@njit(cache=True)
def needs_refresh(body, bounds, terms, t, dt, buffer, world, ref, levers, rows, row_terms):
    """The active set of a body on a mechanism must be refreshed before the
    step at ``t``: :func:`meshwear.kernels.loop._needs_refresh`, with the
    moves of the counter-surfaces riding on the mechanism measured since its
    refresh (:func:`rider_shift`) instead of foreseen."""
    pose, wear_depth, active, active_wear, cull, radius = (body[1], body[9], body[14], body[15],
                                                           body[16], body[19])
    if cull[0] == 0.0:
        return True
    return (moved_since_refresh(pose, cull, radius, bounds, terms, t, wear_depth, active,
                                active_wear, buffer)
            + step_motion(pose, radius, bounds, terms, t, dt, buffer)
            + rider_shift(world, ref, levers, rows, row_terms, dt) >= cull[0])


@njit(cache=True)
def push_body(xipos, xfrc, body, pose, wrench):
    """Add a worn body's contact ``wrench`` (force and torque about its centre
    of mass ``pose[0:3]``) to MuJoCo body ``body``'s applied force and torque
    at that body's centre of mass ``xipos``."""
    fx, fy, fz = wrench[0], wrench[1], wrench[2]
    dx = pose[0] - xipos[body, 0]
    dy = pose[1] - xipos[body, 1]
    dz = pose[2] - xipos[body, 2]
    xfrc[body, 0] += fx
    xfrc[body, 1] += fy
    xfrc[body, 2] += fz
    xfrc[body, 3] += wrench[3] + dy * fz - dz * fy
    xfrc[body, 4] += wrench[4] + dz * fx - dx * fz
    xfrc[body, 5] += wrench[5] + dx * fy - dy * fx


@njit(cache=True)
def push_reaction(xipos, xfrc, body, wrench):
    """Subtract a slot's ``wrench`` on the bodies (force, moment about the
    world origin: :func:`slot_wrench`) from MuJoCo body ``body``'s applied
    force and torque at its centre of mass: the counter-surface's reaction."""
    fx, fy, fz = wrench[0], wrench[1], wrench[2]
    cx, cy, cz = xipos[body, 0], xipos[body, 1], xipos[body, 2]
    xfrc[body, 0] -= fx
    xfrc[body, 1] -= fy
    xfrc[body, 2] -= fz
    xfrc[body, 3] -= wrench[3] - (cy * fz - cz * fy)
    xfrc[body, 4] -= wrench[4] - (cz * fx - cx * fz)
    xfrc[body, 5] -= wrench[5] - (cx * fy - cy * fx)


def _advance_mechanism(k, stop, dt, calls, m, d, mj, bodies, motions, body_riders, placements,
                      surface_riders, rests, rows, row_terms, cull, world, refs, levers, planes,
                      surfaces, bounds, terms, report):
    """Steps ``k`` up to ``stop`` of a mechanism and every body, without
    returning to Python (:meth:`meshwear.mechanism.Mechanism.step` is the
    reference it must match to the last bit). Returns ``(step, what, body)``:
    :data:`meshwear.kernels.loop.DONE`, or the loop's code for ``body`` at
    ``step`` (a counter vertex worn too deep, a load nothing carries), MuJoCo
    having taken that step's ``mj_step1`` only.

    calls
        MuJoCo's ``mj_step1``, ``mj_step2``, ``mj_kinematics``, ``mj_comPos``,
        ``mj_comVel`` (C function pointers) and ``m``, ``d`` the addresses
        of its ``mjModel`` and ``mjData``.
    mj
        Its arrays ``xpos``, ``xquat``, ``xmat``, ``cvel``, ``subtree_com``,
        ``xipos``, ``xfrc_applied``, ``body_rootid``.
    bodies, motions
        Every body's ``body`` and ``motion`` tuples (:mod:`meshwear.kernels.loop`).
    body_riders, placements
        (R, 2) body index and MuJoCo body of each worn body on the
        mechanism, and (R, 13) its placement in that body's frame.
    surface_riders, rests, rows, row_terms
        (S, 2) contact slot and MuJoCo body of each counter-surface on the
        mechanism, (S, 12) its rest frame in that body's, and the (S, 19)
        motions and (S, 1, 9) terms the surfaces' tuples read (a uniform
        plane's are copied into ``planes``).
    cull, world, refs, levers
        Whether bodies keep active sets; (S, 12) each riding surface's frame now, (B, S, 12) its frames at
        each body's last active-set refresh and (S,) its lever
        (:func:`rider_shift`): a body whose active set must be refreshed
        before step ``k`` stops the loop there, with nothing of the step
        done (:data:`meshwear.kernels.loop.REFRESH`).
    """
    xpos, xquat, xmat, cvel, com, xipos, xfrc, rootid = mj
    mj_step1, mj_step2, kinematics, com_pos, com_vel = calls
    n_planes = planes[0].shape[0]
    wrench = np.zeros(6)
    buffer = np.zeros((2, 3))
    while k < stop:
        for b in range(len(bodies)):
            if cull and needs_refresh(bodies[b], bounds, terms, k * dt, dt, buffer, world,
                                      refs[b], levers, rows, row_terms):
                return k, REFRESH, b
        mj_step1(m, d)
        for b in range(len(bodies)):
            reached, what = advance_body(k, k + 1, dt, False, False, bodies[b], motions[b],
                                         planes, surfaces, bounds, terms, report)
            if what != DONE:
                return k, what, b
        for j in range(6 * xfrc.shape[0]):
            xfrc.flat[j] = 0.0
        for r in range(body_riders.shape[0]):
            body = bodies[body_riders[r, 0]]
            push_body(xipos, xfrc, body_riders[r, 1], body[1], body[11])
        for r in range(surface_riders.shape[0]):
            for b in range(len(bodies)):
                body = bodies[b]
                slot_wrench(body[1], body[0], body[14], body[7], body[6], planes[0], body[12],
                            surface_riders[r, 0], wrench)
                push_reaction(xipos, xfrc, surface_riders[r, 1], wrench)
        mj_step2(m, d)
        kinematics(m, d)
        com_pos(m, d)
        com_vel(m, d)
        k += 1
        t = k * dt
        for r in range(body_riders.shape[0]):
            place_body(xpos, xquat, xmat, cvel, com, rootid, body_riders[r, 1],
                       placements[r], bodies[body_riders[r, 0]][1])
        for r in range(surface_riders.shape[0]):
            place_surface(xpos, xmat, cvel, com, rootid, surface_riders[r, 1], rests[r], t,
                          rows[r], row_terms[r], world[r])
            slot = surface_riders[r, 0]
            if slot < n_planes:
                for j in range(19):
                    planes[1][slot, j] = rows[r, j]
                for j in range(9):
                    planes[2][slot, 0, j] = row_terms[r, 0, j]
    return k, DONE, -1


#: the builds made so far, by the step loop's build they call
_MECHANISM_LOOPS = {}


def mechanism_loop(loop=advance_body):
    """:func:`advance_mechanism` calling the step loop's build ``loop``
    (:func:`meshwear.kernels.loop.loop_for`), made once and cached on disk
    under a name of its own."""
    name = loop.py_func.__qualname__.replace("advance_body", "advance_mechanism", 1)
    if name not in _MECHANISM_LOOPS:
        _MECHANISM_LOOPS[name] = njit(cache=True)(_named_copy(_advance_mechanism, name,
                                                              advance_body=loop))
    return _MECHANISM_LOOPS[name]


#: the one that calls the full loop
advance_mechanism = mechanism_loop()
