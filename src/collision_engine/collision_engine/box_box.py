"""The penetration depth of two overlapping boxes in closed form, compiled: EPA's answer, cheaper.

Two convex polytopes in contact overlap by the distance from the origin to the surface of their
Minkowski difference ``C = A - B``: the least of C's support function over C's facet normals.
Every facet normal of the difference of two boxes is a face normal of one of them or the cross
product of an edge direction of each (3 + 3 + 9 axes), and along any unit axis u the support of
C is the boxes' overlap along u: the sum of their half widths along u less the distance between
their centres along it. So the depth is the least overlap over those 15 axes, that axis turned
from A toward B is the normal, and the witness is where the boxes' deepest features along it
meet once B is moved out by the depth:

* a face axis of one box: the other box's deepest feature along it (a vertex, or an edge
  parallel to the face), clipped to the face's rectangle; the witness is the middle of what
  remains;
* an edge-edge axis: the point of A's edge nearest B's edge.

Where the closed form would not be exact to rounding it declines, and EPA answers: an edge-edge
axis from edges within ``CONDITION`` of parallel (its direction, hence its overlap, carries the
rounding of the cross product divided by its length, and skipping it could miss the facet), a
deepest feature that is a face (face on face: the witness is a polygon's), a witness off the
features it should lie on (rounding at a corner), or no overlap at all (touching to rounding:
GJK's contact, which EPA measures).
"""

import math

from collision_engine._jit import jit
from collision_engine.vector3 import cross3, dot3

__all__ = ['CONDITION', 'box_box_depth']

CONDITION = 1e-4  # least |e x f| of an edge-edge axis: its overlap is then exact to ~1e-12 size
_TIE = 1e-12  # a box axis this near perpendicular to the normal: its deepest feature is an edge
_SLACK = 1e-12  # relative: how far off its features rounding may put a witness


@jit
def _half_width(half, axes, u):
    """Return a box's half width along u (half extents; axes: three unit vectors)."""
    return (half[0] * abs(dot3(axes[0], u)) + half[1] * abs(dot3(axes[1], u))
            + half[2] * abs(dot3(axes[2], u)))


@jit
def _overlap(half_a, axes_a, half_b, axes_b, t, u):
    """Return the boxes' overlap along u (unit), and the sign that turns u from A toward B."""
    along = dot3(t, u)
    width = _half_width(half_a, axes_a, u) + _half_width(half_b, axes_b, u)
    return width - abs(along), 1.0 if along >= 0.0 else -1.0


@jit
def _deepest_feature(half, axes, centre, n):
    """Return the box's farthest feature along n: (ok, middle, free axis or -1).

    A box axis within ``_TIE`` of perpendicular to n leaves an edge along it; two leave a face
    (ok false).
    """
    mx, my, mz = centre
    free = -1
    for k in range(3):
        c = dot3(axes[k], n)
        if abs(c) <= _TIE:
            if free >= 0:
                return False, centre, -1
            free = k
            continue
        s = half[k] if c > 0.0 else -half[k]
        mx, my, mz = mx + s * axes[k][0], my + s * axes[k][1], mz + s * axes[k][2]
    return True, (mx, my, mz), free


@jit
def _narrow(lo, hi, offset, slope, half):
    """Narrow [lo, hi] to the parameters s with |offset + s slope| <= half."""
    if slope == 0.0:
        return (lo, hi) if abs(offset) <= half else (math.inf, -math.inf)
    a, b = (-half - offset) / slope, (half - offset) / slope
    return max(lo, min(a, b)), min(hi, max(a, b))


@jit
def _on_face(face_half, face_axes, face_centre, k, feature_half, feature_axes, middle, free,
             scale):
    """Clip the other box's deepest feature to face k's rectangle: (ok, witness on the feature).

    The feature is ``middle`` plus s times its free axis (|s| within its half extent; a vertex
    when there is none); the face box's other two axes bound it.
    """
    lo = hi = 0.0
    u = (0.0, 0.0, 0.0)
    if free >= 0:
        lo, hi, u = -feature_half[free], feature_half[free], feature_axes[free]
    slack = _SLACK * scale
    for j in range(3):
        if j != k:
            offset = dot3((middle[0] - face_centre[0], middle[1] - face_centre[1],
                           middle[2] - face_centre[2]), face_axes[j])
            lo, hi = _narrow(lo, hi, offset, dot3(u, face_axes[j]), face_half[j] + slack)
    if not lo <= hi:
        return False, middle
    s = 0.5 * (lo + hi)
    return True, (middle[0] + s * u[0], middle[1] + s * u[1], middle[2] + s * u[2])


@jit
def _edges_meet(half_a, axes_a, half_b, axes_b, t, i, j, n, scale):
    """Return the point of A's deepest edge (axis i) nearest B's (axis j): (ok, point).

    Once B is moved out along n the two edges touch there; each must be the deepest feature of
    its box along n, and the point within both edges.
    """
    ok_a, m_a, free_a = _deepest_feature(half_a, axes_a, (0.0, 0.0, 0.0), n)
    ok_b, m_b, free_b = _deepest_feature(half_b, axes_b, t, (-n[0], -n[1], -n[2]))
    if not (ok_a and ok_b and free_a == i and free_b == j):
        return False, m_a
    e, f = axes_a[i], axes_b[j]
    d = (m_b[0] - m_a[0], m_b[1] - m_a[1], m_b[2] - m_a[2])
    c = dot3(e, f)
    sin2 = 1.0 - c * c
    lam = (dot3(e, d) - c * dot3(f, d)) / sin2
    mu = (c * dot3(e, d) - dot3(f, d)) / sin2
    slack = _SLACK * scale
    if abs(lam) > half_a[i] + slack or abs(mu) > half_b[j] + slack:
        return False, m_a
    return True, (m_a[0] + lam * e[0], m_a[1] + lam * e[1], m_a[2] + lam * e[2])


@jit
def _witness(half_a, axes_a, half_b, axes_b, t, kind, first, second, n, depth, scale):
    """Return the witness on A for the least overlap's axis (module docstring): (ok, point).

    ``kind`` is 1 for A's face axis ``first``, 2 for B's, 3 for the edge-edge axis of A's axis
    ``first`` and B's ``second``.
    """
    origin = (0.0, 0.0, 0.0)
    if kind == 1:
        ok, middle, free = _deepest_feature(half_b, axes_b, t, (-n[0], -n[1], -n[2]))
        if not ok:
            return False, origin
        ok, p = _on_face(half_a, axes_a, origin, first, half_b, axes_b, middle, free, scale)
        return ok, (p[0] + depth * n[0], p[1] + depth * n[1], p[2] + depth * n[2])
    if kind == 2:
        ok, middle, free = _deepest_feature(half_a, axes_a, origin, n)
        if not ok:
            return False, origin
        return _on_face(half_b, axes_b, t, first, half_a, axes_a, middle, free, scale)
    return _edges_meet(half_a, axes_a, half_b, axes_b, t, first, second, n, scale)


@jit
def box_box_depth(half_a, half_b, rel):
    """Return the depth of box B in box A, B posed by ``rel`` in A's frame (module doc).

    ``half_a`` and ``half_b`` are the half extents (3-tuples), ``rel`` (12,) B's pose in A's
    frame (``gjk.support_difference``). Returns (ok, depth, witness on A x, y, z, normal x, y,
    z), A's frame, m: the normal is the direction B must move along, by the depth, to leave A;
    ok false where the closed form declines (then nothing else is meaningful).
    """
    axes_a = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    axes_b = ((rel[0], rel[3], rel[6]), (rel[1], rel[4], rel[7]), (rel[2], rel[5], rel[8]))
    t = (rel[9], rel[10], rel[11])
    scale = max(half_a[0], half_a[1], half_a[2], half_b[0], half_b[1], half_b[2])
    depth, kind, first, second = math.inf, 0, 0, 0
    n = (0.0, 0.0, 0.0)
    for k in range(3):
        for face, axis in ((1, axes_a[k]), (2, axes_b[k])):
            o, s = _overlap(half_a, axes_a, half_b, axes_b, t, axis)
            if o < depth:
                depth, kind, first, n = o, face, k, (s * axis[0], s * axis[1], s * axis[2])
    for i in range(3):
        for j in range(3):
            w = cross3(axes_a[i], axes_b[j])
            length = math.sqrt(dot3(w, w))
            if length < CONDITION:
                return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
            u = (w[0] / length, w[1] / length, w[2] / length)
            o, s = _overlap(half_a, axes_a, half_b, axes_b, t, u)
            if o < depth:
                depth, kind, first, second = o, 3, i, j
                n = (s * u[0], s * u[1], s * u[2])
    if not depth >= 0.0:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    ok, a = _witness(half_a, axes_a, half_b, axes_b, t, kind, first, second, n, depth, scale)
    return ok, depth, a[0], a[1], a[2], n[0], n[1], n[2]
