"""Roll/yaw quaternions and the roll-yaw Jacobian against rotation matrices built independently."""

from fuzzing import examples
from ground_truth.wand import (matrix_from_quaternion, quaternion_from_matrix, rotation_x,
                               rotation_y, rotation_z)
from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

from haptic_contract.wand import (
    PitchError, quaternion_from_roll_yaw, roll_yaw_from_quaternion, roll_yaw_jacobian)

angles = st.floats(-3.0, 3.0)
SETTINGS = settings(max_examples=examples(60), deadline=None)


@SETTINGS
@given(angles, angles)
def test_quaternion_is_yaw_then_roll(roll, yaw):
    expected = rotation_z(yaw) @ rotation_x(roll)
    quaternion = quaternion_from_roll_yaw(roll, yaw)
    assert np.linalg.norm(quaternion) == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(matrix_from_quaternion(quaternion), expected, atol=1e-12)


@SETTINGS
@given(angles, angles, st.booleans())
def test_roll_yaw_round_trip_either_sign(roll, yaw, negate):
    quaternion = quaternion_from_roll_yaw(roll, yaw) * (-1.0 if negate else 1.0)
    assert roll_yaw_from_quaternion(quaternion) == pytest.approx((roll, yaw), abs=1e-9)


def test_reads_a_quaternion_built_from_a_matrix():
    matrix = rotation_z(0.4) @ rotation_x(-0.2)
    assert roll_yaw_from_quaternion(quaternion_from_matrix(matrix)) == pytest.approx((-0.2, 0.4))


@pytest.mark.parametrize('pitch', [0.01, -0.3, 1.2])
def test_pitch_is_refused(pitch):
    matrix = rotation_z(0.3) @ rotation_y(pitch) @ rotation_x(0.1)
    with pytest.raises(PitchError, match='pitch'):
        roll_yaw_from_quaternion(quaternion_from_matrix(matrix))


def test_pitch_within_tolerance_is_dropped():
    matrix = rotation_z(0.3) @ rotation_y(5e-5) @ rotation_x(0.1)
    roll, yaw = roll_yaw_from_quaternion(quaternion_from_matrix(matrix))
    assert (roll, yaw) == pytest.approx((0.1, 0.3), abs=1e-4)
    with pytest.raises(PitchError):
        roll_yaw_from_quaternion(quaternion_from_matrix(matrix), pitch_tolerance=1e-6)


@pytest.mark.parametrize('quaternion', [[0.0, 0.0, 0.0, 2.0], [0.0, 0.0, 0.0, 0.0],
                                        [np.nan, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
def test_non_rotations_are_refused(quaternion):
    with pytest.raises(PitchError, match='quaternion'):
        roll_yaw_from_quaternion(quaternion)


@SETTINGS
@given(angles, angles, st.floats(-2.0, 2.0), st.floats(-2.0, 2.0))
def test_jacobian_gives_the_angular_velocity(roll, yaw, roll_rate, yaw_rate):
    step = 1e-6

    def matrix(t):
        return rotation_z(yaw + yaw_rate * t) @ rotation_x(roll + roll_rate * t)
    derivative = (matrix(step) - matrix(-step)) / (2 * step)
    skew = derivative @ matrix(0.0).T
    expected = np.array([skew[2, 1], skew[0, 2], skew[1, 0]])
    actual = roll_yaw_jacobian(yaw) @ np.array([roll_rate, yaw_rate])
    np.testing.assert_allclose(actual, expected, atol=1e-7)


@SETTINGS
@given(angles, angles)
def test_jacobian_transpose_drops_the_pitch_torque(roll, yaw):
    step = 1e-6
    derivative = (rotation_z(yaw) @ rotation_y(step) @ rotation_x(roll)
                  - rotation_z(yaw) @ rotation_y(-step) @ rotation_x(roll)) / (2 * step)
    skew = derivative @ (rotation_z(yaw) @ rotation_x(roll)).T
    pitch_axis = np.array([skew[2, 1], skew[0, 2], skew[1, 0]])
    np.testing.assert_allclose(roll_yaw_jacobian(yaw).T @ pitch_axis, [0.0, 0.0], atol=1e-8)
