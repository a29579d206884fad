"""The link's messages through the CDR codec and back, each field where its name says."""
import numpy as np
from rclpy.serialization import deserialize_message

from haptic_contract.teleop import Command, Feedback, RemotePlane
from haptic_contract.teleop_fields import (COMMAND, command_fields, command_from_fields, FEEDBACK,
                                           feedback_fields, feedback_from_fields,
                                           impedance_message, impedance_report)
from haptic_msgs.msg import TeleopCommand, TeleopFeedback


def test_a_command_crosses_whole_and_rclpy_reads_each_field_by_its_name():
    sent = Command(1_795_000_000.123456, np.array([0.1, -0.2, 0.3]), np.array([0.01, 0.0, -0.5]),
                   2.5, 0xABCDEF, 42)
    data = COMMAND.encode(command_fields(sent, 'base_link'))
    message = deserialize_message(data, TeleopCommand)
    assert (message.session, message.sequence) == (0xABCDEF, 42)
    assert message.header.frame_id == 'base_link'
    assert (message.position.y, message.velocity.z, message.energy_in) == (-0.2, -0.5, 2.5)
    frame, back = command_from_fields(COMMAND.decode(data))
    assert frame == 'base_link'
    assert back.stamp == sent.stamp and (back.session, back.sequence) == (0xABCDEF, 42)
    np.testing.assert_array_equal(back.position, sent.position)
    np.testing.assert_array_equal(back.velocity, sent.velocity)


def test_feedback_crosses_whole_with_its_plane_or_without():
    plane = RemotePlane(np.array([0.0, 0.0, -0.01]), np.array([0.0, 0.6, 0.8]), 480.0, 3.0)
    for sent_plane in (plane, None):
        sent = Feedback(7.25, 1_795_000_000.5, 0.002, np.array([0.0, 0.0, 7.5]),
                        np.array([0.0, 0.01, -0.04]), 0.125, sent_plane, 0x5EED, 900, 77)
        data = FEEDBACK.encode(feedback_fields(sent, 'base_link'))
        message = deserialize_message(data, TeleopFeedback)
        assert (message.session, message.sequence, message.echo_sequence) == (0x5EED, 900, 77)
        assert message.kind == (TeleopFeedback.KIND_FREE if sent_plane is None else
                                TeleopFeedback.KIND_PLANE)
        frame, back = feedback_from_fields(FEEDBACK.decode(data))
        assert frame == 'base_link'
        assert (back.stamp, back.echo, back.echo_hold, back.energy_in) == (
            sent.stamp, sent.echo, sent.echo_hold, sent.energy_in)
        assert (back.session, back.sequence, back.echo_sequence) == (0x5EED, 900, 77)
        np.testing.assert_array_equal(back.force, sent.force)
        np.testing.assert_array_equal(back.tcp, sent.tcp)
        if sent_plane is None:
            assert back.plane is None
        else:
            np.testing.assert_array_equal(back.plane.normal, plane.normal)
            assert (back.plane.stiffness, back.plane.damping) == (480.0, 3.0)


def test_feedback_without_a_good_reading_crosses_as_unknown_not_as_free():
    """A faulty or stale force reading says nothing of the contact: not "no contact"."""
    sent = Feedback(7.25, 1_795_000_000.5, 0.002, np.zeros(3), np.array([0.0, 0.01, -0.04]),
                    0.125, None, 0x5EED, 900, 77, measured=False)
    data = FEEDBACK.encode(feedback_fields(sent, 'base_link'))
    assert deserialize_message(data, TeleopFeedback).kind == TeleopFeedback.KIND_UNKNOWN
    _, back = feedback_from_fields(FEEDBACK.decode(data))
    assert not back.measured and back.plane is None
    _, free = feedback_from_fields(FEEDBACK.decode(FEEDBACK.encode(
        feedback_fields(sent._replace(measured=True), 'base_link'))))
    assert free.measured and free.plane is None


def test_what_a_robot_says_of_itself_is_read_back():
    message = impedance_message('base_link', stiffness=1500.0, max_speed=0.25,
                                workspace_lower=(-0.4, -0.3, -0.2),
                                workspace_upper=(0.4, 0.3, 0.2), max_patient_force=20.0)
    frame, report = impedance_report(message, hand_speed=5.0)
    assert frame == 'base_link'
    assert (report.stiffness, report.max_patient_force) == (1500.0, 20.0)
    np.testing.assert_array_equal(report.limits.workspace_lower, [-0.4, -0.3, -0.2])
    np.testing.assert_array_equal(report.limits.workspace_upper, [0.4, 0.3, 0.2])
    assert report.limits.max_speed == 5.0
