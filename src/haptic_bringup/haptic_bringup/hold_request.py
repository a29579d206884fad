"""The operator's force-hold request over a scripted scan, sent from the operator's site.

Why: a bench and the tests ask the remote site to hold a force as an operator would, on
``teleop/hold`` in the operator's DDS domain, carried across by the gateways, at times of the
scan counted from the wand's first pose (the scan's time zero, which a busy machine delays by
seconds after the launcher returns). Start it before the sites: a subscription that joins once
the wand is running hears its first pose late, and asks late (the release of a hold at 0 and
250 ms came after the scan had ended, at load 12).
"""
import time

from rclpy.duration import Duration
from std_msgs.msg import Float64

from haptic_bringup.scan_clock import first_pose, site_node
from haptic_contract.graph import TELEOP_HOLD

__all__ = ['hold_during']

ACKED_WITHIN = 2.0  # [s] for the gateway to acknowledge the last request before this node goes


def hold_during(domain_id: int, force: float, start: float, end: float | None,
                timeout: float) -> float | None:
    """Ask for ``force`` (N) from ``start`` s after the wand's first pose, released at ``end``.

    ``end`` None: never released. Returns when the first pose came on the wall clock (as a
    bag's receive times), or None when no pose came, or no gateway took the request, within
    ``timeout`` s.
    """
    with site_node(domain_id, 'hold_request') as (node, executor):
        publisher = node.create_publisher(Float64, TELEOP_HOLD, 10)
        came = first_pose(node, executor, timeout, also=publisher.get_subscription_count)
        if came is None:
            return None
        for at, value in ((start, force), (end, 0.0)):
            if at is not None:
                time.sleep(max(0.0, came.monotonic + at - time.monotonic()))
                publisher.publish(Float64(data=float(value)))
        acked = publisher.wait_for_all_acked(Duration(seconds=ACKED_WITHIN))  # the gateway has it
        return came.wall if acked else None
