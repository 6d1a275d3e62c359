"""The compiled step loop, Python side: pack a model's arrays for
:func:`meshwear.kernels.loop.advance_body` and take back the steps it leaves.

The loop runs whole spans of steps of one body inside numba. It returns to
Python for an active-set refresh (python-fcl, numpy: done by the reference
step :func:`meshwear.step.simulate.step_body`, or :func:`meshwear.step.simulate.finish_step`
for the rest of a quasi-static step), for a load nothing can carry, and at the
``until`` step the caller asks for (outputs, checkpoints, progress). What
moves the bodies between those is the model's dynamics
(:mod:`meshwear.motion.dynamics`): meshwear's own motions step each body's span
here, a MuJoCo mechanism steps them all with itself in its own compiled
loop (:mod:`meshwear.mechanism`).
"""

import numpy as np

from ..kernels import loop
from ..motion.packing import body_arrays as _body_arrays, motion_arrays as _motion_arrays


def advance(model, state, until):
    """Step every body of ``state`` from ``state.step`` to step ``until``,
    moved by the model's dynamics (:mod:`meshwear.motion.dynamics`: meshwear's own
    motions, or a MuJoCo mechanism)."""
    from ..motion.dynamics import UNSTABLE
    from .simulate import NumericalError, step

    if model.elastic is not None:
        # the half-space solve is numpy's (meshwear.contact.elastic): Python's steps
        while state.step < until:
            step(model, state)
        return

    stopped = model.dynamics.advance(model, state, until,
                                     lambda k0, k1: _advance_bodies(model, state, k0, k1))
    if stopped is not None:
        k, what, b, report = stopped
        if what == UNSTABLE:
            raise NumericalError(model.dynamics.instability(model, k * model.dt,
                                                            until * model.dt))
        _stopped(model, model.bodies[b], state.bodies[b], k, what, report)
    state.step = until
    state.time = until * model.dt


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
    advance_body = loop.loop_for(model)
    for body, s in zip(model.bodies, state.bodies):
        k = start
        while k < until:
            k, what = advance_body(k, until, dt, model.quasi_static, model.cull,
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
