"""The probe over the loop: the collision and force nodes with a mounted tool, torque included.

The scene is probe_flat: a 10 x 40 mm face (2 x 8 cells of 5 mm) at the tip, over the plane
z = -0.025 m of stiffness 1000 N/m. The expected wrench is summed here, point by point, from the
face's cell centres, with no code of the toolkit's.
"""
import math

from domains import session_domain_id
from ground_truth.distances import scene_path
from loop_client import MAX_POSES, TIMELY, WATCHDOG
import numpy as np
import pytest

from haptic_bringup.launcher import Loop, LoopConfig

K = 1000.0
SURFACE = -0.025
FACE = np.array([[x, y, 0.0] for x in (-0.0025, 0.0025)
                 for y in np.arange(-0.0175, 0.018, 0.005)])


@pytest.fixture(scope='module')
def probe_loop(tmp_path_factory):
    config = LoopConfig(nodes=('collision_engine', 'force_renderer'),
                        scene=str(scene_path('probe_flat')), domain_id=session_domain_id(),
                        run_dir=tmp_path_factory.mktemp('launch'))
    with Loop(config) as loop:
        yield loop


def expected_wrench(tip, roll: float):
    """Sum each face point's k/16 times its depth under the plane, and its torque about the tip."""
    c, s = math.cos(roll), math.sin(roll)
    force, torque = np.zeros(3), np.zeros(3)
    for x, y, _ in FACE:
        arm = np.array([x, c * y, s * y])
        depth = SURFACE - (tip[2] + arm[2])
        if depth > 0.0:
            push = np.array([0.0, 0.0, K / len(FACE) * depth])
            force += push
            torque += np.cross(arm, push)
    return force, torque


@pytest.mark.parametrize('roll', [0.0, 0.2, -0.35])
def test_a_rolled_probe_gets_the_face_s_force_and_restoring_torque(probe_loop, client, roll):
    client.wait_connected()
    tip = (0.01, -0.02, SURFACE - 0.004)
    orientation = (math.sin(0.5 * roll), 0.0, 0.0, math.cos(0.5 * roll))
    force, torque = expected_wrench(tip, roll)
    assert force[2] > 0.0 and (roll == 0.0 or np.sign(torque[0]) == -np.sign(roll))
    timely = 0
    for _ in range(MAX_POSES):
        stamp, wrench, latency = client.exchange(tip, orientation=orientation)
        assert wrench is not None, f'the pose stamped {stamp} got no answer'
        if latency > WATCHDOG:
            continue
        w = wrench.wrench
        np.testing.assert_allclose([w.force.x, w.force.y, w.force.z], force, rtol=1e-9,
                                   atol=1e-9)
        np.testing.assert_allclose([w.torque.x, w.torque.y, w.torque.z], torque, rtol=1e-9,
                                   atol=1e-12)
        timely += 1
        if timely == TIMELY:
            return
    raise AssertionError(f'only {timely} of {MAX_POSES} answers came within {WATCHDOG} s')


def test_the_contact_model_carries_three_tool_points_of_the_pressed_face(probe_loop, client):
    """Their mean is the pressed points' mean, in the tip frame; each plane the surface's."""
    from haptic_msgs.msg import ContactModel
    from haptic_util.qos import HAPTIC_STREAM_QOS

    models = {}
    client.node.create_subscription(
        ContactModel, 'wand/contact_model',
        lambda m: models.setdefault((m.header.stamp.sec, m.header.stamp.nanosec), m),
        HAPTIC_STREAM_QOS)
    client.wait_connected()
    roll, tip = 0.3, (0.0, 0.0, SURFACE - 0.003)
    for _ in range(MAX_POSES):
        stamp, _, latency = client.exchange(tip, orientation=(math.sin(0.5 * roll), 0.0, 0.0,
                                                              math.cos(0.5 * roll)))
        if latency <= WATCHDOG and client.spin_until(lambda: stamp in models, 1.0):
            break
    model = models[stamp]
    assert model.kind == ContactModel.KIND_PLANES and model.plane_count == 3
    pressed = FACE[SURFACE - (tip[2] + math.sin(roll) * FACE[:, 1]) > 0.0]
    tool_points = np.array([[p.tool_point.x, p.tool_point.y, p.tool_point.z]
                            for p in model.planes])
    np.testing.assert_allclose(tool_points.mean(axis=0), pressed.mean(axis=0), atol=1e-12)
    for plane in model.planes:
        assert (plane.point.z, plane.normal.z) == pytest.approx((SURFACE, 1.0), abs=1e-12)
        assert plane.stiffness.z == pytest.approx(K * len(pressed) / (3 * len(FACE)))
    _, expected_torque = expected_wrench(tip, roll)
    assert model.wrench.torque.x == pytest.approx(expected_torque[0], rel=1e-9)


@pytest.mark.parametrize('orientation', [(0.0, 0.0, math.nan, 1.0), (0.0, 0.0, 0.0, 0.5)])
def test_a_bad_orientation_gets_an_invalid_state_and_no_wrench(probe_loop, client, orientation):
    from haptic_msgs.msg import CollisionState

    client.wait_connected()
    tip = (0.0, 0.0, SURFACE - 0.004)
    for _ in range(5):
        stamp, wrench, _ = client.exchange(tip, orientation=orientation)
        assert wrench is not None, f'the pose stamped {stamp} got no answer'
        w = wrench.wrench
        assert (w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y, w.torque.z) == (0.0,) * 6
        assert client.spin_until(lambda: stamp in client.states)
        state = client.states[stamp]
        assert state.status == CollisionState.STATUS_INVALID_INPUT and not state.contact_distance
