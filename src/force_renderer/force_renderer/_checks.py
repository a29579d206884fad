"""Argument checks shared by the core, so every error reads the same way, and a float helper."""

import math

import numpy as np

from force_renderer.errors import ForceRendererError

__all__ = ['count', 'floats3', 'non_negative', 'per_axis', 'positive', 'vector3']


def vector3(value, name: str) -> np.ndarray:
    """Return `value` as a read-only (3,) float64 array; NaN is allowed (the watchdog rejects it).

    Raises
    ------
    ForceRendererError
        If `value` does not have exactly three numeric components.
    """
    try:
        array = np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise ForceRendererError(f'{name} must be 3 numbers, got {value!r}') from error
    if array.shape != (3,):
        raise ForceRendererError(f'{name} must have shape (3,), got shape {array.shape}')
    array.flags.writeable = False
    return array


def per_axis(value, name: str) -> np.ndarray:
    """Return a finite, non-negative gain given as one number (all axes) or three (x, y, z)."""
    array = vector3((value,) * 3 if np.ndim(value) == 0 else value, name)
    if not np.all(np.isfinite(array)) or np.any(array < 0.0):
        raise ForceRendererError(f'{name} must be finite and >= 0 per axis, got {array.tolist()}')
    return array


def positive(value: float, name: str) -> float:
    """Return `value` as a float, or raise if it is not finite and > 0."""
    number = float(value)
    if not (math.isfinite(number) and number > 0.0):
        raise ForceRendererError(f'{name} must be finite and > 0, got {value!r}')
    return number


def count(value: int, name: str) -> int:
    """Return `value` if it is an integer >= 1, else raise."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ForceRendererError(f'{name} must be an integer >= 1, got {value!r}')
    return int(value)


def non_negative(value: float, name: str) -> float:
    """Return `value` as a float, or raise if it is not finite and >= 0."""
    number = float(value)
    if not (math.isfinite(number) and number >= 0.0):
        raise ForceRendererError(f'{name} must be finite and >= 0, got {value!r}')
    return number


def floats3(vector) -> tuple[float, float, float]:
    """Three plain floats from a (3,) array or sequence.

    On 3-vectors numpy's per-call overhead dwarfs the arithmetic, so the 1 kHz path uses floats.
    """
    x, y, z = vector
    return float(x), float(y), float(z)
