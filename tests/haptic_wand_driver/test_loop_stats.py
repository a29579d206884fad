"""The driver's loop record: counts, latencies, and flat memory in long sessions."""
import numpy as np
import pytest

from haptic_wand_driver.loop_stats import LoopStats

MS = 1_000_000


def test_counts_and_latencies_of_answered_poses():
    stats = LoopStats()
    for k in range(5):
        stats.sent(k * MS)
    stats.answered(1 * MS, 1 * MS + 400_000)
    stats.answered(3 * MS, 3 * MS + 900_000)
    stats.answered(3 * MS, 3 * MS + 950_000)  # a duplicate answers nothing
    stats.answered(7 * MS, 8 * MS)  # not a pose that was sent
    assert (stats.poses, stats.answers) == (5, 2)
    np.testing.assert_allclose(stats.latencies, [0.0004, 0.0009])
    summary = stats.summary()
    assert summary['answered_percent'] == pytest.approx(40.0)
    assert summary['rate_hz'] == pytest.approx(1000.0)
    assert summary['latency_max_s'] == pytest.approx(0.0009)


def test_a_report_can_take_its_percentiles_over_the_last_answers_only():
    stats = LoopStats()
    for k, latency in enumerate([5 * MS] * 10 + [MS] * 10):
        stats.sent(k * MS)
        stats.answered(k * MS, k * MS + latency)
    assert stats.summary(last=10)['latency_p99_s'] == pytest.approx(0.001)
    assert stats.summary()['latency_max_s'] == pytest.approx(0.005)
    assert stats.summary(last=10)['poses'] == 20


def test_poses_wait_for_their_answer_one_second_at_most():
    stats = LoopStats()
    for k in range(5000):  # 5 s at 1 kHz
        stats.sent(k * MS)
    assert len(stats._pending) <= 1001
    stats.answered(0, 5000 * MS)  # 5 s late: no longer a loop answer
    stats.answered(4500 * MS, 4500 * MS + 300_000)
    assert stats.answers == 1 and stats.poses == 5000
