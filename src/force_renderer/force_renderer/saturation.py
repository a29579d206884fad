"""Saturation to the device's force limit.

Scaling the whole vector (not clipping each axis) keeps the direction, so a saturated force still
points along the surface normal. A force with any NaN or Inf component has no direction to keep
and becomes zero: nothing non-finite ever reaches the device.
"""

import math

import numpy as np

from force_renderer._checks import non_negative, vector3

__all__ = ['saturate', 'saturate_components']


def saturate_components(fx: float, fy: float, fz: float,
                        limit: float) -> tuple[float, float, float]:
    """Float-level `saturate` for the 1 kHz loop (plain floats beat numpy on 3-vectors)."""
    magnitude = math.hypot(fx, fy, fz)
    if not math.isfinite(magnitude):
        return 0.0, 0.0, 0.0
    if magnitude <= limit:
        return fx, fy, fz
    scale = limit / magnitude
    return fx * scale, fy * scale, fz * scale


def saturate(force, limit: float) -> np.ndarray:
    """Scale `force` down to at most `limit` in magnitude, keeping its direction.

    Parameters
    ----------
    force : (3,) float, N
        Force to send to the device, any frame.
    limit : float, N
        The device's largest force magnitude; >= 0.

    Returns
    -------
    (3,) float, N
        `force` if within the limit, else `force * limit / |force|`; zero if `force` is not
        finite.
    """
    fx, fy, fz = vector3(force, 'force').tolist()
    return np.array(saturate_components(fx, fy, fz, non_negative(limit, 'limit')))
