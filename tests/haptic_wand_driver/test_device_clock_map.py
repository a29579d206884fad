"""The device's clock mapped to ROS time across a step of the system clock."""
import numpy as np
import pytest

from haptic_wand_driver.device_clock_map import DeviceClockMap

EPOCH = 1_800_000_000.0  # [s] ROS time minus the device's clock before the step
STEP = 0.19  # [s] the system clock's step, as seen in a CI run


def test_each_instant_takes_the_offset_of_its_side_of_a_step():
    """1 kHz ticks; the system clock steps forward between two of them, at 2.5004 s."""
    clock_map = DeviceClockMap()
    for tick in range(5000):
        device_now = tick * 1e-3
        offset = EPOCH + (STEP if device_now > 2.5004 else 0.0)
        clock_map.observe(device_now, offset, lambda offset=offset: offset)
    edges = np.array([0.3, 2.4, 2.5011, 4.2])
    mapped = clock_map.to_ros_ns(edges)
    truth = np.round(1e9 * edges).astype(np.int64) + np.round(
        1e9 * (EPOCH + np.where(edges > 2.5004, STEP, 0.0))).astype(np.int64)
    assert clock_map.steps == 1
    np.testing.assert_array_equal(mapped, truth)
    once = np.round(1e9 * (edges + EPOCH + STEP)).astype(np.int64)  # one offset, read at the end
    assert np.all(np.abs(once - truth)[:2] > 0.18e9)  # the way it was: before the step, 0.19 s off


def test_an_instant_between_the_step_and_the_tick_that_saw_it_is_off_by_the_step_at_most():
    clock_map = DeviceClockMap()
    clock_map.observe(0.0, EPOCH, lambda: EPOCH)
    clock_map.observe(0.001, EPOCH + STEP, lambda: EPOCH + STEP)
    assert clock_map.to_ros_ns([0.0005])[0] == round(0.0005e9) + round(EPOCH * 1e9)


def test_a_delayed_reading_is_estimated_again_and_starts_no_segment():
    """A driver preempted between its two clock reads reads a larger offset, once."""
    clock_map, estimates = DeviceClockMap(), []

    def estimate():
        estimates.append(EPOCH)
        return EPOCH

    clock_map.observe(0.0, EPOCH, estimate)
    clock_map.observe(0.001, EPOCH + 2e-5, estimate)  # within the tolerance: not estimated
    clock_map.observe(0.002, EPOCH + 0.004, estimate)  # 4 ms between the reads
    assert len(estimates) == 2 and clock_map.steps == 0
    assert clock_map.to_ros_ns([0.0025])[0] == round(0.0025e9) + round(EPOCH * 1e9)


def test_nothing_observed_maps_nothing():
    with pytest.raises(ValueError, match='no offset observed'):
        DeviceClockMap().to_ros_ns([0.0])
