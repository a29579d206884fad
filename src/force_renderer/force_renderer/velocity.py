"""Tip velocity from stamped positions, for when the driver sends no twist.

The estimate is the least-squares slope of position against the actual stamps over a short
window. Using the stamps (not a nominal period) makes it indifferent to servo jitter; a duplicate
or backwards stamp, or a sample with NaN, is ignored instead of producing a division by ~0.
"""

from collections import deque
import math

import numpy as np

from force_renderer.errors import positive
from haptic_contract.checks import floats3

__all__ = ['VelocityEstimator']


class VelocityEstimator:
    """Least-squares velocity over the last `window` seconds of positions.

    The two newest samples are always used, however far apart: with servo periods longer than
    the window the estimate degrades to a finite difference over the actual interval, never to
    zero. (Staleness is the watchdog's business.)

    Parameters
    ----------
    window : float, s
        Age of the oldest sample used. Longer smooths noise more but lags by about window/2,
        and a lagging velocity makes damping less stabilising at high stiffness.
    """

    def __init__(self, window: float = 0.005) -> None:
        self.window = positive(window, 'window')
        self._samples: deque[tuple[float, float, float, float]] = deque()
        self._velocity = (0.0, 0.0, 0.0)  # None: samples came since it was last worked out

    def reset(self) -> None:
        """Forget every sample; the estimate is zero until two new ones arrive."""
        self._samples.clear()
        self._velocity = (0.0, 0.0, 0.0)

    @property
    def velocity(self) -> np.ndarray:
        """(3,) float, m/s: the estimate; zero before the second sample."""
        return np.array(self.velocity_components())

    def velocity_components(self) -> tuple[float, float, float]:
        """Return the estimate as floats, worked out only when asked.

        A loop fed the driver's twist adds a sample every tick and never asks.
        """
        if self._velocity is None:
            samples = self._samples
            self._velocity = _slope(samples) if len(samples) > 1 else (0.0, 0.0, 0.0)
        return self._velocity

    def update(self, stamp: float, position) -> np.ndarray:
        """Add one sample and return the new estimate.

        Parameters
        ----------
        stamp : float, s
            Time the position was measured.
        position : (3,) float, m
            Tip position, any fixed frame.

        Returns
        -------
        (3,) float, m/s
            Velocity estimate in the position's frame; unchanged when the sample is ignored.
        """
        return np.array(self.update_components(stamp, floats3(position)))

    def update_components(self, stamp: float,
                          position: tuple[float, float, float]) -> tuple[float, float, float]:
        """Float-level `update`."""
        self.add(stamp, position)
        return self.velocity_components()

    def add(self, stamp: float, position: tuple[float, float, float]) -> None:
        """Add one sample (m, floats), unless its stamp or a coordinate is unusable."""
        x, y, z = position
        samples = self._samples
        usable = math.isfinite(stamp) and math.isfinite(x + y + z)
        if not usable or (samples and stamp <= samples[-1][0]):
            return
        samples.append((stamp, x, y, z))
        while len(samples) > 2 and stamp - samples[0][0] > self.window:
            samples.popleft()
        self._velocity = None


def _slope(samples) -> tuple[float, float, float]:
    """Least-squares slope of x, y, z against t, all taken relative to the newest sample.

    Centring on the newest sample keeps the sums small: epoch stamps (~1e9 s) would otherwise
    cancel away every significant digit of a 1 ms interval.
    """
    t0, x0, y0, z0 = samples[-1]
    count = len(samples)
    st = stt = sx = sy = sz = stx = sty = stz = 0.0
    for t, x, y, z in samples:
        t -= t0
        x -= x0
        y -= y0
        z -= z0
        st += t
        stt += t * t
        sx += x
        sy += y
        sz += z
        stx += t * x
        sty += t * y
        stz += t * z
    spread = stt - st * st / count
    return ((stx - st * sx / count) / spread, (sty - st * sy / count) / spread,
            (stz - st * sz / count) / spread)
