"""Poses from roll-pitch-yaw and quaternions, against explicit rotation matrices."""

import numpy as np
import pytest

from collision_engine.transforms import Pose


def rx(a):
    return np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])


def ry(a):
    return np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])


def rz(a):
    return np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])


def test_rpy_is_fixed_axis_roll_then_pitch_then_yaw():
    roll, pitch, yaw = 0.3, -1.1, 2.5
    pose = Pose.from_rpy([1.0, 2.0, 3.0], [roll, pitch, yaw])
    np.testing.assert_allclose(pose.rotation, rz(yaw) @ ry(pitch) @ rx(roll), atol=1e-15)
    np.testing.assert_allclose(pose.to_world([0.0, 0.0, 0.0]), [1.0, 2.0, 3.0])


def test_quaternion_in_ros_order():
    angle = 0.7
    quaternion = [0.0, 0.0, np.sin(angle / 2), np.cos(angle / 2)]  # x, y, z, w
    pose = Pose.from_quaternion([0.0, 0.0, 0.0], quaternion)
    np.testing.assert_allclose(pose.rotation, rz(angle), atol=1e-15)
    scaled = Pose.from_quaternion([0.0, 0.0, 0.0], 3.0 * np.array(quaternion))
    np.testing.assert_allclose(scaled.rotation, rz(angle), atol=1e-15)


def test_local_and_world_are_inverse():
    rng = np.random.default_rng(0)
    pose = Pose.from_rpy(rng.normal(size=3), rng.normal(size=3))
    points = rng.normal(size=(50, 3))
    np.testing.assert_allclose(pose.to_local(pose.to_world(points)), points, atol=1e-14)
    np.testing.assert_allclose(pose.to_world(points[0]),
                               pose.rotation @ points[0] + pose.translation, atol=1e-15)
    np.testing.assert_allclose(pose.vector_to_world(points), points @ pose.rotation.T)


@pytest.mark.parametrize('make', [
    lambda: Pose.from_rpy([0.0, 0.0], [0.0, 0.0, 0.0]),
    lambda: Pose.from_rpy([0.0, 0.0, np.nan]),
    lambda: Pose.from_rpy([0.0, 0.0, 0.0], [0.0, np.inf, 0.0]),
    lambda: Pose.from_quaternion([0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]),
    lambda: Pose(np.diag([1.0, 1.0, -1.0])),
    lambda: Pose(2.0 * np.eye(3)),
])
def test_bad_poses_are_rejected(make):
    with pytest.raises(ValueError):
        make()


def test_pose_is_read_only():
    pose = Pose.from_rpy([1.0, 2.0, 3.0])
    with pytest.raises(ValueError):
        pose.translation[0] = 0.0
