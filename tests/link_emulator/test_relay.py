"""The gateway's pure relay: which topics cross, and one direction's order, losses and counts."""
import math

import pytest

from link_emulator.link import EmulatedLink, LinkConfig
from link_emulator.relay import (check_no_loop, LATENESS_WINDOW, message_class, parse_routes,
                                 Relay, Release, Route)


def test_routes_are_parsed_with_their_types():
    routes = parse_routes(['robot/target_pose:geometry_msgs/msg/PoseStamped',
                           ' /wand/wrench : geometry_msgs/msg/WrenchStamped '], 'to_remote')
    assert routes == (Route('robot/target_pose', 'geometry_msgs/msg/PoseStamped'),
                      Route('/wand/wrench', 'geometry_msgs/msg/WrenchStamped'))
    assert message_class('geometry_msgs/msg/PoseStamped').__name__ == 'PoseStamped'


@pytest.mark.parametrize('entry, words', [
    ('robot/target_pose', ['to_remote', "'topic:pkg/msg/Type'"]),
    (':geometry_msgs/msg/PoseStamped', ['to_remote', "'topic:pkg/msg/Type'"]),
    ('robot/target_pose:', ['to_remote', "'topic:pkg/msg/Type'"]),
    ('pose:geometry_msgs/PoseStamped', ['not of the form pkg/msg/Type']),
    ('pose:geometry_msgs/msg/PoseStampd', ["geometry_msgs has no message 'PoseStampd'"]),
    ('pose:geometry_msgz/msg/PoseStamped', ["no message package 'geometry_msgz'"]),
    ('pose:os/msg/Path', ["no message package 'os'"]),
])
def test_a_bad_entry_is_refused_with_what_is_wrong(entry, words):
    with pytest.raises(ValueError) as error:
        parse_routes([entry], 'to_remote')
    for word in words:
        assert word in str(error.value)


def test_a_topic_listed_twice_or_both_ways_is_refused():
    with pytest.raises(ValueError, match="'a' is listed twice"):
        parse_routes(['a:std_msgs/msg/Empty', 'a:std_msgs/msg/String'], 'to_operator')
    to_remote = parse_routes(['a:std_msgs/msg/Empty', 'b:std_msgs/msg/Empty'], 'to_remote')
    check_no_loop(to_remote, parse_routes(['c:std_msgs/msg/Empty'], 'to_operator'))
    with pytest.raises(ValueError, match=r"\['b'\] are listed in both"):
        check_no_loop(to_remote, parse_routes(['/b:std_msgs/msg/Empty'], 'to_operator'))


def test_messages_of_all_topics_keep_their_order_and_wait_for_their_time():
    relay = Relay(EmulatedLink(LinkConfig(delay=0.05, jitter=0.01, seed=3)))
    for index in range(100):
        relay.send(index * 1e-3, index % 3, bytes([index]))
    assert relay.release(0.0) == []
    assert relay.next_arrival >= 0.0 and relay.in_flight == 100
    released = relay.release(math.inf)
    assert released == [Release(index % 3, bytes([index])) for index in range(100)]
    assert relay.relayed == 100 and relay.in_flight == 0 and relay.next_arrival is None


def test_counts_say_what_was_lost_in_flight_and_how_late():
    relay = Relay(EmulatedLink(LinkConfig(delay=0.01, loss=0.5, seed=1)))
    assert relay.counts()['lateness_p99_ms'] == '-' and relay.lateness() == (None, None)
    sent = [relay.send(time, 0, b'x') for time in (0.0, 0.001, 0.002, 0.003)]
    relay.release(0.0115)  # 1.5 ms after the first arrival, 0.5 ms after the second
    counts = relay.counts()
    delivered = sum(sent)
    assert counts['received'] == 4 and counts['lost'] == 4 - delivered
    assert counts['relayed'] + counts['in_flight'] == delivered
    p50, p99 = relay.lateness()
    assert 0.0 <= p50 <= p99 <= 0.0115 - 0.01 + 1e-12


def test_the_routes_that_must_arrive_are_never_lost_where_the_others_are():
    relay = Relay(EmulatedLink(LinkConfig(delay=0.01, loss=0.3, seed=2)), reliable={1})
    for index in range(400):
        relay.send(index * 1e-3, index % 2, bytes([index % 256]))
    released = relay.release(math.inf)
    assert sum(route == 1 for route, _ in released) == 200
    assert 100 < sum(route == 0 for route, _ in released) < 180
    counts = relay.counts()
    assert counts['lost'] == 200 - sum(route == 0 for route, _ in released)
    assert counts['retransmitted'] > 30


def test_lateness_is_summarized_over_the_latest_releases_only():
    relay = Relay(EmulatedLink(LinkConfig(delay=0.0)))
    relay.send(0.0, 0, b'late')
    relay.release(1.0)  # 1 s late, then forgotten behind a window of punctual ones
    for index in range(LATENESS_WINDOW):
        relay.send(2.0 + index, 0, b'on time')
        relay.release(2.0 + index)
    assert relay.lateness() == (0.0, 0.0)


def test_blank_entries_say_nothing_crosses():
    assert parse_routes([''], 'to_operator') == ()
    assert parse_routes([' ', 'a:std_msgs/msg/Empty'], 'to_operator') == (
        Route('a', 'std_msgs/msg/Empty'),)
