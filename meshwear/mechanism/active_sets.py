"""A mechanism's riders' active sets on trial, and the stable step they allow
(docs/model.md, "Mechanisms" and "Stable time step").

A rider on a mechanism keeps an active set (its vertices within reach of a
surface, docs/model.md "Active set") only while it pays: the sets are on
trial in windows of :data:`TRIAL_STEPS` steps and given up for every vertex
at every step when they are refreshed too often. The largest stable step of
the riders' contact in MuJoCo's joint space, over every vertex or over the
active sets only, and the watch of a ``run.dt`` between the two at every
refresh, are here too. :class:`ActiveSets` is a part of
:class:`meshwear.mechanism.build.Mechanism` and works on what that sets up:
chiefly MuJoCo's ``model`` and ``data``, the riders (``bodies``,
``surfaces``) and their packed arrays (``world``, ``levers``, ``rows``,
``row_terms``), and the trial's own fields (``refs``, ``ref_times``,
``refreshes``, ``window``, ``strict``, ``failed``, ``due``).
"""

import numpy as np

from ..kernels.mechanism import needs_refresh as _needs_refresh
from ..motion.packing import body_arrays
from ..contact.stability import STABILITY_MARGIN, contact_matrix, stable_step, vertex_stiffness
from ..surfaces.base import quaternion_matrix


#: the bodies' active sets on a mechanism are on trial in windows of at least
#: :data:`TRIAL_STEPS` steps (the first one exactly that): if more than
#: :data:`TRIAL_REFRESHES` refreshes per that many steps were needed in one,
#: every vertex is checked at every step from then on (riders fast against
#: their margins: a disc turning under a pin refreshes every few steps)
TRIAL_STEPS, TRIAL_REFRESHES = 200, 20


class ActiveSets:
    """The riders' active sets on trial and the stable step (a part of
    :class:`~meshwear.mechanism.build.Mechanism`)."""

    def sync_refs(self, model, state, k):
        """Before step ``k``: each body's riding surfaces' frames at its last
        active-set refresh (recorded when it was refreshed now; one of an
        earlier time not recorded, a checkpoint's, is forced anew), and the
        active sets given up if they do not pay (:data:`TRIAL_STEPS`)."""
        B = len(state.bodies)
        if self.refs is None or len(self.refs) != B:
            self.refs = np.zeros((B, len(self.surfaces), 12))
            self.ref_times = np.full(B, np.nan)
            self.refreshes, self.window = 0, k
        if model.cull and k - self.window >= TRIAL_STEPS:
            if self.refreshes * TRIAL_STEPS > TRIAL_REFRESHES * (k - self.window):
                # riders move so fast against their margins that the active
                # sets cost more than they save: every vertex is checked from
                # here on
                self.give_up_active_sets(model, state)
            else:
                self.refreshes, self.window = 0, k
        if not model.cull:
            return
        for b, s in enumerate(state.bodies):
            if self.ref_times[b] != s.cull[1]:
                if s.cull[1] == k * model.dt:
                    self.refreshed(b, s)
                else:
                    s.cull[0] = 0.0

    def watched_limit(self, model, state):
        """The riders' stable step over their active sets in ``state``
        (:meth:`stable_limit`), and the body that sets it."""
        return self.stable_limit(model.bodies, model.law, model.slots, state.bodies)

    def watch(self, model, state, t):
        """A ``run.dt`` above the bound of every vertex at once
        (:meth:`stable_limit`) holds only while the riders' active sets are
        stiff enough for it: checked at every refresh. False, with the
        message kept for :meth:`instability`, where they are not (or were
        given up: every vertex may then press)."""
        if self.failed is None and model.dt > self.strict:
            if not model.cull:
                self.failed = (
                    f"run.dt: {model.dt:.6g} s is above the stability limit of every vertex "
                    f"of the riders pressing at once ({self.strict:.6g} s), which a run can "
                    "only take while its riders keep active sets, and this one gave them up "
                    "(its riders move too far against their margins in a step); shorten "
                    "run.dt to that limit")
            else:
                limit, who = self.watched_limit(model, state)
                if model.dt > limit:
                    self.failed = (
                        f"run.dt: {model.dt:.6g} s is above the stability limit of the "
                        f"contact of body {who!r} at t = {t:.6g} s ({limit:.6g} s "
                        "over its vertices within reach of a surface now); shorten run.dt")
        return self.failed is None

    def watched(self, model, state, k):
        """:meth:`watch` once after each refresh (and giving up), before step ``k``."""
        if not self.due:
            return self.failed is None
        self.due = False
        return self.watch(model, state, k * model.dt)

    def give_up_active_sets(self, model, state):
        """Every vertex of every body checked at every step from now on."""
        self.due = True
        object.__setattr__(model, "cull", False)
        for s in state.bodies:
            s.active = np.arange(len(s.vertices), dtype=np.int64)
            s.active_wear = s.wear_depth.copy()

    def refreshed(self, b, s):
        """Body ``b``'s active set was refreshed now."""
        self.refs[b] = self.world
        self.ref_times[b] = s.cull[1]
        self.refreshes += 1
        self.due = True

    def needs_refresh(self, model, b, s, t):
        """:func:`meshwear.kernels.mechanism.needs_refresh` of body ``b``."""
        surfaces = model.surfaces
        return model.cull and _needs_refresh(
            body_arrays(model, model.bodies[b], s), surfaces.bounds, surfaces.terms, float(t),
            model.dt, np.zeros((2, 3)), self.world, self.refs[b], self.levers, self.rows,
            self.row_terms)

    def stable_limit(self, bodies, law, slots, states=None):
        """Largest stable step (s) of the riders' contacts in the mechanism,
        and the body that sets it: as :func:`meshwear.model.stable_time_step`
        but in the mechanism's joint space, ``K = sum J^T K_c J`` over every
        rider and every surface it may press on (``J`` the rider's motion
        relative to the surface's body; the world for a surface not on the
        mechanism) against MuJoCo's joint-space mass matrix at the start. A
        joint takes away modes, so this is larger than the free body's.

        ``states`` (the bodies' states): the same bound over each rider's
        active set only (its vertices within reach of a surface), at its pose
        and MuJoCo's mass matrix now: the limit of the contacts the riders can
        make before their next active-set refresh (:meth:`watch`)."""

        m, d = self.model, self.data
        if not self.bodies or m.nv == 0:
            return np.inf, None
        K, C = np.zeros((m.nv, m.nv)), np.zeros((m.nv, m.nv))
        on = [name for _, _, name, _ in self.surfaces]
        fixed = max(0, slots - len(on))
        for _, index, name, _ in self.bodies:
            b = bodies[index]
            k, c = vertex_stiffness(b, law)
            if states is None:
                pose, r = b.initial_pose, b.reference_vertices
            else:
                s = states[index]
                pose, r = s.pose, s.vertices[s.active]
                k, c = k[s.active], c[s.active]
            r = r @ quaternion_matrix(pose[3:7]).T
            Kb, Cb = contact_matrix(k, r), contact_matrix(c, r)
            Jb = self.jacobian(name, pose[0:3])
            for J in [Jb - self.jacobian(s, pose[0:3]) for s in on] + [Jb] * max(fixed, 1 - len(on)):
                K += J.T @ Kb @ J
                C += J.T @ Cb @ J
        M = np.zeros((m.nv, m.nv))
        try:
            self.mujoco.mj_fullM(m, d, M)          # MuJoCo 4
        except TypeError:
            self.mujoco.mj_fullM(m, M, d.qM)       # MuJoCo 3
        moved = np.flatnonzero(np.abs(K).sum(axis=0) > 0.0)
        if not len(moved):
            return np.inf, None
        # the joints no contact moves stay out (their modes are MuJoCo's),
        # their inertia in: the moved joints' mass is the Schur complement
        rest = np.setdiff1d(np.arange(m.nv), moved)
        Ma = M[np.ix_(moved, moved)]
        if len(rest):
            Mab = M[np.ix_(moved, rest)]
            Ma = Ma - Mab @ np.linalg.solve(M[np.ix_(rest, rest)], Mab.T)
        sub = np.ix_(moved, moved)
        dt = stable_step(K[sub], C[sub], Ma)
        return STABILITY_MARGIN * dt, bodies[self.bodies[0][1]].name
