"""Checkpoints: save a running state atomically, and resume from it.

A checkpoint holds everything that changes while a run runs (the
:class:`meshwear.model.State`, cycle-jumping bookkeeping included) plus a
digest of the scene and mesh files it belongs to; the model is rebuilt from
the scene. It is taken only where a run can continue exactly as if never
stopped: after the outputs of its step are written (and flushed), and in
cycle-jumping runs at a cycle boundary. So a run killed at any moment and
resumed ends with the same numbers as one that was never interrupted.
"""

import hashlib
import time
from pathlib import Path

import numpy as np

from ..kernels.rigid import SETTLED, TURNING
from ..output.tables import write_atomic
from ..scene.checks import SceneError

FILE_NAME = "checkpoint.npz"
_BODY_ARRAYS = ("pose", "vertices", "wear_depth", "friction_work", "wear_volume",
                "contact_state", "tangential", "normal_force", "wrench", "vertex_planes", "hint",
                "cull")
#: what a worn counter-surface's state holds (meshwear.model.PartState)
_PART_ARRAYS = ("vertices", "frames", "depth", "volume", "work")


def input_digests(scene):
    """``{what: SHA-256}`` of every input a run reads: the scene file, the
    keys set over it (``--set``) and each mesh file (bodies' and surfaces'),
    keyed by what a message names (``body[0].mesh (pin.stl)``)."""
    out = {f"the scene file {Path(scene.source).name}": _file_digest(Path(scene.source))}
    if getattr(scene, "overrides", ()):
        out["the keys set over it (--set)"] = hashlib.sha256(
            repr(tuple(scene.overrides)).encode()).hexdigest()
    for kind, parts in (("body", scene.bodies), ("surface", scene.surfaces)):
        for i, part in enumerate(parts):
            mesh = getattr(part, "mesh", None)
            if mesh is not None:
                out[f"{kind}[{i}].mesh ({Path(mesh).name})"] = _file_digest(Path(mesh))
    mechanism = getattr(scene, "mechanism", None)
    if mechanism is not None:
        out[f"mechanism.model ({Path(mechanism.model).name})"] = _file_digest(Path(mechanism.model))
    return out


def _file_digest(path):
    """SHA-256 of a file's bytes ('' when it cannot be read)."""
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError:
        return ""


def scene_digest(scene):
    """One SHA-256 over :func:`input_digests`."""
    h = hashlib.sha256()
    for what, digest in sorted(input_digests(scene).items()):
        h.update(f"{what}={digest};".encode())
    return h.hexdigest()


def changed_inputs(saved, scene):
    """What of :func:`input_digests` differs between a checkpoint's ``saved``
    (``what=digest`` strings) and ``scene`` now: a list of names."""
    before = dict(str(item).rsplit("=", 1) for item in saved)
    now = input_digests(scene)
    return [what for what in sorted(set(before) | set(now)) if before.get(what) != now.get(what)]


def save(path, model, state, wall_time):
    """Write ``state`` to ``path`` atomically (a reader sees the old or the new file)."""
    arrays = {"digest": np.array(scene_digest(model.scene)),
              "inputs": np.array([f"{k}={v}" for k, v in input_digests(model.scene).items()]),
              "scalars": np.array([state.time, state.step, state.written, wall_time,
                                   float(state.resolved)], dtype=float)}
    for k, s in enumerate(state.bodies):
        for name in _BODY_ARRAYS:
            arrays[f"body{k}_{name}"] = getattr(s, name)
        arrays[f"body{k}_active"] = s.active
        arrays[f"body{k}_active_wear"] = s.active_wear
        # (the rows the pairs' log last needed: a resumed run sizes its log,
        # and whether it held every pair, as the whole run does)
        arrays[f"body{k}_log_count"] = s.log_count
        arrays[f"body{k}_log_rows"] = np.array([len(s.log_index)])
    for k, body in enumerate(model.bodies):
        if body.motion.kind == TURNING:
            # the angle a body under a torque last settled to: its next
            # step starts from it (meshwear.kernels.turn_balance)
            arrays[f"body{k}_settled"] = np.array([body.motion.settled])
    own = model.dynamics.get_state()
    if own is not None:
        # a mechanism's (MuJoCo's whole integration state): bit for bit on resuming
        arrays["dynamics_state"] = own
        refs = getattr(model.dynamics, "refs", None)
        if refs is not None:
            arrays["dynamics_refs"] = refs
            arrays["dynamics_ref_times"] = model.dynamics.ref_times
            arrays["dynamics_cull"] = np.array([float(model.cull), model.dynamics.refreshes,
                                                model.dynamics.window])
    for m, part in enumerate(state.parts):
        if part is not None:
            for name in _PART_ARRAYS:
                arrays[f"part{m}_{name}"] = getattr(part, name)
    js = state.jump
    if js is not None:
        arrays["jump_scalars"] = np.array([js.gap, js.last_jump, js.jumps, js.resolved_steps,
                                           float(js.settling)])
        arrays["jump_limits"] = np.array([f"{k}={v}" for k, v in js.limits.items()])
        for k, (rate, error) in enumerate(zip(js.rate, js.error)):
            arrays[f"jump{k}_error"] = error
            if rate is not None:
                arrays[f"jump{k}_rate"] = rate
        for k, alpha in enumerate(js.alpha):
            if alpha is not None:
                arrays[f"jump{k}_alpha"] = alpha
        for k, (rate, error) in enumerate(zip(js.part_rate, js.part_error)):
            arrays[f"jump_part{k}_error"] = error
            if rate is not None:
                arrays[f"jump_part{k}_rate"] = rate
        for k, variance in enumerate(js.noise_var):
            arrays[f"jump{k}_noise_var"] = variance
        for k, drift in enumerate(js.drift):
            arrays[f"jump{k}_drift"] = drift
        for k, variance in enumerate(js.part_noise_var):
            arrays[f"jump_part{k}_noise_var"] = variance
        arrays["jump_bias"] = np.array(js.bias, dtype=float).reshape(-1, 2)
        arrays["jump_volumes"] = np.array([[t, *v] for t, v in js.volumes],
                                          dtype=float).reshape(-1, 1 + len(state.bodies))
        arrays["jump_window"] = np.array([js.window, js.relax])
        arrays["jump_history_times"] = np.array([t for t, _, _ in js.history])
        for k, past in enumerate(js.part_past):
            arrays[f"jump_part{k}_past_times"] = np.array([t for t, *_ in past])
            for h, (_, depth, rate, stiffness) in enumerate(past):
                arrays[f"jump_part{k}_past{h}"] = np.stack([depth, rate, stiffness])
        for h, (_, alphas, part_rates) in enumerate(js.history):
            for k, alpha in enumerate(alphas or ()):
                arrays[f"jump_history{h}_alpha{k}"] = alpha
            for k, rate in enumerate(part_rates):
                arrays[f"jump_history{h}_part{k}"] = rate
    write_atomic(path, lambda f: np.savez(f, **arrays), binary=True)


def load(path, model, state):
    """Fill ``state`` (from :func:`meshwear.model.initial_state`) from the
    checkpoint at ``path``; return the wall time spent before it.

    Raises
    ------
    SceneError
        When the checkpoint is missing, unreadable, or belongs to other scene
        or mesh files.
    """
    from .wear import JumpState

    path = Path(path)
    if not path.is_file():
        raise SceneError(model.scene.source, "", f"no checkpoint in {path.parent} to resume from "
                         "(run without --resume)")
    try:  # every array read now: a damaged file fails here, not half-way through
        with np.load(path, allow_pickle=False) as npz:
            data = {name: npz[name] for name in npz.files}
        digest = str(data["digest"])
    except Exception as err:  # noqa: BLE001 - zip, zlib, npy and key errors alike
        raise SceneError(model.scene.source, "", f"{path}: damaged or not a checkpoint "
                         f"({type(err).__name__}); run without --resume to start "
                         "again") from None
    if digest != scene_digest(model.scene):
        changed = changed_inputs(data["inputs"], model.scene) if "inputs" in data else []
        what = (f": {', '.join(changed)} changed" if changed else " or its meshes")
        raise SceneError(model.scene.source, "", f"{path} was written for another version of this "
                         f"scene{what}; run without --resume to start again")
    scalars = data["scalars"]
    if len(scalars) != 5:
        raise SceneError(model.scene.source, "", f"{path} was written by another version of "
                         "meshwear; run without --resume to start again")
    t, step, written, wall, resolved = scalars
    state.time, state.step, state.written = float(t), int(step), int(written)
    state.resolved = bool(resolved)
    try:
        for k, s in enumerate(state.bodies):
            for name in _BODY_ARRAYS:
                getattr(s, name)[...] = data[f"body{k}_{name}"]
            s.active = data[f"body{k}_active"].astype(np.int64)
            s.active_wear = data[f"body{k}_active_wear"].copy()
            if f"body{k}_settled" in data:
                model.bodies[k].motion.params[SETTLED] = float(data[f"body{k}_settled"][0])
            if f"body{k}_log_count" in data:
                s.log_count[...] = data[f"body{k}_log_count"]
                rows = int(data[f"body{k}_log_rows"][0])
                s.log_index, s.log_value = np.zeros((rows, 3), np.int64), np.zeros(rows)
        # in place: the worn surfaces query and draw these very arrays
        for m, part in enumerate(state.parts):
            if part is not None:
                for name in _PART_ARRAYS:
                    getattr(part, name)[...] = data[f"part{m}_{name}"]
                model.surfaces.per_vertex[m].rebin()
        if model.dynamics.get_state() is not None:
            model.dynamics.set_state(data["dynamics_state"], model, state)
            if "dynamics_refs" in data:
                d = model.dynamics
                d.refs, d.ref_times = data["dynamics_refs"].copy(), data["dynamics_ref_times"].copy()
                cull, d.refreshes, window = data["dynamics_cull"]
                d.window = int(window)
                object.__setattr__(model, "cull", bool(cull))
    except (KeyError, ValueError) as err:
        raise SceneError(model.scene.source, "", f"{path} was written by another version of "
                         f"meshwear ({err}); run without --resume to start again") from None
    if "jump_scalars" in data:
        gap, last, jumps, resolved, settling = data["jump_scalars"]
        limits = {}
        for item in data["jump_limits"]:
            key, value = str(item).split("=")
            limits[key] = int(value)
        n = len(state.bodies)
        worn = [p for p in state.parts if p is not None]
        state.jump = JumpState(
            rate=[data[f"jump{k}_rate"].copy() if f"jump{k}_rate" in data else None
                  for k in range(n)],
            error=[data[f"jump{k}_error"].copy() for k in range(n)],
            alpha=[data[f"jump{k}_alpha"].copy() if f"jump{k}_alpha" in data else None
                   for k in range(n)],
            part_rate=[data[f"jump_part{k}_rate"].copy() if f"jump_part{k}_rate" in data
                       else None for k in range(len(worn))],
            part_error=[data[f"jump_part{k}_error"].copy() for k in range(len(worn))],
            gap=float(gap), last_jump=int(last), jumps=int(jumps), resolved_steps=int(resolved),
            settling=bool(settling), limits=limits)
        js = state.jump
        if "jump_window" in data:
            window, relax = data["jump_window"]
            js.window, js.relax = int(window), float(relax)
            if "jump_bias" in data:
                js.noise_var = [data[f"jump{k}_noise_var"].copy() for k in range(n)]
                js.drift = [data[f"jump{k}_drift"].copy() for k in range(n)]
                js.part_noise_var = [data[f"jump_part{k}_noise_var"].copy()
                                     for k in range(len(worn))]
                js.bias = [b.copy() for b in np.atleast_2d(data["jump_bias"])]
                js.volumes = [(float(row[0]), row[1:].copy()) for row in data["jump_volumes"]]
            else:
                # an older checkpoint: one variance per part, for every vertex
                variance = [float(v) for v in data["jump_noise_var"]]
                js.noise_var = [np.full(len(s.wear_depth), v)
                                for s, v in zip(state.bodies, variance[:n])]
                js.part_noise_var = [np.full(len(p.depth), v)
                                     for p, v in zip(worn, variance[n:])]
            js.part_past = [[(float(t), *data[f"jump_part{k}_past{h}"].copy())
                             for h, t in enumerate(data[f"jump_part{k}_past_times"])]
                            if f"jump_part{k}_past_times" in data else []
                            for k in range(len(worn))]
            for h, t in enumerate(data["jump_history_times"]):
                alphas = [data[f"jump_history{h}_alpha{k}"].copy() for k in range(n)
                          if f"jump_history{h}_alpha{k}" in data]
                js.history.append((float(t), alphas or None,
                                   [data[f"jump_history{h}_part{k}"].copy()
                                    for k in range(len(worn))]))
    return float(wall)


class Checkpointer:
    """Observer-side hook for :func:`meshwear.step.simulate.run`: saves the state at
    most every ``every`` seconds of wall time (0: at every opportunity)."""

    def __init__(self, out_dir, every, wall_before=0.0):
        self.path = Path(out_dir) / FILE_NAME
        self.every = float(every)
        self.start = time.perf_counter()
        self.wall_before = wall_before
        self.last = self.start

    @property
    def wall_time(self):
        return self.wall_before + time.perf_counter() - self.start

    def __call__(self, model, state):
        now = time.perf_counter()
        if now - self.last >= self.every:
            save(self.path, model, state, self.wall_time)
            self.last = now

    def remove(self):
        """The run finished: its outputs are complete, nothing to resume."""
        try:
            self.path.unlink()
        except FileNotFoundError:
            pass
