"""EPA's penetration depth inside convex meshes, against brute force on scipy's hull facets."""

from fuzzing import examples
from ground_truth.distances import mesh_signed_distance, outward_hull
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
import numpy as np
import pytest
from scipy.spatial import QhullError

from collision_engine.epa import epa, scratch_size
from collision_engine.gjk import gjk, STATUS_OK
from collision_engine.shapes import ConvexMesh
from collision_engine.support import pack_convex, POINT

TOL = 1e-12


def fresh_scratch(max_iter=128):
    """EPA's work space, filled with garbage: answers must not depend on what it held."""
    n_floats, n_ints = scratch_size(max_iter)
    return np.full(n_floats, np.nan), np.full(n_ints, -7)


def penetration(shape: ConvexMesh, point: np.ndarray, scratch=None):
    """GJK to contact, then EPA: (status, depth, closest point, normal)."""
    kind, floats, ints = pack_convex(shape)
    a, b = (kind, floats, 0, ints, 0), (POINT, floats, 0, ints, 0)
    rel = np.concatenate((np.eye(3).ravel(), point))
    W, A = np.zeros(12), np.zeros(12)
    direction = point - shape.vertices.mean(axis=0)
    size = shape.bounding_sphere()[1]
    _, contact, count, *_, inv, _, _, _ = gjk(a, b, rel, *direction, size, TOL, TOL, 100, W, A)
    assert contact
    status, depth, bound, x, y, z, nx, ny, nz, _ = epa(
        a, b, rel, W, A, count, inv, TOL, TOL, 128, *(scratch or fresh_scratch()))
    assert depth <= bound + 1e-15
    return status, depth, np.array([x, y, z]), np.array([nx, ny, nz])


@settings(max_examples=examples(60), deadline=None)
@given(arrays(np.int64, st.tuples(st.integers(4, 80), st.just(3)),
              elements=st.integers(-64, 64)).map(lambda a: a / 64.0),
       arrays(np.float64, (6, 4), elements=st.floats(0.0, 1.0)),
       st.floats(1e-3, 1e3))
def test_depth_matches_brute_force_inside_random_polytopes(cloud, weights, scale):
    cloud = cloud * scale
    try:
        shape = ConvexMesh(cloud)
        faces, planes = outward_hull(cloud)
    except (ValueError, QhullError):
        assume(False)
    # Points inside: between the centroid and a convex combination of two hull vertices.
    centre = shape.vertices.mean(axis=0)
    first = shape.vertices[(weights[:, 0] * (len(shape.vertices) - 1)).astype(int)]
    second = shape.vertices[(weights[:, 1] * (len(shape.vertices) - 1)).astype(int)]
    on_hull = first + weights[:, [2]] * (second - first)
    inside = centre + weights[:, [3]] * (on_hull - centre)
    # The clouds sit on a 1/64 grid: duplicates and coplanar points, but no sliver, where
    # the brute-force reference itself loses digits (a needle 1e-7 wide and 0.5 long gave it
    # 1e-8 errors).
    truth, _ = mesh_signed_distance(inside, cloud, faces)
    tolerance = max(1e-10 * scale, 2 * TOL)  # 1e-10 of the size, or EPA's own tolerance
    for point, depth_true in zip(inside, truth):
        if depth_true > -1e-9 * scale:
            continue  # on the surface: the cases below cover it
        status, depth, point_on_surface, normal = penetration(shape, point)
        assert status == STATUS_OK
        assert -depth == pytest.approx(depth_true, abs=tolerance)
        # The witness is on the surface at that depth, and the normal is outward there: the
        # whole hull lies behind the plane through the witness with that normal.
        assert abs(mesh_signed_distance(point_on_surface, cloud, faces)[0]) <= tolerance
        assert np.linalg.norm(point_on_surface - point) == pytest.approx(depth, abs=tolerance)
        assert np.linalg.norm(normal) == pytest.approx(1.0, abs=1e-12)
        assert np.max((shape.vertices - point_on_surface) @ normal) <= tolerance


CUBE = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])


@pytest.mark.parametrize('point, depth', [
    ([0.0, 0.0, 0.0], 1.0),
    ([0.5, 0.2, -0.1], 0.5),
    ([1.0, 0.3, 0.1], 0.0),        # on a face
    ([1.0, 1.0, 0.2], 0.0),        # on an edge
    ([1.0, 1.0, 1.0], 0.0),        # on a vertex
    ([1.0 - 1e-12, 0.0, 0.0], 1e-12),
])
def test_depth_on_and_just_inside_the_surface(point, depth):
    status, found, closest, normal = penetration(ConvexMesh(CUBE), np.array(point))
    assert status == STATUS_OK
    assert found == pytest.approx(depth, abs=1e-15)
    assert np.all(np.isfinite(closest)) and np.all(np.isfinite(normal))
    # An outward normal of the cube at the closest point: one of its face normals there.
    assert np.linalg.norm(normal) == pytest.approx(1.0)
    axis = int(np.argmax(np.abs(normal)))
    assert abs(normal[axis]) == pytest.approx(1.0)
    assert closest[axis] == pytest.approx(np.sign(normal[axis]))


def test_reused_scratch_gives_the_answers_of_fresh_scratch():
    # The scene keeps one work space for every query: what an earlier EPA left in it (more
    # faces, other vertices) must not leak into the next answer.
    rng = np.random.default_rng(8)
    shape = ConvexMesh(rng.normal(size=(300, 3)) * [0.03, 0.02, 0.05])
    points = rng.uniform(-0.3, 0.3, size=(200, 3)) * shape.vertices.std(axis=0)
    shared = fresh_scratch()
    for order in (points, points[::-1]):
        for point in order:
            reused = penetration(shape, point, shared)
            fresh = penetration(shape, point)
            assert reused[:2] == fresh[:2]
            np.testing.assert_array_equal(reused[2], fresh[2])
            np.testing.assert_array_equal(reused[3], fresh[3])
