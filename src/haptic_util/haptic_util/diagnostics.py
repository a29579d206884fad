"""A node's health and counts on ``/diagnostics``, periodically and once more when it stops.

The last report of a node that stops cleanly carries its final counts (messages published,
inputs refused), so a recorded session documents its own completeness: a reader compares what each
node says it published with what the bag holds. A recorder in the node's own process
(``listen``) is handed each report as it is published, the last one too: that one is written as
the node is destroyed, when its process no longer takes anything over DDS. Every report also
says how many callbacks of its process raised (``callback_errors``): a bad input must be
refused, never raise.
"""
from typing import Callable

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rclpy.duration import Duration
from rclpy.node import Node

from haptic_util.callback_errors import callback_errors

__all__ = ['Diagnostics', 'Report', 'listen', 'stop_listening', 'OK', 'WARN', 'ERROR']

OK, WARN, ERROR = DiagnosticStatus.OK, DiagnosticStatus.WARN, DiagnosticStatus.ERROR
DIAGNOSTICS_TOPIC = '/diagnostics'
DIAGNOSTICS_DEPTH = 10
FINAL_ACK_TIMEOUT = 0.5  # [s] the longest the last report waits for its readers' receipts
_listeners: list = []  # callables handed every report this process publishes


def listen(callback: Callable[[DiagnosticArray], None]) -> None:
    """Hand ``callback`` every report of this process's nodes, before it goes out over DDS."""
    _listeners.append(callback)


def stop_listening(callback: Callable[[DiagnosticArray], None]) -> None:
    _listeners.remove(callback)


class Report:
    """What a node says about itself: a level, a one-line message, and named values."""

    def __init__(self, level: bytes, message: str, values: dict) -> None:
        self.level, self.message, self.values = level, message, values


class Diagnostics:
    """Publish ``report()`` every ``period`` seconds, and once more on ``final()``."""

    def __init__(self, node: Node, report: Callable[[], Report], period: float) -> None:
        self._node = node
        self._report = report
        self._publisher = node.create_publisher(DiagnosticArray, DIAGNOSTICS_TOPIC,
                                                DIAGNOSTICS_DEPTH)
        self._timer = node.create_timer(period, self.publish)

    def publish(self) -> None:
        report = self._report()
        status = DiagnosticStatus(
            level=report.level, name=self._node.get_fully_qualified_name(),
            message=report.message, hardware_id=self._node.get_name(),
            values=[KeyValue(key=key, value=str(value)) for key, value in
                    {**report.values, 'callback_errors': callback_errors()}.items()])
        array = DiagnosticArray(status=[status])
        array.header.stamp = self._node.get_clock().now().to_msg()
        for listener in _listeners:
            listener(array)
        self._publisher.publish(array)

    def final(self) -> None:
        """Publish the last report (call from ``destroy_node``, before the node goes).

        It waits, a moment at most, for every reader to acknowledge the report: the node is
        destroyed next, and a report still queued in its writer then never leaves (a recorder
        process missed the last reports of two nodes of three in 3 of 4 loaded runs).
        """
        self._timer.cancel()
        self.publish()
        self._publisher.wait_for_all_acked(Duration(seconds=FINAL_ACK_TIMEOUT))
