"""The routing table: which topic crosses which way, under which key, and how."""
import pytest

from link_emulator.relay import Route
from site_gateway.routes import (bye_key, FRAME, other_role, RELIABLE, role_in_key,
                                 site_routes, STREAM)

COMMAND = '/teleop/command:haptic_msgs/msg/TeleopCommand'
FEEDBACK = '/teleop/feedback:haptic_msgs/msg/TeleopFeedback'
CLUTCH = 'teleop/clutch:std_msgs/msg/Bool'
IMAGE = '/probe/image:sensor_msgs/msg/Image'


def test_each_site_sends_what_its_role_publishes_and_receives_the_rest():
    operator = site_routes('operator', [COMMAND, CLUTCH], [FEEDBACK], ['teleop/clutch'])
    remote = site_routes('remote', [COMMAND, CLUTCH], [FEEDBACK], ['/teleop/clutch'])
    assert operator.outgoing == remote.incoming
    assert operator.incoming == remote.outgoing
    command, clutch = operator.outgoing
    assert command.route == Route('/teleop/command', 'haptic_msgs/msg/TeleopCommand')
    assert (command.kind, clutch.kind) == (STREAM, RELIABLE)
    assert command.key('haptic') == 'haptic/operator/teleop/command'
    assert command.any_role_key('site/a') == 'site/a/*/teleop/command'
    assert remote.outgoing[0].key('haptic') == 'haptic/remote/teleop/feedback'


def test_an_image_crosses_as_a_frame():
    remote = site_routes('remote', [COMMAND], [FEEDBACK, IMAGE], frames=['probe/image'])
    assert [c.kind for c in remote.outgoing] == [STREAM, FRAME]


def test_the_role_in_a_key_is_read_back():
    assert role_in_key('haptic/remote/teleop/command', 'haptic') == 'remote'
    assert role_in_key('haptic/operator/x', 'haptic') == 'operator'
    assert role_in_key('haptic/stranger/teleop/command', 'haptic') is None
    assert role_in_key('other/operator/x', 'haptic') is None
    assert bye_key('haptic', 'remote') == 'haptic/remote/_gateway/bye'
    assert other_role('operator') == 'remote' and other_role('remote') == 'operator'


@pytest.mark.parametrize('arguments, words', [
    (('pilot', [COMMAND], [FEEDBACK]), ["role 'pilot'"]),
    (('operator', [COMMAND], [COMMAND]), ['both', 'one way']),
    (('operator', [COMMAND], [FEEDBACK], ['teleop/clutch']), ['reliable', 'teleop/clutch']),
    (('operator', [COMMAND], [FEEDBACK], [], ['/probe/image']), ['frames', 'probe/image']),
    (('operator', [COMMAND], [IMAGE], ['probe/image'], ['/probe/image']), ['both', 'choose']),
    (('operator', ['_gateway/bye:std_msgs/msg/Bool'], [FEEDBACK]), ['gateways\' own']),
    (('operator', ['teleop/command'], [FEEDBACK]), ["'topic:pkg/msg/Type'"]),
])
def test_a_bad_table_is_refused_naming_what_is_wrong(arguments, words):
    with pytest.raises(ValueError) as error:
        site_routes(*arguments)
    for word in words:
        assert word in str(error.value)


@pytest.mark.parametrize('prefix', ['', 'a//b', 'a/*', 'a/$x', '@a', 'a/'])
def test_a_key_prefix_with_wildcards_or_empty_chunks_is_refused(prefix):
    crossing = site_routes('operator', [COMMAND], [FEEDBACK]).outgoing[0]
    with pytest.raises(ValueError, match='key prefix'):
        crossing.key(prefix)
