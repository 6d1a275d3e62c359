"""Recorders: observers that turn a running state into the files of docs/outputs.md.

Physics never writes files; :func:`meshwear.step.simulate.run` calls
``on_sample`` / ``on_frame`` and the CLI calls ``close`` with the summary.
"""

import errno
import shutil
from pathlib import Path

from ..scene.reader import RESERVED_NAMES
from .fields import body_quantities, body_totals, part_quantities
from .export import SERIES_SUFFIXES
from .folder import SPARE_BYTES, FolderLock, check_writable
from .tables import HISTORY_COLUMNS, HistoryWriter, write_json_atomic
from .vtk import PVDSeries


def series_class(model):
    """The writer of ``run.series``: :class:`PVDSeries` or
    :class:`meshwear.output.vtkhdf.VTKHDFSeries`."""
    if model.scene.run.series == "vtkhdf":
        from .vtkhdf import VTKHDFSeries

        return VTKHDFSeries
    return PVDSeries

#: columns added to the history.csv of docs/outputs.md (extend, never rename)
EXTRA_COLUMNS = ("wx", "wy", "wz", "tx", "ty", "tz", "contact_points", "stick_points", "slip_points",
                 "resolved")
FIELDS = ("wear_depth", "normal_force", "friction_force", "pressure", "contact_state", "friction_work")
#: a history.csv row at most (B): 28 columns of up to 17 characters
ROW_BYTES = 28 * 18


class RunRecorder:
    """Writes ``OUT/<body>.pvd`` series (or ``.vtkhdf``), ``history.csv`` and ``summary.json``.

    Parameters
    ----------
    out_dir : path
    model : meshwear.model.Model
    resume_until : float, optional
        Continue the files of a stopped run, keeping what it wrote up to this
        time (s) and dropping the rest.
    state : meshwear.model.State, optional
        The run's first state: ``summary.json`` says ``"running"`` from the
        start (a run killed outright leaves that, not an older run's "ok").
    check_space : bool
        After the first frame, refuse a run whose outputs to come need more
        than the folder's free space (``OSError(ENOSPC)``).

    Raises
    ------
    meshwear.output.folder.FolderBusy
        Another run writes to ``out_dir`` (held from here to :meth:`finish`).
    OSError
        A folder or file that cannot be written: nothing replaced yet.
    ValueError
        Resuming into files that are not the stopped run's, or damaged.
    """

    def __init__(self, out_dir, model, resume_until=None, state=None, check_space=True):
        self.out_dir = Path(out_dir)
        self.out_dir.mkdir(parents=True, exist_ok=True)
        self._projected = not check_space      # the outputs to come checked against the disk
        self.lock = FolderLock(self.out_dir)
        try:
            self._open(model, resume_until, state)
        except BaseException:
            self.lock.release()
            raise

    def _open(self, model, resume_until, state):
        names = [part.name for part in list(model.bodies) + list(model.surfaces.slots)]
        check_writable(self.out_dir, [f"{n}{suffix}" for n in names for suffix in SERIES_SUFFIXES]
                       + list(RESERVED_NAMES), names)
        Series = series_class(model)
        self.series = {b.name: Series(self.out_dir, b.name, b.faces, resume_until)
                       for b in model.bodies}
        joints = tuple(model.dynamics.columns())
        self.history = HistoryWriter(self.out_dir / "history.csv", EXTRA_COLUMNS + joints,
                                     resume_until)
        # counter-surfaces: one frame if they stay put, else one per frame
        self.moving = {}
        # worn counter-surfaces: a series with a body's fields, history rows
        self.parts = {m: Series(self.out_dir, surface.name, surface.faces, resume_until)
                      for m, surface in enumerate(model.surfaces.per_vertex) if surface.worn}
        for surface in model.surfaces.slots:
            if surface.worn:
                continue
            vertices, faces = surface.drawing(model.extent)
            if surface.static:
                still = Series(self.out_dir, surface.name, faces)
                still.write_frame(0.0, surface.world_vertices(vertices, 0.0), {})
                still.close()
            else:
                self.moving[surface.name] = (surface, vertices,
                                             Series(self.out_dir, surface.name, faces,
                                                       resume_until))
        # the files are this run's now (a refused --resume leaves the stopped
        # run's summary); one killed from here on is not taken for a finished one
        if state is not None:
            write_json_atomic(self.out_dir / "summary.json",
                              summary(model, state, 0.0, "running", "the run has not ended"))

    def on_sample(self, model, state):
        for row in history_rows(model, state):
            self.history.write(row)

    def on_frame(self, model, state):
        for body, s in zip(model.bodies, state.bodies):
            q = body_quantities(body, s, model)
            self.series[body.name].write_frame(
                state.time, q["points"], {k: q[k] for k in FIELDS},
                {"resolved": int(state.resolved), "origin": q["origin"],
                 "orientation": s.pose[3:7]})
        for surface, vertices, series in self.moving.values():
            series.write_frame(state.time, surface.world_vertices(vertices, state.time), {})
        for m, series in self.parts.items():
            q = part_quantities(model, state, m)
            series.write_frame(state.time, q["points"], {k: q[k] for k in FIELDS},
                               {"resolved": int(state.resolved), "origin": q["origin"],
                                "orientation": q["orientation"]})
        if not self._projected:
            self._projected = True
            self._refuse_a_full_disk(model, state)

    def _refuse_a_full_disk(self, model, state):
        """After the run's first frame, whose size is now known: refuse
        (``OSError(ENOSPC)``) a run whose frames and history rows to come
        need more than the folder's free space, before any more work."""
        series = (list(self.series.values()) + list(self.parts.values())
                  + [s for _, _, s in self.moving.values()])
        per_frame = sum(getattr(s, "frame_bytes", 0) for s in series)
        frames = int((model.frame_steps > state.step).sum())
        rows = int((model.sample_steps > state.step).sum()) * len(history_rows(model, state))
        need = per_frame * frames + ROW_BYTES * rows
        free = shutil.disk_usage(self.out_dir).free
        if need + SPARE_BYTES > free:
            raise OSError(errno.ENOSPC,
                          f"No space left on device for this run: its {frames} frames to come "
                          f"({per_frame / 2**20:.3g} MiB each) and {rows} history rows need "
                          f"about {need / 2**30:.3g} GiB, {free / 2**30:.3g} GiB are free "
                          "(fewer run.frames, or another folder)", str(self.out_dir))

    def finish(self):
        """Close the history and every series, and free the folder."""
        self.history.close()
        for series in list(self.series.values()) + list(self.parts.values()):
            series.close()
        for _, _, series in self.moving.values():
            series.close()
        self.lock.release()

    def close(self, summary):
        """Write ``summary.json`` and :meth:`finish`."""
        write_json_atomic(self.out_dir / "summary.json", summary)
        self.finish()


def history_rows(model, state):
    """The ``history.csv`` rows of ``state`` (docs/outputs.md), one dict per
    body and worn counter-surface, keyed by column name."""
    rows = []
    for body, s in zip(model.bodies, state.bodies):
        q = body_totals(body, s)
        rows.append(_row(state, body.name, q, q["origin"], s.pose[3:7], s.pose[7:10],
                         s.pose[10:13], s.wrench))
    for m, surface in enumerate(model.surfaces.per_vertex):
        if surface.worn:
            q = part_quantities(model, state, m)
            rows.append(_row(state, surface.name, q, q["origin"], q["orientation"],
                             q["velocity"], q["angular_velocity"], q["wrench"]))
    # a mechanism's joints and actuators, on every row of the sample
    joints = model.dynamics.columns()
    for row in rows:
        row.update(joints)
    return rows


def _row(state, name, q, origin, orientation, velocity, spin, wrench):
    row = dict(zip(("x", "y", "z"), origin))
    row.update(zip(("qw", "qx", "qy", "qz"), orientation))
    row.update(zip(("vx", "vy", "vz"), velocity))
    row.update(zip(("wx", "wy", "wz"), spin))
    row.update(zip(("fx", "fy", "fz", "tx", "ty", "tz"), wrench))
    row.update(time=state.time, body=name, friction_work=q["total_friction_work"],
               wear_volume=q["wear_volume"], max_wear_depth=q["max_wear_depth"],
               contact_points=q["contact_points"], stick_points=q["stick_points"],
               slip_points=q["slip_points"], resolved=int(state.resolved))
    return row


def summary(model, state, wall_time, status="ok", message=None):
    """The ``summary.json`` object of docs/outputs.md (plus ``status``/``message``)."""
    cycles = state.time / model.period if model.period else None
    out = {
        "format": 1,
        "status": status,
        "time": state.time,
        "steps": state.step,
        "dt": model.dt,
        "cycles": cycles,
        "resolved_cycles": cycles,
        "wall_time": wall_time,
        "bodies": {},
    }
    if state.jump is not None:
        out["resolved_cycles"] = state.jump.resolved_steps * model.dt / model.period
        out["resolved_steps"] = state.jump.resolved_steps
        out["jumps"] = state.jump.jumps
        out["error_estimate"] = state.jump.error_estimate(state)
        out["jump_limits"] = dict(state.jump.limits)
        out["jump_method"] = model.scene.wear.jump
    if message:
        out["message"] = message
    for body, s in zip(model.bodies, state.bodies):
        q = body_totals(body, s)
        out["bodies"][body.name] = {
            "wear_volume": q["wear_volume"],
            "max_wear_depth": q["max_wear_depth"],
            "friction_work": q["total_friction_work"],
            "position": q["origin"].tolist(),
            "orientation": s.pose[3:7].tolist(),
            "velocity": s.pose[7:10].tolist(),
            "angular_velocity": s.pose[10:13].tolist(),
            "contact_force": s.wrench[0:3].tolist(),
            "contact_points": q["contact_points"],
            "vertices": int(len(s.wear_depth)),
            "active_vertices": int(len(s.active)),
        }
    # worn counter-surfaces, in the shape of a body's entry
    for m, surface in enumerate(model.surfaces.per_vertex):
        if not surface.worn:
            continue
        q = part_quantities(model, state, m)
        out.setdefault("surfaces", {})[surface.name] = {
            "wear_volume": q["wear_volume"],
            "max_wear_depth": q["max_wear_depth"],
            "friction_work": q["total_friction_work"],
            "position": q["origin"].tolist(),
            "orientation": q["orientation"].tolist(),
            "velocity": q["velocity"].tolist(),
            "angular_velocity": q["angular_velocity"].tolist(),
            "contact_force": q["wrench"][0:3].tolist(),
            "contact_points": q["contact_points"],
            "vertices": int(len(q["wear_depth"])),
        }
    return out


__all__ = ["RunRecorder", "history_rows", "summary", "HISTORY_COLUMNS", "EXTRA_COLUMNS"]
