"""An output folder held by one run at a time, and checked writable before
anything of an earlier run in it is replaced (docs/outputs.md)."""

import errno
import os
import shutil
from pathlib import Path

#: the lock's file in an output folder (hidden; part names cannot start with '.')
LOCK_NAME = ".meshwear.lock"


class FolderBusy(Exception):
    """Another run holds the output folder (one line: the folder, its pid)."""


class FolderLock:
    """An exclusive lock on ``out_dir`` (``flock`` on :data:`LOCK_NAME`,
    holding the owner's pid): the operating system releases it when the
    process ends, however it ends. Where ``fcntl`` is missing (Windows) the
    folder is not locked.

    Raises
    ------
    FolderBusy
        When another process (or another open recorder) holds it.
    """

    def __init__(self, out_dir):
        self.path = Path(out_dir) / LOCK_NAME
        self._fd = None
        try:
            import fcntl
        except ImportError:
            return
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            owner = os.read(fd, 32).decode(errors="replace").strip()
            os.close(fd)
            by = f" (pid {owner})" if owner.isdigit() else ""
            raise FolderBusy(f"{out_dir}: another meshwear run is writing there{by}; wait for "
                             "it to end or choose another output folder (-o)") from None
        os.ftruncate(fd, 0)
        os.write(fd, str(os.getpid()).encode())
        self._fd = fd

    def release(self):
        if self._fd is not None:
            os.close(self._fd)            # closing the descriptor drops the lock
            self._fd = None

    def __del__(self):
        self.release()


def check_writable(out_dir, files=(), folders=()):
    """Raise ``OSError`` naming the first of the ``files`` and ``folders``
    (names in ``out_dir``) that is there and cannot be written as such (no
    permission, or a folder where a file goes and the other way round), or
    the folder itself: a run refused for it has replaced nothing yet."""
    out_dir = Path(out_dir)
    places = ([(out_dir, True)] + [(out_dir / n, False) for n in files]
              + [(out_dir / n, True) for n in folders])
    for path, folder in places:
        if not path.exists():
            continue
        if path.is_dir() != folder:
            raise (NotADirectoryError(20, "Not a directory", str(path)) if folder else
                   IsADirectoryError(21, "Is a directory", str(path)))
        if not os.access(path, os.W_OK):
            raise PermissionError(13, "Permission denied", str(path))


#: free space (bytes) kept beyond a file's expected size
SPARE_BYTES = 4 * 2**20


def ensure_space(folder, size):
    """Raise ``OSError(ENOSPC)`` naming ``folder`` unless a file of about
    ``size`` bytes fits with :data:`SPARE_BYTES` to spare: checked before a
    frame is written, as VTK's writer may abort the process on a full disk
    instead of raising (the outputs written before stay valid)."""
    free = shutil.disk_usage(folder).free
    if free < size + SPARE_BYTES:
        raise OSError(errno.ENOSPC, f"No space left on device ({free / 2**20:.1f} MiB free, "
                                    f"a frame needs about {size / 2**20:.1f} MiB)", str(folder))
