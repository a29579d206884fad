"""Both sites' sides of a test of what relays between them: a context per domain, one executor.

The test process joins both domains and stands in for both sites: it publishes numbered,
stamped poses on one side and times their arrival on the other, on this machine's one clock.
"""
import time

from geometry_msgs.msg import PoseStamped
import rclpy
from rclpy.context import Context
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.task import Future

from haptic_util.qos import HAPTIC_STREAM_QOS, RECORDER_QOS

TO_REMOTE, TO_OPERATOR = 'link_test/to_remote', 'link_test/to_operator'
POSE = 'geometry_msgs/msg/PoseStamped'
CONNECT_TIMEOUT = 20.0  # [s] the relays' start-up and discovery in both domains, busy machine
WARM_UP = -1.0  # pose x of the messages not counted


class Sites:
    """Both sites' sides of the test: a context per domain, one executor for both."""

    def __init__(self, operator_domain: int, remote_domain: int) -> None:
        self.contexts, self.nodes = [], []
        for name, domain in (('operator', operator_domain), ('remote', remote_domain)):
            context = Context()
            rclpy.init(context=context, domain_id=domain)
            self.contexts.append(context)
            self.nodes.append(Node(f'test_{name}_site', context=context))
        self.executor = EventsExecutor(context=self.contexts[0])
        for node in self.nodes:
            self.executor.add_node(node)
        self.received = {}  # (site, topic) -> [(x, delay [s])]

    def publisher(self, site: int, topic: str):
        """Return a function that publishes a pose with ``x`` stamped now on ``topic``."""
        publisher = self.nodes[site].create_publisher(PoseStamped, topic, HAPTIC_STREAM_QOS)
        message = PoseStamped()

        def publish(x: float) -> None:
            stamp = message.header.stamp
            stamp.sec, stamp.nanosec = divmod(time.time_ns(), 10**9)
            message.pose.position.x = x
            publisher.publish(message)
        return publish

    def listen(self, site: int, topic: str) -> list:
        """Record (x, delay) of every pose arriving on ``topic`` at ``site``; return the list."""
        received = self.received.setdefault((site, topic), [])

        def on_pose(message: PoseStamped) -> None:
            stamp = message.header.stamp.sec * 10**9 + message.header.stamp.nanosec
            received.append((message.pose.position.x, (time.time_ns() - stamp) * 1e-9))
        # A deep history, as the recorder's: a test process descheduled for a moment must not
        # drop what the relay delivered (a CI run lost 58 of 503 at the haptic depth of 10).
        self.nodes[site].create_subscription(PoseStamped, topic, on_pose, RECORDER_QOS)
        return received

    def spin(self, seconds: float) -> None:
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            self.executor.spin_until_future_complete(Future(), timeout_sec=0.01)

    def run(self, streams: list, count: int, period: float) -> None:
        """Publish ``count`` numbered poses ``period`` s apart on each (publish, every) stream.

        A stream publishes every ``every``-th tick; each stream counts from 0 on its own.
        """
        start = time.monotonic()
        for tick in range(count):
            for publish, every in streams:
                if tick % every == 0:
                    publish(float(tick // every))
            remaining = start + (tick + 1) * period - time.monotonic()
            self.executor.spin_until_future_complete(Future(), timeout_sec=max(remaining, 0.0))

    def close(self) -> None:
        for node in self.nodes:
            self.executor.remove_node(node)
        self.executor.shutdown(timeout_sec=1.0)
        for node in self.nodes:
            node.destroy_node()
        for context in self.contexts:
            rclpy.try_shutdown(context=context)


def connect(sites: Sites, streams: list) -> None:
    """Publish warm-up poses until each (publish, arrivals) stream's poses arrive."""
    deadline = time.monotonic() + CONNECT_TIMEOUT
    while not all(arrivals for _, arrivals in streams):
        assert time.monotonic() < deadline, 'nothing was relayed'
        for publish, _ in streams:
            publish(WARM_UP)
        sites.spin(0.02)
    sites.spin(0.3)  # the warm-up poses in flight land, then are forgotten
    for _, arrivals in streams:
        arrivals.clear()
