"""The floor the loop is measured against, and the outside observer that measures both.

    python bench/loop_floor.py driver|collision|force|composed [--ros-args ...]
    python bench/loop_floor.py observer OUTPUT.npz [--ros-args ...]

The floor is the loop's topology with no work per hop: a driver publishes ``wand/pose``
(PoseStamped) from a 1 kHz timer and takes ``wand/wrench`` (WrenchStamped); one relay turns each
pose into a ``collision/state`` (CollisionState) with the pose's header, another each state into
a wrench. Same message types, topic names, QoS and executor as the loop, as message objects, the
way a plain rclpy node is written. It has no ``wand/twist``: every stream the project adds shows
in the ratio.

The observer is a separate process subscribing to ``wand/pose`` and ``wand/wrench``, as
``ros2 topic echo`` or RViz would: it counts the poses it sees, matches each wrench to its pose by
stamp, and notes the wrench's arrival; on SIGINT it writes the record to OUTPUT.npz.
"""
import sys

from geometry_msgs.msg import PoseStamped, WrenchStamped
import numpy as np
from rclpy.node import Node

from haptic_msgs.msg import CollisionState
from haptic_util.executor import run_nodes
from haptic_util.qos import HAPTIC_STREAM_QOS

__all__ = ['FloorDriver', 'FloorRelay', 'Observer', 'main']

RATE = 1000.0  # [Hz]


class FloorDriver(Node):
    """Publishes a pose per tick, stamped now; takes the wrenches."""

    def __init__(self):
        super().__init__('wand_driver')
        self.pose = PoseStamped()
        self.pose.header.frame_id = 'world'
        self.pose.pose.orientation.w = 1.0
        self.publisher = self.create_publisher(PoseStamped, 'wand/pose', HAPTIC_STREAM_QOS)
        self.create_subscription(WrenchStamped, 'wand/wrench', lambda msg: None,
                                 HAPTIC_STREAM_QOS)
        self.create_timer(1.0 / RATE, self.tick)

    def tick(self) -> None:
        self.pose.header.stamp = self.get_clock().now().to_msg()
        self.publisher.publish(self.pose)


class FloorRelay(Node):
    """Answers each message on ``source`` with a message on ``target`` carrying its header."""

    def __init__(self, name, source, source_type, target, target_type):
        super().__init__(name)
        self.out = target_type()
        self.publisher = self.create_publisher(target_type, target, HAPTIC_STREAM_QOS)
        self.create_subscription(source_type, source, self.relay, HAPTIC_STREAM_QOS)

    def relay(self, msg) -> None:
        self.out.header = msg.header
        self.publisher.publish(self.out)


def collision_relay():
    return FloorRelay('collision_engine', 'wand/pose', PoseStamped, 'collision/state',
                      CollisionState)


def force_relay():
    return FloorRelay('force_renderer', 'collision/state', CollisionState, 'wand/wrench',
                      WrenchStamped)


class Observer(Node):
    """Sees the poses and the wrenches from outside the loop; records stamps and arrivals."""

    def __init__(self, output: str):
        super().__init__('outside_observer')
        self.output = output
        self.poses = []  # stamps [ns]
        self.wrenches = []  # (stamp [ns], arrival [ns])
        self.create_subscription(PoseStamped, 'wand/pose', self.on_pose, HAPTIC_STREAM_QOS)
        self.create_subscription(WrenchStamped, 'wand/wrench', self.on_wrench,
                                 HAPTIC_STREAM_QOS)

    def on_pose(self, msg: PoseStamped) -> None:
        self.poses.append(msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec)

    def on_wrench(self, msg: WrenchStamped) -> None:
        stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        self.wrenches.append((stamp, self.get_clock().now().nanoseconds))

    def destroy_node(self) -> bool:
        np.savez(self.output, poses=np.array(self.poses, dtype=np.int64),
                 wrenches=np.array(self.wrenches, dtype=np.int64).reshape(-1, 2))
        return super().destroy_node()


FACTORIES = {'driver': [FloorDriver], 'collision': [collision_relay], 'force': [force_relay],
             'composed': [FloorDriver, collision_relay, force_relay]}


def main(argv=None) -> int:
    argv = sys.argv if argv is None else argv
    role = argv[1]
    if role == 'observer':
        return run_nodes([lambda: Observer(argv[2])], argv)
    return run_nodes(FACTORIES[role], argv)


if __name__ == '__main__':
    raise SystemExit(main())
