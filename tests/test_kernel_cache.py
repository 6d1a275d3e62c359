"""The compiled kernels' on-disk cache (meshwear/kernels/jit.py): what
numba's own cache does when two processes compile one function at once, and
that meshwear's guard neither crosses entries nor trusts damaged ones."""

import os
import pickle
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

pytest.importorskip("fcntl")

ROOT = Path(__file__).resolve().parents[1]

KERNEL = """
import numpy as np
{import_line}

@njit(cache=True)
def total(a):
    s = a[0] * 0
    for x in a:
        s += x * 2
    return s
"""

#: a process compiling ``total`` for one dtype; both wait for each other
#: between reading numba's index and writing it, and order their writes so
#: that the index names one signature and its data file holds the other's
#: (the interleaving of two first runs on an empty cache). A wait that times
#: out (the other process holds the guard's lock) lets the process go on.
RACER = """
import multiprocessing as mp, os, sys, threading
import numpy as np

def worker(barrier, dtype, folder):
    os.environ["NUMBA_CACHE_DIR"] = os.path.join(folder, "cache")
    sys.path.insert(0, folder)
    from numba.core import caching

    def meet():
        try:
            barrier.wait(timeout=3.0)
        except threading.BrokenBarrierError:
            pass

    cls = caching.IndexDataCacheFile
    load, save_index, save_data = cls._load_index, cls._save_index, cls._save_data

    def load_index(self):
        out = load(self)
        meet()
        return out

    def save_index_(self, overloads):
        if dtype == "float64":
            meet()
        save_index(self, overloads)
        if dtype == "int64":
            meet()

    def save_data_(self, name, data):
        if dtype == "int64":
            meet()
        save_data(self, name, data)
        if dtype == "float64":
            meet()

    cls._load_index, cls._save_index, cls._save_data = load_index, save_index_, save_data_
    import kernel
    kernel.total(np.arange(5, dtype=dtype))

if __name__ == "__main__":
    ctx = mp.get_context("spawn")
    barrier = ctx.Barrier(2)
    procs = [ctx.Process(target=worker, args=(barrier, d, sys.argv[1]))
             for d in ("int64", "float64")]
    for p in procs:
        p.start()
    for p in procs:
        p.join()
    sys.exit(max(abs(p.exitcode) for p in procs))
"""

CHECK = """
import os, sys
import numpy as np
os.environ["NUMBA_CACHE_DIR"] = os.path.join(sys.argv[1], "cache")
sys.path.insert(0, sys.argv[1])
import kernel
print(kernel.total(np.arange(5, dtype=np.int64)), kernel.total(np.arange(5, dtype=np.float64)))
"""


def _folder(tmp_path, guarded):
    line = ("from meshwear.kernels.jit import njit" if guarded else "from numba import njit")
    (tmp_path / "kernel.py").write_text(KERNEL.format(import_line=line))
    (tmp_path / "racer.py").write_text(textwrap.dedent(RACER))
    (tmp_path / "check.py").write_text(CHECK)
    return tmp_path


def _python(*args, timeout=120):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    env.pop("NUMBA_CACHE_DIR", None)
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, env=env,
                          timeout=timeout)


def _totals(folder):
    done = _python(str(folder / "check.py"), str(folder))
    return done.returncode, done.stdout.split(), done.stderr


def test_two_first_runs_at_once_cross_numba_s_index_but_not_the_guarded_one(tmp_path):
    # numba's own cache: the index names the float signature, its data file
    # holds the int one's machine code, and a later process reads int bits as
    # floats (with larger kernels: SIGSEGV)
    (tmp_path / "stock").mkdir()
    stock = _folder(tmp_path / "stock", guarded=False)
    assert _python(str(stock / "racer.py"), str(stock)).returncode == 0
    code, totals, _ = _totals(stock)
    assert code != 0 or totals != ["20", "20.0"], "the race did not cross numba's own cache"
    # the same two processes on the guard: one compiles, saves and lets go
    # of the folder's lock; the other loads what the first saved
    (tmp_path / "guarded").mkdir()
    guarded = _folder(tmp_path / "guarded", guarded=True)
    assert _python(str(guarded / "racer.py"), str(guarded)).returncode == 0
    assert _totals(guarded)[:2] == (0, ["20", "20.0"])


def _guarded_cache(tmp_path):
    folder = _folder(tmp_path, guarded=True)
    assert _totals(folder)[:2] == (0, ["20", "20.0"])
    (index,) = (folder / "cache").rglob("*.nbi")
    data = sorted(index.parent.glob("*.nbc"))
    assert len(data) == 2
    return folder, index, data


def test_an_index_naming_another_signature_s_entry_is_compiled_anew(tmp_path):
    folder, index, _ = _guarded_cache(tmp_path)
    with open(index, "rb") as f:
        version = pickle.load(f)
        stamp, overloads = pickle.loads(f.read())
    names = list(overloads.values())
    crossed = dict(zip(overloads, reversed(names)))
    with open(index, "wb") as f:
        pickle.dump(version, f, protocol=-1)
        f.write(pickle.dumps((stamp, crossed), protocol=-1))
    code, totals, err = _totals(folder)
    assert (code, totals) == (0, ["20", "20.0"])
    assert "compiling it anew" in err and err.count("\n") == 2
    # and the entries are right again
    code, totals, err = _totals(folder)
    assert (code, totals, err) == (0, ["20", "20.0"], "")


@pytest.mark.parametrize("damage", ["truncated", "garbage index"])
def test_a_damaged_entry_is_compiled_anew_with_one_line(tmp_path, damage):
    folder, index, data = _guarded_cache(tmp_path)
    if damage == "truncated":
        data[0].write_bytes(data[0].read_bytes()[:100])
    else:
        index.write_bytes(b"\x80\x05not a pickle")
    code, totals, err = _totals(folder)
    assert (code, totals) == (0, ["20", "20.0"])
    lines = err.strip().splitlines()
    assert lines and all("compiled anew" in line or "compiling it anew" in line
                         for line in lines), err
    assert _totals(folder) == (0, ["20", "20.0"], "")


NESTED = """
import sys

import numpy as np
from numba import prange

{import_line}


@njit(cache=True, parallel=True)
def inner(a):
    out = np.empty(a.shape[0])
    for i in prange(a.shape[0]):
        out[i] = 2.0 * a[i]
    return out


@njit(cache=True)
def outer(a):
    return inner(a).sum()


a = np.ones(100_000)
print(inner(a).sum() if sys.argv[1] == "inner" else outer(a))
"""


@pytest.mark.parametrize("guarded", [False, True])
def test_a_cached_kernel_calling_a_threaded_one_runs_from_the_cache(tmp_path, guarded):
    """The crash of issue 41. A process compiles and caches a ``parallel=True``
    kernel; a second loads it from the cache, compiles a kernel that calls
    it and caches that; a third loads the caller and, nothing having started
    numba's threading layer there, dies with SIGSEGV at its parallel region
    (numba#8578, #9938). The guarded cache starts the layer when it loads a
    kernel (``jit._threads_up``)."""
    line = ("from meshwear.kernels.jit import njit" if guarded else "from numba import njit")
    script = tmp_path / "nested.py"
    script.write_text(NESTED.format(import_line=line))
    env = dict(os.environ, PYTHONPATH=str(ROOT), NUMBA_CACHE_DIR=str(tmp_path / "cache"),
               NUMBA_NUM_THREADS="2")
    runs = [subprocess.run([sys.executable, str(script), which], capture_output=True,
                           text=True, env=env, timeout=300)
            for which in ("inner", "outer", "outer")]
    for done in runs[:2]:
        assert done.returncode == 0 and done.stdout.split() == ["200000.0"]
    if guarded:
        assert runs[2].returncode == 0 and runs[2].stdout.split() == ["200000.0"]
    else:
        assert runs[2].returncode == -11, "numba's own cache did not crash: the test shows nothing"


def test_a_run_that_compiles_says_so_once_and_how_long_it_took():
    """meshwear.kernels.notice: the first compile prints the line, once
    however many kernels follow (a kernel compiles those it calls), and
    ``done`` gives the time; a run that compiles nothing prints nothing."""
    import io

    import numpy as np
    from numba import njit

    from meshwear.kernels.notice import STARTING, CompileNotice

    @njit
    def inner(a):
        return a.sum()

    @njit
    def outer(a):
        return inner(a) + 1.0

    stream = io.StringIO()
    with CompileNotice(stream) as notice:
        assert outer(np.ones(3)) == 4.0
        assert inner(np.ones(2, np.int64)) == 2
    assert stream.getvalue() == STARTING + "\n"
    assert notice.count == 2 and notice.seconds > 0.0
    assert notice.done().startswith("kernels compiled in ")
    quiet = io.StringIO()
    with CompileNotice(quiet) as again:
        outer(np.ones(3))                      # compiled already
    assert quiet.getvalue() == "" and again.done() == ""
