"""The operator's force-hold request over a scripted scan, sent from the operator's site.

Why: a bench and the tests ask the remote site to hold a force as an operator would, on
``teleop/hold`` in the operator's DDS domain, carried across by the gateways, at times of the
scan counted from its start (``scan_clock``), which a busy machine or a long link delays by
seconds after the launcher returns.
"""
import time

from rclpy.duration import Duration
from std_msgs.msg import Float64

from haptic_bringup.scan_clock import session_start, site_node
from haptic_contract.graph import TELEOP_HOLD

__all__ = ['hold_during']

LINGER = 2.0  # [s] that this node stays after its last request


def hold_during(domain_id: int, force: float, start: float, end: float | None,
                timeout: float) -> float | None:
    """Ask for ``force`` (N) from ``start`` s into the scan, released at ``end``.

    ``end`` None: never released. Returns when the scan began on the wall clock (as a bag's
    receive times), or None when it did not, or no gateway listened, within ``timeout`` s.
    """
    with site_node(domain_id, 'hold_request') as (node, executor):
        publisher = node.create_publisher(Float64, TELEOP_HOLD, 10)
        began = session_start(node, executor, timeout, also=publisher.get_subscription_count)
        if began is None:
            return None
        for at, value in ((start, force), (end, 0.0)):
            if at is not None:
                time.sleep(max(0.0, began.monotonic + at - time.monotonic()))
                publisher.publish(Float64(data=float(value)))
        # A grace for the reliable writer to repair a loss before it goes. Its answer cannot be
        # told: Fast DDS 2.14 here says False even when the reader has the message.
        publisher.wait_for_all_acked(Duration(seconds=LINGER))
        return began.wall
