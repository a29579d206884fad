"""A topic read at a bounded rate: what a tick takes, in order, and what DDS sheds."""
import time

from domains import session_domain_id
from geometry_msgs.msg import PoseStamped
import pytest
import rclpy
from rclpy.context import Context
from rclpy.node import Node
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy

from haptic_util.cdr import MessageCodec
from haptic_util.polled_reader import PolledReader

POSE = MessageCodec(PoseStamped)
# Reliable, so that a burst reaches the reader's history whole on a busy machine: what the
# history keeps is then what is tested.
QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=20,
                 reliability=ReliabilityPolicy.RELIABLE)
MATCH_TIMEOUT = 10.0  # [s]


def pose(k: int) -> tuple:
    return (k, 0, 'world', 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)


def matched(reader, publisher) -> None:
    deadline = time.monotonic() + MATCH_TIMEOUT
    while (reader.get_publisher_count() == 0 or publisher.get_subscription_count() == 0) \
            and time.monotonic() < deadline:
        time.sleep(0.01)
    assert reader.get_publisher_count() == 1


def test_each_tick_takes_at_most_its_share_in_order_and_the_history_sheds_the_rest(context):
    owner = Node('follower', context=context)
    sender = Node('stranger', context=context)
    got = []
    reader = PolledReader(owner, PoseStamped, 'teleop/pose', lambda data: got.append(
        POSE.decode(data)[0]), QOS, max_rate=3000.0)
    publisher = sender.create_publisher(PoseStamped, 'teleop/pose', QOS)
    matched(reader, publisher)
    for k in range(50):
        publisher.publish(POSE.encode(pose(k)))
    time.sleep(0.2)  # all delivered to the history, which keeps the last 20
    assert [reader.take() for _ in range(8)] == [3, 3, 3, 3, 3, 3, 2, 0]
    assert got == list(range(30, 50))
    reader.destroy()


def test_its_subscription_is_on_a_hidden_node_that_no_executor_of_the_owner_spins(context):
    owner = Node('follower', context=context)
    reader = PolledReader(owner, PoseStamped, 'teleop/pose', lambda data: None, QOS, 4000.0)
    assert list(owner.subscriptions) == []
    assert len(list(owner.timers)) == 1  # the tick that takes
    reader.destroy()
    assert list(owner.timers) == []


def test_a_reader_its_owner_takes_in_its_own_tick_has_no_timer(context):
    owner = Node('follower', context=context)
    reader = PolledReader(owner, PoseStamped, 'teleop/pose', lambda data: None, QOS, 4000.0,
                          timed=False)
    assert list(owner.timers) == [] and reader.take() == 0
    reader.destroy()


def test_a_node_renamed_on_the_command_line_keeps_its_name_to_itself():
    context = Context()
    rclpy.init(context=context, domain_id=session_domain_id(),
               args=['follower', '--ros-args', '-r', '__node:=renamed'])
    try:
        owner = Node('teleop_follower', context=context)
        reader = PolledReader(owner, PoseStamped, 'teleop/pose', lambda data: None, QOS, 4000.0)
        deadline = time.monotonic() + MATCH_TIMEOUT
        while '_renamed_intake' not in owner.get_node_names() and time.monotonic() < deadline:
            time.sleep(0.01)
        names = owner.get_node_names()  # the domain's: other tests' nodes may linger in it
        assert '_renamed_intake' in names and names.count('renamed') == 1
        reader.destroy()
    finally:
        rclpy.try_shutdown(context=context)


@pytest.mark.parametrize('max_rate', [0.0, -1.0, float('nan')])
def test_a_rate_that_is_not_positive_is_refused(context, max_rate):
    with pytest.raises(ValueError, match='max_rate'):
        PolledReader(Node('follower', context=context), PoseStamped, 'teleop/pose',
                     lambda data: None, QOS, max_rate)
