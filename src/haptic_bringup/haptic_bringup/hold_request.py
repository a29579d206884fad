"""The operator's force-hold request over a scripted scan, sent from the operator's site.

Why: a bench and the tests ask the remote site to hold a force as an operator would, on
``teleop/hold`` in the operator's DDS domain, carried across by the gateways, at times of the
scan counted from the wand's first pose (the scan's time zero, which a busy machine delays by
seconds after the launcher returns). Start it before the sites: a subscription that joins once
the wand is running hears its first pose late, and asks late (the release of a hold at 0 and
250 ms came after the scan had ended, at load 12).
"""
import time

from geometry_msgs.msg import PoseStamped
import rclpy
from rclpy.context import Context
from rclpy.duration import Duration
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Float64

from haptic_contract.graph import TELEOP_HOLD, WAND_POSE
from haptic_util.qos import HAPTIC_STREAM_QOS

__all__ = ['hold_during']

ACKED_WITHIN = 2.0  # [s] for the gateway to acknowledge the last request before this node goes


def hold_during(domain_id: int, force: float, start: float, end: float | None,
                timeout: float) -> float | None:
    """Ask for ``force`` (N) from ``start`` s after the wand's first pose, released at ``end``.

    ``end`` None: never released. Returns when the first pose came on the wall clock (as a
    bag's receive times), or None when no pose came, or no gateway took the request, within
    ``timeout`` s.
    """
    context = Context()
    rclpy.init(context=context, domain_id=domain_id)
    try:
        node = Node('hold_request', context=context)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        publisher = node.create_publisher(Float64, TELEOP_HOLD, 10)
        came = []  # (monotonic, wall) clocks
        poses = node.create_subscription(
            PoseStamped, WAND_POSE,
            lambda _: came or came.append((time.monotonic(), time.time())), HAPTIC_STREAM_QOS)
        deadline = time.monotonic() + timeout
        while not (came and publisher.get_subscription_count()) and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.01)
        if not (came and publisher.get_subscription_count()):
            return None
        node.destroy_subscription(poses)
        for at, value in ((start, force), (end, 0.0)):
            if at is not None:
                time.sleep(max(0.0, came[0][0] + at - time.monotonic()))
                publisher.publish(Float64(data=float(value)))
        publisher.wait_for_all_acked(Duration(seconds=ACKED_WITHIN))  # the gateway has it
        node.destroy_node()
        return came[0][1]
    finally:
        rclpy.try_shutdown(context=context)
