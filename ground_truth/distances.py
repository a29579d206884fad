"""Exact signed distances for checking the collision engine, sharing no code with it.

Analytic formulas for the primitives and brute force for meshes (every point against every
triangle), in numpy only. Everything is float64, in the shape's local frame, in metres, and the
sign rule is the engine's: negative inside, zero on the surface, positive outside.
"""

from collections.abc import Iterator
from decimal import Decimal, localcontext
from itertools import combinations
from pathlib import Path

import numpy as np

__all__ = [
    'box_signed_distance',
    'capsule_signed_distance',
    'cylinder_signed_distance',
    'exact_norm',
    'exact_unit',
    'hand_mesh_path',
    'mesh_signed_distance',
    'polytope_pair_distance',
    'sample_near_surface',
    'scene_path',
    'segment_distance',
    'simplex_distance',
    'tool_poses_near_surface',
    'triangles_meet',
    'sphere_signed_distance',
    'winding_number',
]

SCENES_DIR = Path(__file__).resolve().parents[1] / 'src' / 'collision_engine' / 'scenes'

# Point-triangle pairs per chunk: small enough for the (k, m) arrays to stay in cache.
_PAIRS_PER_CHUNK = 50_000


def angle_between(u, v) -> float:
    """Angle between two 3-vectors, degrees: atan2(|u x v|, u . v).

    Unlike arccos of the normalised dot product, it needs no clipping (a cosine that rounds to
    1.0000000000000002 on some processors gives arccos NaN) and it resolves small angles.
    """
    u, v = np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64)
    return float(np.degrees(np.arctan2(np.linalg.norm(np.cross(u, v)), u @ v)))


def _as_points(points: np.ndarray) -> np.ndarray:
    """Return `points` as a float64 array whose last axis has length 3."""
    array = np.asarray(points, dtype=np.float64)
    if array.ndim == 0 or array.shape[-1] != 3:
        raise ValueError(f'points must have shape (..., 3), got {array.shape}')
    return array


def _positive(name: str, value: float) -> float:
    value = float(value)
    if not value > 0.0 or not np.isfinite(value):
        raise ValueError(f'{name} must be a positive finite length in metres, got {value}')
    return value


def _length(vectors: np.ndarray) -> np.ndarray:
    """Euclidean norms over the last axis by C ``hypot``, exact at any magnitude.

    ``np.linalg.norm`` squares the components, which underflow below 1e-154 and overflow above
    1e154; ``hypot`` scales, so the truths hold for subnormal and 1e300-sized offsets too.
    """
    vectors = np.asarray(vectors, dtype=np.float64)
    if vectors.shape[-1] == 2:
        return np.hypot(vectors[..., 0], vectors[..., 1])
    return np.hypot(np.hypot(vectors[..., 0], vectors[..., 1]), vectors[..., 2])


def exact_norm(vector) -> Decimal:
    """Euclidean norm of a float vector in 60-digit decimal arithmetic.

    Decimal exponents reach far beyond float64's, so no square underflows or overflows: the
    reference for norms of subnormal and 1e300-sized vectors.
    """
    with localcontext() as context:
        context.prec = 60
        return sum(Decimal(float(c)) ** 2 for c in vector).sqrt()


def exact_unit(vector) -> np.ndarray:
    """Return the unit vector of a non-zero float vector, in 60-digit decimal, as float64."""
    with localcontext() as context:
        context.prec = 60
        norm = exact_norm(vector)
        return np.array([float(Decimal(float(c)) / norm) for c in vector])


def simplex_distance(points: np.ndarray) -> float:
    """Distance from the origin to the convex hull of at most 4 points, by enumerating subsets.

    For each subset, the origin is projected onto its affine hull by least squares on the edge
    vectors from its first point (scale-free), and kept if it falls inside the subset.

    Parameters
    ----------
    points : (k <= 4, 3) float, m
    """
    points = _as_points(points)
    best = np.inf
    for size in range(1, len(points) + 1):
        for subset in combinations(range(len(points)), size):
            p = points[list(subset)]
            edges = (p[1:] - p[0]).T
            if size == 1:
                weights = np.ones(1)
            else:
                steps = np.linalg.lstsq(edges, -p[0], rcond=None)[0]
                weights = np.concatenate(([1.0 - steps.sum()], steps))
            if np.all(weights >= -1e-12):
                best = min(best, float(np.linalg.norm(weights @ p)))
    return best


def triangles_meet(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two triangles meet anywhere but along the corners and the edge they share.

    By linear programming, not geometry: a point in both triangles is a pair of barycentric
    weights (lambda on a's corners, mu on b's) with sum lambda_i a_i = sum mu_j b_j. The
    triangles meet beyond what they share when such a point can give weight to a corner of a
    that b lacks (any point, when they share no corner). Exact enough on small integer
    coordinates, where a real meeting is far above the solver's 1e-9 tolerance.

    Parameters
    ----------
    a, b : (3, 3) float
        The corners; a corner of a equal to one of b's is shared.
    """
    from scipy.optimize import linprog

    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    own = [not np.any(np.all(corner == b, axis=1)) for corner in a]
    if not any(own):
        return True
    equalities = np.zeros((5, 6))
    equalities[0, :3] = equalities[1, 3:] = 1.0
    equalities[2:, :3], equalities[2:, 3:] = a.T, -b.T
    result = linprog(-np.array(own + [False] * 3, dtype=float), A_eq=equalities,
                     b_eq=[1.0, 1.0, 0.0, 0.0, 0.0], bounds=(0.0, None), method='highs')
    return result.status == 0 and -result.fun > 1e-9


def _rounded_box(excess: np.ndarray) -> np.ndarray:
    """Signed distance from per-axis excesses over the faces (last axis), exact for boxes.

    Outside, the distance is the norm of the positive excesses; inside, it is the least negative
    excess (the nearest face).
    """
    outside = _length(np.maximum(excess, 0.0))
    inside = np.minimum(np.max(excess, axis=-1), 0.0)
    return outside + inside


def box_signed_distance(points: np.ndarray, size: np.ndarray) -> np.ndarray:
    """Signed distance to an axis-aligned box centred at the origin.

    Parameters
    ----------
    points : (..., 3) float, m, box frame
    size : (3,) float, m
        Full edge lengths along x, y, z.

    Returns
    -------
    distance : (...) float, m, negative inside
    """
    points = _as_points(points)
    size = np.asarray(size, dtype=np.float64)
    if size.shape != (3,):
        raise ValueError(f'size must have shape (3,), got {size.shape}')
    for axis, edge in zip('xyz', size):
        _positive(f'size.{axis}', edge)
    return _rounded_box(np.abs(points) - 0.5 * size)


def sphere_signed_distance(points: np.ndarray, radius: float) -> np.ndarray:
    """Signed distance to a sphere centred at the origin.

    Parameters
    ----------
    points : (..., 3) float, m, sphere frame
    radius : float, m

    Returns
    -------
    distance : (...) float, m, negative inside
    """
    points = _as_points(points)
    return _length(points) - _positive('radius', radius)


def cylinder_signed_distance(points: np.ndarray, radius: float, height: float) -> np.ndarray:
    """Signed distance to a capped cylinder along z, centred at the origin.

    Parameters
    ----------
    points : (..., 3) float, m, cylinder frame
    radius : float, m
    height : float, m
        Full length along z, from -height/2 to +height/2.

    Returns
    -------
    distance : (...) float, m, negative inside
    """
    points = _as_points(points)
    radial = np.hypot(points[..., 0], points[..., 1]) - _positive('radius', radius)
    axial = np.abs(points[..., 2]) - 0.5 * _positive('height', height)
    return _rounded_box(np.stack([radial, axial], axis=-1))


def capsule_signed_distance(points: np.ndarray, radius: float, length: float) -> np.ndarray:
    """Signed distance to a capsule along z, centred at the origin.

    Parameters
    ----------
    points : (..., 3) float, m, capsule frame
    radius : float, m
    length : float, m
        Length of the core segment, from z = -length/2 to +length/2 (the caps add `radius` at
        each end).

    Returns
    -------
    distance : (...) float, m, negative inside
    """
    points = _as_points(points)
    half = 0.5 * _positive('length', length)
    on_segment = np.zeros_like(points)
    on_segment[..., 2] = np.clip(points[..., 2], -half, half)
    return _length(points - on_segment) - _positive('radius', radius)


def _triangle_corners(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Return the (m, 3, 3) corners of each face, rejecting malformed or zero-area faces."""
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces)
    if vertices.ndim != 2 or vertices.shape[1] != 3:
        raise ValueError(f'vertices must have shape (n, 3), got {vertices.shape}')
    if faces.ndim != 2 or faces.shape[1] != 3 or faces.shape[0] == 0:
        raise ValueError(f'faces must have shape (m, 3) with m > 0, got {faces.shape}')
    if not np.issubdtype(faces.dtype, np.integer):
        raise ValueError(f'faces must be integer indices, got {faces.dtype}')
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise ValueError(f'faces index outside 0..{len(vertices) - 1}')
    if not np.all(np.isfinite(vertices)):
        raise ValueError('vertices contain NaN or Inf')
    corners = vertices[faces]
    doubled_area = np.linalg.norm(
        np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    if np.any(doubled_area == 0.0):
        raise ValueError(f'{np.count_nonzero(doubled_area == 0.0)} faces have zero area')
    return corners


def _chunks(count: int, triangle_count: int) -> Iterator[slice]:
    """Yield slices over `count` points so that each chunk holds a bounded number of pairs."""
    step = max(1, _PAIRS_PER_CHUNK // triangle_count)
    for start in range(0, count, step):
        yield slice(start, min(start + step, count))


def _dot(u: tuple, v: tuple) -> np.ndarray:
    """Dot product of vectors held as (x, y, z) tuples of broadcastable arrays."""
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


def _split(point: np.ndarray, corners: np.ndarray) -> tuple:
    """Points as (k, 1) and triangle corners as (1, m) component tuples, for (k, m) pair arrays.

    Component arrays keep every pair operation on contiguous (k, m) arrays, several times faster
    than reductions over a trailing axis of length 3.
    """
    p = tuple(point[:, i, None] for i in range(3))
    a, b, c = (tuple(corners[None, :, j, i] for i in range(3)) for j in range(3))
    return p, a, b, c


def _closest_on_triangles(point: np.ndarray, corners: np.ndarray) -> tuple:
    """Closest points on every triangle to every point, by Ericson's Voronoi regions.

    Real-Time Collision Detection (2005), section 5.1.5, vectorised: the region tests run on all
    pairs and are applied from the lowest-priority region (the face interior) to the highest
    (vertex A), so each pair ends with the region Ericson's branch order would choose.

    Parameters
    ----------
    point : (k, 3) float, m
    corners : (m, 3, 3) float, m

    Returns
    -------
    closest : tuple of three (k, m) float, m
        x, y, z of the closest point on triangle j to point i.
    """
    p, a, b, c = _split(point, corners)
    ab = tuple(bi - ai for ai, bi in zip(a, b))
    ac = tuple(ci - ai for ai, ci in zip(a, c))
    ap, bp, cp = (tuple(pi - qi for pi, qi in zip(p, q)) for q in (a, b, c))
    d1, d2 = _dot(ab, ap), _dot(ac, ap)
    d3, d4 = _dot(ab, bp), _dot(ac, bp)
    d5, d6 = _dot(ab, cp), _dot(ac, cp)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    with np.errstate(divide='ignore', invalid='ignore'):
        # Face interior, then the regions in reverse of Ericson's order; (s, t) along (ab, ac).
        s = vb / (va + vb + vc)
        t = vc / (va + vb + vc)
        on_bc = (va <= 0.0) & (d4 - d3 >= 0.0) & (d5 - d6 >= 0.0)
        bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        s, t = np.where(on_bc, 1.0 - bc, s), np.where(on_bc, bc, t)
        on_ac = (vb <= 0.0) & (d2 >= 0.0) & (d6 <= 0.0)
        s, t = np.where(on_ac, 0.0, s), np.where(on_ac, d2 / (d2 - d6), t)
        on_c = (d6 >= 0.0) & (d5 <= d6)
        s, t = np.where(on_c, 0.0, s), np.where(on_c, 1.0, t)
        on_ab = (vc <= 0.0) & (d1 >= 0.0) & (d3 <= 0.0)
        s, t = np.where(on_ab, d1 / (d1 - d3), s), np.where(on_ab, 0.0, t)
        on_b = (d3 >= 0.0) & (d4 <= d3)
        s, t = np.where(on_b, 1.0, s), np.where(on_b, 0.0, t)
        on_a = (d1 <= 0.0) & (d2 <= 0.0)
        s, t = np.where(on_a, 0.0, s), np.where(on_a, 0.0, t)
    return tuple(ai + s * abi + t * aci for ai, abi, aci in zip(a, ab, ac))


def _solid_angle_sum(point: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """Sum over triangles of the signed solid angle each subtends at each point, in steradians.

    Van Oosterom and Strackee (1983): tan(omega / 2) = det[a b c] / (|a||b||c| + (a.b)|c| +
    (b.c)|a| + (c.a)|b|), with a, b, c the corners relative to the point.
    """
    p, *corner = _split(point, corners)
    a, b, c = (tuple(qi - pi for pi, qi in zip(p, q)) for q in corner)
    la, lb, lc = (np.sqrt(_dot(v, v)) for v in (a, b, c))
    b_cross_c = (b[1] * c[2] - b[2] * c[1], b[2] * c[0] - b[0] * c[2], b[0] * c[1] - b[1] * c[0])
    den = la * lb * lc + _dot(a, b) * lc + _dot(b, c) * la + _dot(c, a) * lb
    return 2.0 * np.sum(np.arctan2(_dot(a, b_cross_c), den), axis=1)


def winding_number(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Generalized winding number of a triangle mesh at each point (Jacobson et al. 2013).

    1 inside and 0 outside a closed, outward-wound mesh (-1 inside an inward-wound one). Exactly
    on the surface it is undefined (rounding gives 0 or 1 there), where the distance is zero
    anyway. It needs no BVH and no pseudonormals, so it shares nothing with the engine's sign rule.

    Parameters
    ----------
    points : (..., 3) float, m, mesh frame
    vertices : (n, 3) float, m, mesh frame
    faces : (m, 3) int
        Vertex indices, counter-clockwise seen from outside.

    Returns
    -------
    winding : (...) float
    """
    points = _as_points(points)
    corners = _triangle_corners(vertices, faces)
    flat = points.reshape(-1, 3)
    winding = np.empty(len(flat))
    for chunk in _chunks(len(flat), len(corners)):
        winding[chunk] = _solid_angle_sum(flat[chunk], corners) / (4.0 * np.pi)
    return winding.reshape(points.shape[:-1])


def mesh_signed_distance(points: np.ndarray, vertices: np.ndarray,
                         faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Exact signed distance to a closed triangle mesh by brute force over all triangles.

    The magnitude is the least point-triangle distance; the sign is negative where the
    generalized winding number has |w| > 0.5. Cost is O(points x triangles): use it for a few
    thousand points at most.

    Parameters
    ----------
    points : (..., 3) float, m, mesh frame
    vertices : (n, 3) float, m, mesh frame
    faces : (m, 3) int
        Vertex indices of non-degenerate triangles.

    Returns
    -------
    distance : (...) float, m, negative inside
    closest_point : (..., 3) float, m, mesh frame
        A nearest point on the surface (one of them where several are equally near).
    """
    points = _as_points(points)
    corners = _triangle_corners(vertices, faces)
    flat = points.reshape(-1, 3)
    distance = np.empty(len(flat))
    closest_point = np.empty_like(flat)
    for chunk in _chunks(len(flat), len(corners)):
        closest = _closest_on_triangles(flat[chunk], corners)
        squared = sum((q - flat[chunk, i, None]) ** 2 for i, q in enumerate(closest))
        nearest = np.argmin(squared, axis=1)
        rows = np.arange(len(nearest))
        closest_point[chunk] = np.stack([q[rows, nearest] for q in closest], axis=1)
        inside = np.abs(_solid_angle_sum(flat[chunk], corners)) > 2.0 * np.pi
        distance[chunk] = np.where(inside, -1.0, 1.0) * np.sqrt(squared[rows, nearest])
    return distance.reshape(points.shape[:-1]), closest_point.reshape(points.shape)


def sample_near_surface(vertices: np.ndarray, faces: np.ndarray, n: int, band: float,
                        rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Points within +-band of a closed, outward-wound mesh, half inside and half outside.

    Each point is a uniformly sampled surface point moved along its face normal by an offset in
    (0, band], inward for the first n // 2 points and outward for the rest. Near a concave region
    the true distance can be smaller than the offset (another face is nearer), so the returned
    distance is the brute-force truth, and a point whose offset crossed another part of the surface
    (true sign not the intended one) is drawn again.

    Parameters
    ----------
    vertices : (n, 3) float, m, mesh frame
    faces : (m, 3) int
    n : int
        Number of points.
    band : float, m
        Largest offset from the surface.
    rng : numpy.random.Generator

    Returns
    -------
    points : (n, 3) float, m, mesh frame
    distance : (n,) float, m
        True signed distance: negative for the first n // 2 points, positive for the rest, and
        |distance| <= band.
    """
    band = _positive('band', band)
    corners = _triangle_corners(vertices, faces)
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    doubled_area = np.linalg.norm(cross, axis=1)
    unit_normal = cross / doubled_area[:, None]
    intended = np.where(np.arange(n) < n // 2, -1.0, 1.0)
    points = np.empty((n, 3))
    distance = np.empty(n)
    pending = np.arange(n)
    for _ in range(100):
        if len(pending) == 0:
            return points, distance
        face = rng.choice(len(corners), size=len(pending), p=doubled_area / doubled_area.sum())
        root, split = np.sqrt(rng.random(len(pending))), rng.random(len(pending))
        weights = np.stack([1.0 - root, root * (1.0 - split), root * split], axis=1)
        on_surface = np.einsum('ki,kij->kj', weights, corners[face])
        offset = band * (1.0 - rng.random(len(pending)))
        points[pending] = on_surface + (intended[pending] * offset)[:, None] * unit_normal[face]
        distance[pending] = mesh_signed_distance(points[pending], vertices, faces)[0]
        pending = pending[np.sign(distance[pending]) != intended[pending]]
    raise ValueError(f'{len(pending)} of {n} points kept landing on the wrong side: is the mesh '
                     f'closed and wound outward, and band ({band} m) small beside its features?')


def outward_hull(cloud: np.ndarray) -> tuple:
    """Return the convex hull of a point cloud by scipy: faces (m, 3) wound outward, planes.

    ``planes`` are scipy's facet equations: unit outward normal and offset (n·x + d = 0).
    """
    from scipy.spatial import ConvexHull

    hull = ConvexHull(cloud)
    faces = hull.simplices.copy()
    corners = cloud[faces]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    inward = np.einsum('ij,ij->i', normals, hull.equations[:, :3]) < 0.0
    faces[inward] = faces[inward][:, ::-1]
    return faces, hull.equations


def polytope_pair_distance(vertices_a: np.ndarray, vertices_b: np.ndarray) -> float:
    """Signed distance between the convex hulls of two point sets, same frame, m.

    The origin against the hull of the Minkowski difference {a - b} (scipy's ConvexHull): its
    exact point-to-facet distance when outside (the separation), minus its distance to the
    nearest facet when inside (the penetration depth).
    """
    a, b = _as_points(vertices_a), _as_points(vertices_b)
    difference = (a[:, None, :] - b[None, :, :]).reshape(-1, 3)
    faces, _ = outward_hull(difference)
    return float(mesh_signed_distance(np.zeros(3), difference, faces)[0])


def segment_distance(p0, p1, q0, q1) -> float:
    """Distance between the segments p0 p1 and q0 q1, m.

    The least of the four endpoint-to-segment distances and, when the lines' common
    perpendicular meets both segments inside, its length.
    """
    p0, p1, q0, q1 = (np.asarray(v, dtype=np.float64) for v in (p0, p1, q0, q1))

    def to_segment(x, s0, s1):
        edge = s1 - s0
        t = np.clip((x - s0) @ edge / (edge @ edge), 0.0, 1.0)
        return float(_length(x - (s0 + t * edge)))

    best = min(to_segment(p0, q0, q1), to_segment(p1, q0, q1), to_segment(q0, p0, p1),
               to_segment(q1, p0, p1))
    u, v, w = p1 - p0, q1 - q0, p0 - q0
    system = np.array([[u @ u, -(u @ v)], [u @ v, -(v @ v)]])
    if abs(np.linalg.det(system)) > 1e-12 * (u @ u) * (v @ v):
        s, t = np.linalg.solve(system, [-(u @ w), -(v @ w)])
        if 0.0 < s < 1.0 and 0.0 < t < 1.0:
            best = min(best, float(_length(p0 + s * u - q0 - t * v)))
    return best


def tool_poses_near_surface(vertices: np.ndarray, faces: np.ndarray, size, n: int, band: float,
                            rng: np.random.Generator, tilt: float = np.radians(20.0)) -> tuple:
    """Poses of a box tool held face down on a mesh, its lowest corner within ``band`` of it.

    A site is drawn uniformly by area, and the box's -z face turned toward it along the face
    normal, spun about it at random and tilted up to ``tilt`` rad; its lowest corner along the
    normal is then put at a height uniform in [-band, band] above the site. Near, not exact:
    the surface curves under the box.

    Returns
    -------
    rotations : (n, 3, 3) float, tool to mesh frame
    positions : (n, 3) float, m, mesh frame
    """
    from scipy.spatial.transform import Rotation

    corners = _triangle_corners(vertices, faces)
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    doubled_area = _length(normals)
    normals /= doubled_area[:, None]
    face = rng.choice(len(corners), n, p=doubled_area / doubled_area.sum())
    weights = rng.dirichlet([1.0, 1.0, 1.0], n)
    sites = np.einsum('ki,kij->kj', weights, corners[face])
    up = np.array([0.0, 0.0, 1.0])
    rotations = np.empty((n, 3, 3))
    positions = np.empty((n, 3))
    box = (np.array(list(np.ndindex(2, 2, 2))) - 0.5) * np.asarray(size, dtype=np.float64)
    for k in range(n):
        turn = Rotation.align_vectors([normals[face[k]]], [up])[0]
        spin = Rotation.from_rotvec(rng.uniform(0.0, 2.0 * np.pi) * up)
        lean = Rotation.from_rotvec(tilt * rng.uniform(-1.0, 1.0) * np.array([1.0, 0.0, 0.0]))
        rotations[k] = (turn * spin * lean).as_matrix()
        lowest = (box @ rotations[k].T @ normals[face[k]]).min()
        positions[k] = sites[k] + (rng.uniform(-band, band) - lowest) * normals[face[k]]
    return rotations, positions


def scene_path(name: str) -> Path:
    """Path of a shipped scene file: ``'cuboid'`` gives ``scenes/cuboid.yaml``."""
    path = SCENES_DIR / f'{name.removesuffix(".yaml")}.yaml'
    if not path.is_file():
        shipped = sorted(p.stem for p in SCENES_DIR.glob('*.yaml'))
        raise FileNotFoundError(f'no scene {path}; shipped scenes: {shipped}')
    return path


def hand_mesh_path() -> Path:
    """Path of the shipped hand mesh (binary STL in millimetres, load with scale 0.001)."""
    path = SCENES_DIR / 'meshes' / 'hand.stl'
    if not path.is_file():
        raise FileNotFoundError(f'hand mesh missing: {path} (made by tools/make_meshes.py)')
    return path
