"""The scan's time zero: when the wand's session began, heard from the operator's site.

Why: a scripted scan starts once the loop is closed and the recorder ready, which on a busy
machine comes seconds after the launcher returns, and in a telerobotic session a round trip
and more after the wand's first pose (the loop is probed at rest until the remote site answers:
1.5 to 2.5 s at 250 ms one way). Whatever acts on the scan at set times (a force-hold request, a
test's link stall) counts from the driver's ``wand/session_start``, the instant its script's
clock started. It is latched, and carries that instant: heard late, it still gives it.
"""
from contextlib import contextmanager
import time
from typing import Callable, Iterator, NamedTuple

import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Header

from haptic_contract.graph import WAND_SESSION_START
from haptic_util.qos import LATCHED_QOS

__all__ = ['SessionStart', 'session_start', 'site_node', 'wait_for_session_start']


class SessionStart(NamedTuple):
    """When the session began, on both clocks (wall as a bag's receive times)."""

    monotonic: float
    wall: float


@contextmanager
def site_node(domain_id: int, name: str) -> Iterator[tuple[Node, SingleThreadedExecutor]]:
    """Open a node of its own context in a site's DDS domain; shut it down on leaving."""
    context = Context()
    rclpy.init(context=context, domain_id=domain_id)
    try:
        node = Node(name, context=context)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        yield node, executor
        node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)


def session_start(node: Node, executor: SingleThreadedExecutor, timeout: float,
                  also: Callable[[], bool] = lambda: True) -> SessionStart | None:
    """Spin until the session began and ``also()`` holds, or None after ``timeout`` s."""
    began = []

    def heard(header: Header) -> None:
        wall = header.stamp.sec + header.stamp.nanosec * 1e-9
        began[:] = [SessionStart(time.monotonic() - (time.time() - wall), wall)]
    starts = node.create_subscription(Header, WAND_SESSION_START, heard, LATCHED_QOS)
    deadline = time.monotonic() + timeout
    while not (began and also()) and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.01)
    node.destroy_subscription(starts)
    return began[0] if began and also() else None


def wait_for_session_start(domain_id: int, timeout: float) -> SessionStart | None:
    """Return the scan's time zero in the operator's domain, or None after ``timeout`` s."""
    with site_node(domain_id, 'scan_clock') as (node, executor):
        return session_start(node, executor, timeout)
