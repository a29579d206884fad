"""The newest message of a stream, taken when asked: each one once, the older ones never."""
import time

from domains import session_domain_id
from geometry_msgs.msg import PoseStamped
import rclpy
from rclpy.context import Context
from rclpy.node import Node

from haptic_util.cdr import MessageCodec
from haptic_util.newest import NewestMessage
from haptic_util.qos import HAPTIC_STREAM_QOS
from haptic_util.tally import Tally

POSE = MessageCodec(PoseStamped)
MATCH_TIMEOUT = 10.0  # [s] for DDS discovery


def pose(stamp: int) -> PoseStamped:
    message = PoseStamped()
    message.header.stamp.sec, message.header.frame_id = stamp, 'base_link'
    return message


def test_the_reader_takes_the_newest_pose_once_and_never_the_older_ones():
    context = Context()
    rclpy.init(context=context, domain_id=session_domain_id())
    try:
        robot = Node('robot', context=context)
        imager = Node('imager', context=context)  # spun by no executor
        refused = Tally()
        newest = NewestMessage(imager, POSE, 'robot/tcp_pose', refused=refused)
        publisher = robot.create_publisher(PoseStamped, 'robot/tcp_pose', HAPTIC_STREAM_QOS)
        deadline = time.monotonic() + MATCH_TIMEOUT
        while publisher.get_subscription_count() == 0 and time.monotonic() < deadline:
            time.sleep(0.01)
        assert newest.take() is None  # nothing published yet
        for stamp in (1, 2, 3):
            publisher.publish(pose(stamp))
        deadline = time.monotonic() + MATCH_TIMEOUT
        taken = None
        while taken is None and time.monotonic() < deadline:
            taken = newest.take()
            time.sleep(0.01)
        assert taken is not None and taken[0] == 3 and taken[2] == 'base_link'
        assert newest.take() is None  # each once; the older two were never kept
        assert refused.total() == 0
        newest.destroy()
    finally:
        rclpy.try_shutdown(context=context)
