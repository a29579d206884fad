"""The QoS profiles every haptic node must agree on.

The 1 kHz streams (pose, twist, collision state, wrench) are sensor data: the newest sample is the
only one worth having, so they are best effort with a short keep-last history (a retransmitted
pose is already stale). The depth of 5 lets a subscriber catch up after a scheduling hiccup
instead of dropping a sample. Latched descriptions (the scene) are reliable and transient-local so
that a late subscriber, such as a recorder or RViz, still receives them.
"""
from rclpy.qos import (DurabilityPolicy, HistoryPolicy, qos_profile_sensor_data, QoSProfile,
                       ReliabilityPolicy)

__all__ = ['HAPTIC_STREAM_QOS', 'LATCHED_QOS', 'RECORDER_QOS', 'MARKER_QOS']

HAPTIC_STREAM_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=qos_profile_sensor_data.depth,
    reliability=ReliabilityPolicy.BEST_EFFORT,
    durability=DurabilityPolicy.VOLATILE,
)

# A recorder must not lose samples while it writes: same policy, a deep history.
RECORDER_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=2000,
    reliability=ReliabilityPolicy.BEST_EFFORT,
    durability=DurabilityPolicy.VOLATILE,
)

LATCHED_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=1,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
)

MARKER_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=1,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
)
