"""Recording a session to a rosbag2 bag (mcap, Jazzy format) on machines without ``ros2 bag``.

Two recorders share what is here (``Recorder``): the bag, written by its own thread from a
bounded queue (``haptic_bringup.queued_bag``), each message with its receive time as ``ros2 bag
record`` does; the topics taken over DDS as raw CDR (latched ones transient-local, reliable ones
reliably); ``/diagnostics``; and a report of its own: messages written and dropped per topic.

- ``haptic_bringup.process_recorder``: inside a site's own process (``haptic_loop``'s default).
  It takes the 1 kHz streams by the process's handover, so DDS cannot starve it.
- ``BagRecorder`` (this module's ``main``), a process of its own: for three processes
  (``--separate``) and for topics of other programs. Everything reaches it over DDS, and the
  streams are best effort. Once every topic has a matched publisher it says so on
  ``recorder/ready`` (latched), so that a driver can hold its session until nothing it publishes
  can be missed. When asked to stop it first takes whatever is still coming, until every process
  it records has gone (their last reports included) or ``LINGER`` has passed: under ``ros2
  launch`` or a terminal's Ctrl-C, the recorder gets its SIGINT together with the nodes.
  What it guarantees: every message that reached it is in the bag, and every one DDS lost on the
  way is counted in its report (``lost: <topic>``, from the gaps DDS sees in each writer's
  sequence). What it cannot: take a best-effort message its process was too starved to take in
  time. Its shared-memory port holds 8192 messages, 1.4 s of the loop's streams, and the
  processes it records get segments that hold longer (``haptic_util.transport``). A
  loss after a writer's last message has no later one to show it: the nodes' final reports
  (what each says it published) are the full account (``haptic_bringup.session``).

The reports of the recorder's own process are handed over as published
(``haptic_util.diagnostics.listen``), the last ones too, which are written while the nodes are
destroyed; the other processes' come over DDS. After ``kill -9`` a bag is recoverable up to the
last flush (``haptic_bringup.bag``).
"""
import importlib
import pathlib
import time

from ament_index_python.packages import get_package_share_directory
from diagnostic_msgs.msg import DiagnosticArray
from rclpy.event_handler import SubscriptionEventCallbacks
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message, serialize_message
from std_msgs.msg import Bool

from haptic_bringup.bag import typestore_with
from haptic_bringup.params import RecorderParams
from haptic_bringup.queued_bag import QueuedBag
from haptic_contract.graph import DIAGNOSTICS, FRAME_TOPICS, LATCHED_TOPICS, TOPIC_TYPES
from haptic_util import diagnostics
from haptic_util.diagnostics import Diagnostics, OK, Report, WARN
from haptic_util.executor import run_nodes, StartupError
from haptic_util.parameters import declare_parameters
from haptic_util.qos import FRAME_QOS, LATCHED_QOS, RECORDER_QOS, RELIABLE_RECORDER_QOS
from haptic_util.stamps import clock_ns
from haptic_util.tally import Tally
from haptic_util.transport import deep_shared_memory

__all__ = ['Recorder', 'BagRecorder', 'main', 'custom_definitions', 'message_class']

CUSTOM_PACKAGES = ('haptic_msgs',)
GRAPH_POLL_PERIOD = 0.02  # [s]
WRITER_MATCH_SETTLE = 0.5  # [s] see subscribe_new_topics
REPORT_PERIOD = 1.0  # [s]
LINGER = 1.5  # [s] the longest a stopping recorder waits for the processes it records to go
DRAIN_POLL = 0.01  # [s]


def custom_definitions(packages=CUSTOM_PACKAGES) -> list:
    """(type name, .msg text) of the project's own interfaces, from their installed share."""
    definitions = []
    for package in packages:
        share = pathlib.Path(get_package_share_directory(package)) / 'msg'
        for path in sorted(share.glob('*.msg')):
            definitions.append((f'{package}/msg/{path.stem}', path.read_text()))
    return definitions


def message_class(type_name: str):
    """Import and return the Python class of ``pkg/msg/Name``."""
    package, _, name = type_name.split('/')
    return getattr(importlib.import_module(f'{package}.msg'), name)


class Recorder(Node):
    """Records ``topics`` to the new bag ``output``, each as ``prefix`` + its name.

    A subclass decides how each topic is taken (``record``); this one takes them over DDS.
    """

    def __init__(self, name: str, **kwargs):
        super().__init__(name, **kwargs)
        self.params = declare_parameters(self, RecorderParams)
        output = pathlib.Path(self.params.output).expanduser()
        if output.exists():
            raise StartupError(f'{self.get_name()}: output {output} exists already; '
                               'give a new directory')
        self.bag = QueuedBag(output, typestore_with(custom_definitions()))
        self._clock = self.get_clock()
        self._subscribed = []  # (DDS subscription, what writes its messages)
        self._pending = []  # (topic, name in the bag) whose type the graph will tell
        self._reporters = set()  # this process's nodes, whose reports are handed over
        self.taken = 0  # messages queued for the bag
        self.lost = {}  # topic -> messages DDS told a best-effort reader it lost on the way
        self.refused = Tally()  # bytes of a stream it reads itself that were no message
        self._listening = []
        self.diagnostics = Diagnostics(self, self.report, REPORT_PERIOD)
        for topic in [self.resolve_topic_name(t) for t in self.params.topics]:
            self.record(topic, self.params.prefix + topic)
        self._poll = self.create_timer(GRAPH_POLL_PERIOD, self.subscribe_new_topics)
        self.get_logger().info(f'recording {", ".join(self.params.topics)} to {output}')

    def record(self, topic: str, name: str) -> None:
        """Take ``topic`` and write it as ``name``: over DDS, typed now or once it is seen."""
        if topic == DIAGNOSTICS:
            self._record_reports(name)
        elif topic in TOPIC_TYPES:
            qos = (LATCHED_QOS if topic in LATCHED_TOPICS else
                   FRAME_QOS if topic in FRAME_TOPICS else RECORDER_QOS)
            self._over_dds(topic, name, TOPIC_TYPES[topic], qos)
        else:
            self._pending.append((topic, name))

    def put(self, name: str, message) -> None:
        """Queue ``message`` (CDR bytes, or what ``name``'s encoder takes), stamped now."""
        self.taken += 1
        self.bag.put(name, clock_ns(self._clock), message)

    def _over_dds(self, topic: str, name: str, type_name: str, qos, write=None) -> None:
        """Subscribe ``topic`` raw; a best-effort one counts what DDS lost on its way here."""
        self.bag.add_topic(name, type_name)
        write = write or (lambda data: self.put(name, data))
        events = SubscriptionEventCallbacks(
            message_lost=lambda info: self.lost.__setitem__(name, info.total_count))
        self._subscribed.append((self.create_subscription(
            message_class(type_name), topic, write, qos, raw=True,
            event_callbacks=events if qos.reliability == ReliabilityPolicy.BEST_EFFORT
            else None), write))

    def _record_reports(self, name: str) -> None:
        """Take this process's reports as they are published, the others' over DDS, reliably."""
        def own(array: DiagnosticArray) -> None:  # about once a second per node
            self._reporters.update(status.name for status in array.status)
            self.put(name, serialize_message(array))

        def others(data: bytes) -> None:
            statuses = deserialize_message(data, DiagnosticArray).status
            if not all(status.name in self._reporters for status in statuses):
                self.put(name, data)
        self.bag.add_topic(name, TOPIC_TYPES[DIAGNOSTICS])
        diagnostics.listen(own)
        self._listening.append(own)
        self._subscribed.append((self.create_subscription(
            DiagnosticArray, DIAGNOSTICS, others, RELIABLE_RECORDER_QOS, raw=True), others))

    def subscribe_new_topics(self) -> None:
        """Subscribe the topics of unknown type once the graph shows them."""
        types = dict(self.get_topic_names_and_types()) if self._pending else {}
        for topic, name in [entry for entry in self._pending if entry[0] in types]:
            self._over_dds(topic, name, types[topic][0],
                           _matching_qos(self.get_publishers_info_by_topic(topic)))
            self._pending.remove((topic, name))
        if not self._pending and self.matched():
            self._poll.cancel()
            self.all_matched()

    def matched(self) -> bool:
        """Whether the graph poll may end once every topic is subscribed."""
        return True

    def all_matched(self) -> None:
        """Act once the graph poll has ended (a recorder process then says it is ready)."""

    def report(self) -> Report:
        dropped, lost = self.bag.dropped, dict(self.lost)
        values = {'recorded': sum(self.bag.counts.values()), 'dropped': sum(dropped.values()),
                  'lost': sum(lost.values()),
                  **{f'recorded: {t}': n for t, n in self.bag.counts.items()},
                  **{f'dropped: {t}': n for t, n in dropped.items()},
                  **{f'lost: {t}': n for t, n in lost.items()}}
        if self.refused.total():
            values.update(refused=self.refused.total(), **{
                f'refused: {kind}': n for kind, n in self.refused.counts.items()})
        if self.bag.error:
            values['error'] = self.bag.error
        return Report(WARN if values['dropped'] or values['lost'] else OK,
                      f'{values["recorded"]} messages written; {values["dropped"]} dropped (a '
                      f'full queue), {values["lost"]} lost on the way (DDS)', values)

    def destroy_node(self) -> bool:
        """Close the bag after the last report, this node's own included: it is complete."""
        self.bag.drain()  # so that the last report counts all but itself
        self.diagnostics.final()
        for listener in self._listening:
            diagnostics.stop_listening(listener)
        self.bag.close()
        counts = ', '.join(f'{t}: {n}' for t, n in self.bag.counts.items())
        missing = {**{f'dropped {t}': n for t, n in self.bag.dropped.items()},
                   **{f'lost {t}': n for t, n in self.lost.items() if n}}
        self.get_logger().info(f'closed {self.bag.path} ({counts})'
                               + (f'; missing: {missing}' if missing else ''))
        return super().destroy_node()


class BagRecorder(Recorder):
    """The recorder as a process of its own: every topic over DDS (see the module's notes)."""

    def __init__(self, **kwargs):
        super().__init__('recorder', **kwargs)
        self._ready_pub = self.create_publisher(Bool, 'recorder/ready', LATCHED_QOS)
        self._ready_pub.publish(Bool(data=False))
        self._settle = None

    def matched(self) -> bool:
        return all(subscription.get_publisher_count() for subscription, _ in self._subscribed)

    def all_matched(self) -> None:
        # DDS matches each reader-writer pair on both sides separately; the writers' side can
        # lag ours by tens of milliseconds, and what a writer sends before it has matched us
        # never reaches the bag. So ready is said only after a settling time.
        self._settle = self.create_timer(WRITER_MATCH_SETTLE, self.say_ready)

    def say_ready(self) -> None:
        self._settle.cancel()
        self._ready_pub.publish(Bool(data=True))
        self.get_logger().info('every topic has a matched publisher: ready')

    def destroy_node(self) -> bool:
        self._take_what_is_still_coming()
        return super().destroy_node()

    def _take_what_is_still_coming(self) -> None:
        """Take what is left in the readers and still coming, until the recorded nodes have gone.

        A recorder stopped with the nodes (SIGINT to the whole group) would otherwise close
        before their last messages and final reports were taken. The process's executor has
        stopped by now, so this spins one of its own.
        """
        executor = SingleThreadedExecutor(context=self.context)
        executor.add_node(self)
        deadline = time.monotonic() + LINGER
        idle = 0  # spins in a row that took nothing (a timer may have fired in one)
        try:
            while idle < 2 and time.monotonic() < deadline:
                before = self.taken
                executor.spin_once(timeout_sec=DRAIN_POLL)
                idle = 0 if self.taken != before or self._others_publishing() else idle + 1
        finally:
            executor.remove_node(self)
            executor.shutdown()

    def _others_publishing(self) -> bool:
        """Whether a node other than this one still publishes a recorded topic."""
        me = self.get_name(), self.get_namespace()
        return any((info.node_name, info.node_namespace) != me
                   for subscription, _ in self._subscribed
                   for info in self.get_publishers_info_by_topic(subscription.topic_name))


def _matching_qos(publishers) -> QoSProfile:
    """Return the QoS to record a topic with: latched, or reliable if all its publishers are."""
    qos = [p.qos_profile for p in publishers]
    if any(q.durability == DurabilityPolicy.TRANSIENT_LOCAL for q in qos):
        return LATCHED_QOS
    if qos and all(q.reliability == ReliabilityPolicy.RELIABLE for q in qos):
        return RELIABLE_RECORDER_QOS
    return RECORDER_QOS


def main(args=None) -> int:
    deep_shared_memory()
    return run_nodes([BagRecorder], args)


if __name__ == '__main__':
    raise SystemExit(main())
