"""Velocity from stamped positions: exact on lines, indifferent to jitter and bad stamps."""

from fuzzing import examples
from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

from force_renderer.errors import ForceRendererError
from force_renderer.velocity import VelocityEstimator

VELOCITY = np.array([0.12, -0.05, 0.3])
START = np.array([0.01, 0.02, -0.03])


@settings(max_examples=examples(50), deadline=None)
@given(st.lists(st.floats(0.001, 0.005), min_size=3, max_size=30), st.floats(0.0, 1.8e9))
def test_exact_on_straight_motion_with_jittered_epoch_stamps(periods, epoch):
    estimator = VelocityEstimator(0.005)
    stamps = epoch + np.concatenate([[0.0], np.cumsum(periods)])
    for stamp in stamps:
        estimate = estimator.update(stamp, START + VELOCITY * (stamp - epoch))
    # Positions follow the stamps as stored, so only the estimator's own arithmetic can err.
    np.testing.assert_allclose(estimate, VELOCITY, rtol=1e-7)


def test_least_squares_slope_of_noisy_samples():
    stamps = np.array([0.0, 0.001, 0.002, 0.003, 0.004])
    noise = np.array([0.0, 1e-5, -1e-5, 1e-5, 0.0])
    heights = 0.1 * stamps + noise
    estimator = VelocityEstimator(0.005)
    for stamp, height in zip(stamps, heights):
        estimate = estimator.update(stamp, [0.0, 0.0, height])
    slope = np.polyfit(stamps, heights, 1)[0]
    assert estimate[2] == pytest.approx(slope, rel=1e-9)


def test_duplicate_out_of_order_and_nan_samples_are_ignored():
    estimator = VelocityEstimator(0.005)
    estimator.update(0.000, [0.0, 0.0, 0.0])
    expected = estimator.update(0.001, [0.001, 0.0, 0.0])
    np.testing.assert_allclose(expected, [1.0, 0.0, 0.0])
    for stamp, position in [(0.001, [5.0, 5.0, 5.0]), (0.0005, [9.0, 0.0, 0.0]),
                            (0.002, [np.nan, 0.0, 0.0]), (np.nan, [0.002, 0.0, 0.0])]:
        np.testing.assert_array_equal(estimator.update(stamp, position), expected)
    np.testing.assert_allclose(estimator.update(0.002, [0.002, 0.0, 0.0]), [1.0, 0.0, 0.0])


def test_old_samples_leave_the_window_but_two_always_remain():
    estimator = VelocityEstimator(0.002)
    estimator.update(0.000, [0.0, 0.0, 0.0])
    estimator.update(0.001, [0.0, 0.0, 0.0])
    estimator.update(0.002, [0.0, 0.0, 0.0])
    np.testing.assert_allclose(estimator.update(0.010, [0.0, 0.0, 0.008]), [0.0, 0.0, 1.0])


def test_zero_until_two_samples_and_after_reset():
    estimator = VelocityEstimator()
    np.testing.assert_array_equal(estimator.update(1.0, [1.0, 2.0, 3.0]), np.zeros(3))
    estimator.update(1.001, [1.001, 2.0, 3.0])
    estimator.reset()
    np.testing.assert_array_equal(estimator.velocity, np.zeros(3))
    np.testing.assert_array_equal(estimator.update(1.002, [7.0, 2.0, 3.0]), np.zeros(3))


@pytest.mark.parametrize('window', [0.0, -0.001, np.inf])
def test_bad_window_is_rejected(window):
    with pytest.raises(ForceRendererError, match='window'):
        VelocityEstimator(window)


def test_samples_added_unread_give_the_estimate_read_at_each_sample():
    # The loop adds a sample every tick and asks only when no twist came.
    every, lazy = VelocityEstimator(0.003), VelocityEstimator(0.003)
    rng = np.random.default_rng(7)
    stamp = 0.0
    for k in range(40):
        stamp += rng.uniform(0.0005, 0.0015)
        position = tuple(rng.normal(size=3).tolist())
        expected = every.update_components(stamp, position)
        lazy.add(stamp, position)
        if k % 7 == 0:
            assert lazy.velocity_components() == expected
    assert lazy.velocity_components() == expected
