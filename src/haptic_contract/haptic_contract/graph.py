"""The toolkit's graph, written once: its topics, its nodes, and which process runs which.

The nodes name their topics from here (relative names, so that a namespace moves them all);
the launcher, the launch files, the composed process, the recorders and the session reader
read the same names, absolute (``absolute``), with their types, the node table and the layouts
of the loop and of the two telerobotic sites. Strings only: nothing here imports a node.
"""
from typing import NamedTuple

__all__ = ['COLLISION_MARKERS', 'COLLISION_NEARBY', 'COLLISION_STATE', 'DIAGNOSTICS',
           'EXECUTABLES', 'FRAME_TOPICS', 'GATEWAY', 'IMAGER', 'LATCHED_TOPICS', 'LOOP_RECORDER',
           'LOOP_TOPICS', 'NodeEntry', 'NODES', 'OPERATOR_RECORDED', 'OPERATOR_RECORDER',
           'OPERATOR_SITE', 'PROBE_IMAGE', 'PUBLISHERS', 'RECORDERS', 'RELIABLE_CROSSINGS',
           'RELIABLE_TOPICS', 'REMOTE_PREFIX', 'REMOTE_RECORDED', 'REMOTE_RECORDER', 'REMOTE_SITE',
           'ROBOT_FT_WRENCH', 'ROBOT_IMPEDANCE', 'ROBOT_TARGET_POSE', 'ROBOT_TCP_POSE',
           'SCENE_DESCRIPTION', 'SITE_PUBLISHERS', 'STREAMS', 'TELEOP_CLUTCH', 'TELEOP_COMMAND',
           'TELEOP_FEEDBACK', 'TELEOP_HOLD', 'TELEOP_NODES', 'TELEOP_RE_ENGAGE', 'TOPIC_TYPES',
           'TO_OPERATOR', 'TO_REMOTE', 'WAND_APPLIED_WRENCH', 'WAND_CONTACT_MODEL',
           'WAND_FORCE_MARKER', 'WAND_MODEL_SHIFT', 'WAND_POSE', 'WAND_SESSION_START',
           'WAND_TWIST', 'WAND_WRENCH', 'absolute']

# The loop: the wand's state out, the engine's answer, the renderer's wrench or model back.
WAND_POSE = 'wand/pose'
WAND_TWIST = 'wand/twist'
WAND_WRENCH = 'wand/wrench'
WAND_CONTACT_MODEL = 'wand/contact_model'
WAND_APPLIED_WRENCH = 'wand/applied_wrench'  # what the device applied over each tick
WAND_MODEL_SHIFT = 'wand/model_shift'  # how far out the device renders the model's planes
WAND_FORCE_MARKER = 'wand/force_marker'
WAND_SESSION_START = 'wand/session_start'  # when the session began: the experiment's time zero
COLLISION_STATE = 'collision/state'
COLLISION_NEARBY = 'collision/nearby'
COLLISION_MARKERS = 'collision/markers'
SCENE_DESCRIPTION = 'scene/description'
# A telerobotic session: the link between the sites, and the robot at the remote one.
TELEOP_COMMAND = 'teleop/command'
TELEOP_FEEDBACK = 'teleop/feedback'
TELEOP_CLUTCH = 'teleop/clutch'
TELEOP_HOLD = 'teleop/hold'  # the force the remote site is to hold (N; <= 0 releases)
TELEOP_RE_ENGAGE = 'teleop/re_engage'  # the operator's deliberate re-engage after a hard stop
ROBOT_TARGET_POSE = 'robot/target_pose'
ROBOT_TCP_POSE = 'robot/tcp_pose'
ROBOT_FT_WRENCH = 'robot/ft_sensor/wrench'
ROBOT_IMPEDANCE = 'robot/impedance'
PROBE_IMAGE = 'probe/image'  # the ultrasound image, made at the remote site
DIAGNOSTICS = '/diagnostics'


def absolute(topic: str) -> str:
    """Return ``topic`` as the graph and the bags name it, from the root."""
    return topic if topic.startswith('/') else f'/{topic}'


# The types of the topics a session records, so that a recorder subscribes at once instead of
# waiting to see them in the graph.
TOPIC_TYPES = {
    absolute(WAND_POSE): 'geometry_msgs/msg/PoseStamped',
    absolute(WAND_TWIST): 'geometry_msgs/msg/TwistStamped',
    absolute(COLLISION_STATE): 'haptic_msgs/msg/CollisionState',
    absolute(WAND_WRENCH): 'geometry_msgs/msg/WrenchStamped',
    absolute(WAND_CONTACT_MODEL): 'haptic_msgs/msg/ContactModel',
    absolute(WAND_APPLIED_WRENCH): 'geometry_msgs/msg/WrenchStamped',
    absolute(WAND_MODEL_SHIFT): 'geometry_msgs/msg/Vector3Stamped',
    absolute(TELEOP_COMMAND): 'haptic_msgs/msg/TeleopCommand',
    absolute(TELEOP_FEEDBACK): 'haptic_msgs/msg/TeleopFeedback',
    absolute(ROBOT_TCP_POSE): 'geometry_msgs/msg/PoseStamped',
    absolute(ROBOT_FT_WRENCH): 'geometry_msgs/msg/WrenchStamped',
    absolute(ROBOT_TARGET_POSE): 'geometry_msgs/msg/PoseStamped',
    absolute(SCENE_DESCRIPTION): 'std_msgs/msg/String',
    absolute(WAND_SESSION_START): 'std_msgs/msg/Header',
    absolute(PROBE_IMAGE): 'sensor_msgs/msg/Image',
    DIAGNOSTICS: 'diagnostic_msgs/msg/DiagnosticArray',
}
LATCHED_TOPICS = (absolute(SCENE_DESCRIPTION), absolute(WAND_SESSION_START))
RELIABLE_TOPICS = (DIAGNOSTICS,)  # a node's last report, with its final counts, must arrive
# Images for people to look at, tens of hertz: taken over DDS as their viewers take them; across
# the link, after the streams, and dropped when it is congested.
FRAME_TOPICS = (absolute(PROBE_IMAGE),)
# The 1 kHz streams: passed between nodes as values (haptic_util.intra_process), so a recorder
# in their process takes them by that handover, never over DDS.
STREAMS = tuple(t for t in TOPIC_TYPES
                if t not in (*LATCHED_TOPICS, *RELIABLE_TOPICS, *FRAME_TOPICS))
# What a haptic session is: the loop's streams, the scene it ran against, and what each node
# said about itself (its last report carries its final counts).
LOOP_TOPICS = tuple(absolute(topic) for topic in (
    WAND_POSE, WAND_TWIST, COLLISION_STATE, WAND_WRENCH, WAND_CONTACT_MODEL,
    WAND_APPLIED_WRENCH, SCENE_DESCRIPTION, WAND_SESSION_START, DIAGNOSTICS))


class NodeEntry(NamedTuple):
    """A node: its package, and its module (with ``main``) and class there."""

    package: str
    module: str
    cls: str


# By node name: the loop's, and a telerobotic session's.
NODES = {
    'wand_driver': NodeEntry('haptic_wand_driver', 'haptic_wand_driver.node', 'WandDriverNode'),
    'collision_engine': NodeEntry('collision_engine', 'collision_engine.node', 'CollisionNode'),
    'force_renderer': NodeEntry('force_renderer', 'force_renderer.node', 'ForceNode'),
}
TELEOP_NODES = {
    'teleop_leader': NodeEntry('teleop_leader', 'teleop_leader.leader_node', 'LeaderNode'),
    'sim_robot': NodeEntry('robot_site', 'robot_site.robot_node', 'SimulatedRobotNode'),
    'teleop_follower': NodeEntry('robot_site', 'robot_site.follower_node', 'FollowerNode'),
    'probe_imager': NodeEntry('ultrasound_sim', 'ultrasound_sim.node', 'ProbeImagerNode'),
    'site_gateway': NodeEntry('site_gateway', 'site_gateway.gateway', 'GatewayNode'),
}
# Each node's executable in its package (``ros2 run``, the launch files), by node name.
EXECUTABLES = {'wand_driver': 'wand_driver', 'collision_engine': 'collision_node',
               'force_renderer': 'force_node', 'teleop_leader': 'teleop_leader',
               'sim_robot': 'sim_robot', 'teleop_follower': 'teleop_follower',
               'probe_imager': 'probe_imager', 'site_gateway': 'site_gateway'}
# Each telerobotic site is one process. The remote site's ultrasound scanner, when the session
# images, is a process of its own beside it: in the robot's, its frames held the robot's 1 kHz
# loop back for the GIL.
OPERATOR_SITE = ('wand_driver', 'teleop_leader')
REMOTE_SITE = ('sim_robot', 'teleop_follower')
IMAGER = 'probe_imager'
# Each site's gateway to the other: in its site's process, under its role's name
# (``<role>_gateway``); or, the baseline, a process of its own.
GATEWAY = 'site_gateway'
# The recorder in each kind of process (haptic_bringup.process_recorder), by its node name.
RECORDERS = LOOP_RECORDER, OPERATOR_RECORDER, REMOTE_RECORDER = (
    'recorder', 'operator_recorder', 'remote_recorder')
REMOTE_PREFIX = '/remote'  # where the remote site's topics go in its bag
# What crosses between the sites, each way ('topic:type').
TO_REMOTE = (f'{absolute(TELEOP_COMMAND)}:haptic_msgs/msg/TeleopCommand',
             f'{absolute(TELEOP_HOLD)}:std_msgs/msg/Float64',
             f'{absolute(TELEOP_RE_ENGAGE)}:std_msgs/msg/Empty')
TO_OPERATOR = (f'{absolute(TELEOP_FEEDBACK)}:haptic_msgs/msg/TeleopFeedback',
               f'{absolute(PROBE_IMAGE)}:sensor_msgs/msg/Image')
# The operator's requests, rare and each one meant: they must arrive (reliable, in order).
RELIABLE_CROSSINGS = (absolute(TELEOP_HOLD), absolute(TELEOP_RE_ENGAGE))
# A session's bag holds what each site measured and what crossed the link, recorded where it
# arrives (its sent copy is the same message, earlier; a hold's error counts from its arrival).
# Left out, each one step from those and read by no analysis: the wand's twist (the pose's
# rate), the leader's answer to its driver (the feedback through the leader) and the robot's
# target (the command through the patient-safety filter). Each 1 kHz stream recorded costs its
# writer and the recorder about 5 % of a core (docs/cpu_budget.md), on two cores that hold both
# sites. The probe's image is recorded where the operator sees it, once: its stamp is the
# pose's, so the bag gives pose to image there.
OPERATOR_RECORDED = tuple(absolute(topic) for topic in (
    WAND_POSE, WAND_APPLIED_WRENCH, TELEOP_FEEDBACK, WAND_SESSION_START, DIAGNOSTICS))
REMOTE_RECORDED = tuple(absolute(topic) for topic in (
    ROBOT_TCP_POSE, ROBOT_FT_WRENCH, TELEOP_COMMAND, TELEOP_HOLD, TELEOP_RE_ENGAGE, DIAGNOSTICS))
# Which node publishes each stream, by its name in /diagnostics reports (a node publishes each
# of its streams once per count): the loop's, and a telerobotic site's own measurements.
PUBLISHERS = {absolute(WAND_POSE): 'wand_driver', absolute(WAND_TWIST): 'wand_driver',
              absolute(WAND_APPLIED_WRENCH): 'wand_driver',
              absolute(COLLISION_STATE): 'collision_engine',
              absolute(WAND_WRENCH): 'force_renderer',
              absolute(WAND_CONTACT_MODEL): 'force_renderer'}
SITE_PUBLISHERS = {absolute(WAND_POSE): 'wand_driver',
                   absolute(WAND_APPLIED_WRENCH): 'wand_driver',
                   REMOTE_PREFIX + absolute(ROBOT_TCP_POSE): 'sim_robot',
                   REMOTE_PREFIX + absolute(ROBOT_FT_WRENCH): 'sim_robot'}
