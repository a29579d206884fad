"""Support functions of the shapes: the farthest point along a direction, by brute force."""

from decimal import Decimal, localcontext
from itertools import product
import math

from fuzzing import examples
from ground_truth.distances import (box_signed_distance, capsule_signed_distance,
                                    cylinder_signed_distance, sphere_signed_distance)
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
import numpy as np
import pytest

from collision_engine.shapes import Box, Capsule, ConvexMesh, Cylinder, Sphere, TriangleMesh

# Dense samples of each surface (local frame, m), from the shapes' definitions.
ANGLES = np.linspace(0.0, 2.0 * np.pi, 721)
RING = np.column_stack((np.cos(ANGLES), np.sin(ANGLES)))
HEMISPHERE = np.array([[np.cos(a) * np.sin(b), np.sin(a) * np.sin(b), np.cos(b)]
                       for a in ANGLES[::8] for b in np.linspace(0.0, np.pi / 2, 46)])


def samples(shape):
    if isinstance(shape, Box):
        return np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1)
                         for z in (-1, 1)]) * np.array(shape.size) / 2
    if isinstance(shape, Sphere):
        return shape.radius * np.concatenate([HEMISPHERE, -HEMISPHERE])
    if isinstance(shape, Cylinder):
        ring = shape.radius * RING
        h = shape.height / 2
        return np.concatenate([np.column_stack((ring, np.full(len(ring), s * h)))
                               for s in (-1, 1)])
    caps = shape.radius * HEMISPHERE
    h = shape.length / 2
    return np.concatenate([caps + [0, 0, h], -caps - [0, 0, h]])


SHAPES = [Box([0.2, 0.1, 0.05]), Sphere(0.05), Cylinder(0.025, 0.1), Capsule(0.025, 0.1)]
TRUTH = [lambda p: box_signed_distance(p, [0.2, 0.1, 0.05]),
         lambda p: sphere_signed_distance(p, 0.05),
         lambda p: cylinder_signed_distance(p, 0.025, 0.1),
         lambda p: capsule_signed_distance(p, 0.025, 0.1)]


@pytest.mark.parametrize('index', range(4), ids=[type(s).__name__ for s in SHAPES])
@settings(max_examples=examples(100), deadline=None)
@given(direction=arrays(np.float64, 3, elements=st.floats(-1.0, 1.0)))
@example(direction=np.array([3.07e-161, 3.07e-161, 1.0]))  # a radial norm that underflowed
def test_primitive_support_is_the_farthest_point(index, direction):
    assume(np.linalg.norm(direction) > 1e-3)
    direction = direction / np.linalg.norm(direction)
    shape = SHAPES[index]
    point = shape.support(direction)
    assert abs(TRUTH[index](point)) <= 1e-15
    reach = samples(shape) @ direction
    # No sample reaches farther, and the sampling resolution bounds how much farther it is.
    assert point @ direction >= reach.max() - 1e-15
    assert point @ direction <= reach.max() + 1e-4


@settings(max_examples=examples(100), deadline=None)
@given(arrays(np.float64, st.tuples(st.integers(4, 100), st.just(3)),
              elements=st.floats(-1.0, 1.0)),
       arrays(np.float64, (10, 3), elements=st.floats(-1.0, 1.0)))
def test_convex_mesh_hill_climb_finds_the_best_vertex(cloud, directions):
    try:
        shape = ConvexMesh(cloud)
    except ValueError:
        return
    for direction in directions:
        assert shape.support(direction) @ direction == pytest.approx(
            np.max(cloud @ direction), abs=1e-15)


def test_zero_direction_gives_a_point_of_the_shape():
    for shape in SHAPES:
        assert np.all(np.isfinite(shape.support([0.0, 0.0, 0.0])))


EPS = float(np.finfo(np.float64).eps)
UNDERFLOWED = (3.07e-161, 3.07e-161, 1.0)
# Every sign pattern of every mix of subnormal, tiny, ordinary and huge components.
EXTREME_DIRECTIONS = [UNDERFLOWED] + [
    tuple(sign * magnitude for sign, magnitude in zip(signs, magnitudes))
    for magnitudes in product((5e-324, 1e-300, 1.0, 1e300), repeat=3)
    for signs in product((1.0, -1.0), repeat=3)]
HULL = ConvexMesh(np.random.default_rng(5).normal(size=(60, 3)) * [0.03, 0.02, 0.01])
CUBE_CORNERS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
CUBE_FACES = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                       [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])


def exact_reach(shape, direction) -> Decimal:
    """The support function h(u) = max over the shape of x . u, u the unit direction, to 60
    digits: the shapes' closed forms, or every hull vertex, in decimal arithmetic."""
    with localcontext() as context:
        context.prec = 60
        d = [Decimal(float(c)) for c in direction]
        norm = sum(c * c for c in d).sqrt()
        u = [c / norm for c in d]
        radial = (u[0] ** 2 + u[1] ** 2).sqrt()
        if isinstance(shape, Box):
            return sum(abs(c) * Decimal(s) / 2 for c, s in zip(u, shape.size))
        if isinstance(shape, Sphere):
            return Decimal(shape.radius)
        if isinstance(shape, Cylinder):
            return Decimal(shape.radius) * radial + Decimal(shape.height) / 2 * abs(u[2])
        if isinstance(shape, Capsule):
            return Decimal(shape.radius) + Decimal(shape.length) / 2 * abs(u[2])
        return max(sum(Decimal(float(x)) * c for x, c in zip(vertex, u))
                   for vertex in shape.vertices)


def reach_of(point, direction) -> Decimal:
    """x . u for the engine's point x, to 60 digits."""
    with localcontext() as context:
        context.prec = 60
        d = [Decimal(float(c)) for c in direction]
        norm = sum(c * c for c in d).sqrt()
        return sum(Decimal(float(x)) * c / norm for x, c in zip(point, d))


def on_surface(shape, point) -> float:
    """|signed distance| of a point to the shape: analytic, or to the hull's facet planes."""
    if isinstance(shape, ConvexMesh):
        return 0.0 if np.any(np.all(shape.vertices == point, axis=1)) else math.inf
    return abs(TRUTH[[type(s) for s in SHAPES].index(type(shape))](point))


@pytest.mark.parametrize('shape', [*SHAPES, HULL], ids=lambda s: type(s).__name__)
def test_support_is_exact_for_tiny_subnormal_and_huge_directions(shape):
    size = 2.0 * shape.bounding_sphere()[1]
    for direction in EXTREME_DIRECTIONS:
        point = shape.support(direction)
        assert on_surface(shape, point) <= 2 * EPS * size, direction
        # Farthest along the direction: its reach is the support function's, to rounding.
        assert abs(reach_of(point, direction) - exact_reach(shape, direction)) \
            <= Decimal(4 * EPS * size), direction


@pytest.mark.parametrize('shape', SHAPES, ids=lambda s: type(s).__name__)
@settings(max_examples=examples(200), deadline=None)
@given(direction=arrays(np.float64, 3,
                        elements=st.floats(allow_nan=False, allow_infinity=False)))
def test_primitive_support_is_exact_for_any_finite_direction(shape, direction):
    assume(np.any(direction != 0.0))
    point = shape.support(direction)
    size = 2.0 * shape.bounding_sphere()[1]
    assert on_surface(shape, point) <= 2 * EPS * size
    assert abs(reach_of(point, direction) - exact_reach(shape, direction)) \
        <= Decimal(4 * EPS * size)


def test_the_underflowed_cylinder_direction_gives_the_rim_point():
    # The CI failure: the radial norm sqrt(dx^2 + dy^2) underflowed, 1.25e-05 m off the rim.
    r, h = 0.025, 0.1
    point = Cylinder(r, h).support(UNDERFLOWED)
    np.testing.assert_allclose(point, [r / math.sqrt(2.0), r / math.sqrt(2.0), h / 2], rtol=0,
                               atol=EPS * r)


@pytest.mark.parametrize('shape', [*SHAPES, HULL], ids=lambda s: type(s).__name__)
def test_infinite_components_give_a_support_point_of_the_limit_direction(shape):
    size = 2.0 * shape.bounding_sphere()[1]
    for direction, limit in (((math.inf, 1.0, -2.0), (1.0, 0.0, 0.0)),
                             ((-math.inf, math.inf, 5e-324), (-1.0, 1.0, 0.0)),
                             ((1e300, -5.0, -math.inf), (0.0, 0.0, -1.0))):
        point = shape.support(direction)
        assert on_surface(shape, point) <= 2 * EPS * size
        assert abs(reach_of(point, limit) - exact_reach(shape, limit)) <= Decimal(4 * EPS * size)


@pytest.mark.parametrize('shape', [*SHAPES, HULL], ids=lambda s: type(s).__name__)
def test_nan_direction_gives_a_point_of_the_shape(shape):
    for direction in ((math.nan, 1.0, 0.0), (0.0, 0.0, math.nan)):
        point = shape.support(direction)
        assert np.all(np.isfinite(point))
        assert on_surface(shape, point) <= 2 * EPS * 2.0 * shape.bounding_sphere()[1]


def test_triangle_mesh_support_is_the_farthest_vertex_for_extreme_directions():
    mesh = TriangleMesh(CUBE_CORNERS * [0.03, 0.02, 0.01], CUBE_FACES)
    size = 2.0 * mesh.bounding_sphere()[1]
    for direction in EXTREME_DIRECTIONS:
        best = max(reach_of(vertex, direction) for vertex in mesh.vertices)
        assert abs(reach_of(mesh.support(direction), direction) - best) \
            <= Decimal(4 * EPS * size), direction
