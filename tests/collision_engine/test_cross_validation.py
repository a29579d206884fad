"""The FCL cross-check: off the query's thread, it counts, catches a wrong answer (distance or
sign), never changes or delays one, and stops."""

import gc
import threading

from ground_truth.distances import scene_path, winding_number
import numpy as np
import pytest

from collision_engine import _kernels, scene as scene_module
from collision_engine.cross_validation import (fcl_model, FclCrossValidator,
                                               QUEUE_CAPACITY)
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
PALM = (0.0, 0.0, -0.075)  # inside the shipped hand


@pytest.fixture
def checked_scenes():
    """Scenes made by a test, closed after it (their worker threads stopped)."""
    made = []
    yield made
    for scene in made:
        scene.close()


def checked(made, scene):
    made.append(scene)
    return scene


@pytest.mark.parametrize('name', ['cuboid', 'cylinder', 'hand', 'paper_cuboid_stl',
                                  'paper_cylinder_stl'])
def test_shipped_scenes_agree_with_fcl(checked_scenes, name):
    scene = checked(checked_scenes, load_scene(scene_path(name)))
    rng = np.random.default_rng(31)
    points = rng.uniform(-0.12, 0.12, size=(200, 3)) + [0.0, 0.0, -0.075]
    results = [scene.query(p) for p in points]
    every = 10  # as the shipped files say; 20 samples fit the queue, so none is dropped
    assert [r.cross_validated for r in results] == [k % every == 0 for k in range(200)]
    assert scene.wait_for_cross_validation(timeout=60.0)
    stats = scene.cross_validation_stats
    assert (stats.checks, stats.disagreements, stats.errors, stats.dropped) == (20, 0, 0, 0)
    if name == 'hand':  # its signs are checked by the winding number, those of others by FCL
        assert stats.sign_checks == 20 and stats.sign_disagreements == 0
    else:
        assert stats.sign_checks == 0


def test_every_shape_type_agrees_within_its_stated_error(checked_scenes):
    scene = checked(checked_scenes, Scene(OBJECTS, cross_validation=EVERY_QUERY,
                                          tip_radius=0.002))
    rng = np.random.default_rng(32)
    for batch in rng.uniform(-0.25, 0.25, size=(20, QUEUE_CAPACITY // 2, 3)):
        for p in batch:
            scene.query(p)
        assert scene.wait_for_cross_validation(timeout=60.0)  # no sample dropped
    stats = scene.cross_validation_stats
    assert stats.checks == 20 * (QUEUE_CAPACITY // 2)
    assert stats.disagreements == stats.errors == stats.dropped == 0


def corrupt_the_engine(monkeypatch, change):
    """Make Scene.query's compiled call write a wrong answer: ``change(row)`` edits it."""
    original = _kernels.query_point

    def wrong(floats, ints, out, x, y, z):
        original(floats, ints, out, x, y, z)
        change(out)

    monkeypatch.setattr(scene_module._kernels, 'query_point', wrong)


def test_a_wrong_distance_from_the_engine_is_a_disagreement(checked_scenes, monkeypatch):
    scene = checked(checked_scenes, Scene(OBJECTS, cross_validation=EVERY_QUERY))
    honest = scene.query((0.3, 0.1, 0.0))
    corrupt_the_engine(monkeypatch, lambda row: row.__setitem__(0, row[0] + 1e-3))
    wrong = scene.query((0.3, 0.1, 0.0))
    assert wrong.distance == pytest.approx(honest.distance + 1e-3)
    assert scene.wait_for_cross_validation(timeout=60.0)
    stats = scene.cross_validation_stats
    assert (stats.checks, stats.disagreements) == (2, 1)
    assert scene.cross_validation_disagreements == 1  # what every collision state carries
    assert stats.max_discrepancy == pytest.approx(1e-3, abs=1e-8)


def test_a_wrong_sign_inside_a_mesh_is_a_sign_disagreement(checked_scenes, monkeypatch):
    # FCL's BVH is unsigned: |d| agrees whatever the sign. The winding number catches it.
    scene = checked(checked_scenes, load_scene(scene_path('hand')))
    honest = scene.query(PALM)
    mesh = scene.objects[0]
    assert honest.distance < 0.0
    assert winding_number(mesh.pose.to_local(np.array(PALM)), mesh.shape.vertices,
                          mesh.shape.faces) == pytest.approx(1.0)
    corrupt_the_engine(monkeypatch, lambda row: row.__setitem__(0, -row[0]))
    for _ in range(10):  # every 10th query is checked: the 11th query is the 2nd sample
        scene.query(PALM)
    assert scene.wait_for_cross_validation(timeout=60.0)
    stats = scene.cross_validation_stats
    assert stats.checks == 2 and stats.max_discrepancy <= 1e-9
    assert (stats.sign_checks, stats.sign_disagreements, stats.disagreements) == (2, 1, 1)


def test_a_wrong_fcl_answer_is_counted_and_changes_nothing(checked_scenes, monkeypatch):
    plain = Scene(OBJECTS)
    scene = checked(checked_scenes, Scene(OBJECTS, cross_validation=EVERY_QUERY))
    point = (0.3, 0.1, 0.0)
    original = FclCrossValidator.fcl_distance

    def off_by_a_millimetre(self, index, tip):
        distance, fcl_point = original(self, index, tip)
        return distance + 1e-3, fcl_point

    monkeypatch.setattr(FclCrossValidator, 'fcl_distance', off_by_a_millimetre)
    result = scene.query(point)
    assert scene.wait_for_cross_validation(timeout=60.0)
    stats = scene.cross_validation_stats
    assert (stats.checks, stats.disagreements) == (1, 1)
    assert stats.max_discrepancy == pytest.approx(1e-3, abs=1e-8)
    reference = plain.query(point)
    assert plain.cross_validation_disagreements == 0  # no cross-check, nothing to disagree
    assert result.distance == reference.distance
    np.testing.assert_array_equal(result.point, reference.point)
    np.testing.assert_array_equal(result.normal, reference.normal)


def test_an_fcl_exception_is_counted_not_raised(checked_scenes, monkeypatch):
    scene = checked(checked_scenes, Scene(OBJECTS, cross_validation=EVERY_QUERY))

    def broken(self, index, tip):
        raise RuntimeError('FCL exploded')

    monkeypatch.setattr(FclCrossValidator, 'fcl_distance', broken)
    result = scene.query((0.3, 0.1, 0.0))
    assert result.distance == Scene(OBJECTS).query((0.3, 0.1, 0.0)).distance
    assert scene.wait_for_cross_validation(timeout=60.0)
    stats = scene.cross_validation_stats
    assert (stats.checks, stats.errors) == (0, 1)
    assert stats.last_error == 'RuntimeError: FCL exploded'
    assert scene.query((0.3, 0.1, 0.0)).cross_validated  # the worker lives on


def test_a_blocked_worker_never_blocks_a_query(checked_scenes, monkeypatch):
    scene = checked(checked_scenes, Scene(OBJECTS, cross_validation=EVERY_QUERY))
    entered, release = threading.Event(), threading.Event()
    original = FclCrossValidator.fcl_distance

    def stuck(self, index, tip):
        entered.set()
        release.wait()
        return original(self, index, tip)

    monkeypatch.setattr(FclCrossValidator, 'fcl_distance', stuck)
    scene.query((0.3, 0.1, 0.0))
    assert entered.wait(timeout=60.0)  # the worker holds the first sample, stuck in FCL
    extra = QUEUE_CAPACITY + 20
    answers = []
    querying = threading.Thread(
        target=lambda: answers.extend(scene.query((0.3, 0.1, 0.0)) for _ in range(extra)))
    querying.start()
    querying.join(timeout=120.0)  # only a hang fails here: nothing is timed
    assert not querying.is_alive() and len(answers) == extra
    assert sum(a.cross_validated for a in answers) == QUEUE_CAPACITY
    assert scene.cross_validation_stats.dropped == extra - QUEUE_CAPACITY
    release.set()
    assert scene.wait_for_cross_validation(timeout=60.0)
    stats = scene.cross_validation_stats
    assert (stats.checks, stats.disagreements) == (1 + QUEUE_CAPACITY, 0)


def cross_validation_threads() -> set:
    return {t for t in threading.enumerate() if t.name == 'fcl-cross-validation'}


def test_the_worker_stops_on_close_and_when_the_scene_is_collected():
    before = cross_validation_threads()
    scene = Scene(OBJECTS, cross_validation=EVERY_QUERY)
    thread, = cross_validation_threads() - before
    scene.query((0.3, 0.1, 0.0))
    scene.close()
    assert not thread.is_alive()
    scene.close()  # twice is harmless
    assert not scene.query((0.3, 0.1, 0.0)).in_collision  # queries still work, unchecked

    collected = Scene(OBJECTS, cross_validation=EVERY_QUERY)
    thread, = cross_validation_threads() - before
    collected.query((0.3, 0.1, 0.0))
    del collected
    gc.collect()
    thread.join(timeout=60.0)
    assert not thread.is_alive()


def test_results_are_not_stale_after_a_nearer_query():
    # FCL overwrites a reused result only when the new distance is smaller.
    validator = FclCrossValidator([OBJECTS[0].shape], [OBJECTS[0].pose], tolerance=1e-6)
    plain = Scene(OBJECTS[:1])
    near, far = plain.query((0.2, 0.0, 0.1)), plain.query((0.2, 0.0, 1.0))
    near_fcl, _ = validator.check(0, near.tip, near.distance, near.point)
    far_fcl, far_discrepancy = validator.check(0, far.tip, far.distance, far.point)
    assert far_fcl > near_fcl + 0.5 and far_discrepancy < 1e-6


def test_mesh_distance_is_compared_unsigned_inside_and_its_sign_by_winding_number():
    hand = load_scene(scene_path('hand'))
    mesh = hand.objects[0]
    validator = FclCrossValidator([mesh.shape], [mesh.pose], tolerance=1e-6)
    inside = hand.query(PALM)
    fcl_distance, discrepancy = validator.check(0, PALM, inside.distance, inside.point)
    assert inside.distance < 0 and fcl_distance > 0
    assert discrepancy == pytest.approx(abs(abs(inside.distance) - fcl_distance))
    stats = validator.stats
    assert (stats.disagreements, stats.sign_checks, stats.sign_disagreements) == (0, 1, 0)


def test_cylinder_is_checked_against_a_fine_tessellation():
    geometry, signed, relative, absolute = fcl_model(Cylinder(0.025, 0.1))
    assert signed and type(geometry).__name__ == 'Convex'
    assert absolute < 1e-6  # the 512-gon's sagitta, 0.47 um, plus the probe
