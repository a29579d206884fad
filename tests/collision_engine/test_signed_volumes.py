"""GJK's signed-volumes sub-algorithm and the closest point on a triangle, against brute force.

The reference shares no code with the engine: the nearest point of a small simplex by
enumerating every face, edge and vertex with a least-squares affine projection
(``ground_truth.simplex_distance``).
"""

from fuzzing import examples
from ground_truth.distances import simplex_distance
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
import numpy as np
import pytest

from collision_engine.signed_volumes import (closest_point_on_triangle, nearest_on_simplex,
                                             nearest_weights_on_triangle)


simplex_points = arrays(np.float64, st.tuples(st.integers(1, 4), st.just(3)),
                        elements=st.floats(-1.0, 1.0))


@settings(max_examples=examples(300), deadline=None)
@given(simplex_points)
def test_sub_algorithm_matches_brute_force(points):
    W = np.zeros((4, 3))
    W[:len(points)] = points
    W = W.ravel()
    count, vx, vy, vz, *_ = nearest_on_simplex(W, len(points), W, False)
    v = np.array([vx, vy, vz])
    assert np.isfinite(v).all()
    assert np.linalg.norm(v) == pytest.approx(simplex_distance(points), abs=1e-12)
    # The kept rows are input points whose hull holds v: the support set.
    kept = W.reshape(4, 3)[:count]
    assert all(np.any(np.all(points == row, axis=1)) for row in kept)
    assert simplex_distance(kept) == pytest.approx(np.linalg.norm(v), abs=1e-12)


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
    count, vx, vy, vz, *_ = nearest_on_simplex(W.ravel(), len(points), W.ravel(), False)
    assert np.isfinite([vx, vy, vz]).all()
    assert np.linalg.norm([vx, vy, vz]) == pytest.approx(simplex_distance(points), abs=1e-12)


@settings(max_examples=examples(200), deadline=None)
@given(arrays(np.float64, (3, 3), elements=st.floats(-1.0, 1.0)))
def test_closest_point_on_a_triangle_and_its_feature(corners):
    d2, vx, vy, vz, feature, which = closest_point_on_triangle(*corners.ravel())
    assert d2 == pytest.approx(simplex_distance(corners) ** 2, abs=1e-12)
    v = np.array([vx, vy, vz])
    if feature == 1:
        np.testing.assert_allclose(v, corners[which], atol=1e-15)
    elif feature == 2:
        a, b = np.delete(corners, which, axis=0)
        # On the edge's segment, not at its ends: orthogonal to it.
        assert abs(np.dot(v, b - a)) <= 1e-9 * np.linalg.norm(b - a) * max(1.0, np.linalg.norm(v))


@settings(max_examples=examples(300), deadline=None)
@given(simplex_points, arrays(np.float64, 3, elements=st.floats(-5.0, 5.0)))
def test_weights_give_the_nearest_point_and_tracked_rows_follow(points, offset):
    W = np.zeros((4, 3))
    W[:len(points)] = points
    A = W + offset  # what each vertex came from: here the vertex moved by a known offset
    W, A = W.ravel(), A.ravel()
    count, vx, vy, vz, *weights = nearest_on_simplex(W, len(points), A, True)
    kept, weights = W.reshape(4, 3)[:count], np.array(weights)
    np.testing.assert_allclose(A.reshape(4, 3)[:count], kept + offset, rtol=0, atol=1e-12)
    assert np.all(weights[:count] >= 0.0) and np.all(weights[count:] == 0.0)
    assert weights.sum() == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(weights[:count] @ kept, [vx, vy, vz], rtol=0, atol=1e-12)


@settings(max_examples=examples(200), deadline=None)
@given(arrays(np.float64, (3, 3), elements=st.floats(-1.0, 1.0)))
def test_nearest_weights_on_a_triangle(corners):
    weights = np.array(nearest_weights_on_triangle(*corners.ravel()))
    assert np.all(weights >= 0.0) and weights.sum() == pytest.approx(1.0, abs=1e-12)
    assert np.linalg.norm(weights @ corners) == pytest.approx(simplex_distance(corners),
                                                              abs=1e-12)
