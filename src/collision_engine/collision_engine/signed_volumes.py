"""Nearest point of a simplex to the origin by signed volumes, compiled: GJK's sub-algorithm.

The method of Montanari, Petrinic and Barbieri (2017, ACM TOG 36(3) 32): barycentric
coordinates as ratios of signed volumes (tetrahedron), areas (triangle, in the coordinate plane
where it is largest) and lengths (segment), which its authors show to be more accurate and robust
than Johnson's dot-product recursion on near-degenerate simplices. Each step is a closed form;
``closest_point_on_triangle`` is the triangle step on its own, which the mesh search applies to
every candidate triangle.
"""

import numpy as np

from collision_engine._jit import jit

__all__ = ['closest_point_on_triangle', 'nearest_on_simplex', 'nearest_weights_on_triangle']


@jit
def _same_sign(a, b):
    return (a > 0.0 and b > 0.0) or (a < 0.0 and b < 0.0)


@jit
def _s1d(ax, ay, az, bx, by, bz):
    """Nearest point to the origin on the segment a b.

    Returns (count, first, second, lambda_first, vx, vy, vz): the support set as local indices
    (0 for a, 1 for b; ``second`` is -1 when it is one vertex), the weight of ``first`` (the
    other weight is 1 - lambda_first) and the nearest point.
    """
    tx, ty, tz = bx - ax, by - ay, bz - az
    tt = tx * tx + ty * ty + tz * tz
    if tt == 0.0:
        return 1, 0, -1, 1.0, ax, ay, az
    s = -(ax * tx + ay * ty + az * tz) / tt
    px, py, pz = ax + s * tx, ay + s * ty, az + s * tz
    # Signed lengths along the axis where the segment is longest.
    if abs(tx) >= abs(ty) and abs(tx) >= abs(tz):
        a_k, b_k, p_k = ax, bx, px
    elif abs(ty) >= abs(tz):
        a_k, b_k, p_k = ay, by, py
    else:
        a_k, b_k, p_k = az, bz, pz
    mu = a_k - b_k
    c_first = p_k - b_k
    c_second = a_k - p_k
    if _same_sign(mu, c_first) and _same_sign(mu, c_second):
        la = c_first / mu
        lb = 1.0 - la
        return 2, 0, 1, la, la * ax + lb * bx, la * ay + lb * by, la * az + lb * bz
    if _same_sign(mu, c_first):
        return 1, 0, -1, 1.0, ax, ay, az
    return 1, 1, -1, 1.0, bx, by, bz


@jit
def _cross_k(ux, uy, uz, wx, wy, wz, k):
    """Component k of u x w: the signed area of (0, u, w) seen along axis k (doubled)."""
    if k == 0:
        return uy * wz - uz * wy
    if k == 1:
        return uz * wx - ux * wz
    return ux * wy - uy * wx


@jit
def _s2d(ax, ay, az, bx, by, bz, cx, cy, cz):
    """Nearest point to the origin on the triangle a b c.

    Returns (count, i0, i1, i2, l0, l1, l2, vx, vy, vz): the support set as local indices in
    increasing order (0 a, 1 b, 2 c; unused slots -1), their weights and the nearest point.
    """
    # No point of the triangle is nearer than its nearest point, nor farther than a corner:
    # the consistency check that catches rounding on slivers.
    corner2 = min(ax * ax + ay * ay + az * az, bx * bx + by * by + bz * bz,
                  cx * cx + cy * cy + cz * cz)
    ux, uy, uz = bx - ax, by - ay, bz - az
    wx, wy, wz = cx - ax, cy - ay, cz - az
    nx, ny, nz = uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx
    nn = nx * nx + ny * ny + nz * nz
    c0 = c1 = c2 = mu = 0.0
    if nn > 0.0:
        scale = (ax * nx + ay * ny + az * nz) / nn
        px, py, pz = scale * nx, scale * ny, scale * nz
        # Signed areas in the coordinate plane where the triangle's projection is largest.
        k, mu = 0, nx
        if abs(ny) > abs(mu):
            k, mu = 1, ny
        if abs(nz) > abs(mu):
            k, mu = 2, nz
        c0 = _cross_k(bx - px, by - py, bz - pz, cx - px, cy - py, cz - pz, k)
        c1 = _cross_k(cx - px, cy - py, cz - pz, ax - px, ay - py, az - pz, k)
        c2 = _cross_k(ax - px, ay - py, az - pz, bx - px, by - py, bz - pz, k)
        if _same_sign(mu, c0) and _same_sign(mu, c1) and _same_sign(mu, c2):
            total = c0 + c1 + c2
            l0, l1, l2 = c0 / total, c1 / total, c2 / total
            vx = l0 * ax + l1 * bx + l2 * cx
            vy = l0 * ay + l1 * by + l2 * cy
            vz = l0 * az + l1 * bz + l2 * cz
            if vx * vx + vy * vy + vz * vz <= corner2:
                return 3, 0, 1, 2, l0, l1, l2, vx, vy, vz
    # The projection is outside (or the triangle is degenerate): the nearest point is on an
    # edge facing the origin, one opposite a vertex whose signed area has the wrong sign.
    result = _nearest_edge(ax, ay, az, bx, by, bz, cx, cy, cz, mu, c0, c1, c2, False)
    if result[7] ** 2 + result[8] ** 2 + result[9] ** 2 > corner2:
        # Farther than a corner: on a sliver, rounding tilted the plane or flipped a sign.
        # No cheap test is left to trust, so every edge is tried.
        result = _nearest_edge(ax, ay, az, bx, by, bz, cx, cy, cz, mu, c0, c1, c2, True)
    return result


@jit
def _nearest_edge(ax, ay, az, bx, by, bz, cx, cy, cz, mu, c0, c1, c2, every):
    """Nearest point on the edges facing the origin (``every``: on all three edges).

    Returns the ``_s2d`` result tuple.
    """
    best = np.inf
    result = (1, 0, -1, -1, 1.0, 0.0, 0.0, ax, ay, az)
    if every or not _same_sign(mu, c0):
        n, f, s, lf, vx, vy, vz = _s1d(bx, by, bz, cx, cy, cz)
        best = vx * vx + vy * vy + vz * vz
        result = (n, f + 1, s + 1 if s >= 0 else -1, -1, lf, 1.0 - lf, 0.0, vx, vy, vz)
    if every or not _same_sign(mu, c1):
        n, f, s, lf, vx, vy, vz = _s1d(ax, ay, az, cx, cy, cz)
        dist = vx * vx + vy * vy + vz * vz
        if dist < best:
            best = dist
            result = (n, 2 * f, 2 if s >= 0 else -1, -1, lf, 1.0 - lf, 0.0, vx, vy, vz)
    if every or not _same_sign(mu, c2):
        n, f, s, lf, vx, vy, vz = _s1d(ax, ay, az, bx, by, bz)
        dist = vx * vx + vy * vy + vz * vz
        if dist < best:
            result = (n, f, s, -1, lf, 1.0 - lf, 0.0, vx, vy, vz)
    return result


@jit
def _vertex(W, i):
    """Row i of the flat (4 x 3, row-major) simplex W."""
    return W[3 * i], W[3 * i + 1], W[3 * i + 2]


@jit
def _put(W, i, x, y, z):
    W[3 * i], W[3 * i + 1], W[3 * i + 2] = x, y, z


@jit
def _det3(W, i, j, k):
    ax, ay, az = _vertex(W, i)
    bx, by, bz = _vertex(W, j)
    cx, cy, cz = _vertex(W, k)
    return ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx)


@jit
def _face_s2d(W, i, j, k):
    """``_s2d`` on the rows i < j < k of W, with the support set as rows of W."""
    ax, ay, az = _vertex(W, i)
    bx, by, bz = _vertex(W, j)
    cx, cy, cz = _vertex(W, k)
    n, a, b, c, la, lb, lc, vx, vy, vz = _s2d(ax, ay, az, bx, by, bz, cx, cy, cz)
    rows = (i, j, k)
    return (n, rows[a], rows[b] if b >= 0 else -1, rows[c] if c >= 0 else -1,
            la, lb, lc, vx, vy, vz)


@jit
def _s3d(W):
    """Nearest point to the origin on the tetrahedron W[0..3].

    Returns (count, v0, v1, v2, v3, l0, l1, l2, l3, vx, vy, vz) with the support set as rows
    of W; count 4 means the origin is inside and v = 0.
    """
    c0 = _det3(W, 1, 2, 3)
    c1 = -_det3(W, 0, 2, 3)
    c2 = _det3(W, 0, 1, 3)
    c3 = -_det3(W, 0, 1, 2)
    det = c0 + c1 + c2 + c3
    if (_same_sign(det, c0) and _same_sign(det, c1) and _same_sign(det, c2)
            and _same_sign(det, c3)):
        return 4, 0, 1, 2, 3, c0 / det, c1 / det, c2 / det, c3 / det, 0.0, 0.0, 0.0
    result = _nearest_face(W, det, c0, c1, c2, c3, False)
    corner2 = min(W[0] ** 2 + W[1] ** 2 + W[2] ** 2, W[3] ** 2 + W[4] ** 2 + W[5] ** 2,
                  W[6] ** 2 + W[7] ** 2 + W[8] ** 2, W[9] ** 2 + W[10] ** 2 + W[11] ** 2)
    if result[9] ** 2 + result[10] ** 2 + result[11] ** 2 > corner2:
        # Farther than a corner: rounding flipped a sign on a sliver; try every face.
        result = _nearest_face(W, det, c0, c1, c2, c3, True)
    return result


@jit
def _nearest_face(W, det, c0, c1, c2, c3, every):
    """Nearest point on the faces facing the origin (``every``: on all four faces).

    Returns the ``_s3d`` result tuple.
    """
    best = np.inf
    result = (1, 0, -1, -1, -1, 1.0, 0.0, 0.0, 0.0, W[0], W[1], W[2])
    for slot in range(4):
        c = c0 if slot == 0 else (c1 if slot == 1 else (c2 if slot == 2 else c3))
        if not every and _same_sign(det, c):
            continue
        # The face opposite the vertex in this slot, its rows in increasing order.
        n, a, b, c_, la, lb, lc, vx, vy, vz = _face_s2d(
            W, 1 if slot == 0 else 0, 1 if slot >= 2 else 2, 2 if slot == 3 else 3)
        dist = vx * vx + vy * vy + vz * vz
        if dist < best:
            best = dist
            result = (n, a, b, c_, -1, la, lb, lc, 0.0, vx, vy, vz)
    return result


@jit
def nearest_on_simplex(W, count, A, track):
    """Reduce the simplex to the support set of its point nearest the origin.

    ``W`` is (12,): ``count`` vertices as rows of a row-major (4, 3) array. Its first
    ``new_count`` rows are rewritten with the support set; with ``track``, the rows of ``A``
    (12,) (what each vertex came from, e.g. one shape's support point) move with them.
    Returns (new_count, vx, vy, vz, l0, l1, l2, l3): v = sum of l_i times kept row i.
    """
    if count == 1:
        return 1, W[0], W[1], W[2], 1.0, 0.0, 0.0, 0.0
    if count == 2:
        n, a, b, la, vx, vy, vz = _s1d(W[0], W[1], W[2], W[3], W[4], W[5])
        _keep(W, a, b, -1, -1)
        if track:
            _keep(A, a, b, -1, -1)
        return n, vx, vy, vz, la, 1.0 - la, 0.0, 0.0
    if count == 3:
        n, a, b, c, la, lb, lc, vx, vy, vz = _face_s2d(W, 0, 1, 2)
        _keep(W, a, b, c, -1)
        if track:
            _keep(A, a, b, c, -1)
        return n, vx, vy, vz, la, lb, lc, 0.0
    n, a, b, c, d, la, lb, lc, ld, vx, vy, vz = _s3d(W)
    _keep(W, a, b, c, d)
    if track:
        _keep(A, a, b, c, d)
    return n, vx, vy, vz, la, lb, lc, ld


@jit
def _keep(W, a, b, c, d):
    """Move rows a, b, c, d (-1 = absent, present ones in increasing order) of W to the front."""
    slot = 0
    for index in (a, b, c, d):
        if index < 0:
            continue
        if index != slot:
            x, y, z = _vertex(W, index)
            _put(W, slot, x, y, z)
        slot += 1


@jit
def closest_point_on_triangle(ax, ay, az, bx, by, bz, cx, cy, cz):
    """Closest point of one triangle to the origin, in closed form, with its feature.

    Exact: the origin's projection onto the triangle's plane when the signed areas say it lies
    inside, else the nearest point of the edges facing the origin (``_s2d``). No iteration.

    Returns (squared distance, vx, vy, vz, feature, which) where feature is 3 (face), 2 (edge:
    ``which`` is the vertex opposite it) or 1 (vertex: ``which`` is the vertex).
    """
    n, i, j, k, li, lj, lk, vx, vy, vz = _s2d(ax, ay, az, bx, by, bz, cx, cy, cz)
    which = i
    if n == 2:
        which = 3 - i - j
    return vx * vx + vy * vy + vz * vz, vx, vy, vz, n, which


@jit
def nearest_weights_on_triangle(ax, ay, az, bx, by, bz, cx, cy, cz):
    """Barycentric weights (on a, b, c) of the triangle's point nearest the origin."""
    n, i, j, k, li, lj, lk, _, _, _ = _s2d(ax, ay, az, bx, by, bz, cx, cy, cz)
    weights = [0.0, 0.0, 0.0]
    weights[i] = li
    if n >= 2:
        weights[j] = lj
    if n == 3:
        weights[k] = lk
    return weights[0], weights[1], weights[2]
