"""Which messages from the far site are taken: one session, in order, on time, at a sane rate.

Why: the far end of the link is a network peer, and anything on that network can publish. A
message is taken only if

- it belongs to the session being followed: the first one heard, until it has been silent for
  ``session_timeout`` (a second operator, or a stray process, is refused and named);
- it is newer than the last one taken, by sequence and by stamp (a repeat, or a message that
  lost a race on the link, is old news), and its sequence runs no further ahead than its stamp
  allows at ``max_rate`` (else one forged number, 2**63, would make every true one old);
- its stamp is on time. The sites share no clock, so how late a message is can only be judged
  against the link's own history: its lateness, arrival minus stamp (our clock minus theirs),
  is the clocks' offset plus its delay, and a low quantile of the lateness of the last
  ``history`` messages taken is the offset plus the link's best delay (the baseline). After a
  silence of ``max_age`` (a stalled link, when it resumes), a message later than the baseline
  by more than ``max_age`` is the backlog: executed, it would move the robot to where the
  operator was. While messages flow, a late one is still the newest there is, and is taken (a
  busy machine delays them all). One earlier than the baseline by more than ``max_lead`` carries
  a stamp from the future, at any time: taken, it would make every true message after it look
  old. Only messages taken make the baseline, so neither a backlog nor forged stamps move it,
  and it is a quantile, not the minimum, so a few forged stamps that pass do not either; it
  counts messages, not time, so a stall does not empty it. A link that really became slower
  (or a clock that stepped) shows as messages refused for ``relearn`` seconds with none taken
  between: the baseline is then learnt again from them;
- the session sends no faster than ``max_rate``: a flood is shed (a token bucket), not queued.

Without authentication (the two-sites transport's mutual TLS) a peer that reads the session's
messages can still forge them; what this stops is any other publisher, and any stamp, sequence
or rate out of the ordinary.
"""
import bisect
from collections import deque
from dataclasses import dataclass

from haptic_contract.checks import finite_number, whole_number
from haptic_contract.teleop import Refusal

__all__ = ['Admission', 'AdmissionConfig', 'Refusal']


@dataclass(frozen=True)
class AdmissionConfig:
    """Parameters of admission at one end of the link.

    Parameters
    ----------
    max_age : float, s
        How much later than the link's best delay a message may arrive after a silence this
        long.
    max_lead : float, s
        How much earlier than the link's best delay a stamp may say it was sent.
    session_timeout : float, s
        Silence of the followed session after which another may take over.
    max_rate : float, Hz
        Messages of the session taken per second at most, over bursts of ``max_rate · burst``.
    burst : float, s
    history : int
        Messages taken whose lateness makes the baseline.
    quantile : float
        The baseline's quantile of their lateness.
    relearn : float, s
        How long every message must be refused as late or early before the baseline is learnt
        again.
    """

    max_age: float = 0.1
    max_lead: float = 0.05
    session_timeout: float = 1.0
    max_rate: float = 2000.0
    burst: float = 0.05
    history: int = 5000
    quantile: float = 0.01
    relearn: float = 1.0

    def __post_init__(self):
        for name in ('max_age', 'max_lead', 'session_timeout', 'max_rate', 'burst', 'relearn'):
            finite_number(getattr(self, name), f'AdmissionConfig.{name}', minimum=0.0,
                          strict=True)
        whole_number(self.history, 'AdmissionConfig.history')
        finite_number(self.quantile, 'AdmissionConfig.quantile', minimum=0.0, maximum=1.0)


class Admission:
    """Admits the far site's messages one by one (see the module's docstring).

    Parameters
    ----------
    config : AdmissionConfig
    """

    def __init__(self, config: AdmissionConfig = AdmissionConfig()) -> None:
        self.config = config
        self._follow(0)  # 0: none followed yet

    def _follow(self, session: int) -> None:
        """Start following ``session``, from nothing known of it."""
        self.session = session
        self._last_heard = None  # [s] our clock, the followed session's newest message
        self._sequence = 0
        self._stamp = None
        self._arrivals = deque()  # the lateness of the messages taken, in arrival order
        self._sorted = []  # the same, sorted
        self._streak = None  # (first arrival, least lateness) of refusals since the last taken
        self._taken_at = None  # [s] our clock, when the last message was taken
        self._tokens = 0.0
        self._filled = None  # [s] when the bucket was last filled

    def stranger(self, now: float, session: int) -> Refusal | None:
        """Return why a message of ``session`` arriving at ``now`` is not followed, if it is not.

        The cheap first question, asked before anything else is read of a message: a flood of
        strangers is refused by this alone.
        """
        if session == 0:
            return Refusal('no session')
        if session != self.session and self._last_heard is not None and \
                now - self._last_heard <= self.config.session_timeout:
            return Refusal('another session', f'session {session:#x}, following '
                           f'{self.session:#x}')
        return None

    def admit(self, now: float, session: int, sequence: int, stamp: float) -> Refusal | None:
        """Return None if the message sent at ``stamp`` (s, their clock) is taken, or why not.

        ``now`` is our clock (s) at its arrival; ``session`` and ``sequence`` are its own.
        """
        refusal = self.stranger(now, session)
        if refusal is not None:
            return refusal
        if session != self.session:
            self._follow(session)
        if sequence <= self._sequence or (self._stamp is not None and stamp <= self._stamp):
            return Refusal('not newer than the last taken', f'sequence {sequence} stamped '
                           f'{stamp:.6f} s, after {self._sequence} stamped {self._stamp} s')
        if self._stamp is not None and sequence - self._sequence > \
                (stamp - self._stamp) * self.config.max_rate + self.config.max_rate * \
                self.config.burst:
            return Refusal('sequence ahead of its stamp', f'sequence {sequence} stamped '
                           f'{stamp:.6f} s, after {self._sequence} stamped {self._stamp:.6f} s')
        lateness = now - stamp
        self._last_heard = now
        refusal = self._timing(now, stamp, lateness)
        if refusal is not None:
            return refusal
        if not self._take_token(now):
            return Refusal('over the session\'s rate', f'above {self.config.max_rate:g} Hz')
        self._sequence, self._stamp, self._streak, self._taken_at = sequence, stamp, None, now
        self._remember(lateness)
        return None

    def _timing(self, now: float, stamp: float, lateness: float) -> Refusal | None:
        """Return why ``stamp`` is too old or too early for the link, or None."""
        baseline = self._baseline()
        if baseline is None:
            return None
        resuming = now - self._taken_at > self.config.max_age
        if resuming and lateness > baseline + self.config.max_age:
            refusal = Refusal('older than the link allows', f'stamp {stamp:.6f} s is '
                              f'{lateness - baseline:.3f} s late after a silence')
        elif lateness < baseline - self.config.max_lead:
            refusal = Refusal('stamped in the future', f'stamp {stamp:.6f} s is '
                              f'{baseline - lateness:.3f} s ahead of the link')
        else:
            return None
        first, least = self._streak or (now, lateness)
        self._streak = (first, min(least, lateness))
        if now - first < self.config.relearn:
            return refusal
        self._arrivals.clear()  # nothing but refusals for so long: the link has changed
        self._sorted.clear()
        self._remember(self._streak[1])
        self._streak = None
        return self._timing(now, stamp, lateness)

    def _baseline(self) -> float | None:
        """Return the quantile of recent lateness (s); None before any message."""
        if not self._sorted:
            return None
        return self._sorted[int(self.config.quantile * (len(self._sorted) - 1))]

    def _remember(self, lateness: float) -> None:
        self._arrivals.append(lateness)
        bisect.insort(self._sorted, lateness)
        if len(self._arrivals) > self.config.history:
            oldest = self._arrivals.popleft()
            del self._sorted[bisect.bisect_left(self._sorted, oldest)]

    def _take_token(self, now: float) -> bool:
        config = self.config
        capacity = config.max_rate * config.burst
        if self._filled is None:
            self._tokens = capacity
        else:
            self._tokens = min(capacity, self._tokens + (now - self._filled) * config.max_rate)
        self._filled = now
        if self._tokens < 1.0:
            return False
        self._tokens -= 1.0
        return True
