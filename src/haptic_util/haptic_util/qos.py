"""The QoS profiles every haptic node must agree on.

The 1 kHz streams (pose, twist, collision state, wrench) are sensor data: best effort, keep last
(a retransmitted pose is already stale, and a reliable queue under load only adds latency). The
depth of 10 lets a subscriber that was descheduled for a few milliseconds catch up and still
answer every pose instead of dropping samples. Latched descriptions (the scene) are reliable and
transient-local, so that a late subscriber, such as a recorder or RViz, still receives them.
"""
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

__all__ = ['FRAME_QOS', 'HAPTIC_STREAM_QOS', 'LATCHED_QOS', 'LINK_QOS', 'NEWEST_STREAM_QOS',
           'RECORDER_QOS', 'RELIABLE_RECORDER_QOS', 'MARKER_QOS']

STREAM_DEPTH = 10

HAPTIC_STREAM_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=STREAM_DEPTH,
    reliability=ReliabilityPolicy.BEST_EFFORT,
    durability=DurabilityPolicy.VOLATILE,
)

# What comes from another site: the same policy, a history deep enough that a flood from any
# publisher on the topic does not push the followed session's messages out before the node has
# refused the flood's (it sheds them by content, at a few microseconds each): 100 is 5 ms of a
# 20 kHz flood, and 100 ms of the link's own 1 kHz. Not deeper: a gateway reading the commands
# 1000 deep stopped taking them a few seconds into an attacked session (cause not found).
# A reader of a stream that wants its newest message only (the imager's pose, 30 times a
# second): one kept, so that a reader that was descheduled wakes to it, not to a backlog.
NEWEST_STREAM_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=1,
    reliability=ReliabilityPolicy.BEST_EFFORT,
    durability=DurabilityPolicy.VOLATILE,
)

LINK_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=100,
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

# For what is published reliably (reports): a best-effort reader may lose a node's last report
# and never be told; a reliable one acknowledges it before the node goes.
RELIABLE_RECORDER_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=RECORDER_QOS.depth,
    reliability=ReliabilityPolicy.RELIABLE,
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

# Frames for people to look at (an ultrasound image): reliable, so that every viewer matches
# (RViz's Image display subscribes reliably by default, rqt_image_view best effort), keep last
# 2: a slow viewer gets the newest, and a publisher never waits for one.
FRAME_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=2,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
)
