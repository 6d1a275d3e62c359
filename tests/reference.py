"""Plain-numpy twins of the numba kernels, written array-at-a-time.

They follow docs/model.md directly and share no code with meshwear.kernels
but the wear laws' numpy twins, which the law registry keeps beside the
increments they twin (meshwear/kernels/laws.py), so agreement between the two
is evidence about both. The benchmark imports the
contact twin as its same-run reference.
"""

import numpy as np

from meshwear.kernels.laws import LAWS

NO_CONTACT, STICK, SLIP = 0, 1, 2

#: a worn counter vertex moves once its lag reaches this fraction of the
#: smallest penetration of the pairs that wore it since (docs/model.md)
LAG_FRACTION = 1e-2
#: a spreading counter vertex spreads what waits on it once its depth there
#: reaches this fraction of its lag limit
PENDING_FRACTION = 0.5
#: a spread along the pairs' direction of sliding reaches this fraction of
#: its radius across it
ALONG = 0.18
#: law code -> numpy twin of its increment (the twins live beside the
#: increments in the registry; the kernel's dispatch on codes is what this
#: checks)
LAW_TWINS = {law.code: law.twin for law in LAWS.values()}


def quaternion_matrix(q):
    w, x, y, z = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def _dot(a, b):
    return np.einsum("ij,ij->i", a, b)


FACING = 1e-3
REVERSAL_MARGIN = 1.0 + 1e-9


def point_coefficients(area, law):
    """c, d, c_t, d_t (n,) from the (per point, per area) pairs of ``law``."""
    return tuple(law[5 + 2 * j] + law[6 + 2 * j] * area for j in range(4))


def contact_areas(area_vectors, R, n):
    """(n,) contact area of each vertex against the plane of normal ``n`` ((3,)
    or one per vertex): its world area vector projected on -n."""
    return -_dot(area_vectors[:, 0:3] @ R.T, np.broadcast_to(n, (len(area_vectors), 3)))


def contact(body_vertices, pose, planes, vertex_planes, active, area_vectors, law,
            wear_direction, contact_state, tangential, normal_force, friction_work, wear_depth,
            wear_volume, wrench):
    """Same contract as :func:`meshwear.kernels.contact.contact`."""
    f, f0, wear_law, k, dt = law[0], law[1], int(law[2]), law[3], law[4]
    R = quaternion_matrix(pose[3:7])
    r = body_vertices @ R.T
    x = pose[0:3] + r
    u = pose[7:10] + np.cross(pose[10:13], r)
    count = len(x)
    force = np.zeros_like(x)
    moves = np.zeros_like(x)
    is_active = np.zeros(count, bool)
    is_active[active] = True
    slots = [np.broadcast_to(pl, (count, 4, 3)) for pl in planes] + list(vertex_planes)
    for s, pl in enumerate(slots):
        p, n, vel = pl[:, 0], pl[:, 1], pl[:, 2]
        delta = _dot(x - p, n)
        if s < len(planes):
            # a plane turning about its point: omega x (foot - point)
            vel = vel + np.cross(pl[:, 3], x - delta[:, None] * n - p)
        area = contact_areas(area_vectors, R, n)
        touching = is_active & (delta < 0.0) & (area > FACING * area_vectors[:, 3])
        c, d, ct, dtan = point_coefficients(area, law)
        safe_area = np.where(touching, area, 1.0)
        g = u - vel
        rate = _dot(g, n)
        slip_v = g - rate[:, None] * n
        load = np.where(touching, np.maximum(-(c * delta + d * rate), 0.0), 0.0)
        on_plane = x - delta[:, None] * n
        T = tangential[s]
        state = contact_state[s].copy()
        anchor, F0, v_old = T[:, 0].copy(), T[:, 1].copy(), T[:, 3].copy()

        # a sticking anchor is a point of the counter-surface: it moves with it
        held = touching & (state == STICK)
        anchor[held] += dt * vel[held]
        new = touching & (state == NO_CONTACT)
        # where it came into contact: on the plane at the step's start
        anchor[new] = on_plane[new] - dt * slip_v[new]
        F0[new], v_old[new] = 0.0, slip_v[new]
        reversed_ = touching & (state == SLIP) & (_dot(slip_v, v_old) < 0.0)
        # stick starts at the turning point, one step back along the slip velocity
        anchor[reversed_] = on_plane[reversed_] - dt * slip_v[reversed_]
        # holding the slip force at the current load: F0 = -f N l/|l|
        l_norm = np.linalg.norm(v_old[reversed_], axis=1)
        F0[reversed_] = -(f * load[reversed_] / l_norm)[:, None] * v_old[reversed_]
        state[new | reversed_] = STICK

        speed = np.linalg.norm(slip_v, axis=1)
        e = on_plane - anchor
        e -= _dot(e, n)[:, None] * n
        trial = F0 - ct[:, None] * e - dtan[:, None] * slip_v
        trial -= _dot(trial, n)[:, None] * n
        trial_mag = np.linalg.norm(trial, axis=1)
        # a point that reversed in this step slips again only past a margin
        exceeds = trial_mag > f0 * load * np.where(reversed_, REVERSAL_MARGIN, 1.0)
        stick = touching & (state == STICK) & ~exceeds
        breaks = touching & (state == STICK) & exceeds
        v_old[breaks & (speed == 0.0)] = -trial[breaks & (speed == 0.0)]
        slip = touching & ((state == SLIP) | breaks)
        moving = touching & (speed > 0.0)
        v_old[moving] = slip_v[moving]
        v_norm = np.linalg.norm(v_old, axis=1)
        safe = np.where(v_norm > 0.0, v_norm, 1.0)
        slip_force = np.where((v_norm > 0.0)[:, None], -(f * load / safe)[:, None] * v_old, 0.0)
        F = np.where(stick[:, None], trial, np.where(slip[:, None], slip_force, 0.0))
        energy = np.where(stick, dtan * speed ** 2 * dt, np.where(slip, f * load * speed * dt, 0.0))
        # the law's numpy twin from the registry (it twins the increment
        # the kernel inlines); the slip distance is zero where it sticks
        dw, dv = LAW_TWINS[wear_law](k, energy, load, np.where(slip, speed * dt, 0.0), safe_area)
        dw, dv = np.where(touching, dw, 0.0), np.where(touching, dv, 0.0)

        direction = wear_direction if wear_direction.shape[0] else n @ R
        if wear_direction.shape[0]:
            # a sticking point's anchor follows its foot on the plane as it wears
            along_plane = direction @ R.T
            along_plane -= _dot(along_plane, n)[:, None] * n
            anchor += np.where(stick[:, None], dw[:, None] * along_plane, 0.0)

        keep = ~is_active
        contact_state[s] = np.where(keep, contact_state[s],
                                    np.where(touching, np.where(slip, SLIP, STICK), NO_CONTACT))
        normal_force[s] = np.where(keep, normal_force[s], load)
        T[:, 0] = np.where(keep[:, None], T[:, 0], anchor)
        T[:, 1] = np.where(keep[:, None], T[:, 1], F0)
        T[:, 3] = np.where(keep[:, None], T[:, 3], v_old)
        T[:, 2] = np.where(keep[:, None], T[:, 2], F)
        friction_work += energy
        wear_depth += dw
        wear_volume += np.where(dw > 0.0, dv, 0.0)
        moves += dw[:, None] * direction
        force += np.where(touching[:, None], load[:, None] * n + F, 0.0)
    body_vertices += moves
    wrench[0:3] = force.sum(axis=0)
    wrench[3:6] = np.cross(r, force).sum(axis=0)


def free_step(pose, wrench, inverse_mass, inertia_body, inverse_inertia_body, acceleration, dt):
    """Same contract as :func:`meshwear.kernels.rigid.free_step`."""
    pose[7:10] += dt * (wrench[0:3] * inverse_mass + acceleration)
    R = quaternion_matrix(pose[3:7])
    L = R @ inertia_body @ R.T @ pose[10:13] + dt * wrench[3:6]
    omega = R @ inverse_inertia_body @ R.T @ L
    pose[0:3] += dt * pose[7:10]
    angle = np.linalg.norm(omega) * dt
    if angle > 0.0:
        axis = omega / np.linalg.norm(omega)
        dq = np.concatenate([[np.cos(angle / 2)], np.sin(angle / 2) * axis])
        w0, v0 = dq[0], dq[1:]
        w1, v1 = pose[3], pose[4:7]
        q = np.concatenate([[w0 * w1 - v0 @ v1], w0 * v1 + w1 * v0 + np.cross(v0, v1)])
        pose[3:7] = q / np.linalg.norm(q)
    R = quaternion_matrix(pose[3:7])
    pose[10:13] = R @ inverse_inertia_body @ R.T @ L


def path_point(terms, t):
    """Displacement and velocity (2, 3) of the summed path terms at ``t``."""
    out = np.zeros((2, 3))
    for kind, ax, ay, az, bx, by, bz, amplitude, omega in terms:
        a, b = np.array([ax, ay, az]), np.array([bx, by, bz])
        if kind == 0:
            out += [amplitude * np.sin(omega * t) * a, amplitude * omega * np.cos(omega * t) * a]
        elif kind == 1:
            out += [t * a, a]
        else:
            out += [amplitude * (np.cos(omega * t) * a + np.sin(omega * t) * b),
                    amplitude * omega * (-np.sin(omega * t) * a + np.cos(omega * t) * b)]
    return out


def guided_step(pose, wrench, inverse_mass, acceleration, axis, start, terms, t, dt):
    """Same contract as :func:`meshwear.kernels.rigid.guided_step`."""
    rate = pose[7:10] @ axis + dt * (wrench[0:3] * inverse_mass + acceleration) @ axis
    along = pose[0:3] @ axis + dt * rate
    across = np.eye(3) - np.outer(axis, axis)
    disp, vel = path_point(terms, t + dt)
    pose[0:3] = across @ (start + disp) + along * axis
    pose[7:10] = across @ vel + rate * axis
    pose[10:13] = 0.0


def balance_offset(body_vertices, pose, axis, planes, vertex_planes, active, area_vectors, law,
                   load, scale=None):
    """Same contract as :func:`meshwear.kernels.balance.balance_offset`, solved
    by another route: sort every breakpoint of the piecewise-linear contact
    force g(z), evaluate g there, and interpolate in the piece that holds the
    load."""
    R = quaternion_matrix(pose[3:7])
    x = pose[0:3] + body_vertices[active] @ R.T
    av = area_vectors[active]
    zs, ws, signs = [], [], []
    slots = [np.broadcast_to(pl[:3], (len(active), 3, 3)) for pl in planes]
    slots += [vp[active] for vp in vertex_planes]
    for pl in slots:
        p, n = pl[:, 0], pl[:, 1]
        beta = n @ axis
        area = contact_areas(av, R, n)
        c = law[5] + law[6] * area
        ok = (beta != 0.0) & (area > FACING * av[:, 3]) & (c > 0.0)
        zs.append(-_dot(x - p, n)[ok] / beta[ok])
        stiffness = c if scale is None else c * scale[active]
        ws.append(stiffness[ok] * beta[ok] ** 2)
        signs.append(np.sign(beta[ok]))
    z_j, w, sign = np.concatenate(zs), np.concatenate(ws), np.concatenate(signs)
    carrying = sign > 0 if load >= 0 else sign < 0
    if not carrying.any():
        return np.nan

    def g(z):
        active = np.where(sign > 0, z < z_j, z > z_j)
        return (w * (z_j - z))[active].sum()

    points = np.unique(z_j)
    values = np.array([g(z) for z in points])      # non-increasing in z
    # g is linear between neighbouring breakpoints, and beyond the outermost
    # ones with the slope of the pairs active there
    if load >= values[0]:
        left = points[0]
        slope = w[(sign > 0)].sum()
        return left - (load - values[0]) / slope
    if load <= values[-1]:
        right = points[-1]
        slope = w[(sign < 0)].sum()
        return right + (values[-1] - load) / slope
    k = np.searchsorted(-values, -load)            # values[k-1] > load >= values[k]
    z0, z1, g0, g1 = points[k - 1], points[k], values[k - 1], values[k]
    return z0 + (g0 - load) / (g0 - g1) * (z1 - z0)


def closest_points(tri, points):
    """Closest point of each triangle (m, 3, 3) to each point (m, 3), and its
    barycentric weights: the projection on the plane when it falls inside,
    else the nearest of the three edges' closest points (another route than
    the kernel's Voronoi regions)."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    n = np.cross(b - a, c - a)
    n2 = _dot(n, n)
    proj = points - (_dot(points - a, n) / n2)[:, None] * n
    # barycentric weights of the projection from sub-triangle areas
    u = _dot(np.cross(c - b, proj - b), n) / n2
    v = _dot(np.cross(a - c, proj - c), n) / n2
    w = 1.0 - u - v
    inside = (u > 0) & (v > 0) & (w > 0)
    best = np.where(inside[:, None], proj, np.nan)
    bary = np.where(inside[:, None], np.stack([u, v, w], axis=1), np.nan)
    best_d2 = np.where(inside, _dot(proj - points, proj - points), np.inf)
    for (p, q, i, j) in ((a, b, 0, 1), (b, c, 1, 2), (c, a, 2, 0)):
        e = q - p
        t = np.clip(_dot(points - p, e) / _dot(e, e), 0.0, 1.0)
        cand = p + t[:, None] * e
        d2 = _dot(cand - points, cand - points)
        better = ~inside & (d2 < best_d2)
        weights = np.zeros((len(points), 3))
        weights[:, i], weights[:, j] = 1.0 - t, t
        best = np.where(better[:, None], cand, best)
        bary = np.where(better[:, None], weights, bary)
        best_d2 = np.where(better, d2, best_d2)
    return best, bary


def _walk(y, h, prev, edges, normals, faces, over, tracking, steps):
    """The face a walk from face ``h`` reaches: across the edge the foot of
    ``y`` lies farthest beyond, while the next face shares the edge and its
    normal is within ``tracking`` of ``prev``, until the foot is over a face
    (``steps`` faces at most), or over the fold between two faces (its foot
    beyond their shared edge on both: the walk would go back). Returns the
    face, and the other face of such a fold (-1: none)."""
    f, back = h, -1
    for _ in range(steps):
        beyond = edges[f, :, 0:3] @ y - edges[f, :, 3]
        edge = int(np.argmax(beyond))
        if beyond[edge] <= over:
            break
        a, b = faces[f, edge], faces[f, (edge + 1) % 3]
        shared = [g for g in range(len(faces)) if g != f and {a, b} <= set(faces[g].tolist())]
        if len(shared) == 1 and shared[0] == back:
            return f, back
        if len(shared) != 1 or normals[shared[0]] @ prev < tracking:
            break
        f, back = shared[0], f
    return f, -1


def nearest_planes(body_vertices, pose, active, rotation, motion, counter_vertices, faces,
                   face_normals, corner_normals, reach, out, distance, hint, fixed=False,
                   tracking=0.5, tie=1e-9, release=16.0, walk=32):
    """Same contract as :func:`meshwear.kernels.nearest.nearest_planes`, by
    brute force over every face (no tree); ``fixed`` only lets the kernel
    reuse what it wrote, so the twin ignores it."""
    R = quaternion_matrix(pose[3:7])
    x = pose[0:3] + body_vertices[active] @ R.T
    y = (x - motion[0]) @ rotation
    previous = out[active, 1].copy()
    tri = counter_vertices[faces]
    edges = face_frames(counter_vertices, faces)[:, 1:4]
    F = len(faces)
    for row, i in enumerate(active):
        points = np.repeat(y[row][None], F, axis=0)
        closest, bary = closest_points(tri, points)
        d2 = ((points - closest) ** 2).sum(axis=1)
        delta = _dot(points - tri[:, 0], face_normals)
        prev = rotation.T @ previous[row]
        tracked = bool(np.any(previous[row] != 0.0))
        within = d2 <= reach * reach

        def pick(ok):
            if not ok.any():
                return -1
            best = np.flatnonzero(ok)[np.argmin(d2[ok])]
            near = ok & (d2 <= d2[best] * (1 + tie))
            return np.flatnonzero(near)[np.argmax(delta[near])]

        # the foot on the plane, and how far it lies outside the triangle
        foot = points - delta[:, None] * face_normals
        lateral = np.linalg.norm(closest_points(tri, foot)[0] - foot, axis=1)
        over = lateral <= 1e-9 * reach
        eligible = within & over & (face_normals @ prev >= tracking)
        h = hint[i]
        nearest = pick(within)
        def released(f):
            return delta[f] < 0.0 and -delta[f] > release * _to_crease(
                tri[f], foot[f], faces, f, face_normals, tracking)

        if tracked and h >= 0 and eligible[h] and not released(h):
            kept = h                  # still over the face it had: it stays there
        else:
            kept = -1
            onto = False
            if tracked:
                # the face the walk from its last face reaches: it stays on
                # it as on its own (not deep under it); else on the nearest
                # face it can stay on if the walk reached one, or on one as
                # near as the nearest face
                f, fold = _walk(y[row], h, prev, edges, face_normals, faces, 1e-9 * reach,
                                tracking, walk) if h >= 0 else (-1, -1)
                if fold >= 0:
                    # over the fold of f and the face the walk came from:
                    # over both; the nearer, the one whose plane separates
                    # more if as near
                    both = np.zeros(F, dtype=bool)
                    both[[f, fold]] = True
                    both &= within & (face_normals @ prev >= tracking)
                    eligible |= both
                    f = pick(both) if both.any() else f
                if f >= 0 and eligible[f] and not released(f):
                    kept, onto = f, True
                elif f >= 0 and eligible[f]:
                    kept = pick(eligible)
                elif nearest >= 0:
                    kept = pick(eligible & (d2 <= d2[nearest] * (1 + 2 * tie)))
            if (kept >= 0 and not onto and delta[kept] < 0.0
                    and delta[kept] ** 2 > release ** 2 * d2[nearest]):
                kept = -1             # deep under it, near another face: let go
        best = kept if kept >= 0 else nearest
        hint[i] = best
        if best < 0:
            out[i] = 0.0
            distance[i] = np.inf
            continue
        distance[i] = np.sqrt(d2[best])
        if corner_normals.shape[0]:
            normal = bary[best] @ corner_normals[best]
            normal /= np.linalg.norm(normal)
            point = closest[best]
        else:
            normal = face_normals[best]
            point = y[row] - delta[best] * normal
        p = rotation @ point + motion[0]
        out[i, 0] = p
        out[i, 1] = rotation @ normal
        out[i, 2] = motion[1] + np.cross(motion[2], p - motion[3])


def _to_crease(tri, foot, faces, f, normals, tracking):
    """Distance (>= 0) from a foot inside triangle ``tri`` (face ``f``) to its
    nearest edge line across which no face continues the surface within
    ``tracking`` (a crease, or a border); inf when there is none."""
    n = np.cross(tri[1] - tri[0], tri[2] - tri[0])
    n /= np.linalg.norm(n)
    out = np.inf
    for k in range(3):
        a, b = faces[f, k], faces[f, (k + 1) % 3]
        shared = [g for g in range(len(faces)) if g != f and {a, b} <= set(faces[g].tolist())]
        if len(shared) == 1 and normals[shared[0]] @ normals[f] >= tracking:
            continue
        p, q = tri[k], tri[(k + 1) % 3]
        m = np.cross(q - p, n)
        out = min(out, -float((foot - p) @ m) / np.linalg.norm(m))
    return max(out, 0.0)


# ---------------------------------------------------------------- counter-surfaces

def turn_matrix(axis, angle):
    """Rotation by ``angle`` about unit ``axis`` (matrix exponential form)."""
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * (K @ K)


def surface_frame(motion, terms, t, frozen):
    """Same contract as :func:`meshwear.kernels.frames.surface_frame`:
    returns (rotation, frame)."""
    R0, position = motion[0:9].reshape(3, 3), motion[9:12]
    axis, rate, center = motion[12:15], motion[15], motion[16:19]
    shift, velocity = path_point(terms, t)
    turn = turn_matrix(axis, 0.0 if frozen else rate * t)
    frame = np.array([turn @ (position - center) + center + shift, velocity, rate * axis,
                      center + shift])
    return turn @ R0, frame


def _surface_planes(points, normals, frame, gap, ok, active, out, distance):
    velocity = frame[1] + np.cross(frame[2], points - frame[3])
    rows = np.stack([points, normals, velocity], axis=1)
    out[active] = np.where(ok[:, None, None], rows, 0.0)
    distance[active] = np.where(ok, gap, np.inf)


def cylinder_planes(body_vertices, pose, active, rotation, frame, geometry, out, distance):
    """Same contract as :func:`meshwear.kernels.analytic.cylinder_planes_serial`."""
    radius, half, sign = geometry[0], geometry[1], 1.0 - 2.0 * geometry[2]
    x = pose[0:3] + body_vertices[active] @ quaternion_matrix(pose[3:7]).T
    y = (x - frame[0]) @ rotation
    r = np.hypot(y[:, 0], y[:, 1])
    ok = (np.abs(y[:, 2]) <= half) & (r > 0.0)
    u = np.zeros_like(y)
    u[:, 0:2] = y[:, 0:2] / np.where(ok, r, 1.0)[:, None]
    closest = radius * u
    closest[:, 2] = y[:, 2]
    _surface_planes(closest @ rotation.T + frame[0], sign * u @ rotation.T, frame,
                    sign * (r - radius), ok, active, out, distance)


def sphere_planes(body_vertices, pose, active, rotation, frame, geometry, out, distance):
    """Same contract as :func:`meshwear.kernels.analytic.sphere_planes_serial`."""
    radius, sign = geometry[0], 1.0 - 2.0 * geometry[1]
    x = pose[0:3] + body_vertices[active] @ quaternion_matrix(pose[3:7]).T
    e = x - frame[0]
    r = np.linalg.norm(e, axis=1)
    ok = r > 0.0
    u = e / np.where(ok, r, 1.0)[:, None]
    _surface_planes(frame[0] + radius * u, sign * u, frame, sign * (r - radius), ok, active,
                    out, distance)


def wear_counter(body_vertices, pose, active, area_vectors, law, contact_state, normal_force,
                 planes, hint, rotation, frame, part, surface=0, log=None):
    """Same contract as :func:`meshwear.kernels.counter_wear.wear_counter`,
    array at a time (the pairs' energy and slip from their velocities, the
    law's twin, the closest-point weights of :func:`closest_points`); the
    face frames are all recomputed. Returns the vertices that sank more than
    half their spacing since they last moved (the kernel returns the first
    of them). ``log``: (index, value, count) as the kernel's log (logged
    while ``count[1]`` is 1)."""
    (counter_law, faces, reference, normals, tributary, spacing, _, _, vertices, frames, depth,
     volume, work, added, _, limit, _, _, stiffness, _, spread) = part
    code, k = int(counter_law[0]), counter_law[1]
    f, dt, dt0, dt1 = law[0], law[4], law[11], law[12]
    R = quaternion_matrix(pose[3:7])
    i = active[(contact_state[active] != NO_CONTACT) & (normal_force[active] > 0.0)
               & (hint[active] >= 0)]
    n = planes[i, 1]
    r = body_vertices[i] @ R.T
    x = pose[0:3] + r
    delta = _dot(x - planes[i, 0], n)
    foot = x - delta[:, None] * n
    a = contact_areas(area_vectors[i], R, n)
    keep = a > 0.0
    i, n, r, foot, a, delta = i[keep], n[keep], r[keep], foot[keep], a[keep], delta[keep]
    g = pose[7:10] + np.cross(pose[10:13], r) - planes[i, 2]
    s = g - _dot(g, n)[:, None] * n
    speed = np.linalg.norm(s, axis=1)
    load = normal_force[i]
    slipping = contact_state[i] == SLIP
    energy = np.where(slipping, f * load * speed * dt, (dt0 + dt1 * a) * speed ** 2 * dt)
    dv = LAW_TWINS[code](k, energy, load, np.where(slipping, speed * dt, 0.0), a)[1]
    q = (foot - frame[0]) @ rotation
    corners = faces[hint[i]]
    _, weights = closest_points(vertices[corners], q)
    if log is not None and log[2][1] == 1:
        index, value, count = log
        wearing = (dv > 0.0) | (energy > 0.0)
        for p in np.flatnonzero(wearing):
            for c in range(3):
                if weights[p, c] > 0.0:
                    row, j = count[0], corners[p, c]
                    if row < len(index):
                        index[row] = surface, i[p], j
                        value[row] = weights[p, c] * load[p]
                    count[0] = row + 1
    before = depth.copy()
    if len(spread[0]):
        # each slipping pair's direction of sliding, counter frame
        along = np.where((slipping & (speed > 0.0))[:, None],
                         s / np.where(speed > 0.0, speed, 1.0)[:, None], 0.0) @ rotation
        _spread_pairs(energy, dv, delta, corners, weights, part, along, q, hint[i])
    else:
        for c in range(3):
            np.add.at(work, corners[:, c], weights[:, c] * energy)
            np.add.at(volume, corners[:, c], weights[:, c] * dv)
            np.add.at(depth, corners[:, c], weights[:, c] * dv / tributary[corners[:, c]])
            # a vertex moves once its lag reaches LAG_FRACTION of the smallest
            # penetration of the pairs that wore it since it last moved
            wore = (weights[:, c] > 0.0) & (dv > 0.0)
            np.minimum.at(limit, corners[wore, c],
                          LAG_FRACTION * np.minimum(-delta[wore], spacing[corners[wore, c]]))
            # how much its wear falls per unit of its own depth: w^2 dV / (delta A)
            pressed = wore & (delta < 0.0)
            if len(stiffness):
                np.add.at(stiffness, corners[pressed, c], weights[pressed, c] ** 2 * dv[pressed]
                          / (-delta[pressed] * tributary[corners[pressed, c]]))
    added += depth - before
    deep = np.flatnonzero(added > 0.5 * spacing)
    moved = (added > 0.0) & (added >= limit)
    vertices[moved] = reference[moved] - depth[moved, None] * normals[moved]
    added[moved] = 0.0
    limit[moved] = np.inf
    frames[...] = face_frames(vertices, faces)
    return deep


def _spread_pairs(energy, dv, delta, corners, weights, part, along, q, face_of):
    """A spreading part's pairs, one after the other (:func:`wear_counter`):
    each one's wear waits on the face under it (with its point, weighed by
    volume), and a face spreads once its depth there reaches
    PENDING_FRACTION of its lag limit; a face whose first corner keeps its
    share takes the pair at its corners as an unspread part does."""
    faces, tributary, spacing, stiffness, spread = part[1], part[4], part[5], part[18], part[20]
    starts, self_weight, face_area, pending, waiting = (spread[0], spread[3], spread[5],
                                                        spread[6], spread[8])
    for p in range(len(energy)):
        if dv[p] <= 0.0 and energy[p] <= 0.0:
            continue
        f = face_of[p]
        spreads = starts[faces[f, 0] + 1] - starts[faces[f, 0]] > 1
        for c in range(3):
            k, w = corners[p, c], weights[p, c]
            if w <= 0.0:
                continue
            if not spreads:
                _deposit(part, k, w * energy[p], w * dv[p], -delta[p])
                if len(stiffness) and dv[p] > 0.0 and delta[p] < 0.0:
                    stiffness[k] += w * w * dv[p] / (-delta[p] * tributary[k])
            elif len(stiffness) and dv[p] > 0.0 and delta[p] < 0.0:
                stiffness[k] += w * w * dv[p] * self_weight[k] / (-delta[p] * tributary[k])
        if not spreads:
            continue
        waiting[f] = 1
        pending[1, f] += energy[p]
        if dv[p] <= 0.0:
            continue
        pending[0, f] += dv[p]
        pending[2, f] += dv[p] * -delta[p]
        u = along[p] if along[p] @ pending[3:6, f] >= 0.0 else -along[p]
        pending[3:6, f] += dv[p] * u
        pending[6:9, f] += dv[p] * q[p]
        if pending[0, f] >= (PENDING_FRACTION * LAG_FRACTION * face_area[f]
                             * min(pending[2, f] / pending[0, f], spacing[faces[f]].min())):
            _spread_face(f, part)


def _deposit(part, j, energy, volume_, penetration):
    """A counter vertex's share of a pair's energy and volume (work,
    volume, depth and lag limit; the twin moves vertices at the step's end)."""
    tributary, spacing, depth, volume, work, limit = (part[4], part[5], part[10], part[11],
                                                      part[12], part[15])
    work[j] += energy
    if volume_ > 0.0:
        volume[j] += volume_
        depth[j] += volume_ / tributary[j]
        limit[j] = min(limit[j], LAG_FRACTION * min(penetration, spacing[j]))


def _spread_face(f, part):
    """Twin of :func:`meshwear.kernels.counter_wear._spread_face` (the
    pending list's order aside)."""
    (_, faces, reference, normals, tributary, _, _, _, _, _, _, _, _, _, _, _, _, _, _, _,
     spread) = part
    starts, items, radius, pending, waiting = spread[0], spread[1], spread[4][0], spread[6], spread[8]
    volume_f, energy_f, penetration = pending[0:3, f]
    penetration = penetration / volume_f if volume_f > 0.0 else 0.0
    a = faces[f, 0]
    point = pending[6:9, f] / volume_f if volume_f > 0.0 else reference[faces[f]].mean(axis=0)
    j = items[starts[a]:starts[a + 1]]
    d = reference[j] - point
    u = pending[3:6, f]
    if np.linalg.norm(u) > 0.0:
        u = u / np.linalg.norm(u)
        corners = reference[faces[f]]
        edges = np.linalg.norm(corners - np.roll(corners, -1, axis=0), axis=1)
        along = max(ALONG * radius, 0.5 * (edges.mean() + edges.max()))
        par = d @ u
        r2 = ((d * d).sum(axis=1) - par * par) / radius ** 2 + par * par / along ** 2
    else:
        r2 = (d * d).sum(axis=1) / radius ** 2
    # (corner a's list holds the vertices facing within 60 degrees of it)
    share = np.where(r2 < 1.0, (1.0 - r2) ** 2, 0.0)
    share = share * tributary[j]
    if share.sum() > 0.0:
        share = share / share.sum()
    else:
        j = faces[f]
        share = closest_points(reference[j][None], point[None])[1][0]
    for jj, ss in zip(j, share):
        if ss > 0.0:
            _deposit(part, jj, ss * energy_f, ss * volume_f, penetration)
    pending[:, f] = 0.0
    waiting[f] = -1


def settle_counter(part):
    """Twin of :func:`meshwear.kernels.counter_wear.settle_counter`."""
    (_, faces, reference, normals, _, _, _, _, vertices, frames, depth, _, _, added, _, limit,
     _, _, _, _, spread) = part
    if len(spread[0]):
        before = depth.copy()
        for f in np.flatnonzero(spread[8] >= 0):
            _spread_face(f, part)
        added += depth - before
    moved = added > 0.0
    vertices[moved] = reference[moved] - depth[moved, None] * normals[moved]
    added[moved] = 0.0
    limit[moved] = np.inf
    frames[...] = face_frames(vertices, faces)


def face_frames(vertices, faces):
    """(F, 4, 4) face planes and edge lines, as meshwear.kernels.nearest.face_frames."""
    tri = vertices[faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.linalg.norm(n, axis=1)[:, None]
    out = np.zeros((len(faces), 4, 4))
    out[:, 0, 0:3], out[:, 0, 3] = n, _dot(n, tri[:, 0])
    for e in range(3):
        p, q = tri[:, e], tri[:, (e + 1) % 3]
        m = np.cross(q - p, n)
        m /= np.linalg.norm(m, axis=1)[:, None]
        out[:, e + 1, 0:3], out[:, e + 1, 3] = m, _dot(m, p)
    return out


def deepest_penetration(body_vertices, pose, planes, vertex_planes, active, contact_state):
    """Twin of :func:`meshwear.kernels.loop.deepest_penetration`."""
    x = pose[0:3] + body_vertices[active] @ quaternion_matrix(pose[3:7]).T
    best = (0.0, -1, -1)
    for s in range(contact_state.shape[0]):
        if s < len(planes):
            point, normal = planes[s, 0], planes[s, 1]
        else:
            point = vertex_planes[s - len(planes), active, 0]
            normal = vertex_planes[s - len(planes), active, 1]
        depth = -np.einsum("ij,ij->i", x - point, np.broadcast_to(normal, x.shape))
        depth[contact_state[s, active] == 0] = -np.inf
        k = int(np.argmax(depth))
        if depth[k] > best[0]:
            best = (float(depth[k]), s, int(active[k]))
    return best


def implicit_step(jump, alpha, gamma, member, touched, beta, stiffness, depth, now, load, guided):
    """numpy twin of meshwear.kernels.balance.implicit_step (the balance by
    the compiled bracketed Newton ``solve``, which balance_offset's twin
    checks)."""
    from meshwear.kernels.balance import solve

    rate = alpha + gamma
    relief = 1.0 / (1.0 + jump * rate)
    z = 0.0
    k = member
    if guided:
        ahead = depth[k] + jump * rate[k] * (depth[k] - now[k])
        b, stiff = beta[k], stiffness[k] * relief[k]
        ok = (b != 0.0) & (stiff > 0.0) & np.isfinite(ahead)
        b = b[ok]
        breaks = np.ascontiguousarray(ahead[ok] / b)
        weights = np.ascontiguousarray(stiff[ok] * b * np.abs(b))
        z = solve(breaks, weights, len(breaks), float(load), 0.0, np.nan) if len(breaks) else 0.0
        z = float(z) if np.isfinite(z) else 0.0
    left = np.zeros(len(depth))
    k = k | touched
    left[k] = np.maximum(0.0, now[k] - beta[k] * z) * relief[k]
    return jump * alpha * left, z, jump * rate * left
