"""Rigid-body kernels: one semi-implicit (symplectic) Euler step of Newton-Euler.

``pose`` is the (13,) array of :mod:`meshwear.kernels.contact`: centre of mass,
quaternion (w, x, y, z), velocity, angular velocity (world frame).
"""

import numpy as np
from .jit import njit

from .contact import _named_copy, rotation_entries


@njit(cache=True, inline="always")
def _rotate(r, x, y, z):
    """R (x, y, z) with R given row by row as 9 floats."""
    return (r[0] * x + r[1] * y + r[2] * z,
            r[3] * x + r[4] * y + r[5] * z,
            r[6] * x + r[7] * y + r[8] * z)


@njit(cache=True, inline="always")
def _rotate_back(r, x, y, z):
    """R^T (x, y, z)."""
    return (r[0] * x + r[3] * y + r[6] * z,
            r[1] * x + r[4] * y + r[7] * z,
            r[2] * x + r[5] * y + r[8] * z)


@njit(cache=True, inline="always")
def _mul(m, x, y, z):
    """M (x, y, z) for a (3, 3) array M."""
    return (m[0, 0] * x + m[0, 1] * y + m[0, 2] * z,
            m[1, 0] * x + m[1, 1] * y + m[1, 2] * z,
            m[2, 0] * x + m[2, 1] * y + m[2, 2] * z)


@njit(cache=True, inline="always")
def quaternion_product(w1, x1, y1, z1, w2, x2, y2, z2):
    """The quaternion product (w1, x1, y1, z1) (w2, x2, y2, z2)."""
    return (w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2)


@njit(cache=True)
def free_step(pose, wrench, inverse_mass, inertia_body, inverse_inertia_body,
              acceleration, dt):
    """Advance a free body by one step, in place.

    Velocities first (from the forces at the current pose), then the pose with
    the new velocities: the symplectic Euler step. The angular momentum
    ``L = R I R^T omega`` takes the torque; the orientation turns with the
    ``omega`` that ``L`` gives at the old orientation, and the stored ``omega``
    is the one ``L`` gives at the new orientation, so a torque-free body keeps
    ``L`` exactly.

    Parameters
    ----------
    pose : (13,) float
        Rigid state, updated.
    wrench : (6,) float
        Contact force (N) and torque about the centre of mass (N·m), world.
    inverse_mass : float
        1/m (1/kg).
    inertia_body, inverse_inertia_body : (3, 3) float
        Inertia tensor about the centre of mass in the body frame (kg·m²) and
        its inverse.
    acceleration : (3,) float
        Gravity plus the constant applied force over the mass (m/s²).
    dt : float
        Time step (s).
    """
    for j in range(3):
        pose[7 + j] += dt * (wrench[j] * inverse_mass + acceleration[j])
    r = rotation_entries(pose[3:7])
    bx, by, bz = _rotate_back(r, pose[10], pose[11], pose[12])
    bx, by, bz = _mul(inertia_body, bx, by, bz)
    lx, ly, lz = _rotate(r, bx, by, bz)
    lx, ly, lz = lx + dt * wrench[3], ly + dt * wrench[4], lz + dt * wrench[5]
    bx, by, bz = _rotate_back(r, lx, ly, lz)
    bx, by, bz = _mul(inverse_inertia_body, bx, by, bz)
    ox, oy, oz = _rotate(r, bx, by, bz)
    for j in range(3):
        pose[j] += dt * pose[7 + j]
    # q <- exp(omega dt / 2) q, renormalised
    rate = np.sqrt(ox * ox + oy * oy + oz * oz)
    if rate > 0.0:
        half = 0.5 * rate * dt
        sw = np.sin(half) / rate
        dw, dx, dy, dz = np.cos(half), sw * ox, sw * oy, sw * oz
        nw, nx, ny, nz = quaternion_product(dw, dx, dy, dz, pose[3], pose[4], pose[5], pose[6])
        norm = np.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
        pose[3], pose[4], pose[5], pose[6] = nw / norm, nx / norm, ny / norm, nz / norm
    # omega consistent with L at the new orientation
    r = rotation_entries(pose[3:7])
    bx, by, bz = _rotate_back(r, lx, ly, lz)
    bx, by, bz = _mul(inverse_inertia_body, bx, by, bz)
    pose[10], pose[11], pose[12] = _rotate(r, bx, by, bz)


#: path term kinds: rows of a (k, 9) ``terms`` array are
#: ``[kind, a(3), b(3), amplitude, omega]``
OSCILLATION, STEADY, CIRCLE = 0, 1, 2


@njit(cache=True)
def path_point(terms, t, out):
    """Displacement (``out[0]``, m) and velocity (``out[1]``, m/s) of a path at ``t``.

    Each row of ``terms`` adds one term: an oscillation ``A sin(omega t) a``,
    a steady velocity ``t a``, or a circle ``R (cos(omega t) a + sin(omega t) b)``
    (a, b orthonormal in the circle's plane).
    """
    for j in range(3):
        out[0, j] = 0.0
        out[1, j] = 0.0
    for m in range(terms.shape[0]):
        kind, amplitude, omega = int(terms[m, 0]), terms[m, 7], terms[m, 8]
        for j in range(3):
            a, b = terms[m, 1 + j], terms[m, 4 + j]
            if kind == OSCILLATION:
                out[0, j] += amplitude * np.sin(omega * t) * a
                out[1, j] += amplitude * omega * np.cos(omega * t) * a
            elif kind == STEADY:
                out[0, j] += t * a
                out[1, j] += a
            else:
                out[0, j] += amplitude * (np.cos(omega * t) * a + np.sin(omega * t) * b)
                out[1, j] += amplitude * omega * (-np.sin(omega * t) * a + np.cos(omega * t) * b)


@njit(cache=True)
def place_on_path(pose, start, terms, axis, along, rate, t, buffer):
    """Put ``pose`` on its path at ``t``: ``start + path(t)`` across ``axis``,
    ``along`` (m) and ``rate`` (m/s) along it. A zero ``axis`` prescribes every
    translation. Rotation stays; angular velocity is zero (:func:`turn` adds
    a steady turn)."""
    path_point(terms, t, buffer)
    across = 0.0
    speed = 0.0
    for j in range(3):
        across += (start[j] + buffer[0, j]) * axis[j]
        speed += buffer[1, j] * axis[j]
    for j in range(3):
        pose[j] = start[j] + buffer[0, j] + (along - across) * axis[j]
        pose[7 + j] = buffer[1, j] + (rate - speed) * axis[j]
        pose[10 + j] = 0.0


@njit(cache=True)
def guided_step(pose, wrench, inverse_mass, acceleration, axis, start, terms, t, dt, buffer):
    """Advance a guided body from ``t`` to ``t + dt``, in place.

    The translation along the unit ``axis`` follows Newton's law under the
    contact force, gravity and the applied force (symplectic Euler: velocity
    first, then position with the new velocity); all else follows the path.
    """
    a = 0.0
    rate = 0.0
    along = 0.0
    for j in range(3):
        a += (wrench[j] * inverse_mass + acceleration[j]) * axis[j]
        rate += pose[7 + j] * axis[j]
        along += pose[j] * axis[j]
    rate += dt * a
    along += dt * rate
    place_on_path(pose, start, terms, axis, along, rate, t + dt, buffer)


#: motion kinds of :func:`place_motion` and :func:`advance_motion`
#: (TURNING: a quasi-static body on its path, turned about its turn's axis
#: to a torque balance: :mod:`meshwear.kernels.turn_balance`)
FIXED, FREE, GUIDED, PRESCRIBED, BALANCED, TURNING = 0, 1, 2, 3, 4, 5
#: slots of a motion's ``params`` (41,): the mass terms, the free axis, the
#: start, the load a balanced body carries (N along the free axis; a turning
#: one's torque, N·m about the turn's axis), a steady turn: the
#: orientation at t = 0, the turn's unit axis, its rate (rad/s, 0: none) and
#: the point it turns about at t = 0 (carried along the path), and the angle
#: a turning body last settled to (rad, beyond its path's turn: a state the
#: quasi-static step updates)
INVERSE_MASS, INERTIA, INVERSE_INERTIA, ACCELERATION, AXIS, START, CARRIED = (
    0, slice(1, 10), slice(10, 19), slice(19, 22), slice(22, 25), slice(25, 28), 28)
ORIENTATION, TURN_AXIS, TURN_RATE, TURN_CENTER = slice(29, 33), slice(33, 36), 36, slice(37, 40)
SETTLED = 40
MOTION_PARAMS = 41


@njit(cache=True)
def turn(pose, params, axis, t):
    """A path-driven body's steady turn at ``t``, in place: its orientation
    turned by ``rate t`` about the turn's axis, its angular velocity
    ``rate axis``, and its centre of mass carried round the turn's centre
    (that motion's component along a free ``axis`` left out: it is the
    body's own)."""
    rate = params[TURN_RATE]
    if rate == 0.0:
        return
    ax, ay, az = params[33], params[34], params[35]
    half = 0.5 * rate * t
    c, s = np.cos(half), np.sin(half)
    dw, dx, dy, dz = c, s * ax, s * ay, s * az
    pose[3], pose[4], pose[5], pose[6] = quaternion_product(dw, dx, dy, dz, params[29],
                                                            params[30], params[31], params[32])
    ox, oy, oz = rate * ax, rate * ay, rate * az
    pose[10], pose[11], pose[12] = ox, oy, oz
    # the centre of mass about the turn's centre: r0 = start - centre, turned
    rx, ry, rz = params[25] - params[37], params[26] - params[38], params[27] - params[39]
    if rx == 0.0 and ry == 0.0 and rz == 0.0:
        return
    angle = rate * t
    ca, sa = np.cos(angle), np.sin(angle)
    along = ax * rx + ay * ry + az * rz
    cx, cy, cz = ay * rz - az * ry, az * rx - ax * rz, ax * ry - ay * rx
    tx = rx * ca + cx * sa + ax * along * (1.0 - ca)
    ty = ry * ca + cy * sa + ay * along * (1.0 - ca)
    tz = rz * ca + cz * sa + az * along * (1.0 - ca)
    d = (tx - rx, ty - ry, tz - rz)
    v = (oy * tz - oz * ty, oz * tx - ox * tz, ox * ty - oy * tx)
    dn = d[0] * axis[0] + d[1] * axis[1] + d[2] * axis[2]
    vn = v[0] * axis[0] + v[1] * axis[1] + v[2] * axis[2]
    for j in range(3):
        pose[j] += d[j] - dn * axis[j]
        pose[7 + j] += v[j] - vn * axis[j]


@njit(cache=True)
def place_motion(kind, params, terms, buffer, pose, t):
    """Put the path-driven part of ``pose`` where a motion of ``kind`` has it
    at ``t`` (a guided body keeps its place and rate along its free axis; a
    balanced one its place, at rate 0; a fixed one stops)."""
    if kind == FIXED:
        for j in range(7, 13):
            pose[j] = 0.0
    elif kind == PRESCRIBED or kind == TURNING:
        # (a turning body's settled angle is added by turn_balance.place_settled)
        place_on_path(pose, params[START], terms, np.zeros(3), 0.0, 0.0, t, buffer)
        turn(pose, params, np.zeros(3), t)
    elif kind == GUIDED or kind == BALANCED:
        axis = params[AXIS]
        along = pose[0] * axis[0] + pose[1] * axis[1] + pose[2] * axis[2]
        rate = 0.0
        if kind == GUIDED:
            rate = pose[7] * axis[0] + pose[8] * axis[1] + pose[9] * axis[2]
        place_on_path(pose, params[START], terms, axis, along, rate, t, buffer)
        turn(pose, params, axis, t)


#: a build for free bodies only (:data:`advance_free_motion`): the paths'
#: code is left out (numba prunes a branch on a constant before typing it)
FREE_ONLY = False


def _advance_motion(kind, params, terms, buffer, pose, wrench, t, dt):
    """Advance ``pose`` from ``t`` to ``t + dt`` under the contact ``wrench``
    (dynamic mode)."""
    if kind == FREE:
        free_step(pose, wrench, params[INVERSE_MASS], params[INERTIA].reshape(3, 3),
                  params[INVERSE_INERTIA].reshape(3, 3), params[ACCELERATION], dt)
    elif FREE_ONLY:
        return
    elif kind == GUIDED:
        guided_step(pose, wrench, params[INVERSE_MASS], params[ACCELERATION], params[AXIS],
                    params[START], terms, t, dt, buffer)
        turn(pose, params, params[AXIS], t + dt)
    elif kind == PRESCRIBED:
        place_on_path(pose, params[START], terms, np.zeros(3), 0.0, 0.0, t + dt, buffer)
        turn(pose, params, np.zeros(3), t + dt)


advance_motion = njit(cache=True)(_named_copy(_advance_motion, "advance_motion"))
#: the same for free (and fixed) bodies only
advance_free_motion = njit(cache=True)(_named_copy(_advance_motion, "advance_free_motion",
                                                   FREE_ONLY=True))
