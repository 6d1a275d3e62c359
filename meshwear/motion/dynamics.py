"""How the parts of a run move: the dynamics seam (docs/model.md, "Dynamics").

The step loop (:mod:`meshwear.step.stepper`, its Python reference
:func:`meshwear.step.simulate.step`, the cycle jumps, checkpoints and outputs)
moves the parts through one object, ``model.dynamics``, and does not care
which it is. Two implement it:

:class:`OwnMotions`
    meshwear's own rigid-body motions (:mod:`meshwear.motion`: free,
    guided, prescribed, fixed, the quasi-static balance), each body's inside
    the compiled step loop, from the contact wrench it has just computed.
:class:`meshwear.mechanism.Mechanism`
    A MuJoCo mechanism: the parts' poses and velocities out of MuJoCo's
    kinematics, the contact wrenches into MuJoCo's applied forces.

The interface (a new engine is one more class):

``advance(model, state, until, step_bodies)``
    Take the steps from ``state.step`` up to ``until``; ``step_bodies(k0,
    k1)`` takes steps ``k0`` to ``k1`` of every body in the compiled loop.
    Returns None, or ``(k, code, body)`` for a step it could not take
    (:mod:`meshwear.kernels.loop` codes, or :data:`UNSTABLE`).
``step(model, state, k, contact)``
    Step ``k`` in Python (the reference), ``contact(k)`` the contact step of
    every body; False if the dynamics became unstable in it.
``reset(model, state)``, ``jumped(model, state, duration)``
    At the start of a run, and after a cycle jump moved the clock on.
``get_state()``, ``set_state(values, model, state)``
    Its own state for checkpoints (None: it has none beyond the parts').
``show(model, state, values=None)``
    Outputs filled from a jump (:mod:`meshwear.output.filled`) are written
    from ``state`` with its parts, their surfaces and its columns at the
    phase its state ``values`` (a ``get_state()``) was taken at; None: back
    to its own state, untouched by the showing.
``columns()``, ``describe(model, state)``, ``stable_limit(bodies, law, slots)``
    Its ``history.csv`` columns now, its lines in ``meshwear check`` (the run
    about to start from ``state``), and the
    largest stable step of the parts it moves (s) and the part that sets it.
``watched_limit(model, state)``
    The largest stable step of the contacts its parts can make before their
    next active-set refresh (their vertices within reach of a surface in
    ``state``): a ``run.dt`` above ``stable_limit`` but within this one is
    taken, watched at every refresh (inf: it takes none).
``instability(model, t, until=None)``
    The message of a step it found unstable.
``warm_steps``
    Steps ``meshwear check``'s estimate takes before it times steps (its
    own start-up: a mechanism's trial of its active sets).
"""

import numpy as np

#: :meth:`advance`'s code for a step the dynamics found unstable
UNSTABLE = -1


class OwnMotions:
    """meshwear's own motions: every body moves by its :mod:`meshwear.motion`
    rule inside the compiled loop; bodies that share a worn counter-surface
    take their steps in turn, one each."""

    #: steps a cost estimate takes before timing them (the compile)
    warm_steps = 1

    def advance(self, model, state, until, step_bodies):
        if model.worn_counters and len(model.bodies) > 1:
            for k in range(state.step, until):
                step_bodies(k, k + 1)
        else:
            step_bodies(state.step, until)

    def step(self, model, state, k, contact):
        contact(k)
        return True

    def reset(self, model, state):
        pass

    def jumped(self, model, state, duration):
        pass

    def get_state(self):
        return None

    def set_state(self, values, model, state):
        pass

    def show(self, model, state, values=None):
        pass

    def columns(self):
        return {}

    def describe(self, model, state):
        return []

    def stable_limit(self, bodies, law, slots):
        # meshwear.model.stable_time_step bounds the bodies' own motions
        return np.inf, None

    def watched_limit(self, model, state):
        return np.inf, None

    def instability(self, model, t, until=None):
        return f"the step from t = {t:.6g} s became unstable"
