"""The paper's collision code, re-implemented in ``report_generator/paper_method.py``: by hand.

The expected values are worked out in the docstrings from the geometry and from the MATLAB
code's steps; ``ground_truth`` (analytic box and cylinder, brute-force triangle distance) shares
no code with the re-implementation.
"""
import math

from fuzzing import examples
from ground_truth.distances import (box_signed_distance, cylinder_signed_distance,
                                    mesh_signed_distance)
from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest
from report_generator.paper_method import _point_triangle_distance, PaperMethod

# The unit cube [0, 1]^3 as 12 outward-wound triangles (36 vertex rows), like the authors' STL.
CUBE_CORNERS = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                         [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=float)
CUBE_FACES = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
                       [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]])
CUBE_ROWS = CUBE_CORNERS[CUBE_FACES].reshape(-1, 3)


def cube_truth(point) -> float:
    return float(box_signed_distance(np.asarray(point, dtype=float) - 0.5, (1.0, 1.0, 1.0)))


def prism_rows(sides: int, radius: float, height: float) -> np.ndarray:
    """A cylinder tessellated as the paper's STL: side quads and centre-fan caps, as rows."""
    angles = 2.0 * np.pi * np.arange(sides) / sides
    ring = np.column_stack((radius * np.cos(angles), radius * np.sin(angles)))
    top, bottom = 0.5 * height, -0.5 * height
    rows = []
    for k in range(sides):
        (x0, y0), (x1, y1) = ring[k], ring[(k + 1) % sides]
        rows += [(x0, y0, bottom), (x1, y1, bottom), (x1, y1, top),
                 (x0, y0, bottom), (x1, y1, top), (x0, y0, top),
                 (0, 0, top), (x0, y0, top), (x1, y1, top),
                 (0, 0, bottom), (x1, y1, bottom), (x0, y0, bottom)]
    return np.array(rows, dtype=float)


@pytest.fixture(scope='module')
def cube():
    return PaperMethod(CUBE_ROWS, stiffness=160.0, damping=0.8)


def test_outside_a_face_the_distance_is_right(cube):
    """0.3 above the top face's centre: the first triangle already lies on the face's plane."""
    answer = cube.query((0.5, 0.5, 1.3))
    assert not answer.in_collision
    assert answer.distance.outcome == 'converged'
    assert answer.distance.distance == pytest.approx(0.3, abs=1e-12)
    assert answer.signed_distance == pytest.approx(cube_truth((0.5, 0.5, 1.3)), abs=1e-12)


def test_inside_the_distance_is_unsigned_and_not_the_depth(cube):
    """0.1 below the top face, the flag is set but the distance is 0, not a depth of 0.1.

    The first supports along (1, 1, 1) and its opposite are the corners (1, 1, 1) and (0, 0, 0);
    the third, toward the origin from their line, is (0, 0, 1). The point (0.5, 0.5, 0.9) is
    0.5 (1, 1, 1) + 0.4 (0, 0, 1) + 0.1 (0, 0, 0): it lies in that diagonal triangle, whose
    distance from the point is 0, and the stopping test fires at once.
    """
    answer = cube.query((0.5, 0.5, 0.9))
    assert answer.in_collision
    assert answer.distance.distance == 0.0
    assert cube_truth((0.5, 0.5, 0.9)) == pytest.approx(-0.1)
    assert abs(answer.signed_distance - cube_truth((0.5, 0.5, 0.9))) == pytest.approx(0.1)


def test_a_norm_coincidence_stops_it_20_cm_off_outside_a_face(cube):
    """1 cm below the bottom face, at (0.3, 0.7): it answers 0.219 m.

    Minus the point, the corners (1, 1, 1), (0, 0, 0) and (0, 1, 0) make the first triangle;
    its normal toward the origin, (1, 0, -1)/sqrt(2), picks the corner (1, 1, 0), whose norm
    |(0.7, 0.3, 0.01)| equals that of (0, 0, 0) - p = (-0.3, -0.7, 0.01). The test "a vertex
    norm within 1e-6 of the new one" reads that as convergence, on a triangle that cuts through
    the cube's diagonal.
    """
    answer = cube.query((0.3, 0.7, -0.01))
    assert not answer.in_collision
    assert answer.distance.outcome == 'converged'
    assert cube_truth((0.3, 0.7, -0.01)) == pytest.approx(0.01)
    assert answer.distance.distance > 0.2


def test_at_the_cap_it_returns_the_last_triangle_not_the_best(cube):
    """The MATLAB code saves its best triangle, then overwrites it with the last at the cap."""
    answer = cube.query((0.2, 0.3, 0.95))
    assert answer.in_collision
    assert answer.distance.outcome == 'cap'
    assert answer.distance.passes == 11
    assert answer.distance.distance > answer.distance.best_distance


def test_on_the_cubes_diagonal_the_matlab_code_never_finishes(cube):
    """From (1.5, 1.5, 1.5) the first two supports, (1, 1, 1) and (0, 0, 0), are in line with
    the point, so the third search direction is zero; the support of a zero direction is the
    first row, (0, 0, 0), a duplicate, and so is that of its negative: MATLAB loops forever.
    """
    answer = cube.query((1.5, 1.5, 1.5))
    assert answer.distance.outcome == 'hang'
    assert math.isnan(answer.distance.distance)


def test_near_a_curved_surface_it_measures_the_hull():
    """Beside an 8-sided prism of radius 1: 1.2 m from the axis, 0.01 rad off a facet's middle.

    The facet's plane is cos(pi/8) from the axis, so the hull is 1.2 cos(0.01) - cos(pi/8)
    away; the true cylinder is 0.2 away, 1 - cos(pi/8) = 7.6 cm nearer.
    """
    angle = 5.0 * np.pi / 8.0 + 0.01
    point = (1.2 * np.cos(angle), 1.2 * np.sin(angle), 0.1)
    answer = PaperMethod(prism_rows(8, 1.0, 2.0)).query(point)
    hull = 1.2 * np.cos(0.01) - np.cos(np.pi / 8.0)
    truth = float(cylinder_signed_distance(np.array(point), 1.0, 2.0))
    assert answer.distance.distance == pytest.approx(hull, abs=1e-12)
    assert truth == pytest.approx(0.2)
    assert answer.signed_distance - truth == pytest.approx(1.0 - np.cos(np.pi / 8.0) - 1.2 * (
        1.0 - np.cos(0.01)), abs=1e-12)


def test_force_points_away_from_the_centroid_with_its_unsigned_distance(cube):
    """F = (r/|r|) k dist - kd v, r = tip - centroid (0.5, 0.5, 0.5); zero when not flagged."""
    tip, velocity = np.array([0.2, 0.3, 0.95]), np.array([0.1, -0.2, 0.05])
    dist = cube.query(tip).distance.distance
    radial = tip - 0.5
    expected = radial / np.linalg.norm(radial) * 160.0 * dist - 0.8 * velocity
    np.testing.assert_allclose(cube.force(tip, velocity), expected, rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(cube.force((0.5, 0.5, 1.3), velocity), np.zeros(3))


def test_centroid_is_the_mean_of_rows_duplicates_included():
    rows = np.array([[0.0, 0.0, 0.0]] * 3 + [[4.0, 0.0, 0.0]])
    np.testing.assert_allclose(PaperMethod(rows).centroid, [1.0, 0.0, 0.0])


@settings(max_examples=examples(60), deadline=None)
@given(st.tuples(*[st.floats(-2.0, 3.0)] * 3))
def test_outside_it_never_under_estimates(point):
    """Its triangles are made of hull points, so their distance is at least the hull's.

    Up to the rounding of Eberly's squared distance, a sum of terms as large as |p|² whose
    cancellation leaves it: about eps·|p|² in the square, so 1e-10 m of distance 3.5e-8 m from
    the surface (a case ``make fuzz`` found). So the squares are compared, to that rounding.
    """
    truth = cube_truth(point)
    answer = PaperMethod(CUBE_ROWS).query(point)
    if truth > 1e-9 and answer.distance.outcome != 'hang':
        rounding = 16 * np.finfo(float).eps * (1.0 + float(np.dot(point, point)))
        assert answer.distance.distance ** 2 >= truth ** 2 - rounding


@settings(max_examples=examples(60), deadline=None)
@given(st.lists(st.floats(-1.0, 1.0), min_size=9, max_size=9),
       st.tuples(*[st.floats(-1.0, 1.0)] * 3))
def test_point_triangle_distance_matches_brute_force(corners, origin):
    """Eberly's region tree against the brute-force closest point on the triangle.

    Eberly forms the squared distance as a quadratic form, which cancels to about eps times the
    squared size of the triangle: squared distances are compared, to that.
    """
    triangle = np.array(corners).reshape(3, 3) - np.array(origin)
    doubled_area = np.linalg.norm(np.cross(triangle[1] - triangle[0], triangle[2] - triangle[0]))
    if doubled_area < 1e-6:
        return
    expected = abs(float(mesh_signed_distance(np.zeros(3), triangle, np.array([[0, 1, 2]]))[0]))
    found = _point_triangle_distance(*map(tuple, triangle))
    assert found ** 2 == pytest.approx(expected ** 2, abs=64 * np.finfo(float).eps)


@pytest.mark.parametrize('rows, message', [(np.zeros((0, 3)), 'shape'),
                                           (np.zeros((4, 2)), 'shape'),
                                           (np.array([[0.0, np.nan, 0.0]]), 'NaN')])
def test_bad_vertex_rows_are_refused(rows, message):
    with pytest.raises(ValueError, match=message):
        PaperMethod(rows)


def test_bad_point_is_refused(cube):
    with pytest.raises(ValueError, match='finite'):
        cube.query((np.nan, 0.0, 0.0))
