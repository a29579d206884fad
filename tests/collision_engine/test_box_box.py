"""Two overlapping boxes in closed form (``box_box``), against ground truth sharing no code.

The depth: scipy's hull of the Minkowski difference of the corners
(``ground_truth.polytope_pair_distance``). The witnesses: each on its own box's surface
(``ground_truth.box_signed_distance`` zero), B's being A's moved by the depth against the normal.
Every depth within 1e-9 m of the truth (relative, below a metre), the witnesses within 1e-12 of
the boxes' size. The closed form must answer the general cases itself, and where it declines the
pair query (EPA) still answers exactly.
"""

from itertools import product

from ground_truth.distances import box_signed_distance, polytope_pair_distance
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from collision_engine import Box, distance_between, Pose
from collision_engine.box_box import box_box_depth

TOLERANCE = 1e-9  # m, relative below a metre


def corners(size) -> np.ndarray:
    return np.array(list(product(*[(-0.5 * s, 0.5 * s) for s in size])))


def closed_form(size_a, size_b, rotation, translation):
    """box_box_depth for B posed by (rotation, translation) in A's frame: (ok, depth, a, n)."""
    rel = np.concatenate((np.asarray(rotation, dtype=np.float64).ravel(), translation))
    ok, depth, ax, ay, az, nx, ny, nz = box_box_depth(tuple(0.5 * np.asarray(size_a)),
                                                      tuple(0.5 * np.asarray(size_b)), rel)
    return ok, depth, np.array([ax, ay, az]), np.array([nx, ny, nz])


def check_against_truth(size_a, size_b, rotation, translation):
    """Assert the closed form answers, with the hull's depth and witnesses on both boxes."""
    truth = polytope_pair_distance(corners(size_a),
                                   corners(size_b) @ np.asarray(rotation).T + translation)
    ok, depth, a, n = closed_form(size_a, size_b, rotation, translation)
    assert ok
    scale = max(max(size_a), max(size_b))
    assert -depth == pytest.approx(truth, abs=TOLERANCE * min(1.0, scale))
    assert np.linalg.norm(n) == pytest.approx(1.0, abs=1e-12)
    b = a - depth * n
    assert abs(box_signed_distance(a, size_a)) <= 1e-12 * scale
    assert abs(box_signed_distance((b - translation) @ np.asarray(rotation),
                                   size_b)) <= 1e-12 * scale
    return n


def along_edges(normal, rotation) -> bool:
    """Whether the normal is along no face axis of either box: an edge-edge axis."""
    return max(np.abs(normal).max(), np.abs(normal @ rotation).max()) < 1.0 - 1e-9


def test_random_overlapping_boxes_match_the_minkowski_hull():
    rng = np.random.default_rng(41)
    answered = edges = 0
    for _ in range(300):
        size_a, size_b = rng.uniform(0.005, 0.05, 3), rng.uniform(0.005, 0.05, 3)
        rotation = Rotation.random(random_state=rng).as_matrix()
        translation = rng.uniform(-0.5, 0.5, 3) * (size_a + size_b) * 0.8
        if polytope_pair_distance(corners(size_a), corners(size_b) @ rotation.T
                                  + translation) < -TOLERANCE:
            normal = check_against_truth(size_a, size_b, rotation, translation)
            answered += 1
            edges += along_edges(normal, rotation)
    assert answered > 150 and edges > 10  # face axes and edge-edge axes both won


@pytest.mark.parametrize('scale', [1e-6, 1e-3, 1.0, 1e3])
def test_rotated_plates_and_needles_at_any_scale(scale):
    rng = np.random.default_rng(42)
    answered = 0
    for _ in range(60):
        size_a = scale * np.array([1.0, 1e-2, 1e-4])[rng.permutation(3)]
        size_b = scale * np.array([0.5, 0.5, 1e-3])
        rotation = Rotation.random(random_state=rng).as_matrix()
        translation = rng.uniform(-0.05, 0.05, 3) * scale
        if polytope_pair_distance(corners(size_a), corners(size_b) @ rotation.T
                                  + translation) < -TOLERANCE * min(1.0, scale):
            check_against_truth(size_a, size_b, rotation, translation)
            answered += 1
    assert answered > 20


@pytest.mark.parametrize('tilt', [0.05, 0.3, np.radians(20.0)])
@pytest.mark.parametrize('spin', [0.4, 1.3, 2.5])
def test_a_tilted_probe_edge_down_on_a_block(tilt, spin):
    """The probe's lowest feature is an edge parallel to the block's top (a tie to clip)."""
    block, probe = np.array([0.2, 0.1, 0.05]), np.array([0.04, 0.01, 0.02])
    rotation = (Rotation.from_rotvec([0.0, 0.0, spin])
                * Rotation.from_rotvec([tilt, 0.0, 0.0])).as_matrix()
    lowest = (corners(probe) @ rotation.T)[:, 2].min()
    for depth in (1e-12, 1e-6, 0.001, 0.004):
        translation = np.array([0.01, -0.02, 0.025 - lowest - depth])
        check_against_truth(block, probe, rotation, translation)


@pytest.mark.parametrize('rotvec', [[0.3, 0.5, 0.7], [0.1, 0.6, 0.05], [1.1, 0.2, 0.4]])
def test_a_corner_pressed_into_a_face(rotvec):
    cube = np.array([1.0, 1.0, 1.0])
    rotation = Rotation.from_rotvec(rotvec).as_matrix()
    turned = corners(cube) @ rotation.T
    lowest = turned[np.argmin(turned[:, 0])]
    for depth in (1e-9, 0.01, 0.2):
        check_against_truth(cube, cube, rotation, np.array([0.5 - depth, 0.1, -0.05]) - lowest)


def test_a_touching_corner_is_answered_or_declined_never_wrong():
    cube = np.array([1.0, 1.0, 1.0])
    rotation = Rotation.from_rotvec([0.3, 0.5, 0.7]).as_matrix()
    turned = corners(cube) @ rotation.T
    lowest = turned[np.argmin(turned[:, 0])]
    ok, depth, a, n = closed_form(cube, cube, rotation, np.array([0.5, 0.1, -0.05]) - lowest)
    assert not ok or abs(depth) <= 1e-12


@pytest.mark.parametrize('rotation', [np.eye(3), Rotation.from_rotvec([0, 0, 0.5]).as_matrix()])
def test_parallel_edges_decline_and_the_pair_query_still_answers(rotation):
    """Boxes sharing an edge direction: the closed form declines (module doc), EPA answers."""
    size_a, size_b = np.array([0.03, 0.02, 0.01]), np.array([0.01, 0.02, 0.03])
    translation = np.array([0.015, 0.004, -0.002])
    assert not closed_form(size_a, size_b, rotation, translation)[0]
    truth = polytope_pair_distance(corners(size_a), corners(size_b) @ rotation.T + translation)
    result = distance_between(Box(size_a), Pose(), Box(size_b), Pose(rotation, translation))
    assert result.distance == pytest.approx(truth, abs=TOLERANCE)


def test_the_pair_query_gives_the_closed_form_s_answer():
    rng = np.random.default_rng(43)
    size_a, size_b = np.array([0.03, 0.02, 0.01]), np.array([0.01, 0.04, 0.02])
    rotation = Rotation.random(random_state=rng).as_matrix()
    translation = np.array([0.01, 0.005, 0.008])
    ok, depth, a, n = closed_form(size_a, size_b, rotation, translation)
    assert ok
    result = distance_between(Box(size_a), Pose(), Box(size_b), Pose(rotation, translation))
    assert result.distance == -depth
    np.testing.assert_array_equal(result.witness_points[0], a)
    np.testing.assert_array_equal(result.normal, n)
