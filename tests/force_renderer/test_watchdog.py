"""Watchdog: stale, non-finite, out-of-order and future input give a reason; it recovers."""

import math

import pytest

from force_renderer.errors import ForceRendererError
from force_renderer.watchdog import Reason, Watchdog


def test_fresh_in_order_input_is_ok_and_a_repeat_is_allowed():
    watchdog = Watchdog(0.010)
    assert watchdog.check(1.000, 1.0005) is Reason.OK
    assert watchdog.check(1.001, 1.0015) is Reason.OK
    assert watchdog.check(1.001, 1.0080) is Reason.OK   # same message, still within 10 ms


def test_stale_after_the_timeout_then_recovers():
    watchdog = Watchdog(0.010)
    assert watchdog.check(2.000, 2.0100) is Reason.OK
    assert watchdog.check(2.000, 2.0101) is Reason.STALE
    assert watchdog.check(2.020, 2.0201) is Reason.OK


@pytest.mark.parametrize('stamp, now', [(math.nan, 1.0), (math.inf, 1.0), (1.0, math.nan)])
def test_non_finite_stamp_or_clock(stamp, now):
    assert Watchdog().check(stamp, now) is Reason.NON_FINITE


def test_non_finite_payload_then_recovers():
    watchdog = Watchdog()
    assert watchdog.check(1.0, 1.0, finite=False) is Reason.NON_FINITE
    assert watchdog.check(1.001, 1.001) is Reason.OK


def test_out_of_order_is_rejected_without_moving_the_newest_stamp():
    watchdog = Watchdog(0.010)
    assert watchdog.check(5.000, 5.000) is Reason.OK
    assert watchdog.check(4.999, 5.001) is Reason.OUT_OF_ORDER
    assert watchdog.check(4.9995, 5.001) is Reason.OUT_OF_ORDER
    assert watchdog.check(5.001, 5.001) is Reason.OK


def test_far_future_is_rejected_and_not_remembered():
    watchdog = Watchdog(0.010, max_lead=0.002)
    assert watchdog.check(7.0021, 7.0) is Reason.FUTURE
    assert watchdog.check(7.0019, 7.0) is Reason.OK      # within the allowed clock skew
    assert watchdog.check(7.0025, 7.001) is Reason.OK   # the future stamp was not kept


def test_reset_forgets_the_newest_stamp():
    watchdog = Watchdog()
    watchdog.check(10.0, 10.0)
    watchdog.reset()
    assert watchdog.check(3.0, 3.0) is Reason.OK


def test_reasons_are_loggable_text():
    assert all(isinstance(reason.value, str) and reason.value for reason in Reason)
    assert Reason.STALE == 'input older than the timeout'


@pytest.mark.parametrize('timeout, max_lead, name', [(0.0, 0.01, 'timeout'),
                                                     (math.nan, 0.01, 'timeout'),
                                                     (0.01, -1.0, 'max_lead')])
def test_bad_settings_name_the_argument(timeout, max_lead, name):
    with pytest.raises(ForceRendererError, match=name):
        Watchdog(timeout, max_lead=max_lead)
