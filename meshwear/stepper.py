"""The compiled step loop, Python side: pack a model's arrays for
:func:`meshwear.kernels.loop.advance_body` and take back the steps it leaves.

The loop runs whole spans of steps of one body inside numba. It returns to
Python for an active-set refresh (python-fcl, numpy: done by the reference
step :func:`meshwear.simulate.step_body`, or :func:`meshwear.simulate.finish_step`
for the rest of a quasi-static step), for a load nothing can carry, and at the
``until`` step the caller asks for (outputs, checkpoints, progress).
"""

import numpy as np

from .kernels import loop
from .kernels.rigid import BALANCED


def _body_arrays(model, body, s):
    """The ``body`` tuple of :mod:`meshwear.kernels.loop`."""
    return (s.vertices, s.pose, body.area_vectors, model.law, body.wear_direction,
            s.contact_state, s.tangential, s.normal_force, s.friction_work, s.wear_depth,
            s.wear_volume, s.wrench, s.vertex_planes, s.hint, s.active, s.active_wear, s.cull,
            s.cull_scratch.distance, s.load, float(body.radius), float(body.depth_limit),
            s.impact_room)


def _motion_arrays(model, body, s):
    """The ``motion`` tuple of :mod:`meshwear.kernels.loop`."""
    m = body.motion
    if m.kind == BALANCED and model.quasi_static:
        scratch = m.ensure_scratch(len(s.active) * model.slots)
    else:
        scratch = np.zeros((2, 0))
    return (int(m.kind), m.params, m.path.terms, m.path.buffer, scratch)


def advance(model, state, until):
    """Step every body of ``state`` from ``state.step`` to step ``until``
    (bodies that share a worn counter-surface in turn, a step each; with a
    mechanism, a step at a time, MuJoCo's step around the bodies')."""
    if model.mechanism is not None:
        _advance_mechanism(model, state, until)
    elif model.worn_counters and len(model.bodies) > 1:
        for k in range(state.step, until):
            _advance_bodies(model, state, k, k + 1)
    else:
        _advance_bodies(model, state, state.step, until)
    state.step = until
    state.time = until * model.dt


def _advance_mechanism(model, state, until):
    """Steps of a mechanism and every body up to ``until``: in the compiled
    loop (:func:`meshwear.kernels.mechanism.advance_mechanism`), or a step at
    a time through Python where MuJoCo's library cannot be called from it."""
    from .kernels.mechanism import advance_mechanism
    from .simulate import NumericalError

    mech = model.mechanism
    if mech.calls is None:
        for k in range(state.step, until):
            if not mech.step(model, state, k, lambda k: _advance_bodies(model, state, k, k + 1)):
                raise NumericalError(mech.instability(model, k * model.dt))
        return
    surfaces = model.surfaces
    report = np.zeros(2, np.int64)
    bodies = tuple(_body_arrays(model, body, s) for body, s in zip(model.bodies, state.bodies))
    motions = tuple(_motion_arrays(model, body, s) for body, s in zip(model.bodies,
                                                                      state.bodies))
    start = state.step
    k, what, b = advance_mechanism(
        start, until, model.dt, mech.calls, mech.model._address, mech.data._address,
        mech.compiled_arrays(), bodies, motions, mech.body_riders, mech.placements,
        mech.surface_riders, mech.rests, mech.rows, mech.row_terms, surfaces.compiled_planes(),
        surfaces.compiled_list(), surfaces.bounds, surfaces.terms, report)
    if not mech.stable():
        raise NumericalError(mech.instability(model, start * model.dt, until * model.dt))
    if what != loop.DONE:
        _stopped(model, model.bodies[b], state.bodies[b], k, what, report)


def _stopped(model, body, s, k, what, report):
    """The error of a step the compiled loop could not take (see
    :func:`meshwear.kernels.loop.advance_body`)."""
    from .simulate import counter_too_deep, impact_too_deep, no_balance

    dt = model.dt
    if what == loop.TOO_DEEP:
        t = (k + 1) * dt if model.quasi_static else k * dt
        raise counter_too_deep(model, model.surfaces.per_vertex[report[0]], report[1], t)
    if what == loop.IMPACT:
        raise impact_too_deep(model, body, s, report[0], report[1], k * dt)
    raise no_balance(body, (k + 1) * dt)


def _advance_bodies(model, state, start, until):
    from .simulate import finish_step, step_body

    dt = model.dt
    surfaces = model.surfaces
    planes = surfaces.compiled_planes()
    report = np.zeros(2, np.int64)
    for body, s in zip(model.bodies, state.bodies):
        k = start
        while k < until:
            k, what = loop.advance_body(k, until, dt, model.quasi_static, model.cull,
                                        _body_arrays(model, body, s),
                                        _motion_arrays(model, body, s), planes,
                                        surfaces.compiled_list(), surfaces.bounds,
                                        surfaces.terms, report)
            if what == loop.DONE:
                break
            if what == loop.REFRESH:
                step_body(model, body, s, k)
            elif what == loop.FINISH:
                finish_step(model, body, s, (k + 1) * dt)
            else:
                _stopped(model, body, s, k, what, report)
            k += 1
