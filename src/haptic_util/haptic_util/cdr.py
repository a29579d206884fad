"""Read and write the 1 kHz loop's messages as CDR bytes, without rclpy's message objects.

Why: converting a message to and from a Python object costs about half of each node's CPU at
1 kHz, and every subscriber pays it again (``../shared/loop-latency.md``: a relay chain forwarding
bytes used 21-37 % of a core per process against 37-51 % with objects). A node that subscribes
with ``raw=True`` gets the serialized bytes; ``Publisher.publish`` takes bytes too. What the node
reads and writes is a flat tuple of the message's leaf fields, in the order of its definition.

Scope: messages whose leaves are numbers, booleans and strings, nested to any depth, with
fixed-size arrays (no sequences): the stamped poses, twists and wrenches, and
``haptic_msgs/CollisionState`` and ``ContactModel``. The
layout is little-endian plain CDR (XCDR1), as Fast DDS writes it: a 4-byte encapsulation header,
then each field aligned to its own size from the end of that header; a string is a ``uint32``
length (including its NUL), the bytes and the NUL. The layout of a message depends only on the
lengths of its strings, so one ``struct.Struct`` per combination of lengths is built and kept.
``tests/haptic_util/test_cdr.py`` checks both directions against ``rclpy.serialization``.
"""
import importlib
import re
import struct
from typing import Sequence

__all__ = ['MessageCodec']

_LEAVES = {'boolean': '?', 'octet': 'B', 'uint8': 'B', 'int8': 'b', 'char': 'B', 'int16': 'h',
           'uint16': 'H', 'int32': 'i', 'uint32': 'I', 'int64': 'q', 'uint64': 'Q',
           'float': 'f', 'double': 'd'}
_ENCAPSULATION = b'\x00\x01\x00\x00'  # CDR, little endian
_FIXED_ARRAY = re.compile(r'(.+)\[(\d+)\]')  # T[N]: N elements, no length on the wire
_STRING = 'string'


def _message_class(type_name: str):
    package, name = type_name.split('/')
    return getattr(importlib.import_module(f'{package}.msg'), name)


def _leaves(message_class, prefix: str = '') -> list:
    """Return the leaf fields, depth first: [(dotted name, struct code or "string")]."""
    leaves = []
    for name, kind in message_class.get_fields_and_field_types().items():
        array = _FIXED_ARRAY.fullmatch(kind)
        names = ([f'{prefix}{name}[{i}]' for i in range(int(array[2]))] if array
                 else [prefix + name])
        kind = array[1] if array else kind
        for element in names:
            if kind in _LEAVES or kind == _STRING:
                leaves.append((element, _LEAVES.get(kind, _STRING)))
            elif '/' in kind and '[' not in kind and '<' not in kind:
                leaves += _leaves(_message_class(kind), f'{element}.')
            else:
                raise ValueError(f'{message_class.__name__}.{element}: {kind} is not supported')
    return leaves


class MessageCodec:
    """Encode and decode one message type as a flat tuple of its leaf fields.

    Parameters
    ----------
    message_class : a rosidl message class, e.g. ``geometry_msgs.msg.PoseStamped``

    Attributes
    ----------
    fields : tuple of str
        The leaf fields' dotted names, in the order the tuples hold them.
    """

    def __init__(self, message_class) -> None:
        self.message_class = message_class
        leaves = _leaves(message_class)
        self.fields = tuple(name for name, _ in leaves)
        self._codes = tuple(code for _, code in leaves)
        self._strings = tuple(i for i, code in enumerate(self._codes) if code == _STRING)
        self._layouts: dict = {}  # string lengths -> (struct, where each string's bytes are)
        self._string_offsets: dict = {}  # lengths of the strings before -> offset of the next

    def decode(self, data: bytes) -> list:
        """Return the leaf values of a serialized message (strings as str)."""
        lengths = []
        for k in range(len(self._strings)):
            offset = self._string_offset(tuple(lengths))
            lengths.append(struct.unpack_from('<I', data, offset)[0])
        layout, picks, strings = self._layout(tuple(lengths))
        raw = layout.unpack_from(data)
        values = [raw[i] for i in picks]
        for field, position in strings:
            values[field] = raw[position][:-1].decode()
        return values

    def encode(self, values: Sequence) -> bytes:
        """Return the serialized message of leaf ``values`` (in ``fields`` order)."""
        args = [_ENCAPSULATION, *values]
        lengths = []
        for i in reversed(self._strings):  # from the back, so earlier indices stay valid
            text = values[i].encode() + b'\0'
            args[i + 1:i + 2] = (len(text), text)
            lengths.append(len(text))
        return self._layout(tuple(reversed(lengths)))[0].pack(*args)

    def to_message(self, values: Sequence):
        """Return a message object with these leaf values (for the paths off the 1 kHz loop)."""
        message = self.message_class()
        for field, value in zip(self.fields, values):
            *parents, leaf = _steps(field)
            target = message
            for parent in parents:
                target = target[parent] if isinstance(parent, int) else getattr(target, parent)
            if isinstance(leaf, int):
                target[leaf] = value
            else:
                setattr(target, leaf, value)
        return message

    def _layout(self, lengths: tuple) -> tuple:
        """Return the struct of the whole message for these string lengths, built once."""
        if lengths not in self._layouts:
            fmt, offset, k, picks, strings = ['<4s'], 0, 0, [], []
            for i, code in enumerate(self._codes):
                size = 4 if code == _STRING else struct.calcsize(code)
                fmt.append(f'{-offset % size}x')
                offset += -offset % size
                if code == _STRING:
                    fmt.append(f'I{lengths[k]}s')
                    strings.append((i, 1 + len(picks) + len(strings) + 1))
                    picks.append(1 + len(picks) + len(strings))
                    offset += 4 + lengths[k]
                    k += 1
                else:
                    fmt.append(code)
                    picks.append(1 + len(picks) + len(strings))
                    offset += size
            self._layouts[lengths] = (struct.Struct(''.join(fmt)), picks, strings)
        return self._layouts[lengths]

    def _string_offset(self, before: tuple) -> int:
        """Byte offset of the length of string number ``len(before)``, from the buffer start."""
        if before not in self._string_offsets:
            offset, k = 0, 0
            for code in self._codes:
                size = 4 if code == _STRING else struct.calcsize(code)
                offset += -offset % size
                if code == _STRING:
                    if k == len(before):
                        break
                    offset += 4 + before[k]
                    k += 1
                else:
                    offset += size
            self._string_offsets[before] = len(_ENCAPSULATION) + offset
        return self._string_offsets[before]


def _steps(field: str) -> list:
    """``'planes[1].point.x'`` -> ``['planes', 1, 'point', 'x']``."""
    steps = []
    for part in field.split('.'):
        name, _, index = part.partition('[')
        steps.append(name)
        if index:
            steps.append(int(index[:-1]))
    return steps
