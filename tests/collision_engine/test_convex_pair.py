"""The pair query, against ground truth that shares no code with the engine.

Polytope pairs: the origin against scipy's hull of the Minkowski difference of their vertices
(``ground_truth.polytope_pair_distance``), which gives the separation and the penetration depth.
Primitive pairs: closed forms (sphere-sphere, sphere-box, capsule-capsule by segment distance,
box-plane). Every case within 1e-9 m.
"""

from itertools import product

from fuzzing import examples
from ground_truth.distances import (box_signed_distance, polytope_pair_distance, segment_distance)
from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from collision_engine import (Box, Capsule, ConvexMesh, Cylinder, distance_between,
                              DistanceRequest, Pose, Sphere, STATUS_OK, TriangleMesh)

TOLERANCE = 1e-9  # m


def corners(size) -> np.ndarray:
    """The 8 corners of a box of full edge lengths ``size``, centred, local frame."""
    return np.array(list(product(*[(-0.5 * s, 0.5 * s) for s in size])))


def vertices(shape, pose) -> np.ndarray:
    """A polytope's vertices in the world frame."""
    local = corners(shape.size) if isinstance(shape, Box) else shape.vertices
    return pose.to_world(local)


def random_pose(rng, spread=0.05) -> Pose:
    return Pose(Rotation.random(random_state=rng).as_matrix(), rng.uniform(-spread, spread, 3))


def random_polytope(rng, scale=0.02):
    """A box of random aspect or the hull of random points, about ``scale`` m across."""
    if rng.random() < 0.5:
        return Box(scale * rng.uniform(0.05, 1.0, 3))
    return ConvexMesh(rng.normal(size=(rng.integers(4, 40), 3)) * scale * rng.uniform(0.1, 1, 3))


def check_witnesses(result):
    """B's witness minus A's is the distance times the unit normal."""
    a, b = result.witness_points
    assert np.linalg.norm(result.normal) == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(b - a, result.distance * result.normal, rtol=0, atol=1e-12)


def assert_same_distance(first, second):
    """Equal within 1e-9 m when both converged; else their proven brackets overlap.

    Curved pairs in overlap (a cylinder) stop at EPA's iteration cap: the true distance is
    then known to lie in [lower_bound, distance] only.
    """
    if first.status == second.status == STATUS_OK:
        assert second.distance == pytest.approx(first.distance, abs=TOLERANCE)
    assert first.lower_bound - TOLERANCE <= second.distance
    assert second.lower_bound - TOLERANCE <= first.distance


def unique_normal(first, second, *pair) -> bool:
    """Whether both normals are pinned to 1e-6: apart, converged, and no cylinder.

    On a curved support a distance exact to 1e-12 leaves the direction known to about the
    square root of that, as it is second order in the direction.
    """
    return (first.status == second.status == STATUS_OK and first.distance > 1e-6
            and not any(isinstance(shape, Cylinder) for shape in pair))


def test_polytope_pairs_match_the_minkowski_hull():
    rng = np.random.default_rng(11)
    apart = overlapping = 0
    for _ in range(300):
        shape_a, shape_b = random_polytope(rng), random_polytope(rng)
        pose_a, pose_b = random_pose(rng, 0.015), random_pose(rng, 0.015)
        truth = polytope_pair_distance(vertices(shape_a, pose_a), vertices(shape_b, pose_b))
        result = distance_between(shape_a, pose_a, shape_b, pose_b)
        assert result.status == STATUS_OK
        assert result.distance == pytest.approx(truth, abs=TOLERANCE)
        assert result.lower_bound <= result.distance + 1e-15
        check_witnesses(result)
        apart += truth > TOLERANCE
        overlapping += truth < -TOLERANCE
    assert apart > 50 and overlapping > 50  # both branches (GJK, EPA) were exercised


@pytest.mark.parametrize('scale', [1e-6, 1e-3, 1.0, 1e3])
def test_rotated_extreme_aspect_boxes_at_any_scale(scale):
    rng = np.random.default_rng(12)
    for _ in range(40):
        # Plates and needles: aspect up to 1e4.
        shape_a = Box(scale * np.array([1.0, 1e-2, 1e-4])[rng.permutation(3)])
        shape_b = Box(scale * np.array([0.5, 0.5, 1e-3]))
        pose_a = random_pose(rng, 0.0)
        pose_b = random_pose(rng, 0.6 * scale)
        truth = polytope_pair_distance(vertices(shape_a, pose_a), vertices(shape_b, pose_b))
        # The request's absolute tolerance scaled too: then the answer is scale-free.
        result = distance_between(shape_a, pose_a, shape_b, pose_b,
                                  DistanceRequest(abs_tol=1e-12 * scale))
        assert result.distance == pytest.approx(truth, abs=min(TOLERANCE, 1e-9 * scale))
        check_witnesses(result)


@pytest.mark.parametrize('offset, rpy, truth', [
    ([1.0, 0.0, 0.0], [0, 0, 0], 0.0),                           # faces flush
    ([1.0, 0.3, 0.2], [0, 0, 0], 0.0),                           # faces flush, shifted
    ([1.0, 1.0, 0.0], [0, 0, 0], 0.0),                           # edge on edge
    ([1.0, 1.0, 1.0], [0, 0, 0], 0.0),                           # corner on corner
    ([0.5 + 0.5 * np.sqrt(2), 0.0, 0.0], [0, 0, np.pi / 4], 0.0),  # edge on face
    ([1.0 + 1e-12, 0.0, 0.0], [0, 0, 0], 1e-12),                 # a picometre apart
    ([1.0 - 1e-12, 0.0, 0.0], [0, 0, 0], -1e-12),                # a picometre deep
    ([1.001, 0.2, -0.1], [0, 0, 0], 0.001),                      # parallel faces
    ([0.999, 0.2, -0.1], [0, 0, 0], -0.001),
])
def test_touching_and_parallel_unit_cubes(offset, rpy, truth):
    cube = Box([1.0, 1.0, 1.0])
    pose_b = Pose.from_rpy(offset, rpy)
    result = distance_between(cube, Pose(), cube, pose_b)
    assert result.distance == pytest.approx(truth, abs=1e-12)
    assert polytope_pair_distance(corners(cube.size), vertices(cube, pose_b)) == pytest.approx(
        truth, abs=1e-12)
    check_witnesses(result)
    if abs(truth) > 0.0:
        assert abs(result.normal[0]) == pytest.approx(1.0, abs=1e-12)


def test_spheres_match_the_closed_form():
    rng = np.random.default_rng(13)
    for _ in range(200):
        ra, rb = rng.uniform(0.001, 0.05, 2)
        ca, cb = rng.uniform(-0.05, 0.05, (2, 3))
        result = distance_between(Sphere(ra), Pose(translation=ca), Sphere(rb),
                                  Pose(translation=cb))
        assert result.distance == pytest.approx(np.linalg.norm(cb - ca) - ra - rb,
                                                abs=TOLERANCE)
        check_witnesses(result)
        np.testing.assert_allclose(np.linalg.norm(result.witness_points - [ca, cb], axis=1),
                                   [ra, rb], rtol=0, atol=1e-15 + 1e-12)


@pytest.mark.parametrize('sphere_first', [True, False])
def test_sphere_and_box_match_the_closed_form(sphere_first):
    rng = np.random.default_rng(14)
    for _ in range(200):
        box, box_pose = Box(rng.uniform(0.005, 0.05, 3)), random_pose(rng, 0.0)
        radius, centre = rng.uniform(0.001, 0.02), rng.uniform(-0.05, 0.05, 3)
        sphere, sphere_pose = Sphere(radius), Pose(translation=centre)
        truth = float(box_signed_distance(box_pose.to_local(centre), box.size)) - radius
        if sphere_first:
            result = distance_between(sphere, sphere_pose, box, box_pose)
        else:
            result = distance_between(box, box_pose, sphere, sphere_pose)
        assert result.distance == pytest.approx(truth, abs=TOLERANCE)
        check_witnesses(result)
        on_box = result.witness_points[1 if sphere_first else 0]
        assert box_signed_distance(box_pose.to_local(on_box), box.size) == pytest.approx(
            0.0, abs=1e-12)


def test_capsules_match_the_segment_distance():
    rng = np.random.default_rng(15)
    for _ in range(300):
        capsules = [Capsule(rng.uniform(0.001, 0.01), rng.uniform(0.005, 0.05)) for _ in 'ab']
        poses = [random_pose(rng, 0.03) for _ in 'ab']
        ends = [pose.to_world([[0, 0, -0.5 * c.length], [0, 0, 0.5 * c.length]])
                for c, pose in zip(capsules, poses)]
        truth = segment_distance(*ends[0], *ends[1]) - capsules[0].radius - capsules[1].radius
        result = distance_between(capsules[0], poses[0], capsules[1], poses[1])
        assert result.distance == pytest.approx(truth, abs=TOLERANCE)
        check_witnesses(result)


@pytest.mark.parametrize('rpy', [[0, 0, 0], [0, np.pi / 2, 0], [0.4, 0, 0], [np.pi / 2, 0, 0]])
def test_crossing_and_parallel_capsules(rpy):
    # Crossing axes have depth zero between their cores: the capsules overlap by both radii.
    first, second = Capsule(0.01, 0.1), Capsule(0.02, 0.1)
    result = distance_between(first, Pose(), second, Pose.from_rpy([0.0, 0.0, 0.01], rpy))
    assert result.distance == pytest.approx(-0.03, abs=1e-15)
    check_witnesses(result)
    axis = Pose.from_rpy(rpy=rpy).rotation[:, 2]
    if np.linalg.norm(np.cross(axis, [0, 0, 1])) > 0.1:
        assert abs(result.normal @ axis) <= 1e-12 and abs(result.normal[2]) <= 1e-12


def test_box_against_a_plane():
    # The plane is the top face of a slab 1 km wide: far from its edges, box-box is box-plane,
    # whose signed distance is that of the box's lowest corner, in overlap as well.
    slab = Box([1000.0, 1000.0, 1.0])
    slab_pose = Pose(translation=[0.0, 0.0, -0.5])
    rng = np.random.default_rng(16)
    for height in np.concatenate((rng.uniform(-0.01, 0.03, 60), [0.0])):
        box, pose = Box([0.04, 0.01, 0.02]), random_pose(rng, 0.0)
        lowest = pose.to_world(corners(box.size))[:, 2].min()
        pose = Pose(pose.rotation, [0.1, -0.2, height - lowest])
        result = distance_between(slab, slab_pose, box, pose)
        assert result.distance == pytest.approx(height, abs=TOLERANCE)
        np.testing.assert_allclose(result.normal, [0.0, 0.0, 1.0], atol=1e-9)


@pytest.mark.parametrize('guess', [(1e-300, 5e-324, 1e300), (5e-324, 0.0, 0.0),
                                   (1e-300, -1e-300, 1e-300), (0.0, 0.0, -1e300)])
def test_underflowing_and_huge_first_directions(guess):
    rng = np.random.default_rng(17)
    for _ in range(30):
        shape_a, shape_b = random_polytope(rng), Cylinder(0.01, 0.03)
        pose_a, pose_b = random_pose(rng), random_pose(rng, 0.1)
        plain = distance_between(shape_a, pose_a, shape_b, pose_b)
        guided = distance_between(shape_a, pose_a, shape_b, pose_b, DistanceRequest(guess=guess))
        assert guided.distance == pytest.approx(plain.distance, abs=TOLERANCE)
        assert np.all(np.isfinite(guided.witness_points)) and np.all(np.isfinite(guided.normal))


@pytest.mark.parametrize('offset', [[1e300, 0.0, 0.0], [1e300, 1e300, -1e300],
                                    [1.0, 1e-300, 5e-324], [5e-324, 0.0, 0.0],
                                    [1e-300, -1e-300, 1e-300], [1.0 + 2e-16, 5e-324, 0.0]])
def test_huge_and_underflowing_offsets(offset):
    # Unit cubes, and a cube against a unit ball: their closed forms at any offset (the
    # squares of the offsets here underflow to 0 or overflow to inf).
    cube, ball = Box([1.0, 1.0, 1.0]), Sphere(0.5)
    offset = np.array(offset)
    gaps = np.maximum(np.abs(offset) - 1.0, 0.0)
    box_box = float(np.hypot(np.hypot(gaps[0], gaps[1]), gaps[2]))
    if box_box == 0.0:
        box_box = float(np.max(np.abs(offset)) - 1.0)  # overlap: the least push out
    for pair, truth in (((cube, cube), box_box),
                        ((cube, ball), float(box_signed_distance(offset, cube.size)) - 0.5)):
        result = distance_between(pair[0], Pose(), pair[1], Pose(translation=offset))
        assert result.status == STATUS_OK
        assert result.distance == pytest.approx(truth, rel=1e-15, abs=1e-15)
        assert np.all(np.isfinite(result.witness_points)) and np.all(np.isfinite(result.normal))


def test_a_non_convex_mesh_is_refused():
    tetrahedron = TriangleMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]],
                               [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    with pytest.raises(ValueError, match='not a convex shape'):
        distance_between(tetrahedron, Pose(), Sphere(0.1), Pose())


def shapes():
    return st.sampled_from([Box([0.04, 0.01, 0.02]), Sphere(0.01), Capsule(0.005, 0.03),
                            Cylinder(0.01, 0.02), ConvexMesh(np.random.default_rng(5).normal(
                                size=(30, 3)) * 0.01)])


def poses(spread=0.04):
    return st.builds(lambda q, t: Pose(Rotation.from_quat(q).as_matrix(), t),
                     st.tuples(*[st.floats(-1, 1)] * 4).filter(lambda q: np.linalg.norm(q) > 0.1),
                     st.tuples(*[st.floats(-spread, spread)] * 3))


@settings(max_examples=examples(150), deadline=None)
@given(shapes(), poses(), shapes(), poses())
def test_symmetry(shape_a, pose_a, shape_b, pose_b):
    forward = distance_between(shape_a, pose_a, shape_b, pose_b)
    backward = distance_between(shape_b, pose_b, shape_a, pose_a)
    assert_same_distance(forward, backward)
    if unique_normal(forward, backward, shape_a, shape_b):
        np.testing.assert_allclose(backward.normal, -forward.normal, atol=1e-6)


@settings(max_examples=examples(150), deadline=None)
@given(shapes(), poses(), shapes(), poses(), poses(spread=10.0))
def test_invariance_under_a_shared_rigid_motion(shape_a, pose_a, shape_b, pose_b, motion):
    before = distance_between(shape_a, pose_a, shape_b, pose_b)
    moved = [Pose(motion.rotation @ p.rotation, motion.to_world(p.translation))
             for p in (pose_a, pose_b)]
    after = distance_between(shape_a, moved[0], shape_b, moved[1])
    assert_same_distance(before, after)
    if unique_normal(before, after, shape_a, shape_b):
        np.testing.assert_allclose(after.normal, motion.rotation @ before.normal, atol=1e-6)


@settings(max_examples=examples(150), deadline=None)
@given(shapes(), poses(), shapes(), poses(), st.floats(1e-6, 0.05))
def test_monotone_under_separation(shape_a, pose_a, shape_b, pose_b, step):
    # Moving B along the normal by `step` adds exactly `step` once apart, and never subtracts.
    before = distance_between(shape_a, pose_a, shape_b, pose_b)
    pose = Pose(pose_b.rotation, pose_b.translation + step * before.normal)
    after = distance_between(shape_a, pose_a, shape_b, pose)
    assert after.distance >= before.lower_bound - TOLERANCE
    if before.status == after.status == STATUS_OK and before.distance > TOLERANCE:
        assert after.distance == pytest.approx(before.distance + step, abs=TOLERANCE)


def test_fcl_agrees_on_separated_pairs():
    fcl = pytest.importorskip('fcl')

    def model(shape):
        if isinstance(shape, Box):
            return fcl.Box(*shape.size)
        if isinstance(shape, Sphere):
            return fcl.Sphere(shape.radius)
        if isinstance(shape, Capsule):
            return fcl.Capsule(shape.radius, shape.length)
        faces = np.column_stack((np.full(len(shape.faces), 3), shape.faces)).ravel()
        return fcl.Convex(shape.vertices, len(shape.faces), faces)

    rng = np.random.default_rng(18)
    compared = 0
    for _ in range(300):
        pair = [rng.choice([Box(rng.uniform(0.005, 0.04, 3)), Sphere(rng.uniform(0.002, 0.02)),
                            Capsule(rng.uniform(0.002, 0.01), rng.uniform(0.005, 0.04)),
                            random_polytope(rng)]) for _ in 'ab']
        poses_ = [random_pose(rng, 0.06) for _ in 'ab']
        ours = distance_between(pair[0], poses_[0], pair[1], poses_[1])
        if ours.distance < 1e-3:
            continue  # FCL is trusted apart only
        objects = [fcl.CollisionObject(model(s), fcl.Transform(p.rotation, p.translation))
                   for s, p in zip(pair, poses_)]
        theirs = fcl.distance(*objects, fcl.DistanceRequest(), fcl.DistanceResult())
        # FCL's GJK stops at a relative gap (cross_validation: up to ~3 % of the distance),
        # from above: its distance is between two points of the shapes, never below ours.
        assert ours.distance - 1e-9 <= theirs <= ours.distance * 1.03 + 1e-9
        compared += 1
    assert compared > 100
