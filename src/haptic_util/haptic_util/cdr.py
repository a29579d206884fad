"""Read and write the 1 kHz loop's messages as CDR bytes, without rclpy's message objects.

Why: converting a message to and from a Python object costs about half of each node's CPU at
1 kHz, and every subscriber pays it again (``../shared/loop-latency.md``: a relay chain forwarding
bytes used 21-37 % of a core per process against 37-51 % with objects). A node that subscribes
with ``raw=True`` gets the serialized bytes; ``Publisher.publish`` takes bytes too. What the node
reads and writes is a flat tuple of the message's leaf fields, in the order of its definition.

Scope: messages whose leaves are numbers, booleans and strings, nested to any depth, with
fixed-size arrays and sequences of numbers (a sequence is one leaf, a tuple of its elements):
the stamped poses, twists and wrenches, and ``haptic_msgs/CollisionState`` and
``ContactModel``. The layout is little-endian plain CDR (XCDR1), as Fast DDS writes it: a 4-byte
encapsulation header, then each field aligned to its own size from the end of that header; a
string is a ``uint32`` length (including its NUL), the bytes and the NUL; a sequence a ``uint32``
count, then its elements, aligned to their size (no padding when there are none). The layout
of a message depends only on the lengths of its strings and sequences, so one ``struct.Struct``
per combination of lengths is built and kept.
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
_SEQUENCE = re.compile(r'sequence<(\w+)(?:, \d+)?>')  # a count, then the elements
_STRING = 'string'
_SEQUENCE_MARK = '*'  # code of a sequence of numbers: '*' + the element's code


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
        sequence = _SEQUENCE.fullmatch(kind)
        if sequence and sequence[1] in _LEAVES:
            leaves.append((prefix + name, _SEQUENCE_MARK + _LEAVES[sequence[1]]))
            continue
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
        # Strings and sequences: their lengths (bytes with the NUL; elements) set the layout.
        self._variable = tuple(i for i, code in enumerate(self._codes)
                               if code == _STRING or code[0] == _SEQUENCE_MARK)
        self._layouts: dict = {}  # lengths -> (struct, picks, strings, sequences)
        self._length_offsets: dict = {}  # lengths before -> offset of the next length

    def decode(self, data: bytes) -> list:
        """Return the leaf values of a serialized message (strings as str, sequences tuples)."""
        lengths = []
        for k in range(len(self._variable)):
            offset = self._length_offset(tuple(lengths))
            lengths.append(struct.unpack_from('<I', data, offset)[0])
        layout, picks, strings, sequences = self._layout(tuple(lengths))
        raw = layout.unpack_from(data)
        values = [raw[i] for i in picks]
        for field, position in strings:
            values[field] = raw[position][:-1].decode()
        for field, elements in sequences:
            values[field] = raw[elements]
        return values

    def encode(self, values: Sequence) -> bytes:
        """Return the serialized message of leaf ``values`` (in ``fields`` order)."""
        args = [_ENCAPSULATION, *values]
        lengths = []
        for i in reversed(self._variable):  # from the back, so earlier indices stay valid
            if self._codes[i] == _STRING:
                text = values[i].encode() + b'\0'
                args[i + 1:i + 2] = (len(text), text)
                lengths.append(len(text))
            else:
                args[i + 1:i + 2] = (len(values[i]), *values[i])
                lengths.append(len(values[i]))
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
        """Return the struct of the whole message for these lengths, built once.

        With it: where each leaf's value is in the unpacked tuple (``picks``), and the fields
        read differently: strings (their bytes' position) and sequences (their slice).
        """
        if lengths not in self._layouts:
            fmt, offset, k, picks, strings, sequences = ['<4s'], 0, 0, [], [], []
            unpacked = 1  # values before the next field's, in the unpacked tuple
            for i, code in enumerate(self._codes):
                size = 4 if code == _STRING or code[0] == _SEQUENCE_MARK else struct.calcsize(code)
                fmt.append(f'{-offset % size}x')
                offset += -offset % size
                picks.append(unpacked)
                if code == _STRING:
                    fmt.append(f'I{lengths[k]}s')
                    strings.append((i, unpacked + 1))
                    offset += 4 + lengths[k]
                    unpacked += 2
                    k += 1
                elif code[0] == _SEQUENCE_MARK:
                    element, count = code[1:], lengths[k]
                    offset += 4
                    padding = -offset % struct.calcsize(element) if count else 0
                    fmt.append(f'I{padding}x{count}{element}')
                    sequences.append((i, slice(unpacked + 1, unpacked + 1 + count)))
                    offset += padding + count * struct.calcsize(element)
                    unpacked += 1 + count
                    k += 1
                else:
                    fmt.append(code)
                    offset += size
                    unpacked += 1
            self._layouts[lengths] = (struct.Struct(''.join(fmt)), picks, strings, sequences)
        return self._layouts[lengths]

    def _length_offset(self, before: tuple) -> int:
        """Byte offset of the length of variable field number ``len(before)``, from the start."""
        if before not in self._length_offsets:
            offset, k = 0, 0
            for code in self._codes:
                variable = code == _STRING or code[0] == _SEQUENCE_MARK
                size = 4 if variable else struct.calcsize(code)
                offset += -offset % size
                if not variable:
                    offset += size
                    continue
                if k == len(before):
                    break
                offset += 4
                if code == _STRING:
                    offset += before[k]
                elif before[k]:
                    element = struct.calcsize(code[1:])
                    offset += -offset % element + before[k] * element
                k += 1
            self._length_offsets[before] = len(_ENCAPSULATION) + offset
        return self._length_offsets[before]


def _steps(field: str) -> list:
    """``'planes[1].point.x'`` -> ``['planes', 1, 'point', 'x']``."""
    steps = []
    for part in field.split('.'):
        name, _, index = part.partition('[')
        steps.append(name)
        if index:
            steps.append(int(index[:-1]))
    return steps
