"""Argument checks shared by the remote site's core, so every 'must be' error reads the same."""

import math

import numpy as np

__all__ = ['finite_floats', 'finite_number', 'finite_vector', 'nonzero_floats', 'unit_vector']


def finite_number(value, name: str, *, minimum: float | None = None,
                  strict: bool = False, maximum: float | None = None) -> float:
    """Return ``value`` as a float if it is finite and within the bounds, else raise ValueError.

    ``minimum`` is exclusive when ``strict``; ``maximum`` is inclusive.
    """
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    below = minimum is not None and (number < minimum or (strict and number == minimum))
    above = maximum is not None and number > maximum
    if not math.isfinite(number) or below or above:
        bounds = ''.join([
            '' if minimum is None else f' {">" if strict else ">="} {minimum:g}',
            '' if maximum is None else f' <= {maximum:g}'])
        raise ValueError(f'{name} must be finite{bounds}, got {value!r}')
    return number


def finite_vector(value, size: int, name: str, *, minimum: float | None = None) -> np.ndarray:
    """Return a read-only float64 copy of ``value`` if it is ``size`` finite numbers.

    With ``minimum``, every component must also be at least that. Raises ValueError otherwise.
    """
    vector, _ = _finite_array(value, size, name, minimum)
    vector.flags.writeable = False
    return vector


def finite_floats(value, size: int, name: str) -> tuple:
    """Return ``value`` as a tuple of ``size`` floats, checked as ``finite_vector`` checks it.

    For a caller that keeps floats (a command every tick): no read-only array is made.
    """
    return tuple(_finite_array(value, size, name, None)[1])


def nonzero_floats(value, size: int, name: str) -> tuple:
    """Return ``value`` as a tuple of ``size`` floats, checked as ``unit_vector`` checks it.

    For a caller that only refuses a zero vector: not scaled, no read-only array made.
    """
    vector, components = _finite_array(value, size, name, None)
    _nonzero_length(vector, value, name)
    return tuple(components)


def unit_vector(value, size: int, name: str) -> np.ndarray:
    """Return ``value`` (``size`` finite numbers, not zero) scaled to unit length, read-only."""
    vector, _ = _finite_array(value, size, name, None)
    unit = vector / _nonzero_length(vector, value, name)
    unit.flags.writeable = False
    return unit


def _finite_array(value, size: int, name: str, minimum: float | None) -> tuple[np.ndarray, list]:
    """Return ``value`` as a float64 array and a list of its floats; raise unless all finite."""
    try:
        vector = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        vector = np.full(0, math.nan)
    # Its components as floats: numpy's per-call dispatch (np.all took 7 % of the remote site's
    # process, the array's own isfinite().all() 1.2 µs) costs more than checking three floats.
    components = vector.tolist() if vector.shape == (size,) else [math.nan]
    if not all(map(math.isfinite, components)) or (
            minimum is not None and min(components) < minimum):
        bound = '' if minimum is None else f' >= {minimum:g}'
        raise ValueError(f'{name} must be {size} finite numbers{bound}, got {value!r}')
    return vector, components


def _nonzero_length(vector: np.ndarray, value, name: str) -> float:
    """Return the length of ``vector`` (``value`` checked finite); raise if it is zero."""
    length = math.sqrt(vector.dot(vector))  # np.linalg.norm's own sum, without its dispatch
    if length < 1e-9:
        raise ValueError(f'{name} must not be zero, got {value!r}')
    return length
