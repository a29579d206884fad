"""Book-keeping of the haptic loop as the driver sees it: poses, answers, round trips.

Every wrench carries the stamp of the pose it answers, so the driver, which stamped that pose,
knows the loop's round trip exactly, on one clock, without any extra traffic: poses sent, poses
answered (a wrench with that pose's stamp), each answer's latency and arrival time. (When the
force on the hand started and stopped is the device's to say, not the driver's: ``force_edges``.)

A driver runs for days, so memory stays flat: the recent latencies live in a ring of
``RECENT`` entries (what the 1 Hz report takes its percentiles over, at a constant cost), and the
full record, when one is asked for, goes to a file in chunks as it is made.
"""
from array import array
import pathlib
from typing import Optional

import numpy as np

__all__ = ['LoopStats']


class LoopStats:
    """Poses sent and answered, and round-trip latencies [s].

    Parameters
    ----------
    record : path or None
        Where the full record (every answer) is spooled while the session runs; ``save`` turns
        it into an .npz. None keeps only counts and the recent ring.
    """

    ANSWER_WINDOW_NS = 1_000_000_000  # a wrench later than this could not be applied anyway
    RECENT = 10_000  # answers: about the last 10 s at 1 kHz
    CHUNK = 4096  # rows of the full record buffered before they are written out

    def __init__(self, record: Optional[pathlib.Path] = None) -> None:
        self._pending: dict = {}  # stamps of poses awaiting their wrench, oldest first
        self._poses = 0
        self._answers = 0
        self._recent = np.zeros(self.RECENT, dtype=np.int64)
        self._first_ns = None
        self._last_ns = None
        self._record_path = None if record is None else pathlib.Path(record)
        self._rows = array('q')  # (latency, arrival) pairs not yet written out
        if self._record_path is not None:
            self._record_path.write_bytes(b'')

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
            self._recent[self._answers % self.RECENT] = received_ns - stamp_ns
            self._answers += 1
            if self._record_path is not None:
                self._rows.extend((received_ns - stamp_ns, received_ns))
                if len(self._rows) >= 2 * self.CHUNK:
                    self._flush()

    def _flush(self) -> None:
        with self._record_path.open('ab') as stream:
            self._rows.tofile(stream)
        del self._rows[:]

    @property
    def poses(self) -> int:
        return self._poses

    @property
    def answers(self) -> int:
        return self._answers

    @property
    def recent_latencies(self) -> np.ndarray:
        """(n,) float, s: round trips of the last ``RECENT`` answers (in no order), a copy."""
        count = min(self._answers, self.RECENT)
        return self._recent[:count] * 1e-9

    @property
    def rate(self) -> float:
        """Achieved pose rate [Hz] over the poses sent so far."""
        if self.poses < 2:
            return 0.0
        return (self.poses - 1) / ((self._last_ns - self._first_ns) * 1e-9)

    def summary(self) -> dict:
        """Rate, share answered, and the recent answers' latency percentiles (s).

        The counts are the whole session's; the percentiles cover the last ``RECENT`` answers,
        so a periodic report costs the same however long the session.
        """
        return {
            'poses': self.poses,
            'answers': self.answers,
            'answered_percent': 100.0 * self.answers / self.poses if self.poses else 0.0,
            'rate_hz': self.rate,
            **_latency_figures(self.recent_latencies),
        }

    def save(self, path, **extra) -> None:
        """Write the full record, the summary and ``extra`` figures to an .npz file.

        Raises ValueError when the stats were made without a record.
        """
        if self._record_path is None:
            raise ValueError('LoopStats.save needs the full record: make it with record=path')
        self._flush()
        answers = np.fromfile(self._record_path, dtype=np.int64).reshape(-1, 2)
        latencies = answers[:, 0] * 1e-9
        whole_session = {**self.summary(), **_latency_figures(latencies)}
        np.savez(path, latencies=latencies, arrival_ns=answers[:, 1], **whole_session, **extra)


def _latency_figures(latency: np.ndarray) -> dict:
    """p50, p90, p99 and max of round trips (s); NaN when there are none."""
    percentiles = np.percentile(latency, [50, 90, 99]) if latency.size else np.full(3, np.nan)
    return {'latency_p50_s': float(percentiles[0]), 'latency_p90_s': float(percentiles[1]),
            'latency_p99_s': float(percentiles[2]),
            'latency_max_s': float(latency.max()) if latency.size else float('nan')}
