"""Argument checks shared by the driver core, so that every 'must be' error reads the same."""

import numpy as np

__all__ = ['checked_number', 'finite_vector']


def finite_vector(value, size: int, name: str, *, error: type[ValueError] = ValueError
                  ) -> np.ndarray:
    """Return a read-only float64 copy of ``value`` if it is ``size`` finite numbers.

    Raises ``error`` naming ``name`` otherwise.
    """
    try:
        vector = np.array(value, dtype=np.float64)
        valid = vector.shape == (size,) and bool(np.all(np.isfinite(vector)))
    except (TypeError, ValueError):
        valid = False
    if not valid:
        raise error(f'{name} must be {size} finite numbers, got {value!r}')
    vector.flags.writeable = False
    return vector


def checked_number(value, name: str, *, minimum: float | None = None, strict: bool = False,
                   error: type[ValueError] = ValueError) -> float:
    """Return ``value`` as a float if it is finite and (strictly, if asked) above ``minimum``.

    Raises ``error`` naming ``name`` otherwise.
    """
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = np.nan
    valid = np.isfinite(number) and (minimum is None or number > minimum
                                     or (number == minimum and not strict))
    if not valid:
        bound = '' if minimum is None else f' and {">" if strict else ">="} {minimum:g}'
        raise error(f'{name} must be finite{bound}, got {value!r}')
    return number
