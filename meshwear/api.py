"""The Python interface (docs/api.md): load a scene, set keys, run, read the results.

::

    import meshwear

    scene = meshwear.load("examples/pin_on_disc.toml", {"wear.coefficient": 1e-13})
    result = meshwear.run(scene, progress=print)
    pin = result.parts["pin"]
    pin.wear_depth.max(), pin.mesh.volume, result.summary["bodies"]["pin"]["wear_volume"]

The runs are those of ``meshwear run``: the same model, loop and outputs
(an ``out`` folder gets the files of docs/outputs.md), kept in memory as
numpy arrays. The history keeps each sample's totals; the per-vertex wear
depth at every sample only when asked (``vertex_history=True``: samples ×
vertices floats).
"""

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .geometry.remesh import available_memory
from .scene.reader import Scene, load_scene
from .scene.checks import SceneError


def load(path, values=None):
    """Read and check a scene file, with keys set over the file's.

    Parameters
    ----------
    path : str or os.PathLike
        TOML scene (docs/scene-format.md).
    values : dict or sequence of (key, value), optional
        Keys by their dotted names (``wear.coefficient``, ``body[0].force``),
        as :meth:`meshwear.scene.Scene.set` takes them.

    Returns
    -------
    meshwear.scene.Scene

    Raises
    ------
    meshwear.scene.SceneError
        One line naming the file and the key.
    """
    pairs = list(values.items()) if isinstance(values, dict) else list(values or ())
    from .scene.reader import _plain

    return load_scene(path, [(k, _plain(v)) for k, v in pairs])


@dataclass
class Part:
    """One worn part of a finished run: a ``[[body]]`` or a worn mesh surface.

    Attributes
    ----------
    name : str
    kind : str
        ``"body"`` or ``"surface"``.
    vertices : (n, 3) float
        Worn vertices in the part's own frame: the mesh file's axes and
        origin, in metres.
    faces : (m, 3) int
    fields : dict of arrays
        The per-vertex point data of the frames (docs/outputs.md) at the end:
        ``wear_depth`` (m), ``normal_force`` (N), ``friction_force`` (n, 3) N,
        ``pressure`` (Pa), ``contact_state`` (0 free, 1 stick, 2 slip),
        ``friction_work`` (J).
    history : dict of arrays
        This part's rows of the history: one array per column of
        ``history.csv``.
    depth_history : (k, n) float or None
        Wear depth of every vertex at every history sample, when the run was
        asked for it (``vertex_history=True``).
    """

    name: str
    kind: str
    vertices: np.ndarray
    faces: np.ndarray
    fields: dict
    history: dict = field(default_factory=dict)
    depth_history: np.ndarray | None = None

    @property
    def wear_depth(self):
        """(n,) wear depth of each vertex at the end (m)."""
        return self.fields["wear_depth"]

    @property
    def mesh(self):
        """The worn part as a :class:`trimesh.Trimesh` in its own frame (m)."""
        import trimesh

        return trimesh.Trimesh(self.vertices.copy(), self.faces.copy(), process=False)


@dataclass
class Result:
    """A finished run: its parts, history columns and summary.

    Attributes
    ----------
    scene : meshwear.scene.Scene
    parts : dict of str to Part
        Every worn part by name: the bodies, then the worn counter-surfaces.
    history : dict of arrays
        The whole history table, one array per column of ``history.csv``
        (``body`` names the part of each row).
    summary : dict
        The ``summary.json`` object (docs/outputs.md).
    out : pathlib.Path or None
        The folder the files were written to, if any.
    model, state
        The run's :class:`meshwear.model.Model` and final state, for
        scripts that go further.
    """

    scene: Scene
    parts: dict
    history: dict
    summary: dict
    out: Path | None
    model: object = field(repr=False)
    state: object = field(repr=False)


def run(scene, *, out=None, progress=None, vertex_history=False, check_dt=True):
    """Run a scene in memory, optionally writing its files too.

    Parameters
    ----------
    scene : Scene or path
        A scene from :func:`load` (or a file, loaded as it is).
    out : path, optional
        Also write the ParaView series, ``history.csv`` and ``summary.json``
        there, as ``meshwear run -o OUT`` does.
    progress : callable, optional
        ``progress(step, n_steps)``, called every few thousand steps and at
        every history sample.
    vertex_history : bool
        Keep every vertex's wear depth at every history sample
        (:attr:`Part.depth_history`).
    check_dt : bool
        Refuse a ``run.dt`` above the stability limit, as the command does.

    Returns
    -------
    Result

    Raises
    ------
    meshwear.scene.SceneError
        Bad input (one line naming the key).
    meshwear.step.simulate.NumericalError
        The run became numerically invalid (the files written so far stay valid).
    """
    from .model.build import build_model, check_time_step, initial_state
    from .output.folder import FolderBusy
    from .output.recorder import RunRecorder, summary
    from .step.simulate import NumericalError, run as run_model

    if not isinstance(scene, Scene):
        scene = load_scene(scene)
    model = build_model(scene)
    if check_dt:
        check_time_step(model)
    _refuse_more_history_than_memory(model, vertex_history)
    state = initial_state(model)
    columns = HistoryColumns(vertex_history)
    observers = [columns]
    recorder = None
    if out is not None:
        try:
            recorder = RunRecorder(out, model, state=state)
        except FolderBusy as err:
            raise SceneError(str(out), "", str(err)) from None
        except OSError as err:
            raise SceneError(str(out), "", f"output folder: cannot write there "
                                           f"({err.strerror or err})") from None
        observers.append(recorder)
    start = time.perf_counter()
    try:
        run_model(model, state, observers=observers, progress=progress)
    except NumericalError as err:
        if recorder is not None:
            recorder.close(summary(model, state, time.perf_counter() - start,
                                   "numerical_error", str(err)))
        raise
    totals = summary(model, state, time.perf_counter() - start)
    if recorder is not None:
        recorder.close(totals)
    table = columns.table()
    return Result(scene=scene, parts=_parts(model, state, columns, table), history=table,
                  summary=totals, out=Path(out) if out is not None else None, model=model,
                  state=state)


def _parts(model, state, columns, table):
    from .output.fields import body_quantities, part_quantities
    from .output.recorder import FIELDS

    names = table.get("body", np.array([], dtype=object))
    parts = {}
    for body, s in zip(model.bodies, state.bodies):
        q = body_quantities(body, s, model)
        parts[body.name] = Part(
            name=body.name, kind="body", vertices=s.vertices - body.origin,
            faces=body.faces.copy(), fields={k: np.array(q[k]) for k in FIELDS},
            history={k: v[names == body.name] for k, v in table.items()},
            depth_history=columns.depths(body.name))
    for m, surface in enumerate(model.surfaces.per_vertex):
        if surface.worn:
            q = part_quantities(model, state, m)
            parts[surface.name] = Part(
                name=surface.name, kind="surface", vertices=state.parts[m].vertices.copy(),
                faces=surface.faces.copy(), fields={k: np.array(q[k]) for k in FIELDS},
                history={k: v[names == surface.name] for k, v in table.items()},
                depth_history=columns.depths(surface.name))
    return parts


#: history columns that count
INTEGER_COLUMNS = ("contact_points", "stick_points", "slip_points", "resolved")


#: memory one history row takes in :class:`HistoryColumns` (B): measured
#: ~1.5 KiB as a dict of Python floats, and its share of the columns
ROW_BYTES = 2048


def _refuse_more_history_than_memory(model, vertex_history):
    """SceneError naming ``run.history`` when the rows kept in memory (and
    each part's wear depth per row, if asked) need more than the available
    memory."""
    samples = len(model.sample_steps)
    sizes = [len(b.tributary_area) for b in model.bodies] + [
        len(m.vertices) for m in model.surfaces.per_vertex if m.worn]
    need = samples * len(sizes) * ROW_BYTES + (8 * samples * sum(sizes) if vertex_history else 0)
    memory = available_memory()
    if memory is not None and need > memory:
        kept = "history rows and per-vertex wear depths" if vertex_history else "history rows"
        raise SceneError(model.scene.source, "run.history",
                         f"{samples} samples of {len(sizes)} part(s): their {kept} take about "
                         f"{need / 2**30:.3g} GiB in memory, more than the "
                         f"{memory / 2**30:.3g} GiB available; ask fewer, or run "
                         "`meshwear run`, which writes them to history.csv")


class HistoryColumns:
    """Observer keeping the history rows of ``history.csv`` in memory (and,
    if asked, every part's per-vertex wear depth at each sample)."""

    def __init__(self, vertex_history=False):
        self.vertex_history = vertex_history
        self.rows = []
        self._depths = {}

    def on_sample(self, model, state):
        from .output.recorder import history_rows

        self.rows.extend(history_rows(model, state))
        if self.vertex_history:
            for body, s in zip(model.bodies, state.bodies):
                self._depths.setdefault(body.name, []).append(s.wear_depth.copy())
            for m, surface in enumerate(model.surfaces.per_vertex):
                if surface.worn:
                    self._depths.setdefault(surface.name, []).append(
                        state.parts[m].depth.copy())

    def on_frame(self, model, state):
        pass

    def table(self):
        """One array per column (``body`` an object array of names), in the
        order of ``history.csv``: a mechanism's joint and actuator columns
        last."""
        from .output.recorder import EXTRA_COLUMNS
        from .output.tables import HISTORY_COLUMNS

        out = {}
        fixed = tuple(HISTORY_COLUMNS) + tuple(EXTRA_COLUMNS)
        for column in fixed + tuple(c for c in (self.rows[0] if self.rows else ())
                                    if c not in fixed):
            values = [row[column] for row in self.rows]
            out[column] = np.array(values, dtype=object if column == "body" else
                                   int if column in INTEGER_COLUMNS else float)
        return out

    def depths(self, name):
        """(k, n) wear depth of part ``name`` at each sample, or None."""
        if not self.vertex_history or name not in self._depths:
            return None
        return np.array(self._depths[name])
