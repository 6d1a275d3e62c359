"""Quasi-static torque balance of a guided body about its turn's axis.

A body that turns about the unit axis ``a`` through ``c`` (its path's
steady turn, docs/model.md "Quasi-static mode") and carries an applied
torque ``T`` about ``a`` turns, besides its path's ``rate t``, by the
settled angle ``phi`` at which the contact normal forces' torque about the
axis balances ``T``. Turning the body by a small ``phi`` moves vertex ``i``
by ``phi a x r_i`` (``r_i = x_i - c``), which changes its penetration on a
plane of normal ``n`` by ``-phi beta_i``, ``beta_i = n . (a x r_i)``; the
normal force ``f_i n`` has the torque ``f_i beta_i`` about the axis. So the
contact torque is

    g(phi) = sum over touching pairs of  c_i beta_i max(0, -Delta_i - phi beta_i),

the translational balance's form (:mod:`meshwear.kernels.balance`) with a
``beta`` per pair instead of per plane: piecewise linear and never
increasing, solved by the same bracketed Newton (:func:`balance._near`,
:func:`balance.solve`) with ``load = -T``.

The move is a rotation, not a translation along a line, so the solve is a
linearisation about the pose it starts from: the body is turned by the
``phi`` found (exactly, about the axis), the pairs are evaluated again at
that pose, and the correction solved, until a pass moves it by less than
:data:`SETTLED_ANGLE` (the second-order error of a pass, ``|r| phi^2 / 2``,
is then below 10^-14 m per metre of lever). Each step starts from the
angle the last one settled to (``params[SETTLED]``), so one pass, rarely
two, is the usual cost.

Friction does not enter the balance (as in the translational one): its
torque is the stick/slip state machine's, which depends on the history of
the step's tangential displacements; docs/model.md says what that leaves out.
"""

import numpy as np
from .jit import njit

from .balance import _near, solve
from .contact import FACING, rotation_entries
from .rigid import (CARRIED, ORIENTATION, SETTLED, TURN_AXIS, TURN_CENTER, TURN_RATE, path_point,
                    quaternion_product)

#: a pass that turns the body by less than this (rad) ends the settling
SETTLED_ANGLE = 1e-7
#: passes of the linearised solve at most (the start of a run, from a guess
#: far off, takes a few; a step one or two)
MAX_PASSES = 12
#: a pass that would turn the body by more than this (rad) finds no balance:
#: the linearisation holds for small turns, and a pair that touches only
#: that far off (a gear out of mesh, its mate's faces seen from afar) is not
#: a contact that carries the torque
MAX_TURN = 0.1


@njit(cache=True)
def _turn_pairs(body_vertices, pose, axis, center, planes, vertex_planes, active, area, law,
                breakpoint, weight):
    """Fill ``breakpoint`` (phi_j, rad) and ``weight`` (c_j beta_j^2 signed
    as beta_j, N·m) of every pair that can touch; return how many, and g and
    its slope magnitude at phi = 0 (the pose as it is)."""
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rotation_entries(pose[3:7])
    c0, c1 = law[5], law[6]
    ax, ay, az = axis[0], axis[1], axis[2]
    n_planes = planes.shape[0]
    count = 0
    g = 0.0
    slope = 0.0
    for s in range(n_planes + vertex_planes.shape[0]):
        m = s - n_planes
        for k in range(active.shape[0]):
            i = active[k]
            if s < n_planes:
                ox, oy, oz = planes[s, 0, 0], planes[s, 0, 1], planes[s, 0, 2]
                nx, ny, nz = planes[s, 1, 0], planes[s, 1, 1], planes[s, 1, 2]
            else:
                ox, oy = vertex_planes[m, i, 0, 0], vertex_planes[m, i, 0, 1]
                oz = vertex_planes[m, i, 0, 2]
                nx, ny = vertex_planes[m, i, 1, 0], vertex_planes[m, i, 1, 1]
                nz = vertex_planes[m, i, 1, 2]
            if nx == 0.0 and ny == 0.0 and nz == 0.0:
                continue
            mx = r00 * nx + r10 * ny + r20 * nz
            my = r01 * nx + r11 * ny + r21 * nz
            mz = r02 * nx + r12 * ny + r22 * nz
            a = -(mx * area[i, 0] + my * area[i, 1] + mz * area[i, 2])
            if a <= FACING * area[i, 3]:
                continue
            c = c0 + c1 * a
            if c <= 0.0:
                continue
            bx, by, bz = body_vertices[i, 0], body_vertices[i, 1], body_vertices[i, 2]
            px = pose[0] + r00 * bx + r01 * by + r02 * bz
            py = pose[1] + r10 * bx + r11 * by + r12 * bz
            pz = pose[2] + r20 * bx + r21 * by + r22 * bz
            # beta = n . (a x r): the penetration lost per radian turned
            rx, ry, rz = px - center[0], py - center[1], pz - center[2]
            beta = (nx * (ay * rz - az * ry) + ny * (az * rx - ax * rz)
                    + nz * (ax * ry - ay * rx))
            if beta == 0.0:
                continue
            delta = (px - ox) * nx + (py - oy) * ny + (pz - oz) * nz
            z = -delta / beta
            w = c * beta * beta * (1.0 if beta > 0.0 else -1.0)
            breakpoint[count] = z
            weight[count] = w
            if (w > 0.0 and 0.0 < z) or (w < 0.0 and 0.0 > z):
                g += abs(w) * z
                slope += abs(w)
            count += 1
    return count, g, slope


@njit(cache=True)
def balance_angle(body_vertices, pose, axis, center, planes, vertex_planes, active, area, law,
                  load, scratch):
    """The angle (rad, about ``axis`` through ``center``) by which the body
    at ``pose`` turns to where its contacts' normal forces have the torque
    ``load`` (N·m) about the axis, linearised about ``pose``; NaN when no
    contact can. ``scratch`` (2, k S) as for
    :func:`meshwear.kernels.balance.balance_offset`."""
    breakpoint, weight = scratch[0], scratch[1]
    count, g, slope = _turn_pairs(body_vertices, pose, axis, center, planes, vertex_planes,
                                  active, area, law, breakpoint, weight)
    count, bound = _near(breakpoint, weight, count, load, 0.0, g, slope)
    return solve(breakpoint, weight, count, load, 0.0, bound)


@njit(cache=True)
def turn_pose(pose, axis, center, angle):
    """Turn ``pose`` (its orientation and centre of mass) by ``angle`` (rad)
    about the unit ``axis`` through ``center``, in place."""
    half = 0.5 * angle
    c, s = np.cos(half), np.sin(half)
    w, x, y, z = quaternion_product(c, s * axis[0], s * axis[1], s * axis[2],
                                    pose[3], pose[4], pose[5], pose[6])
    norm = np.sqrt(w * w + x * x + y * y + z * z)
    pose[3], pose[4], pose[5], pose[6] = w / norm, x / norm, y / norm, z / norm
    # Rodrigues: r cos + (a x r) sin + a (a . r)(1 - cos)
    rx, ry, rz = pose[0] - center[0], pose[1] - center[1], pose[2] - center[2]
    ca, sa = np.cos(angle), np.sin(angle)
    along = axis[0] * rx + axis[1] * ry + axis[2] * rz
    cx = axis[1] * rz - axis[2] * ry
    cy = axis[2] * rx - axis[0] * rz
    cz = axis[0] * ry - axis[1] * rx
    pose[0] = center[0] + rx * ca + cx * sa + axis[0] * along * (1.0 - ca)
    pose[1] = center[1] + ry * ca + cy * sa + axis[1] * along * (1.0 - ca)
    pose[2] = center[2] + rz * ca + cz * sa + axis[2] * along * (1.0 - ca)


@njit(cache=True)
def turn_center(params, terms, t, buffer):
    """(3,) the point the turn's axis passes through at ``t`` (m): its place
    at t = 0 carried along the path."""
    path_point(terms, t, buffer)
    center = np.empty(3)
    for j in range(3):
        center[j] = params[TURN_CENTER][j] + buffer[0, j]
    return center


@njit(cache=True)
def place_settled(pose, params, terms, t, buffer):
    """Turn ``pose``, placed on its path at ``t``, by the angle the body
    last settled to (``params[SETTLED]``). (A path without a turn keeps the
    pose's orientation: it is put back to the one at t = 0 first.)"""
    if params[TURN_RATE] == 0.0:
        for j in range(4):
            pose[3 + j] = params[ORIENTATION][j]
    if params[SETTLED] != 0.0:
        turn_pose(pose, params[TURN_AXIS], turn_center(params, terms, t, buffer),
                  params[SETTLED])


@njit(cache=True)
def settle_turn(body_vertices, pose, params, terms, t, dt, buffer, planes, vertex_planes, active,
                area, law, scratch):
    """Turn ``pose`` about its turn's axis to the torque balance
    (``params[CARRIED]``, N·m, the torque the contacts carry) on the planes
    given: passes of :func:`balance_angle`, each from the pose the last
    left, until one turns it by less than :data:`SETTLED_ANGLE`. Adds the
    angle to ``params[SETTLED]`` and, if ``dt`` > 0, its rate over the step
    to the angular velocity. Returns the angle (rad), NaN if no contact
    carries the torque, a pass would turn it by more than :data:`MAX_TURN`
    or :data:`MAX_PASSES` do not settle it (``pose`` then as the passes
    before left it)."""
    axis = params[TURN_AXIS]
    center = turn_center(params, terms, t, buffer)
    total = 0.0
    for _ in range(MAX_PASSES):
        angle = balance_angle(body_vertices, pose, axis, center, planes, vertex_planes, active,
                              area, law, params[CARRIED], scratch)
        if not abs(angle) <= MAX_TURN:
            return np.nan
        turn_pose(pose, axis, center, angle)
        total += angle
        if abs(angle) < SETTLED_ANGLE:
            break
    else:
        return np.nan                    # the passes did not settle
    params[SETTLED] += total
    if dt > 0.0:
        for j in range(3):
            pose[10 + j] += total / dt * axis[j]
    return total
