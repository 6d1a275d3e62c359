"""Parameter sweeps (docs/sweeps.md): one scene run over a grid or a list of
key values, on Dask.

A sweep is a scene file and, per varied key (the dotted names of ``--set``),
a list of values: every combination of them (``grid``) or the i-th value of
each (``list``). Each run writes its files to ``OUT/run_NNN`` and is one row
of ``OUT/sweep.csv``: the varied values, its status, wall time and the
summary figures of each worn part. A failed run is a row with its message;
a run whose folder holds a finished run with the same values is not run
again. Runs go to a :class:`distributed.LocalCluster` (one process per core,
one numba thread each, so they do not oversubscribe the cores), to an
existing scheduler, or one after another in this process (``workers=0``).
"""

import csv
import io
import itertools
import json
import time
import tomllib
from dataclasses import dataclass
from pathlib import Path

from .scene.reader import parse_override
from .scene.checks import SceneError

#: modes of combining the varied values
MODES = ("grid", "list")
#: summary figures of each part in sweep.csv
FIGURES = ("wear_volume", "max_wear_depth", "friction_work")
#: a finished run's record in its folder
RECORD = "sweep_run.json"


@dataclass(frozen=True)
class Sweep:
    """A scene and the values of its varied keys."""

    scene: Path
    keys: tuple
    values: tuple          # per key, a tuple of values
    mode: str = "grid"

    def runs(self):
        """Per run, a dict {key: value} in key order."""
        if self.mode == "list":
            return [dict(zip(self.keys, combo)) for combo in zip(*self.values)]
        return [dict(zip(self.keys, combo)) for combo in itertools.product(*self.values)]


def from_arguments(scene, vary=(), sweep_file=None, mode=None):
    """A :class:`Sweep` from the command line: ``--vary KEY=[v1, v2, ...]``
    (repeatable) and/or a sweep file (TOML: ``scene``, ``mode``, and a table
    ``[values]`` of key = list)."""
    keys, values, file_mode = [], [], None
    source = "--vary"
    if sweep_file is not None:
        source = str(sweep_file)
        try:
            data = tomllib.loads(Path(sweep_file).read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise SceneError(source, "", "file not found") from None
        except (OSError, UnicodeDecodeError) as err:
            raise SceneError(source, "", f"cannot read: {err}") from None
        except tomllib.TOMLDecodeError as err:
            raise SceneError(source, "", f"TOML syntax error: {err}") from None
        unknown = set(data) - {"scene", "mode", "values"}
        if unknown:
            raise SceneError(source, sorted(unknown)[0], "unknown key (expected scene, mode, "
                                                         "values)")
        if scene is None and "scene" in data:
            if not isinstance(data["scene"], str):
                raise SceneError(source, "scene", "expected a file name")
            scene = Path(sweep_file).parent / data["scene"]
        file_mode = data.get("mode")
        table = data.get("values", {})
        if not isinstance(table, dict):
            raise SceneError(source, "values", "expected a table of key = [values]")
        for key, value in table.items():
            keys.append(key)
            values.append(value)
    for text in vary:
        key, value = parse_override(text)
        keys.append(key)
        values.append(value)
        source = "--vary"
    if scene is None:
        raise SceneError(source, "scene", "no scene: give SCENE or scene = \"...\" in the "
                                          "sweep file")
    if not keys:
        raise SceneError(source, "", "nothing varies: give --vary KEY=[v1, v2] or a sweep file")
    if len(set(keys)) != len(keys):
        raise SceneError(source, next(k for k in keys if keys.count(k) > 1), "varied twice")
    for key, value in zip(keys, values):
        if not isinstance(value, list) or not value:
            raise SceneError(source, key, f"expected a non-empty list of values, got {value!r}")
    mode = mode or file_mode or "grid"
    if mode not in MODES:
        raise SceneError(source, "mode", f"expected one of {', '.join(MODES)}, got {mode!r}")
    if mode == "list" and len({len(v) for v in values}) > 1:
        raise SceneError(source, keys[0], "mode 'list' takes lists of one length; got "
                         + ", ".join(f"{k}: {len(v)}" for k, v in zip(keys, values)))
    return Sweep(Path(scene), tuple(keys), tuple(tuple(v) for v in values), mode)


def run_one(scene, values, out_dir, numba_threads=None):
    """Run ``scene`` with ``values`` set, its files into ``out_dir``; return
    the sweep row (status, wall time, figures, message). Never raises for a
    failed run: the failure is the row."""
    start = time.perf_counter()
    row = {"status": "ok", "message": ""}
    if numba_threads:
        import numba

        numba.set_num_threads(min(int(numba_threads), numba.config.NUMBA_NUM_THREADS))
    from .api import load, run
    from .step.simulate import NumericalError

    try:
        result = run(load(scene, values), out=out_dir)
        summary = result.summary
        for name, entry in list(summary["bodies"].items()) + list(
                summary.get("surfaces", {}).items()):
            for figure in FIGURES:
                row[f"{name}.{figure}"] = entry[figure]
        if "error_estimate" in summary:
            row["error_estimate"] = summary["error_estimate"]
    except SceneError as err:
        row.update(status="bad_input", message=str(err))
    except NumericalError as err:
        row.update(status="numerical_error", message=str(err))
    except Exception as err:  # a sweep reports every run; one failing stops none
        row.update(status="failed", message=f"{type(err).__name__}: {err}")
    row["wall_time"] = time.perf_counter() - start
    Path(out_dir).mkdir(parents=True, exist_ok=True)
    record = {"values": values, "row": row}
    (Path(out_dir) / RECORD).write_text(json.dumps(record, indent=1))
    return row


def run_sweep(sweep, out, scheduler=None, workers=None, report=print):
    """Run every run of ``sweep`` not finished in ``out``; write
    ``out/sweep.csv``; return its rows.

    Parameters
    ----------
    scheduler : str, optional
        Address of a running Dask scheduler; default: a LocalCluster.
    workers : int, optional
        LocalCluster processes (default: one per core); 0 runs one after
        another in this process.
    report : callable
        Gets a line per finished run.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    runs = sweep.runs()
    rows = [None] * len(runs)
    todo = []
    for i, values in enumerate(runs):
        folder = out / f"run_{i:03d}"
        done = _finished(folder, values)
        if done is not None:
            rows[i] = done
        else:
            todo.append(i)
    skipped = len(runs) - len(todo)
    if skipped:
        report(f"{skipped} of {len(runs)} runs already finished in {out}: not run again")
    scene = str(sweep.scene.resolve())

    def finish(i, row):
        rows[i] = row
        _write_table(out / "sweep.csv", sweep.keys, runs, rows)
        report(f"run_{i:03d} {row['status']} in {row['wall_time']:.1f} s "
               f"({sum(r is not None for r in rows)} of {len(runs)})"
               + (f": {row['message']}" if row["message"] else ""))

    if todo and workers == 0 and scheduler is None:
        for i in todo:
            finish(i, run_one(scene, runs[i], str(out / f"run_{i:03d}")))
    elif todo:
        with _client(scheduler, workers) as (client, threads):
            futures = {client.submit(run_one, scene, runs[i], str(out / f"run_{i:03d}"),
                                     threads, pure=False): i for i in todo}
            from distributed import as_completed

            for future in as_completed(futures):
                i = futures[future]
                try:
                    row = future.result()
                except Exception as err:  # the worker died (memory, a crash)
                    row = {"status": "failed", "message": f"{type(err).__name__}: {err}",
                           "wall_time": float("nan")}
                finish(i, row)
    _write_table(out / "sweep.csv", sweep.keys, runs, rows)
    return rows


class _client:
    """A Dask client on a scheduler or on a LocalCluster of one-numba-thread
    processes; yields ``(client, numba threads per run)``."""

    def __init__(self, scheduler, workers):
        self.scheduler, self.workers = scheduler, workers
        self.cluster = self.client = None

    def __enter__(self):
        import logging
        import os

        from distributed import Client, LocalCluster

        logging.getLogger("distributed").setLevel(logging.ERROR)
        if self.scheduler is not None:
            self.client = Client(self.scheduler)
            return self.client, None
        import multiprocessing

        import dask

        n = self.workers or os.cpu_count() or 1
        # forked workers start with what this process has loaded (numba's
        # kernels once a run has taken place here: a script's or a
        # notebook's second sweep) instead of importing it all again
        # (docs/sweeps.md); numba's workqueue threads are fork-safe
        method = "fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn"
        with dask.config.set({"distributed.worker.multiprocessing-method": method}):
            self.cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                        dashboard_address=None, silence_logs=logging.ERROR,
                                        env={"NUMBA_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"})
        self.client = Client(self.cluster)
        return self.client, 1

    def __exit__(self, *exc):
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def _finished(folder, values):
    """The row of a run finished in ``folder`` with ``values``, or None."""
    try:
        record = json.loads((folder / RECORD).read_text())
    except (OSError, ValueError):
        return None
    if (record.get("values") != json.loads(json.dumps(values))
            or record.get("row", {}).get("status") != "ok"
            or not (folder / "summary.json").is_file()):
        return None
    return record["row"]


def _text(value):
    """A varied value as it is written in the table (TOML-like)."""
    if isinstance(value, str):
        return value
    return json.dumps(value)


def _write_table(path, keys, runs, rows):
    """Rewrite sweep.csv with the rows so far (atomically)."""
    from .output.tables import write_text_atomic

    figures = []
    for row in rows:
        for column in (row or {}):
            if column not in ("status", "message", "wall_time") and column not in figures:
                figures.append(column)
    columns = ["run", *keys, "status", "wall_time", *figures, "message"]
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(columns)
    for i, (values, row) in enumerate(zip(runs, rows)):
        if row is None:
            continue
        cells = [f"run_{i:03d}", *(_text(values[k]) for k in keys), row["status"],
                 repr(float(row["wall_time"]))]
        cells += [repr(row[f]) if f in row else "" for f in figures]
        cells.append(row.get("message", ""))
        writer.writerow(cells)
    write_text_atomic(path, buffer.getvalue())
