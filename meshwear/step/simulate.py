"""The step loop. :func:`step_body` fixes the phase order of a step of one
body; :func:`run` drives the steps and calls the observers (recorders) at the
sample and frame times.

Phase order of one step of a body: the surfaces at the step's time and the
active-set check, then contact -> normal force -> friction -> energy -> wear
-> geometry update (one fused kernel, docs/model.md), then the body's motion
from the contact wrench just computed (quasi-static: placed on its path and
in load balance first). Runs take their steps in the compiled loop
(:mod:`meshwear.step.stepper`), which runs the same kernels in the same order;
:func:`step` is its Python reference.
"""

from functools import partial

import numpy as np
from threadpoolctl import threadpool_limits

from ..contact import elastic
from ..contact.winkler import body_contact
from . import stepper
from .. import surfaces
from ..geometry.properties import inverted_faces
from ..kernels.loop import deepest_penetration, impact_check, use_impact_room
from ..kernels.rigid import TURNING
from ..model.build import IMPACT_DEPTH
from .counters import settle_counters, wear_counters
from ..output.memory import MemoryHistory
from ..longrun.wear import run_cycle_jump


#: steps between two progress reports at most
PROGRESS_STEPS = 2000


class NumericalError(RuntimeError):
    """The run became numerically invalid (NaN, instability, inverted triangles)."""


def step(model, state):
    """Advance ``state`` by one time step of ``model``, in place: the Python
    reference of the compiled loop (:func:`advance` uses that)."""
    if not model.dynamics.step(model, state, state.step, partial(_step_bodies, model, state)):
        raise NumericalError(model.dynamics.instability(model, state.time))
    state.step += 1
    state.time = state.step * model.dt


def _step_bodies(model, state, k):
    for body, s in zip(model.bodies, state.bodies):
        step_body(model, body, s, k)


def step_body(model, body, s, k):
    """Step ``k`` of one body (bodies act on counter-surfaces only, never on
    each other, so each can be stepped on its own)."""
    if model.quasi_static:
        _quasi_static_step(model, body, s, k)
        return
    t = k * model.dt
    surfaces.update(model, body, s, t)
    touch(model, body, s, t)
    if body.depth_limit > 0.0:
        slot, vertex = impact_check(s.vertices, s.pose, model.planes, s.vertex_planes, s.active,
                                    s.contact_state, body.depth_limit, s.impact_room)
        if slot >= 0:
            raise impact_too_deep(model, body, s, slot, vertex, t)
    body.motion.advance(s.pose, s.wrench, t, model.dt)
    if body.depth_limit > 0.0:
        use_impact_room(s.impact_room, s.pose, body.radius, model.surfaces.bounds,
                        model.surfaces.terms, t, model.dt, body.motion.path.buffer)


def _quasi_static_step(model, body, s, k):
    """Quasi-static: put the body where it is at the end of the step (on its
    path, a guided one in load balance), with the velocity of that
    increment, then evaluate contact, friction and wear there. Friction thus
    follows the tangential displacement increments, and the contact forces
    of the new state carry its load exactly."""
    t = (k + 1) * model.dt
    before = s.pose[0:3].copy()
    body.motion.place(s.pose, t)
    s.pose[7:10] = (s.pose[0:3] - before) / model.dt
    # (the angular velocity is the path's: zero, or a steady turn's)
    # the planes under the vertices where the path puts the body, then the
    # balance along its free axis on them
    surfaces.update(model, body, s, t)
    if model.elastic is not None:
        try:
            elastic.step(model, body, s, t, before)
        except elastic.PatchError as err:
            raise NumericalError(str(err)) from None
        if model.worn_counters:
            too_deep = wear_counters(model, body, s, t, elastic.counter_pairs(s))
            if too_deep is not None:
                raise counter_too_deep(model, *too_deep, t)
        if surfaces.moved_since_refresh(model, body, s, t) >= s.cull[surfaces.CULL_MARGIN]:
            # the balance moved it beyond its active set's bound: refresh it
            # for the next step
            surfaces.update(model, body, s, t)
        return
    settle = getattr(body.motion, "settle", None)
    if settle is not None:
        # (a turning body's settle takes the step's time: its axis's place,
        # and the rate of its turn)
        when = dict(t=t, dt=model.dt) if body.motion.kind == TURNING else {}
        if not settle(s.pose, s.vertices, body.area_vectors, model.planes, s.vertex_planes,
                      s.active, model.law, **when):
            raise no_balance(body, t)
        s.pose[7:10] = (s.pose[0:3] - before) / model.dt
        if surfaces.moved_since_refresh(model, body, s, t) >= s.cull[surfaces.CULL_MARGIN]:
            finish_step(model, body, s, t)
            return
    touch(model, body, s, t)


def finish_step(model, body, s, t):
    """The rest of a quasi-static step whose settling move reached the
    active-set bound: refresh, planes at ``t``, contact."""
    surfaces.update(model, body, s, t)
    touch(model, body, s, t)


def touch(model, body, s, t):
    """One step of the contact kernel at ``t``, the normal forces, their
    squares and vectors added to ``s.load`` if kept
    (:data:`meshwear.longrun.jumps.LOAD_ROWS`), and the wear of worn counter-surfaces."""
    body_contact(model, body, s)
    if s.load.shape[1]:
        a = s.active
        force = s.normal_force[:, a].sum(axis=0)
        s.load[0, a] += force
        s.load[1, a] += force * force
        if len(s.load) > 2:
            # each slot's force along its normal (planes first, as the
            # kernel's slots), summed over the slots before it is added, as
            # the kernel does
            normals = [p[1] for p in model.planes] + [vp[a, 1] for vp in s.vertex_planes]
            pushed = np.zeros((3, len(a)))
            for slot, normal in enumerate(normals):
                pushed += (s.normal_force[slot, a][:, None] * normal).T
            s.load[2:5, a] += pushed
    if model.worn_counters:
        too_deep = wear_counters(model, body, s, t)
        if too_deep is not None:
            raise counter_too_deep(model, *too_deep, t)


def counter_too_deep(model, surface, vertex, t):
    """The error of a counter vertex worn deeper than its mesh can follow."""
    return NumericalError(
        f"surface {surface.name!r}: vertex {vertex} wore {surface.part.depth[vertex]:.3g} m deep, "
        f"more than half its shortest edge ({surface.spacing[vertex]:.3g} m) in the step to "
        f"t = {t:.6g} s: refine the surface (resolution), lower its wear coefficient or "
        "shorten run.dt")


def impact_too_deep(model, body, s, slot, vertex, t):
    """The error of a body vertex that went deeper into a surface than its
    contact can stand for (docs/model.md, "Impacts")."""
    depth = deepest_penetration(s.vertices, s.pose, model.planes, s.vertex_planes,
                                np.array([vertex]), s.contact_state)[0]
    surface = model.surfaces.slots[slot]
    speed = float(np.linalg.norm(s.pose[7:10]))
    return NumericalError(
        f"body {body.name!r}: vertex {vertex} went {depth:.3g} m into surface {surface.name!r} "
        f"at t = {t:.6g} s, more than {IMPACT_DEPTH:.0%} of the body's thinnest extent "
        f"({body.depth_limit / IMPACT_DEPTH:.3g} m): an impact faster than the contact can stop "
        f"(body speed {speed:.3g} m/s); lower the speed, raise the contact stiffness or "
        "shorten run.dt")


def no_balance(body, t):
    return NumericalError(f"body {body.name!r}: no contact carries its load at t = {t:.6g} s")


def run(model, state, observers=(), progress=None, checkpoint=None, compiled=True,
        forced_jump=None):
    """Run ``state`` from its current step to the end of ``model``'s duration.

    Parameters
    ----------
    model : meshwear.model.Model
    state : meshwear.model.State
        Advanced in place and returned.
    observers : sequence
        Objects with ``on_sample(model, state)`` and ``on_frame(model, state)``,
        called at ``model.sample_steps`` and ``model.frame_steps``. Contact
        quantities they see are those of the last step taken.
    progress : callable, optional
        ``progress(step, n_steps)``, called at least every
        :data:`PROGRESS_STEPS` steps and at every sample.
    checkpoint : callable, optional
        ``checkpoint(model, state)``, called at points where the state can be
        saved and resumed from (every output written up to its step).
    compiled : bool
        Step with the compiled loop (default), or with the Python reference
        :func:`step` (the same numbers, slower; for tests).
    forced_jump : int, optional
        With cycle jumping, jump this many cycles each time instead of the
        controller's choice (:func:`meshwear.longrun.wear.run_cycle_jump`).

    Raises
    ------
    NumericalError
        When a sample finds NaN, an unbounded state or inverted triangles; the
        observers have seen every sample before it.
    """
    # numpy's BLAS on one thread while the run lasts: its threads spin on
    # after each call, and on a small machine they took the cores from the
    # compiled loop's (docs/performance.md, "Threads")
    with threadpool_limits(limits=1, user_api="blas"):
        if model.cycle_steps:
            # the jumps resolve their cycles with this module's loop
            resolve = partial(advance, compiled=compiled)
            return run_cycle_jump(model, state, resolve, check, observers, progress, checkpoint,
                                  forced_jump)
        advance(model, state, model.n_steps, observers, progress, checkpoint, compiled)
    return state


def advance(model, state, stop, observers=(), progress=None, checkpoint=None, compiled=True):
    """Step ``state`` up to step ``stop``, writing every output due on the way
    (those of the current step first, unless already written); by the
    compiled loop (:mod:`meshwear.step.stepper`), or step by step in Python."""
    schedule = model.output_steps
    while True:
        if state.step > state.written:
            _write_outputs(model, state, observers)
            if checkpoint is not None:
                checkpoint(model, state)
        if state.step >= stop:
            return
        following = schedule[np.searchsorted(schedule, state.step, side="right")]
        until = min(stop, following, state.step + PROGRESS_STEPS)
        if compiled:
            stepper.advance(model, state, until)
        while state.step < until:
            step(model, state)
        # (outputs, checkpoints and jumps see the counter-parts where their
        # depths put them)
        settle_counters(model)
        state.resolved = True
        if progress is not None:
            progress(state.step, model.n_steps)
        if checkpoint is not None and state.step not in model.output_steps_set:
            checkpoint(model, state)


def _write_outputs(model, state, observers):
    """Check the state and call the observers due at its step."""
    at = state.step
    sample, frame = at in model.sample_set, at in model.frame_set
    if sample or frame:
        check(model, state, [b.reference_face_normals for b in model.bodies])
    if sample:
        for o in observers:
            o.on_sample(model, state)
    if frame:
        for o in observers:
            o.on_frame(model, state)
    state.written = at


def check(model, state, face_normals):
    """Raise :class:`NumericalError` if the state is not a valid one."""
    for body, s, normals in zip(model.bodies, state.bodies, face_normals):
        if not (np.all(np.isfinite(s.pose)) and np.all(np.isfinite(s.wrench))):
            raise NumericalError(
                f"body {body.name!r}: the state became non-finite at t = {state.time:.6g} s "
                "(unstable step: reduce run.dt or the contact stiffness)")
        worn = s.wear_depth > 0.0
        if worn.any():
            touched = worn[body.faces].any(axis=1)
            flipped = inverted_faces(normals[touched], s.vertices, body.faces[touched])
            if len(flipped):
                raise NumericalError(inverted(body, s, body.faces[touched][flipped], state))


def inverted(body, s, faces, state):
    """The message of the worn faces ``faces`` (k, 3) of ``body`` (state
    ``s``) found folded over at ``state``'s time: how deep their corners
    wore against their edges, and what to do, which depends on whether
    steps or a cycle jump brought them there (a jump is bounded so as not
    to fold a face: docs/model.md, "Long durations")."""
    x = body.reference_vertices[faces]
    edge = float(np.linalg.norm(x - np.roll(x, 1, axis=1), axis=2).min())
    deepest = float(s.wear_depth[np.unique(faces)].max())
    where = (f"body {body.name!r}: wear inverted {len(faces)} triangle(s) at "
             f"t = {state.time:.6g} s (their corners worn up to {deepest:.3g} m, their "
             f"shortest edge {edge:.3g} m)")
    if not state.resolved:
        return (f"{where}: a cycle jump moved the mesh further than it can follow; lower "
                "wear.tolerance, or resolve every cycle (wear.acceleration = \"none\")")
    return (f"{where}: the mesh cannot follow the wear there, or it wore through the part; "
            "refine the mesh where it wears or shorten the run (or, where a single step "
            "wears about as deep as the edges, lower the wear coefficient or run.dt)")


def run_scene(scene, observers=(), check_dt=True):
    """Build and run a scene in memory.

    Parameters
    ----------
    scene : meshwear.scene.Scene or path
    observers : sequence
        Extra observers (see :func:`run`).
    check_dt : bool
        Refuse a ``run.dt`` above the stability limit (SceneError naming it).

    Returns
    -------
    model, state, history : Model, State, MemoryHistory
    """
    from ..model.build import build_model, check_time_step, initial_state
    from ..scene.reader import Scene, load_scene

    if not isinstance(scene, Scene):
        scene = load_scene(scene)
    model = build_model(scene)
    if check_dt:
        check_time_step(model)
    history = MemoryHistory()
    state = run(model, initial_state(model), observers=[history, *observers])
    return model, state, history
