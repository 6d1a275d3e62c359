"""The compiled step loop: many steps of one body without returning to Python.

:func:`advance_body` runs the steps of :func:`meshwear.step.simulate.step_body`
(the Python reference it must match to the last bit) for one worn body, from
step ``k`` up to ``stop``, and hands back to Python whatever it does not do
itself: an active-set refresh (before the step that needs it, having changed
nothing of that step, or, in the quasi-static mode, after the settling move
of a step, for Python to finish it), a load nothing carries and a counter
vertex worn too deep. Bodies do not act on one another (only on
counter-surfaces), so each runs on its own between two output times, unless
a counter-surface they share wears (then :mod:`meshwear.step.stepper` steps them
in turn, one step each).

Arguments are grouped in tuples (:mod:`meshwear.step.stepper` packs them):

body
    ``vertices, pose, area, law, wear_direction, contact_state, tangential,
    normal_force, friction_work, wear_depth, wear_volume, wrench,
    vertex_planes, hint, active, active_wear, cull, distance, load`` (the
    arrays of :class:`meshwear.model.BodyState` and its model; ``load`` (5, n)
    adds up each vertex's total normal force, its square and its vector over
    the steps, or is (2, 0): :data:`meshwear.longrun.jumps.LOAD_ROWS`) and
    ``radius`` (m).
motion
    ``kind`` and ``params`` (:mod:`meshwear.kernels.rigid`), the path
    ``terms``, ``buffer`` (2, 3) and the balance's ``scratch`` (2, m), at
    least as long as the active vertices times the slots.
planes
    The contact kernel's ``planes`` (P, 4, 3) and, per plane, its motion
    (P, 19), path terms (P, K, 9), normal and point at rest (P, 3) and
    whether it moves (P,) (:func:`meshwear.kernels.frames.plane_rows`).
surfaces
    A typed list of surface tuples (:mod:`meshwear.kernels.counter`).
bounds, terms
    The active-set bounds of every slot (:mod:`meshwear.kernels.frames`).
report
    (2,) int64: where a counter vertex worn too deep (surface, vertex) or a
    body vertex gone too deep (slot, vertex) is reported.
"""

import numpy as np
from .jit import njit

from .balance import balance_offset
from .contact import (BUILDS, PARALLEL_THRESHOLD, _named_copy, contact_parallel, contact_serial,
                      plane_under, rotation_entries)
from .counter import NAMES, PARALLEL_THRESHOLD as LOOKUP_THRESHOLD, fill_planes, fill_planes_for
from .counter_wear import wear_counter
from .frames import moved_since_refresh, plane_rows, step_motion, surface_frame
from .rigid import (AXIS, BALANCED, CARRIED, FIXED, FREE, TURNING, advance_free_motion,
                    advance_motion, place_motion)
from .turn_balance import place_settled, settle_turn

#: what :func:`advance_body` returns besides the step it reached
DONE, REFRESH, FINISH, NO_BALANCE, TOO_DEEP, IMPACT = 0, 1, 2, 3, 4, 5


# The loop is compiled in builds from the one definition (as the contact
# kernel is, meshwear.kernels.contact._build), one per kind of scene
# (:func:`loop_build`): numba compiles globals as constants and prunes the
# branches of a constant False before typing them, so a build compiles only
# the counter-surface kinds, contact case, threads and motions its scenes
# use, and a first run compiles only the build its scene needs
# (docs/performance.md, "The first run compiles").
#: the build's constants: per-vertex counter-surfaces, worn ones, the
#: threaded contact kernel, and the contact kernels it calls
MESHES, WORN, PARALLEL = True, True, True
SERIAL_CONTACT, PARALLEL_CONTACT = contact_serial, contact_parallel
#: a build for dynamic runs only: the quasi-static step (the path placed at
#: the step's end, the load balance) is left out (the build for free bodies
#: also takes ``advance_motion=advance_free_motion``)
DYNAMIC_ONLY = False
#: a build for quasi-static runs only: the dynamic step is left out
QUASI_STATIC_ONLY = False
#: a build with the torque balance of turning bodies (kind TURNING,
#: :mod:`meshwear.kernels.turn_balance`); only the scenes that have one
#: compile it
TURNS = False


def _fill(body, planes, surfaces, t, buffer, rotation, frame):
    """The planes of every surface at ``t`` under the body's active vertices."""
    vertices, pose = body[0], body[1]
    vertex_planes, hint, active, distance = body[12], body[13], body[14], body[17]
    plane_array, plane_motion, plane_terms, normal0, point0, moving = planes
    for j in range(plane_array.shape[0]):
        if moving[j]:
            plane_rows(plane_motion[j], plane_terms[j], normal0[j], point0[j], t, buffer,
                       plane_array[j])
    if MESHES:
        for j in range(len(surfaces)):
            fill_planes(surfaces[j], t, vertices, pose, active, vertex_planes[j], distance,
                        hint[j], buffer, rotation, frame)


def _touch(body, plane_array):
    """One step of the contact kernel; the normal forces, their squares and
    their vectors (along each slot's normal) added to ``load``
    (:data:`meshwear.longrun.jumps.LOAD_ROWS`)."""
    (vertices, pose, area, law, wear_direction, contact_state, tangential, normal_force,
     friction_work, wear_depth, wear_volume, wrench, vertex_planes, hint, active, active_wear,
     cull, distance, load, radius, depth_limit, impact_room, _, _, _) = body
    slots = plane_array.shape[0] + vertex_planes.shape[0]
    threads = False
    if PARALLEL:
        threads = active.shape[0] * slots >= PARALLEL_THRESHOLD
        if threads:
            PARALLEL_CONTACT(vertices, pose, plane_array, vertex_planes, active, area, law,
                             wear_direction, contact_state, tangential, normal_force,
                             friction_work, wear_depth, wear_volume, wrench)
    if not threads:
        SERIAL_CONTACT(vertices, pose, plane_array, vertex_planes, active, area, law,
                       wear_direction, contact_state, tangential, normal_force, friction_work,
                       wear_depth, wear_volume, wrench)
    if load.shape[1]:
        n_planes = plane_array.shape[0]
        vectors = load.shape[0] > 2
        for k in range(active.shape[0]):
            i = active[k]
            total = fx = fy = fz = 0.0
            for s in range(slots):
                f = normal_force[s, i]
                if f > 0.0:
                    total += f
                    _, _, _, nx, ny, nz = plane_under(plane_array, vertex_planes, n_planes, s,
                                                      i)
                    fx += f * nx
                    fy += f * ny
                    fz += f * nz
            load[0, i] += total
            load[1, i] += total * total
            if vectors:
                load[2, i] += fx
                load[3, i] += fy
                load[4, i] += fz


@njit(cache=True)
def deepest_penetration(vertices, pose, plane_array, vertex_planes, active, contact_state):
    """The deepest penetration (m, positive inside) of the body's vertices in
    contact (``contact_state`` not 0) at ``pose``, with its slot and vertex
    (-1, -1 when none is in contact): docs/model.md, "Impacts"."""
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rotation_entries(pose[3:7])
    n_planes = plane_array.shape[0]
    deepest, where_slot, where_vertex = 0.0, -1, -1
    for k in range(active.shape[0]):
        i = active[k]
        bx, by, bz = vertices[i, 0], vertices[i, 1], vertices[i, 2]
        px = pose[0] + r00 * bx + r01 * by + r02 * bz
        py = pose[1] + r10 * bx + r11 * by + r12 * bz
        pz = pose[2] + r20 * bx + r21 * by + r22 * bz
        for s in range(contact_state.shape[0]):
            if contact_state[s, i] == 0:
                continue
            ox, oy, oz, nx, ny, nz = plane_under(plane_array, vertex_planes, n_planes, s, i)
            depth = -((px - ox) * nx + (py - oy) * ny + (pz - oz) * nz)
            if depth > deepest:
                deepest, where_slot, where_vertex = depth, s, i
    return deepest, where_slot, where_vertex


@njit(cache=True)
def impact_check(vertices, pose, plane_array, vertex_planes, active, contact_state, depth_limit,
                 impact_room):
    """``(slot, vertex)`` of a vertex in contact deeper than ``depth_limit``,
    else ``(-1, -1)``. Conservative advancement: the deepest penetration is
    measured only once the body's motion since the last measurement
    (:func:`use_impact_room`) may have used up the room it left below the
    limit; between, no vertex can have gone that deep."""
    if impact_room[0] > 0.0:
        return -1, -1
    depth, slot, vertex = deepest_penetration(vertices, pose, plane_array, vertex_planes,
                                              active, contact_state)
    if depth > depth_limit:
        return slot, vertex
    impact_room[0] = depth_limit - depth
    return -1, -1


@njit(cache=True)
def use_impact_room(impact_room, pose, radius, bounds, terms, t, dt, buffer):
    """Take the step just moved (the body's new velocities, the surfaces'
    speeds) off ``impact_room``."""
    impact_room[0] -= step_motion(pose, radius, bounds, terms, t, dt, buffer)


@njit(cache=True)
def _wear_parts(body, surfaces, law, n_planes, t, buffer, rotation, frame, report):
    """The worn counter-surfaces' wear by the step just taken at ``t``
    (:func:`meshwear.kernels.counter_wear.wear_counter`); False, with the
    surface and vertex in ``report``, if a counter vertex sank too deep."""
    vertices, pose, area = body[0], body[1], body[2]
    contact_state, normal_force = body[5], body[7]
    vertex_planes, hint, active = body[12], body[13], body[14]
    for m in range(len(surfaces)):
        surface = surfaces[m]
        part = surface[14]
        if part[0][0] < 0.0:
            continue
        surface_frame(surface[2], surface[3], t, surface[4], buffer, rotation, frame)
        worst = wear_counter(vertices, pose, active, area, law, contact_state[n_planes + m],
                             normal_force[n_planes + m], vertex_planes[m], hint[m], rotation,
                             frame, part, m, body[22], body[23], body[24])
        if worst >= 0:
            report[0], report[1] = m, worst
            return False
    return True


@njit(cache=True)
def _needs_refresh(body, bounds, terms, t, dt, buffer, cull_enabled):
    """``meshwear.surfaces.needs_refresh``: the active set must be rebuilt before a step at ``t``."""
    pose, wear_depth, active, active_wear, cull, radius = (body[1], body[9], body[14], body[15],
                                                           body[16], body[19])
    if not cull_enabled:
        return False
    if cull[0] == 0.0:
        return True
    return (moved_since_refresh(pose, cull, radius, bounds, terms, t, wear_depth, active,
                                active_wear, buffer)
            + step_motion(pose, radius, bounds, terms, t, dt, buffer) >= cull[0])


def _advance_body(k, stop, dt, quasi_static, cull_enabled, body, motion, planes, surfaces, bounds,
                  terms, report):
    """Step one body from step ``k`` up to ``stop``. Returns ``(step, what)``:
    the step reached and :data:`DONE` (``step == stop``), :data:`REFRESH`
    (step ``step`` needs an active-set refresh first; nothing of it is done),
    :data:`FINISH` (quasi-static: step ``step`` is placed, its planes queried
    and the body settled, but its bound is reached: refresh, query and touch
    are left), :data:`NO_BALANCE` (no contact carries the load at step
    ``step``), :data:`TOO_DEEP` (step ``step`` wore a counter vertex deeper
    than its mesh follows: surface and vertex in ``report``; the step's
    contact is done, its motion is not) or :data:`IMPACT` (the dynamic step
    ``step`` found a vertex in contact deeper than ``depth_limit``: slot and
    vertex in ``report``; its contact is done, its motion is not)."""
    vertices, pose, area, law = body[0], body[1], body[2], body[3]
    vertex_planes, active, cull, radius = body[12], body[14], body[16], body[19]
    depth_limit, impact_room = body[20], body[21]
    kind, params, path_terms, buffer, scratch = motion
    plane_array = planes[0]
    n_planes = plane_array.shape[0]
    worn = False
    if WORN:
        for m in range(len(surfaces)):
            worn = worn or surfaces[m][14][0][0] >= 0.0
    rotation, frame = np.zeros((3, 3)), np.zeros((4, 3))
    placed = np.zeros(13)
    no_scale = np.zeros(0)
    if (quasi_static and (kind == BALANCED or (TURNS and kind == TURNING))
            and scratch.shape[1] < active.shape[0] * (plane_array.shape[0] + vertex_planes.shape[0])):
        return k, REFRESH                # Python grows the scratch
    while k < stop:
        if not QUASI_STATIC_ONLY:
            if DYNAMIC_ONLY or not quasi_static:
                t = k * dt
                if _needs_refresh(body, bounds, terms, t, dt, buffer, cull_enabled):
                    return k, REFRESH
                _fill(body, planes, surfaces, t, buffer, rotation, frame)
                _touch(body, plane_array)
                if WORN:
                    if worn and not _wear_parts(body, surfaces, law, n_planes, t, buffer, rotation,
                                                frame, report):
                        return k, TOO_DEEP
                if depth_limit > 0.0:
                    slot, vertex = impact_check(vertices, pose, plane_array, vertex_planes, active,
                                                body[5], depth_limit, impact_room)
                    if slot >= 0:
                        report[0], report[1] = slot, vertex
                        return k, IMPACT
                advance_motion(kind, params, path_terms, buffer, pose, body[11], t, dt)
                if depth_limit > 0.0:
                    use_impact_room(impact_room, pose, radius, bounds, terms, t, dt, buffer)
                k += 1
                continue
        # quasi-static: where the path puts the body at the end of the step,
        # with the velocity of that increment (on a copy: a refresh must find
        # the step untouched)
        t = (k + 1) * dt
        for j in range(13):
            placed[j] = pose[j]
        place_motion(kind, params, path_terms, buffer, placed, t)
        if TURNS:
            if kind == TURNING:
                place_settled(placed, params, path_terms, t, buffer)
        for j in range(3):
            placed[7 + j] = (placed[j] - pose[j]) / dt
        # (the angular velocity is the path's: zero, or a steady turn's)
        saved = pose.copy()
        for j in range(13):
            pose[j] = placed[j]
        if _needs_refresh(body, bounds, terms, t, dt, buffer, cull_enabled):
            for j in range(13):
                pose[j] = saved[j]
            return k, REFRESH
        _fill(body, planes, surfaces, t, buffer, rotation, frame)
        if kind == BALANCED:
            z = balance_offset(vertices, pose, params[AXIS], plane_array, vertex_planes, active,
                               area, law, params[CARRIED], 0.0, scratch, no_scale)
            if not np.isfinite(z):
                return k, NO_BALANCE
            for j in range(3):
                pose[j] += z * params[AXIS][j]
            for j in range(3):
                pose[7 + j] = (pose[j] - saved[j]) / dt
            if cull_enabled and moved_since_refresh(pose, cull, radius, bounds, terms, t,
                                                    body[9], active, body[15], buffer) >= cull[0]:
                return k, FINISH
        if TURNS:
            if kind == TURNING:
                angle = settle_turn(vertices, pose, params, path_terms, t, dt, buffer,
                                    plane_array, vertex_planes, active, area, law, scratch)
                if not np.isfinite(angle):
                    return k, NO_BALANCE
                for j in range(3):
                    pose[7 + j] = (pose[j] - saved[j]) / dt
                if cull_enabled and moved_since_refresh(pose, cull, radius, bounds, terms, t,
                                                        body[9], active, body[15],
                                                        buffer) >= cull[0]:
                    return k, FINISH
        _touch(body, plane_array)
        if WORN:
            if worn and not _wear_parts(body, surfaces, law, n_planes, t, buffer, rotation, frame,
                                        report):
                return k, TOO_DEEP
        k += 1
    return k, DONE


#: the counter-surface kinds a build can meet (:data:`meshwear.kernels.counter.KINDS`)
ALL_KINDS = ("cylinder", "mesh", "sphere")
#: the contact kernels' cases (the index into :data:`meshwear.kernels.contact.BUILDS`;
#: None: the dispatch that picks one at each call)
GENERAL, ONE_PLANE, ONE_SURFACE = 0, 1, 2

#: the builds made so far, by :func:`loop_build`'s arguments
_LOOPS = {}


def loop_build(kinds=ALL_KINDS, worn=True, threaded=True, case=None, dynamic=None, free=False,
               turns=False):
    """The build of :func:`advance_body` for the scenes that meet per-vertex
    counter-surfaces of ``kinds`` only (worn ones if ``worn``), have bodies
    large enough for the threaded kernels (``threaded``), call the contact
    kernel's ``case`` build, run dynamically (``dynamic`` True), quasi-statically
    (False) or either (None), and move only free or fixed bodies (``free``).
    Each build is made once and cached on disk under its own name; the
    defaults make the full one, :data:`advance_body`."""
    kinds = tuple(sorted(set(kinds)))
    worn = worn and bool(kinds)
    turns = turns and dynamic is not True
    key = (kinds, worn, threaded, case, dynamic, free, turns)
    if key in _LOOPS:
        return _LOOPS[key]
    full = key == (ALL_KINDS, True, True, None, None, False, False)
    parts = ["".join(k[0] for k in kinds) or "planes", "worn" if worn else "",
             "threads" if threaded else "serial",
             {None: "any", GENERAL: "general", ONE_PLANE: "plane", ONE_SURFACE: "surface"}[case],
             {None: "", True: "dynamic", False: "quasi"}[dynamic], "free" if free else "",
             "turns" if turns else ""]
    name = "" if full else "_" + "_".join(p for p in parts if p)
    constants = dict(MESHES=bool(kinds), WORN=worn, PARALLEL=threaded,
                     DYNAMIC_ONLY=dynamic is True, QUASI_STATIC_ONLY=dynamic is False,
                     TURNS=turns,
                     fill_planes=fill_planes_for(kinds, threaded))
    if case is not None:
        constants.update(SERIAL_CONTACT=BUILDS["contact_serial"][case],
                         PARALLEL_CONTACT=BUILDS["contact_parallel"][case])
    if free:
        constants["advance_motion"] = advance_free_motion
    fill = njit(cache=True)(_named_copy(_fill, "_fill" + name, **constants))
    touch = njit(cache=True)(_named_copy(_touch, "_touch" + name, **constants))
    _LOOPS[key] = njit(cache=True)(_named_copy(_advance_body, "advance_body" + name, _fill=fill,
                                               _touch=touch, **constants))
    return _LOOPS[key]


#: the loop: every counter-surface, both contact kernels, either mode
advance_body = loop_build()


def scene_build(model, dynamic=None):
    """:func:`loop_build`'s arguments for ``model``'s scene (``dynamic``: the
    mode its caller runs the loop in; the model's own by default)."""
    per_vertex = model.surfaces.per_vertex
    n_planes, n_surfaces = model.planes.shape[0], len(per_vertex)
    slots = n_planes + n_surfaces
    if dynamic is None:
        dynamic = not model.quasi_static
    case = (ONE_PLANE if (n_planes, n_surfaces) == (1, 0)
            else ONE_SURFACE if (n_planes, n_surfaces) == (0, 1) else GENERAL)
    build = dict(kinds=tuple(NAMES[s.kind] for s in per_vertex),
                worn=any(s.worn for s in per_vertex),
                # (the threaded contact from its threshold of vertex-surface
                # pairs, the threaded lookups from theirs of vertices)
                threaded=any(len(b.tributary_area) * slots >= PARALLEL_THRESHOLD
                             or (n_surfaces and len(b.tributary_area) >= LOOKUP_THRESHOLD)
                             for b in model.bodies),
                case=case, dynamic=dynamic,
                free=dynamic and all(b.motion.kind in (FREE, FIXED) for b in model.bodies))
    if not dynamic and any(b.motion.kind == TURNING for b in model.bodies):
        build["turns"] = True            # (only then: the others' builds keep their names)
    return build


def loop_for(model, dynamic=None):
    """The build of :func:`advance_body` that ``model`` needs (see :func:`scene_build`)."""
    return loop_build(**scene_build(model, dynamic))
