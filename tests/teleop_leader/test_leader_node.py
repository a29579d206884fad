"""The leader node answers each wand pose once, when its twist (same stamp) is in, in either order.

Within one process the driver's twist reaches the leader before its pose (``intra_process``
delivers in publishing order); over DDS the two may arrive either way round. No pose is answered
before the robot is found, so the driver's probe of the loop waits for it.
"""
import dataclasses
import time

from domains import session_domain_id
import numpy as np
import pytest
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node

from haptic_contract.graph import TELEOP_FEEDBACK
from haptic_contract.teleop import Feedback
from haptic_contract.teleop_fields import FEEDBACK, feedback_fields
from haptic_util.diagnostics import WARN
from haptic_util.qos import LINK_QOS
from teleop_leader.leader_node import LeaderNode

STAMP = (100, 500)
WAND = (0.01, 0.02, 0.03)  # [m] the pose's position
TCP = np.array([0.3, -0.1, 0.2])  # [m] the robot's, in its first feedback
PROBE = (99, 0)  # the stamp of the driver's probe before the robot is found
MATCH_TIMEOUT = 10.0  # [s]


def pose(stamp=STAMP, frame='world'):
    return (*stamp, frame, *WAND, 0.0, 0.0, 0.0, 1.0)


def twist(stamp=STAMP):
    return (*stamp, 'world', 0.1, 0.0, 0.0, 0.0, 0.0, 0.0)


class Sent:
    """Stands in for a stream publisher: keeps what is published."""

    def __init__(self):
        self.messages = []

    def publish(self, values):
        self.messages.append(values)


def robot_found(node):
    """Probe ``node`` with the wand at ``WAND``, then give it the first feedback: the robot at
    ``TCP``, touching nothing."""
    node.on_twist(twist(PROBE))
    node.on_pose(pose(PROBE))
    node.on_feedback(feedback_fields(Feedback(node._now(), 0.0, 0.0, np.zeros(3), TCP, 0.0, None,
                                              session=7, sequence=1), 'base_link'))


@pytest.fixture(params=['tdpa'])
def leader(request):
    context = Context()
    rclpy.init(context=context, domain_id=97)
    node = LeaderNode(context=context, parameter_overrides=[
        rclpy.parameter.Parameter('scheme', value=request.param)])
    node._answer_pub = Sent()
    node._command_pub = Sent()
    yield node
    node.destroy_node()
    rclpy.try_shutdown(context=context)


def test_the_feedback_s_reader_leaves_the_graph_with_the_leader():
    """It reads on a node of its own, which must not outlive the leader, still matched."""
    context = Context()
    rclpy.init(context=context, domain_id=session_domain_id())  # none else sees it
    try:
        probe = Node('probe', context=context)
        LeaderNode(context=context).destroy_node()
        assert probe.get_node_names() == ['probe']
    finally:
        rclpy.try_shutdown(context=context)


@pytest.mark.parametrize('order', ['pose first', 'twist first'])
def test_a_pose_is_answered_once_its_twist_is_in_whichever_comes_first(leader, order):
    robot_found(leader)
    if order == 'pose first':
        leader.on_pose(pose())
        assert leader._answer_pub.messages == []  # waits for the twist
        leader.on_twist(twist())
    else:
        leader.on_twist(twist())
        assert leader._answer_pub.messages == []  # waits for the pose
        leader.on_pose(pose())
    [answer] = leader._answer_pub.messages
    assert answer[:3] == (*STAMP, 'world')
    assert len(answer) == 9 and np.all(np.isfinite(answer[3:]))  # the coupling's wrench
    leader.on_twist(twist())  # the same twist again answers nothing more
    assert len(leader._answer_pub.messages) == 1


def test_a_twist_of_another_stamp_answers_nothing(leader):
    robot_found(leader)
    leader.on_twist(twist((100, 400)))
    leader.on_pose(pose())
    assert leader._answer_pub.messages == []
    leader.on_twist(twist())
    assert len(leader._answer_pub.messages) == 1


def test_no_pose_is_answered_before_the_robot_is_found_and_the_session_anchors_the_wand_there(
        leader):
    leader.on_twist(twist(PROBE))
    leader.on_pose(pose(PROBE))  # the driver's probe, the wand at rest
    assert leader._answer_pub.messages == [] and leader._command_pub.messages == []
    robot_found(leader)
    leader.on_twist(twist())
    leader.on_pose(pose())  # the same place: the robot's target is where the robot is
    [answer] = leader._answer_pub.messages
    assert answer[:3] == (*STAMP, 'world')
    [command] = leader._command_pub.messages
    assert np.allclose(command[5:8], TCP)


@pytest.mark.parametrize('leader', ['model'], indirect=True)
def test_the_robot_s_target_moves_out_as_far_as_the_device_renders_the_planes(leader):
    """The device's shift of the planes it renders (``wand/model_shift``) is the robot's too; one
    not finite or in another frame is refused and counted, and the last good one kept."""
    robot_found(leader)
    leader.on_model_shift((*STAMP, 'world', 0.0, 0.0, 0.012))
    leader.on_model_shift((*STAMP, 'world', 0.0, 0.0, float('nan')))
    leader.on_model_shift((*STAMP, 'base_link', 0.0, 0.0, 0.5))
    leader.on_twist(twist())
    leader.on_pose(pose())
    [command] = leader._command_pub.messages
    assert np.allclose(command[5:8], TCP + [0.0, 0.0, 0.012])
    assert leader._refused.total() == 2


def test_the_feedback_is_taken_at_a_wand_pose_and_never_by_itself(leader):
    """The robot's feedback, over DDS here, waits in the reader until the next pose (in a site's
    process, the gateway's handover waits so: ``tests/site_gateway/test_handover.py``)."""
    site = Node('robot_site', context=leader.context)
    feedback = site.create_publisher(FEEDBACK.message_class, TELEOP_FEEDBACK, LINK_QOS)
    executor = SingleThreadedExecutor(context=leader.context)
    for node in (leader, site):
        executor.add_node(node)
    deadline = time.monotonic() + MATCH_TIMEOUT
    while feedback.get_subscription_count() == 0 and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.01)
    assert feedback.get_subscription_count() >= 1  # the leader's own, in this participant
    leader.on_twist(twist(PROBE))
    leader.on_pose(pose(PROBE))  # the wand is known: the first feedback starts the session
    feedback.publish(FEEDBACK.encode(feedback_fields(
        Feedback(leader._now(), 0.0, 0.0, np.zeros(3), TCP, 0.0, None, session=7, sequence=1),
        'base_link')))
    deadline = time.monotonic() + 0.5
    while time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.01)
    assert leader.leader is None  # spun, not taken
    leader.on_twist(twist())
    leader.on_pose(pose())
    assert leader.leader is not None and np.allclose(leader.leader.map.to_robot(WAND), TCP)
    executor.shutdown()
    site.destroy_node()


def test_the_report_names_the_wand_when_it_is_the_wand_that_is_silent(leader):
    """With the wand silent the feedback is not read, so the link looks silent too: the report
    says which one stopped."""
    # A longer timeout than the default 0.1 s, so that a busy machine's pause between two lines
    # of this test is not taken for a silence.
    leader.config = dataclasses.replace(leader.config, link_timeout=0.5)
    robot_found(leader)
    assert leader.report().message.startswith('link live')
    time.sleep(1.5 * leader.config.link_timeout)
    report = leader.report()
    assert report.message.startswith('the wand is silent')
    assert report.level == WARN and not report.values['wand_live']
    leader.on_twist(twist())
    leader.on_pose(pose())  # the wand again, but no feedback since
    report = leader.report()
    assert report.message.startswith('link silent') and report.values['wand_live']
