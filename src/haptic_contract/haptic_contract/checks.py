"""The one set of argument checks, so that every 'must be' error in the toolkit reads the same.

Each raises ``error`` (ValueError unless the caller's package has its own subclass) with a
sentence that names the argument and says what it must be. They sit on the 1 kHz paths, so
finiteness is checked on Python floats: a numpy ufunc and reduction on a 3-vector cost
microseconds, ``math.isfinite`` tens of nanoseconds.
"""

import functools
import math
import struct
from typing import Callable, Sequence

import numpy as np

__all__ = ['finite_components', 'finite_number', 'finite_vector', 'floats3',
           'nonzero_components', 'per_axis', 'read_only_vector', 'unit_vector', 'vector3',
           'whole_number', 'within_box']

_FLOAT64 = np.dtype(np.float64)


def finite_number(value, name: str, *, minimum: float | None = None, strict: bool = False,
                  maximum: float | None = None, unit: str = '',
                  error: type[ValueError] = ValueError) -> float:
    """Return ``value`` as a float if it is finite and within the bounds, else raise ``error``.

    ``minimum`` is exclusive when ``strict``; ``maximum`` is inclusive. ``unit`` is named in the
    error, so that a wrong order of magnitude reads as one.
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
            '' if maximum is None else f' <= {maximum:g}', f' ({unit})' if unit else ''])
        raise error(f'{name} must be finite{bounds}, got {value!r}')
    return number


def finite_components(value, size: int, name: str, *, minimum: float | None = None,
                      error: type[ValueError] = ValueError) -> tuple[float, ...]:
    """Return ``value`` as a tuple of ``size`` finite floats (each at least ``minimum``, if set).

    For the per-tick paths, which keep floats. Raises ``error`` naming ``name`` otherwise.
    """
    if type(value) is np.ndarray and value.dtype is _FLOAT64:
        vector = value  # the usual case at 1 kHz: read as it is, no conversion
    else:
        try:
            vector = np.array(value, dtype=np.float64)
        except (TypeError, ValueError):
            vector = None
    components = vector.tolist() if vector is not None and vector.shape == (size,) else []
    if (len(components) != size or not all(map(math.isfinite, components))
            or (minimum is not None and min(components) < minimum)):
        bound = '' if minimum is None else f' >= {minimum:g}'
        raise error(f'{name} must be {size} finite numbers{bound}, got {value!r}')
    return tuple(components)


def finite_vector(value, size: int, name: str, *, minimum: float | None = None,
                  error: type[ValueError] = ValueError) -> np.ndarray:
    """Return a read-only float64 copy of ``value``, checked as :func:`finite_components`."""
    vector = np.array(finite_components(value, size, name, minimum=minimum, error=error))
    vector.flags.writeable = False
    return vector


def nonzero_components(value, size: int, name: str) -> tuple:
    """Return ``value`` as a tuple of ``size`` finite floats, refusing a zero vector.

    For a caller that only refuses a zero vector: not scaled, no read-only array made.
    """
    components = finite_components(value, size, name)
    _nonzero_length(np.array(components), value, name)
    return components


def unit_vector(value, size: int, name: str) -> np.ndarray:
    """Return ``value`` (``size`` finite numbers, not zero) scaled to unit length, read-only."""
    vector = np.array(finite_components(value, size, name))
    unit = vector / _nonzero_length(vector, value, name)
    unit.flags.writeable = False
    return unit


def _nonzero_length(vector: np.ndarray, value, name: str) -> float:
    """Return the length of ``vector`` (``value`` checked finite); raise if it is zero."""
    length = math.sqrt(vector.dot(vector))  # np.linalg.norm's own sum, without its dispatch
    if length < 1e-9:
        raise ValueError(f'{name} must not be zero, got {value!r}')
    return length


def read_only_vector(components: Sequence[float]) -> np.ndarray:
    """Return a new read-only float64 array of ``components``, floats the caller has checked.

    Packing into immutable bytes makes the array read-only at its birth, which is cheaper than
    building it writable and then clearing its flag.
    """
    return np.frombuffer(_packer(len(components))(*components))


@functools.cache
def _packer(size: int) -> Callable[..., bytes]:
    return struct.Struct(f'{size}d').pack


def vector3(value, name: str, *, error: type[ValueError] = ValueError) -> np.ndarray:
    """Return ``value`` as a read-only (3,) float64 array; NaN is allowed (a watchdog rejects it).

    Raises ``error`` if ``value`` does not have exactly three numeric components.
    """
    try:
        array = np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as failure:
        raise error(f'{name} must be 3 numbers, got {value!r}') from failure
    if array.shape != (3,):
        raise error(f'{name} must have shape (3,), got shape {array.shape}')
    array.flags.writeable = False
    return array


def per_axis(value, name: str, *, error: type[ValueError] = ValueError) -> np.ndarray:
    """Return a finite, non-negative gain given as one number (all axes) or three (x, y, z)."""
    array = vector3((value,) * 3 if np.ndim(value) == 0 else value, name, error=error)
    if not np.all(np.isfinite(array)) or np.any(array < 0.0):
        raise error(f'{name} must be finite and >= 0 per axis, got {array.tolist()}')
    return array


def whole_number(value, name: str, *, minimum: int = 1,
                 error: type[ValueError] = ValueError) -> int:
    """Return ``value`` if it is an integer (not a bool) of at least ``minimum``, else raise."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise error(f'{name} must be an integer >= {minimum}, got {value!r}')
    return int(value)


def floats3(vector) -> tuple[float, float, float]:
    """Three plain floats from a (3,) array or sequence.

    On 3-vectors numpy's per-call overhead dwarfs the arithmetic, so the 1 kHz paths use floats.
    """
    x, y, z = vector
    return float(x), float(y), float(z)


def within_box(point, lower, upper, margin: float = 0.0) -> bool:
    """Whether each component of ``point`` lies within [lower - margin, upper + margin].

    The one test of a box (a workspace, a wand's joint ranges), so that a margin is the only
    way two of them differ; walls count as inside. A NaN component is outside.
    """
    return all(low - margin <= x <= high + margin for low, x, high in zip(lower, point, upper))
