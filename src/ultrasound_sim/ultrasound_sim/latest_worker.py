"""A thread that works on the newest item only, beside the thread feeding it, at its own priority.

Why: a B-mode frame is milliseconds of compiled work. On the imager's executor thread it would
leave the TCP poses waiting as long, at every frame, and the next frame would start from one
that old. Here the executor only hands the newest pose over (``offer``) and goes on taking poses;
the compiled kernels release the GIL, so both go on together. The thread may yield the cores
(``on_start``: ``haptic_util.priority``) while the executor's keeps its priority. An item
offered while one still waits replaces it (the newest pose is the one to image), and is counted
in ``replaced``: when frames take longer than their period, frames are dropped, never queued.
"""

import threading
from typing import Callable

__all__ = ['LatestWorker']


class LatestWorker:
    """Runs ``job(item)`` in a thread of its own, on the newest item offered.

    Parameters
    ----------
    job : callable item -> None
    on_error : callable Exception -> None
        Told of an exception ``job`` raised; the thread goes on with the next item.
    on_start : callable () -> None
        Run first in the thread (to set its priority).
    """

    def __init__(self, job: Callable, *, on_error: Callable[[Exception], None],
                 on_start: Callable[[], None] = lambda: None,
                 name: str = 'latest_worker') -> None:
        self._job, self._on_error, self._on_start = job, on_error, on_start
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
        self._on_start()
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
