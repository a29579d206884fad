"""Our GJK, against brute force.

The reference shares no code with the engine: the distance to a polytope by
``ground_truth.mesh_signed_distance`` on scipy's hull facets.
"""

from fuzzing import examples
from ground_truth.distances import capsule_signed_distance, mesh_signed_distance, outward_hull
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
import numpy as np
import pytest
from scipy.spatial import QhullError

from collision_engine.gjk import gjk, STATUS_NOT_CONVERGED, STATUS_OK
from collision_engine.shapes import Capsule, ConvexMesh
from collision_engine.support import pack_convex, POINT

REL_TOL = ABS_TOL = 1e-12


def point_pair(shape, point):
    """The packed shape as GJK's A and the point as B (a POINT posed at it): (a, b, rel)."""
    kind, floats, ints = pack_convex(shape)
    rel = np.concatenate((np.eye(3).ravel(), np.asarray(point, dtype=np.float64)))
    return (kind, floats, 0, ints, 0), (POINT, floats, 0, ints, 0), rel


def run_gjk(shape, point, direction=None, max_iterations=100):
    direction = point if direction is None else direction
    size = shape.bounding_sphere()[1]
    status, contact, count, vx, vy, vz, lower, iterations, *_ = gjk(
        *point_pair(shape, point), *direction, size, REL_TOL, ABS_TOL, max_iterations,
        np.zeros(12), np.zeros(12))
    return status, contact, np.array([vx, vy, vz]), lower, iterations


def hull_distance(cloud: np.ndarray, points) -> np.ndarray:
    """Brute-force signed distance to the hull, its facets wound outward for the sign."""
    faces, _ = outward_hull(cloud)
    return mesh_signed_distance(np.asarray(points, dtype=np.float64), cloud, faces)[0]


def hull_or_skip(cloud: np.ndarray, points) -> tuple[ConvexMesh, np.ndarray]:
    """The hull of ``cloud`` and each point's brute-force distance; a degenerate cloud skips."""
    try:
        return ConvexMesh(cloud), hull_distance(cloud, points)
    except (ValueError, QhullError):
        assume(False)


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
    shape, reference = hull_or_skip(cloud, points)
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
    shape, reference = hull_or_skip(cloud, points)
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
