"""Book-keeping of the haptic loop as the driver sees it: round trips and force drop-outs.

Every wrench carries the stamp of the pose it answers, so the driver, which stamped that pose,
knows the loop's round trip exactly, on one clock, without any extra traffic: poses sent, poses
answered (a wrench with that pose's stamp), each answer's latency and arrival time. It also notes
each instant the applied force started (became non-zero) and stopped (dropped to zero, at the
watchdog deadline when the wrenches stopped), which is what the fail-safe tests measure.
"""
from array import array

import numpy as np

__all__ = ['LoopStats']


class LoopStats:
    """Poses sent and answered, and round-trip latencies [s].

    Its memory stays flat in sessions of hours: a pose waits for its answer at most
    ``ANSWER_WINDOW`` (a wrench later than that could not be applied anyway), and each answer
    keeps 16 bytes.
    """

    ANSWER_WINDOW_NS = 1_000_000_000

    def __init__(self) -> None:
        self._pending: dict = {}  # stamps of poses awaiting their wrench, oldest first
        self._poses = 0
        self._answers = 0
        self._latency_ns = array('q')
        self._arrival_ns = array('q')
        self._force_on_ns: list = []
        self._force_off_ns: list = []
        self._first_ns = None
        self._last_ns = None

    def sent(self, stamp_ns: int) -> None:
        pending = self._pending
        pending[stamp_ns] = None
        while (oldest := next(iter(pending))) < stamp_ns - self.ANSWER_WINDOW_NS:
            del pending[oldest]
        self._poses += 1
        if self._first_ns is None:
            self._first_ns = stamp_ns
        self._last_ns = stamp_ns

    def answered(self, stamp_ns: int, received_ns: int) -> None:
        """Record a wrench for the pose stamped ``stamp_ns``; others are not loop answers."""
        if self._pending.pop(stamp_ns, False) is None:
            self._answers += 1
            self._latency_ns.append(received_ns - stamp_ns)
            self._arrival_ns.append(received_ns)

    def force_on(self, instant_ns: int) -> None:
        """Note that the applied force became non-zero at ``instant_ns``."""
        self._force_on_ns.append(instant_ns)

    def force_off(self, instant_ns: int) -> None:
        """Note that the applied force dropped to zero at ``instant_ns``."""
        self._force_off_ns.append(instant_ns)

    @property
    def poses(self) -> int:
        return self._poses

    @property
    def answers(self) -> int:
        return self._answers

    @property
    def latencies(self) -> np.ndarray:
        """(n,) float, s: round trip of each answered pose, in arrival order."""
        return np.frombuffer(self._latency_ns, dtype=np.int64) * 1e-9

    @property
    def rate(self) -> float:
        """Achieved pose rate [Hz] over the poses sent so far."""
        if self.poses < 2:
            return 0.0
        return (self.poses - 1) / ((self._last_ns - self._first_ns) * 1e-9)

    def summary(self, last: int = 0) -> dict:
        """Rate, share answered, and latency percentiles (s), for logs and benchmarks.

        ``last`` > 0 takes the percentiles over the last answers only (a periodic report stays
        cheap however long the session); the counts are always the whole session's.
        """
        latency = self.latencies[-last:] if last else self.latencies
        percentiles = (np.percentile(latency, [50, 90, 99]) if latency.size
                       else np.full(3, np.nan))
        return {
            'poses': self.poses,
            'answers': self.answers,
            'answered_percent': 100.0 * self.answers / self.poses if self.poses else 0.0,
            'rate_hz': self.rate,
            'latency_p50_s': float(percentiles[0]),
            'latency_p90_s': float(percentiles[1]),
            'latency_p99_s': float(percentiles[2]),
            'latency_max_s': float(latency.max()) if latency.size else float('nan'),
        }

    def save(self, path, **extra) -> None:
        """Write the raw latencies, the summary and ``extra`` figures to an .npz file."""
        np.savez(path, latencies=self.latencies,
                 arrival_ns=np.frombuffer(self._arrival_ns, dtype=np.int64),
                 force_on_ns=np.asarray(self._force_on_ns, dtype=np.int64),
                 force_off_ns=np.asarray(self._force_off_ns, dtype=np.int64),
                 **self.summary(), **extra)
