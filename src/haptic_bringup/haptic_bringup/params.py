"""ROS parameters of the bring-up's own nodes (the recorder)."""
from dataclasses import dataclass

from haptic_util.parameters import parameter

__all__ = ['RecorderParams', 'LOOP_TOPICS', 'LATCHED_TOPICS', 'RELIABLE_TOPICS']

# What a haptic session is: the loop's streams, the scene it ran against, and what each node
# said about itself (its last report carries its final counts), with their types, so that the
# recorder subscribes at once instead of waiting to see them in the graph.
LOOP_TOPICS = {
    '/wand/pose': 'geometry_msgs/msg/PoseStamped',
    '/wand/twist': 'geometry_msgs/msg/TwistStamped',
    '/collision/state': 'haptic_msgs/msg/CollisionState',
    '/wand/wrench': 'geometry_msgs/msg/WrenchStamped',
    '/wand/contact_model': 'haptic_msgs/msg/ContactModel',
    '/wand/applied_wrench': 'geometry_msgs/msg/WrenchStamped',
    '/scene/description': 'std_msgs/msg/String',
    '/diagnostics': 'diagnostic_msgs/msg/DiagnosticArray',
}
LATCHED_TOPICS = ('/scene/description',)
RELIABLE_TOPICS = ('/diagnostics',)  # a node's last report, with its final counts, must arrive


@dataclass(frozen=True)
class RecorderParams:
    output: str = parameter('bags/haptic_session', 'new bag directory to write')
    topics: tuple[str, ...] = parameter(tuple(LOOP_TOPICS), 'topics to record (others than '
                                        'the loop\'s are typed from the graph)')
    remote_domain: int = parameter(-1, 'the remote site\'s DDS domain, recorded too (-1: none)',
                                   low=-1, high=232)
    remote_topics: tuple[str, ...] = parameter(('/diagnostics',), 'its topics to record, as '
                                               '/remote/<topic> in the bag')
