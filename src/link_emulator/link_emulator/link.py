"""An emulated network link between the two sites.

Why: the operator and the patient are far apart, and every bilateral scheme must be judged at
the delays of real links (23–30 ms for 5G over 2,600 km, 100–370 ms over the internet, over
500 ms by satellite). The kernel here has no netem qdisc, so the link is emulated in user space:
the site gateway hands each message to ``EmulatedLink.send`` and relays what ``deliver``
returns. It is pure (times are arguments, no clock is read), so a run is reproducible.

Each message is lost with probability ``loss``, else it arrives after the one-way delay plus
Gaussian jitter, clipped at zero. A message sent ``reliable`` (the hold, the re-engage: what
the transport must deliver) is never lost: each loss drawn for it costs a retransmission, one
round trip (twice the delay) later, as a reliable protocol over a lossy path recovers it. The
delay is ``delay``, or read from a ``DelayTrace`` (a CSV of measured delays) at the message's
send time. Without ``reorder`` a message never overtakes an earlier one (one ordered path: a late
message holds back those behind it); with it, each arrives at its own time. One seed fixes
every draw. The round trip over it is measured by the sites themselves
(``teleop_protocol.round_trip``).
"""

import csv
from dataclasses import dataclass
import heapq
import itertools
import math
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from haptic_contract.checks import finite_number, whole_number

__all__ = ['delay_spread', 'DelayTrace', 'Delivery', 'EmulatedLink', 'LinkConfig',
           'silence_timeout']

GAP_DEVIATIONS = 5.0  # jitter deviations a watchdog waits past its own timeout


def delay_spread(jitter: float, trace: 'DelayTrace | None' = None) -> float:
    """Return how far a link's one-way delays spread (s, one SD): its jitter and a trace's own.

    Why: a measured link's delay rises and falls, and a rise of d leaves it silent for d (a
    message never overtakes another) then delivers a backlog d late; a fall delivers messages
    early. The watchdogs and the admission must wait that out as they wait out jitter.
    """
    own = 0.0 if trace is None else float(np.std(trace.delays))
    return math.hypot(jitter, own)


def silence_timeout(timeout: float, jitter: float) -> float:
    """Return a watchdog's timeout (s) on a link whose delays scatter by ``jitter`` (s, one SD).

    Why: without reordering, a message held back by its jitter holds back every one behind it,
    so a link with a 100 ms deviation (20 % of 500 ms) is silent for 200-300 ms now and then. A
    100 ms watchdog then reads each such gap as a dead link: the robot held and retracted, the
    operator's model dropped, over and over (the scan's lockstep at 500 ms: 62 % oscillation,
    97 % transparency error; with this, 0.5 % and 2.8 %). ``GAP_DEVIATIONS`` deviations more.
    """
    return timeout + GAP_DEVIATIONS * jitter


@dataclass(frozen=True)
class LinkConfig:
    """Parameters of the emulated link, one direction.

    Parameters
    ----------
    delay : float, s
        One-way delay (ignored when a ``DelayTrace`` is given).
    jitter : float, s
        Standard deviation of the Gaussian jitter added to each message's delay.
    loss : float
        Probability that a message is lost, in [0, 1).
    reorder : bool
        Whether a message may overtake an earlier one.
    seed : int
    """

    delay: float = 0.0
    jitter: float = 0.0
    loss: float = 0.0
    reorder: bool = False
    seed: int = 0

    def __post_init__(self):
        finite_number(self.delay, 'LinkConfig.delay', minimum=0.0)
        finite_number(self.jitter, 'LinkConfig.jitter', minimum=0.0)
        if not 0.0 <= self.loss < 1.0:
            raise ValueError(f'LinkConfig.loss must be in [0, 1), got {self.loss!r}')
        if not isinstance(self.reorder, bool):
            raise ValueError(f'LinkConfig.reorder must be true or false, got {self.reorder!r}')
        whole_number(self.seed, 'LinkConfig.seed', minimum=0)


class DelayTrace:
    """One-way delays measured over time, replayed: the latest sample at or before a time holds.

    Parameters
    ----------
    times : (n,) float, s
        Strictly increasing, from the trace's start.
    delays : (n,) float, s
        >= 0.
    """

    def __init__(self, times, delays) -> None:
        times = np.asarray(times, dtype=np.float64)
        delays = np.asarray(delays, dtype=np.float64)
        if times.ndim != 1 or times.shape != delays.shape or times.size == 0:
            raise ValueError(f'DelayTrace needs as many times as delays, at least one; got '
                             f'shapes {times.shape} and {delays.shape}')
        if not (np.all(np.isfinite(times)) and np.all(np.isfinite(delays))):
            raise ValueError('DelayTrace times and delays must be finite')
        if np.any(np.diff(times) <= 0.0) or np.any(delays < 0.0):
            raise ValueError('DelayTrace times must increase strictly and delays be >= 0 s')
        self.times, self.delays = times, delays

    @classmethod
    def from_csv(cls, path) -> 'DelayTrace':
        """Read a CSV with the header ``time,delay`` (both in s), one sample a row."""
        path = Path(path)
        with path.open(newline='', encoding='utf-8') as file:
            rows = list(csv.reader(file))
        if not rows or [cell.strip() for cell in rows[0]] != ['time', 'delay']:
            raise ValueError(f'{path}: the first row must be the header "time,delay"')
        try:
            samples = np.array([[float(time), float(delay)] for time, delay in rows[1:]],
                               dtype=np.float64).reshape(-1, 2)
        except ValueError as error:
            raise ValueError(f'{path}: every row must be two numbers, time and delay: '
                             f'{error}') from None
        try:
            return cls(samples[:, 0], samples[:, 1])
        except ValueError as error:
            raise ValueError(f'{path}: {error}') from None

    def to_csv(self, path) -> None:
        """Write the trace as ``from_csv`` reads it."""
        with Path(path).open('w', newline='', encoding='utf-8') as file:
            writer = csv.writer(file)
            writer.writerow(['time', 'delay'])
            writer.writerows(zip(self.times.tolist(), self.delays.tolist()))

    def after(self, start: float, length: float = math.inf) -> 'DelayTrace':
        """Return ``length`` s of the trace from ``start`` (s), its time 0 there.

        What a run begun ``start`` s into the measured link replays.
        """
        start = finite_number(start, 'DelayTrace.after start', minimum=0.0)
        if start > self.times[-1]:
            raise ValueError(f'DelayTrace.after: {start!r} s is past the last sample '
                             f'({self.times[-1]!r} s)')
        if not length > 0.0:
            raise ValueError(f'DelayTrace.after: length must be > 0 s, got {length!r}')
        first = max(int(np.searchsorted(self.times, start, side='right')) - 1, 0)
        stop = int(np.searchsorted(self.times, start + length, side='left'))
        times = np.maximum(self.times[first:stop] - start, 0.0)
        return DelayTrace(times, self.delays[first:stop])

    def delay_at(self, time: float) -> float:
        """Return the delay (s) of the latest sample at or before ``time`` (s), or the first."""
        index = max(int(np.searchsorted(self.times, time, side='right')) - 1, 0)
        return float(self.delays[index])


class Delivery(NamedTuple):
    """A message out of the link: when it was sent and arrived (s), and what it carries."""

    sent: float
    arrived: float
    payload: Any


class EmulatedLink:
    """One direction of a delayed, jittery, lossy link: messages in, messages due out.

    Parameters
    ----------
    config : LinkConfig
    trace : DelayTrace or None
        Replaces ``config.delay``; its time 0 is the first message's send time.
    """

    def __init__(self, config: LinkConfig = LinkConfig(), *,
                 trace: DelayTrace | None = None) -> None:
        self.config = config
        self._trace = trace
        self._rng = np.random.default_rng(config.seed)
        self._queue: list = []  # heap of (arrival, order, sent, payload)
        self._order = itertools.count()  # ties arrive in send order
        self._first_sent: float | None = None
        self._last_arrival = -math.inf
        self._last_sent = -math.inf
        self.sent = self.lost = self.retransmitted = 0

    def send(self, time: float, payload, *, reliable: bool = False) -> bool:
        """Put ``payload`` on the link at ``time`` (s); return False if it is lost.

        ``reliable``: it is never lost; each loss drawn delays it by a retransmission.
        """
        time = finite_number(time, 'EmulatedLink.send time')
        if time < self._last_sent:
            raise ValueError(f'EmulatedLink.send: time {time!r} s is before the last send '
                             f'({self._last_sent!r} s); the clock must not go back')
        self._last_sent = time
        if self._first_sent is None:
            self._first_sent = time
        self.sent += 1
        lost, jitter = self._rng.random() < self.config.loss, self._rng.standard_normal()
        delay, resent = self._delay(time), 0.0
        while lost and reliable:
            self.retransmitted += 1
            resent += 2.0 * delay
            lost = self._rng.random() < self.config.loss
        if lost:
            self.lost += 1
            return False
        arrival = time + resent + max(0.0, delay + self.config.jitter * jitter)
        if not self.config.reorder:
            arrival = self._last_arrival = max(arrival, self._last_arrival)
        heapq.heappush(self._queue, (arrival, next(self._order), time, payload))
        return True

    def deliver(self, now: float) -> list[Delivery]:
        """Return the messages that have arrived by ``now`` (s), in their order of arrival."""
        due = []
        while self._queue and self._queue[0][0] <= now:
            arrival, _, sent, payload = heapq.heappop(self._queue)
            due.append(Delivery(sent, arrival, payload))
        return due

    @property
    def next_arrival(self) -> float | None:
        """When (s) the next message in flight arrives, or None when none is."""
        return self._queue[0][0] if self._queue else None

    def _delay(self, time: float) -> float:
        if self._trace is None:
            return self.config.delay
        return self._trace.delay_at(time - self._first_sent)
