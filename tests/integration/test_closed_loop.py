"""The loop's nodes as real processes: scripted poses in, wrenches checked against depth × k.

The test stands in for the wand driver. Expected forces are computed here from the paper's
cuboid (0.2 × 0.1 × 0.1 m along x, y, z, centred at (0, 0, -0.075) m, 160 N/m per axis), not by
the toolkit's code.
"""
import math

import numpy as np
import pytest

from haptic_msgs.msg import CollisionState

K = 160.0  # [N/m] the paper's stiffness, the default scene's material
CENTRE = np.array([0.0, 0.0, -0.075])
HALF = np.array([0.1, 0.05, 0.05])
TOP = CENTRE[2] + HALF[2]  # z of the top face
LEFT = CENTRE[0] - HALF[0]  # x of the -x end face
HOLD = 0.08  # [s] each pose is held this long at 1 kHz
SETTLED = 20  # the last poses of a hold are checked (the force node's filters have settled)
MIN_ANSWERED = 0.8  # share of held poses that must come back as wrenches


def held_forces(client, position, **kwargs) -> np.ndarray:
    stamps = client.hold(position, HOLD, **kwargs)
    wrenches = client.collect(stamps)
    answered = [w for w in wrenches if w is not None]
    assert len(answered) >= MIN_ANSWERED * len(stamps), \
        f'{len(answered)} of {len(stamps)} poses answered'
    tail = [w for w in wrenches[-SETTLED:] if w is not None]
    assert tail, 'no wrench for the settled poses'
    return np.array([(w.wrench.force.x, w.wrench.force.y, w.wrench.force.z) for w in tail])


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
    forces = held_forces(client, position)
    np.testing.assert_allclose(forces, np.broadcast_to(expected, forces.shape), rtol=1e-9,
                               atol=1e-9, err_msg=label)


def test_a_sequence_free_touch_press_release(collision_and_force, client):
    client.wait_connected()
    depths = [-0.01, 0.0, 0.001, 0.003, 0.001, -0.01]
    for depth in depths:
        forces = held_forces(client, (0.0, 0.0, TOP - depth))
        np.testing.assert_allclose(forces[:, 2], K * max(depth, 0.0), rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(forces[:, :2], 0.0, atol=1e-12)


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
    press = held_forces(client, (0.0, 0.0, TOP - 0.002))
    assert press[-1][2] == pytest.approx(K * 0.002)
    position = kwargs.pop('position')
    stamps = client.hold(position, HOLD, **kwargs)
    wrenches = [w for w in client.collect(stamps) if w is not None]
    assert wrenches, label
    assert all(w.wrench.force.x == w.wrench.force.y == w.wrench.force.z == 0.0
               for w in wrenches), label
    states = [client.states[s] for s in stamps if s in client.states]
    assert states and all(s.status == CollisionState.STATUS_INVALID_INPUT for s in states), label


@pytest.mark.parametrize('label, offset', [
    ('stamped 1 s in the future', 1.0),
    ('stamped 0.5 s in the past (going backwards)', -0.5),
])
def test_poses_with_bad_stamps_get_zero_force(collision_and_force, client, label, offset):
    client.wait_connected()
    press = held_forces(client, (0.0, 0.0, TOP - 0.002))
    assert press[-1][2] == pytest.approx(K * 0.002)
    stamps = client.hold((0.0, 0.0, TOP - 0.002), HOLD, stamp_offset=offset)
    wrenches = [w for w in client.collect(stamps) if w is not None]
    assert wrenches, label
    assert all(w.wrench.force.z == 0.0 for w in wrenches), label


FLOOD_RATE = 20000.0  # [Hz] asked of the test client
FLOOD_FLOOR = 15000.0  # [Hz] what this Python client reaches at the least, the nodes busy too


def test_a_20_khz_flood_of_poses_crashes_nothing_and_the_loop_answers_after(
        collision_and_force, client):
    client.wait_connected()
    flooded = client.flood((0.0, 0.0, TOP - 0.001), rate=FLOOD_RATE, duration=1.0)
    assert flooded >= FLOOD_FLOOR, f'the flood reached only {flooded} poses/s'
    assert all(child.returncode is None for child in collision_and_force.children)
    forces = held_forces(client, (0.0, 0.0, TOP - 0.003))
    np.testing.assert_allclose(forces[:, 2], K * 0.003, rtol=1e-9)
