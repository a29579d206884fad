"""The scan's time zero: when the wand's first pose came, heard from the operator's site.

Why: a scripted scan starts once the loop is closed and the recorder ready, which on a busy
machine comes seconds after the launcher returns; whatever acts on the scan at set times (a
force-hold request, a test's link stall) counts from its first pose, not from the launch.
"""
from contextlib import contextmanager
import time
from typing import Callable, Iterator, NamedTuple

from geometry_msgs.msg import PoseStamped
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node

from haptic_contract.graph import WAND_POSE
from haptic_util.qos import HAPTIC_STREAM_QOS

__all__ = ['FirstPose', 'first_pose', 'site_node', 'wait_for_first_pose']


class FirstPose(NamedTuple):
    """When the first pose came, on both clocks (wall as a bag's receive times)."""

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


def first_pose(node: Node, executor: SingleThreadedExecutor, timeout: float,
               also: Callable[[], bool] = lambda: True) -> FirstPose | None:
    """Spin until the wand's first pose came and ``also()`` holds, or None after ``timeout`` s."""
    came = []
    poses = node.create_subscription(
        PoseStamped, WAND_POSE,
        lambda _: came or came.append(FirstPose(time.monotonic(), time.time())),
        HAPTIC_STREAM_QOS)
    deadline = time.monotonic() + timeout
    while not (came and also()) and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.01)
    node.destroy_subscription(poses)
    return came[0] if came and also() else None


def wait_for_first_pose(domain_id: int, timeout: float) -> FirstPose | None:
    """Return the scan's time zero in the operator's domain, or None after ``timeout`` s."""
    with site_node(domain_id, 'scan_clock') as (node, executor):
        return first_pose(node, executor, timeout)
