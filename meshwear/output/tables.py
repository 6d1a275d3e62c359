"""``history.csv`` and JSON files (docs/outputs.md), written so an interrupted run leaves them valid."""

import csv
import json
import math
import os
import tempfile
from pathlib import Path

import numpy as np

#: the columns docs/outputs.md fixes, in this order (others are appended, never renamed)
HISTORY_COLUMNS = ("time", "body", "x", "y", "z", "qw", "qx", "qy", "qz", "vx", "vy", "vz",
                   "fx", "fy", "fz", "friction_work", "wear_volume", "max_wear_depth")


class HistoryWriter:
    """``OUT/history.csv``: one row per body per sample.

    Every row is flushed as it is written, so a run stopped at any moment leaves
    a file of complete rows. Floats are written with ``repr`` (round-trip exact,
    ``nan``/``inf`` as such).

    Parameters
    ----------
    path : str or Path
        Replaced if it exists.
    extra_columns : sequence of str
        Columns after :data:`HISTORY_COLUMNS`.
    """

    def __init__(self, path, extra_columns=(), resume_until=None):
        self.columns = tuple(HISTORY_COLUMNS) + tuple(extra_columns)
        if len(set(self.columns)) != len(self.columns):
            raise ValueError(f"duplicate history columns in {self.columns}")
        self.path = Path(path)
        if resume_until is not None:
            self._keep_rows_until(resume_until)
            self._file = open(self.path, "a", newline="", encoding="utf-8")
            self._csv = csv.writer(self._file, lineterminator="\n")
            return
        self._file = open(self.path, "w", newline="", encoding="utf-8")
        self._csv = csv.writer(self._file, lineterminator="\n")
        self._csv.writerow(self.columns)
        self._file.flush()

    def _keep_rows_until(self, time):
        """Resuming: drop the rows written after ``time`` (s) by the stopped run."""
        try:
            with open(self.path, newline="", encoding="utf-8") as f:
                rows = list(csv.reader(f))
        except FileNotFoundError:
            raise ValueError(f"{self.path}: the stopped run's history is missing") from None
        except (csv.Error, UnicodeDecodeError) as err:
            raise ValueError(f"{self.path}: damaged history ({err})") from None
        if not rows or tuple(rows[0]) != self.columns:
            raise ValueError(f"{self.path}: not the history of this run (columns differ)")
        limit = time + 1e-12 * max(1.0, abs(time))
        try:
            kept = [r for r in rows[1:] if len(r) == len(self.columns) and float(r[0]) <= limit]
        except ValueError as err:
            raise ValueError(f"{self.path}: damaged history ({err})") from None
        lines = [",".join(self.columns)] + [",".join(r) for r in kept]
        write_text_atomic(self.path, "\n".join(lines) + "\n")

    def write(self, row):
        """Append one row.

        Parameters
        ----------
        row : dict
            Exactly the writer's columns (missing or unknown keys raise ValueError).
        """
        if self._file.closed:
            raise RuntimeError(f"{self.path} is closed")
        if row.keys() != set(self.columns):
            missing = [c for c in self.columns if c not in row]
            unknown = [k for k in row if k not in self.columns]
            raise ValueError(f"history row: missing columns {missing}, unknown columns {unknown}")
        self._csv.writerow([_cell(row[c]) for c in self.columns])
        self._file.flush()

    def close(self):
        self._file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _cell(value):
    if isinstance(value, (bool, np.bool_)):
        return int(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    if isinstance(value, str):
        return value
    raise TypeError(f"history value {value!r} ({type(value).__name__}) is not a number or a string")


def write_json_atomic(path, obj):
    """Write ``obj`` as JSON to ``path`` atomically (temporary file, then ``os.replace``).

    numpy scalars and arrays become plain numbers and lists, paths become
    strings, and non-finite floats become ``null`` (strict JSON has no NaN).
    """
    write_text_atomic(path, json.dumps(_plain(obj), indent=2, allow_nan=False) + "\n")


def file_mode():
    """The mode a new file gets under the process's umask (0644 under the
    usual 022): temporary files are created 0600, and their replacement must
    not keep that (colleagues on a shared disk open the outputs too)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def replace_atomic(tmp, path):
    """Give ``tmp`` the mode of a new file and move it over ``path``."""
    os.chmod(tmp, file_mode())
    os.replace(tmp, path)


def write_text_atomic(path, text):
    """Replace ``path`` by ``text`` atomically (:func:`write_atomic`)."""
    write_atomic(path, lambda f: f.write(text))


def write_atomic(path, write, binary=False):
    """Replace ``path`` by what ``write(f)`` writes to an open file ``f``
    (text, UTF-8 with ``\\n`` line ends, or ``binary``), atomically: through
    a temporary file in the same directory. A reader, or a run killed
    mid-write, sees the old file or the new one, never a part.
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with (os.fdopen(fd, "wb") if binary
              else os.fdopen(fd, "w", encoding="utf-8", newline="\n")) as f:
            write(f)
        replace_atomic(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def _plain(obj):
    """Recursively convert to JSON-native types."""
    if isinstance(obj, dict):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _plain(obj.tolist())
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        value = float(obj)
        return value if math.isfinite(value) else None
    if isinstance(obj, Path):
        return str(obj)
    if obj is None or isinstance(obj, str):
        return obj
    raise TypeError(f"cannot write {type(obj).__name__} to JSON: {obj!r}")
