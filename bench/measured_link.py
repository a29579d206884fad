"""The measured intercontinental link the telerobotic scan is replayed over (issue 28).

Echo round trips between Argentina and Málaga, 2014 (``delay_traces/argentina_malaga_2014``,
its README for the source and licence): as one-way delays the emulated link replays
(``link_emulator.link.DelayTrace``). The file has no timestamps; an echo's round trips follow
each other back to back, so sample k is sent at the sum of the round trips before it, and each
way takes half its round trip.
"""

from pathlib import Path

import numpy as np

from link_emulator.link import DelayTrace

__all__ = ['ECHO_ROUND_TRIPS', 'echo_delays']

ECHO_ROUND_TRIPS = (Path(__file__).resolve().parent
                    / 'delay_traces/argentina_malaga_2014/tyrell_roundtrip023.csv')


def echo_delays(path: Path = ECHO_ROUND_TRIPS) -> DelayTrace:
    """Return the one-way delays (s) of a file of echo round trips (ms, one a line)."""
    try:
        round_trips = np.loadtxt(path, dtype=np.float64, ndmin=1) / 1e3
    except ValueError as error:
        raise ValueError(f'{path}: every line must be one round trip in ms: {error}') from None
    if round_trips.size == 0 or not np.all(np.isfinite(round_trips) & (round_trips > 0.0)):
        raise ValueError(f'{path}: round trips must be finite and > 0 ms, at least one')
    times = np.concatenate(([0.0], np.cumsum(round_trips)[:-1]))
    return DelayTrace(times, round_trips / 2.0)
