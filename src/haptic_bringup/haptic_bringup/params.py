"""ROS parameters of the bring-up's own nodes (the recorders), and the topics they know."""
from dataclasses import dataclass

from haptic_util.parameters import parameter

__all__ = ['RecorderParams', 'TOPIC_TYPES', 'LOOP_TOPICS', 'STREAMS', 'LATCHED_TOPICS',
           'RELIABLE_TOPICS', 'FRAME_TOPICS', 'DIAGNOSTICS']

DIAGNOSTICS = '/diagnostics'
# The types of the topics a session records, so that a recorder subscribes at once instead of
# waiting to see them in the graph.
TOPIC_TYPES = {
    '/wand/pose': 'geometry_msgs/msg/PoseStamped',
    '/wand/twist': 'geometry_msgs/msg/TwistStamped',
    '/collision/state': 'haptic_msgs/msg/CollisionState',
    '/wand/wrench': 'geometry_msgs/msg/WrenchStamped',
    '/wand/contact_model': 'haptic_msgs/msg/ContactModel',
    '/wand/applied_wrench': 'geometry_msgs/msg/WrenchStamped',
    '/teleop/command': 'haptic_msgs/msg/TeleopCommand',
    '/teleop/feedback': 'haptic_msgs/msg/TeleopFeedback',
    '/robot/tcp_pose': 'geometry_msgs/msg/PoseStamped',
    '/robot/ft_sensor/wrench': 'geometry_msgs/msg/WrenchStamped',
    '/robot/target_pose': 'geometry_msgs/msg/PoseStamped',
    '/scene/description': 'std_msgs/msg/String',
    '/probe/image': 'sensor_msgs/msg/Image',
    DIAGNOSTICS: 'diagnostic_msgs/msg/DiagnosticArray',
}
LATCHED_TOPICS = ('/scene/description',)
# Images for people to look at, tens of hertz: taken over DDS as their viewers take them.
FRAME_TOPICS = ('/probe/image',)
RELIABLE_TOPICS = (DIAGNOSTICS,)  # a node's last report, with its final counts, must arrive
# The 1 kHz streams: passed between nodes as values (haptic_util.intra_process), so a recorder
# in their process takes them by that handover, never over DDS.
STREAMS = tuple(t for t in TOPIC_TYPES
                if t not in (*LATCHED_TOPICS, *RELIABLE_TOPICS, *FRAME_TOPICS))
# What a haptic session is: the loop's streams, the scene it ran against, and what each node
# said about itself (its last report carries its final counts).
LOOP_TOPICS = ('/wand/pose', '/wand/twist', '/collision/state', '/wand/wrench',
               '/wand/contact_model', '/wand/applied_wrench', '/scene/description', DIAGNOSTICS)


@dataclass(frozen=True)
class RecorderParams:
    output: str = parameter('bags/haptic_session', 'new bag directory to write')
    topics: tuple[str, ...] = parameter(LOOP_TOPICS, 'topics to record (others than the '
                                        'session\'s are typed from the graph)')
    prefix: str = parameter('', 'put before each topic\'s name in the bag (a site\'s, as '
                            '/remote)')
