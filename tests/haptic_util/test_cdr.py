"""The loop's CDR codec against rclpy's own serialization, both ways, for every type it carries."""
import functools
import math

from fuzzing import examples
from hypothesis import given, settings
from hypothesis import strategies as st
import pytest
from rclpy.serialization import deserialize_message, serialize_message

from haptic_util.cdr import MalformedMessage, MessageCodec

TYPES = ['geometry_msgs/PoseStamped', 'geometry_msgs/TwistStamped',
         'geometry_msgs/WrenchStamped', 'haptic_msgs/CollisionState', 'haptic_msgs/ContactModel',
         'std_msgs/Header']
LEAF = {'?': st.booleans(), 'B': st.integers(0, 255), 'I': st.integers(0, 2**32 - 1),
        'i': st.integers(-2**31, 2**31 - 1), 'd': st.floats(allow_nan=False),
        'string': st.text(max_size=40).filter(lambda s: '\0' not in s),
        '*d': st.lists(st.floats(allow_nan=False), max_size=32).map(tuple)}


@functools.lru_cache(maxsize=None)
def message_class(type_name: str):
    import importlib
    package, name = type_name.split('/')
    return getattr(importlib.import_module(f'{package}.msg'), name)


def message_from(cls, codec: MessageCodec, values):
    """Set each leaf by its dotted name (an element of an array by hand, not by the codec)."""
    message = cls()
    for field, value in zip(codec.fields, values):
        target = message
        *parents, leaf = field.split('.')
        for parent in parents:
            name, _, index = parent.partition('[')
            target = getattr(target, name)
            if index:
                target = target[int(index[:-1])]
        name, _, index = leaf.partition('[')
        if index:  # an element of an array of numbers
            getattr(target, name)[int(index[:-1])] = value
        else:
            setattr(target, leaf, value)
    return message


@st.composite
def typed_values(draw):
    type_name = draw(st.sampled_from(TYPES))
    codec = MessageCodec(message_class(type_name))
    return type_name, codec, [draw(LEAF[code]) for code in codec._codes]


@settings(max_examples=examples(300), deadline=None)
@given(typed_values())
def test_encoding_has_rclpy_s_layout(case):
    """rclpy reads the message back; only padding may differ (rclpy leaves whatever was in its
    buffer there). Same length without sequences; with them rclpy's buffer may be longer, by
    the alignment it reserved for each sequence's elements and did not use (at its end)."""
    type_name, codec, values = case
    cls = message_class(type_name)
    message = message_from(cls, codec, values)
    encoded = codec.encode(values)
    reference = len(serialize_message(message))
    sequences = sum(code.startswith('*') for code in codec._codes)
    assert reference - 4 * sequences <= len(encoded) <= reference
    assert len(encoded) == reference or sequences
    assert deserialize_message(encoded, cls) == message


@settings(max_examples=examples(300), deadline=None)
@given(typed_values())
def test_decoding_reads_back_what_rclpy_wrote(case):
    type_name, codec, values = case
    cls = message_class(type_name)
    decoded = codec.decode(serialize_message(message_from(cls, codec, values)))
    assert decoded == values


def test_the_fields_are_the_message_s_leaves_in_order():
    codec = MessageCodec(message_class('geometry_msgs/PoseStamped'))
    assert codec.fields == ('header.stamp.sec', 'header.stamp.nanosec', 'header.frame_id',
                            'pose.position.x', 'pose.position.y', 'pose.position.z',
                            'pose.orientation.x', 'pose.orientation.y', 'pose.orientation.z',
                            'pose.orientation.w')


def test_a_fixed_array_of_messages_is_flattened_element_by_element():
    codec = MessageCodec(message_class('haptic_msgs/ContactModel'))
    assert codec.fields[6:9] == ('planes[0].point.x', 'planes[0].point.y', 'planes[0].point.z')
    assert 'planes[2].tool_point.z' in codec.fields and len(codec.fields) == 6 + 45 + 6 + 6
    values = list(range(len(codec.fields)))
    values[2], values[3] = 'world', 'hand'
    values[4:] = [float(v) if codec._codes[i + 4] == 'd' else v % 256
                  for i, v in enumerate(values[4:])]
    assert codec.to_message(values) == message_from(message_class('haptic_msgs/ContactModel'),
                                                    codec, values)


def test_non_finite_numbers_pass_through():
    codec = MessageCodec(message_class('geometry_msgs/WrenchStamped'))
    values = [1, 2, 'world', math.nan, math.inf, -math.inf, 0.0, 0.0, 0.0]
    decoded = codec.decode(codec.encode(values))
    assert math.isnan(decoded[3]) and decoded[4:6] == [math.inf, -math.inf]


def test_a_sequence_of_numbers_is_one_leaf_and_an_empty_one_costs_its_count_alone():
    codec = MessageCodec(message_class('haptic_msgs/CollisionState'))
    assert codec.fields[-3:] == ('contact_distance', 'contact_points', 'contact_normals')
    empty = codec.encode([draw_free_value(code) for code in codec._codes])
    full = codec.encode([draw_free_value(code, 32) for code in codec._codes])
    assert len(full) - len(empty) == 3 * (8 * 32 + 4)  # the doubles, each run padded to 8


def draw_free_value(code: str, count: int = 0):
    return {'string': 'world', '*d': (0.5,) * count}.get(code, 0)


def test_a_sequence_of_messages_is_refused_by_name():
    with pytest.raises(ValueError, match='markers'):
        MessageCodec(message_class('visualization_msgs/MarkerArray'))


@settings(max_examples=examples(300), deadline=None)
@given(typed_values(), st.data())
def test_any_damage_to_a_message_is_refused_as_malformed_or_read_as_some_message(case, data):
    """Bytes from the network may be anything: cut short, lengths rewritten, bytes flipped.
    Whatever comes, decoding gives a message of the type or says it is malformed; nothing else
    raises, and nothing grows with the lengths a sender chooses."""
    _, codec, values = case
    encoded = bytearray(codec.encode(values))
    damage = data.draw(st.sampled_from(['cut', 'flip', 'length']))
    if damage == 'cut':
        encoded = encoded[:data.draw(st.integers(0, len(encoded) - 1))]
    elif damage == 'flip':
        for _ in range(data.draw(st.integers(1, 8))):
            encoded[data.draw(st.integers(0, len(encoded) - 1))] = data.draw(st.integers(0, 255))
    else:
        at = data.draw(st.integers(4, max(4, len(encoded) - 4)))
        encoded[at:at + 4] = data.draw(st.integers(0, 2**32 - 1)).to_bytes(4, 'little')
    try:
        decoded = codec.decode(bytes(encoded))
    except MalformedMessage as error:
        assert codec.message_class.__name__ in str(error)
    else:
        assert len(decoded) == len(codec.fields)
    assert len(codec._runs) <= 8 * len(codec._segments)


def test_strings_of_every_length_leave_the_decoder_s_layouts_bounded():
    """One layout per string length would grow by one entry per length an attacker picks."""
    codec = MessageCodec(message_class('geometry_msgs/PoseStamped'))
    for length in range(1, 2000):
        values = [1, 2, 'x' * length, 0.1, 0.2, 0.3, 0.0, 0.0, 0.0, 1.0]
        assert codec.decode(codec.encode(values)) == values
    assert len(codec._runs) <= 8 * len(codec._segments)
    assert len(codec._encode_layouts) <= 16


@pytest.mark.parametrize('data, reason', [
    (b'', 'not little-endian CDR'),
    (b'\x01\x00\x00\x00' + bytes(60), 'not little-endian CDR'),  # big endian
    (b'\x00\x01\x00\x00' + bytes(8) + (1000).to_bytes(4, 'little') + b'abc', 'does not fit'),
    (b'\x00\x01\x00\x00' + bytes(8) + (2).to_bytes(4, 'little') + b'ab' + bytes(64),
     'does not end in NUL'),
    (b'\x00\x01\x00\x00' + bytes(8) + (2).to_bytes(4, 'little') + b'\xff\x00' + bytes(64),
     'not UTF-8'),
    (b'\x00\x01\x00\x00' + bytes(8) + (6).to_bytes(4, 'little') + b'world\x00', 'ends early'),
])
def test_a_malformed_message_says_what_is_wrong(data, reason):
    codec = MessageCodec(message_class('geometry_msgs/PoseStamped'))
    with pytest.raises(MalformedMessage, match=f'PoseStamped: .*{reason}'):
        codec.decode(data)
