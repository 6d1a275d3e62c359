"""Where the compiled kernels are cached, chosen before numba is imported.

The folder is named by a digest of everything that changes the machine code
numba would make: the source of every meshwear module with compiled
functions (numba keys a cached function by its own file only, so a loop that
calls a changed kernel of another file would run the old one), and the
versions of Python, numba, llvmlite and numpy. An upgrade or a change to any
kernel therefore starts an empty folder; the folders of other digests beside
it are removed. The digest is also the cached entries' source stamp
(:mod:`meshwear.kernels.jit`), in place of numba's modification time and
size of each file, so a file touched without a change (a checkout) does not
make numba compile one file's kernels anew while the cached callers of
another still hold the old ones. docs/performance.md, "Kernel cache".

No numba import here: :mod:`meshwear` calls :func:`choose` at import, and
numba reads ``NUMBA_CACHE_DIR`` when it is first imported.
"""

import hashlib
import os
import sys
import tempfile

PACKAGE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

#: what a source file must contain for its code to count in the digest
COMPILED = b"njit"

_digest = None


def digest():
    """The digest of the compiled code's sources and of the toolchain (hex)."""
    global _digest
    if _digest is None:
        h = hashlib.sha1()
        for name in _versions():
            h.update(name.encode() + b"\0")
        for root, dirs, files in os.walk(PACKAGE):
            dirs[:] = sorted(d for d in dirs if not d.startswith(("__", ".")))
            for name in sorted(files):
                if not name.endswith(".py"):
                    continue
                path = os.path.join(root, name)
                with open(path, "rb") as f:
                    text = f.read()
                if COMPILED in text:
                    h.update(os.path.relpath(path, PACKAGE).encode() + b"\0" + text)
        _digest = h.hexdigest()
    return _digest


def _versions():
    """Python's version and machine, and those of the compiler and numpy."""
    from importlib import metadata

    out = [sys.version, sys.platform, os.uname().machine if hasattr(os, "uname") else ""]
    for dist in ("numba", "llvmlite", "numpy"):
        try:
            out.append(f"{dist}=={metadata.version(dist)}")
        except metadata.PackageNotFoundError:
            out.append(f"{dist}: none")
    return out


def choose():
    """The cache folder: ``numba-<digest>`` in ``kernels/__pycache__``
    beside the sources if it can be written, else in ``meshwear-numba-<uid>``
    in the user's cache or the temporary folder (a system-wide or container
    install, a user without a writable HOME); folders of other digests there
    are removed. None when ``$NUMBA_CACHE_DIR`` is set (the user's choice
    stands) or no folder can be written."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return None
    user = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    uid = getattr(os, "getuid", lambda: 0)()
    name = f"numba-{digest()[:16]}"
    for base in (os.path.join(PACKAGE, "kernels", "__pycache__"),
                 os.path.join(user, f"meshwear-numba-{uid}"),
                 os.path.join(tempfile.gettempdir(), f"meshwear-numba-{uid}")):
        folder = os.path.join(base, name)
        if _writable(folder):
            _forget_others(base, folder)
            return folder
    return None


def _forget_others(base, keep):
    """Remove the cache folders of other digests under ``base`` (best effort)."""
    import shutil

    try:
        names = os.listdir(base)
    except OSError:
        return
    for name in names:
        path = os.path.join(base, name)
        if name.startswith("numba-") and path != keep:
            shutil.rmtree(path, ignore_errors=True)


def _writable(folder):
    """Whether a file can be made in ``folder`` (made if missing): tried, as
    permissions say nothing of a read-only mount."""
    try:
        os.makedirs(folder, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            return True
    except OSError:
        return False
