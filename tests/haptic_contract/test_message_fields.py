"""The contract's readers and writers against rclpy: every field where its name says.

rclpy's own serialization, reached through attribute names, is the ground truth: it shares no
code with the slices the contract finds in the codec's flat tuple.
"""
from geometry_msgs.msg import PoseStamped, TwistStamped, WrenchStamped
import pytest
from rclpy.serialization import deserialize_message, serialize_message

from haptic_contract import collision_state, streams
from haptic_contract.contact_model import ContactModel, Kind, MAX_PLANES, MODEL, model_fields
from haptic_msgs.msg import CollisionState, ContactModel as ContactModelMessage

PLANES = [((0.1, 0.2, 0.3), (0.0, 0.6, 0.8), (100.0, 200.0, 300.0), (1.0, 2.0, 3.0),
           (0.01, 0.02, 0.03)),
          ((-0.1, -0.2, -0.3), (1.0, 0.0, 0.0), (400.0, 500.0, 600.0), (4.0, 5.0, 6.0))]


def test_a_model_written_by_field_name_is_the_message_rclpy_reads():
    values = model_fields((12, 345, 'world'), 'box', Kind.PLANES, PLANES, 9.5, 0.02, 0.003,
                          (0.5, 0.6, 0.7), (1.0, 2.0, 3.0, 4.0, 5.0, 6.0))
    message = deserialize_message(MODEL.encode(values), ContactModelMessage)
    assert (message.header.stamp.sec, message.header.stamp.nanosec) == (12, 345)
    assert (message.header.frame_id, message.object) == ('world', 'box')
    assert (message.kind, message.plane_count) == (ContactModelMessage.KIND_PLANES, 2)
    assert len(message.planes) == MAX_PLANES == 3
    first, second, unused = message.planes
    assert (first.point.z, first.normal.y, first.stiffness.x, first.damping.z) == (
        0.3, 0.6, 100.0, 3.0)
    assert (first.tool_point.x, first.tool_point.z) == (0.01, 0.03)
    assert (second.point.x, second.stiffness.z, second.damping.y) == (-0.1, 600.0, 5.0)
    assert (second.tool_point.x, second.tool_point.y, second.tool_point.z) == (0.0, 0.0, 0.0)
    assert unused.normal.z == 0.0 and unused.stiffness.x == 0.0
    assert (message.force_limit, message.valid_for, message.valid_radius) == (9.5, 0.02, 0.003)
    assert (message.tip.x, message.tip.z) == (0.5, 0.7)
    assert (message.wrench.force.x, message.wrench.torque.z) == (1.0, 6.0)


def test_a_model_rclpy_wrote_is_read_by_field_name():
    message = ContactModelMessage(kind=ContactModelMessage.KIND_PLANES, plane_count=2,
                                  force_limit=7.0, valid_for=0.01, valid_radius=0.002)
    message.header.stamp.sec, message.header.frame_id = 3, 'world'
    message.planes[1].point.z = -0.25
    message.planes[1].normal.x = 1.0
    message.planes[1].stiffness.y = 800.0
    message.planes[1].tool_point.x = 0.04
    message.planes[0].normal.z = 1.0
    message.tip.y = 0.125
    message.wrench.torque.y = -2.0
    model = ContactModel.from_fields(MODEL.decode(serialize_message(message)), 'world')
    assert model.kind is Kind.PLANES and len(model.planes) == 2
    assert model.planes[1].point == (0.0, 0.0, -0.25)
    assert model.planes[1].normal == (1.0, 0.0, 0.0)
    assert model.planes[1].stiffness == (0.0, 800.0, 0.0)
    assert model.planes[1].tool_point == (0.04, 0.0, 0.0)
    assert (model.stamp, model.force_limit, model.valid_radius) == (3.0, 7.0, 0.002)
    assert model.tip == (0.0, 0.125, 0.0)
    assert model.held_wrench == (0.0, 0.0, 0.0, 0.0, -2.0, 0.0)


def test_a_collision_state_is_read_by_field_name():
    message = CollisionState(object='hand', status=CollisionState.STATUS_NOT_CONVERGED,
                             distance=-0.002, contact_distance=[0.1, -0.2],
                             contact_points=[1.0] * 6, contact_normals=[0.0, 0.0, 1.0] * 2)
    message.header.stamp.sec, message.header.stamp.nanosec, message.header.frame_id = \
        4, 5, 'world'
    message.closest_point.y, message.normal.z, message.tip.x = 0.5, 1.0, -0.75
    message.orientation.w = 1.0
    fields = collision_state.STATE.decode(serialize_message(message))
    header, name, status, distance, point, normal, tip = collision_state.contact_fields(fields)
    assert (header, name, distance) == ((4, 5, 'world'), 'hand', -0.002)
    assert status == collision_state.STATUS_NOT_CONVERGED == 1
    assert (tuple(point), tuple(normal), tuple(tip)) == (
        (0.0, 0.5, 0.0), (0.0, 0.0, 1.0), (-0.75, 0.0, 0.0))
    distances, points, normals, orientation = collision_state.face_fields(fields)
    assert (distances, points, normals) == ((0.1, -0.2), (1.0,) * 6, (0.0, 0.0, 1.0) * 2)
    assert tuple(orientation) == (0.0, 0.0, 0.0, 1.0)


@pytest.mark.parametrize('codec, message_class, vectors', [
    (streams.POSE, PoseStamped, [(streams.POSE_POSITION, 'pose', 'position'),
                                 (streams.POSE_ORIENTATION, 'pose', 'orientation')]),
    (streams.TWIST, TwistStamped, [(streams.TWIST_LINEAR, 'twist', 'linear'),
                                   (streams.TWIST_ANGULAR, 'twist', 'angular')]),
    (streams.WRENCH, WrenchStamped, [(streams.WRENCH_FORCE, 'wrench', 'force'),
                                     (streams.WRENCH_TORQUE, 'wrench', 'torque')])])
def test_every_stream_is_read_by_field_name(codec, message_class, vectors):
    message = message_class()
    message.header.stamp.sec, message.header.stamp.nanosec = 1_795_000_000, 999_999_999
    message.header.frame_id = 'world'
    expected = []
    for k, (_, parent, child) in enumerate(vectors):
        vector = getattr(getattr(message, parent), child)
        axes = 'xyzw' if child == 'orientation' else 'xyz'
        for axis, name in enumerate(axes):
            setattr(vector, name, 10.0 * k + axis + 0.5)
        expected.append(tuple(10.0 * k + axis + 0.5 for axis in range(len(axes))))
    fields = codec.decode(serialize_message(message))
    assert streams.stamp_ns(fields) == 1_795_000_000_999_999_999
    assert streams.frame(fields) == 'world'
    assert [tuple(fields[where]) for where, _, _ in vectors] == expected
