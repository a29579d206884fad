"""EPA: penetration depth of two overlapping convex shapes (or a point inside one), compiled.

The expanding polytope algorithm (van den Bergen 2001) grows a polytope inside the Minkowski
difference ``C = A - B`` from GJK's final simplex, always pushing out its face nearest the origin
along that face's normal, until the support point no longer moves the face: the face then lies
on C's surface, its distance to the origin is the penetration depth and its normal n the
direction in which B must move (by the depth) to leave A. The origin's projection on that face,
weighed onto the support points of A its corners came from, is the witness on A. On polytopes
(convex meshes, boxes, triangles) the answer is exact up to rounding; on a curved support
(cylinders) EPA stops at the tolerance. A point inside a primitive does not come here: the
primitive's own exact interior distance is cheaper (``support.interior``).

The simplex GJK ends with when it detects contact can be a point, segment or triangle (the point
is on the surface, or within rounding of it); it is first blown up to a tetrahedron with support
points along directions that span the missing dimensions (as libccd and coal do).
"""

import numpy as np

from collision_engine._jit import jit
from collision_engine.gjk import STATUS_NOT_CONVERGED, STATUS_OK, support_difference
from collision_engine.norms import norm3, unit3
from collision_engine.signed_volumes import nearest_weights_on_triangle
from collision_engine.support import POINT

__all__ = ['epa', 'scratch_size']

_EPS = float(np.finfo(np.float64).eps)
_FLOOR = 16.0 * _EPS
_UNIT_AXES = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


@jit
def _support_scaled(a, b, rel, inv, dx, dy, dz):
    """Support point of ``inv (A - B)`` (GJK's scaled unit) and A's support point (m)."""
    wx, wy, wz, ax, ay, az, _, _ = support_difference(a, b, rel, dx, dy, dz, 0, 0)
    return wx * inv, wy * inv, wz * inv, ax, ay, az


@jit
def _off_affine_hull(V, count, x, y, z, tolerance):
    """Whether the point is farther than ``tolerance`` from the affine hull of V[:count]."""
    if count == 1:
        dx, dy, dz = x - V[0, 0], y - V[0, 1], z - V[0, 2]
        return dx * dx + dy * dy + dz * dz > tolerance * tolerance
    ux, uy, uz = V[1, 0] - V[0, 0], V[1, 1] - V[0, 1], V[1, 2] - V[0, 2]
    px, py, pz = x - V[0, 0], y - V[0, 1], z - V[0, 2]
    if count == 2:
        cx, cy, cz = uy * pz - uz * py, uz * px - ux * pz, ux * py - uy * px
        return cx * cx + cy * cy + cz * cz > tolerance * tolerance * (ux * ux + uy * uy + uz * uz)
    wx, wy, wz = V[2, 0] - V[0, 0], V[2, 1] - V[0, 1], V[2, 2] - V[0, 2]
    nx, ny, nz = uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx
    height = nx * px + ny * py + nz * pz
    return height * height > tolerance * tolerance * (nx * nx + ny * ny + nz * nz)


@jit
def _blow_up(a, b, rel, inv, V, VA, count, tolerance):
    """Grow the simplex V[:count] (A's points in VA) to a tetrahedron; returns its size."""
    while count < 4:
        grown = False
        for axis in range(3):
            ax, ay, az = _UNIT_AXES[axis]
            if count == 1:
                dx, dy, dz = ax, ay, az
            elif count == 2:
                ux, uy, uz = V[1, 0] - V[0, 0], V[1, 1] - V[0, 1], V[1, 2] - V[0, 2]
                dx, dy, dz = uy * az - uz * ay, uz * ax - ux * az, ux * ay - uy * ax
            else:
                ux, uy, uz = V[1, 0] - V[0, 0], V[1, 1] - V[0, 1], V[1, 2] - V[0, 2]
                wx, wy, wz = V[2, 0] - V[0, 0], V[2, 1] - V[0, 1], V[2, 2] - V[0, 2]
                dx, dy, dz = uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx
            if dx == 0.0 and dy == 0.0 and dz == 0.0:
                continue
            for sign in (1.0, -1.0):
                x, y, z, sx, sy, sz = _support_scaled(a, b, rel, inv, sign * dx, sign * dy,
                                                      sign * dz)
                if _off_affine_hull(V, count, x, y, z, tolerance):
                    V[count, 0], V[count, 1], V[count, 2] = x, y, z
                    VA[count, 0], VA[count, 1], VA[count, 2] = sx, sy, sz
                    count += 1
                    grown = True
                    break
            if grown:
                break
        if not grown:
            return count
    return count


@jit
def _set_face(V, F, N, D, f, a, b, c):
    """Store face f = (a, b, c) with its unit normal and signed distance from the origin."""
    F[f, 0], F[f, 1], F[f, 2] = a, b, c
    ux, uy, uz = V[b, 0] - V[a, 0], V[b, 1] - V[a, 1], V[b, 2] - V[a, 2]
    wx, wy, wz = V[c, 0] - V[a, 0], V[c, 1] - V[a, 1], V[c, 2] - V[a, 2]
    nx, ny, nz = unit3(uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx)
    if nx == 0.0 and ny == 0.0 and nz == 0.0:
        return False
    N[f, 0], N[f, 1], N[f, 2] = nx, ny, nz
    D[f] = nx * V[a, 0] + ny * V[a, 1] + nz * V[a, 2]
    return True


@jit
def _tetrahedron(V, F, N, D):
    """Set the four outward faces of the tetrahedron V[0..3]; false if it is flat."""
    ux, uy, uz = V[1, 0] - V[0, 0], V[1, 1] - V[0, 1], V[1, 2] - V[0, 2]
    wx, wy, wz = V[2, 0] - V[0, 0], V[2, 1] - V[0, 1], V[2, 2] - V[0, 2]
    tx, ty, tz = V[3, 0] - V[0, 0], V[3, 1] - V[0, 1], V[3, 2] - V[0, 2]
    volume = (ux * (wy * tz - wz * ty) - uy * (wx * tz - wz * tx) + uz * (wx * ty - wy * tx))
    if volume > 0.0:
        faces = ((0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3))
    else:
        faces = ((0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2))
    ok = True
    for f in range(4):
        a, b, c = faces[f]
        ok = _set_face(V, F, N, D, f, a, b, c) and ok
    return ok


@jit
def _expand(V, F, N, D, alive, edge_a, edge_b, n_faces, w, scale):
    """Replace the faces vertex w sees by faces from their horizon to w.

    Returns the new face count, or -1 when a new face is degenerate or there is no room.
    """
    wx, wy, wz = V[w, 0], V[w, 1], V[w, 2]
    n_edges = 0
    for f in range(n_faces):
        if alive[f] == 0:
            continue
        corner = F[f, 0]
        if (N[f, 0] * (wx - V[corner, 0]) + N[f, 1] * (wy - V[corner, 1])
                + N[f, 2] * (wz - V[corner, 2])) > _FLOOR * scale:
            alive[f] = 0
            for e in range(3):
                edge_a[n_edges] = F[f, e]
                edge_b[n_edges] = F[f, (e + 1) % 3]
                n_edges += 1
    for e in range(n_edges):
        shared = False
        for g in range(n_edges):
            if edge_a[g] == edge_b[e] and edge_b[g] == edge_a[e]:
                shared = True
                break
        if shared:
            continue
        if n_faces >= len(D) or not _set_face(V, F, N, D, n_faces, edge_a[e], edge_b[e], w):
            return -1
        alive[n_faces] = 1
        n_faces += 1
    return n_faces


@jit
def _witness(V, VA, F, f):
    """A's point under the origin's projection on face f: its weights on the face's corners."""
    i, j, k = F[f, 0], F[f, 1], F[f, 2]
    li, lj, lk = nearest_weights_on_triangle(V[i, 0], V[i, 1], V[i, 2], V[j, 0], V[j, 1],
                                             V[j, 2], V[k, 0], V[k, 1], V[k, 2])
    return (li * VA[i, 0] + lj * VA[j, 0] + lk * VA[k, 0],
            li * VA[i, 1] + lj * VA[j, 1] + lk * VA[k, 1],
            li * VA[i, 2] + lj * VA[j, 2] + lk * VA[k, 2])


@jit
def scratch_size(max_iter):
    """Scratch lengths ``epa`` needs for ``max_iter`` iterations: (floats, ints).

    With m = max_iter + 4 vertices at most (the tetrahedron, then one a step): floats hold the
    vertices (m, 3) and A's points they came from (m, 3), face normals (2m, 3) and face offsets
    (2m,); ints hold the faces (2m, 3), their alive flags (2m,) and the horizon's edge ends
    (6m,) twice.
    """
    m = max_iter + 4
    return 14 * m, 20 * m


@jit
def epa(a, b, rel, W, A, count, inv, rel_tol, abs_tol, max_iter, scratch_floats,
        scratch_ints):
    """Penetration of B into A, convex shapes, from GJK's contact simplex; A's frame.

    Parameters
    ----------
    a, b : packed shapes ``(kind, floats, fo, ints, io)``
    rel : (12,) float
        B's pose in A's frame (``gjk.support_difference``).
    W, A : (12,) float
        GJK's final simplex of ``inv C``, ``C = A - B`` (``count`` rows of a row-major (4, 3)
        array), which contains the origin, and A's support points it came from.
    inv : float
        GJK's power-of-two unit (``gjk.power_of_two_inverse``): EPA works in it too.
    scratch_floats, scratch_ints : float64 and int64 arrays
        Preallocated work space, at least ``scratch_size(max_iter)`` long: allocating it costs
        more than a short EPA run.

    Returns
    -------
    (status, depth, depth_bound, witness x, y, z, normal x, y, z, iterations), A's frame, m:
    the penetration depth lies in [depth, depth_bound] (equal to rounding when converged); the
    witness is the point of A's surface where B leaves it (for a point B: the point moved by
    ``depth`` along the normal), the normal the unit direction B must move along.
    """
    max_vertices = max_iter + 4
    m = max_vertices
    V = scratch_floats[:3 * m].reshape((m, 3))
    VA = scratch_floats[3 * m:6 * m].reshape((m, 3))
    N = scratch_floats[6 * m:12 * m].reshape((2 * m, 3))
    D = scratch_floats[12 * m:14 * m]
    F = scratch_ints[:6 * m].reshape((2 * m, 3))
    alive = scratch_ints[6 * m:8 * m]  # only faces below n_faces, each set when made, are read
    edge_a = scratch_ints[8 * m:14 * m]
    edge_b = scratch_ints[14 * m:20 * m]
    V[:count] = W[:3 * count].reshape((count, 3))
    VA[:count] = A[:3 * count].reshape((count, 3))
    abs_tol = abs_tol * inv
    scale = 0.0
    for k in range(count):
        scale = max(scale, norm3(V[k, 0], V[k, 1], V[k, 2]))
    x0, y0, z0, _, _, _ = _support_scaled(a, b, rel, inv, 1.0, 0.0, 0.0)
    x1, y1, z1, _, _, _ = _support_scaled(a, b, rel, inv, -1.0, 0.0, 0.0)
    scale = max(scale, abs(x0 - x1))
    count = _blow_up(a, b, rel, inv, V, VA, count, 1e-9 * scale)
    if count < 4 or not _tetrahedron(V, F, N, D):
        return (STATUS_NOT_CONVERGED, 0.0, np.inf, rel[9], rel[10], rel[11], 1.0, 0.0, 0.0,
                0)
    alive[:4] = 1
    n_vertices, n_faces = 4, 4
    status = STATUS_NOT_CONVERGED
    bound = np.inf
    iteration = 0
    best = 0
    while True:
        best = -1
        for f in range(n_faces):
            if alive[f] == 1 and (best < 0 or D[f] < D[best]):
                best = f
        nx, ny, nz, depth = N[best, 0], N[best, 1], N[best, 2], D[best]
        if iteration >= max_iter or n_vertices >= max_vertices:
            break
        iteration += 1
        wx, wy, wz, sx, sy, sz = _support_scaled(a, b, rel, inv, nx, ny, nz)
        bound = min(bound, nx * wx + ny * wy + nz * wz)
        gap = nx * wx + ny * wy + nz * wz - depth
        if gap <= max(rel_tol * abs(depth), abs_tol, _FLOOR * scale):
            status = STATUS_OK
            break
        w = n_vertices
        V[w, 0], V[w, 1], V[w, 2] = wx, wy, wz
        VA[w, 0], VA[w, 1], VA[w, 2] = sx, sy, sz
        n_vertices += 1
        n_faces = _expand(V, F, N, D, alive, edge_a, edge_b, n_faces, w, scale)
        if n_faces < 0:
            break
    depth, bound = depth / inv, max(bound, depth) / inv
    if b[0] == POINT:
        x, y, z = rel[9] + depth * nx, rel[10] + depth * ny, rel[11] + depth * nz
    else:
        x, y, z = _witness(V, VA, F, best)
    return status, depth, bound, x, y, z, nx, ny, nz, iteration
