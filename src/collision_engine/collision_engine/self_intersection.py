"""Whether a closed triangle mesh crosses or touches itself, compiled (no FCL needed).

A surface that meets itself has no inside to sign the distance by, so a mesh that does is
refused at load time. Each triangle's box is matched against an AABB tree of the mesh
(``bvh.build_tree``), and every pair of triangles whose boxes overlap is tested:

* sharing an edge, two triangles meet along it; beyond it only when folded flat onto each
  other (coplanar, their third corners on the same side of the edge);
* sharing one corner p, they meet beyond p exactly when some direction from p points into both
  (their intersection is convex and holds p): the line where their planes cross, one way or the
  other, must lie in both corner angles at p; coplanar, the two angles must overlap;
* sharing nothing, they meet when an edge of one meets the other triangle (the ends of the
  segment two crossing triangles share lie on their edges, Moeller 1997), or, coplanar, when two
  edges cross or a corner of one lies in the other (Guigue and Devillers 2003).

Touching counts as meeting. The tests are orientation predicates (signs of 3x3 determinants)
in float64, not exact ones: a contact within rounding of the mesh (about 1e-16 of its size) can
go either way.
"""

import numpy as np

from collision_engine._jit import jit
from collision_engine.bvh import build_tree, tree_depth
from collision_engine.vector3 import cross3, dot3

__all__ = ['self_intersections']


def self_intersections(vertices: np.ndarray, faces: np.ndarray) -> tuple[int, int, int]:
    """Count the pairs of triangles that cross or touch other than along shared features.

    Parameters
    ----------
    vertices : (n, 3) float, m
        Welded: a corner shared by several faces is one row.
    faces : (m, 3) int
        No zero-area face.

    Returns
    -------
    count : int
        Pairs of faces that meet where they should not.
    first, second : int
        The first such pair (lowest indices, first < second), or (-1, -1).
    """
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    corners = np.ascontiguousarray(np.asarray(vertices, dtype=np.float64)[faces])
    order, boxes, nodes = build_tree(corners)
    face_boxes = np.concatenate((corners.min(axis=1), corners.max(axis=1)), axis=1)
    stack = np.empty(tree_depth(nodes) + 1, dtype=np.int64)
    return _self_intersections(corners, faces, face_boxes, order, np.ascontiguousarray(boxes),
                               nodes, stack)


@jit
def _self_intersections(corners, faces, face_boxes, order, boxes, nodes, stack):
    count, first, second = 0, -1, -1
    for t in range(len(faces)):
        low, high = face_boxes[t, :3], face_boxes[t, 3:]
        stack[0] = 0
        top = 1
        while top > 0:
            top -= 1
            node = stack[top]
            if not _overlap(low, high, boxes[node, :3], boxes[node, 3:]):
                continue
            child = nodes[node, 0]
            if child >= 0:
                stack[top] = child
                stack[top + 1] = child + 1
                top += 2
                continue
            for k in range(nodes[node, 1], nodes[node, 1] + nodes[node, 2]):
                u = order[k]
                if u <= t:
                    continue
                if (_overlap(low, high, face_boxes[u, :3], face_boxes[u, 3:])
                        and _faces_meet(corners, faces, t, u)):
                    count += 1
                    if first < 0 or (t == first and u < second):
                        first, second = t, u
    return count, first, second


@jit
def _overlap(low, high, other_low, other_high):
    """Tell whether two closed boxes overlap (touching counts)."""
    for axis in range(3):
        if low[axis] > other_high[axis] or other_low[axis] > high[axis]:
            return False
    return True


@jit
def _faces_meet(corners, faces, t, u):
    """Whether faces t and u meet anywhere but along the corners or the edge they share."""
    shared = 0
    t_at, u_at = -1, -1  # a shared corner's position in each face
    for i in range(3):
        for j in range(3):
            if faces[t, i] == faces[u, j]:
                shared += 1
                t_at, u_at = i, j
    a, b = corners[t], corners[u]
    if shared == 0:
        return _triangles_meet(a, b)
    if shared == 1:
        return _meet_beyond_corner(a, t_at, b, u_at)
    if shared == 2:
        return _folded_onto_each_other(a, b, faces[t], faces[u])
    return True  # the same three corners twice


@jit
def _orient(a, b, c, d):
    """Six times the signed volume of the tetrahedron a b c d: the side of plane abc d is on."""
    ux, uy, uz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    vx, vy, vz = c[0] - a[0], c[1] - a[1], c[2] - a[2]
    wx, wy, wz = d[0] - a[0], d[1] - a[1], d[2] - a[2]
    return ux * (vy * wz - vz * wy) - uy * (vx * wz - vz * wx) + uz * (vx * wy - vy * wx)


@jit
def _minus(p, q):
    return p[0] - q[0], p[1] - q[1], p[2] - q[2]


@jit
def _strictly_one_side(s0, s1, s2):
    return (s0 > 0.0 and s1 > 0.0 and s2 > 0.0) or (s0 < 0.0 and s1 < 0.0 and s2 < 0.0)


@jit
def _triangles_meet(a, b):
    """Whether triangles a and b (3, 3), sharing no corner, meet."""
    s0 = _orient(a[0], a[1], a[2], b[0])
    s1 = _orient(a[0], a[1], a[2], b[1])
    s2 = _orient(a[0], a[1], a[2], b[2])
    if _strictly_one_side(s0, s1, s2):
        return False
    if s0 == 0.0 and s1 == 0.0 and s2 == 0.0:
        return _coplanar_triangles_meet(a, b)
    if _strictly_one_side(_orient(b[0], b[1], b[2], a[0]), _orient(b[0], b[1], b[2], a[1]),
                          _orient(b[0], b[1], b[2], a[2])):
        return False
    for k in range(3):
        if (_segment_meets_triangle(a[k], a[(k + 1) % 3], b)
                or _segment_meets_triangle(b[k], b[(k + 1) % 3], a)):
            return True
    return False


@jit
def _segment_meets_triangle(p, q, t):
    """Whether the segment p q meets triangle t (3, 3), which is not in the segment's plane."""
    sp, sq = _orient(t[0], t[1], t[2], p), _orient(t[0], t[1], t[2], q)
    if (sp > 0.0 and sq > 0.0) or (sp < 0.0 and sq < 0.0) or (sp == 0.0 and sq == 0.0):
        return False
    # The segment crosses the plane; it meets the triangle where its line passes inside all
    # three edges, i.e. where the line's orientation about every edge has one sign.
    e0, e1, e2 = _orient(p, q, t[0], t[1]), _orient(p, q, t[1], t[2]), _orient(p, q, t[2], t[0])
    return (e0 >= 0.0 and e1 >= 0.0 and e2 >= 0.0) or (e0 <= 0.0 and e1 <= 0.0 and e2 <= 0.0)


@jit
def _drop_axis(a):
    """Find the axis along which triangle a (3, 3) has its largest normal component."""
    n = cross3(_minus(a[1], a[0]), _minus(a[2], a[0]))
    axis = 0
    if abs(n[1]) > abs(n[axis]):
        axis = 1
    if abs(n[2]) > abs(n[axis]):
        axis = 2
    return axis


@jit
def _orient2(a, b, c, i, j):
    """Twice the signed area of a b c in the plane of coordinates i and j."""
    return (b[i] - a[i]) * (c[j] - a[j]) - (b[j] - a[j]) * (c[i] - a[i])


@jit
def _segments_meet2(p, q, r, s, i, j):
    """Whether the segments p q and r s, in the plane of coordinates i, j, meet."""
    d1, d2 = _orient2(r, s, p, i, j), _orient2(r, s, q, i, j)
    d3, d4 = _orient2(p, q, r, i, j), _orient2(p, q, s, i, j)
    if (((d1 > 0.0 and d2 < 0.0) or (d1 < 0.0 and d2 > 0.0))
            and ((d3 > 0.0 and d4 < 0.0) or (d3 < 0.0 and d4 > 0.0))):
        return True
    return ((d1 == 0.0 and _between2(r, s, p, i, j)) or (d2 == 0.0 and _between2(r, s, q, i, j))
            or (d3 == 0.0 and _between2(p, q, r, i, j))
            or (d4 == 0.0 and _between2(p, q, s, i, j)))


@jit
def _between2(p, q, r, i, j):
    """Whether r, collinear with p q, lies on the segment (within its box)."""
    return (min(p[i], q[i]) <= r[i] <= max(p[i], q[i])
            and min(p[j], q[j]) <= r[j] <= max(p[j], q[j]))


@jit
def _inside2(t, p, i, j):
    """Whether p lies in the closed triangle t, in the plane of coordinates i, j."""
    e0, e1, e2 = (_orient2(t[0], t[1], p, i, j), _orient2(t[1], t[2], p, i, j),
                  _orient2(t[2], t[0], p, i, j))
    return (e0 >= 0.0 and e1 >= 0.0 and e2 >= 0.0) or (e0 <= 0.0 and e1 <= 0.0 and e2 <= 0.0)


@jit
def _coplanar_triangles_meet(a, b):
    """Whether coplanar triangles a and b meet: two edges cross or a corner is inside."""
    axis = _drop_axis(a)
    i, j = (axis + 1) % 3, (axis + 2) % 3
    for k in range(3):
        for m in range(3):
            if _segments_meet2(a[k], a[(k + 1) % 3], b[m], b[(m + 1) % 3], i, j):
                return True
    return _inside2(a, b[0], i, j) or _inside2(b, a[0], i, j)


@jit
def _in_angle(u, v, w):
    """Whether direction w lies in the closed angle (< 180 degrees) between u and v.

    w must lie in the plane of u and v.
    """
    n = cross3(u, v)
    return dot3(cross3(u, w), n) >= 0.0 and dot3(cross3(w, v), n) >= 0.0


@jit
def _meet_beyond_corner(a, i, b, j):
    """Whether triangles a and b (3, 3) that share only a corner p meet anywhere but at p.

    p is a's corner i and b's corner j.
    """
    u1, v1 = _minus(a[(i + 1) % 3], a[i]), _minus(a[(i + 2) % 3], a[i])
    u2, v2 = _minus(b[(j + 1) % 3], b[j]), _minus(b[(j + 2) % 3], b[j])
    d = cross3(cross3(u1, v1), cross3(u2, v2))
    if d[0] == 0.0 and d[1] == 0.0 and d[2] == 0.0:  # coplanar: do the corner angles overlap?
        return (_in_angle(u1, v1, u2) or _in_angle(u1, v1, v2) or _in_angle(u2, v2, u1)
                or _in_angle(u2, v2, v1))
    minus_d = (-d[0], -d[1], -d[2])
    return ((_in_angle(u1, v1, d) and _in_angle(u2, v2, d))
            or (_in_angle(u1, v1, minus_d) and _in_angle(u2, v2, minus_d)))


@jit
def _apex(face, other):
    """Position in ``face`` of its corner that ``other`` lacks (they share the other two)."""
    for k in range(3):
        if face[k] != other[0] and face[k] != other[1] and face[k] != other[2]:
            return k
    return 0


@jit
def _folded_onto_each_other(a, b, face_a, face_b):
    """Whether triangles sharing an edge lie flat on each other (coplanar, same side of it)."""
    k = _apex(face_a, face_b)
    apex_a, p, q = a[k], a[(k + 1) % 3], a[(k + 2) % 3]
    apex_b = b[_apex(face_b, face_a)]
    if _orient(p, q, apex_a, apex_b) != 0.0:
        return False
    edge = _minus(q, p)
    return dot3(cross3(edge, _minus(apex_a, p)), cross3(edge, _minus(apex_b, p))) > 0.0
