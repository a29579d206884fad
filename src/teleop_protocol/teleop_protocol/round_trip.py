"""The round-trip delay of the link between the two sites, measured from echoed stamps.

The sites share no clock, so the delay is measured as NTP does: a stamp sent out and echoed back
with the far site's receive and reply stamps gives the round trip, free of the clocks' offset
(``echo_sample``); ``RoundTripEstimator`` keeps the latest few.
"""
from typing import NamedTuple

import numpy as np

from haptic_contract.checks import finite_number, whole_number

__all__ = ['EchoSample', 'RoundTripEstimator', 'echo_sample']


class EchoSample(NamedTuple):
    """One echoed stamp: the ``round_trip`` (s) and the far clock's ``offset`` (s) from ours."""

    round_trip: float
    offset: float


def echo_sample(sent: float, received: float, replied: float, returned: float) -> EchoSample:
    """Measure the link from one echo, as NTP does.

    Parameters
    ----------
    sent : float, s
        Our clock when the probe left.
    received, replied : float, s
        The far site's clock when the probe arrived there and when the echo left.
    returned : float, s
        Our clock when the echo came back.

    The round trip excludes the far site's time in between; the offset is exact when both
    directions take equally long, and off by half their difference otherwise.
    """
    return EchoSample(round_trip=(returned - sent) - (replied - received),
                      offset=((received - sent) + (replied - returned)) / 2.0)


class RoundTripEstimator:
    """The link's round trip and the clock offset from the latest ``window`` echoes.

    The round trip is their median (robust to a delayed echo); the offset is that of the echo
    with the shortest round trip, the one least skewed by queueing (NTP's clock filter).
    """

    def __init__(self, window: int = 8) -> None:
        self.window = whole_number(window, 'RoundTripEstimator.window')
        self._samples: list[EchoSample] = []

    def add(self, sent: float, received: float, replied: float, returned: float) -> EchoSample:
        """Take one echo's four stamps (see ``echo_sample``) and return its sample."""
        stamps = [finite_number(value, f'RoundTripEstimator.add {name}') for name, value in (
            ('sent', sent), ('received', received), ('replied', replied), ('returned', returned))]
        sample = echo_sample(*stamps)
        if sample.round_trip < 0.0 or replied < received:
            raise ValueError(f'RoundTripEstimator.add: inconsistent stamps {stamps} '
                             f'(round trip {sample.round_trip!r} s)')
        self._samples = [*self._samples, sample][-self.window:]
        return sample

    @property
    def round_trip(self) -> float | None:
        """The median round trip (s) of the window; None before the first echo."""
        if not self._samples:
            return None
        return float(np.median([sample.round_trip for sample in self._samples]))

    @property
    def offset(self) -> float | None:
        """The far clock minus ours (s), from the shortest round trip; None before any echo."""
        if not self._samples:
            return None
        return min(self._samples).offset
