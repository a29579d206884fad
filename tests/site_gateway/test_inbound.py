"""What the gateway hands into its site: the right role's well-formed messages, rate-bound."""
from rclpy.serialization import serialize_message
from std_msgs.msg import Bool

from haptic_msgs.msg import TeleopCommand
from site_gateway.inbound import BURST, Inbound
from site_gateway.routes import site_routes

COMMAND = '/teleop/command:haptic_msgs/msg/TeleopCommand'
CLUTCH = 'teleop/clutch:std_msgs/msg/Bool'
FEEDBACK = '/teleop/feedback:haptic_msgs/msg/TeleopFeedback'
GOOD = serialize_message(TeleopCommand(session=7, sequence=1))
KEY = 'haptic/operator/teleop/command'


def remote_inbound(max_rate: float = 0.0) -> Inbound:
    return Inbound(site_routes('remote', [COMMAND, CLUTCH], [FEEDBACK]).incoming, 'haptic',
                   max_rate)


def test_the_operator_s_well_formed_command_is_handed_on():
    inbound = remote_inbound()
    assert inbound.judge(0.0, 0, KEY, GOOD).deliver
    assert inbound.judge(0.0, 1, 'haptic/operator/teleop/clutch',
                         serialize_message(Bool(data=True))).deliver
    assert inbound.counts()['in teleop/command delivered'] == 1


def test_a_command_under_another_role_s_key_is_refused_by_its_sender_s_name():
    inbound = remote_inbound()
    verdict = inbound.judge(0.0, 0, 'haptic/remote/teleop/command', GOOD)
    assert not verdict.deliver and verdict.sender == 'remote'
    assert inbound.counts()['refused: teleop/command from the remote role'] == 1
    assert not inbound.judge(0.0, 0, 'haptic/pilot/teleop/command', GOOD).deliver
    logged = []
    inbound.refused.log_new(logged.append)
    assert 'only the operator site may publish it' in logged[0]


def test_malformed_bytes_are_dropped_and_counted_and_the_next_good_one_goes():
    inbound = remote_inbound()
    for bad in (b'', GOOD[:-3], b'\x00\x01\x00\x00' + bytes(8) + (10**6).to_bytes(4, 'little'),
                b'\x00\x00' + GOOD[2:]):  # big-endian: not what Fast DDS writes
        assert not inbound.judge(0.0, 0, KEY, bad).deliver
    assert inbound.refused.counts == {'malformed teleop/command': 4}
    assert inbound.judge(0.0, 0, KEY, GOOD).deliver
    assert inbound.received == [5, 0] and inbound.delivered == [1, 0]


def test_a_flood_is_shed_to_max_rate_each_topic_on_its_own():
    rate = 2000.0
    inbound = remote_inbound(rate)
    # 20 kHz for one second: what passes is the burst plus the rate, within one message.
    delivered = sum(inbound.judge(k / 20_000, 0, KEY, GOOD).deliver for k in range(20_000))
    assert abs(delivered - (rate * BURST + rate * (19_999 / 20_000))) <= 1.0
    assert inbound.judge(1.0, 1, 'haptic/operator/teleop/clutch',
                         serialize_message(Bool())).deliver
    # At the nominal 1 kHz nothing is shed.
    steady = remote_inbound(rate)
    assert all(steady.judge(k / 1000, 0, KEY, GOOD).deliver for k in range(5000))
