"""ROS parameters of the bring-up's own nodes (the recorder)."""
from dataclasses import dataclass

from haptic_util.parameters import parameter

__all__ = ['RecorderParams', 'LOOP_TOPICS']

# What a haptic session is: the loop's streams, the scene it ran against, and what each node
# said about itself (its last report carries its final counts).
LOOP_TOPICS = ('/wand/pose', '/wand/twist', '/collision/state', '/wand/wrench',
               '/scene/description', '/diagnostics')
# The streams a session must not start before the recorder hears them.
STREAM_TOPICS = LOOP_TOPICS[:4]


@dataclass(frozen=True)
class RecorderParams:
    output: str = parameter('bags/haptic_session', 'new bag directory to write')
    topics: tuple[str, ...] = parameter(LOOP_TOPICS, 'topics to record')
