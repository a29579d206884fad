"""The QoS profiles every haptic node must agree on.

The 1 kHz streams (pose, twist, collision state, wrench) are sensor data: best effort, keep last
(a retransmitted pose is already stale, and a reliable queue under load only adds latency). The
depth of 10 lets a subscriber that was descheduled for a few milliseconds catch up and still
answer every pose instead of dropping samples. Latched descriptions (the scene) are reliable and
transient-local, so that a late subscriber, such as a recorder or RViz, still receives them.
"""
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

__all__ = ['FRAME_QOS', 'HAPTIC_STREAM_QOS', 'LATCHED_QOS', 'LINK_INTAKE_RATE', 'LINK_QOS',
           'NEWEST_STREAM_QOS',
           'RECORDER_QOS', 'RELIABLE_RECORDER_QOS', 'MARKER_QOS']

STREAM_DEPTH = 10


def _best_effort(depth: int) -> QoSProfile:
    """Return the streams' policy: best effort, volatile, the last ``depth`` messages kept."""
    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=depth,
                      reliability=ReliabilityPolicy.BEST_EFFORT,
                      durability=DurabilityPolicy.VOLATILE)


def _reliable(depth: int, durability: DurabilityPolicy = DurabilityPolicy.VOLATILE) -> QoSProfile:
    """Return the policy of what must arrive: reliable, the last ``depth`` messages kept."""
    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=depth,
                      reliability=ReliabilityPolicy.RELIABLE, durability=durability)


HAPTIC_STREAM_QOS = _best_effort(STREAM_DEPTH)

# A reader of a stream that wants its newest message only (the imager's pose, 30 times a
# second): one kept, so that a reader that was descheduled wakes to it, not to a backlog.
NEWEST_STREAM_QOS = _best_effort(1)

# What comes from another site: the same policy, a history deep enough that a flood from any
# publisher on the topic does not push the followed session's messages out before the node has
# refused the flood's (it sheds them by content, at a few microseconds each): 100 is 5 ms of a
# 20 kHz flood, and 100 ms of the link's own 1 kHz. Not deeper: a gateway reading the commands
# 1000 deep stopped taking them a few seconds into an attacked session (cause not found).
LINK_QOS = _best_effort(100)
# [Hz] what the robot's site takes of the commands at most, from every publisher together: 4 x
# their 1 kHz, so that a burst from a jittered link is taken within a few ticks, while a
# flood is shed by the reader's history, in DDS (haptic_util.polled_reader).
LINK_INTAKE_RATE = 4000.0

# A recorder must not lose samples while it writes: same policy, a deep history.
RECORDER_QOS = _best_effort(2000)

# For what is published reliably (reports): a best-effort reader may lose a node's last report
# and never be told; a reliable one acknowledges it before the node goes.
RELIABLE_RECORDER_QOS = _reliable(RECORDER_QOS.depth)

LATCHED_QOS = _reliable(1, DurabilityPolicy.TRANSIENT_LOCAL)

MARKER_QOS = _reliable(1)

# Frames for people to look at (an ultrasound image): reliable, so that every viewer matches
# (RViz's Image display subscribes reliably by default, rqt_image_view best effort), keep last
# 2: a slow viewer gets the newest, and a publisher never waits for one.
FRAME_QOS = _reliable(2)
