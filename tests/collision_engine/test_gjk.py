"""Our GJK and its signed-volumes sub-algorithm, against brute force.

The references here share no code with the engine: the nearest point of a small simplex by
enumerating every face, edge and vertex with a least-squares affine projection, and the
distance to a polytope by ``ground_truth.mesh_signed_distance`` on scipy's hull facets.
"""

from itertools import combinations

from fuzzing import examples
from ground_truth import capsule_signed_distance, mesh_signed_distance, outward_hull
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
import numpy as np
import pytest
from scipy.spatial import QhullError

from collision_engine.gjk import (gjk, nearest_on_simplex, nearest_on_triangle,
                                  STATUS_NOT_CONVERGED, STATUS_OK)
from collision_engine.shapes import Capsule, ConvexMesh
from collision_engine.support import pack_convex

REL_TOL = ABS_TOL = 1e-12


def brute_nearest(points: np.ndarray) -> float:
    """Distance from the origin to the convex hull of <= 4 points, by enumerating subsets.

    For each subset, the origin is projected onto its affine hull by least squares on the edge
    vectors from its first point (scale-free), and kept if it falls inside the subset.
    """
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


def run_gjk(shape, point, direction=None, max_iterations=100):
    kind, floats, ints = pack_convex(shape)
    direction = point if direction is None else direction
    size = shape.bounding_sphere()[1]
    status, contact, count, vx, vy, vz, lower, iterations, _ = gjk(
        kind, floats, 0, ints, 0, *point, *direction, size, REL_TOL, ABS_TOL, max_iterations,
        np.zeros(12))
    return status, contact, np.array([vx, vy, vz]), lower, iterations


def hull_distance(cloud: np.ndarray, points) -> np.ndarray:
    """Brute-force signed distance to the hull, its facets wound outward for the sign."""
    faces, _ = outward_hull(cloud)
    return mesh_signed_distance(np.asarray(points, dtype=np.float64), cloud, faces)[0]


simplex_points = arrays(np.float64, st.tuples(st.integers(1, 4), st.just(3)),
                        elements=st.floats(-1.0, 1.0))


@settings(max_examples=examples(300), deadline=None)
@given(simplex_points)
def test_sub_algorithm_matches_brute_force(points):
    W = np.zeros((4, 3))
    W[:len(points)] = points
    W = W.ravel()
    count, vx, vy, vz = nearest_on_simplex(W, len(points))
    v = np.array([vx, vy, vz])
    assert np.isfinite(v).all()
    assert np.linalg.norm(v) == pytest.approx(brute_nearest(points), abs=1e-12)
    # The kept rows are input points whose hull holds v: the support set.
    kept = W.reshape(4, 3)[:count]
    assert all(np.any(np.all(points == row, axis=1)) for row in kept)
    assert brute_nearest(kept) == pytest.approx(np.linalg.norm(v), abs=1e-12)


@pytest.mark.parametrize('points', [
    [[1.0, 1.0, 0.0], [1.0, 1.0, 0.0]],                                    # duplicate
    [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.0, 0.0, 0.0]],                   # collinear
    [[1.0, -1.0, 1.0], [1.0, 1.0, 1.0], [1.0, -1.0, 1.0]],                 # repeated corner
    [[1.0, -1.0, -1.0], [1.0, 1.0, -1.0], [1.0, 0.0, 1.0], [1.0, 0.2, 0.3]],  # coplanar
    [[0.5, 0.5, 0.5]] * 4,                                                  # all one point
    [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],                   # origin a vertex
    [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],  # origin on an edge
    [[1e-9, -1.0, -1.0], [1e-9, 1.0, -1.0], [1e-9, 0.0, 1.0], [1e-9 + 1e-20, 0.0, 0.0]],
])
def test_sub_algorithm_degenerate_simplices(points):
    points = np.array(points)
    W = np.zeros((4, 3))
    W[:len(points)] = points
    count, vx, vy, vz = nearest_on_simplex(W.ravel(), len(points))
    assert np.isfinite([vx, vy, vz]).all()
    assert np.linalg.norm([vx, vy, vz]) == pytest.approx(brute_nearest(points), abs=1e-12)


@settings(max_examples=examples(200), deadline=None)
@given(arrays(np.float64, (3, 3), elements=st.floats(-1.0, 1.0)))
def test_triangle_step_reports_the_feature(corners):
    d2, vx, vy, vz, feature, which = nearest_on_triangle(*corners.ravel())
    assert d2 == pytest.approx(brute_nearest(corners) ** 2, abs=1e-12)
    v = np.array([vx, vy, vz])
    if feature == 1:
        np.testing.assert_allclose(v, corners[which], atol=1e-15)
    elif feature == 2:
        a, b = np.delete(corners, which, axis=0)
        # On the edge's segment, not at its ends: orthogonal to it.
        assert abs(np.dot(v, b - a)) <= 1e-9 * np.linalg.norm(b - a) * max(1.0, np.linalg.norm(v))


def grid_clouds():
    """Point clouds on a 1/64 grid: exact duplicates, collinear and coplanar points abound,
    but no feature is thinner than the grid allows (slivers are tested apart)."""
    return arrays(np.int64, st.tuples(st.integers(4, 60), st.just(3)),
                  elements=st.integers(-64, 64)).map(lambda a: a / 64.0)


def float_clouds():
    """Any floats in [-1, 1], including slivers with corners 1e-9 apart."""
    return arrays(np.float64, st.tuples(st.integers(4, 60), st.just(3)),
                  elements=st.floats(-1.0, 1.0))


def check_outside(shape, cloud, point, truth, scale):
    """GJK's answer for a point outside: a true bracket, and exact when it says OK."""
    status, contact, v, lower, _ = run_gjk(shape, point, point - shape.vertices.mean(axis=0))
    tolerance = max(1e-10 * scale, 2 * ABS_TOL)  # 1e-10 of the size, or GJK's tolerance
    assert not contact
    assert lower - tolerance <= truth <= np.linalg.norm(v) + tolerance
    # The witness is a point of the hull's surface, whatever the status.
    assert abs(hull_distance(cloud, [point + v])[0]) <= tolerance
    if status == STATUS_OK:
        assert np.linalg.norm(v) == pytest.approx(truth, abs=tolerance)
    else:
        assert status == STATUS_NOT_CONVERGED
    return status


@settings(max_examples=examples(60), deadline=None)
@given(grid_clouds(), arrays(np.float64, (8, 3), elements=st.floats(-3.0, 3.0)),
       st.floats(1e-3, 1e3))
def test_gjk_matches_brute_force_on_random_polytopes(cloud, points, scale):
    cloud, points = cloud * scale, points * scale
    try:
        shape = ConvexMesh(cloud)
        reference = hull_distance(cloud, points)
    except (ValueError, QhullError):
        assume(False)
    for point, truth in zip(points, reference):
        if truth > 1e-9 * scale:
            check_outside(shape, cloud, point, truth, scale)
        elif truth < -1e-9 * scale:
            assert run_gjk(shape, point)[1]


@settings(max_examples=examples(60), deadline=None)
@given(float_clouds(), arrays(np.float64, (8, 3), elements=st.floats(-3.0, 3.0)))
def test_gjk_stays_within_1e_6_on_slivers(cloud, points):
    # With corners 1e-9 apart the search direction, known to rounding over the distance,
    # cannot tell such features apart: GJK may stop early or miss a contact by about that
    # much (2e-10 seen). No NaN, no exception, and the error is far below 1e-6 of the size.
    try:
        shape = ConvexMesh(cloud)
        reference = hull_distance(cloud, points)
    except (ValueError, QhullError):
        assume(False)
    for point, truth in zip(points, reference):
        _, contact, v, _, _ = run_gjk(shape, point, point - shape.vertices.mean(axis=0))
        distance = 0.0 if contact else np.linalg.norm(v)
        assert distance == pytest.approx(max(truth, 0.0), abs=1e-6)


def test_gjk_converges_on_ordinary_polytopes():
    rng = np.random.default_rng(3)
    for _ in range(100):
        scale = 10.0 ** rng.uniform(-3, 3)
        cloud = rng.normal(size=(rng.integers(4, 200), 3)) * rng.uniform(0.1, 1.0, 3) * scale
        shape = ConvexMesh(cloud)
        points = rng.normal(size=(20, 3)) * 2 * scale
        for point, truth in zip(points, hull_distance(cloud, points)):
            if truth > 1e-9 * scale:
                assert check_outside(shape, cloud, point, truth, scale) == STATUS_OK


def test_no_cycling_near_a_many_vertex_hull():
    # 3000 points on a sphere: a relative stop alone cycles just outside such hulls.
    rng = np.random.default_rng(7)
    cloud = rng.normal(size=(3000, 3))
    cloud /= np.linalg.norm(cloud, axis=1, keepdims=True)
    shape = ConvexMesh(cloud)
    directions = rng.normal(size=(200, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    for offset in (1e-12, 1e-9, 1e-6, 1e-3):
        points = directions * (1.0 + offset)
        reference = hull_distance(shape.vertices, points)
        for point, truth in zip(points, reference):
            status, contact, v, _, iterations = run_gjk(shape, point)
            assert status == STATUS_OK and not contact and iterations < 100
            assert np.linalg.norm(v) == pytest.approx(truth, abs=1e-12)


def test_iteration_cap_reports_not_converged_with_an_upper_bound():
    shape = Capsule(0.025, 0.1)
    point = np.array([0.2, 0.1, 0.03])
    truth = capsule_signed_distance(point, 0.025, 0.1)
    # A poor first direction: straight down, so one iteration cannot reach the answer.
    status, contact, v, lower, iterations = run_gjk(shape, point, np.array([0.0, 0.0, -1.0]),
                                                    max_iterations=1)
    assert status == STATUS_NOT_CONVERGED
    assert iterations == 1
    assert lower <= truth <= np.linalg.norm(v)
    status, _, v, lower, _ = run_gjk(shape, point, np.array([0.0, 0.0, -1.0]))
    assert status == STATUS_OK
    assert np.linalg.norm(v) == pytest.approx(truth, abs=1e-12)


def test_contact_for_points_inside():
    shape = ConvexMesh(np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]))
    for point in ([0.0, 0.0, 0.0], [0.999, 0.5, -0.2], [1.0, 0.3, 0.1], [1.0, 1.0, 1.0]):
        status, contact, v, _, _ = run_gjk(shape, np.array(point))
        assert status == STATUS_OK and contact
        assert np.linalg.norm(v) <= 1e-14
