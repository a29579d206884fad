"""A stand-in wand for integration tests: publishes poses (and twists), collects the wrenches.

It lives in its own rclpy context, so a test can use it beside a launched loop.
"""
import math
import struct
import time

from geometry_msgs.msg import PoseStamped, TwistStamped, WrenchStamped
import numpy as np
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.serialization import serialize_message

from haptic_msgs.msg import CollisionState
from haptic_util.qos import HAPTIC_STREAM_QOS, RECORDER_QOS
from haptic_util.stamps import to_stamp

STAMP_OFFSET = 4  # [bytes] header.stamp in a CDR message, after the encapsulation header
ANSWER_TIMEOUT = 5.0  # [s] for one pose's answer: ample on a machine busy with other work
FORCE_LIMIT = 10.0  # [N] the force node's default force_limit
WATCHDOG = 0.010  # [s] the force node's default watchdog_timeout
TIMELY = 20  # answers back within WATCHDOG that each press checks
MAX_POSES = 2000  # per press: a machine too busy to answer 20 in time fails with a clear line


class LoopClient:
    """Publishes ``wand/pose`` and ``wand/twist``; records ``wand/wrench`` and collision states."""

    def __init__(self, domain_id: int) -> None:
        self.domain_id = domain_id
        self.wrenches = {}
        self.answer_stamps = {'force_renderer': [], 'collision_engine': []}  # [ns] every one
        self.arrivals = {}  # stamp key -> when its first wrench arrived [ns, this clock]
        self.states = {}
        self.applied = []  # (stamp [ns], |force| [N]) of each wand/applied_wrench, as it came
        self._join()

    def _join(self) -> None:
        """Make this client's participant, node, publishers and subscriptions."""
        self.context = Context()
        rclpy.init(context=self.context, domain_id=self.domain_id)
        self.node = Node('test_wand', context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.pose_pub = self.node.create_publisher(PoseStamped, 'wand/pose', HAPTIC_STREAM_QOS)
        self.twist_pub = self.node.create_publisher(TwistStamped, 'wand/twist',
                                                    HAPTIC_STREAM_QOS)
        self.wrench_sub = self.node.create_subscription(
            WrenchStamped, 'wand/wrench', self._on_wrench, HAPTIC_STREAM_QOS)
        self.state_sub = self.node.create_subscription(
            CollisionState, 'collision/state', self._on_state, HAPTIC_STREAM_QOS)
        self.node.create_subscription(WrenchStamped, 'wand/applied_wrench', self._on_applied,
                                      RECORDER_QOS)  # deep: nothing lost while a test sleeps

    def rejoin(self) -> None:
        """Leave DDS and join it anew as another participant, keeping what was recorded.

        A process SIGKILLed while it wrote to this client could leave the client's own
        participant undelivered to, by the restarted process as well (Fast DDS 2.14).
        """
        self.close()
        self._join()

    def _on_wrench(self, msg: WrenchStamped) -> None:
        key = (msg.header.stamp.sec, msg.header.stamp.nanosec)
        self.answer_stamps['force_renderer'].append(key[0] * 1_000_000_000 + key[1])
        if key not in self.wrenches:  # the answer; a watchdog's zero for the same stamp follows
            self.wrenches[key] = msg
            self.arrivals[key] = self.node.get_clock().now().nanoseconds

    def _on_applied(self, msg: WrenchStamped) -> None:
        f = msg.wrench.force
        self.applied.append((msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec,
                             math.sqrt(f.x * f.x + f.y * f.y + f.z * f.z)))

    def _on_state(self, msg: CollisionState) -> None:
        self.answer_stamps['collision_engine'].append(
            msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec)
        self.states[(msg.header.stamp.sec, msg.header.stamp.nanosec)] = msg

    def wait_connected(self, timeout: float = 20.0) -> None:
        """Until the loop answers a pose: both ways matched, so no later pose is lost to it."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if (self.pose_pub.get_subscription_count() >= 1
                    and self.twist_pub.get_subscription_count() >= 1
                    and self.wrench_sub.get_publisher_count() >= 1
                    and self.state_sub.get_publisher_count() >= 1
                    and self.exchange((0.0, 0.0, 1.0), timeout=0.2)[1] is not None):
                return
            self.executor.spin_once(timeout_sec=0.02)
        raise TimeoutError('the loop did not connect to the test client')

    def spin_until(self, done, timeout: float = ANSWER_TIMEOUT) -> bool:
        """Spin until ``done()`` or ``timeout`` s; return ``done()``."""
        deadline = time.monotonic() + timeout
        while not done() and time.monotonic() < deadline:
            self.executor.spin_once(timeout_sec=0.005)
        return done()

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

    def flood(self, position, count: int) -> float:
        """Publish ``count`` poses alone (no twist) as fast as this client can; return the rate.

        Each pose is serialized once and only its stamp rewritten, so the flood is limited by
        DDS, not by Python message conversion. The rate (Hz) is what was actually sent.
        """
        pose = PoseStamped()
        pose.header.frame_id = 'world'
        pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = position
        pose.pose.orientation.w = 1.0
        cdr = bytearray(serialize_message(pose))
        start = time.monotonic()
        for _ in range(count):
            sec, nanosec = divmod(time.time_ns(), 1_000_000_000)  # ROS time is system time
            struct.pack_into('<iI', cdr, STAMP_OFFSET, sec, nanosec)
            self.pose_pub.publish(bytes(cdr))
        return count / (time.monotonic() - start)

    def exchange(self, position, *, timeout: float = ANSWER_TIMEOUT, **kwargs):
        """Send one pose (see ``send``) and wait for the wrench that answers it.

        Returns (stamp key, wrench or None if none came within ``timeout`` s, seconds from the
        pose's stamp to the wrench's arrival on this client).
        """
        stamp = self.send(position, **kwargs)
        sent_ns = stamp[0] * 1_000_000_000 + stamp[1] - round(kwargs.get('stamp_offset', 0.0)
                                                              * 1e9)
        self.spin_until(lambda: stamp in self.wrenches, timeout)
        wrench = self.wrenches.get(stamp)
        arrived_ns = self.arrivals.get(stamp, sent_ns)
        return stamp, wrench, (arrived_ns - sent_ns) * 1e-9

    def close(self) -> None:
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


def press(client, position, expected, label='', **kwargs) -> None:
    """Drive the loop in lockstep (one pose, then its answer) until TIMELY timely answers.

    Every pose must be answered. An answer back within the force node's watchdog timeout was
    rendered from a fresh state, so it must carry the law's force ``expected`` (3,) N, along a
    face normal. A later one may be the watchdog's zero (its state went stale on the way), or
    carry damping from an estimated velocity (its twist came too late), but never a force off
    the normal or over the limit.
    """
    expected = np.asarray(expected, dtype=float)
    normal = expected != 0.0 if expected.any() else np.ones(3, dtype=bool)
    timely = 0
    for _ in range(MAX_POSES):
        stamp, wrench, latency = client.exchange(position, **kwargs)
        assert wrench is not None, f'{label}: the pose stamped {stamp} got no answer'
        force = np.array([wrench.wrench.force.x, wrench.wrench.force.y, wrench.wrench.force.z])
        if latency <= WATCHDOG:
            np.testing.assert_allclose(force, expected, rtol=1e-9, atol=1e-9, err_msg=label)
            timely += 1
            if timely == TIMELY:
                return
        else:
            assert (np.all(np.abs(force[~normal]) <= 1e-9)
                    and np.linalg.norm(force) <= FORCE_LIMIT), \
                f'{label}: a late answer ({latency:.3f} s) pushes {force} N'
    raise AssertionError(f'{label}: only {timely} of {MAX_POSES} answers came back within '
                         f'{WATCHDOG} s')
