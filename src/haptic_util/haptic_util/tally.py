"""Repeated events (a refused input, a zeroed force) counted per tick, logged once a period.

Why not a throttled log call on the error path: rclpy's logger inspects the caller's frame on
every call, before the throttle drops it, which cost 13 % of a node on a stream of stale inputs.
Overload makes inputs stale, and stale inputs then made more load. Counting costs a dictionary
update; the node logs what is new from its 1 Hz report.
"""
import collections
from typing import Callable

__all__ = ['Tally']


class Tally:
    """Counts per kind of event, with the latest detail of each.

    ``kind`` is a short fixed text (what happened); ``detail`` the particulars of the latest one
    (a stamp, a frame), kept for the log line only.
    """

    def __init__(self) -> None:
        self._counts = collections.Counter()
        self._logged = collections.Counter()
        self._details: dict = {}

    def add(self, kind: str, detail: str = '') -> None:
        self._counts[kind] += 1
        if detail:
            self._details[kind] = detail

    @property
    def counts(self) -> dict:
        """Counts per kind, over the whole session."""
        return dict(self._counts)

    def total(self) -> int:
        return sum(self._counts.values())

    def log_new(self, log: Callable[[str], None]) -> None:
        """Call ``log`` with one line for the events since the last call, if there were any."""
        new = self._counts - self._logged
        if not new:
            return
        parts = []
        for kind, count in new.items():
            detail = self._details.get(kind)
            parts.append(f'{count} x {kind}' + (f' (latest: {detail})' if detail else ''))
        log('; '.join(parts))
        self._logged = self._counts.copy()
