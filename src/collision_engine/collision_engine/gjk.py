"""Our GJK: distance between two convex shapes given by their support functions, compiled.

GJK (Gilbert, Johnson, Keerthi 1988) searches the Minkowski difference ``C = A - B`` for its
point ``v`` nearest the origin: ``|v|`` is the distance, and the barycentric weights of v in its
simplex, applied to the support points of A each vertex came from, give the witness on A (the
one on B is that minus v). A point is the convex shape whose support is itself (``POINT``): the
point query is this same GJK, ``q + v`` its closest point. The sub-algorithm that finds the
nearest point of the current simplex is the signed-volumes method of Montanari, Petrinic and
Barbieri (2017), in ``signed_volumes``.

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
from collision_engine.support import POINT, support
from haptic_contract.collision_state import (STATUS_INVALID_INPUT, STATUS_NO_OBJECT,
                                             STATUS_NOT_CONVERGED, STATUS_OK)

__all__ = ['STATUS_OK', 'STATUS_NOT_CONVERGED', 'STATUS_NO_OBJECT', 'STATUS_INVALID_INPUT',
           'gjk', 'power_of_two_inverse', 'support_difference']

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
def support_difference(a, b, rel, dx, dy, dz, start_a, start_b):
    """Support point of the Minkowski difference A - B along d, in A's frame.

    ``a`` and ``b`` are packed shapes ``(kind, floats, fo, ints, io)`` (see ``support``);
    ``rel`` (12,) is B's pose in A's frame, rotation row-major then translation
    (``x_A = R x_B + t``). A point B (kind ``POINT``) is its translation, with no rotation.
    Returns (wx, wy, wz, ax, ay, az, vertex_a, vertex_b): w = a - b, and a, A's support point.
    """
    ax, ay, az, vertex_a = support(a[0], a[1], a[2], a[3], a[4], dx, dy, dz, start_a)
    if b[0] == POINT:
        return ax - rel[9], ay - rel[10], az - rel[11], ax, ay, az, vertex_a, -1
    ex = -(rel[0] * dx + rel[3] * dy + rel[6] * dz)  # -d in B's frame: R^T (-d)
    ey = -(rel[1] * dx + rel[4] * dy + rel[7] * dz)
    ez = -(rel[2] * dx + rel[5] * dy + rel[8] * dz)
    sx, sy, sz, vertex_b = support(b[0], b[1], b[2], b[3], b[4], ex, ey, ez, start_b)
    bx = rel[0] * sx + rel[1] * sy + rel[2] * sz + rel[9]
    by = rel[3] * sx + rel[4] * sy + rel[5] * sz + rel[10]
    bz = rel[6] * sx + rel[7] * sy + rel[8] * sz + rel[11]
    return ax - bx, ay - by, az - bz, ax, ay, az, vertex_a, vertex_b


@jit
def gjk(a, b, rel, dx, dy, dz, size, rel_tol, abs_tol, max_iter, W, A):
    """Distance between convex shapes A and B (packed as in ``support``), in A's frame.

    GJK on ``C = A - B`` (``support_difference``; ``rel`` is B's pose in A's frame). A point is
    the shape whose support is itself (``POINT``), which makes this the point query too; then
    no witness is tracked, ``q + v`` being the nearest point. (dx, dy, dz) is the first search
    direction, from B toward A (a warm start when it is near the answer); ``size`` (m) is about
    the pair's size (the sum of their bounding radii). The search runs on C scaled by ``inv``, a
    power of two that brings the larger of ``size`` and the first ``|w|`` to about 1
    (``power_of_two_inverse``): exact, and no squared length underflows or overflows at any
    magnitude of the shapes or of their offset. ``W`` and ``A`` (12,) are scratch; on contact
    ``W`` holds the final simplex of ``inv C`` for EPA (rows of a row-major (4, 3) array) and
    ``A`` the support points of A they came from.

    Returns (status, contact, count, vx, vy, vz, lower, iterations, inv, wx, wy, wz): v = a - b
    for the nearest points a of A (the witness w) and b = w - v of B found, ``|v|`` the upper
    bound on the distance and ``lower`` the best lower bound, in metres. ``contact`` is true
    when the shapes touch or overlap (then v ~ 0).
    """
    track = b[0] != POINT
    cx, cy, cz, sx, sy, sz, vertex_a, vertex_b = support_difference(a, b, rel, dx, dy, dz, 0, 0)
    inv = power_of_two_inverse(max(abs(cx), abs(cy), abs(cz), size))
    vx, vy, vz = cx * inv, cy * inv, cz * inv
    abs_tol = abs_tol * inv
    W[0], W[1], W[2] = vx, vy, vz
    A[0], A[1], A[2] = sx, sy, sz
    wx, wy, wz = sx, sy, sz  # the witness on A of the current v
    count = 1
    vv = vx * vx + vy * vy + vz * vz
    w_max2 = vv
    lower = 0.0
    status = STATUS_NOT_CONVERGED
    iteration = sideways = 0
    while iteration < max_iter:
        iteration += 1
        if vv == 0.0:
            return STATUS_OK, True, count, 0.0, 0.0, 0.0, 0.0, iteration, inv, wx, wy, wz
        cx, cy, cz, sx, sy, sz, vertex_a, vertex_b = support_difference(
            a, b, rel, -vx, -vy, -vz, vertex_a, vertex_b)
        cx, cy, cz = cx * inv, cy * inv, cz * inv
        w_max2 = max(w_max2, cx * cx + cy * cy + cz * cz)
        norm_v = math.sqrt(vv)
        vc = vx * cx + vy * cy + vz * cz
        if vc > 0.0:
            lower = max(lower, vc / norm_v)
        gap = vv - vc
        tolerance = max(rel_tol * vv, abs_tol * norm_v, _ROUNDING * norm_v * math.sqrt(w_max2))
        if gap <= tolerance:
            status = STATUS_OK
            break
        stalled = STATUS_OK if gap <= _ROUNDING * w_max2 else STATUS_NOT_CONVERGED
        duplicate = False
        for m in range(count):
            if W[3 * m] == cx and W[3 * m + 1] == cy and W[3 * m + 2] == cz:
                duplicate = True
        if duplicate:
            status = stalled
            break
        W[3 * count], W[3 * count + 1], W[3 * count + 2] = cx, cy, cz
        A[3 * count], A[3 * count + 1], A[3 * count + 2] = sx, sy, sz
        count, nx, ny, nz, l0, l1, l2, l3 = nearest_on_simplex(W, count + 1, A, track)
        nn = nx * nx + ny * ny + nz * nz
        if count == 4 or nn <= (_CONTACT * _CONTACT) * w_max2:
            if track:
                wx, wy, wz = _combine(A, count, l0, l1, l2, l3)
            return (STATUS_OK, True, count, nx / inv, ny / inv, nz / inv, 0.0, iteration, inv,
                    wx, wy, wz)
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
        if track:
            wx, wy, wz = _combine(A, count, l0, l1, l2, l3)
    vx, vy, vz = vx / inv, vy / inv, vz / inv
    if not track:
        wx, wy, wz = rel[9] + vx, rel[10] + vy, rel[11] + vz
    return status, False, count, vx, vy, vz, lower / inv, iteration, inv, wx, wy, wz


@jit
def _combine(A, count, l0, l1, l2, l3):
    """Return the sum of l_i times row i of A, over its first ``count`` rows."""
    x, y, z = l0 * A[0], l0 * A[1], l0 * A[2]
    weights = (l1, l2, l3)
    for row in range(1, count):
        x += weights[row - 1] * A[3 * row]
        y += weights[row - 1] * A[3 * row + 1]
        z += weights[row - 1] * A[3 * row + 2]
    return x, y, z
