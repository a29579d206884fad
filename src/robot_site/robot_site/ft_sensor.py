"""A simulated six-axis force/torque sensor at the probe mount.

Why: the remote site never knows the true contact force, only what its sensor reports, and every
use of that reading (the force sent to the operator, the contact model's estimate, the safety
limit) must cope with the sensor's faults. A real strain-gauge sensor has three that matter here:
an offset left after taring (``bias``), white noise, and the low-pass filter of its electronics,
which delays the reading. Each is a parameter, so a test can switch it off or make it worse.

The reading is filter(true wrench) + bias + noise: the filter is first order with its cut-off at
``bandwidth`` Hz, and the noise is Gaussian, independent per axis, drawn from a seeded generator
so that a run is reproducible. Inputs are checked finite, so a reading is never NaN.
"""

from dataclasses import dataclass, field
import math
from typing import NamedTuple

import numpy as np

from haptic_contract.checks import finite_number, finite_vector, whole_number

__all__ = ['FirstOrderLowPass', 'ForceTorqueSensor', 'ForceTorqueSensorConfig', 'Wrench']

_ZERO = (0.0, 0.0, 0.0)


class Wrench(NamedTuple):
    """A force (3,) N and a torque (3,) N·m, in the sensor's frame."""

    force: np.ndarray
    torque: np.ndarray


class FirstOrderLowPass:
    """The filter y' = 2π·f_c·(u − y), discretised exactly for an input held over each interval.

    Each ``update`` moves y toward the new input by 1 − exp(−2π·f_c·dt), so a step input reads
    1 − exp(−2π·f_c·t) at every sample whatever the sample times.

    Parameters
    ----------
    bandwidth : float, Hz
        The cut-off frequency f_c, > 0.
    initial : (n,) float
        The output before the first update.
    """

    def __init__(self, bandwidth: float, initial) -> None:
        self._rate = 2.0 * math.pi * finite_number(bandwidth, 'FirstOrderLowPass.bandwidth',
                                                   minimum=0.0, strict=True)
        self._output = np.array(initial, dtype=np.float64)

    @property
    def output(self) -> np.ndarray:
        """The filtered value, a copy."""
        return self._output.copy()

    def update(self, elapsed: float, value) -> np.ndarray:
        """Filter ``value``, held for ``elapsed`` seconds (>= 0), and return the output."""
        if not elapsed >= 0.0:
            raise ValueError(f'FirstOrderLowPass.update elapsed must be >= 0 s, got {elapsed!r}')
        self._output += -math.expm1(-self._rate * elapsed) * (value - self._output)
        return self.output


@dataclass(frozen=True, eq=False)
class ForceTorqueSensorConfig:
    """Parameters of the simulated sensor.

    The defaults are of the order of a small six-axis sensor (ATI Mini45 class) after taring:
    0.05 N RMS force noise as the issue asks, a filter at 200 Hz, no bias.

    Parameters
    ----------
    force_bias : (3,) float, N
    torque_bias : (3,) float, N·m
    force_noise : float, N
        RMS of the white noise on each force axis.
    torque_noise : float, N·m
        RMS of the white noise on each torque axis.
    bandwidth : float, Hz
        Cut-off of the first-order low-pass filter.
    seed : int
        Seed of the noise generator.
    """

    force_bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    torque_bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    force_noise: float = 0.05
    torque_noise: float = 0.002
    bandwidth: float = 200.0
    seed: int = 0

    def __post_init__(self):
        for name in ('force_bias', 'torque_bias'):
            object.__setattr__(self, name, finite_vector(getattr(self, name), 3,
                                                         f'ForceTorqueSensorConfig.{name}'))
        for name in ('force_noise', 'torque_noise'):
            finite_number(getattr(self, name), f'ForceTorqueSensorConfig.{name}', minimum=0.0)
        finite_number(self.bandwidth, 'ForceTorqueSensorConfig.bandwidth',
                      minimum=0.0, strict=True)
        whole_number(self.seed, 'ForceTorqueSensorConfig.seed', minimum=0)


class ForceTorqueSensor:
    """Reads the true wrench at the probe mount the way a real sensor would.

    Parameters
    ----------
    config : ForceTorqueSensorConfig
    """

    def __init__(self, config: ForceTorqueSensorConfig = ForceTorqueSensorConfig()) -> None:
        self._config = config
        self._filter = FirstOrderLowPass(config.bandwidth, np.zeros(6))  # tared at rest
        self._noise = np.repeat([config.force_noise, config.torque_noise], 3)
        self._bias = np.concatenate([config.force_bias, config.torque_bias])
        self._rng = np.random.default_rng(config.seed)
        self._last_time: float | None = None

    @property
    def config(self) -> ForceTorqueSensorConfig:
        """The configuration it was built with."""
        return self._config

    def measure(self, time: float, force, torque=_ZERO) -> Wrench:
        """Return the reading at ``time`` (s) of the true ``force`` (3,) N and ``torque`` N·m.

        The true wrench is taken as held since the previous reading; the first reading starts
        the clock. Times must not go back.
        """
        time = finite_number(time, 'ForceTorqueSensor.measure time')
        true_wrench = np.concatenate([
            finite_vector(force, 3, 'ForceTorqueSensor.measure force'),
            finite_vector(torque, 3, 'ForceTorqueSensor.measure torque')])
        elapsed = 0.0 if self._last_time is None else time - self._last_time
        if elapsed < 0.0:
            raise ValueError(f'ForceTorqueSensor.measure: time {time!r} s is before the last '
                             f'reading ({self._last_time!r} s); the clock must not go back')
        self._last_time = time
        reading = (self._filter.update(elapsed, true_wrench) + self._bias
                   + self._noise * self._rng.standard_normal(6))
        return Wrench(reading[:3], reading[3:])
