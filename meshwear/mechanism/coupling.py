"""A mechanism's coupling in the step (docs/model.md, "Mechanisms"): the
contact wrenches pushed onto MuJoCo's bodies, the coupled step taken in the
compiled loop or a step at a time through Python, and MuJoCo's own check of
its accelerations with the message of an unstable step. :class:`Coupling`
is a part of :class:`meshwear.mechanism.build.Mechanism` and works on what
that sets up: chiefly MuJoCo's ``model`` and ``data`` (and ``calls``, its C
functions), the riders and their packed arrays (``finish``), their placing
(``place``) and the active sets' trial (:mod:`meshwear.mechanism.active_sets`).
:func:`slot_wrench` is the wrench of one counter-surface on a body.
"""

import numpy as np

from ..kernels.loop import DONE, REFRESH, loop_for
from ..kernels.mechanism import (mechanism_loop, push_body, push_reaction,
                                 slot_wrench as _slot_wrench)
from ..motion.packing import body_arrays, motion_arrays
from .active_sets import TRIAL_STEPS


class Coupling:
    """The coupled step of MuJoCo and the riders' contact (a part of
    :class:`~meshwear.mechanism.build.Mechanism`)."""

    def push(self, model, state):
        """The contact wrenches of the step just taken, on the MuJoCo bodies:
        each worn body's, and the reaction of each counter-surface on a
        mechanism body (at the same contact points, so the pair's moments
        cancel), applied at the bodies' centres of mass."""
        d = self.data
        xfrc, xipos = d.xfrc_applied, d.xipos
        xfrc[:] = 0.0
        for body, index, name, placement in self.bodies:
            s = state.bodies[index]
            push_body(xipos, xfrc, self.ids[name], s.pose, s.wrench)
        wrench = self._wrench
        for surface, slot, name, _ in self.surfaces:
            for s in state.bodies:
                slot_wrench(model, s, slot, wrench)
                push_reaction(xipos, xfrc, self.ids[name], wrench)

    def advance(self, model, state, until, step_bodies):
        """Steps from ``state.step`` up to ``until`` of the mechanism and every
        body (:mod:`meshwear.motion.dynamics`): in the compiled loop
        (:func:`meshwear.kernels.mechanism.advance_mechanism`), or a step at
        a time through Python where MuJoCo's library cannot be called from
        it. Returns None, or ``(step, code, body, report)``."""
        from ..motion.dynamics import UNSTABLE

        if self.calls is None:
            for k in range(state.step, until):
                if not self.step(model, state, k, lambda k: step_bodies(k, k + 1)):
                    return k, UNSTABLE, -1, None
            return None
        from ..surfaces import update

        surfaces = model.surfaces
        report = np.zeros(2, np.int64)
        start = k = state.step
        last = None
        while k < until:
            self.sync_refs(model, state, k)
            if not self.watched(model, state, k):
                return k, UNSTABLE, -1, None
            # (the trial of the active sets ends at a step of its own)
            stop = TRIAL_STEPS if k < TRIAL_STEPS < until and model.cull else until
            # (a refresh rebinds a body's arrays: packed anew)
            bodies = tuple(body_arrays(model, body, s) for body, s in zip(model.bodies,
                                                                          state.bodies))
            motions = tuple(motion_arrays(model, body, s) for body, s in zip(model.bodies,
                                                                             state.bodies))
            k, what, b = mechanism_loop(loop_for(model, dynamic=True))(
                k, stop, model.dt, self.calls, self.model._address, self.data._address,
                self.compiled_arrays(), bodies, motions, self.body_riders, self.placements,
                self.surface_riders, self.rests, self.rows, self.row_terms, model.cull,
                self.world, self.refs, self.levers, surfaces.compiled_planes(),
                surfaces.compiled_list(), surfaces.bounds, surfaces.terms, report)
            if not self.stable():
                return start, UNSTABLE, -1, None
            if what == REFRESH and last == (k, b):
                # a rider moves farther than the margin in one step: no
                # active set can follow it
                self.give_up_active_sets(model, state)
            elif what == REFRESH:
                s = state.bodies[b]
                s.cull[0] = 0.0                 # (the riders' moves decided it: forced)
                update(model, model.bodies[b], s, k * model.dt)
                self.refreshed(b, s)
                last = (k, b)
            elif what != DONE:
                return k, what, b, report
        return None

    def step(self, model, state, k, contact):
        """Step ``k`` of the mechanism and its riders: ``contact(k)`` takes
        the contact step of every body (the riders placed at ``k dt``).
        Returns False if MuJoCo found its accelerations non-finite in the
        step (it then resets itself: the run cannot go on)."""
        mujoco, m, d = self.mujoco, self.model, self.data
        self.sync_refs(model, state, k)
        for b, s in enumerate(state.bodies):
            if self.needs_refresh(model, b, s, k * model.dt):
                s.cull[0] = 0.0         # the step's own check refreshes it
        mujoco.mj_step1(m, d)
        contact(k)
        if model.cull:
            for b, s in enumerate(state.bodies):
                if self.ref_times[b] != s.cull[1]:
                    self.refreshed(b, s)
        if not self.watched(model, state, k):
            return False
        self.push(model, state)
        mujoco.mj_step2(m, d)
        if not self.stable():
            return False
        # the kinematics at t + dt place the riders for the next step and the outputs
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        mujoco.mj_comVel(m, d)
        self.place(model, state, (k + 1) * model.dt)
        return True

    def stable(self):
        """MuJoCo found no non-finite acceleration since the start (it then
        resets its state and goes on: the run cannot)."""
        return self.data.warning[self._bad_acceleration].number == 0

    def instability(self, model, t, until=None):
        """The message of a step MuJoCo found unstable at ``t`` (or between
        ``t`` and ``until``), or of a ``run.dt`` the riders' contact
        outgrew (:meth:`watch`)."""
        if self.failed is not None:
            return f"{self.source}: {self.failed}"
        when = f"step from t = {t:.6g} s" if until is None else (
            f"steps from t = {t:.6g} s to {until:.6g} s")
        return (f"mechanism {self.path.name}: MuJoCo's accelerations became non-finite in the "
                f"{when} (unstable coupled step): shorten run.dt, soften the "
                "contact, or integrate stiff actuators implicitly (integrator=\"implicitfast\")")


def slot_wrench(model, s, slot, out=None):
    """(6,) force (N) of counter-surface ``slot`` on a body and its moment
    about the world origin (N·m), from the body state ``s`` of the step just
    taken (:func:`meshwear.kernels.mechanism.slot_wrench`)."""
    out = np.zeros(6) if out is None else out
    _slot_wrench(s.pose, s.vertices, s.active, s.normal_force, s.tangential, model.planes,
                 s.vertex_planes, slot, out)
    return out
