"""``njit`` with an on-disk cache that concurrent, interrupted or mixed use
cannot corrupt.

numba's cache (``numba.core.caching``) keeps, per function, an index (each
compiled signature's key to a numbered data file) and the data files. Two
processes that compile two signatures of one function at once (a sweep's
workers, runs started together on an empty cache) both read the empty
index, both take data file 1, and the index written last can name the data
written by the other: a later process then loads machine code compiled for
other argument types and computes garbage or dies with SIGSEGV (numba#4807,
numba#10128; `tests/test_kernel_cache.py` rebuilds that state). numba also
writes the index before the data, so an interrupted save can leave an index
naming an older data file.

The kernels are compiled with this module's :func:`njit`, which keeps
numba's cache but:

- holds an exclusive lock on the cache folder (``fcntl.flock`` of
  ``compile.lock`` there) while a kernel is loaded or compiled and saved,
  so processes that start together compile one at a time and the later ones
  load what the first saved;
- names a data file by digests of its key (signature, CPU, bytecode, the
  sources' stamp) and of its contents, writes it before the index names it,
  and checks the contents against their digest when it loads them;
- takes a loaded entry only if it was compiled for the signature asked for;
- starts numba's threading layer before it loads any kernel: a kernel that
  calls threaded ones, compiled where those were loaded from the cache, is
  saved without their start-up and, loaded first in a later process, calls
  the parallel scheduler at address 0 (numba#8578; :func:`_threads_up`).

Anything else it finds (a foreign, truncated or unreadable entry) it drops
with one warning (a line on stderr) and compiles anew, saving over it. The source stamp
is the digest of :mod:`meshwear.kernels.cachedir`, not each file's
modification time. docs/performance.md, "Kernel cache".
"""

import contextlib
import hashlib
import logging
import os
import threading
import time

import numba
from numba.core import caching, sigutils
from numba.core.compiler_lock import global_compiler_lock

from . import cachedir

#: seconds a process waits for another's compile before it says so
WAIT_NOTICE = 2.0

_lock = threading.RLock()
_held = [0, None]            # depth of this process's hold, the lock file
_told = set()


def njit(*args, **options):
    """numba's ``njit``; with ``cache=True`` the kernel's cache is the guarded
    one of this module."""
    cache = options.pop("cache", False)

    def decorate(fn):
        dispatcher = numba.njit(**options)(fn)
        if cache:
            dispatcher._cache = GuardedCache(dispatcher.py_func)
            _lock_compiles(dispatcher)
        return dispatcher

    if args and callable(args[0]):
        return decorate(args[0])
    return decorate


def _lock_compiles(dispatcher):
    """Make ``dispatcher.compile`` hold the cache folder's lock where it
    loads or compiles (numba's compiler lock first, then the file's, always
    in that order)."""
    compile_ = dispatcher.compile

    def compile(sig):
        args, _ = sigutils.normalize_signature(sig)
        if tuple(args) in dispatcher.overloads:
            return compile_(sig)
        with global_compiler_lock, folder_lock():
            return compile_(sig)

    dispatcher.compile = compile


def lock_path():
    """The lock file of the cache folder."""
    folder = numba.config.CACHE_DIR or os.path.join(
        __import__("tempfile").gettempdir(), f"meshwear-numba-{getattr(os, 'getuid', lambda: 0)()}")
    return os.path.join(folder, "compile.lock")


@contextlib.contextmanager
def folder_lock():
    """An exclusive hold of the cache folder's lock, re-entrant in a process."""
    with _lock:
        if _held[0] == 0:
            _held[1] = _acquire(lock_path())
        _held[0] += 1
        try:
            yield
        finally:
            _held[0] -= 1
            if _held[0] == 0 and _held[1] is not None:
                _held[1].close()           # closing the file drops the lock
                _held[1] = None


def _acquire(path):
    """The open lock file, locked; None where files cannot be locked here
    (no ``fcntl``, a folder that cannot be written): then numba's own,
    unlocked, behaviour with the other guards."""
    try:
        import fcntl
    except ImportError:
        return None
    try:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        f = open(path, "a+b")
    except OSError:
        return None
    start = time.monotonic()
    told = False
    while True:
        try:
            fcntl.flock(f.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
            return f
        except BlockingIOError:
            pass
        except OSError:
            f.close()
            return None
        if not told and time.monotonic() - start > WAIT_NOTICE:
            logging.getLogger("meshwear").warning(
                "waiting for another process compiling kernels into %s", os.path.dirname(path))
            told = True
        time.sleep(0.05)


def _threads_up():
    """Start numba's threading layer (once), before any kernel is loaded
    from the cache. Starting it gives LLVM the layer's symbols (the parallel
    scheduler's entry points); a kernel whose machine code calls them, linked
    before they are given, calls address 0. A kernel that is not
    ``parallel=True`` itself but calls one that is (the step loop calls the
    threaded contact and counter kernels) does not start it when loaded if
    it was compiled in a process that loaded that threaded kernel from the
    cache: its saved library does not carry the callee's start-up
    (numba#8578, #9938; numba PR #9950, not released). A process that
    loads it first then dies with SIGSEGV at its first parallel region,
    every run, until the cache is emptied: the crash of issue 41, after
    runs that compiled some kernels and loaded others. Started after the
    load is too late. ``numba.get_num_threads`` starts it."""
    if not _started[0]:
        numba.get_num_threads()
        _started[0] = True


_started = [False]


def _say(what):
    """One warning (a line on stderr), once per process and entry."""
    if what not in _told:
        _told.add(what)
        logging.getLogger("meshwear").warning("%s", what)


class GuardedIndex(caching.IndexDataCacheFile):
    """numba's index and data files, with data named by digests of key and
    contents, written before the index, and checked when read."""

    def save(self, key, data):
        payload = self._dump(data)
        key_digest = hashlib.sha1(repr((key, self._source_stamp)).encode()).hexdigest()[:16]
        name = (f"{self._index_name[:-4]}.{key_digest}."
                f"{hashlib.sha1(payload).hexdigest()[:16]}.nbc")
        with self._open_for_write(self._data_path(name)) as f:
            f.write(payload)
        overloads = self._load_index()
        old = overloads.get(key)
        overloads[key] = name
        self._save_index(overloads)
        if old is not None and old != name:
            with contextlib.suppress(OSError):
                os.unlink(self._data_path(old))

    def _load_index(self):
        try:
            return super()._load_index()
        except Exception as error:                      # noqa: BLE001 (any damage)
            _say(f"the kernel cache index {self._index_path} could not be read "
                 f"({type(error).__name__}); its kernels are compiled anew")
            return {}

    def _load_data(self, name):
        path = self._data_path(name)
        with open(path, "rb") as f:
            payload = f.read()
        parts = name.rsplit(".", 3)
        if len(parts) != 4 or hashlib.sha1(payload).hexdigest()[:16] != parts[2]:
            raise DamagedEntry(f"{path} does not hold what its name says")
        return caching.pickle.loads(payload)


class DamagedEntry(Exception):
    """A cached entry that cannot be trusted."""


class GuardedCache(caching.FunctionCache):
    """numba's per-function cache on :class:`GuardedIndex`, stamped with the
    sources' digest, taking only entries compiled for the signature asked
    for and dropping any other with one line."""

    def __init__(self, py_func):
        super().__init__(py_func)
        self._cache_file = GuardedIndex(self._cache_path, self._impl.filename_base,
                                        cachedir.digest())

    def load_overload(self, sig, target_context):
        _threads_up()
        try:
            cres = super().load_overload(sig, target_context)
        except Exception as error:                      # noqa: BLE001 (any damage)
            _say(f"a cached kernel ({self._name}) in {self._cache_path} could not be "
                 f"loaded ({type(error).__name__}: {error}); compiling it anew")
            return None
        if cres is None:
            return None
        args = tuple(sigutils.normalize_signature(sig)[0])
        if tuple(cres.signature.args) != args:
            _say(f"a cached kernel ({self._name}) in {self._cache_path} was compiled for "
                 f"{cres.signature.args}, not {args}; compiling it anew")
            return None
        return cres

    def save_overload(self, sig, data):
        try:
            super().save_overload(sig, data)
        except OSError as error:
            _say(f"kernels cannot be cached in {self._cache_path} ({error}); "
                 f"they are compiled again in each run")
