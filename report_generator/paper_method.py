"""The paper's own collision code, re-implemented in plain Python and numpy for comparison only.

The paper's MATLAB Function block (atiandjf/HF2TS, ``q_5dof_wand_vr_sphere_collision_atia.mdl``,
function ``virtual_object``) answers each wand position with three pieces, rebuilt here one for
one so that its errors can be measured on our recorded trajectories:

* the collision flag: ``GJK_mod`` (M. Sheen's GJK, P. Lebel's fix), capped at 6 iterations,
  whose comment admits "a higher chance of false-NEGATIVES";
* the distance: ``GJK_dist`` (P. Lebel), a GJK that starts from the direction (1, 1, 1), only
  ever keeps a triangle, replaces the vertex farthest from the origin, measures the triangle
  with Eberly's point-triangle distance, stops when a new support point's norm is within 1e-6
  of a simplex vertex's norm, and after 10 passes gives up. At that cap it means to return the
  best triangle seen, but overwrites the saved best with the current one first (a bug, kept:
  ``PaperDistance.best_distance`` says what it threw away). No EPA: the distance is unsigned,
  and inside the object it is the distance to some triangle of hull vertices;
* the force: ``F = (r/|r|) k dist - kd v`` with ``r = tip - centroid``, when the flag is set,
  zero otherwise; ``k`` is the first axis' stiffness, ``kd`` per axis, ``centroid`` the plain
  mean of the STL vertex rows, duplicates included.

The support of every GJK scans all vertex rows (``getFarthestInDir``), so every mesh is its
convex hull. Rows are kept unique here, in order of first appearance: the scan returns the same
vertex (MATLAB's ``max`` and numpy's ``argmax`` both take the first of equal maxima, and an
earlier copy of a vertex ties with any later one), in a sixth of the time for an STL.

Where the MATLAB code would not finish, the most literal reading is kept and the outcome said:
its ``while true`` that replaces a duplicated first triangle vertex by the support in ``-d``
loops forever when that support is also a duplicate; here it returns NaN with outcome
``'hang'``. Divisions follow IEEE (MATLAB) rules, not Python's ``ZeroDivisionError``. Units
are the caller's (metres in this repository); frames are the vertex rows' frame.
"""

from dataclasses import dataclass
import math
from pathlib import Path
from typing import Callable, NamedTuple

import numpy as np

__all__ = ['COLLISION_ITERATIONS', 'DISTANCE_ITERATION_CAP', 'PaperAnswer', 'PaperDistance',
           'PaperMethod', 'stl_vertex_rows']

COLLISION_ITERATIONS = 6  # ``iterationsAllowed`` of the collision flag's GJK
DISTANCE_ITERATION_CAP = 10  # ``GJK_dist`` gives up once its pass counter exceeds this
FLAG_PASS = 6  # ``GJK_dist`` sets its flag once its pass counter exceeds this ...
FALLBACK_PASS = 5  # ... and, flagged, tries its edge-based direction on passes above this
CONVERGED_NORM = 1e-6  # a support point whose norm is this close to a vertex's ends the search
FIRST_DIRECTION = (1.0, 1.0, 1.0)
COLLISION_DIRECTION = (0.8, 0.5, 1.0)

Vector = tuple[float, float, float]
Support = Callable[[Vector], Vector]


class PaperDistance(NamedTuple):
    """What ``GJK_dist`` returns for one point, with what it hid.

    distance : float, unsigned, the rows' unit
        NaN for outcome ``'hang'``.
    best_distance : float
        The least triangle distance it measured on the way (its best-so-far); at the cap it
        returns the last one, ``distance``, instead.
    passes : int
        Passes of its main loop.
    outcome : str
        ``'converged'`` (its norm test), ``'cap'`` (gave up after 10 passes) or ``'hang'``.
    """

    distance: float
    best_distance: float
    passes: int
    outcome: str


class PaperAnswer(NamedTuple):
    """The paper's answer for one tip position: flag, distance, and that distance signed.

    ``signed_distance`` is ``-distance`` when the flag is set, ``+distance`` otherwise: the
    most favourable reading of its unsigned distance (its figures plot negative distances in
    contact), used to compare it with a signed ground truth.
    """

    in_collision: bool
    distance: PaperDistance
    signed_distance: float


def stl_vertex_rows(path: str | Path, *, scale: float = 1.0) -> np.ndarray:
    """Read an STL's vertex rows as the paper's STL reader gives them: 3 per triangle.

    Parameters
    ----------
    path : str or pathlib.Path
        ASCII or binary STL.
    scale : float
        File units to metres (0.001 for millimetres).

    Returns
    -------
    rows : (3 m, 3) float64, m, file frame
    """
    import trimesh

    mesh = trimesh.load(Path(path), file_type='stl', process=False)
    return np.asarray(mesh.triangles, dtype=np.float64).reshape(-1, 3) * scale


@dataclass(frozen=True)
class PaperMethod:
    """The paper's collision flag, distance and force for one object given by its vertex rows.

    Parameters
    ----------
    vertex_rows : (n, 3) float, m, world frame
        The STL's rows, as ``stl_vertex_rows`` reads them (posed by the caller).
    stiffness : float, N/m
        The paper's ``k_stiff(1)`` (160 N/m in the paper, 80 N/m in its Simulink model).
    damping : float or (3,) float, N·s/m
        ``k_damp`` per axis.

    Raises
    ------
    ValueError
        If the rows are not an (n >= 1, 3) array of finite numbers or the gains are not
        finite and >= 0.
    """

    vertex_rows: np.ndarray
    stiffness: float = 160.0
    damping: float | tuple = 0.8

    def __post_init__(self) -> None:
        rows = np.asarray(self.vertex_rows, dtype=np.float64)
        if rows.ndim != 2 or rows.shape[1] != 3 or len(rows) == 0:
            raise ValueError(f'vertex_rows must have shape (n >= 1, 3), got {rows.shape}')
        if not np.all(np.isfinite(rows)):
            raise ValueError('vertex_rows contain NaN or Inf')
        damping = np.broadcast_to(np.asarray(self.damping, dtype=np.float64), (3,)).copy()
        for name, value in (('stiffness', np.asarray(self.stiffness)), ('damping', damping)):
            if not (np.all(np.isfinite(value)) and np.all(value >= 0.0)):
                raise ValueError(f'{name} must be finite and >= 0, got {value.tolist()}')
        _, first = np.unique(rows, axis=0, return_index=True)
        unique = rows[np.sort(first)]
        object.__setattr__(self, 'vertex_rows', rows)
        object.__setattr__(self, 'damping', damping)
        object.__setattr__(self, '_columns', tuple(np.ascontiguousarray(c) for c in unique.T))
        object.__setattr__(self, '_unique', unique.tolist())

    @property
    def centroid(self) -> np.ndarray:
        """(3,) float, m: the mean of the vertex rows, duplicates included (``atia_centroid``)."""
        return self.vertex_rows.mean(axis=0)

    def query(self, point) -> PaperAnswer:
        """Flag and distance for one tip position, (3,) float, m."""
        support = self._support_from(_checked_point(point))
        flag = _collision_flag(support, COLLISION_ITERATIONS)
        distance = _gjk_distance(support)
        signed = -distance.distance if flag else distance.distance
        return PaperAnswer(flag, distance, signed)

    def force(self, point, velocity) -> np.ndarray:
        """Return the paper's force on the tip, (3,) float, N: along tip - centroid, in contact.

        Parameters
        ----------
        point : (3,) float, m
        velocity : (3,) float, m/s
        """
        return self.force_for(self.query(point), point, velocity)

    def force_for(self, answer: PaperAnswer, point, velocity) -> np.ndarray:
        """Return the force for an answer ``query(point)`` already gave, (3,) float, N."""
        if not answer.in_collision:
            return np.zeros(3)
        radial = np.asarray(point, dtype=np.float64) - self.centroid
        with np.errstate(divide='ignore', invalid='ignore'):
            direction = radial / np.linalg.norm(radial)
        spring = direction * self.stiffness * answer.distance.distance
        return spring - self.damping * np.asarray(velocity, dtype=np.float64)

    def _support_from(self, point: Vector) -> Support:
        """Support of (hull of the rows) - point, by a scan of every row, as the paper's."""
        xs, ys, zs = self._columns
        unique = self._unique
        px, py, pz = point

        def support(direction: Vector) -> Vector:
            dotted = xs * direction[0] + ys * direction[1] + zs * direction[2]
            x, y, z = unique[int(np.argmax(dotted))]
            return (x - px, y - py, z - pz)

        return support


def _checked_point(point) -> Vector:
    values = np.asarray(point, dtype=np.float64)
    if values.shape != (3,) or not np.all(np.isfinite(values)):
        raise ValueError(f'point must be 3 finite numbers (m), got {point!r}')
    return tuple(values.tolist())


# -- vector helpers on tuples of floats (numpy is slower than this for 3-vectors) -------------

def _sub(a: Vector, b: Vector) -> Vector:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _neg(a: Vector) -> Vector:
    return (-a[0], -a[1], -a[2])


def _scale(a: Vector, s: float) -> Vector:
    return (a[0] * s, a[1] * s, a[2] * s)


def _dot(a: Vector, b: Vector) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a: Vector, b: Vector) -> Vector:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _norm(a: Vector) -> float:
    return math.sqrt(_dot(a, a))


def _divide(numerator: float, denominator: float) -> float:
    """Divide as MATLAB does (IEEE): x/0 is +-inf and 0/0 is NaN, never an exception."""
    if denominator != 0.0:
        return numerator / denominator
    if numerator == 0.0 or math.isnan(numerator):
        return math.nan
    return math.copysign(math.inf, numerator) * math.copysign(1.0, denominator)


def _unit(a: Vector) -> Vector:
    length = _norm(a)
    return (_divide(a[0], length), _divide(a[1], length), _divide(a[2], length))


def _toward_origin(edge: Vector, start: Vector) -> Vector:
    """``cross(cross(ab, ao), ab)``: perpendicular to an edge, toward the origin."""
    return _cross(_cross(edge, _neg(start)), edge)


def _nanmin(values) -> float:
    """Take the least value as MATLAB's ``min`` does: NaN is ignored unless all are NaN."""
    kept = [v for v in values if not math.isnan(v)]
    return min(kept) if kept else math.nan


# -- the collision flag: GJK_mod with pickLine, pickTriangle, pickTetrahedron ------------------

def _collision_flag(support: Support, iterations: int) -> bool:
    """``GJK_mod``: True when it builds a tetrahedron around the origin within the cap.

    As in the paper's code, the tetrahedron search runs even when no triangle was found.
    """
    b = support(COLLISION_DIRECTION)
    a = support(_neg(COLLISION_DIRECTION))
    a, b, c = _pick_triangle(support, a, b, iterations)
    return _pick_tetrahedron(support, a, b, c, iterations)


def _pick_triangle(support: Support, a: Vector, b: Vector, iterations: int) -> tuple:
    """``pickTriangle``: a triangle whose 2-D projection holds the origin (flag unused)."""
    v = _toward_origin(_sub(b, a), a)
    c, b = b, a
    a = support(v)
    for _ in range(iterations):
        ab, ac, ao = _sub(b, a), _sub(c, a), _neg(a)
        abc = _cross(ab, ac)
        abp, acp = _cross(ab, abc), _cross(abc, ac)
        if _dot(abp, ao) > 0.0:
            c, b, v = b, a, abp
        elif _dot(acp, ao) > 0.0:
            b, v = a, acp
        else:
            break
        a = support(v)
    return a, b, c


def _pick_tetrahedron(support: Support, a: Vector, b: Vector, c: Vector,
                      iterations: int) -> bool:
    """``pickTetrahedron``: True when the origin is found inside a tetrahedron."""
    abc = _cross(_sub(b, a), _sub(c, a))
    a, b, c, d = _grow_tetrahedron(support, a, b, c, abc)
    for _ in range(iterations):
        ab, ac, ad, ao = _sub(b, a), _sub(c, a), _sub(d, a), _neg(a)
        abc = _cross(ab, ac)
        if not _dot(abc, ao) > 0.0:
            acd = _cross(ac, ad)
            if _dot(acd, ao) > 0.0:
                b, c, abc = c, d, acd
            elif _dot(acd, ao) < 0.0:
                adb = _cross(ad, ab)
                if _dot(adb, ao) > 0.0:
                    c, b, abc = b, d, adb
                else:
                    return True
        a, b, c, d = _grow_tetrahedron(support, a, b, c, abc)
    return False


def _grow_tetrahedron(support: Support, a: Vector, b: Vector, c: Vector, abc: Vector) -> tuple:
    """Add the support point on the origin's side of triangle abc (``pickTetrahedron``)."""
    if _dot(abc, _neg(a)) > 0.0:
        return support(abc), a, b, c
    return support(_neg(abc)), a, c, b


# -- the distance: GJK_dist with pointTriangleDistance and distLinSeg ---------------------------

def _gjk_distance(support: Support) -> PaperDistance:
    """``GJK_dist``: unsigned distance from the origin to (hull of the rows) - point."""
    d = FIRST_DIRECTION
    a, b = support(d), support(_neg(d))
    d = _toward_origin(_sub(b, a), a)
    c = support(d)
    if c in (a, b):
        c = support(_neg(d))
        if c in (a, b):
            return PaperDistance(math.nan, math.nan, 0, 'hang')
    pts = [a, b, c]
    passes, flag, dist, best = 0, 0, 1000.0, math.inf
    measured = False
    while True:
        norms = [_norm(p) for p in pts]
        index = int(np.argmax(norms))
        c, normal, origin_projected = _normal_support(support, pts)
        if _repeats(norms, c) or (passes > FALLBACK_PASS and flag == 5):
            c, index = _edge_support(support, pts, index, origin_projected, dist, c, normal)
            if _repeats(norms, c):
                if not measured:
                    dist = _point_triangle_distance(*pts)
                return PaperDistance(dist, min(best, dist), passes, 'converged')
        pts = [p for k, p in enumerate(pts) if k != index] + [c]
        dist = _point_triangle_distance(*pts)
        measured = True
        best = min(best, dist)
        if passes > FLAG_PASS:
            flag = 5
            if passes > DISTANCE_ITERATION_CAP:
                return PaperDistance(dist, best, passes, 'cap')
        passes += 1


def _repeats(norms: list, c: Vector) -> bool:
    """Test for a stop: ``any(abs(Norm_pts - norm(c)) < 0.000001)``."""
    length = _norm(c)
    return any(abs(n - length) < CONVERGED_NORM for n in norms)


def _normal_support(support: Support, pts: list) -> tuple:
    """Return the support along the triangle's unit normal toward the origin, that normal.

    And the origin's projection on the triangle's plane. As written, the normal's side is
    chosen from ``(p1.d) d`` with ``d`` not yet normalised.
    """
    d = _cross(_sub(pts[1], pts[0]), _sub(pts[2], pts[0]))
    origin_projected = _scale(d, _dot(pts[0], d))
    if _dot(d, origin_projected) > 0.0:
        d = _neg(d)
    d = _unit(d)
    return support(d), d, _scale(d, _dot(pts[0], d))


def _edge_support(support: Support, pts: list, index: int, origin_projected: Vector,
                  dist: float, c: Vector, d: Vector) -> tuple:
    """Search from the triangle's edge nearest the origin's projection (the paper's fallback).

    Returns the new support point and which vertex to drop (unchanged on a tie of edges).
    ``d`` is the current search direction, which one tie-break reuses as it stands.
    """
    p1, p2, p3 = pts
    d1 = _point_segment_distance(p1, p2, origin_projected)
    d2 = _point_segment_distance(p1, p3, origin_projected)
    d3 = _point_segment_distance(p2, p3, origin_projected)
    nearest = _nanmin([d1, d2, d3])
    if not nearest < dist:
        return c, index
    for distance, (other, another), (start, end), drop in ((d1, (d2, d3), (p1, p2), 2),
                                                           (d2, (d1, d3), (p1, p3), 1),
                                                           (d3, (d1, d2), (p2, p3), 0)):
        if distance == nearest:
            d = _toward_origin(_sub(end, start), start)
            if distance != other and distance != another:
                return support(d), drop
    if d1 == d2:
        first = _edge_alignment(p1, p2, origin_projected) > _edge_alignment(
            p1, p3, origin_projected)
        start, end = (p1, p2) if first else (p1, p3)
    elif d1 == d3:
        first = _edge_alignment(p1, p2, origin_projected) > _edge_alignment(
            p2, p3, origin_projected)
        start, end = (p1, p2) if first else (p2, p3)
    elif d2 == d3:
        if not _edge_alignment(p1, p3, origin_projected) > _edge_alignment(
                p2, p3, origin_projected):
            return support(d), index
        start, end = p1, p3
    else:
        return c, index
    return support(_toward_origin(_sub(end, start), start)), index


def _edge_alignment(start: Vector, end: Vector, origin_projected: Vector) -> float:
    """``L = (e/|e|)'(start - o)/|start - o|``: the paper's tie-break between two edges."""
    return _dot(_unit(_sub(end, start)), _unit(_sub(start, origin_projected)))


def _point_segment_distance(start: Vector, end: Vector, point: Vector) -> float:
    """``distLinSeg(start, end, point, point)`` (Lumelsky) with its second segment a point."""
    edge = _sub(end, start)
    offset = _sub(point, start)
    length2 = _dot(edge, edge)
    t = min(max(_divide(_dot(edge, offset), length2), 0.0), 1.0) if length2 != 0.0 else 0.0
    return _norm(_sub(_scale(edge, t), offset))


def _point_triangle_distance(p1: Vector, p2: Vector, p3: Vector) -> float:
    """Distance from the origin to triangle p1 p2 p3 (``pointTriangleDistance``, Eberly 1999).

    Region by region as the MATLAB code (release 1.3); a degenerate triangle divides by zero
    there too, giving inf or NaN.
    """
    e0, e1, base = _sub(p2, p1), _sub(p3, p1), p1
    a, b, c = _dot(e0, e0), _dot(e0, e1), _dot(e1, e1)
    d, e, f = _dot(e0, base), _dot(e1, base), _dot(base, base)
    det = a * c - b * b
    s, t = b * e - c * d, b * d - a * e
    if s + t <= det:
        if s < 0.0:
            squared = _region_4(a, c, d, e, f) if t < 0.0 else _edge_s0(c, e, f)
        elif t < 0.0:
            squared = _edge_t0(a, d, f)
        else:
            inv = _divide(1.0, det)
            s, t = s * inv, t * inv
            squared = s * (a * s + b * t + 2 * d) + t * (b * s + c * t + 2 * e) + f
    elif s < 0.0:
        squared = _region_2(a, b, c, d, e, f)
    elif t < 0.0:
        squared = _region_6(a, b, c, d, e, f)
    else:
        squared = _edge_hypotenuse(a, b, c, d, e, f, c + e - b - d)
    return math.sqrt(max(squared, 0.0)) if not math.isnan(squared) else math.nan


def _edge_s0(c: float, e: float, f: float) -> float:
    """Region 3: on the edge s = 0."""
    if e >= 0.0:
        return f
    if -e >= c:
        return c + 2 * e + f
    return e * _divide(-e, c) + f


def _edge_t0(a: float, d: float, f: float) -> float:
    """Region 5: on the edge t = 0."""
    if d >= 0.0:
        return f
    if -d >= a:
        return a + 2 * d + f
    return d * _divide(-d, a) + f


def _region_4(a: float, c: float, d: float, e: float, f: float) -> float:
    if d < 0.0:
        return _edge_t0(a, d, f)
    return _edge_s0(c, e, f)


def _edge_hypotenuse(a, b, c, d, e, f, numer) -> float:
    """Region 1: on the edge s + t = 1 (``numer`` as the region computes it)."""
    if numer <= 0.0:
        return c + 2 * e + f
    denom = a - 2 * b + c
    if numer >= denom:
        return a + 2 * d + f
    s = _divide(numer, denom)
    t = 1 - s
    return s * (a * s + b * t + 2 * d) + t * (b * s + c * t + 2 * e) + f


def _region_2(a, b, c, d, e, f) -> float:
    tmp0, tmp1 = b + d, c + e
    if tmp1 > tmp0:
        numer, denom = tmp1 - tmp0, a - 2 * b + c
        if numer >= denom:
            return a + 2 * d + f
        s = _divide(numer, denom)
        t = 1 - s
        return s * (a * s + b * t + 2 * d) + t * (b * s + c * t + 2 * e) + f
    if tmp1 <= 0.0:
        return c + 2 * e + f
    if e >= 0.0:
        return f
    return e * _divide(-e, c) + f


def _region_6(a, b, c, d, e, f) -> float:
    tmp0, tmp1 = b + e, a + d
    if tmp1 > tmp0:
        numer, denom = tmp1 - tmp0, a - 2 * b + c
        if numer >= denom:
            return c + 2 * e + f
        t = _divide(numer, denom)
        s = 1 - t
        return s * (a * s + b * t + 2 * d) + t * (b * s + c * t + 2 * e) + f
    if tmp1 <= 0.0:
        return a + 2 * d + f
    if d >= 0.0:
        return f
    return d * _divide(-d, a) + f
