"""Norms and unit vectors that neither underflow nor overflow, compiled.

``sqrt(x*x + y*y + z*z)`` loses every digit when the components are below about 1e-154 (the
squares are subnormal or zero: a direction (3e-161, 3e-161, 1) gave a cylinder support point
1.25e-05 m off its surface) and is infinite above about 1e154. Here the plain formula is kept
where its squares are exact to rounding (the fast path, bit for bit the old answer), and anything
else is divided by its largest component first, so that the squares lie in [0, 3].

Conventions, for every function here: a zero or NaN vector has no direction (unit vector
(0, 0, 0)); a vector with infinite components points along the limit direction of those
components (finite ones count as 0), so ``(inf, 1, 0)`` is ``(1, 0, 0)``.
"""

import math

from collision_engine._jit import jit

__all__ = ['norm2', 'norm3', 'unit2', 'unit3', 'scaled3']

# Squared norms in this range are sums of squares exact to rounding (no term underflowed by
# more than 2^-1074 / 1e-290 ~ 1e-34 of the sum, none overflowed).
_SMALLEST_SAFE_SQUARE = 1e-290
_LARGEST_SAFE_SQUARE = 1e290


@jit
def scaled3(x, y, z):
    """Divide a vector by its largest absolute component: (x, y, z) / max|.|, in [-1, 1].

    Returns (0, 0, 0) for a zero or NaN vector and the limit direction (components -1, 0 or 1)
    when some component is infinite. The result points the same way as the input, so a support
    function may take it in place of the direction.
    """
    if math.isnan(x) or math.isnan(y) or math.isnan(z):
        return 0.0, 0.0, 0.0
    largest = max(abs(x), abs(y), abs(z))
    if largest == 0.0:
        return 0.0, 0.0, 0.0
    if math.isinf(largest):
        return _limit(x), _limit(y), _limit(z)
    return x / largest, y / largest, z / largest


@jit
def _limit(value):
    if value == math.inf:
        return 1.0
    if value == -math.inf:
        return -1.0
    return 0.0


@jit
def norm3(x, y, z):
    """Euclidean norm of (x, y, z), exact to rounding at any magnitude (inf if any is inf)."""
    squared = x * x + y * y + z * z
    if _SMALLEST_SAFE_SQUARE <= squared <= _LARGEST_SAFE_SQUARE:
        return math.sqrt(squared)
    if math.isnan(squared):
        return math.nan
    largest = max(abs(x), abs(y), abs(z))
    if largest == 0.0 or math.isinf(largest):
        return largest
    sx, sy, sz = x / largest, y / largest, z / largest
    return largest * math.sqrt(sx * sx + sy * sy + sz * sz)


@jit
def unit3(x, y, z):
    """(x, y, z) / |(x, y, z)|, exact to rounding at any magnitude; (0, 0, 0) if it has none."""
    squared = x * x + y * y + z * z
    if _SMALLEST_SAFE_SQUARE <= squared <= _LARGEST_SAFE_SQUARE:
        norm = math.sqrt(squared)
        return x / norm, y / norm, z / norm
    sx, sy, sz = scaled3(x, y, z)
    norm = math.sqrt(sx * sx + sy * sy + sz * sz)
    if norm == 0.0:
        return 0.0, 0.0, 0.0
    return sx / norm, sy / norm, sz / norm


@jit
def norm2(x, y):
    """Euclidean norm of (x, y), as ``norm3(x, y, 0)``."""
    return norm3(x, y, 0.0)


@jit
def unit2(x, y):
    """(x, y) / |(x, y)|, as ``unit3(x, y, 0)``; (0, 0) if it has no direction."""
    ux, uy, _ = unit3(x, y, 0.0)
    return ux, uy
