"""Mechanisms: worn parts riding on the bodies of a MuJoCo model.

MuJoCo (the ``mujoco`` package, optional extra ``meshwear[mechanism]``)
integrates the mechanism: joints, actuators, springs, gravity and its own
contacts. meshwear keeps the contact of each worn part with its
counter-surfaces, friction, wear and the evolving geometry. A step of
``dt`` (docs/model.md, "Mechanisms"):

1. the parts are where MuJoCo has their bodies at ``t`` (pose and velocity of
   each body's frame, the part placed in it by its ``position`` and
   ``orientation``);
2. MuJoCo's position and velocity stages (``mj_step1``);
3. meshwear's contact step of every worn body (normal force, friction, wear);
4. the contact wrench on each body and, reversed, on each counter-surface,
   applied to their MuJoCo bodies (``xfrc_applied``, at their centres of mass);
5. MuJoCo's force stage and its integration to ``t + dt`` (``mj_step2``),
   then its kinematics there, which place the parts for the next step.

:class:`Mechanism` is one implementation of the dynamics seam
(:mod:`meshwear.dynamics`; meshwear's own motions are the other): poses and
velocities out (:meth:`Mechanism.place`), wrenches in (:meth:`Mechanism.push`).
A part on a mechanism body has the motion kind ``FIXED`` in the compiled
loop, so the loop never moves it between two placings.
"""

import itertools
import logging

import numpy as np

from ..kernels.loop import DONE, REFRESH, loop_for
from ..kernels.mechanism import (mechanism_loop, needs_refresh as _needs_refresh, place_body,
                                 place_surface, push_body, push_reaction,
                                 slot_wrench as _slot_wrench)
from ..motion.packing import body_arrays, motion_arrays
from ..scene.checks import SceneError
from ..contact.stability import STABILITY_MARGIN, contact_matrix, stable_step, vertex_stiffness
from ..surfaces.base import quaternion_matrix


#: the bodies' active sets on a mechanism are on trial in windows of at least
#: :data:`TRIAL_STEPS` steps (the first one exactly that): if more than
#: :data:`TRIAL_REFRESHES` refreshes per that many steps were needed in one,
#: every vertex is checked at every step from then on (riders fast against
#: their margins: a disc turning under a pin refreshes every few steps)
TRIAL_STEPS, TRIAL_REFRESHES = 200, 20


def _mujoco(source):
    try:
        import mujoco
    except ImportError:
        raise SceneError(source, "mechanism", "needs the mujoco package, the optional "
                         "mechanism extra: pip install 'meshwear[mechanism]'") from None
    return mujoco


def _first_line(err):
    text = str(err).strip().splitlines()
    return " ".join(line.strip() for line in text[:2]) if text else type(err).__name__


class Mechanism:
    """A compiled MuJoCo model and its data, and which meshwear parts ride
    on which of its bodies.

    Parameters
    ----------
    scene : meshwear.scene.Scene
        With a ``[mechanism]`` table.

    Raises
    ------
    SceneError
        A missing ``mujoco``, a model MuJoCo cannot read or compile (its
        first line), a ``mechanism_body`` it does not have, or the RK4
        integrator (its step cannot be split for the contact forces).
    """

    def __init__(self, scene):
        mujoco = self.mujoco = _mujoco(scene.source)
        path = scene.mechanism.model
        self.source = scene.source
        try:
            spec = mujoco.MjSpec.from_file(str(path))
        except Exception as err:   # mujoco raises ValueError with the parser's text
            raise SceneError(scene.source, "mechanism.model",
                             f"{path.name}: MuJoCo cannot read it: {_first_line(err)}") from None
        names = [b.name for b in spec.bodies]
        riders = [(f"body[{i}]", b) for i, b in enumerate(scene.bodies)]
        riders += [(f"surface[{j}]", s) for j, s in enumerate(scene.surfaces)]
        riders = [(key, x) for key, x in riders if x.mechanism_body is not None]
        for key, x in riders:
            if x.mechanism_body not in names or x.mechanism_body == "world":
                shown = ", ".join(repr(n) for n in names if n and n != "world") or "none"
                raise SceneError(scene.source, f"{key}.mechanism_body",
                                 f"{x.mechanism_body!r} is not a moving body of {path.name} "
                                 f"(its bodies: {shown})")
        # MuJoCo's own collisions between the bodies meshwear handles are
        # meshwear's to compute: excluded
        handled = sorted({x.mechanism_body for _, x in riders})
        for a, b in itertools.combinations(handled, 2):
            exclude = spec.add_exclude()
            exclude.bodyname1, exclude.bodyname2 = a, b
        try:
            self.model = spec.compile()
        except Exception as err:
            raise SceneError(scene.source, "mechanism.model",
                             f"{path.name}: MuJoCo cannot compile it: {_first_line(err)}") from None
        m = self.model
        if m.opt.integrator == mujoco.mjtIntegrator.mjINT_RK4:
            raise SceneError(scene.source, "mechanism.model",
                             f"{path.name}: the RK4 integrator cannot take meshwear's contact "
                             "forces within its step; use Euler, implicit or implicitfast")
        for key, x in riders:
            if getattr(x, "mechanism_geom", None) is not None:
                self._check_geom(scene, key, x.mechanism_geom, x.mechanism_body, path)
        #: the timestep of the MJCF file (s), before meshwear sets its own
        self.file_timestep = float(m.opt.timestep)
        config = scene.mechanism
        self.keyframe = None
        if config.keyframe is not None:
            keys = [m.key(k).name for k in range(m.nkey)]
            if config.keyframe not in keys:
                raise SceneError(scene.source, "mechanism.keyframe",
                                 f"{config.keyframe!r} is not a keyframe of {path.name} "
                                 f"(its keyframes: {', '.join(map(repr, keys)) or 'none'})")
            self.keyframe = keys.index(config.keyframe)
        actuators = [m.actuator(a).name for a in range(m.nu)]
        self.controls = []
        for name, value in config.controls.items():
            if name not in actuators:
                raise SceneError(scene.source, f"mechanism.controls.{name}",
                                 f"{name!r} is not an actuator of {path.name} (its actuators: "
                                 f"{', '.join(map(repr, actuators)) or 'none'})")
            self.controls.append((actuators.index(name), float(value)))
        self.data = mujoco.MjData(m)
        self._bad_acceleration = int(mujoco.mjtWarning.mjWARN_BADQACC)
        if mujoco.get_mju_user_warning() is None:
            # MuJoCo's warnings to meshwear's log, not to stdout and MUJOCO_LOG.TXT
            log = logging.getLogger("meshwear")
            mujoco.set_mju_user_warning(lambda text: log.warning("MuJoCo: %s", text))
        self._start()
        self.ids = {name: m.body(name).id for name in handled}
        self.path = path
        #: (part, state index, MuJoCo body id, placement) of the riders, set by the model
        self.bodies, self.surfaces = [], []
        self._wrench = np.zeros(6)
        #: steps a cost estimate takes before timing steps: the active sets' trial
        self.warm_steps = TRIAL_STEPS + 1
        #: the riders' stable step over every vertex (set by the model), the
        #: message of a run.dt above it that the active sets no longer hold
        #: (:meth:`watch`), and whether a refresh is to be checked
        self.strict, self.failed, self.due = np.inf, None, False
        #: the data of a phase outputs filled from a jump show (:meth:`show`)
        self.shown, self._phase = None, None

    # ------------------------------------------------------------ set-up
    def _check_geom(self, scene, key, name, body, path):
        """A part's ``mechanism_geom``: a mesh geom of its mechanism body."""
        m, mujoco = self.model, self.mujoco
        mesh = int(mujoco.mjtGeom.mjGEOM_MESH)
        own = [m.geom(g).name for g in range(m.ngeom)
               if m.body(int(m.geom_bodyid[g])).name == body and int(m.geom_type[g]) == mesh]
        if name not in own:
            raise SceneError(scene.source, f"{key}.mechanism_geom",
                             f"{name!r} is not a mesh geom of body {body!r} in {path.name} "
                             f"(its mesh geoms: {', '.join(map(repr, own)) or 'none'})")

    def geom_mesh(self, name, body):
        """(vertices, faces) of mesh geom ``name`` in the frame of its body
        ``body``: MuJoCo's vertices (scaled, re-centred on the mesh's
        centroid and turned to its principal axes when it compiled them)
        placed by the geom's ``pos`` and ``quat``, which undo that, so the
        part lies where the MJCF file puts the mesh."""
        m = self.model
        g = m.geom(name).id
        mesh = int(m.geom_dataid[g])
        start, count = int(m.mesh_vertadr[mesh]), int(m.mesh_vertnum[mesh])
        vertices = np.asarray(m.mesh_vert[start:start + count], dtype=np.float64)
        first, faces = int(m.mesh_faceadr[mesh]), int(m.mesh_facenum[mesh])
        faces = np.asarray(m.mesh_face[first:first + faces], dtype=np.int64)
        rotation = quaternion_matrix(np.asarray(m.geom_quat[g], dtype=np.float64))
        return vertices @ rotation.T + np.asarray(m.geom_pos[g], dtype=np.float64), faces

    def finish(self):
        """After the model is built: the riders' motions become rows of one
        array the compiled loop writes (each surface's arrays views of it),
        and MuJoCo's C functions are looked up for that loop."""
        S = len(self.surfaces)
        self.rows, self.row_terms = np.zeros((S, 19)), np.zeros((S, 1, 9))
        for r, (surface, slot, name, rest) in enumerate(self.surfaces):
            m = surface.motion
            self.rows[r], self.row_terms[r] = m.array, m.path.terms
            m.array, m.path.terms = self.rows[r], self.row_terms[r]
            surface._compiled = None        # its tuple takes the views
        self.surface_riders = np.array([[slot, self.ids[name]] for _, slot, name, _ in
                                        self.surfaces], dtype=np.int64).reshape(-1, 2)
        self.rests = np.array([rest for *_, rest in self.surfaces], float).reshape(-1, 12)
        self.body_riders = np.array([[index, self.ids[name]] for _, index, name, _ in
                                     self.bodies], dtype=np.int64).reshape(-1, 2)
        self.placements = np.array([p for *_, p in self.bodies], float).reshape(-1, 13)
        self.calls = _c_functions(self.mujoco)
        #: each riding surface's frame now, at each body's last refresh, and its lever
        self.world = np.zeros((S, 12))
        self.levers = np.zeros(S)
        for r, (surface, *_) in enumerate(self.surfaces):
            points = getattr(surface, "vertices", None)
            if points is None:
                points = surface.drawing(1.0)[0]
            self.levers[r] = float(np.linalg.norm(points, axis=1).max()) if len(points) else 0.0
        self.refs = None

    # ------------------------------------------------------------ active sets
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

    def compiled_arrays(self):
        """MuJoCo's arrays the compiled loop reads and writes (views of its data)."""
        d, m = self.data, self.model
        return (d.xpos, d.xquat, d.xmat, d.cvel, d.subtree_com, d.xipos, d.xfrc_applied,
                m.body_rootid)

    def set_timestep(self, dt):
        self.model.opt.timestep = float(dt)

    def mass(self, name):
        """Mass (kg) of MuJoCo body ``name``."""
        return float(self.model.body_mass[self.ids[name]])

    def jacobian(self, name, point):
        """(6, nv) velocity of ``point`` (world) moving with body ``name``,
        and the body's angular velocity, per joint velocity."""
        J = np.zeros((6, self.model.nv))
        self.mujoco.mj_jac(self.model, self.data, J[0:3], J[3:6], np.asarray(point, float),
                           self.ids[name])
        return J

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

    def describe(self, model, state):
        """Lines for ``meshwear check``: the MuJoCo model, its joints and
        actuators, the parts meshwear handles on its bodies, the stability
        limits of their contact (every vertex; those within reach of a
        surface in ``state``, the run's start)."""
        m = self.model
        mujoco = self.mujoco
        kinds = {int(v): k.removeprefix("mjJNT_").lower()
                 for k, v in mujoco.mjtJoint.__members__.items()}
        joints = ", ".join(f"{m.joint(j).name or j} ({kinds.get(int(m.jnt_type[j]), '?')})"
                           for j in range(m.njnt)) or "none"
        actuators = ", ".join(m.actuator(a).name or str(a) for a in range(m.nu)) or "none"
        riders = {}
        for _, i, name, _ in self.bodies:
            riders.setdefault(name, []).append(model.bodies[i].name)
        for surface, _, name, _ in self.surfaces:
            riders.setdefault(name, []).append(surface.name)
        lines = [f"mechanism {self.path.name}: {m.nbody - 1} bodies, {m.njnt} joints "
                 f"[{joints}], actuators [{actuators}]"]
        for name, parts in riders.items():
            lines.append(f"  body {name!r} ({self.mass(name):.6g} kg) carries "
                         + ", ".join(repr(p) for p in parts))
        contact, _ = self.stable_limit(model.bodies, model.law, model.slots)
        reach, _ = self.watched_limit(model, state)
        lines.append(f"  MuJoCo timestep in the file {self.file_timestep:.3g} s; the coupled "
                     f"step {model.dt:.3g} s; the riders' contact in the joints is stable up to "
                     f"{contact:.3g} s with every vertex pressing at once, {reach:.3g} s with "
                     "the vertices within reach of a surface at the start (a run.dt between "
                     "the two is checked at every active-set refresh)")
        return lines

    # ------------------------------------------------------------ coupling
    def _arrays(self):
        d = self.data if self.shown is None else self.shown
        return d.xpos, d.xquat, d.xmat, d.cvel, d.subtree_com, self.model.body_rootid

    def body_pose(self, name, placement, out=None):
        """The (13,) pose of a part placed at ``placement`` (its pose in the
        frame of body ``name``: centre of mass and orientation) in the world,
        where MuJoCo's last kinematics have that body."""
        out = np.zeros(13) if out is None else out
        place_body(*self._arrays(), self.ids[name], placement, out)
        return out

    def surface_motion(self, name, rest, t, array, terms):
        """Write a surface's motion (``array`` (19,), ``terms`` (1, 9)) so
        its frame at ``t``, and its velocity field about it, are those of
        body ``name`` with the surface at ``rest`` in it (12,: rotation row
        by row, then position): a steady turn at the body's angular velocity
        and a steady velocity (:func:`meshwear.kernels.mechanism.place_surface`)."""
        xpos, _, xmat, cvel, com, root = self._arrays()
        place_surface(xpos, xmat, cvel, com, root, self.ids[name], rest, float(t), array, terms,
                      np.zeros(12))

    def place(self, model, state, t):
        """Put every rider where MuJoCo's last kinematics have its body (at ``t``)."""
        xpos, xquat, xmat, cvel, com, root = self._arrays()
        for body, index, name, placement in self.bodies:
            place_body(xpos, xquat, xmat, cvel, com, root, self.ids[name], placement,
                       state.bodies[index].pose)
        for r, (surface, slot, name, rest) in enumerate(self.surfaces):
            place_surface(xpos, xmat, cvel, com, root, self.ids[name], rest, float(t),
                          surface.motion.array, surface.motion.path.terms, self.world[r])
        if self.surfaces:
            model.surfaces.mechanism_moved(t)

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
        body (:mod:`meshwear.dynamics`): in the compiled loop
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

    def jumped(self, model, state, duration):
        """A cycle jump moved meshwear's clock by ``duration`` (whole cycles):
        MuJoCo's with it, its state otherwise that of the end of the resolved
        cycle, the riders placed at the new time."""
        self.data.time += duration
        self.place(model, state, state.time)

    def show(self, model, state, values=None):
        """For outputs filled from a jump (:mod:`meshwear.output.filled`):
        the riders of ``state``, the surfaces on its bodies and the joint
        columns where MuJoCo had them at the phase of ``values`` (a
        :meth:`get_state`), placed at ``state.time``; None: back where its
        own data has them. Its own data is left alone (:meth:`set_state`'s
        forward pass would change the next step's warm start)."""
        mujoco, m = self.mujoco, self.model
        self.shown = None
        if values is not None:
            if self._phase is None:
                self._phase = mujoco.MjData(m)
            mujoco.mj_setState(m, self._phase, np.asarray(values, float),
                               mujoco.mjtState.mjSTATE_INTEGRATION)
            mujoco.mj_forward(m, self._phase)
            self.shown = self._phase
        self.place(model, state, state.time)

    # ------------------------------------------------------------ state
    def _start(self):
        mujoco, m, d = self.mujoco, self.model, self.data
        d.warning[self._bad_acceleration].number = 0
        if self.keyframe is None:
            mujoco.mj_resetData(m, d)
        else:
            mujoco.mj_resetDataKeyframe(m, d, self.keyframe)
        for a, value in self.controls:
            d.ctrl[a] = value
        mujoco.mj_forward(m, d)

    def reset(self, model, state):
        """MuJoCo back at its initial state (the keyframe, or the model's
        reference pose at rest), the controls set, the riders there; the
        bodies' active sets on trial again."""
        self._start()
        object.__setattr__(model, "cull", True)
        self.refs = None
        self.failed, self.due = None, True
        self.place(model, state, 0.0)

    def get_state(self):
        """MuJoCo's whole integration state (time, qpos, qvel, act, ...)."""
        mujoco = self.mujoco
        kind = mujoco.mjtState.mjSTATE_INTEGRATION
        out = np.zeros(mujoco.mj_stateSize(self.model, kind))
        mujoco.mj_getState(self.model, self.data, out, kind)
        return out

    def set_state(self, values, model, state):
        mujoco, m, d = self.mujoco, self.model, self.data
        mujoco.mj_setState(m, d, np.asarray(values, float), mujoco.mjtState.mjSTATE_INTEGRATION)
        mujoco.mj_forward(m, d)
        self.place(model, state, state.time)

    def columns(self):
        """Its ``history.csv`` columns now (:meth:`joints`)."""
        return self.joints()

    def joints(self):
        """History columns of the mechanism (docs/outputs.md): each hinge and
        slide joint's position and velocity (``<joint>.q``, ``<joint>.v``)
        and each actuator's force (``<actuator>.force``); ball and free
        joints are in the rows of the parts they carry."""
        m, d = self.model, self.data if self.shown is None else self.shown
        out = {}
        kinds = (int(self.mujoco.mjtJoint.mjJNT_HINGE), int(self.mujoco.mjtJoint.mjJNT_SLIDE))
        for j in range(m.njnt):
            if int(m.jnt_type[j]) not in kinds:
                continue
            name = m.joint(j).name or f"joint{j}"
            out[f"{name}.q"] = float(d.qpos[m.jnt_qposadr[j]])
            out[f"{name}.v"] = float(d.qvel[m.jnt_dofadr[j]])
        for a in range(m.nu):
            name = m.actuator(a).name or f"actuator{a}"
            out[f"{name}.force"] = float(d.actuator_force[a])
        return out


def _c_functions(mujoco):
    """MuJoCo's ``mj_step1``, ``mj_step2``, ``mj_kinematics``, ``mj_comPos``
    and ``mj_comVel`` as C function pointers the compiled loop calls, from
    the library the ``mujoco`` package ships; None if it cannot be found
    (the steps then go through Python, a few times slower)."""
    import ctypes
    import glob
    import os

    folder = os.path.dirname(mujoco.__file__)
    for pattern in ("libmujoco.so*", "libmujoco*.dylib", "mujoco.dll"):
        for path in sorted(glob.glob(os.path.join(folder, pattern))):
            try:
                lib = ctypes.CDLL(path)
                out = []
                for name in ("mj_step1", "mj_step2", "mj_kinematics", "mj_comPos", "mj_comVel"):
                    f = getattr(lib, name)
                    f.argtypes, f.restype = [ctypes.c_void_p, ctypes.c_void_p], None
                    out.append(f)
                return tuple(out)
            except (OSError, AttributeError):
                continue
    return None


def slot_wrench(model, s, slot, out=None):
    """(6,) force (N) of counter-surface ``slot`` on a body and its moment
    about the world origin (N·m), from the body state ``s`` of the step just
    taken (:func:`meshwear.kernels.mechanism.slot_wrench`)."""
    out = np.zeros(6) if out is None else out
    _slot_wrench(s.pose, s.vertices, s.active, s.normal_force, s.tangential, model.planes,
                 s.vertex_planes, slot, out)
    return out
