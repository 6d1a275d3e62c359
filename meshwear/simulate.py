"""The step loop. :func:`step` fixes the phase order; :func:`run` drives it and
calls the observers (recorders) at the sample and frame times.

Phase order of one step, for every body: contact -> normal force -> friction
-> energy -> wear -> geometry update (one fused kernel, DESIGN.md §1), then
the dynamics of every body from the contact wrench just computed.
"""

import logging
import time as _time

import numpy as np

from .kernels.contact import plane_contact, rotation_entries

log = logging.getLogger(__name__)


class NumericalError(RuntimeError):
    """The run became numerically invalid (NaN, instability, inverted triangles)."""


def step(model, state):
    """Advance ``state`` by one time step of ``model``, in place."""
    for body, s in zip(model.bodies, state.bodies):
        plane_contact(s.vertices, s.pose, model.planes, body.tributary_area, model.law,
                      body.wear_direction, s.contact_state, s.tangential, s.normal_force,
                      s.friction_work, s.wear_depth, s.wrench)
    for body, s in zip(model.bodies, state.bodies):
        body.motion.advance(s.pose, s.wrench, state.time, model.dt)
    state.step += 1
    state.time = state.step * model.dt


def run(model, state, observers=(), progress=None):
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
        ``progress(step, n_steps)``, called at every sample.

    Raises
    ------
    NumericalError
        When a sample finds NaN, an unbounded state or inverted triangles; the
        observers have seen every sample before it.
    """
    samples = set(model.sample_steps.tolist())
    frames = set(model.frame_steps.tolist())
    checkpoints = sorted(samples | frames | {model.n_steps})
    face_normals = [b.reference_face_normals for b in model.bodies]
    for stop in checkpoints:
        while state.step < stop:
            step(model, state)
        if state.step in samples or state.step in frames:
            check(model, state, face_normals)
        if state.step in samples:
            for o in observers:
                o.on_sample(model, state)
            if progress is not None:
                progress(state.step, model.n_steps)
        if state.step in frames:
            for o in observers:
                o.on_frame(model, state)
    return state


def check(model, state, face_normals):
    """Raise :class:`NumericalError` if the state is not a valid one."""
    for body, s, normals in zip(model.bodies, state.bodies, face_normals):
        if not (np.all(np.isfinite(s.pose)) and np.all(np.isfinite(s.wrench))):
            raise NumericalError(
                f"body {body.name!r}: the state became non-finite at t = {state.time:.6g} s "
                "(unstable step: reduce run.dt or the contact stiffness)")
        worn = s.wear_depth > 0.0
        if worn.any():
            faces = body.faces[worn[body.faces].any(axis=1)]
            tri = s.vertices[faces]
            current = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
            ref = normals[worn[body.faces].any(axis=1)]
            flipped = np.einsum("ij,ij->i", current, ref) <= 0.0
            if flipped.any():
                raise NumericalError(
                    f"body {body.name!r}: wear inverted {int(flipped.sum())} triangle(s) at "
                    f"t = {state.time:.6g} s (wear deeper than the local mesh spacing or "
                    "thickness: refine the mesh or lower the wear coefficient)")


def body_quantities(body, s):
    """Per-vertex fields and totals of one body, for recorders.

    Returns
    -------
    dict
        ``points`` (n, 3) world positions, the point-data fields of DESIGN.md
        §5 and the history totals.
    """
    R = np.array(rotation_entries(s.pose[3:7])).reshape(3, 3)
    normal_force = s.normal_force.sum(axis=0)
    friction_force = s.tangential[:, :, 2, :].sum(axis=0)
    return {
        "points": s.pose[0:3] + s.vertices @ R.T,
        "origin": s.pose[0:3] + R @ body.origin,
        "wear_depth": s.wear_depth,
        "normal_force": normal_force,
        "friction_force": friction_force,
        "pressure": normal_force / body.tributary_area,
        "contact_state": (s.contact_state.max(axis=0) if s.contact_state.shape[0]
                          else np.zeros(len(s.wear_depth), np.int8)).astype(np.int32),
        "friction_work": s.friction_work,
        "wear_volume": float(s.wear_depth @ body.tributary_area),
        "max_wear_depth": float(s.wear_depth.max()),
        "total_friction_work": float(s.friction_work.sum()),
    }


class Timer:
    """Wall-clock time of a run, for the summary."""

    def __init__(self):
        self.start = _time.perf_counter()

    @property
    def elapsed(self):
        return _time.perf_counter() - self.start


class MemoryHistory:
    """Observer that keeps every sample in memory, for scripts and tests.

    After a run, ``rows[name]`` is a dict of arrays per body: ``time``,
    ``pose`` (k, 13), ``origin`` (k, 3), ``wrench`` (k, 6), ``friction_work``,
    ``wear_volume``, ``max_wear_depth``, ``wear_depth`` (k, n) and
    ``contact_points``.
    """

    def __init__(self):
        self._rows = {}

    def on_sample(self, model, state):
        for body, s in zip(model.bodies, state.bodies):
            q = body_quantities(body, s)
            r = self._rows.setdefault(body.name, {k: [] for k in (
                "time", "pose", "origin", "wrench", "friction_work", "wear_volume",
                "max_wear_depth", "wear_depth", "contact_points")})
            r["time"].append(state.time)
            r["pose"].append(s.pose.copy())
            r["origin"].append(q["origin"])
            r["wrench"].append(s.wrench.copy())
            r["friction_work"].append(q["total_friction_work"])
            r["wear_volume"].append(q["wear_volume"])
            r["max_wear_depth"].append(q["max_wear_depth"])
            r["wear_depth"].append(s.wear_depth.copy())
            r["contact_points"].append(int((q["contact_state"] > 0).sum()))

    def on_frame(self, model, state):
        pass

    @property
    def rows(self):
        return {name: {k: np.asarray(v) for k, v in r.items()} for name, r in self._rows.items()}


def run_scene(scene, observers=(), check_dt=True):
    """Build and run a scene in memory.

    Parameters
    ----------
    scene : meshwear.scene.Scene or path
    observers : sequence
        Extra observers (see :func:`run`).
    check_dt : bool
        Refuse a ``run.dt`` above the stability limit (ValueError naming it).

    Returns
    -------
    model, state, history : Model, State, MemoryHistory
    """
    from .model import build_model, initial_state, stable_time_step
    from .scene import Scene, load_scene

    if not isinstance(scene, Scene):
        scene = load_scene(scene)
    model = build_model(scene)
    if check_dt:
        limit, who = stable_time_step(model)
        if scene.run.dt > limit:
            raise ValueError(f"run.dt = {scene.run.dt:.3g} s is above the stability limit of "
                             f"body {who!r}; the largest stable dt is {limit:.3g} s")
    history = MemoryHistory()
    state = run(model, initial_state(model), observers=[history, *observers])
    return model, state, history
