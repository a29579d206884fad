"""The follower node follows only a robot that says it is the one its force bound was set for."""
import math
import time

from domains import session_domain_id
import pytest
import rclpy
from rclpy.context import Context
from rclpy.node import Node

from haptic_contract.teleop_fields import impedance_message
from haptic_util.diagnostics import ERROR, WARN
from robot_site.follower_node import FollowerNode

ROBOT = dict(max_speed=0.25, workspace_lower=(-0.4,) * 3, workspace_upper=(0.4,) * 3,
             max_patient_force=20.0)


def command(sequence=1):
    """A TeleopCommand's fields: now-ish, in the robot's frame, at its start."""
    return (1_795_000_000, 1000 * sequence, 'base_link', 0x5E55, sequence, 0.0, 0.0, 0.0,
            0.0, 0.0, 0.0, 0.0)


@pytest.fixture
def follower():
    context = Context()
    rclpy.init(context=context, domain_id=97)
    node = FollowerNode(context=context, parameter_overrides=[
        rclpy.parameter.Parameter('scene_file', value=''),
        rclpy.parameter.Parameter('robot_stiffness', value=1500.0)])
    yield node
    node.destroy_node()
    rclpy.try_shutdown(context=context)


def test_the_commands_reader_leaves_the_graph_with_the_follower():
    """It reads on a node of its own, which must not outlive the follower, still matched."""
    context = Context()
    rclpy.init(context=context, domain_id=session_domain_id())  # none else sees it
    try:
        probe = Node('probe', context=context)
        FollowerNode(context=context, parameter_overrides=[
            rclpy.parameter.Parameter('scene_file', value='')]).destroy_node()
        assert probe.get_node_names() == ['probe']
    finally:
        rclpy.try_shutdown(context=context)


def test_it_commands_nothing_until_the_robot_says_what_it_is(follower):
    assert follower.report().level == WARN and 'robot/impedance' in follower.report().message
    follower.on_command(command())
    assert follower._refused.counts == {'command before the robot is known': 1}
    follower.on_impedance(impedance_message('base_link', stiffness=1500.0, **ROBOT))
    follower.on_command(command(2))
    assert follower._refused.total() == 1 and follower.report().level != ERROR


def test_a_robot_of_another_stiffness_is_not_commanded_and_an_error_says_why(follower):
    follower.on_impedance(impedance_message('base_link', stiffness=1500.0, **ROBOT))
    assert follower.follower is not None
    follower.on_impedance(impedance_message('base_link', stiffness=3000.0, **ROBOT))
    assert follower.follower is None
    report = follower.report()
    assert report.level == ERROR and '3000 N/m' in report.message
    follower.on_command(command())
    assert follower._refused.counts == {'command before the robot is known': 1}
    follower.tick()  # no target while it is not known: the robot holds on its own


def test_a_robot_in_another_frame_is_not_commanded(follower):
    follower.on_impedance(impedance_message('world', stiffness=1500.0, **ROBOT))
    assert follower.follower is None and follower.report().level == ERROR


def test_tcp_poses_the_robot_cannot_have_are_refused_and_named(follower):
    pose = ('base_link', 0.0, 0.0, -0.02, 0.0, 0.0, 0.0, 1.0)
    follower.on_tcp((0, 0, *pose))
    assert follower._refused.counts == {'TCP pose before the robot is known': 1}
    follower.on_impedance(impedance_message('base_link', stiffness=1500.0, **ROBOT))
    follower.on_tcp((0, 0, *pose))
    follower.on_tcp((0, 0, 'base_link', 0.0, 0.0, -0.07, 0.0, 0.0, 0.0, 1.0))  # 50 mm at once
    assert follower._refused.counts['TCP faster than the robot'] == 1
    assert follower._tcp.position[2] == -0.02
    assert follower.report().values['refused: TCP faster than the robot'] == 1


@pytest.mark.parametrize('speed', [0.0, math.nan])
def test_a_robot_with_no_top_speed_is_not_commanded(follower, speed):
    follower.on_impedance(impedance_message('base_link', stiffness=1500.0,
                                            **{**ROBOT, 'max_speed': speed}))
    assert follower.follower is None and 'top speed' in follower.report().message


def test_the_tcp_poses_are_checked_against_the_robot_s_latest_limits(follower):
    """A robot that reports a smaller workspace, then a lower top speed: the poses are checked
    against those, as its commands are (before, the gate kept the first report's limits)."""
    def pose(z):
        follower.on_tcp((0, 0, 'base_link', 0.0, 0.0, z, 0.0, 0.0, 0.0, 1.0))
    follower.on_impedance(impedance_message('base_link', stiffness=1500.0, **ROBOT))
    pose(0.0)
    follower.on_impedance(impedance_message('base_link', stiffness=1500.0, **{
        **ROBOT, 'workspace_upper': (0.4, 0.4, -0.0025)}))
    pose(0.001)  # 3.5 mm above the new box: beyond the 2 mm a pose's noise is given
    assert follower._refused.counts == {'TCP outside the workspace': 1}
    follower.on_impedance(impedance_message('base_link', stiffness=1500.0, **{
        **ROBOT, 'max_speed': 0.01}))
    time.sleep(0.05)  # 12.5 mm at the first top speed, 0.5 mm at the new one (2 mm given)
    pose(-0.008)
    assert follower._refused.counts['TCP faster than the robot'] == 1
    assert follower._tcp.position[2] == 0.0
