"""Input watchdog: decides whether the latest input may drive the device.

Pure: the caller passes the current time `now` (s, same clock as the stamps); nothing here reads a
clock. Any reason other than `Reason.OK` means "send zero force"; the watchdog recovers by itself
as soon as fresh, valid, in-order input arrives.
"""

import enum
import math

from force_renderer.errors import positive

__all__ = ['Reason', 'Watchdog']


class Reason(str, enum.Enum):
    """Why the force is what it is; the value is a short text for a throttled log line."""

    OK = 'ok'
    NO_STATE = 'no collision state received'
    NON_FINITE = 'NaN or Inf in the input'
    FUTURE = 'input stamped in the future'
    OUT_OF_ORDER = 'input stamp went backwards'
    STALE = 'input older than the timeout'
    NO_OBJECT = 'the scene has no object'
    REFUSED = 'the collision engine refused the pose'


class Watchdog:
    """Rejects stale, non-finite, out-of-order and future-stamped input.

    Parameters
    ----------
    timeout : float, s
        Largest accepted age `now - stamp`.
    max_lead : float, s
        Largest accepted lead `stamp - now` (clock skew between processes); more is "future".
    """

    def __init__(self, timeout: float = 0.010, *, max_lead: float = 0.010) -> None:
        self.timeout = positive(timeout, 'timeout')
        self.max_lead = positive(max_lead, 'max_lead')
        self._newest = -math.inf

    def reset(self) -> None:
        """Forget the newest stamp seen (e.g. after the clock source restarted)."""
        self._newest = -math.inf

    def check(self, stamp: float, now: float, finite: bool = True) -> Reason:
        """Judge one input.

        Parameters
        ----------
        stamp : float, s
            The input's stamp. A stamp equal to the newest one is the same message again: allowed.
        now : float, s
            Current time on the stamps' clock.
        finite : bool
            False when any number in the input is NaN or Inf.

        Returns
        -------
        Reason
            The first failed check in the order NON_FINITE, FUTURE, OUT_OF_ORDER, STALE; else OK.
            Only an OK or STALE input becomes the newest stamp.
        """
        if not (finite and math.isfinite(stamp) and math.isfinite(now)):
            return Reason.NON_FINITE
        if stamp - now > self.max_lead:
            return Reason.FUTURE
        if stamp < self._newest:
            return Reason.OUT_OF_ORDER
        self._newest = stamp
        if now - stamp > self.timeout:
            return Reason.STALE
        return Reason.OK
