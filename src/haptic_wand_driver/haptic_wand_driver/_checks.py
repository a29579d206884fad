"""Argument checks shared by the driver core, so that every 'must be' error reads the same.

They sit on the 1 kHz path, so finiteness is checked on Python floats: a numpy ufunc and
reduction on a 3-vector cost microseconds, ``math.isfinite`` tens of nanoseconds.
"""

import functools
import math
import struct
from typing import Callable, Sequence

import numpy as np

__all__ = ['checked_number', 'finite_components', 'finite_vector', 'read_only_vector']

_FLOAT64 = np.dtype(np.float64)


def finite_vector(value, size: int, name: str, *, error: type[ValueError] = ValueError
                  ) -> np.ndarray:
    """Return a read-only float64 copy of ``value`` if it is ``size`` finite numbers.

    Raises ``error`` naming ``name`` otherwise.
    """
    vector = np.array(finite_components(value, size, name, error=error))
    vector.flags.writeable = False
    return vector


def finite_components(value, size: int, name: str, *, error: type[ValueError] = ValueError
                      ) -> tuple[float, ...]:
    """Return ``value`` as a tuple of ``size`` finite floats, for the per-tick paths.

    Raises ``error`` naming ``name`` otherwise, as :func:`finite_vector`.
    """
    if type(value) is np.ndarray and value.dtype is _FLOAT64:
        vector = value  # the usual case at 1 kHz: read as it is, no conversion
    else:
        try:
            vector = np.array(value, dtype=np.float64)
        except (TypeError, ValueError):
            vector = None
    components = vector.tolist() if vector is not None and vector.shape == (size,) else []
    if len(components) != size or not all(map(math.isfinite, components)):
        raise error(f'{name} must be {size} finite numbers, got {value!r}')
    return tuple(components)


def read_only_vector(components: Sequence[float]) -> np.ndarray:
    """Return a new read-only float64 array of ``components``, floats the caller has checked.

    Packing into immutable bytes makes the array read-only at its birth, which is cheaper than
    building it writable and then clearing its flag.
    """
    return np.frombuffer(_packer(len(components))(*components))


@functools.cache
def _packer(size: int) -> Callable[..., bytes]:
    return struct.Struct(f'{size}d').pack


def checked_number(value, name: str, *, minimum: float | None = None, strict: bool = False,
                   error: type[ValueError] = ValueError) -> float:
    """Return ``value`` as a float if it is finite and (strictly, if asked) above ``minimum``.

    Raises ``error`` naming ``name`` otherwise.
    """
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    valid = math.isfinite(number) and (minimum is None or number > minimum
                                       or (number == minimum and not strict))
    if not valid:
        bound = '' if minimum is None else f' and {">" if strict else ">="} {minimum:g}'
        raise error(f'{name} must be finite{bound}, got {value!r}')
    return number
