"""A foreign routine run under a wall-clock limit, in a forked child process.

Why a process: SLICOT's AB13MD (the mixed-µ upper bound :func:`~lmi_suspension.mu.mussv`
takes by default) has loops without an iteration bound, its Osborne balancing and its
barrier iteration.  On the seat's µ controller's set loop, 104 calls of one grid took
118.9 s: two calls on one matrix (a split point below the grid, ‖M‖ = 35) took 63 s and
46 s, two on another 4.1 s each, the other 100 calls 6–130 ms; the matrix at 1.585e-3
rad/s, warm-started from the neighbouring frequency, did not return in 300 s
(2026-11-27).  A Fortran loop cannot be interrupted from Python, so the call runs in a
child process that is killed when the limit passes, and the caller falls back to a
route that has a bound.

The child is forked on the first call (and again after a call it had to stop) and
serves every later call through a pipe until :meth:`TimeLimited.close`, which kills it:
it holds no state, and a call interrupted in the parent may still be running in it.
Forking this package's process takes about 22 ms (183 MB resident, this machine), a
call through the pipe 0.7 ms more than in-process.  Where ``os.fork`` does not exist
(Windows), the routine runs in-process, without a limit.
"""

from __future__ import annotations

import ctypes
import logging
import os
import signal
import sys
import warnings
from multiprocessing import Pipe

__all__ = ["TimeLimited"]

logger = logging.getLogger(__name__)


class TimeLimited:
    """Call ``fn(*args)`` in a forked child process, at most ``seconds`` per call.

    A call past the limit kills the child and raises :class:`TimeoutError`; the next
    call forks a new one.  An exception inside ``fn`` is raised in the caller as
    :class:`RuntimeError` naming it; a child that dies raises :class:`ChildProcessError`.
    Arguments and results travel by pickle.  Use it as a context manager, so that the
    child ends with the work that needed it.

    Parameters
    ----------
    fn : callable
        The routine; it must be reachable in the child, which a fork guarantees.
    seconds : float
        Wall-clock limit of one call, > 0.

    Examples
    --------
    >>> from lmi_suspension.mu.timelimit import TimeLimited
    >>> with TimeLimited(divmod, seconds=5.0) as call:
    ...     call(7, 2)
    (3, 1)
    """

    def __init__(self, fn, seconds: float):
        if not seconds > 0:
            raise ValueError(f"seconds must be > 0, got {seconds!r}")
        self.fn = fn
        self.seconds = float(seconds)
        self._pid = None
        self._conn = None
        self._busy = False      # a call was sent and its reply not read (interrupted)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __call__(self, *args):
        if not hasattr(os, "fork"):
            return self.fn(*args)
        if self._busy:          # the last call was interrupted: its reply would be read
            self._kill()
        if self._pid is None:
            self._start()
        try:
            self._busy = True
            self._conn.send(args)
            ready = self._conn.poll(self.seconds)
        except (BrokenPipeError, EOFError, OSError) as exc:
            self._kill()
            raise ChildProcessError(f"the child running {self._name} died: {exc}") from None
        if not ready:
            logger.debug("%s: killing child %d after %g s", self._name, self._pid, self.seconds)
            self._kill()
            raise TimeoutError(f"{self._name} did not return within {self.seconds:g} s")
        try:
            status, value = self._conn.recv()
            self._busy = False
        except (EOFError, OSError) as exc:
            self._kill()
            raise ChildProcessError(f"the child running {self._name} died: {exc}") from None
        if status == "error":
            raise RuntimeError(f"{self._name} raised {value}")
        return value

    def close(self):
        """End the child (if any); the object can be called again afterwards.

        The child is killed, not asked to stop: a call interrupted in the parent (by
        an exception or Ctrl-C) may still be running in it, and a child forked by
        another ``TimeLimited`` holds a copy of this pipe, so that it never closes."""
        if self._pid is not None:
            self._kill()

    @property
    def _name(self):
        return getattr(self.fn, "__name__", repr(self.fn))

    def _start(self):
        parent, child = Pipe()
        try:
            with warnings.catch_warnings():
                # Python 3.12+ warns on every fork of a process with threads (here
                # OpenBLAS's pool); the child only runs ``fn``, already imported, and the
                # C libraries it calls into (glibc's malloc, OpenBLAS) reset their locks
                # at fork
                warnings.filterwarnings("ignore", message=r".*fork\(\) may lead to deadlocks",
                                        category=DeprecationWarning)
                pid = os.fork()
        except OSError:
            parent.close()
            child.close()
            raise
        if pid == 0:                # the child: serve calls until the pipe closes
            code = 1
            try:
                parent.close()
                _orphan_proof()
                _serve(self.fn, child)
                code = 0
            finally:
                os._exit(code)      # never run the parent's cleanup or atexit code
        child.close()
        self._pid, self._conn, self._busy = pid, parent, False

    def _kill(self):
        try:
            os.kill(self._pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        try:
            os.waitpid(self._pid, 0)
        except ChildProcessError:
            pass
        self._conn.close()
        self._pid = self._conn = None
        self._busy = False


def _orphan_proof():
    """In the child: Ctrl-C is the parent's to handle, and on Linux the child dies with
    its parent (a parent killed during a call would otherwise leave it spinning)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if sys.platform.startswith("linux"):
        try:
            ctypes.CDLL(None).prctl(1, signal.SIGKILL)      # PR_SET_PDEATHSIG
        except (OSError, AttributeError):
            pass


def _serve(fn, conn):
    while True:
        try:
            args = conn.recv()
        except (EOFError, OSError):
            return
        try:
            conn.send(("ok", fn(*args)))
        except BaseException as exc:        # reported to the caller, which decides
            conn.send(("error", repr(exc)))
