"""The loop's nodes as real processes: scripted poses in, wrenches checked against depth × k.

The test stands in for the wand driver. Expected forces are computed here from the paper's
cuboid (0.2 × 0.1 × 0.1 m along x, y, z, centred at (0, 0, -0.075) m, 160 N/m per axis), not by
the toolkit's code.
"""
import math

from loop_client import press
import numpy as np
import pytest

from haptic_msgs.msg import CollisionState

K = 160.0  # [N/m] the paper's stiffness, the default scene's material
CENTRE = np.array([0.0, 0.0, -0.075])
HALF = np.array([0.1, 0.05, 0.05])
TOP = CENTRE[2] + HALF[2]  # z of the top face
LEFT = CENTRE[0] - HALF[0]  # x of the -x end face
POSES = 20  # per check of refused poses
LOOP_RATE = 1000.0  # [Hz] the rate the loop is built for
FLOOD_POSES = 20000
FLOOD_FACTOR = 10.0  # a flood sends at least this many times the loop's rate
FLOOD_DRAIN = 0.5  # [s] for the flood's samples to leave the queues and buffers


def refused(client, position, **kwargs) -> list:
    """Send POSES poses in lockstep; return their answers, each of which must have come."""
    answers = []
    for _ in range(POSES):
        stamp, wrench, _ = client.exchange(position, **kwargs)
        assert wrench is not None, f'the pose stamped {stamp} got no answer'
        answers.append((stamp, wrench))
    return answers


@pytest.mark.parametrize('label, position, expected', [
    ('free space', (0.0, 0.0, TOP + 0.05), (0.0, 0.0, 0.0)),
    ('touching the top face', (0.01, 0.02, TOP), (0.0, 0.0, 0.0)),
    ('0.5 mm into the top face', (0.01, 0.02, TOP - 0.0005), (0.0, 0.0, K * 0.0005)),
    ('1 mm into the top face', (-0.03, 0.0, TOP - 0.001), (0.0, 0.0, K * 0.001)),
    ('5 mm into the top face', (0.05, -0.02, TOP - 0.005), (0.0, 0.0, K * 0.005)),
    ('2 mm into the -x face', (LEFT + 0.002, 0.01, CENTRE[2]), (-K * 0.002, 0.0, 0.0)),
    ('12 mm into the -x face', (LEFT + 0.012, -0.01, CENTRE[2] + 0.01), (-K * 0.012, 0.0, 0.0)),
])
def test_wrench_is_depth_times_k_along_the_face_normal(
        collision_and_force, client, label, position, expected):
    client.wait_connected()
    press(client, position, expected, label)


def test_a_sequence_free_touch_press_release(collision_and_force, client):
    client.wait_connected()
    for depth in [-0.01, 0.0, 0.001, 0.003, 0.001, -0.01]:
        press(client, (0.0, 0.0, TOP - depth), (0.0, 0.0, K * max(depth, 0.0)), f'{depth} m')


@pytest.mark.parametrize('label, kwargs', [
    ('NaN position', dict(position=(math.nan, 0.0, TOP - 0.002))),
    ('infinite position', dict(position=(0.0, math.inf, TOP - 0.002))),
    ('NaN orientation', dict(position=(0.0, 0.0, TOP - 0.002),
                             orientation=(0.0, 0.0, math.nan, 1.0))),
    ('unknown frame', dict(position=(0.0, 0.0, TOP - 0.002), frame_id='base_link')),
    ('non-unit quaternion', dict(position=(0.0, 0.0, TOP - 0.002),
                                 orientation=(0.0, 0.0, 0.0, 0.5))),
])
def test_bad_poses_are_refused_and_the_force_is_zero(collision_and_force, client, label, kwargs):
    client.wait_connected()
    press(client, (0.0, 0.0, TOP - 0.002), (0.0, 0.0, K * 0.002), 'the press before')
    answers = refused(client, **kwargs)
    assert all(w.wrench.force.x == w.wrench.force.y == w.wrench.force.z == 0.0
               for _, w in answers), label
    assert client.spin_until(lambda: all(stamp in client.states for stamp, _ in answers)), \
        f'{label}: a collision state did not come'
    states = [client.states[stamp] for stamp, _ in answers]
    assert all(s.status == CollisionState.STATUS_INVALID_INPUT
               for s in states), label


@pytest.mark.parametrize('label, offset', [
    ('stamped 1 s in the future', 1.0),
    ('stamped 0.5 s in the past (going backwards)', -0.5),
])
def test_poses_with_bad_stamps_get_zero_force(collision_and_force, client, label, offset):
    client.wait_connected()
    press(client, (0.0, 0.0, TOP - 0.002), (0.0, 0.0, K * 0.002), 'the press before')
    answers = refused(client, (0.0, 0.0, TOP - 0.002), stamp_offset=offset)
    assert all(w.wrench.force.z == 0.0 for _, w in answers), label


def test_a_flood_of_poses_crashes_nothing_and_the_loop_answers_after(
        collision_and_force, client):
    client.wait_connected()
    rate = client.flood((0.0, 0.0, TOP - 0.001), FLOOD_POSES)
    print(f'flood: {FLOOD_POSES} poses at {rate:.0f} Hz, {rate / LOOP_RATE:.1f} times the '
          f'loop\'s rate')
    assert rate >= FLOOD_FACTOR * LOOP_RATE, \
        f'not a flood: {FLOOD_POSES} poses sent at only {rate:.0f} Hz'
    assert all(child.returncode is None for child in collision_and_force.children)
    # The flood fills the nodes' queues and this client's shared-memory buffers. A press sent
    # right after got, in about 1 run of 10, a timely answer with a damper's force (10 N once,
    # 0 N once): the force node had no twist of that pose and estimated the velocity from the
    # poses, across this client's jump from the flood to the press. So the press comes once the
    # flood has drained (0 failures in 25 runs).
    client.spin_until(lambda: False, FLOOD_DRAIN)
    client.wait_connected()
    press(client, (0.0, 0.0, TOP - 0.003), (0.0, 0.0, K * 0.003), 'after the flood')
