"""A stand-in wand for integration tests: publishes poses (and twists), collects the wrenches.

It lives in its own rclpy context, so a test can use it beside a launched loop.
"""
import time

from geometry_msgs.msg import PoseStamped, TwistStamped, WrenchStamped
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node

from haptic_msgs.msg import CollisionState
from haptic_util.qos import HAPTIC_STREAM_QOS
from haptic_util.stamps import to_stamp


class LoopClient:
    """Publishes ``wand/pose`` and ``wand/twist``; records ``wand/wrench`` and collision states."""

    def __init__(self, domain_id: int) -> None:
        self.context = Context()
        rclpy.init(context=self.context, domain_id=domain_id)
        self.node = Node('test_wand', context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.pose_pub = self.node.create_publisher(PoseStamped, 'wand/pose', HAPTIC_STREAM_QOS)
        self.twist_pub = self.node.create_publisher(TwistStamped, 'wand/twist',
                                                    HAPTIC_STREAM_QOS)
        self.wrenches = {}
        self.states = {}
        self.wrench_sub = self.node.create_subscription(
            WrenchStamped, 'wand/wrench', self._on_wrench, HAPTIC_STREAM_QOS)
        self.state_sub = self.node.create_subscription(
            CollisionState, 'collision/state', self._on_state, HAPTIC_STREAM_QOS)

    def _on_wrench(self, msg: WrenchStamped) -> None:
        self.wrenches[(msg.header.stamp.sec, msg.header.stamp.nanosec)] = msg

    def _on_state(self, msg: CollisionState) -> None:
        self.states[(msg.header.stamp.sec, msg.header.stamp.nanosec)] = msg

    def wait_connected(self, timeout: float = 20.0) -> None:
        """Until our publishers and subscriptions have matched the loop's."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if (self.pose_pub.get_subscription_count() >= 1
                    and self.twist_pub.get_subscription_count() >= 1
                    and self.wrench_sub.get_publisher_count() >= 1
                    and self.state_sub.get_publisher_count() >= 1):
                return
            self.executor.spin_once(timeout_sec=0.02)
        raise TimeoutError('the loop did not connect to the test client')

    def send(self, position, *, frame_id: str = 'world', orientation=(0.0, 0.0, 0.0, 1.0),
             velocity=(0.0, 0.0, 0.0), stamp_offset: float = 0.0) -> tuple:
        """Publish one pose and its twist, stamped now (+ offset s); return the stamp key."""
        now = self.node.get_clock().now().nanoseconds + round(stamp_offset * 1e9)
        stamp = to_stamp(now)
        pose = PoseStamped()
        pose.header.stamp, pose.header.frame_id = stamp, frame_id
        pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = position
        q = pose.pose.orientation
        q.x, q.y, q.z, q.w = orientation
        twist = TwistStamped()
        twist.header = pose.header
        twist.twist.linear.x, twist.twist.linear.y, twist.twist.linear.z = velocity
        self.twist_pub.publish(twist)
        self.pose_pub.publish(pose)
        return (stamp.sec, stamp.nanosec)

    def flood(self, position, rate: float, duration: float) -> int:
        """Publish poses alone (no twist) at ``rate`` Hz for ``duration`` s; return how many."""
        pose = PoseStamped()
        pose.header.frame_id = 'world'
        pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = position
        pose.pose.orientation.w = 1.0
        clock, sent = self.node.get_clock(), 0
        start = time.monotonic()
        while (elapsed := time.monotonic() - start) < duration:
            if sent < elapsed * rate:
                pose.header.stamp = clock.now().to_msg()
                self.pose_pub.publish(pose)
                sent += 1
        return sent

    def hold(self, position, duration: float, period: float = 0.001, **kwargs) -> list:
        """Send the same pose every ``period`` for ``duration`` s; return the stamps sent.

        Like a driver's timer, a late send does not make up for missed ones with a burst.
        """
        stamps = []
        next_send = time.monotonic()
        for _ in range(round(duration / period)):
            while (remaining := next_send - time.monotonic()) > 0:
                self.executor.spin_once(timeout_sec=remaining)
            stamps.append(self.send(position, **kwargs))
            next_send = max(next_send + period, time.monotonic())
        return stamps

    def collect(self, stamps, timeout: float = 1.0) -> list:
        """Wrenches answering ``stamps`` (None where none came), after waiting up to timeout."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline and any(s not in self.wrenches for s in stamps):
            self.executor.spin_once(timeout_sec=0.01)
        return [self.wrenches.get(s) for s in stamps]

    def close(self) -> None:
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)
