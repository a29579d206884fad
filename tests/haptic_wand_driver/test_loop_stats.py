"""The driver's loop record: counts, latencies, and flat memory in long sessions."""
import numpy as np
import pytest

from haptic_wand_driver.loop_stats import LoopStats

MS = 1_000_000


def test_counts_and_latencies_of_answered_poses(tmp_path):
    stats = LoopStats(record=tmp_path / 'record')
    for k in range(5):
        stats.sent(k * MS)
    stats.answered(1 * MS, 1 * MS + 400_000)
    stats.answered(3 * MS, 3 * MS + 900_000)
    stats.answered(3 * MS, 3 * MS + 950_000)  # a duplicate answers nothing
    stats.answered(7 * MS, 8 * MS)  # not a pose that was sent
    assert (stats.poses, stats.answers) == (5, 2)
    np.testing.assert_allclose(np.sort(stats.recent_latencies), [0.0004, 0.0009])
    summary = stats.summary()
    assert summary['answered_percent'] == pytest.approx(40.0)
    assert summary['rate_hz'] == pytest.approx(1000.0)
    assert summary['latency_max_s'] == pytest.approx(0.0009)


def test_the_report_takes_its_percentiles_over_the_recent_answers_only():
    stats = LoopStats()
    latencies = [5 * MS] * LoopStats.RECENT + [MS] * LoopStats.RECENT
    for k, latency in enumerate(latencies):
        stats.sent(k * MS)
        stats.answered(k * MS, k * MS + latency)
    summary = stats.summary()
    assert summary['latency_max_s'] == pytest.approx(0.001)
    assert summary['poses'] == summary['answers'] == 2 * LoopStats.RECENT


def test_the_full_record_keeps_every_answer(tmp_path):
    stats = LoopStats(record=tmp_path / 'record')
    count = 3 * LoopStats.CHUNK + 17  # spans several chunks written out and a partial one
    for k in range(count):
        stats.sent(k * MS)
        stats.answered(k * MS, k * MS + (k % 7 + 1) * 100_000)
    stats.save(tmp_path / 'stats.npz', published=count)
    saved = np.load(tmp_path / 'stats.npz')
    np.testing.assert_allclose(saved['latencies'], [(k % 7 + 1) * 1e-4 for k in range(count)])
    np.testing.assert_array_equal(saved['arrival_ns'],
                                  [k * MS + (k % 7 + 1) * 100_000 for k in range(count)])
    assert saved['latency_max_s'] == pytest.approx(7e-4)  # the whole session's, not the ring's
    assert int(saved['published']) == count


def test_saving_needs_a_record():
    with pytest.raises(ValueError, match='record'):
        LoopStats().save('stats.npz')


def test_memory_stays_flat_without_a_record():
    stats = LoopStats()
    for k in range(5 * LoopStats.RECENT):
        stats.sent(k * MS)
        stats.answered(k * MS, k * MS + 300_000)
    assert stats._recent.nbytes == 8 * LoopStats.RECENT
    assert len(stats._rows) == 0 and len(stats._pending) <= 1001


def test_holding_the_recent_latencies_does_not_block_new_answers():
    stats = LoopStats()
    stats.sent(0)
    held = stats.recent_latencies  # a caller keeps it while the loop goes on
    stats.sent(MS)
    stats.answered(MS, MS + 200_000)  # raised BufferError with a view of a growing buffer
    assert held.size == 0 and stats.answers == 1


def test_poses_wait_for_their_answer_one_second_at_most():
    stats = LoopStats()
    for k in range(5000):  # 5 s at 1 kHz
        stats.sent(k * MS)
    assert len(stats._pending) <= 1001
    stats.answered(0, 5000 * MS)  # 5 s late: no longer a loop answer
    stats.answered(4500 * MS, 4500 * MS + 300_000)
    assert stats.answers == 1 and stats.poses == 5000
