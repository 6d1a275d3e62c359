"""Point-plane contact, friction and wear of one body against its counter-surfaces.

One fused kernel does, for every active vertex ``i`` of a worn body and every
counter-surface ``s`` (the analytic planes first, then the mesh surfaces), the
phases of docs/model.md in order: penetration, normal force (eq. 1), the
stick/slip state machine (eq. 2-4), dissipated energy, wear (eq. 5 and its
variants) and the geometry update. Fusing keeps each vertex's data in registers
for one pass. The kernel is compiled three times from the one definition
:func:`_contact`: in general, for the common case of one analytic plane and
no per-vertex surface, and for one per-vertex surface and no plane; the
threaded kernel runs the same builds in threads, on pieces of the active set
(see :func:`_build`). What made it fast is in docs/performance.md.

Array conventions (all C-contiguous float64 unless said otherwise):

pose : (13,)
    Rigid state of the body: centre of mass ``x`` (0:3, m, world), unit
    quaternion ``q`` (3:7, w x y z, body -> world), velocity ``v`` of the centre
    of mass (7:10, m/s, world), angular velocity ``omega`` (10:13, rad/s, world).
planes : (P, 4, 3)
    Per plane: a point on it (m), its unit normal ``n`` pointing into the worn
    body, its translational velocity (m/s) and its angular velocity (rad/s,
    along ``n``: a turning disc) about that point. The surface velocity under
    a vertex is ``v + omega x (a - point)``, ``a`` the vertex's foot.
vertex_planes : (M, n, 3, 3)
    Per mesh counter-surface and vertex, the same for the plane of the
    counter face under the vertex (a point of it, not necessarily the
    vertex's foot), the velocity being the counter-surface's at the vertex's
    foot (:mod:`meshwear.kernels.nearest` fills it); a zero normal means
    no face within reach. Pair slot ``P + m``.
active : (k,) int64
    Indices of the vertices to process (the active set), each in
    ``0 .. n - 1`` (no negative, numpy-style index); the others are out of
    reach of every surface and keep no contact.
area : (n, 4)
    Area vector of each vertex in the body frame (m², the third of each
    adjacent face's area times its outward unit normal, summed) and its
    length. Against a plane of normal ``n`` the vertex's contact area is
    ``A_i = -(R a_i) . n``, its tributary area projected on the plane; a
    vertex with ``A_i`` below :data:`FACING` of its length does not touch.
law : (13,)
    ``f``, ``f0``, wear law code (:data:`meshwear.kernels.laws.LAWS`), wear
    coefficient ``k``, time step ``dt`` (s), then the
    contact coefficients as (per point, per area) pairs: normal stiffness,
    normal damping, tangential stiffness, tangential damping. Point ``i`` gets
    ``c_i = c_point + c_area A_i`` (N/m), ``A_i`` the contact area, and likewise ``d_i``, ``c_t,i``,
    ``d_t,i``: one of each pair is zero (docs/model.md, per point or Winkler).
body_vertices : (n, 3)
    Worn vertex positions in the body frame (m, relative to the centre of
    mass); wear moves them in place.
wear_direction : (n, 3) or (0, 3)
    Inward unit vertex normals in the body frame when wear moves vertices
    along them; an empty array moves vertices along the contact normal.
contact_state : (P + M, n) int8
    0 no contact, 1 stick, 2 slip; updated in place.
tangential : (P + M, n, 4, 3)
    Per contact pair: stick anchor ``r0`` (m, world, on the plane; it moves
    with the counter-surface's velocity while the pair sticks), friction
    force ``F0`` when stick began (N), current friction force ``F`` (N) and the
    last non-zero slip velocity (m/s); updated in place.
normal_force : (P + M, n)
    ``N`` (N), written.
friction_work, wear_depth, wear_volume : (n,)
    Cumulative dissipated energy ``E`` (J), wear depth ``w`` (m) and worn
    volume (m³, the depth increments times the contact area); increased.
wrench : (6,)
    Total contact force (N, world) and torque about the centre of mass (N·m),
    written.
"""

import types

import numpy as np
from numba import prange

from .jit import njit

from . import laws
from .laws import wear_increment

NO_CONTACT, STICK, SLIP = 0, 1, 2
#: law codes (the registry, :data:`meshwear.kernels.laws.LAWS`, is the list)
ENERGY, ENERGY_DENSITY, ARCHARD = (laws.code_of(name) for name in ("energy", "energy_density",
                                                                   "archard"))

#: slots of ``tangential[s, i]``
ANCHOR, START_FORCE, FORCE, SLIP_VELOCITY = 0, 1, 2, 3

#: slots of ``law``, in order
LAW_SLOTS = ("friction", "static_friction", "wear_law", "wear_coefficient", "dt",
             "stiffness", "stiffness_per_area", "damping", "damping_per_area",
             "tangential_stiffness", "tangential_stiffness_per_area",
             "tangential_damping", "tangential_damping_per_area")


def make_law(*, friction, static_friction, wear_law, wear_coefficient, dt,
             stiffness=0.0, stiffness_per_area=0.0, damping=0.0, damping_per_area=0.0,
             tangential_stiffness=0.0, tangential_stiffness_per_area=0.0,
             tangential_damping=0.0, tangential_damping_per_area=0.0):
    """The ``law`` array of the kernel from named values (``wear_law``: a code
    of :data:`meshwear.kernels.laws.LAWS` or its name)."""
    if isinstance(wear_law, str):
        wear_law = laws.code_of(wear_law)
    values = dict(locals())
    return np.array([float(values[name]) for name in LAW_SLOTS])

#: relative margin on the static limit in the step a slip reverses in
REVERSAL_MARGIN = 1.0 + 1e-9

#: a vertex touches a plane only where its area vector, projected on the
#: plane, exceeds this fraction of its length (its surface faces the plane)
FACING = 1e-3

# Pairs with at least this many vertex-plane pairs use the threaded kernel;
# below it thread start-up costs more than the work.
PARALLEL_THRESHOLD = 4096


@njit(cache=True, inline="always")
def rotation_entries(q):
    """Rotation matrix of unit quaternion ``q`` (w, x, y, z), row by row, as 9 floats."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    return (1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y),
            2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x),
            2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y))


#: set in the build for one analytic plane and no per-vertex surface, and in
#: the one for one per-vertex surface and no plane (see _build)
ONE_PLANE = ONE_SURFACE = False


@njit(cache=True, inline="always")
def plane_under(planes, vertex_planes, n_planes, s, i):
    """Point and normal of contact slot ``s`` under vertex ``i``, as six
    scalars: uniform plane ``s`` or, past the ``n_planes`` planes, the
    per-vertex plane (a zero normal: no face within reach). Read as scalars:
    a view would cost a reference count per pair."""
    if s < n_planes:
        return (planes[s, 0, 0], planes[s, 0, 1], planes[s, 0, 2],
                planes[s, 1, 0], planes[s, 1, 1], planes[s, 1, 2])
    m = s - n_planes
    return (vertex_planes[m, i, 0, 0], vertex_planes[m, i, 0, 1], vertex_planes[m, i, 0, 2],
            vertex_planes[m, i, 1, 0], vertex_planes[m, i, 1, 1], vertex_planes[m, i, 1, 2])


# One function of about 230 lines, and on purpose: it is the inner loop over
# every active vertex, and the pose, the law's coefficients and each plane's
# normal are read into scalars once, before it. Pieces of it as functions
# would take those twenty-odd scalars as arguments per vertex, and the
# ONE_PLANE / ONE_SURFACE builds rely on LLVM seeing the whole loop to drop
# the branches a build never takes (docs/performance.md, "Contact kernel
# throughput").
def _contact(body_vertices, pose, planes, vertex_planes, active, area, law, wear_direction,
             contact_state, tangential, normal_force,
             friction_work, wear_depth, wear_volume, wrench):
    n_points = body_vertices.shape[0]
    if ONE_PLANE:
        # constant counts: LLVM drops the slot loop and the mesh branches
        n_planes = n_slots = 1
    elif ONE_SURFACE:
        # and here the plane branches
        n_planes, n_slots = 0, 1
    else:
        n_planes = planes.shape[0]
        n_slots = n_planes + vertex_planes.shape[0]
    f, f0, wear_law, k, dt = law[0], law[1], int(law[2]), law[3], law[4]
    c0, c1, d0, d1 = law[5], law[6], law[7], law[8]
    ct0, ct1, dt0, dt1 = law[9], law[10], law[11], law[12]
    along_vertex_normal = wear_direction.shape[0] == n_points
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rotation_entries(pose[3:7])
    cx, cy, cz = pose[0], pose[1], pose[2]
    vx, vy, vz = pose[7], pose[8], pose[9]
    wx, wy, wz = pose[10], pose[11], pose[12]
    fx = fy = fz = tx = ty = tz = 0.0
    # per plane: its normal in the body frame, R^T n, and whether it turns
    local = np.empty((n_planes, 4))
    for s in range(n_planes):
        nx, ny, nz = planes[s, 1, 0], planes[s, 1, 1], planes[s, 1, 2]
        local[s, 0] = r00 * nx + r10 * ny + r20 * nz
        local[s, 1] = r01 * nx + r11 * ny + r21 * nz
        local[s, 2] = r02 * nx + r12 * ny + r22 * nz
        turns = planes[s, 3, 0] != 0.0 or planes[s, 3, 1] != 0.0 or planes[s, 3, 2] != 0.0
        local[s, 3] = 1.0 if turns else 0.0
    for slot in range(active.shape[0]):
        # unsigned, so that indexing skips numpy's negative-index wrap-around
        i = np.uint64(active[slot])
        bx, by, bz = body_vertices[i, 0], body_vertices[i, 1], body_vertices[i, 2]
        # world offset from the centre of mass, position and velocity of point A
        rx = r00 * bx + r01 * by + r02 * bz
        ry = r10 * bx + r11 * by + r12 * bz
        rz = r20 * bx + r21 * by + r22 * bz
        px, py, pz = cx + rx, cy + ry, cz + rz
        ux = vx + wy * rz - wz * ry
        uy = vy + wz * rx - wx * rz
        uz = vz + wx * ry - wy * rx
        for s in range(n_slots):
            # the counter-surface's plane under A, read as scalars (an array
            # view here would cost a reference count per pair): point o,
            # normal n, velocity, and n in the body frame (mx, my, mz)
            ox, oy, oz, nx, ny, nz = plane_under(planes, vertex_planes, n_planes, s, i)
            if s < n_planes:
                svx, svy, svz = planes[s, 2, 0], planes[s, 2, 1], planes[s, 2, 2]
                mx, my, mz = local[s, 0], local[s, 1], local[s, 2]
            else:
                # a mesh counter-surface: the plane of its face under this
                # vertex (a zero normal: no face within reach)
                m = s - n_planes
                svx, svy = vertex_planes[m, i, 2, 0], vertex_planes[m, i, 2, 1]
                svz = vertex_planes[m, i, 2, 2]
                mx = r00 * nx + r10 * ny + r20 * nz
                my = r01 * nx + r11 * ny + r21 * nz
                mz = r02 * nx + r12 * ny + r22 * nz
            # penetration (docs/model.md): Delta = (x - o) . n, negative inside
            delta = (px - ox) * nx + (py - oy) * ny + (pz - oz) * nz
            # contact area: the vertex's area vector projected on the plane,
            # -(R a) . n; a vertex whose surface does not face the plane
            # (a side face standing on it) carries nothing
            a = -(mx * area[i, 0] + my * area[i, 1] + mz * area[i, 2])
            if delta >= 0.0 or a <= FACING * area[i, 3]:
                contact_state[s, i] = NO_CONTACT
                normal_force[s, i] = 0.0
                for j in range(3):
                    tangential[s, i, FORCE, j] = 0.0
                continue
            # point of the plane under A
            ax, ay, az = px - delta * nx, py - delta * ny, pz - delta * nz
            # the counter-surface's velocity there: a plane's translation plus
            # its turn about its point (skipped for a plane that does not
            # turn: it adds zero); a mesh surface's, as given
            if s < n_planes and local[s, 3] != 0.0:
                wpx, wpy, wpz = planes[s, 3, 0], planes[s, 3, 1], planes[s, 3, 2]
                kx, ky, kz = ax - ox, ay - oy, az - oz
                svx += wpy * kz - wpz * ky
                svy += wpz * kx - wpx * kz
                svz += wpx * ky - wpy * kx
            # velocity of A relative to the surface: normal rate and slip velocity
            gx, gy, gz = ux - svx, uy - svy, uz - svz
            rate = gx * nx + gy * ny + gz * nz
            sx, sy, sz = gx - rate * nx, gy - rate * ny, gz - rate * nz
            # coefficients of the point (docs/model.md, per point or per area)
            c, d, ct, dtan = c0 + c1 * a, d0 + d1 * a, ct0 + ct1 * a, dt0 + dt1 * a
            # eq. 1: spring-damper normal force, no adhesion
            load = -(c * delta + d * rate)
            if load < 0.0:
                load = 0.0
            normal_force[s, i] = load
            state = contact_state[s, i]
            reversed_now = False
            # eq. 2-4, the friction state of the pair (tangential[s, i]): stick
            # anchor o, force when stick began h, friction force F, last slip
            # velocity l; read and written only where the state machine needs them
            if state == STICK:
                # the anchor is a point of the counter-surface: it moves with it
                tangential[s, i, ANCHOR, 0] += svx * dt
                tangential[s, i, ANCHOR, 1] += svy * dt
                tangential[s, i, ANCHOR, 2] += svz * dt
            elif state == NO_CONTACT:
                # a new contact starts in stick with F0 = 0 at its position
                # when it came into contact, within this step: its position
                # on the plane at the step's start, so the step's slip
                # stretches the spring and a point touching down on a
                # surface sliding under it slips at once where that exceeds
                # f0 N (anchored at its end, it held one step without slip
                # or wear, and vertices riding over a worn mesh's facets,
                # touching down step after step, never wore)
                state = STICK
                tangential[s, i, ANCHOR, 0] = ax - sx * dt
                tangential[s, i, ANCHOR, 1] = ay - sy * dt
                tangential[s, i, ANCHOR, 2] = az - sz * dt
                for j in range(3):
                    tangential[s, i, START_FORCE, j] = 0.0
                tangential[s, i, SLIP_VELOCITY, 0] = sx
                tangential[s, i, SLIP_VELOCITY, 1] = sy
                tangential[s, i, SLIP_VELOCITY, 2] = sz
            elif state == SLIP and (sx * tangential[s, i, SLIP_VELOCITY, 0]
                                    + sy * tangential[s, i, SLIP_VELOCITY, 1]
                                    + sz * tangential[s, i, SLIP_VELOCITY, 2]) < 0.0:
                # slip velocity reversed: stick from the turning point, one
                # step back, holding the slip force (Jenkins element: the
                # force is continuous). F0 is that force at the current load,
                # -f N l/|l|. The spring unloads from it and slips again in
                # this same step only if the step carried it past -F0 (a stiff
                # spring, a coarse step); the limit gets a margin of
                # REVERSAL_MARGIN, because at a turning point that falls on a
                # step the slip velocity is round-off, and a round-off excess
                # of |F| over f0 N must not skip a whole stick branch
                state = STICK
                reversed_now = True
                tangential[s, i, ANCHOR, 0] = ax - sx * dt
                tangential[s, i, ANCHOR, 1] = ay - sy * dt
                tangential[s, i, ANCHOR, 2] = az - sz * dt
                lx = tangential[s, i, SLIP_VELOCITY, 0]
                ly = tangential[s, i, SLIP_VELOCITY, 1]
                lz = tangential[s, i, SLIP_VELOCITY, 2]
                scale = -f * load / np.sqrt(lx * lx + ly * ly + lz * lz)
                tangential[s, i, START_FORCE, 0] = scale * lx
                tangential[s, i, START_FORCE, 1] = scale * ly
                tangential[s, i, START_FORCE, 2] = scale * lz
            speed2 = sx * sx + sy * sy + sz * sz
            speed = energy = 0.0
            Fx = Fy = Fz = 0.0
            if state == STICK:
                # eq. 2, stick: F = F0 - c_t (r - r0) - d_t v, r - r0 in the plane
                ex = ax - tangential[s, i, ANCHOR, 0]
                ey = ay - tangential[s, i, ANCHOR, 1]
                ez = az - tangential[s, i, ANCHOR, 2]
                en = ex * nx + ey * ny + ez * nz
                Fx = tangential[s, i, START_FORCE, 0] - ct * (ex - en * nx) - dtan * sx
                Fy = tangential[s, i, START_FORCE, 1] - ct * (ey - en * ny) - dtan * sy
                Fz = tangential[s, i, START_FORCE, 2] - ct * (ez - en * nz) - dtan * sz
                Fn = Fx * nx + Fy * ny + Fz * nz
                Fx, Fy, Fz = Fx - Fn * nx, Fy - Fn * ny, Fz - Fn * nz
                limit = f0 * load * (REVERSAL_MARGIN if reversed_now else 1.0)
                if Fx * Fx + Fy * Fy + Fz * Fz > limit * limit:
                    # eq. 4: static limit exceeded, slip in the direction the
                    # spring was dragged (or of the slip velocity if any)
                    state = SLIP
                    if speed2 == 0.0:
                        tangential[s, i, SLIP_VELOCITY, 0] = -Fx
                        tangential[s, i, SLIP_VELOCITY, 1] = -Fy
                        tangential[s, i, SLIP_VELOCITY, 2] = -Fz
                else:
                    # dissipated energy (docs/model.md): the dashpot's
                    energy = dtan * speed2 * dt
            if speed2 > 0.0:
                tangential[s, i, SLIP_VELOCITY, 0] = sx
                tangential[s, i, SLIP_VELOCITY, 1] = sy
                tangential[s, i, SLIP_VELOCITY, 2] = sz
            if state == SLIP:
                # eq. 3: Coulomb slip force against the (last) slip direction
                if speed2 > 0.0:
                    lx, ly, lz = sx, sy, sz
                    speed = np.sqrt(speed2)
                    ll = speed
                else:
                    lx = tangential[s, i, SLIP_VELOCITY, 0]
                    ly = tangential[s, i, SLIP_VELOCITY, 1]
                    lz = tangential[s, i, SLIP_VELOCITY, 2]
                    ll = np.sqrt(lx * lx + ly * ly + lz * lz)
                if ll > 0.0:
                    scale = -f * load / ll
                    Fx, Fy, Fz = scale * lx, scale * ly, scale * lz
                # dissipated energy (docs/model.md): f N |v| dt
                energy = f * load * speed * dt
            contact_state[s, i] = state
            tangential[s, i, FORCE, 0] = Fx
            tangential[s, i, FORCE, 1] = Fy
            tangential[s, i, FORCE, 2] = Fz
            # eq. 5 and variants: wear depth and volume increments of the
            # law (meshwear.kernels.laws; speed is zero unless it slips)
            dw, dv = wear_increment(wear_law, k, energy, load, speed * dt, a)
            friction_work[i] += energy
            if dw > 0.0:
                wear_depth[i] += dw
                wear_volume[i] += dv
                # geometry update (docs/model.md): into the body along +n, in
                # the body frame; (mx, my, mz) is the contact normal there
                if along_vertex_normal:
                    mx, my, mz = wear_direction[i, 0], wear_direction[i, 1], wear_direction[i, 2]
                    if state == STICK:
                        # the vertex's foot on the plane moves with the part of
                        # the wear step along the plane: move the anchor with
                        # it, so wear does not load the stick spring
                        hx = r00 * mx + r01 * my + r02 * mz
                        hy = r10 * mx + r11 * my + r12 * mz
                        hz = r20 * mx + r21 * my + r22 * mz
                        hn = hx * nx + hy * ny + hz * nz
                        tangential[s, i, ANCHOR, 0] += dw * (hx - hn * nx)
                        tangential[s, i, ANCHOR, 1] += dw * (hy - hn * ny)
                        tangential[s, i, ANCHOR, 2] += dw * (hz - hn * nz)
                body_vertices[i, 0] += dw * mx
                body_vertices[i, 1] += dw * my
                body_vertices[i, 2] += dw * mz
            # force on the body from this contact, and its moment about the centre
            qx, qy, qz = load * nx + Fx, load * ny + Fy, load * nz + Fz
            fx += qx
            fy += qy
            fz += qz
            tx += ry * qz - rz * qy
            ty += rz * qx - rx * qz
            tz += rx * qy - ry * qx
    wrench[0], wrench[1], wrench[2] = fx, fy, fz
    wrench[3], wrench[4], wrench[5] = tx, ty, tz


#: the builds a copy of _dispatch calls, set per copy by _build
GENERAL_BUILD = ONE_PLANE_BUILD = ONE_SURFACE_BUILD = None


def _dispatch(body_vertices, pose, planes, vertex_planes, active, area, law, wear_direction,
              contact_state, tangential, normal_force,
              friction_work, wear_depth, wear_volume, wrench):
    """The kernel: GENERAL_BUILD, or ONE_PLANE_BUILD for one analytic plane
    and no per-vertex surface, or ONE_SURFACE_BUILD for one per-vertex surface
    and no plane (the same computation, compiled for that case)."""
    if planes.shape[0] == 1 and vertex_planes.shape[0] == 0:
        ONE_PLANE_BUILD(body_vertices, pose, planes, vertex_planes, active, area, law,
                        wear_direction, contact_state, tangential, normal_force,
                        friction_work, wear_depth, wear_volume, wrench)
    elif planes.shape[0] == 0 and vertex_planes.shape[0] == 1:
        ONE_SURFACE_BUILD(body_vertices, pose, planes, vertex_planes, active, area, law,
                          wear_direction, contact_state, tangential, normal_force,
                          friction_work, wear_depth, wear_volume, wrench)
    else:
        GENERAL_BUILD(body_vertices, pose, planes, vertex_planes, active, area, law,
                      wear_direction, contact_state, tangential, normal_force,
                      friction_work, wear_depth, wear_volume, wrench)


def _named_copy(fn, name, **constants):
    """The same function under another name, ``constants`` added to (or
    replacing) its module globals. numba's on-disk cache is keyed by the
    qualified name, so each build needs its own; numba compiles globals as
    constants, so ``ONE_PLANE=True`` gives the specialised build."""
    copy = types.FunctionType(fn.__code__, dict(fn.__globals__, **constants), name,
                              fn.__defaults__, fn.__closure__)
    copy.__qualname__ = name
    return copy


# fastmath "contract" only: lets LLVM fuse a*b + c into one FMA (one rounding
# instead of two, +20% here). Results stay deterministic on a machine but may
# differ in the last bits between CPUs with and without FMA; NaN and infinity
# keep their IEEE meaning (no "nnan"/"ninf"), so non-finite states are still
# caught downstream. error_model="numpy": a division by zero gives inf or NaN
# (IEEE) instead of raising ZeroDivisionError, which drops a test and a branch
# per division (+9 %); the kernel divides only by a contact area above FACING
# times its length, by a slip speed checked > 0 and by the length of a last
# slip velocity a reversal has just found non-zero.
_FLAGS = {"contract"}


#: each kernel's builds by name: general, one plane, one surface
BUILDS = {}

#: the threaded kernel's pieces: a power of two of them (so that they share
#: out evenly over 2, 4, 8 ... threads), at most :data:`CHUNKS`, of at least
#: :data:`CHUNK` active vertices each; a split fixed by the active set alone,
#: so that the wrench's sum is the same whatever the number of threads
CHUNKS, CHUNK = 64, 512


@njit(cache=True, inline="always")
def pieces(n):
    """How many pieces the threaded kernels cut ``n`` active vertices into."""
    chunks = 1
    while chunks < CHUNKS and 2 * chunks * CHUNK <= n:
        chunks *= 2
    return chunks
#: the serial build a copy of _threaded runs on each piece, set per copy by _build
SERIAL_BUILD = None


def _threaded(body_vertices, pose, planes, vertex_planes, active, area, law, wear_direction,
              contact_state, tangential, normal_force, friction_work, wear_depth, wear_volume,
              wrench):
    """The threaded kernel: SERIAL_BUILD on pieces of ``active`` in threads,
    their wrenches added in order. Each piece touches only its own vertices,
    so the per-vertex results are the serial kernel's, bit for bit; and the
    threaded build compiles only this loop, not the kernel once more (numba
    compiles a threaded loop's body anew: 10-20 s for the kernel's)."""
    n = active.shape[0]
    chunks = pieces(n)
    partial = np.zeros((chunks, 6))
    for c in prange(chunks):
        SERIAL_BUILD(body_vertices, pose, planes, vertex_planes,
                     active[c * n // chunks:(c + 1) * n // chunks], area, law, wear_direction,
                     contact_state, tangential, normal_force, friction_work, wear_depth,
                     wear_volume, partial[c])
    for j in range(6):
        total = 0.0
        for c in range(chunks):
            total += partial[c, j]
        wrench[j] = total


def _build(name, parallel):
    """``name``: the kernel, serial or threaded, dispatching to its general
    build or to the ones compiled for one analytic plane and no per-vertex
    surface, and for one per-vertex surface and no plane (also in
    :data:`BUILDS`, for a caller that knows its case and compiles only it).
    A threaded build runs the serial build of its case in threads."""
    if parallel:
        builds = tuple(njit(cache=True, parallel=True)(_named_copy(
            _threaded, f"{name}_{case}", SERIAL_BUILD=serial))
            for case, serial in zip(("general", "one_plane", "one_surface"),
                                    BUILDS["contact_serial"]))
    else:
        options = dict(cache=True, fastmath=_FLAGS, error_model="numpy")
        builds = (njit(**options)(_named_copy(_contact, name + "_general")),
                  njit(**options)(_named_copy(_contact, name + "_one_plane", ONE_PLANE=True)),
                  njit(**options)(_named_copy(_contact, name + "_one_surface",
                                              ONE_SURFACE=True)))
    BUILDS[name] = builds
    general, one_plane, one_surface = builds
    return njit(cache=True)(_named_copy(_dispatch, name, GENERAL_BUILD=general,
                                        ONE_PLANE_BUILD=one_plane,
                                        ONE_SURFACE_BUILD=one_surface))


contact_serial = _build("contact_serial", parallel=False)
contact_parallel = _build("contact_parallel", parallel=True)


def contact(body_vertices, pose, planes, vertex_planes, active, area, law, wear_direction,
            contact_state, tangential, normal_force, friction_work, wear_depth, wear_volume,
            wrench):
    """Contact, friction and wear of the ``active`` vertices against every
    plane and mesh counter-surface, one step.

    See the module docstring for the arrays. Picks the threaded kernel when the
    number of vertex-surface pairs makes threads worth starting.
    """
    slots = planes.shape[0] + vertex_planes.shape[0]
    name = "contact_parallel" if active.shape[0] * slots >= PARALLEL_THRESHOLD else "contact_serial"
    # the build for the case, picked here as _dispatch picks it in a compiled
    # caller (so that a first run compiles only the build it uses)
    general, one_plane, one_surface = BUILDS[name]
    if planes.shape[0] == 1 and vertex_planes.shape[0] == 0:
        kernel = one_plane
    elif planes.shape[0] == 0 and vertex_planes.shape[0] == 1:
        kernel = one_surface
    else:
        kernel = general
    kernel(body_vertices, pose, planes, vertex_planes, active, area, law, wear_direction,
           contact_state, tangential, normal_force, friction_work, wear_depth, wear_volume, wrench)


def all_vertices(n):
    """The ``active`` array that processes every one of ``n`` vertices."""
    return np.arange(n, dtype=np.int64)


def no_mesh_planes(n):
    """The ``vertex_planes`` array of a body that meets no mesh surface."""
    return np.zeros((0, n, 3, 3))
