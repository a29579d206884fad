"""The mounted probe at a wand pose: the tool's and each face point's distance, and the state.

Ground truth: the flat probe scene's slab top is the plane z = -0.025 m, so a face point's signed
distance is its height above it, and the box probe's deepest point is a corner of its face.
"""

import math

from ground_truth.distances import scene_path
import numpy as np
import pytest

from collision_engine import load_scene, Pose, Scene, SceneObject, Sphere
from collision_engine.conversions import InvalidPose, POSE, STATE, tip_pose, tool_state
from collision_engine.probe import query_probe, rotation_matrix
from collision_engine.tool import MAX_FACE_POINTS, mount_tool
from haptic_msgs.msg import CollisionState

SURFACE = -0.025  # m: the slab's top


def roll(theta: float) -> tuple:
    return (math.sin(0.5 * theta), 0.0, 0.0, math.cos(0.5 * theta))


@pytest.fixture(scope='module')
def flat():
    return load_scene(scene_path('probe_flat'))


def test_a_flush_face_measures_its_depth_at_every_point(flat):
    result = query_probe(flat, (0.01, -0.02, SURFACE - 0.002), (0.0, 0.0, 0.0, 1.0))
    assert result.tool.distance == pytest.approx(-0.002, abs=1e-12)
    np.testing.assert_allclose(result.distance, np.full(16, -0.002), atol=1e-12)
    np.testing.assert_allclose(result.normals, np.tile([0.0, 0.0, 1.0], (16, 1)), atol=1e-12)
    np.testing.assert_allclose(result.points, flat.tool.face + [0.01, -0.02, SURFACE - 0.002],
                               atol=1e-15)


@pytest.mark.parametrize('theta', [0.2, -0.35])
def test_a_rolled_face_measures_each_point_by_its_height(flat, theta):
    tip = np.array([0.0, 0.0, SURFACE + 0.001])
    result = query_probe(flat, tip, roll(theta))
    heights = tip[2] + flat.tool.face[:, 1] * math.sin(theta)
    np.testing.assert_allclose(result.distance, heights - SURFACE, atol=1e-12)
    # The box's lowest point is a corner of its face, 20 mm from the roll axis.
    assert result.tool.distance == pytest.approx(
        tip[2] - 0.02 * abs(math.sin(theta)) - SURFACE, abs=1e-12)


def test_yaw_turns_the_face_about_the_tip(flat):
    yaw = (0.0, 0.0, math.sin(0.25), math.cos(0.25))  # 0.5 rad about z
    result = query_probe(flat, (0.0, 0.0, 0.0), yaw)
    turned = flat.tool.face @ rotation_matrix(yaw).T
    np.testing.assert_allclose(result.points, turned, atol=1e-15)
    np.testing.assert_allclose(turned[:, 1], np.sin(0.5) * flat.tool.face[:, 0]
                               + np.cos(0.5) * flat.tool.face[:, 1], atol=1e-15)


def test_a_round_tool_takes_its_radius_off_and_reports_its_surface_point():
    slab = SceneObject('slab', Sphere(1.0), Pose.from_rpy((0.0, 0.0, -1.0)))
    scene = Scene([slab], tool=mount_tool(Sphere(0.005), Pose(), face_spacing=0.001,
                                          workspace_size=0.3))
    result = query_probe(scene, (0.0, 0.0, 0.002), (0.0, 0.0, 0.0, 1.0))
    np.testing.assert_allclose(result.distance, [0.002 - 0.005], atol=1e-12)
    np.testing.assert_allclose(result.points, [[0.0, 0.0, -0.003]], atol=1e-12)


def test_the_state_carries_the_face_and_the_whole_pose(flat):
    tip = (0.0, 0.0, SURFACE + 0.001)
    result = query_probe(flat, tip, roll(0.2))
    fields = tool_state((5, 6, 'world'), result, tip, roll(0.2), 1e-5, 0)
    message = STATE.to_message(STATE.decode(STATE.encode(fields)))
    assert len(message.contact_distance) == 16 and message.object == 'slab'
    np.testing.assert_allclose(message.contact_distance, result.distance, rtol=0, atol=0)
    assert (message.contact_points[3 * 3 + 1], message.contact_normals[3 * 3 + 2]) == (
        result.points[3, 1], result.normals[3, 2])
    assert (message.tip.x, message.tip.y, message.tip.z) == tip
    orientation = message.orientation
    assert (orientation.x, orientation.y, orientation.z, orientation.w) == roll(0.2)
    assert message.distance == result.tool.distance and message.in_collision
    assert (message.tool_point.x, message.tool_point.y, message.tool_point.z) == tuple(
        result.tool.tool_point.tolist())


def test_the_face_limit_is_the_messages():
    fields = CollisionState.get_fields_and_field_types()
    assert fields['contact_distance'] == f'sequence<double, {MAX_FACE_POINTS}>'
    assert fields['contact_points'] == f'sequence<double, {3 * MAX_FACE_POINTS}>'
    assert fields['contact_normals'] == f'sequence<double, {3 * MAX_FACE_POINTS}>'


def test_the_pose_s_quaternion_is_normalised_and_a_bad_one_refused():
    pose = [0, 0, 'world', 0.1, 0.2, 0.3, 0.0, 0.0, 0.0, 1.0005]
    position, quaternion = tip_pose(pose, 'world')
    assert position == (0.1, 0.2, 0.3) and quaternion == (0.0, 0.0, 0.0, 1.0)
    assert len(POSE.fields) == len(pose)
    with pytest.raises(InvalidPose, match='not a unit quaternion'):
        tip_pose(pose[:9] + [1.1], 'world')
