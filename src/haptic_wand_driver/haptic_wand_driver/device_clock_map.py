"""ROS time of instants on the device's clock, across steps of the system clock.

Why: the device's record (when its force switched on and off) is on its own clock, which is
monotonic, and is read against ROS time (the system clock) kept by other processes. Mapped with
one offset read when the driver stops, every instant before a step of the system clock moved by
the step: in a CI run, each force on the hand seemed to end 0.2 s after its fault. The driver
reads ROS time minus the device's clock every tick; a reading that differs from the offset in
force by more than ``tolerance`` starts a new segment, with the offset estimated precisely then.
An instant between a step and the tick that saw it keeps the offset before the step: the map is
right to within a tick of each step, and exact elsewhere.
"""
from typing import Callable, Sequence

import numpy as np

__all__ = ['DeviceClockMap']

TOLERANCE = 1e-3  # [s] a reading this far from the offset in force is re-estimated


class DeviceClockMap:
    """ROS time minus the device's clock, by segments of the device's clock."""

    def __init__(self, tolerance: float = TOLERANCE) -> None:
        self.tolerance = tolerance
        self._starts: list = []  # the device's clock where each segment starts [s]
        self._offsets: list = []  # ROS time minus the device's clock in each segment [s]

    @property
    def steps(self) -> int:
        """How many steps of the system clock were seen."""
        return max(len(self._offsets) - 1, 0)

    def observe(self, device_now: float, reading: float, estimate: Callable[[], float]) -> None:
        """Book a reading of ROS time minus the device's clock, taken at ``device_now``.

        ``estimate`` returns the offset read precisely: called only when the reading is off.
        A reading delayed between its two clocks (a preempted driver) is off too, and its
        estimate then matches the offset in force, which is kept.
        """
        if self._offsets and abs(reading - self._offsets[-1]) <= self.tolerance:
            return
        offset = estimate()
        if not self._offsets or abs(offset - self._offsets[-1]) > self.tolerance:
            self._starts.append(device_now)
            self._offsets.append(offset)

    def to_ros_ns(self, device_times: Sequence[float]) -> np.ndarray:
        """Return the ROS time [ns] of each instant on the device's clock [s]."""
        if not self._offsets:
            raise ValueError('no offset observed yet: the device clock maps to no ROS time')
        times = np.asarray(device_times, dtype=float)
        segment = np.searchsorted(self._starts, times, side='right') - 1
        offsets_ns = np.round(1e9 * np.asarray(self._offsets)).astype(np.int64)
        return np.round(1e9 * times).astype(np.int64) + offsets_ns[np.maximum(segment, 0)]
