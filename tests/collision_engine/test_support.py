"""Support functions of the shapes: the farthest point along a direction, by brute force."""

from fuzzing import examples
from ground_truth import (box_signed_distance, capsule_signed_distance,
                          cylinder_signed_distance, sphere_signed_distance)
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
import numpy as np
import pytest

from collision_engine.shapes import Box, Capsule, ConvexMesh, Cylinder, Sphere

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
