"""The follower takes only TCP poses the robot can have: in its box, no faster than it moves."""
import math

import numpy as np
import pytest

from robot_site.tcp_gate import TCP_TOLERANCE, TcpGate

LOWER, UPPER, TOP_SPEED = np.full(3, -0.4), np.full(3, 0.4), 0.25
PERIOD = 1e-3  # [s] the robot's TCP poses


def true_tcp(time):
    """The robot sweeping at its top speed along x, 20 mm below the origin."""
    return np.array([-0.2 + TOP_SPEED * time, 0.0, -0.02])


def test_the_robot_at_its_top_speed_is_taken_even_when_its_poses_arrive_in_bursts():
    """Every 0.1 s a stall holds 20 poses back, and they all arrive at once."""
    gate = TcpGate(LOWER, UPPER, TOP_SPEED)
    for k in range(1000):
        held = (k // 20) % 5 == 0
        now = (k // 20 * 20 + 19) * PERIOD if held else k * PERIOD
        assert gate.take(now, true_tcp(k * PERIOD)) is None, k
    np.testing.assert_allclose(gate.position, true_tcp(999 * PERIOD))


def test_a_stranger_s_poses_interleaved_with_the_robot_s_are_refused():
    """At twice the robot's rate, 50 mm below its true poses. Taken as they come (the node
    before the gate), the velocity swings by 100 m/s; gated, it is the robot's."""
    gate, taken, refused, naive = TcpGate(LOWER, UPPER, TOP_SPEED), [], [], []
    last = None
    for k in range(2000):
        now = k * PERIOD / 2
        position = true_tcp(now) if k % 2 == 0 else true_tcp(now) - [0.0, 0.0, 0.05]
        if last is not None:
            naive.append(np.linalg.norm(position - last) / (PERIOD / 2))
        last = position
        refusal = gate.take(now, position)
        (taken if refusal is None else refused).append((k, refusal))
    assert max(naive) > 90.0
    assert [k for k, _ in taken] == list(range(0, 2000, 2))
    assert {refusal.kind for _, refusal in refused} == {'TCP faster than the robot'}
    np.testing.assert_allclose(gate.velocity, [TOP_SPEED, 0.0, 0.0], atol=1e-9)


def test_a_gate_held_by_a_stream_that_stops_takes_the_true_poses_once_the_robot_could_be_there():
    gate = TcpGate(LOWER, UPPER, TOP_SPEED)
    assert gate.take(0.0, [0.0, 0.0, -0.07]) is None  # a stranger's, before the robot spoke
    offset = 0.05  # [m] the true TCP's distance from it
    reached = (offset - TCP_TOLERANCE) / TOP_SPEED  # [s] when the robot could be there
    for now in np.arange(PERIOD, reached - PERIOD, PERIOD):
        assert gate.take(now, [0.0, 0.0, -0.02]).kind == 'TCP faster than the robot'
    assert gate.take(reached + PERIOD, [0.0, 0.0, -0.02]) is None


@pytest.mark.parametrize('position, kind', [
    ([0.0, 0.0, 0.41], 'TCP outside the workspace'),
    ([-0.5, 0.0, 0.0], 'TCP outside the workspace'),
    ([0.0, math.nan, 0.0], 'TCP not finite'),
    ([math.inf, 0.0, 0.0], 'TCP not finite'),
])
def test_a_pose_no_robot_in_this_box_can_have_is_refused_and_changes_nothing(position, kind):
    gate = TcpGate(LOWER, UPPER, TOP_SPEED)
    assert gate.take(0.0, [0.0, 0.0, 0.0]) is None
    assert gate.take(10.0, position).kind == kind
    np.testing.assert_array_equal(gate.position, [0.0, 0.0, 0.0])
    assert gate.time == 0.0
