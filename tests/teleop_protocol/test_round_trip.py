"""The round trip and the far clock's offset measured by echoes, over the emulated link too."""
import math

import pytest

from link_emulator.link import EmulatedLink, LinkConfig
from teleop_protocol.round_trip import echo_sample, RoundTripEstimator


def test_one_echo_gives_the_round_trip_and_offset_in_closed_form():
    # Out 30 ms, 5 ms at the far site, back 50 ms; the far clock is 100 s ahead.
    sample = echo_sample(sent=1.0, received=101.03, replied=101.035, returned=1.085)
    assert sample.round_trip == pytest.approx(0.08)
    assert sample.offset == pytest.approx(100.0 - (0.05 - 0.03) / 2)


def test_echoes_over_the_emulated_link_measure_its_round_trip_without_a_shared_clock():
    far_ahead = 3.7  # s: the far site's clock minus ours, unknown to the estimator
    out = EmulatedLink(LinkConfig(delay=0.05, jitter=0.005, reorder=True, seed=1))
    back = EmulatedLink(LinkConfig(delay=0.05, jitter=0.005, reorder=True, seed=2))
    estimator = RoundTripEstimator(window=16)
    assert estimator.round_trip is None and estimator.offset is None
    for k in range(400):  # true time in ms: a probe every 10 ms, the far site answers in 1 ms
        now = k * 1e-3
        if k % 10 == 0:
            out.send(now, now)
        for probe in out.deliver(now):
            back.send(now + 1e-3, (probe.payload, now + far_ahead, now + 1e-3 + far_ahead))
        for echo in back.deliver(now):
            estimator.add(*echo.payload, returned=now)
    assert estimator.round_trip == pytest.approx(0.1, abs=0.005)
    assert estimator.offset == pytest.approx(far_ahead, abs=0.005)


def test_inconsistent_echoes_are_refused():
    estimator = RoundTripEstimator()
    with pytest.raises(ValueError, match='inconsistent stamps'):
        estimator.add(sent=1.0, received=5.0, replied=5.5, returned=1.2)  # far site took longer
    with pytest.raises(ValueError, match='returned must be finite'):
        estimator.add(1.0, 2.0, 2.1, math.nan)
    with pytest.raises(ValueError, match='window must be an integer >= 1'):
        RoundTripEstimator(window=0)
