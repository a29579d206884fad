"""Support functions and exact interior distances of the convex shapes, compiled.

A convex shape enters the kernels as a kind code and two flat blocks, ``floats`` and ``ints``,
read from an offset (so that a whole scene packs into one float64 and one int64 array):

=============  ==============================================  ===================================
kind           floats                                          ints
=============  ==============================================  ===================================
BOX            half extents hx, hy, hz                         (none)
SPHERE         radius                                          (none)
CYLINDER       radius, half height (axis z)                    (none)
CAPSULE        radius, half segment length (axis z)            (none)
CONVEX_MESH    n vertices x, y, z                              n, then CSR vertex adjacency:
                                                               n + 1 offsets, then neighbours
POINT          (none): the point is the local origin            (none)
TRIANGLE       corners a, b, c (9)                             (none)
SEGMENT        (radius, ignored), half length (axis z)         (none)
=============  ==============================================  ===================================

A ``SEGMENT`` reads a capsule's own block without its radius: the capsule's core, which the pair
query (``convex_pair``) measures before subtracting the radius.

All vectors are in the shape's local frame, in metres.
"""

import numpy as np

from collision_engine._jit import jit
from collision_engine.norms import norm2, norm3, scaled3, unit2, unit3

__all__ = [
    'BOX', 'SPHERE', 'CYLINDER', 'CAPSULE', 'CONVEX_MESH', 'TRIANGLE_MESH', 'POINT', 'TRIANGLE',
    'SEGMENT', 'pack_convex', 'support', 'support_point', 'interior',
]

BOX = 0
SPHERE = 1
CYLINDER = 2
CAPSULE = 3
CONVEX_MESH = 4
TRIANGLE_MESH = 5
POINT = 6
TRIANGLE = 7
SEGMENT = 8


def pack_convex(shape) -> tuple[int, np.ndarray, np.ndarray]:
    """Flatten a convex shape into its kind code and its ``floats`` and ``ints`` blocks.

    Parameters
    ----------
    shape : Box, Sphere, Cylinder, Capsule or ConvexMesh
        Read through its ``kind`` code and geometric attributes.

    Returns
    -------
    kind : int
    floats : (k,) float64, m
    ints : (j,) int64
    """
    kind = shape.kind
    if kind == BOX:
        return kind, 0.5 * np.asarray(shape.size, dtype=np.float64), np.zeros(0, np.int64)
    if kind == SPHERE:
        return kind, np.array([shape.radius], dtype=np.float64), np.zeros(0, np.int64)
    if kind == CYLINDER:
        floats = np.array([shape.radius, 0.5 * shape.height], dtype=np.float64)
        return kind, floats, np.zeros(0, np.int64)
    if kind == CAPSULE:
        floats = np.array([shape.radius, 0.5 * shape.length], dtype=np.float64)
        return kind, floats, np.zeros(0, np.int64)
    if kind == CONVEX_MESH:
        offsets, neighbours = shape.vertex_adjacency()
        ints = np.concatenate(([len(shape.vertices)], offsets, neighbours)).astype(np.int64)
        return kind, np.ascontiguousarray(shape.vertices, dtype=np.float64).ravel(), ints
    raise ValueError(f'shape kind {kind!r} has no support function')


@jit
def support(kind, floats, fo, ints, io, dx, dy, dz, start):
    """Farthest point of a convex shape along the direction (dx, dy, dz), local frame.

    Any magnitude of direction gives the exact point (``norms``: no component is squared
    unscaled); a zero or NaN direction gives some point of the shape, an infinite one its limit.
    ``start`` is the vertex a convex mesh starts its hill climb from (the previous answer is a
    good warm start); the returned index is the vertex found (-1 for primitives). Returns
    (x, y, z, index).
    """
    if kind == BOX:
        x = floats[fo] if dx >= 0.0 else -floats[fo]
        y = floats[fo + 1] if dy >= 0.0 else -floats[fo + 1]
        z = floats[fo + 2] if dz >= 0.0 else -floats[fo + 2]
        return x, y, z, -1
    if kind == SPHERE:
        r = floats[fo]
        ux, uy, uz = unit3(dx, dy, dz)
        if ux == 0.0 and uy == 0.0 and uz == 0.0:
            return r, 0.0, 0.0, -1
        return r * ux, r * uy, r * uz, -1
    if kind == CYLINDER:
        r = floats[fo]
        z = floats[fo + 1] if dz >= 0.0 else -floats[fo + 1]
        ux, uy = unit2(dx, dy)
        return r * ux, r * uy, z, -1
    if kind == CAPSULE:
        r = floats[fo]
        z = floats[fo + 1] if dz >= 0.0 else -floats[fo + 1]
        ux, uy, uz = unit3(dx, dy, dz)
        if ux == 0.0 and uy == 0.0 and uz == 0.0:
            return r, 0.0, z, -1
        return r * ux, r * uy, z + r * uz, -1
    if kind == POINT:
        return 0.0, 0.0, 0.0, -1
    if kind == SEGMENT:
        return 0.0, 0.0, floats[fo + 1] if dz >= 0.0 else -floats[fo + 1], -1
    sx, sy, sz = scaled3(dx, dy, dz)
    if kind == TRIANGLE:
        return _farthest_corner(floats, fo, sx, sy, sz)
    return _hill_climb(floats, fo, ints, io, sx, sy, sz, start)


@jit
def _farthest_corner(floats, fo, dx, dy, dz):
    """Support of a triangle: its corner farthest along d (first of equals)."""
    best, best_dot = 0, floats[fo] * dx + floats[fo + 1] * dy + floats[fo + 2] * dz
    for k in (1, 2):
        dot = floats[fo + 3 * k] * dx + floats[fo + 3 * k + 1] * dy + floats[fo + 3 * k + 2] * dz
        if dot > best_dot:
            best, best_dot = k, dot
    p = fo + 3 * best
    return floats[p], floats[p + 1], floats[p + 2], best


@jit
def _hill_climb(floats, fo, ints, io, dx, dy, dz, start):
    """Support vertex of a convex polytope by steepest ascent on its vertex graph.

    The direction's largest component must be about 1 (``norms.scaled3``), so that no dot
    product underflows or overflows. On a convex polytope a vertex with no better neighbour is
    a global maximum, so the climb is exact; from the previous support vertex it takes a few
    steps.
    """
    n = ints[io]
    offsets = io + 1
    neighbours = io + n + 2
    best = start if 0 <= start < n else 0
    best_dot = (floats[fo + 3 * best] * dx + floats[fo + 3 * best + 1] * dy
                + floats[fo + 3 * best + 2] * dz)
    improved = True
    while improved:
        improved = False
        for k in range(ints[offsets + best], ints[offsets + best + 1]):
            j = ints[neighbours + k]
            p = fo + 3 * j
            dot = floats[p] * dx + floats[p + 1] * dy + floats[p + 2] * dz
            if dot > best_dot:
                best_dot = dot
                best = j
                improved = True
    return floats[fo + 3 * best], floats[fo + 3 * best + 1], floats[fo + 3 * best + 2], best


@jit
def interior(kind, floats, fo, qx, qy, qz):
    """Exact signed distance of a point inside (or on) a primitive, with its surface witness.

    Valid where the returned distance is <= 0 (it is then exact); outside it is only a lower
    bound for the box and the cylinder, whose outside distance GJK computes. The distance to the
    nearest face (box, cylinder) or to the axis (sphere, capsule) is the penetration depth.
    Returns (distance, closest x, y, z, outward unit normal x, y, z), local frame, m.
    """
    if kind == BOX:
        return _box_interior(floats[fo], floats[fo + 1], floats[fo + 2], qx, qy, qz)
    if kind == CYLINDER:
        return _cylinder_interior(floats[fo], floats[fo + 1], qx, qy, qz)
    r = floats[fo]
    cz = 0.0
    if kind == CAPSULE:
        cz = min(max(qz, -floats[fo + 1]), floats[fo + 1])
    norm = norm3(qx, qy, qz - cz)
    nx, ny, nz = unit3(qx, qy, qz - cz)
    if nx == 0.0 and ny == 0.0 and nz == 0.0:
        nx = 1.0
    return norm - r, r * nx, r * ny, cz + r * nz, nx, ny, nz


@jit
def _box_interior(hx, hy, hz, qx, qy, qz):
    ex = abs(qx) - hx
    ey = abs(qy) - hy
    ez = abs(qz) - hz
    x, y, z = qx, qy, qz
    if ex >= ey and ex >= ez:
        sx = 1.0 if qx >= 0.0 else -1.0
        return ex, sx * hx, y, z, sx, 0.0, 0.0
    if ey >= ez:
        sy = 1.0 if qy >= 0.0 else -1.0
        return ey, x, sy * hy, z, 0.0, sy, 0.0
    sz = 1.0 if qz >= 0.0 else -1.0
    return ez, x, y, sz * hz, 0.0, 0.0, sz


@jit
def _cylinder_interior(r, hh, qx, qy, qz):
    e_side = norm2(qx, qy) - r
    e_cap = abs(qz) - hh
    if e_cap >= e_side:
        sz = 1.0 if qz >= 0.0 else -1.0
        return e_cap, qx, qy, sz * hh, 0.0, 0.0, sz
    ux, uy = unit2(qx, qy)
    if ux == 0.0 and uy == 0.0:
        ux = 1.0
    return e_side, r * ux, r * uy, qz, ux, uy, 0.0


@jit
def _support_point(kind, floats, ints, dx, dy, dz):
    x, y, z, _ = support(kind, floats, 0, ints, 0, dx, dy, dz, 0)
    return x, y, z


def support_point(kind: int, floats: np.ndarray, ints: np.ndarray,
                  direction: np.ndarray) -> np.ndarray:
    """Support point of one packed shape (see :func:`pack_convex`), for the Python API.

    Parameters
    ----------
    direction : (3,) float, local frame
        Need not be unit; zero gives some point of the shape.

    Returns
    -------
    (3,) float64, m, local frame
    """
    dx, dy, dz = (float(c) for c in direction)
    return np.array(_support_point(kind, floats, ints, dx, dy, dz))
