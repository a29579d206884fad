"""The FCL cross-check: it counts, catches a wrong answer, and never changes or breaks one."""

from ground_truth import scene_path
import numpy as np
import pytest

from collision_engine.cross_validation import fcl_model, FclCrossValidator
from collision_engine.scene import load_scene, Scene, SceneObject
from collision_engine.scene_file import CrossValidationSpec
from collision_engine.shapes import Box, Capsule, ConvexMesh, Cylinder, Sphere
from collision_engine.transforms import Pose

EVERY_QUERY = CrossValidationSpec(fcl=True, every=1, tolerance=1e-6)
OBJECTS = [
    SceneObject('box', Box([0.1, 0.2, 0.05]), Pose.from_rpy([0.2, 0.0, 0.0], [0.1, 0.2, 0.3])),
    SceneObject('ball', Sphere(0.05), Pose.from_rpy([-0.1, 0.05, 0.0])),
    SceneObject('can', Cylinder(0.03, 0.1), Pose.from_rpy([0.0, -0.15, 0.02], [1.0, 0.0, 0.0])),
    SceneObject('pill', Capsule(0.02, 0.1), Pose.from_rpy([0.0, 0.0, 0.1], [0.0, 1.2, 0.0])),
    SceneObject('rock', ConvexMesh(np.random.default_rng(0).normal(size=(40, 3)) * 0.03),
                Pose.from_rpy([0.1, 0.15, -0.05], [0.3, 0.0, 0.2])),
]


@pytest.mark.parametrize('name', ['cuboid', 'cylinder', 'hand', 'paper_cuboid_stl',
                                  'paper_cylinder_stl'])
def test_shipped_scenes_agree_with_fcl(name):
    scene = load_scene(scene_path(name))
    rng = np.random.default_rng(31)
    points = rng.uniform(-0.12, 0.12, size=(200, 3)) + [0.0, 0.0, -0.075]
    checked = [scene.query(p) for p in points]
    every = 10  # as the shipped files say
    assert [r.cross_validated for r in checked] == [k % every == 0 for k in range(200)]
    stats = scene.cross_validation_stats
    assert (stats.checks, stats.disagreements, stats.errors) == (20, 0, 0)
    for r in checked[::every]:
        assert abs(r.distance - r.fcl_distance) == pytest.approx(r.fcl_discrepancy) or (
            name == 'hand' and abs(abs(r.distance) - r.fcl_distance) == r.fcl_discrepancy)
    for r in checked[1::every]:
        assert np.isnan(r.fcl_distance) and np.isnan(r.fcl_discrepancy)


def test_every_shape_type_agrees_within_its_stated_error():
    scene = Scene(OBJECTS, cross_validation=EVERY_QUERY, tip_radius=0.002)
    rng = np.random.default_rng(32)
    for p in rng.uniform(-0.25, 0.25, size=(1000, 3)):
        scene.query(p)
    stats = scene.cross_validation_stats
    assert stats.checks == 1000 and stats.disagreements == 0 and stats.errors == 0


def test_a_wrong_fcl_answer_is_counted_and_changes_nothing(monkeypatch):
    plain = Scene(OBJECTS)
    checked = Scene(OBJECTS, cross_validation=EVERY_QUERY)
    point = (0.3, 0.1, 0.0)
    honest = checked.query(point)
    assert honest.cross_validated and checked.cross_validation_stats.disagreements == 0

    original = FclCrossValidator.fcl_distance

    def off_by_a_millimetre(self, index, tip):
        distance, fcl_point = original(self, index, tip)
        return distance + 1e-3, fcl_point

    monkeypatch.setattr(FclCrossValidator, 'fcl_distance', off_by_a_millimetre)
    result = checked.query(point)
    stats = checked.cross_validation_stats
    assert (stats.checks, stats.disagreements) == (2, 1)
    assert result.fcl_discrepancy == pytest.approx(1e-3, abs=1e-8)
    assert stats.max_discrepancy == pytest.approx(1e-3, abs=1e-8)
    reference = plain.query(point)
    assert result.distance == reference.distance == honest.distance
    np.testing.assert_array_equal(result.point, reference.point)
    np.testing.assert_array_equal(result.normal, reference.normal)


def test_an_fcl_exception_is_counted_not_raised(monkeypatch):
    scene = Scene(OBJECTS, cross_validation=EVERY_QUERY)

    def broken(self, index, tip):
        raise RuntimeError('FCL exploded')

    monkeypatch.setattr(FclCrossValidator, 'fcl_distance', broken)
    result = scene.query((0.3, 0.1, 0.0))
    assert result.distance == Scene(OBJECTS).query((0.3, 0.1, 0.0)).distance
    assert not result.cross_validated and np.isnan(result.fcl_distance)
    stats = scene.cross_validation_stats
    assert (stats.checks, stats.errors) == (0, 1)
    assert stats.last_error == 'RuntimeError: FCL exploded'


def test_results_are_not_stale_after_a_nearer_query():
    # FCL overwrites a reused result only when the new distance is smaller.
    scene = Scene(OBJECTS[:1], cross_validation=EVERY_QUERY)
    near = scene.query((0.2, 0.0, 0.1))
    far = scene.query((0.2, 0.0, 1.0))
    assert far.fcl_distance > near.fcl_distance + 0.5
    assert far.fcl_discrepancy < 1e-6


def test_mesh_distance_is_compared_unsigned_inside():
    scene = load_scene(scene_path('hand'))
    # The centre of the palm is inside the hand: ours is negative, FCL's BVH positive.
    inside = scene.query((0.0, 0.0, -0.075))  # the first query is always checked
    assert inside.distance < 0 and inside.fcl_distance > 0
    assert inside.fcl_discrepancy == pytest.approx(abs(abs(inside.distance)
                                                       - inside.fcl_distance))
    assert scene.cross_validation_stats.disagreements == 0


def test_cylinder_is_checked_against_a_fine_tessellation():
    geometry, signed, relative, absolute = fcl_model(Cylinder(0.025, 0.1))
    assert signed and type(geometry).__name__ == 'Convex'
    assert absolute < 1e-6  # the 512-gon's sagitta, 0.47 um, plus the probe
