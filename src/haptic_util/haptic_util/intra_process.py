"""The 1 kHz streams between nodes of one process, handed over in the process; DDS for the rest.

Why: rclpy has no intra-process transport (rclcpp's ``use_intra_process_comms``). Between two
nodes of one process, a stream went through Fast DDS all the same: serialized, written, a
listener event, a take, the executor's dispatch and a parse, per message and per reader. With
intra-process delivery on (``enable``, as the composed process does), a message published in
the process is handed to the process's own subscriptions of its topic as its leaf values (what
``haptic_util.cdr`` would have parsed), and serialized and written to DDS only while a reader of
another process matches it (a recorder, RViz, ``ros2 topic echo``): a stream nobody outside
reads costs no DDS at all. A topic no node of the process publishes is taken over DDS once for
the whole process, by one reader that hands each message to every subscription of the topic in
the process (the node that uses it and the process's recorder get the same messages); once a
node of the process publishes it, that reader goes, so nothing arrives twice.

Order: messages are delivered in the order they were published in the process (one first-in
first-out queue). A ``publish`` from outside any delivery (a timer, a DDS callback) delivers
before it returns, and with it everything its subscribers publish in turn: a node that publishes
a request gets the answer of its own process inside that ``publish``. A callback that raises is
logged and counted as the executor does it (``callback_errors``) and stops no other. The
process's executor is single-threaded (``executor.EXECUTORS``), so the queue takes no lock.

Without ``enable`` (one node per process), a stream is CDR over DDS, parsed and serialized by
its codec, and a publisher skips the write while nobody reads it. Streams use the haptic QoS.
A topic that comes from the network (the link's) may be read at a bounded rate instead
(``max_rate``, ``haptic_util.polled_reader``), so that a flood on it is shed by DDS.

What comes into the process from outside it without DDS (the site's gateway, from the other site)
is published by a publisher with a *source* (``StreamPublisher.set_source``): a callable that
publishes what has arrived. A subscription made ``in_tick`` takes its topic in its node's own
tick (``StreamSubscription.take``): from the source, or from its polled DDS reader. The follower
reads the link so, in the tick it runs anyway, and the gateway needs no 1 kHz timer of its own
for that topic.

A publisher learns its DDS readers from the matched events its node's executor delivers, not
by asking DDS on every message (about 1.3 µs a call, six streams a tick): like any ROS 2
node, it must be spun.
"""
from collections import deque
import functools
from typing import Callable, Sequence

from rclpy.event_handler import PublisherEventCallbacks
from rclpy.node import Node
from rclpy.qos import QoSProfile

from haptic_util.callback_errors import log_callback_error
from haptic_util.cdr import MalformedMessage, MessageCodec
from haptic_util.polled_reader import PolledReader
from haptic_util.qos import HAPTIC_STREAM_QOS, LINK_INTAKE_RATE, LINK_QOS
from haptic_util.tally import Tally

__all__ = ['close', 'enable', 'enabled', 'link_subscription', 'stream_publisher',
           'stream_subscription', 'StreamPublisher', 'StreamSubscription']

_state = {'enabled': False}
_topics: dict = {}  # resolved topic -> _Topic, while enabled
_pending: deque = deque()  # (subscription, leaf values) to deliver, in publishing order
_draining = [False]


def enable() -> None:
    """Hand streams between this process's nodes over in the process (call before making them)."""
    _state['enabled'] = True


def enabled() -> bool:
    """Whether streams are handed over in this process (a composed process's nodes)."""
    return _state['enabled']


def close() -> None:
    """Stop delivering in the process and forget its topics: its nodes are being destroyed.

    A subscription's DDS reader goes with the subscription (``StreamSubscription.destroy``),
    which its node's ``destroy_node`` calls.
    """
    for record in _topics.values():
        record.subscriptions.clear()  # the publishers hold these lists
    _topics.clear()
    _pending.clear()
    _state['enabled'] = False


class _Topic:
    """A topic's local publishers and subscriptions, its message type, and its DDS reader."""

    def __init__(self, msg_type) -> None:
        self.msg_type = msg_type
        self.publishers: list = []
        self.subscriptions: list = []
        # (its DDS reader, what destroys it, the subscription whose node reads) while nobody
        # here publishes
        self.reader = None
        self.source = None  # what publishes what came from outside, when a tick takes it

    def take_over_dds(self) -> None:
        """Take the topic over DDS for every subscription of the process, unless it does.

        The first subscription's node reads it, with that subscription's QoS and rate (and,
        polled, by its own timer or in its tick), and counts what is malformed in its tally.
        """
        if self.reader is None and not self.publishers and self.subscriptions:
            reading = self.subscriptions[0]
            self.reader = (*reading.open_reader(self.deliver), reading)

    def remove(self, subscription: 'StreamSubscription') -> None:
        """Forget a destroyed subscription; if its node read the topic, the next one's does."""
        if subscription in self.subscriptions:  # not if ``close`` forgot them all
            self.subscriptions.remove(subscription)
        if self.reader is not None and self.reader[2] is subscription:
            self.drop_reader()
            self.take_over_dds()

    @property
    def taken_in_tick(self) -> bool:
        return any(subscription.in_tick for subscription in self.subscriptions)

    def take(self) -> None:
        """Take what came from outside: from the source, or a DDS reader no timer takes from."""
        if self.source is not None:
            self.source()
        elif self.reader is not None and isinstance(self.reader[0], PolledReader) \
                and not self.reader[0].timed:
            self.reader[0].take()

    def deliver(self, values: Sequence) -> None:
        _pending.extend((subscription, values) for subscription in self.subscriptions)
        _drain()

    def drop_reader(self) -> None:
        """Stop taking the topic over DDS: a node here publishes it, or none reads it so."""
        if self.reader is not None:
            self.reader[1]()
            self.reader = None

    def dds_publisher_count(self) -> int:
        return self.reader[0].get_publisher_count() if self.reader is not None else 0


def _topic(node: Node, msg_type, topic: str) -> _Topic | None:
    """Return the process's record of ``topic`` (None while intra-process delivery is off)."""
    if not _state['enabled']:
        return None
    name = node.resolve_topic_name(topic)
    record = _topics.setdefault(name, _Topic(msg_type))
    if record.msg_type is not msg_type:
        raise ValueError(f'topic {name} is {record.msg_type.__name__} in this process, '
                         f'not {msg_type.__name__}')
    return record


class StreamPublisher:
    """Publishes leaf values: to the process's subscriptions, and to DDS when another reads it."""

    def __init__(self, node: Node, codec: MessageCodec, topic: str) -> None:
        self._codec = codec
        self._dds = node.create_publisher(
            codec.message_class, topic, HAPTIC_STREAM_QOS,
            event_callbacks=PublisherEventCallbacks(matched=self._matched))
        self._readers = self._dds.get_subscription_count()  # DDS readers, kept by _matched
        self._topic = _topic(node, codec.message_class, topic)
        self._local = self._topic.subscriptions if self._topic is not None else []
        if self._topic is not None:
            self._topic.publishers.append(self)
            self._topic.drop_reader()

    @property
    def topic_name(self) -> str:
        """The resolved topic name."""
        return self._dds.topic_name

    def publish(self, values: Sequence) -> None:
        """Publish one message, given as its leaf values in the codec's ``fields`` order."""
        if len(values) != len(self._codec.fields):
            raise ValueError(f'{self.topic_name}: {len(values)} values for the '
                             f'{len(self._codec.fields)} fields of '
                             f'{self._codec.message_class.__name__}')
        if self._local:
            _pending.extend((subscription, values) for subscription in self._local)
            _drain()
        if self._readers:
            self._dds.publish(self._codec.encode(values))

    def get_subscription_count(self) -> int:
        """Return how many subscriptions match: of this process, and over DDS."""
        return len(self._local) + self._dds.get_subscription_count()

    def set_source(self, source: Callable[[], None]) -> None:
        """Publish what comes from outside the process when a subscription takes it in its tick.

        ``source()`` publishes what has arrived since it was last called, by this publisher.
        """
        if self._topic is not None:
            self._topic.source = source

    @property
    def taken_in_tick(self) -> bool:
        """Whether a subscription of this process takes the topic in its node's tick."""
        return self._topic is not None and self._topic.taken_in_tick

    def _matched(self, info) -> None:
        self._readers = info.current_count


class StreamSubscription:
    """Takes a topic's messages as leaf values: from the process's publishers, or over DDS.

    Bytes over DDS that are no message of the type are counted in ``refused``, with the reason,
    and dropped: they never reach the callback, nor raise into the executor (an exception there
    ends its spin, and restarting it stalled a site for hundreds of milliseconds).

    Made ``in_tick`` (polled: ``max_rate`` given), it takes nothing by itself: its node calls
    ``take`` in its own tick.

    Its node's ``destroy_node`` calls ``destroy``: a polled reader lives on a node of its own,
    which would otherwise outlive its owner, matched to the topic's publishers.
    """

    def __init__(self, node: Node, codec: MessageCodec, topic: str,
                 callback: Callable[[Sequence], None], *, refused: Tally,
                 qos: QoSProfile = HAPTIC_STREAM_QOS, max_rate: float | None = None,
                 in_tick: bool = False) -> None:
        if in_tick and max_rate is None:
            raise ValueError(f'{topic}: a subscription taken in its tick is polled: give max_rate')
        self.callback = callback
        self.in_tick = in_tick
        self.open_reader = functools.partial(_dds_reader, node, codec, topic, refused=refused,
                                             qos=qos, max_rate=max_rate, timed=not in_tick)
        self._topic = _topic(node, codec.message_class, topic)
        self._dds = None  # (its own DDS reader, what destroys it), while intra-process is off
        if self._topic is not None:
            self._topic.subscriptions.append(self)
            self._topic.take_over_dds()
        else:
            self._dds = self.open_reader(callback)

    def take(self) -> None:
        """Take what came from outside the process since the last tick (made ``in_tick``)."""
        if not self.in_tick:
            raise ValueError('take: this subscription was not made in_tick; its messages come '
                             'by themselves')
        if self._topic is not None:
            self._topic.take()
        else:
            self._dds[0].take()

    def get_publisher_count(self) -> int:
        """Return how many publishers match: of this process, and over DDS."""
        if self._topic is None:
            return self._dds[0].get_publisher_count()
        return len(self._topic.publishers) + self._topic.dds_publisher_count()

    def destroy(self) -> None:
        """Stop taking the topic, and destroy the DDS reader this subscription's node holds."""
        if self._topic is not None:
            self._topic.remove(self)
        elif self._dds is not None:
            self._dds[1]()
        self._topic = self._dds = None


def _dds_reader(node: Node, codec: MessageCodec, topic: str,
                deliver: Callable[[Sequence], None], *, refused: Tally, qos: QoSProfile,
                max_rate: float | None, timed: bool) -> tuple:
    """Return a DDS reader of ``topic`` for ``node`` (executor-taken or polled), its destroyer."""
    take = _decoding(codec, topic, refused, deliver)
    if max_rate is None:
        subscription = node.create_subscription(codec.message_class, topic, take, qos, raw=True)
        return subscription, lambda: node.destroy_subscription(subscription)
    reader = PolledReader(node, codec.message_class, topic, take, qos, max_rate, timed=timed)
    return reader, reader.destroy


def _decoding(codec: MessageCodec, topic: str, refused: Tally,
              deliver: Callable[[Sequence], None]) -> Callable[[bytes], None]:
    """Return a DDS callback that decodes, hands on what is a message, and counts what is not."""
    kind = f'malformed {topic}'

    def take(data: bytes) -> None:
        try:
            values = codec.decode(data)
        except MalformedMessage as error:
            refused.add(kind, str(error))
            return
        deliver(values)
    return take


def _drain() -> None:
    """Deliver the pending messages in order; the outermost ``publish`` does it."""
    if _draining[0]:
        return
    _draining[0] = True
    try:
        while _pending:
            subscription, values = _pending.popleft()
            try:
                subscription.callback(values)
            except Exception as error:  # one node's failure does not stop the others
                log_callback_error(error)
    finally:
        _draining[0] = False


def stream_publisher(node: Node, codec: MessageCodec, topic: str) -> StreamPublisher:
    """Return a publisher of a 1 kHz stream of ``codec``'s message type on ``topic``."""
    return StreamPublisher(node, codec, topic)


def stream_subscription(node: Node, codec: MessageCodec, topic: str,
                        callback: Callable[[Sequence], None], *, refused: Tally,
                        qos: QoSProfile = HAPTIC_STREAM_QOS, max_rate: float | None = None,
                        in_tick: bool = False) -> StreamSubscription:
    """Return a subscription of a 1 kHz stream: ``callback`` gets each message's leaf values.

    Malformed messages are counted in the node's ``refused`` tally, which its report logs.
    ``qos`` must match the publishers' (the haptic streams'); a deeper history is the one
    choice left to the reader. With ``max_rate`` (Hz), what comes over DDS is taken at most
    that fast (``haptic_util.polled_reader``): for what any network peer may publish; and
    with ``in_tick``, only when the node calls the subscription's ``take``.
    """
    return StreamSubscription(node, codec, topic, callback, refused=refused, qos=qos,
                              max_rate=max_rate, in_tick=in_tick)


def link_subscription(node: Node, codec: MessageCodec, topic: str,
                      callback: Callable[[Sequence], None], *, refused: Tally,
                      in_tick: bool = False) -> StreamSubscription:
    """Return a subscription of a stream that comes over the link to the robot's site.

    Anything on the site's network may publish it too: it is read with the link's history, at
    most ``LINK_INTAKE_RATE`` messages a second from all publishers together, so that a flood
    leaves the site's loop its rate. A node that ticks at 1 kHz takes it in its tick
    (``in_tick``, then ``take`` each tick: the follower its commands, the leader its feedback
    at each wand pose); else a 1 ms timer of its own takes it.
    """
    return stream_subscription(node, codec, topic, callback, refused=refused, qos=LINK_QOS,
                               max_rate=LINK_INTAKE_RATE, in_tick=in_tick)
