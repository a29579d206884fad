"""A thread that works on the newest item only, at a lower priority than the thread feeding it.

Why: a B-mode frame is milliseconds of compiled work. On a site's executor thread it would hold
that site's 1 kHz loop back as long, at every frame. Here the executor only hands the newest
pose over (``offer``) and goes on; the compiled kernels release the GIL, so the frame is made
beside the loop, on the other core or in the loop's idle time. When the cores are busy the
thread's added niceness lets the loop go first: a frame may come later, the loop does not. An
item offered while one still waits replaces it (the newest pose is the one to image), and is
counted in ``replaced``.
"""

import os
import threading
from typing import Callable

__all__ = ['LatestWorker']


def _lower_priority(niceness: int) -> None:
    """Add ``niceness`` to the calling thread's own (Linux sets it per thread)."""
    if niceness <= 0 or not hasattr(os, 'setpriority'):
        return
    thread = threading.get_native_id()
    try:
        os.setpriority(os.PRIO_PROCESS, thread,
                       os.getpriority(os.PRIO_PROCESS, thread) + niceness)
    except OSError:
        pass  # the thread keeps the process's priority; the frames still come


class LatestWorker:
    """Runs ``job(item)`` in a thread of its own, on the newest item offered.

    Parameters
    ----------
    job : callable item -> None
    on_error : callable Exception -> None
        Told of an exception ``job`` raised; the thread goes on with the next item.
    niceness : int
        Added to the thread's niceness (0: none).
    """

    def __init__(self, job: Callable, *, on_error: Callable[[Exception], None],
                 niceness: int = 0, name: str = 'latest_worker') -> None:
        self._job, self._on_error, self._niceness = job, on_error, niceness
        self._condition = threading.Condition()
        self._waiting = []  # at most one item
        self._closed = False
        self.replaced = 0
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

    def offer(self, item) -> None:
        """Hand ``item`` over; one still waiting is dropped for it."""
        with self._condition:
            self.replaced += len(self._waiting)
            self._waiting[:] = [item]
            self._condition.notify()

    def close(self, timeout: float = 1.0) -> bool:
        """Stop after the job in progress; return whether the thread ended within ``timeout`` s."""
        with self._condition:
            self._closed = True
            self._condition.notify()
        self._thread.join(timeout)
        return not self._thread.is_alive()

    def _run(self) -> None:
        _lower_priority(self._niceness)
        while True:
            with self._condition:
                while not self._waiting and not self._closed:
                    self._condition.wait()
                if self._closed:
                    return
                item = self._waiting.pop()
            try:
                self._job(item)
            except Exception as error:  # a bad frame must not end the imaging
                self._on_error(error)
