"""The remote site's ``teleop_follower`` as a real process, its robot and link played by the test.

A NaN in the F/T wrench must not reach the operator: the feedback carries zero force and no
contact plane while the readings are bad, and the contact again once a good one comes. Read from
what the node published, never from its internals.
"""
import math
import sys
import time

from domains import session_domain_id
from geometry_msgs.msg import PoseStamped, WrenchStamped
import pytest
import rclpy
from rclpy.context import Context
from rclpy.experimental import EventsExecutor
from rclpy.node import Node

from haptic_bringup.launcher import loop_environment
from haptic_bringup.processes import start_child, stop_children
from haptic_contract.teleop_fields import impedance_message
from haptic_msgs.msg import RobotImpedance, TeleopCommand, TeleopFeedback
from haptic_util.qos import HAPTIC_STREAM_QOS, LATCHED_QOS

PRESSED = 8.0  # [N] the sensor's good reading: the probe pressed on the patient
CONNECT_TIMEOUT = 60.0  # [s] the node's imports and the phantom's mesh, on a busy machine
SETTLE = 0.1  # [s] past a change: the feedback is at 100 Hz for the model, and in flight
OPERATOR_SESSION = 0x5E55


class RobotAndLink:
    """The robot (TCP pose, F/T wrench) and the operator's commands, at 500 Hz; the feedback."""

    def __init__(self, domain: int) -> None:
        self.context = Context()
        rclpy.init(context=self.context, domain_id=domain)
        self.node = Node('test_robot_and_link', context=self.context)
        self.executor = EventsExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.reading = PRESSED  # the sensor's z force
        self.feedback = []  # (arrived s, force z, kind)
        self._tcp = self.node.create_publisher(PoseStamped, 'robot/tcp_pose', HAPTIC_STREAM_QOS)
        self._wrench = self.node.create_publisher(WrenchStamped, 'robot/ft_sensor/wrench',
                                                  HAPTIC_STREAM_QOS)
        self._command = self.node.create_publisher(TeleopCommand, 'teleop/command',
                                                   HAPTIC_STREAM_QOS)
        self.node.create_subscription(TeleopFeedback, 'teleop/feedback', self._on_feedback,
                                      HAPTIC_STREAM_QOS)
        self._impedance = self.node.create_publisher(RobotImpedance, 'robot/impedance',
                                                     LATCHED_QOS)
        self._impedance.publish(impedance_message(
            'base_link', stiffness=1500.0, max_speed=0.25, workspace_lower=(-0.4,) * 3,
            workspace_upper=(0.4,) * 3, max_patient_force=20.0))
        self._sequence = 0
        self.node.create_timer(0.002, self._publish)

    def _publish(self) -> None:
        stamp = self.node.get_clock().now().to_msg()
        pose = PoseStamped()
        pose.header.stamp, pose.header.frame_id = stamp, 'base_link'
        pose.pose.position.z = -0.01
        pose.pose.orientation.w = 1.0
        self._tcp.publish(pose)
        wrench = WrenchStamped()
        wrench.header.stamp, wrench.header.frame_id = stamp, 'base_link'
        wrench.wrench.force.z = self.reading
        self._wrench.publish(wrench)
        self._sequence += 1
        command = TeleopCommand(session=OPERATOR_SESSION, sequence=self._sequence)
        command.header.stamp, command.header.frame_id = stamp, 'base_link'
        command.position.z = -0.01
        self._command.publish(command)

    def _on_feedback(self, message: TeleopFeedback) -> None:
        self.feedback.append((time.monotonic(), message.force.z, message.kind))

    def spin(self, seconds: float) -> None:
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            self.executor.spin_once(timeout_sec=0.01)

    def since(self, start: float) -> list:
        return [(force, kind) for arrived, force, kind in self.feedback if arrived >= start]

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()
        self.context.try_shutdown()


@pytest.fixture
def follower(tmp_path):
    domain = session_domain_id()
    # A sensor timeout far above this test's own hiccups on a busy machine: it is not tested here.
    child = start_child('teleop_follower', [
        sys.executable, '-m', 'robot_site.follower_node', '--ros-args', '-p', 'scheme:=model',
        '-p', 'sensor_timeout:=0.5'], loop_environment(domain, tmp_path / 'log'))
    sites = RobotAndLink(domain)
    try:
        deadline = time.monotonic() + CONNECT_TIMEOUT
        while not sites.feedback and time.monotonic() < deadline:
            assert child.returncode is None, 'the follower exited'
            sites.spin(0.1)
        assert sites.feedback, 'no feedback from the follower'
        yield sites
    finally:
        sites.close()
        stop_children([child])


def test_a_nan_in_the_ft_wrench_feeds_back_zero_force_and_no_plane_until_a_good_one(follower):
    """Said as unknown, not free: a bad reading says nothing of the contact."""
    follower.spin(1.0)
    good = follower.since(time.monotonic() - 0.5)
    assert good and all(force == PRESSED for force, _ in good)
    assert all(kind == TeleopFeedback.KIND_PLANE for _, kind in good)  # the patient's surface

    follower.reading = math.nan
    follower.spin(SETTLE)
    bad_start = time.monotonic()
    follower.spin(0.5)
    bad = follower.since(bad_start)
    assert len(bad) > 20
    assert all(force == 0.0 and kind == TeleopFeedback.KIND_UNKNOWN for force, kind in bad), bad

    follower.reading = PRESSED
    follower.spin(SETTLE)
    again = time.monotonic()
    follower.spin(0.5)
    back = follower.since(again)
    assert back and all(force == PRESSED and kind == TeleopFeedback.KIND_PLANE
                        for force, kind in back)
