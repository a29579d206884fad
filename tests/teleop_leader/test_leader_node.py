"""The leader node answers each wand pose once, when its twist (same stamp) is in, in either order.

Within one process the driver's twist reaches the leader before its pose (``intra_process``
delivers in publishing order); over DDS the two may arrive either way round.
"""
import pytest
import rclpy
from rclpy.context import Context

from teleop_leader.leader_node import LeaderNode

STAMP = (100, 500)


def pose(stamp=STAMP, frame='world'):
    return (*stamp, frame, 0.01, 0.02, 0.03, 0.0, 0.0, 0.0, 1.0)


def twist(stamp=STAMP):
    return (*stamp, 'world', 0.1, 0.0, 0.0, 0.0, 0.0, 0.0)


class Sent:
    """Stands in for a stream publisher: keeps what is published."""

    def __init__(self):
        self.messages = []

    def publish(self, values):
        self.messages.append(values)


@pytest.fixture
def leader():
    context = Context()
    rclpy.init(context=context, domain_id=97)
    node = LeaderNode(context=context, parameter_overrides=[
        rclpy.parameter.Parameter('scheme', value='tdpa')])
    node._answer_pub = Sent()
    node._command_pub = Sent()
    yield node
    node.destroy_node()
    rclpy.try_shutdown(context=context)


@pytest.mark.parametrize('order', ['pose first', 'twist first'])
def test_a_pose_is_answered_once_its_twist_is_in_whichever_comes_first(leader, order):
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
    assert answer[3:] == (0.0,) * 6  # no robot yet: zero force
    leader.on_twist(twist())  # the same twist again answers nothing more
    assert len(leader._answer_pub.messages) == 1


def test_a_twist_of_another_stamp_answers_nothing(leader):
    leader.on_twist(twist((100, 400)))
    leader.on_pose(pose())
    assert leader._answer_pub.messages == []
    leader.on_twist(twist())
    assert len(leader._answer_pub.messages) == 1
