"""Say when a run compiles kernels, and how long it took.

A first run on an empty kernel cache (a fresh install, an upgrade, a
changed kernel) compiles the builds its scene needs before its first step:
seconds to half a minute with nothing on the screen. :class:`CompileNotice`
listens to numba's compile events and prints one line when the first
compile starts, and :meth:`CompileNotice.done` the time all of them took
(docs/performance.md, "The first run compiles"). Loads from the cache are
not compiles and print nothing.
"""

import sys
import time

#: the line printed when the first compile starts
STARTING = "compiling kernels for this scene (first run only) ..."


class CompileNotice:
    """A context: while it is open, the first compile prints :data:`STARTING`
    on ``stream``; ``seconds`` adds up the time spent compiling (the
    outermost compiles only: a kernel compiles the ones it calls)."""

    def __init__(self, stream=None):
        self.stream = sys.stderr if stream is None else stream
        self.seconds, self.count = 0.0, 0
        self._depth, self._start = 0, 0.0

    def __enter__(self):
        from numba.core import event

        notice = self

        class _Listener(event.Listener):
            def on_start(self, ev):
                notice._started()

            def on_end(self, ev):
                notice._ended()

        self._listener = _Listener()
        event.register("numba:compile", self._listener)
        return self

    def __exit__(self, *exc):
        from numba.core import event

        event.unregister("numba:compile", self._listener)
        return False

    def _started(self):
        if self._depth == 0:
            if self.count == 0:
                self.stream.write(STARTING + "\n")
                self.stream.flush()
            self._start = time.perf_counter()
        self._depth += 1

    def _ended(self):
        self._depth -= 1
        if self._depth == 0:
            self.seconds += time.perf_counter() - self._start
            self.count += 1

    def done(self):
        """The line that says how long compiling took ("" if nothing compiled)."""
        if not self.count:
            return ""
        return f"kernels compiled in {self.seconds:.1f} s (cached: the next runs skip this)"
