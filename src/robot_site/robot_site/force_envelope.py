"""The clinical force envelope at the patient: how hard, how fast, and when to stop.

Why: a bound on the force alone lets an operator who jabs reach it in one control tick, and
nothing stops a force that gets past it (an impact on a stiff spot, a sensor-side surprise).
Clinical robots bound more than the force (issue 28):

- the **working limit** (``PatientSafety``'s spring bound) stays;
- a **rate of rise**: in contact, the robot's spring may grow by at most ``rise_rate`` N/s from
  what it commanded the tick before, so a jab reaches the patient as a ramp;
- a **ramp at first contact**: for ``contact_ramp`` s after the probe touches, the spring is held
  under a line from ``contact_force`` up to the working limit: an approach the robot lagged
  behind does not land with the whole lag as force (the target is drawn back to the TCP at the
  touch, which only ever lowers the force). Contact ends after ``contact_break`` s below
  ``contact_force`` (a sweep's flicker, a probe held on the skin after a retraction, are not new
  contacts);
- a **hard stop** above the working limit: a measured force at or above ``hard_stop`` latches;
  the robot then holds and retracts (``PatientSafety``) and follows the operator again only
  after a deliberate ``re_engage``, once the probe has let go.

The rate and the ramp act on the commanded spring, the force the robot is asked to press with,
by keeping the target within reach of the TCP (``toward_within``): moved from the last target
toward the operator's only as far as the reach allows, so it never moves faster than the
operator's does (a target dragged along the reach's sphere would follow the TCP instead);
the patient's F/T sensor is what the tests measure them on. Out of contact nothing is bounded
but the working limit: the spring is what moves the robot through free space.
"""
from dataclasses import dataclass
import math

import numpy as np

from haptic_contract.checks import finite_number

__all__ = ['EnvelopeConfig', 'ForceEnvelope', 'toward_within']


@dataclass(frozen=True)
class EnvelopeConfig:
    """Parameters of the force envelope (sources in ``config/robot_site.yaml``).

    Parameters
    ----------
    hard_stop : float, N
        A measured force at or above this stops the robot until re-engaged (inf: never).
    rise_rate : float, N/s
        In contact, how fast the commanded spring may grow (inf: at once).
    contact_ramp : float, s
        How long after the first touch the spring stays under the ramp (0: no ramp).
    contact_force : float, N
        A measured force above this is contact.
    contact_break : float, s
        Below ``contact_force`` this long, the contact has ended.
    """

    hard_stop: float = 30.0
    rise_rate: float = 40.0
    contact_ramp: float = 1.0
    contact_force: float = 0.5
    contact_break: float = 0.2

    def __post_init__(self):
        for name in ('hard_stop', 'rise_rate'):
            value = getattr(self, name)
            if not (value > 0.0):  # NaN too
                raise ValueError(f'EnvelopeConfig.{name} must be > 0 (inf: off), got {value!r}')
        for name in ('contact_ramp', 'contact_force', 'contact_break'):
            finite_number(getattr(self, name), f'EnvelopeConfig.{name}', minimum=0.0)


class ForceEnvelope:
    """The envelope's state, tick by tick: the contact's start, the last spring, the latch.

    Parameters
    ----------
    config : EnvelopeConfig
    working_limit : float, N
        The largest spring force (``PatientSafety``'s bound).
    """

    def __init__(self, config: EnvelopeConfig, working_limit: float) -> None:
        if config.hard_stop <= working_limit:
            raise ValueError(f'EnvelopeConfig.hard_stop {config.hard_stop} N must lie above the '
                             f'working limit {working_limit} N')
        self.config = config
        self.working_limit = working_limit
        self.stopped = False
        self._touched = -math.inf  # [s] when this contact began (-inf: none)
        self._released = -math.inf  # [s] when the force last fell below contact (-inf: pressed)
        self._spring = 0.0  # [N] the spring commanded the tick before

    def trip(self, measured: float) -> bool:
        """Latch the hard stop if the measured force (N) reached it; return whether stopped."""
        self.stopped = self.stopped or measured >= self.config.hard_stop
        return self.stopped

    def re_engage(self, measured: float) -> bool:
        """Lift the hard stop once the probe has let go (``measured`` N at most the contact).

        Return whether the robot follows again.
        """
        if self.stopped and measured <= self.config.contact_force:
            self.stopped = False
            self._touched = -math.inf
        return not self.stopped

    def allowed(self, now: float, elapsed: float, measured: float) -> float:
        """Return the largest spring force (N) to command now, ``elapsed`` s after the last."""
        config = self.config
        if measured > config.contact_force:
            self._released = -math.inf
            if self._touched == -math.inf:
                self._touched = now
        elif self._touched > -math.inf:
            self._released = now if self._released == -math.inf else self._released
            if now - self._released >= config.contact_break:
                self._touched = -math.inf
        if self._touched == -math.inf:
            return self.working_limit
        start = min(config.contact_force, self.working_limit)
        ramp = (self.working_limit if config.contact_ramp == 0.0 else start
                + (self.working_limit - start) * (now - self._touched) / config.contact_ramp)
        return min(self.working_limit, ramp, self._spring + config.rise_rate * elapsed)

    def commanded(self, spring: float) -> None:
        """Note the spring force (N) commanded this tick."""
        self._spring = spring


def toward_within(previous: np.ndarray, target: np.ndarray, tcp: np.ndarray,
                  reach: float) -> np.ndarray:
    """Return ``target``, or as far toward it from ``previous`` as ``reach`` of ``tcp`` allows.

    All m. When ``previous`` is out of reach too, ``target`` drawn toward ``tcp``.
    """
    offset = target - tcp
    if float(offset @ offset) <= reach * reach:
        return target
    start = previous - tcp
    outside = float(start @ start) - reach * reach
    if outside > 0.0:
        return tcp + offset * (reach / math.sqrt(float(offset @ offset)))
    step = target - previous
    a, b = float(step @ step), float(start @ step)
    return previous + step * ((-b + math.sqrt(b * b - a * outside)) / a)
