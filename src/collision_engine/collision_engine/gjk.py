"""Our GJK: distance from a point to a convex shape given by its support function, compiled.

GJK (Gilbert, Johnson, Keerthi 1988) searches the shape minus the point, ``C = A - q``, for its
point ``v`` nearest the origin; ``q + v`` is then the closest point of ``A`` and ``|v|`` the
distance. The sub-algorithm that finds the nearest point of the current simplex is the
signed-volumes method of Montanari, Petrinic and Barbieri (2017), in ``signed_volumes``.

The loop stops on whichever comes first:

* a relative test, ``|v|^2 - v.w <= rel_tol |v|^2`` (the bound gap is a fraction of the
  distance);
* an absolute test, ``|v|^2 - v.w <= abs_tol |v|`` (the gap is below ``abs_tol`` metres);
* the rounding floor, ``|v|^2 - v.w <= 1024 eps |v| max|w|``: the distance is then known to
  about 2e-13 of the shape's size, what float64 sub-algorithm steps on it can resolve;
* contact: the origin lies in the simplex (the point is inside or on the shape);
* no progress: the new support point is already in the simplex, or the new simplex is not
  nearer. In exact arithmetic that proves optimality (classic GJK stops there). A new simplex
  farther by no more than rounding is still taken, up to two steps in a row, while the gap is
  wider than rounding: the previous v, rounded off its simplex, can seem nearer than the next
  simplex's exact answer (a point 1.6e-9 off the centre line of a box face stalled so, with
  a gap of 1e-8 of the distance). In float64, v carries about eps max|w| of rounding, so near
  the surface its direction, hence the lower bound, is loose while |v| stays exact to that
  rounding: the stall is reported as converged
  when the gap is at that rounding (``1024 eps max|w|^2``), else as ``NOT_CONVERGED`` with the
  best bound. On a sliver hull, whose corners are closer than that direction can tell apart,
  the stall can come early: errors of ~2e-10 of the size were seen on hulls with corners
  1e-9 of the size apart;
* the iteration cap, reported as ``NOT_CONVERGED`` with the best upper bound found.

A relative test alone cycles near the surface of a many-vertex hull, hence all of them.
Status codes are those of ``haptic_msgs/CollisionState``.
"""

import math

import numpy as np

from collision_engine._jit import jit
from collision_engine.signed_volumes import nearest_on_simplex
from collision_engine.support import support

__all__ = ['STATUS_OK', 'STATUS_NOT_CONVERGED', 'STATUS_NO_OBJECT', 'STATUS_INVALID_INPUT',
           'gjk', 'power_of_two_inverse']

STATUS_OK = 0
STATUS_NOT_CONVERGED = 1
STATUS_NO_OBJECT = 2
STATUS_INVALID_INPUT = 3

_EPS = float(np.finfo(np.float64).eps)
_ROUNDING = 1024.0 * _EPS
_CONTACT = 16.0 * _EPS
_MAX_EXPONENT = 1000  # 2**1000 and 2**-1000 are finite and normal
_SIDEWAYS = 2  # steps in a row to a simplex as near as the last to rounding, before a stall


@jit
def power_of_two_inverse(length):
    """Return the power of two ``inv`` with ``length * inv`` in [0.5, 1): a change of unit.

    Multiplying by a power of two only moves the exponent, so a problem scaled by ``inv`` has
    the same digits as the original, while its squared lengths neither underflow nor overflow.
    Lengths of 0, inf or NaN give 1.
    """
    if not (0.0 < length < math.inf):
        return 1.0
    _, exponent = math.frexp(length)
    return math.ldexp(1.0, -max(min(exponent, _MAX_EXPONENT), -_MAX_EXPONENT))


@jit
def gjk(kind, floats, fo, ints, io, qx, qy, qz, dx, dy, dz, size, rel_tol, abs_tol, max_iter,
        W):
    """Distance from the point q to a convex shape (packed as in ``support``), local frame.

    (dx, dy, dz) is the first search direction, from the shape toward the point (a warm start
    when it is near the answer); ``size`` (m) is about the shape's size (its bounding radius).
    The search runs on ``C = A - q`` scaled by ``inv``, a power of two that brings the larger of
    ``size`` and the first ``|w|`` to about 1 (``power_of_two_inverse``): exact, and no squared
    length underflows or overflows at any magnitude of the shape or of the offset of q.
    ``W`` (12,) is scratch; on contact it holds the final simplex of ``inv C`` for EPA, as rows
    of a row-major (4, 3) array.

    Returns (status, contact, count, vx, vy, vz, lower, iterations, inv): ``q + v`` is the
    nearest point found, ``|v|`` the upper bound on the distance and ``lower`` the best lower
    bound, in metres. ``contact`` is true when the point is inside or on the shape (then
    v ~ 0).
    """
    sx, sy, sz, vertex = support(kind, floats, fo, ints, io, dx, dy, dz, 0)
    inv = power_of_two_inverse(max(abs(sx - qx), abs(sy - qy), abs(sz - qz), size))
    vx, vy, vz = (sx - qx) * inv, (sy - qy) * inv, (sz - qz) * inv
    abs_tol = abs_tol * inv
    W[0], W[1], W[2] = vx, vy, vz
    count = 1
    vv = vx * vx + vy * vy + vz * vz
    w_max2 = vv
    lower = 0.0
    status = STATUS_NOT_CONVERGED
    iteration = sideways = 0
    while iteration < max_iter:
        iteration += 1
        if vv == 0.0:
            return STATUS_OK, True, count, 0.0, 0.0, 0.0, 0.0, iteration, inv
        sx, sy, sz, vertex = support(kind, floats, fo, ints, io, -vx, -vy, -vz, vertex)
        wx, wy, wz = (sx - qx) * inv, (sy - qy) * inv, (sz - qz) * inv
        w_max2 = max(w_max2, wx * wx + wy * wy + wz * wz)
        norm_v = math.sqrt(vv)
        vw = vx * wx + vy * wy + vz * wz
        if vw > 0.0:
            lower = max(lower, vw / norm_v)
        gap = vv - vw
        tolerance = max(rel_tol * vv, abs_tol * norm_v, _ROUNDING * norm_v * math.sqrt(w_max2))
        if gap <= tolerance:
            status = STATUS_OK
            break
        stalled = STATUS_OK if gap <= _ROUNDING * w_max2 else STATUS_NOT_CONVERGED
        duplicate = False
        for m in range(count):
            if W[3 * m] == wx and W[3 * m + 1] == wy and W[3 * m + 2] == wz:
                duplicate = True
        if duplicate:
            status = stalled
            break
        W[3 * count], W[3 * count + 1], W[3 * count + 2] = wx, wy, wz
        count, nx, ny, nz = nearest_on_simplex(W, count + 1)
        nn = nx * nx + ny * ny + nz * nz
        if count == 4 or nn <= (_CONTACT * _CONTACT) * w_max2:
            return STATUS_OK, True, count, nx / inv, ny / inv, nz / inv, 0.0, iteration, inv
        if nn >= vv:
            # Not nearer. When only by rounding while the gap is still wide, the old v was the
            # one rounded low (it lay off its simplex by an ulp): take a few such steps.
            sideways += 1
            if stalled == STATUS_OK or nn > vv + _ROUNDING * w_max2 or sideways > _SIDEWAYS:
                status = stalled
                break
        else:
            sideways = 0
        vx, vy, vz, vv = nx, ny, nz, nn
    return status, False, count, vx / inv, vy / inv, vz / inv, lower / inv, iteration, inv
