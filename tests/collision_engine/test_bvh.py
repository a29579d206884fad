"""Exact signed distance to the shipped non-convex hand, against brute force.

``ground_truth.mesh_signed_distance`` tests every triangle and takes the sign from the winding
number: no tree, no pseudonormals, no code shared with the engine.
"""

from fuzzing import examples
from ground_truth.distances import (hand_mesh_path, mesh_signed_distance, sample_near_surface,
                                    simplex_distance)
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
import numpy as np
import pytest

from collision_engine import bvh
from collision_engine.bvh import build_tree, LEAF_SIZE, search_stack_size, tree_depth
from collision_engine.distance import distance
from collision_engine.gjk import STATUS_OK
from collision_engine.mesh_io import load_mesh
from collision_engine.scene import Scene, SceneObject
from collision_engine.shapes import TriangleMesh
from collision_engine.transforms import Pose

POSE = Pose.from_rpy([0.01, -0.02, -0.075], [0.2, 0.1, -0.4])


@pytest.fixture(scope='module')
def hand():
    data = load_mesh(hand_mesh_path(), scale=0.001, check_self_intersection=False)
    assert len(data.vertices) >= 3000
    return TriangleMesh(data.vertices, data.faces)


def query(mesh, local_points):
    world = POSE.to_world(local_points)
    results = [distance(mesh, POSE, p) for p in world]
    assert all(r.status == STATUS_OK for r in results)
    return (np.array([r.distance for r in results]),
            POSE.to_local(np.array([r.point for r in results])))


def check(mesh, local_points, closest_too=True):
    found, closest = query(mesh, local_points)
    truth, truth_closest = mesh_signed_distance(local_points, mesh.vertices, mesh.faces)
    np.testing.assert_allclose(found, truth, rtol=0, atol=1e-14)
    assert np.count_nonzero(np.sign(found) != np.sign(truth)) == 0
    np.testing.assert_allclose(np.linalg.norm(closest - local_points, axis=1), np.abs(found),
                               rtol=0, atol=1e-14)
    if closest_too:
        np.testing.assert_allclose(closest, truth_closest, rtol=0, atol=1e-12)


def test_random_points(hand):
    rng = np.random.default_rng(11)
    low, high = hand.vertices.min(axis=0), hand.vertices.max(axis=0)
    centre, half = 0.5 * (low + high), 0.5 * (high - low)
    check(hand, centre + rng.uniform(-2 * half, 2 * half, size=(1500, 3)))


def test_near_surface_points(hand):
    points, _ = sample_near_surface(hand.vertices, hand.faces, 1500, 0.002,
                                    np.random.default_rng(12))
    check(hand, points)


def unit(vectors):
    return vectors / np.linalg.norm(vectors, axis=-1, keepdims=True)


def feature_points(mesh, rng, count):
    """Points on vertices, edges and faces, each with a direction off the surface there (the
    plain mean of the adjacent face normals: any direction pointing out will do)."""
    corners = mesh.vertices[mesh.faces]
    face_normal = unit(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]))
    vertex_normal = np.zeros_like(mesh.vertices)
    np.add.at(vertex_normal, mesh.faces.ravel(), np.repeat(face_normal, 3, axis=0))
    vertices = rng.choice(len(mesh.vertices), count, replace=False)
    faces = rng.choice(len(mesh.faces), count, replace=False)
    weights = rng.dirichlet(np.ones(3), size=count)
    # An edge (a, b) of a face and the face across it, found by its reversed direction.
    edge_faces = rng.choice(len(mesh.faces), count, replace=False)
    a, b = mesh.faces[edge_faces, 0], mesh.faces[edge_faces, 1]
    directed = {(int(p), int(q)): f for f, face in enumerate(mesh.faces)
                for p, q in ((face[0], face[1]), (face[1], face[2]), (face[2], face[0]))}
    across = np.array([directed[(int(q), int(p))] for p, q in zip(a, b)])
    t = rng.uniform(0.05, 0.95, size=(count, 1))
    return [
        (mesh.vertices[vertices], unit(vertex_normal[vertices])),
        (mesh.vertices[a] + t * (mesh.vertices[b] - mesh.vertices[a]),
         unit(face_normal[edge_faces] + face_normal[across])),
        (np.einsum('fk,fkj->fj', weights, corners[faces]), face_normal[faces]),
    ]


@pytest.mark.parametrize('offset', [1e-9, 1e-10, 1e-11, 1e-12])
def test_points_just_off_vertices_edges_and_faces(hand, offset):
    rng = np.random.default_rng(13)
    for points, direction in feature_points(hand, rng, 100):
        for sign in (1.0, -1.0):
            check(hand, points + sign * offset * direction, closest_too=False)


def test_a_search_told_what_is_enough_stops_only_within_it(hand):
    # The probe's overlap search asks only whether a shell point lies within the deepest depth
    # so far: a triangle that near answers it (a bound from above, sign unknown); a point with
    # none that near gets its exact signed distance.
    floats, ints = bvh.pack_triangle_mesh(hand.vertices, hand.faces)
    size = search_stack_size(ints)
    stack, stack_d2 = np.zeros(size, dtype=np.int64), np.zeros(size)
    points, _ = sample_near_surface(hand.vertices, hand.faces, 600, 0.004,
                                    np.random.default_rng(15))
    truth, _ = mesh_signed_distance(points, hand.vertices, hand.faces)
    enough = 0.002
    answers = np.array([bvh.mesh_distance(floats, 0, ints, 0, *p, -1, stack, stack_d2,
                                          enough * enough)[0] for p in points])
    within = np.abs(truth) <= enough
    assert 0 < np.count_nonzero(within) < len(points)
    assert np.all(np.abs(answers[within]) <= enough)
    assert np.all(np.abs(answers[within]) >= np.abs(truth[within]) - 1e-14)
    np.testing.assert_allclose(answers[~within], truth[~within], rtol=0, atol=1e-14)


def test_the_distance_grid_holds_exact_signed_distances_that_bound_the_field(hand):
    # The probe's overlap search rules shell points out by the grid's bounds: its values must
    # be the exact signed distance (brute force), and the bounds must hold around them.
    floats, ints = bvh.pack_triangle_mesh(hand.vertices, hand.faces, grid_vertices=5000)
    grid = bvh.grid_at(floats, 0, ints, 0)
    origin, spacing = floats[grid:grid + 3], floats[grid + 3]
    shape = floats[grid + 4:grid + 7].astype(int)
    finer = np.ceil(np.ptp(hand.vertices, axis=0) * 1.25 / spacing) + 3
    assert np.prod(shape) <= 5000 < np.prod(finer)
    assert np.all(origin + spacing * (shape - 1) >= hand.vertices.max(axis=0) + spacing - 1e-12)
    assert np.all(origin <= hand.vertices.min(axis=0) - spacing + 1e-12)
    values = floats[grid + bvh.GRID_HEADER:].reshape(shape)
    rng = np.random.default_rng(16)
    picked = rng.integers(0, shape, size=(300, 3))
    truth, _ = mesh_signed_distance(origin + spacing * picked, hand.vertices, hand.faces)
    np.testing.assert_allclose(values[tuple(picked.T)], truth, rtol=0, atol=1e-14)
    near, _ = sample_near_surface(hand.vertices, hand.faces, 300, 2 * spacing, rng)
    low, high = origin - 2 * spacing, origin + spacing * (shape + 1)
    points = np.concatenate((near, rng.uniform(low, high, size=(300, 3))))
    truth, _ = mesh_signed_distance(points, hand.vertices, hand.faces)
    bounds = np.array([bvh.grid_bounds(floats, grid, *p) for p in points])
    beyond = bounds[:, 0] == np.inf
    assert 0 < np.count_nonzero(beyond) and np.all(truth[beyond] > 0.0)
    lower, upper, truth = bounds[~beyond, 0], bounds[~beyond, 1], truth[~beyond]
    assert np.all(lower <= truth + 1e-14) and np.all(truth <= upper + 1e-14)
    assert np.all(upper - lower <= spacing * 3 ** 0.5 + 1e-14)


def test_a_mesh_packed_without_a_grid_bounds_nothing(hand):
    floats, ints = bvh.pack_triangle_mesh(hand.vertices, hand.faces)
    grid = bvh.grid_at(floats, 0, ints, 0)
    assert grid == len(floats) - bvh.GRID_HEADER
    assert bvh.grid_bounds(floats, grid, *hand.vertices[0]) == (-np.inf, np.inf)


def reference_triangle_bound2(corners, point) -> float:
    """The larger squared distance from the point to the triangle's plane and to its box."""
    normal = unit(np.cross(corners[1] - corners[0], corners[2] - corners[0]))
    gaps = np.maximum(np.maximum(corners.min(axis=0) - point, 0.0), point - corners.max(axis=0))
    return max(float(normal @ (point - corners[0])) ** 2, float(gaps @ gaps))


@settings(max_examples=examples(300), deadline=None)
@given(arrays(np.float64, (3, 3), elements=st.floats(-1.0, 1.0)),
       arrays(np.float64, 3, elements=st.floats(-2.0, 2.0)))
def test_the_triangle_bound_is_its_reference_and_below_the_distance(corners, point):
    # The search skips a triangle whose bound is not below the best: it must never exceed the
    # triangle's own distance (brute force, sharing no code).
    normal = np.cross(corners[1] - corners[0], corners[2] - corners[0])
    assume(np.linalg.norm(normal) > 1e-3)
    floats = np.concatenate((corners.ravel(), unit(normal)))
    bound = bvh.triangle_bound2(floats, 0, 1, 0, *point)
    assert bound == pytest.approx(reference_triangle_bound2(corners, point), rel=1e-12, abs=1e-15)
    assert bound <= simplex_distance(corners - point) ** 2 * (1.0 + 1e-12) + 1e-15


def test_tree_covers_every_triangle_once_in_nested_boxes(hand):
    corners = hand.vertices[hand.faces]
    order, boxes, nodes = build_tree(corners)
    assert sorted(order.tolist()) == list(range(len(hand.faces)))
    leaves = nodes[nodes[:, 0] < 0]
    assert leaves[:, 2].max() <= LEAF_SIZE and leaves[:, 2].sum() == len(hand.faces)
    covered = np.zeros(len(hand.faces), dtype=int)
    for (child, first, count), box in zip(nodes, boxes):
        members = corners[order[first:first + count]].reshape(-1, 3)
        assert np.all(members >= box[:3]) and np.all(members <= box[3:])
        if child < 0:
            covered[first:first + count] += 1
        else:
            for c in (child, child + 1):
                assert np.all(boxes[c, :3] >= box[:3]) and np.all(boxes[c, 3:] <= box[3:])
    assert np.all(covered == 1)
    assert tree_depth(nodes) == levels(nodes) - 1


def levels(nodes):
    """Levels of a tree, counted breadth first (the root alone is one level)."""
    count, level = 0, [0]
    while level:
        count += 1
        level = [c for n in level if nodes[n, 0] >= 0 for c in (nodes[n, 0], nodes[n, 0] + 1)]
    return count


@pytest.mark.parametrize('count', [1, 4, 5, 1000, 4097])
def test_median_splits_stay_balanced_even_on_a_degenerate_mesh(count):
    # Every triangle the same, so every centroid coincides: the split is by count alone.
    corners = np.tile(np.eye(3), (count, 1, 1))
    _, _, nodes = build_tree(corners)
    assert tree_depth(nodes) == levels(nodes) - 1 == np.ceil(np.log2(np.ceil(count / LEAF_SIZE)))


def peeling_tree(corners, leaf_size=LEAF_SIZE):
    """The most unbalanced tree: each node splits one leaf off and keeps the rest (along x)."""
    order = np.argsort(corners.mean(axis=1)[:, 0], kind='stable')
    lows, highs = corners.min(axis=1), corners.max(axis=1)

    def box(members):
        return np.concatenate((lows[members].min(axis=0), highs[members].max(axis=0)))

    boxes, nodes, start = [box(order)], [None], 0
    while len(order) - start > leaf_size:
        child = len(nodes)
        nodes[-1] = (child, start, len(order) - start)
        boxes += [box(order[start:start + leaf_size]), box(order[start + leaf_size:])]
        nodes += [(-1, start, leaf_size), None]
        start += leaf_size
    nodes[-1] = (-1, start, len(order) - start)
    return order, np.array(boxes), np.array(nodes, dtype=np.int64)


def test_a_deep_tree_gets_a_search_stack_as_deep(hand, monkeypatch):
    # The search stack used to be 128 entries, unchecked: a tree deeper than that (possible with
    # any split but a median one) would have written past it. It is sized from the depth now.
    monkeypatch.setattr(bvh, 'build_tree', peeling_tree)
    floats, ints = bvh.pack_triangle_mesh(hand.vertices, hand.faces)
    depth = len(hand.faces) // LEAF_SIZE - (len(hand.faces) % LEAF_SIZE == 0)
    assert search_stack_size(ints) == depth + 1 > 2000
    scene = Scene([SceneObject('hand', hand, POSE)])
    assert scene._ints[scene._ints[3]] == depth + 1  # the stack's length, heading the scratch
    rng = np.random.default_rng(14)
    low, high = hand.vertices.min(axis=0), hand.vertices.max(axis=0)
    local = np.concatenate([
        rng.uniform(2 * low - high, 2 * high - low, size=(150, 3)),
        sample_near_surface(hand.vertices, hand.faces, 150, 0.002, rng)[0]])
    truth, _ = mesh_signed_distance(local, hand.vertices, hand.faces)
    found = scene.query_many(POSE.to_world(local))
    np.testing.assert_allclose(found.distance, truth, rtol=0, atol=1e-14)
    assert np.all(found.status == STATUS_OK)
