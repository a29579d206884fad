"""The compiled self-intersection check, against linear programming on triangle pairs."""

from fuzzing import examples
from ground_truth.distances import triangles_meet
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
import numpy as np
import pytest

from collision_engine.self_intersection import self_intersections

CUBE_VERTICES = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])
CUBE_FACES = np.array([
    [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
    [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],
])


def welded(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and faces of triangles (m, 3, 3), equal corners made one vertex."""
    vertices, faces = np.unique(corners.reshape(-1, 3), axis=0, return_inverse=True)
    return vertices, faces.reshape(-1, 3)


def corners_sharing(shared: int):
    """Two triangles on a small integer grid, the second taking ``shared`` of the first's
    corners; any other coincidences are left to chance (and counted as shared)."""
    grid = arrays(np.int64, (6, 3), elements=st.integers(-3, 3)).map(lambda a: a.astype(float))
    return grid.map(lambda c: np.stack((c[:3], np.concatenate((c[:shared], c[3:6 - shared])))))


def area(triangle: np.ndarray) -> float:
    return float(np.linalg.norm(np.cross(triangle[1] - triangle[0], triangle[2] - triangle[0])))


@pytest.mark.parametrize('shared', [0, 1, 2])
@settings(max_examples=examples(400), deadline=None)
@given(data=st.data())
def test_a_pair_of_triangles_meets_as_linear_programming_says(shared, data):
    corners = data.draw(corners_sharing(shared))
    assume(area(corners[0]) > 0.0 and area(corners[1]) > 0.0)
    assume(not np.array_equal(np.sort(corners[0], axis=0), np.sort(corners[1], axis=0)))
    vertices, faces = welded(corners)
    count, first, second = self_intersections(vertices, faces)
    assert count == int(triangles_meet(corners[0], corners[1]))
    assert (first, second) == ((0, 1) if count else (-1, -1))


@pytest.mark.parametrize('a, b, meet', [
    # Sharing a corner, one pierces the other's interior from it.
    ([[0, 0, 0], [2, 0, 0], [0, 2, 0]], [[0, 0, 0], [1, 1, 1], [1, 1, -1]], True),
    # Sharing a corner, on either side of each other's planes: a proper fan.
    ([[0, 0, 0], [2, 0, 0], [0, 2, 0]], [[0, 0, 0], [-1, 0, 1], [0, -1, 1]], False),
    # Sharing a corner, touching along a ray from it.
    ([[0, 0, 0], [2, 0, 0], [0, 2, 0]], [[0, 0, 0], [1, 1, 0], [1, 1, 2]], True),
    # Sharing an edge, folded flat onto each other, and flat side by side.
    ([[0, 0, 0], [2, 0, 0], [0, 2, 0]], [[2, 0, 0], [0, 0, 0], [1, 1, 0]], True),
    ([[0, 0, 0], [2, 0, 0], [0, 2, 0]], [[2, 0, 0], [0, 0, 0], [1, -1, 0]], False),
    # Sharing nothing: crossing, a corner touching a face, coplanar overlap, coplanar apart.
    ([[0, 0, 0], [2, 0, 0], [0, 2, 0]], [[0.5, 0.5, -1], [0.5, 0.5, 1], [3, 3, 0]], True),
    ([[0, 0, 0], [2, 0, 0], [0, 2, 0]], [[0.5, 0.5, 0], [0.5, 0.5, 1], [3, 3, 1]], True),
    ([[0, 0, 0], [2, 0, 0], [0, 2, 0]], [[1, 1, 0], [3, 1, 0], [1, 3, 0]], True),
    ([[0, 0, 0], [2, 0, 0], [0, 2, 0]], [[3, 3, 0], [4, 3, 0], [3, 4, 0]], False),
])
def test_each_kind_of_pair(a, b, meet):
    corners = np.array([a, b], dtype=float)
    assert triangles_meet(corners[0], corners[1]) == meet  # the reference agrees
    vertices, faces = welded(corners)
    assert self_intersections(vertices, faces)[0] == int(meet)


def test_closed_cube_does_not_meet_itself():
    assert self_intersections(CUBE_VERTICES, CUBE_FACES) == (0, -1, -1)


def test_every_reported_pair_of_two_overlapping_cubes_really_meets():
    vertices = np.vstack([CUBE_VERTICES, CUBE_VERTICES + [0.5, 0.3, 0.2]])
    faces = np.vstack([CUBE_FACES, CUBE_FACES + 8])
    count, first, second = self_intersections(vertices, faces)
    corners = vertices[faces]
    truth = [(i, j) for i in range(24) for j in range(i + 1, 24)
             if triangles_meet(corners[i], corners[j])]
    assert count == len(truth) > 0 and (first, second) == truth[0]
