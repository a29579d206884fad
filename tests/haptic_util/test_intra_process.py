"""Streams between nodes of one process: handed over in it, in order; DDS only for the outside.

The "outside" is a node of a second rclpy context: its own DDS participant, as another process
would have, whose subscriptions the bus does not know.
"""
import time

from domains import session_domain_id
from geometry_msgs.msg import PoseStamped, WrenchStamped
import pytest
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node

from haptic_util import intra_process
from haptic_util.callback_errors import callback_errors
from haptic_util.cdr import MessageCodec
from haptic_util.intra_process import stream_publisher, stream_subscription
from haptic_util.qos import HAPTIC_STREAM_QOS
from haptic_util.tally import Tally

POSE = MessageCodec(PoseStamped)
WRENCH = MessageCodec(WrenchStamped)
VALUES = (12, 345, 'world', 0.1, -0.2, 0.3, 0.0, 0.0, 0.0, 1.0)
MATCH_TIMEOUT = 10.0  # [s] for DDS discovery between two participants


@pytest.fixture
def bus():
    intra_process.enable()
    yield
    intra_process.close()


def node(context, name):
    return Node(name, context=context)


def spin_until(nodes, done, timeout=MATCH_TIMEOUT) -> bool:
    """Spin the nodes, of any contexts (one executor each), until ``done()`` or the timeout."""
    executors = {}
    for each in nodes:
        executors.setdefault(each.context, SingleThreadedExecutor(context=each.context))
        executors[each.context].add_node(each)
    deadline = time.monotonic() + timeout
    while not done() and time.monotonic() < deadline:
        for executor in executors.values():
            executor.spin_once(timeout_sec=0.005)
    return done()


def test_in_one_process_a_message_reaches_its_subscriber_as_values_before_publish_returns(
        context, bus):
    got = []
    publisher = stream_publisher(node(context, 'driver'), POSE, 'wand/pose')
    subscriber = node(context, 'collision')
    stream_subscription(subscriber, POSE, 'wand/pose', got.append, refused=Tally())
    publisher.publish(VALUES)
    assert got == [VALUES]
    assert list(subscriber.subscriptions) == []  # nothing taken over DDS


@pytest.mark.parametrize('max_rate', [None, 1000.0], ids=['taken', 'polled'])
def test_a_subscription_made_before_its_publisher_stops_taking_the_topic_over_dds(
        context, bus, max_rate):
    """Its DDS reader goes: the subscription the executor takes, or a polled reader's timer."""
    subscriber = node(context, 'collision')
    subscription = stream_subscription(subscriber, POSE, 'wand/pose', lambda values: None,
                                       refused=Tally(), max_rate=max_rate)
    readers = (len(list(subscriber.subscriptions)), len(list(subscriber.timers)))
    assert readers == ((1, 0) if max_rate is None else (0, 1))
    publisher = stream_publisher(node(context, 'driver'), POSE, 'wand/pose')
    assert (len(list(subscriber.subscriptions)), len(list(subscriber.timers))) == (0, 0)
    assert publisher.get_subscription_count() == 1 and subscription.get_publisher_count() == 1


def test_what_comes_from_outside_is_taken_in_the_tick_of_the_node_that_reads_it(context, bus):
    """The gateway's source is called by the follower's tick alone, and serves every reader."""
    arrived, got = [], {'follower': [], 'recorder': []}
    gateway = node(context, 'gateway')
    publisher = stream_publisher(gateway, POSE, 'teleop/command')

    def source():
        while arrived:
            publisher.publish(arrived.pop(0))
    publisher.set_source(source)
    assert not publisher.taken_in_tick  # so far the gateway must hand over by itself
    follower, recorder = node(context, 'follower'), node(context, 'recorder')
    commands = stream_subscription(follower, POSE, 'teleop/command', got['follower'].append,
                                   refused=Tally(), max_rate=4000.0, in_tick=True)
    stream_subscription(recorder, POSE, 'teleop/command', got['recorder'].append,
                        refused=Tally(), max_rate=4000.0)
    assert publisher.taken_in_tick
    assert [list(n.timers) for n in (gateway, follower, recorder)] == [[], [], []]
    arrived.extend([VALUES, VALUES[:1] + (346,) + VALUES[2:]])
    assert got == {'follower': [], 'recorder': []}  # nothing until the tick takes it
    commands.take()
    assert [values[1] for values in got['follower']] == [345, 346]
    assert got['recorder'] == got['follower']


@pytest.mark.parametrize('in_process', [True, False], ids=['in_process', 'over_dds'])
def test_a_subscription_taken_in_its_tick_takes_over_dds_only_when_its_node_takes(
        context, in_process):
    """No timer of its own: what DDS brings waits in the reader's history for ``take``."""
    if in_process:
        intra_process.enable()
    try:
        got = []
        follower = node(context, 'follower')
        commands = stream_subscription(follower, POSE, 'teleop/command', got.append,
                                       refused=Tally(), max_rate=4000.0, in_tick=True)
        assert list(follower.timers) == [] and list(follower.subscriptions) == []
        operator = node(context, 'operator')
        publisher = operator.create_publisher(PoseStamped, 'teleop/command', HAPTIC_STREAM_QOS)
        assert spin_until([follower, operator], lambda: commands.get_publisher_count() == 1)
        publisher.publish(POSE.encode(VALUES))
        deadline = time.monotonic() + MATCH_TIMEOUT
        while not got and time.monotonic() < deadline:
            spin_until([follower, operator], lambda: False, timeout=0.01)
            assert got == []  # spinning takes nothing
            commands.take()
        assert got == [list(VALUES)]
    finally:
        intra_process.close()


def test_a_subscription_taken_in_its_tick_is_polled_and_only_it_is_taken(context):
    with pytest.raises(ValueError, match='give max_rate'):
        stream_subscription(node(context, 'follower'), POSE, 'teleop/command', print,
                            refused=Tally(), in_tick=True)
    pushed = stream_subscription(node(context, 'leader'), POSE, 'teleop/feedback', print,
                                 refused=Tally(), max_rate=4000.0)
    with pytest.raises(ValueError, match='not made in_tick'):
        pushed.take()


@pytest.mark.parametrize('in_process', [True, False], ids=['in_process', 'over_dds'])
def test_a_polled_reader_leaves_the_graph_with_its_subscription(context, in_process):
    """Its node of its own goes then, not when the process closes, and no reader is left."""
    if in_process:
        intra_process.enable()
    try:
        follower = node(context, 'follower')
        commands = stream_subscription(follower, POSE, 'teleop/command', print,
                                       refused=Tally(), max_rate=4000.0, in_tick=True)
        assert sorted(follower.get_node_names()) == ['_follower_intake', 'follower']
        commands.destroy()
        assert follower.get_node_names() == ['follower']
        assert follower.count_subscribers('teleop/command') == 0
    finally:
        intra_process.close()


def test_when_the_subscription_whose_node_reads_a_topic_goes_the_next_one_s_node_reads_it(
        context, bus):
    follower, recorder = node(context, 'follower'), node(context, 'recorder')
    commands = stream_subscription(follower, POSE, 'teleop/command', print, refused=Tally(),
                                   max_rate=4000.0, in_tick=True)
    got = []
    stream_subscription(recorder, POSE, 'teleop/command', got.append, refused=Tally(),
                        max_rate=4000.0)
    assert list(recorder.timers) == []  # one reader for the process: the follower's
    commands.destroy()
    assert sorted(recorder.get_node_names()) == ['_recorder_intake', 'follower', 'recorder']
    operator = node(context, 'operator')
    publisher = operator.create_publisher(PoseStamped, 'teleop/command', HAPTIC_STREAM_QOS)
    assert spin_until([recorder, operator],
                      lambda: publisher.publish(POSE.encode(VALUES)) or bool(got))
    assert got[0] == list(VALUES)


def test_messages_are_delivered_in_the_order_they_were_published(context, bus):
    seen = []
    pose_out = stream_publisher(node(context, 'driver'), POSE, 'wand/pose')
    relay = node(context, 'relay')
    wrench_out = stream_publisher(relay, WRENCH, 'wand/wrench')

    def answer(values):
        seen.append(('relay', values[1]))
        wrench_out.publish((*values[:3], 1.0, 2.0, 3.0, 0.0, 0.0, 0.0))
        seen.append(('relay published', values[1]))
    stream_subscription(relay, POSE, 'wand/pose', answer, refused=Tally())
    stream_subscription(node(context, 'observer'), POSE, 'wand/pose',
                        lambda values: seen.append(('observer', values[1])), refused=Tally())
    stream_subscription(node(context, 'driver_in'), WRENCH, 'wand/wrench',
                        lambda values: seen.append(('wrench', values[1])), refused=Tally())
    pose_out.publish(VALUES)
    seen.append('returned')
    # The relay's wrench waits for the relay's callback and the pose's other subscriber.
    assert seen == [('relay', 345), ('relay published', 345), ('observer', 345),
                    ('wrench', 345), 'returned']


def test_a_raising_subscriber_is_counted_and_the_others_still_get_the_message(context, bus,
                                                                              capsys):
    got = []
    publisher = stream_publisher(node(context, 'driver'), POSE, 'wand/pose')

    def fails(values):
        raise RuntimeError('a bad pose')
    stream_subscription(node(context, 'flaky'), POSE, 'wand/pose', fails, refused=Tally())
    stream_subscription(node(context, 'steady'), POSE, 'wand/pose', got.append, refused=Tally())
    errors = callback_errors()
    publisher.publish(VALUES)
    publisher.publish(VALUES)
    assert got == [VALUES, VALUES] and callback_errors() == errors + 2
    assert capsys.readouterr().err.count('RuntimeError: a bad pose') == 1  # once per place


def test_dds_carries_a_message_only_while_a_reader_of_another_process_matches(context, bus):
    driver = node(context, 'driver')
    publisher = stream_publisher(driver, POSE, 'wand/pose')
    stream_subscription(node(context, 'collision'), POSE, 'wand/pose', lambda values: None,
                        refused=Tally())
    writes = []
    write = publisher._dds.publish
    publisher._dds.publish = lambda data: (writes.append(data), write(data))
    publisher.publish(VALUES)
    assert writes == []  # the one reader is in the process
    outside = Context()
    rclpy.init(context=outside, domain_id=session_domain_id())
    recorder = node(outside, 'recorder')
    received = []
    reader = recorder.create_subscription(PoseStamped, 'wand/pose', received.append,
                                          HAPTIC_STREAM_QOS, raw=True)
    try:
        assert spin_until([driver, recorder], lambda: publisher.get_subscription_count() == 2)
        assert spin_until([driver, recorder],
                          lambda: publisher.publish(VALUES) or bool(received))
        assert POSE.decode(received[0]) == list(VALUES) and writes[0] == received[0]
        recorder.destroy_subscription(reader)
        assert spin_until([driver, recorder], lambda: publisher._readers == 0)
        written = len(writes)
        publisher.publish(VALUES)
        assert len(writes) == written  # the reader left: no more DDS writes
    finally:
        rclpy.try_shutdown(context=outside)


def test_a_topic_published_outside_is_taken_once_for_all_its_subscriptions_here(context, bus):
    """The process's recorder gets exactly what its node got, and DDS carries it once."""
    leader, recorder = node(context, 'leader'), node(context, 'recorder')
    got = {'leader': [], 'recorder': []}
    for each in (leader, recorder):
        stream_subscription(each, POSE, 'teleop/feedback', got[each.get_name()].append,
                            refused=Tally())
    assert len([*leader.subscriptions, *recorder.subscriptions]) == 1
    outside = Context()
    rclpy.init(context=outside, domain_id=session_domain_id())
    bridge = node(outside, 'bridge')
    publisher = bridge.create_publisher(PoseStamped, 'teleop/feedback', HAPTIC_STREAM_QOS)
    try:
        assert spin_until([leader, recorder, bridge], lambda: (
            publisher.publish(POSE.message_class()) or len(got['leader']) >= 3))
    finally:
        rclpy.try_shutdown(context=outside)
    assert got['leader'] and got['recorder'] == got['leader']


def test_without_it_a_stream_is_cdr_over_dds_and_parsed_for_the_callback(context):
    got = []
    driver = node(context, 'driver')
    publisher = stream_publisher(driver, POSE, 'wand/pose')
    subscriber = node(context, 'collision')
    stream_subscription(subscriber, POSE, 'wand/pose', got.append, refused=Tally())
    assert [s.topic_name for s in subscriber.subscriptions] == ['/wand/pose']
    assert spin_until([driver, subscriber], lambda: publisher.publish(VALUES) or bool(got))
    assert got[0] == list(VALUES)


def test_a_topic_of_two_types_or_a_message_of_the_wrong_length_is_refused(context, bus):
    publisher = stream_publisher(node(context, 'driver'), POSE, 'wand/pose')
    with pytest.raises(ValueError, match='wand/pose is PoseStamped in this process'):
        stream_subscription(node(context, 'other'), WRENCH, 'wand/pose', lambda values: None,
                            refused=Tally())
    with pytest.raises(ValueError, match='9 values for the 10 fields of PoseStamped'):
        publisher.publish(VALUES[:-1])


def test_bytes_that_are_no_message_are_counted_with_their_reason_and_the_good_ones_go_on(
        context):
    """A peer on the network may send anything on a topic: the callback sees only messages,
    nothing raises into the executor, and the node's tally says what came."""
    got, refused = [], Tally()
    subscriber = node(context, 'collision')
    stream_subscription(subscriber, POSE, 'wand/pose', got.append, refused=refused)
    sender = node(context, 'sender')
    raw = sender.create_publisher(PoseStamped, 'wand/pose', HAPTIC_STREAM_QOS)
    good = POSE.encode(VALUES)
    bad = good[:12] + (10**6).to_bytes(4, 'little') + good[16:]  # frame_id: too long to fit

    def send() -> bool:
        raw.publish(bad)
        raw.publish(good)
        return bool(got) and bool(refused.total())
    assert spin_until([subscriber, sender], send)
    assert all(values == list(VALUES) for values in got)
    [(kind, count)] = refused.counts.items()
    assert kind == 'malformed wand/pose' and count >= 1
