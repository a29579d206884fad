"""Wait for the loop's endpoints to be discovered, instead of sleeping a guessed time.

Discovery takes 0.4–1.8 s here and varies; a launcher that sleeps either wastes time or starts
measuring a loop that is not closed yet. This watches the ROS graph from a private context, so
it can run inside a process that has its own rclpy nodes (a test, a benchmark).
"""
import time
from typing import Callable, Mapping, Optional

import rclpy
from rclpy.context import Context
from rclpy.node import Node

__all__ = ['GraphWatcher']


class GraphWatcher:
    """A node in a private context that reads the ROS graph."""

    def __init__(self, domain_id: int) -> None:
        self._context = Context()
        rclpy.init(context=self._context, domain_id=domain_id)
        self._node = Node('haptic_launcher_graph', context=self._context,
                          start_parameter_services=False, enable_rosout=False)

    def counts(self, topic: str) -> tuple:
        """Return how many publishers and subscribers of ``topic`` are discovered."""
        return self._node.count_publishers(topic), self._node.count_subscribers(topic)

    def missing(self, endpoints: Mapping[str, tuple]) -> list:
        """Descriptions of the endpoints not discovered yet."""
        missing = []
        for topic, (publishers, subscribers) in endpoints.items():
            have_pub, have_sub = self.counts(topic)
            if have_pub < publishers:
                missing.append(f'{topic}: {have_pub}/{publishers} publisher(s)')
            if have_sub < subscribers:
                missing.append(f'{topic}: {have_sub}/{subscribers} subscriber(s)')
        return missing

    def wait(self, endpoints: Mapping[str, tuple], timeout: float, *,
             abort: Optional[Callable[[], bool]] = None, poll: float = 0.02) -> list:
        """Wait until every endpoint is discovered; return what is still missing at the end.

        ``abort()`` returning True (e.g. a child process died) ends the wait early.
        """
        deadline = time.monotonic() + timeout
        missing = self.missing(endpoints)
        while missing and time.monotonic() < deadline:
            if abort is not None and abort():
                break
            time.sleep(poll)
            missing = self.missing(endpoints)
        return missing

    def close(self) -> None:
        self._node.destroy_node()
        rclpy.try_shutdown(context=self._context)
