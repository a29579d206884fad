"""The compiled winding number, against ground_truth's numpy one and the brute-force sign."""

from ground_truth.distances import hand_mesh_path, mesh_signed_distance, winding_number as truth
import numpy as np
import pytest

from collision_engine.mesh_io import load_mesh
from collision_engine.winding import winding_number


@pytest.fixture(scope='module')
def hand():
    return load_mesh(hand_mesh_path(), scale=0.001, check_self_intersection=False)


def test_winding_number_of_the_hand(hand):
    rng = np.random.default_rng(41)
    low, high = hand.vertices.min(axis=0), hand.vertices.max(axis=0)
    points = rng.uniform(2 * low - high, 2 * high - low, size=(300, 3))
    corners = np.ascontiguousarray(hand.vertices[hand.faces])
    found = np.array([winding_number(corners, *p) for p in points])
    np.testing.assert_allclose(found, truth(points, hand.vertices, hand.faces), atol=1e-9)
    distance, _ = mesh_signed_distance(points, hand.vertices, hand.faces)
    clear = np.abs(distance) > 1e-6
    np.testing.assert_array_equal((found > 0.5)[clear], (distance < 0.0)[clear])
    assert np.all((np.abs(found) < 1e-6) | (np.abs(found - 1.0) < 1e-6))
