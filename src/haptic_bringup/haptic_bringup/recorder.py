"""A rosbag2 recorder for machines without ``ros2 bag``: raw CDR in, mcap (Jazzy format) out.

Subscriptions are raw, so no message is converted to Python; each one is written with its
receive time, as ``ros2 bag record`` does. The loop's topics are subscribed at once; another
topic's type is taken from the graph once a publisher appears. Latched topics (the scene
description) are subscribed transient-local, and reliable ones (the nodes' reports) reliably, so
that a node's last report is acknowledged before the node goes.
Once every topic has a matched publisher it says so on ``recorder/ready`` (latched), so that a
driver can hold its session until nothing it publishes can be missed. On SIGINT or SIGTERM the
bag is closed and complete; after ``kill -9`` it is recoverable up to the last flush (see
``haptic_bringup.bag``).

A telerobotic session spans two DDS domains, the operator's and the remote site's. With
``remote_domain`` set, the recorder joins that domain too (a second context, spun in its own
thread) and writes its ``remote_topics`` into the same bag under ``/remote/``, on the same
clock, so one bag holds both sites.
"""
import importlib
import pathlib
import threading

from ament_index_python.packages import get_package_share_directory
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Bool

from haptic_bringup.bag import BagWriter, typestore_with
from haptic_bringup.params import LATCHED_TOPICS, LOOP_TOPICS, RecorderParams, RELIABLE_TOPICS
from haptic_util.executor import run_nodes, StartupError
from haptic_util.parameters import declare_parameters
from haptic_util.qos import LATCHED_QOS, RECORDER_QOS, RELIABLE_RECORDER_QOS
from haptic_util.stamps import clock_ns

__all__ = ['BagRecorder', 'main', 'custom_definitions']

CUSTOM_PACKAGES = ('haptic_msgs',)
GRAPH_POLL_PERIOD = 0.02  # [s]
REMOTE_PREFIX = '/remote'  # where the remote site's topics go in the bag
WRITER_MATCH_SETTLE = 0.5  # [s] see subscribe_new_topics


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


class BagRecorder(Node):
    """Records the configured topics to ``output`` as soon as each one has a publisher."""

    def __init__(self, **kwargs):
        super().__init__('recorder', **kwargs)
        self.params = declare_parameters(self, RecorderParams)
        output = pathlib.Path(self.params.output).expanduser()
        if output.exists():
            raise StartupError(f'{self.get_name()}: output {output} exists already; '
                               'give a new directory')
        self.bag = BagWriter(output, typestore_with(custom_definitions()))
        self._lock = threading.Lock()  # the remote site's thread writes too
        self._subscribed = []
        self._pending = []  # (node, topic, name in the bag) whose type the graph will tell
        self._ready_pub = self.create_publisher(Bool, 'recorder/ready', LATCHED_QOS)
        self._ready_pub.publish(Bool(data=False))
        self._remote = None
        self._record(self, self.params.topics, '')
        if self.params.remote_domain >= 0:
            self._remote = _RemoteSite(self.params.remote_domain)
            self._record(self._remote.node, self.params.remote_topics, REMOTE_PREFIX)
        self._poll = self.create_timer(GRAPH_POLL_PERIOD, self.subscribe_new_topics)
        self.get_logger().info(f'recording {", ".join(self.bag.counts)} to {output}')

    def _record(self, node: Node, topics, prefix: str) -> None:
        """Record ``topics`` of ``node``'s domain, each as ``prefix`` + its name."""
        for topic in [node.resolve_topic_name(t) for t in topics]:
            if topic in LOOP_TOPICS:
                self._subscribe(node, topic, prefix + topic, LOOP_TOPICS[topic], (
                    LATCHED_QOS if topic in LATCHED_TOPICS else
                    RELIABLE_RECORDER_QOS if topic in RELIABLE_TOPICS else RECORDER_QOS))
            else:
                self._pending.append((node, topic, prefix + topic))

    def _subscribe(self, node: Node, topic: str, name: str, type_name: str, qos) -> None:
        self.bag.add_topic(name, type_name)
        self._subscribed.append(node.create_subscription(
            message_class(type_name), topic, self._writer_for(name), qos, raw=True))

    def subscribe_new_topics(self) -> None:
        """Subscribe the topics of unknown type once the graph shows them; say when ready."""
        for entry in list(self._pending):
            node, topic, name = entry
            types = dict(node.get_topic_names_and_types())
            if topic in types:
                self._subscribe(node, topic, name, types[topic][0],
                                _matching_qos(node.get_publishers_info_by_topic(topic)))
                self._pending.remove(entry)
        if not self._pending and all(s.get_publisher_count() for s in self._subscribed):
            self._poll.cancel()
            # DDS matches each reader-writer pair on both sides separately; the writers' side
            # can lag ours by tens of milliseconds, and what a writer sends before it has matched
            # us never reaches the bag. So ready is said only after a settling time.
            self._settle = self.create_timer(WRITER_MATCH_SETTLE, self.say_ready)

    def say_ready(self) -> None:
        self._settle.cancel()
        self._ready_pub.publish(Bool(data=True))
        self.get_logger().info('every topic has a matched publisher: ready')

    def _writer_for(self, topic: str):
        clock = self.get_clock()

        def write(data: bytes) -> None:
            with self._lock:
                self.bag.write(topic, clock_ns(clock), data)
        return write

    def destroy_node(self) -> bool:
        if self._remote is not None:
            self._remote.close()
        self.bag.close()
        counts = ', '.join(f'{t}: {n}' for t, n in self.bag.counts.items())
        self.get_logger().info(f'closed {self.bag.path} ({counts})')
        return super().destroy_node()


class _RemoteSite:
    """A node in another DDS domain, spun in a thread of its own."""

    def __init__(self, domain_id: int) -> None:
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=domain_id)
        self.node = Node('recorder_remote', context=self.context)
        self.executor = EventsExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.thread = threading.Thread(target=self._spin, daemon=True)
        self.thread.start()

    def _spin(self) -> None:
        try:
            while self.context.ok():
                self.executor.spin_once(timeout_sec=0.05)
        except ExternalShutdownException:
            pass  # closed: the recorder is stopping

    def close(self) -> None:
        self.context.try_shutdown()
        self.thread.join(timeout=2.0)
        self.node.destroy_node()


def _matching_qos(publishers) -> QoSProfile:
    """Return the QoS to record a topic with: latched, or reliable if all its publishers are."""
    qos = [p.qos_profile for p in publishers]
    if any(q.durability == DurabilityPolicy.TRANSIENT_LOCAL for q in qos):
        return LATCHED_QOS
    if qos and all(q.reliability == ReliabilityPolicy.RELIABLE for q in qos):
        return RELIABLE_RECORDER_QOS
    return RECORDER_QOS


def main(args=None) -> int:
    return run_nodes([BagRecorder], args)


if __name__ == '__main__':
    raise SystemExit(main())
