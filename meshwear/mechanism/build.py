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
(:mod:`meshwear.motion.dynamics`; meshwear's own motions are the other): poses and
velocities out (:meth:`Mechanism.place`), wrenches in (:meth:`Mechanism.push`).
A part on a mechanism body has the motion kind ``FIXED`` in the compiled
loop, so the loop never moves it between two placings.

This module owns the mechanism's MuJoCo model and the placing: it compiles
the MJCF file, checks the riders' ``mechanism_body`` and ``mechanism_geom``,
packs the riders for the compiled loop and puts them where MuJoCo has their
bodies. :class:`Mechanism` is one object for its callers; its other jobs are
classes it is made of, each in its own module: the step's coupling
(:mod:`meshwear.mechanism.coupling`), the active sets' trial and the stable
step (:mod:`meshwear.mechanism.active_sets`), and its state for checkpoints,
jumps and outputs with its lines for ``meshwear check``
(:mod:`meshwear.mechanism.state`).
"""

import itertools
import logging

import numpy as np

from ..kernels.mechanism import place_body, place_surface
from ..scene.checks import SceneError
from ..surfaces.base import quaternion_matrix
from .active_sets import TRIAL_STEPS, ActiveSets
from .coupling import Coupling
from .state import StateAndReports


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


class Mechanism(ActiveSets, Coupling, StateAndReports):
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

    Notes
    -----
    Its methods live with their jobs: the model and the placing here, the
    rest in :class:`~meshwear.mechanism.coupling.Coupling`,
    :class:`~meshwear.mechanism.active_sets.ActiveSets` and
    :class:`~meshwear.mechanism.state.StateAndReports`. Those hold no state
    of their own and call no ``super()``: every attribute is set here, in
    ``__init__`` and :meth:`finish` (the active sets' ``ref_times``,
    ``refreshes`` and ``window`` at their first trial, :meth:`sync_refs`).
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

    # ------------------------------------------------------------ MuJoCo's model
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

    # ------------------------------------------------------------ placing
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
