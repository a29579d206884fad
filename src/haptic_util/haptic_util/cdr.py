"""Read and write the 1 kHz loop's messages as CDR bytes, without rclpy's message objects.

Why: converting a message to and from a Python object costs about half of each node's CPU at
1 kHz, and every subscriber pays it again (``../shared/loop-latency.md``: a relay chain forwarding
bytes used 21-37 % of a core per process against 37-51 % with objects). A node that subscribes
with ``raw=True`` gets the serialized bytes; ``Publisher.publish`` takes bytes too. What the node
reads and writes is a flat tuple of the message's leaf fields, in the order of its definition.

Scope: messages whose leaves are numbers, booleans and strings, nested to any depth, with
fixed-size arrays and sequences of numbers (a sequence is one leaf, a tuple of its elements):
the stamped poses, twists and wrenches, and ``haptic_msgs``' messages. The layout is
little-endian plain CDR (XCDR1), as Fast DDS writes it: a 4-byte encapsulation header, then each
field aligned to its own size from the end of that header; a string is a ``uint32`` length
(including its NUL), the bytes and the NUL; a sequence a ``uint32`` count, then its elements,
aligned to their size (no padding when there are none).

Bytes from the network are untrusted: a peer may send anything. So the message is read in
segments, the runs of fixed fields between strings and sequences, each with a ``struct`` built
for where it starts modulo 8 (all its padding depends on): at most eight per run, however long
the strings an attacker chooses, where one layout per combination of lengths would grow without
bound. Every length is checked against the bytes there are before it is used, and anything that
is not a message of the type raises ``MalformedMessage`` at about the cost of a good message.
Encoding our own messages keeps one whole-message ``struct`` per combination of lengths (a few:
our frame names), in a bounded cache.
``tests/haptic_util/test_cdr.py`` checks both directions against ``rclpy.serialization``.
"""
from collections import OrderedDict
import importlib
import re
import struct
from typing import Sequence

__all__ = ['MalformedMessage', 'MessageCodec']

_LEAVES = {'boolean': '?', 'octet': 'B', 'uint8': 'B', 'int8': 'b', 'char': 'B', 'int16': 'h',
           'uint16': 'H', 'int32': 'i', 'uint32': 'I', 'int64': 'q', 'uint64': 'Q',
           'float': 'f', 'double': 'd'}
_ENCAPSULATION = b'\x00\x01\x00\x00'  # CDR, little endian
_HEADER = len(_ENCAPSULATION)
_FIXED_ARRAY = re.compile(r'(.+)\[(\d+)\]')  # T[N]: N elements, no length on the wire
_SEQUENCE = re.compile(r'sequence<(\w+)(?:, \d+)?>')  # a count, then the elements
_STRING = 'string'
_SEQUENCE_MARK = '*'  # code of a sequence of numbers: '*' + the element's code
_LENGTH = struct.Struct('<I')
_ENCODE_LAYOUTS = 16  # whole-message structs kept per codec, for our own messages' lengths


class MalformedMessage(ValueError):
    """Bytes that are not a message of the codec's type; the text says what is wrong."""


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


def _segments(codes: tuple) -> list:
    """Split the leaf codes into runs of fixed fields and single strings or sequences."""
    segments, run = [], []
    for code in codes:
        if code == _STRING or code[0] == _SEQUENCE_MARK:
            if run:
                segments.append(tuple(run))
                run = []
            segments.append(code)
        else:
            run.append(code)
    if run:
        segments.append(tuple(run))
    return segments


def _fixed_format(codes: tuple, offset: int) -> tuple[str, int]:
    """Return the struct format of fixed ``codes`` starting at ``offset``, and the end offset."""
    parts = []
    for code in codes:
        size = struct.calcsize(code)
        parts.append(f'{-offset % size}x{code}')
        offset += -offset % size + size
    return ''.join(parts), offset


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
        self._segments = _segments(self._codes)
        # Strings and sequences: their lengths (bytes with the NUL; elements) set the layout.
        self._variable = tuple(i for i, code in enumerate(self._codes)
                               if code == _STRING or code[0] == _SEQUENCE_MARK)
        # A fixed run's struct by (segment, start offset modulo 8): at most 8 per run.
        self._runs = {}
        self._encode_layouts = OrderedDict()  # lengths -> struct, the latest used last

    def index(self, field: str) -> int:
        """Return the position of leaf ``field`` (a dotted name) in the values."""
        return self.fields.index(field)

    def decode(self, data: bytes) -> list:
        """Return the leaf values of a serialized message (strings as str, sequences tuples).

        Raises ``MalformedMessage`` if ``data`` is not a message of this type.
        """
        end = len(data)
        if end < _HEADER or data[:2] != _ENCAPSULATION[:2]:
            raise MalformedMessage(f'{self.message_class.__name__}: not little-endian CDR '
                                   f'({bytes(data[:4])!r}, {end} bytes)')
        values, offset = [], 0  # offset: from the end of the encapsulation header
        try:
            for segment, code in enumerate(self._segments):
                if isinstance(code, tuple):
                    run = self._run(segment, offset)
                    values.extend(run.unpack_from(data, _HEADER + offset))
                    offset += run.size
                    continue
                offset += -offset % 4
                (count,) = _LENGTH.unpack_from(data, _HEADER + offset)
                offset += 4
                if code == _STRING:
                    values.append(self._string(data, offset, count))
                    offset += count
                    continue
                element = code[1:]
                size = struct.calcsize(element)
                offset += -offset % size if count else 0
                if _HEADER + offset + count * size > end:
                    raise MalformedMessage(f'{count} elements run past the end')
                values.append(struct.unpack_from(f'<{count}{element}', data, _HEADER + offset))
                offset += count * size
        except struct.error as error:
            raise MalformedMessage(f'{self.message_class.__name__}: ends early '
                                   f'({end} bytes): {error}') from None
        except MalformedMessage as error:
            raise MalformedMessage(f'{self.message_class.__name__}: {error}') from None
        return values

    def _string(self, data: bytes, offset: int, count: int) -> str:
        """Return the string of ``count`` bytes (NUL included) at ``offset``."""
        start = _HEADER + offset
        if count == 0 or start + count > len(data):
            raise MalformedMessage(f'a string of {count} bytes does not fit')
        if data[start + count - 1] != 0:
            raise MalformedMessage('a string does not end in NUL')
        try:
            return bytes(data[start:start + count - 1]).decode()
        except UnicodeDecodeError:
            raise MalformedMessage('a string is not UTF-8') from None

    def _run(self, segment: int, offset: int) -> struct.Struct:
        """Return the struct of fixed run ``segment`` starting at ``offset``, built once."""
        key = (segment, offset % 8)
        run = self._runs.get(key)
        if run is None:
            fmt, end = _fixed_format(self._segments[segment], offset % 8)
            run = self._runs[key] = struct.Struct('<' + fmt)
        return run

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
        return self._encode_layout(tuple(reversed(lengths))).pack(*args)

    def _encode_layout(self, lengths: tuple) -> struct.Struct:
        """Return the whole message's struct for these lengths, from a bounded cache."""
        layout = self._encode_layouts.get(lengths)
        if layout is not None:
            self._encode_layouts.move_to_end(lengths)
            return layout
        fmt, offset, k = ['<4s'], 0, 0
        for code in self._segments:
            if isinstance(code, tuple):
                run, offset = _fixed_format(code, offset)
                fmt.append(run)
                continue
            fmt.append(f'{-offset % 4}x')
            offset += -offset % 4 + 4
            count = lengths[k]
            k += 1
            if code == _STRING:
                fmt.append(f'I{count}s')
                offset += count
                continue
            size = struct.calcsize(code[1:])
            padding = -offset % size if count else 0
            fmt.append(f'I{padding}x{count}{code[1:]}')
            offset += padding + count * size
        layout = self._encode_layouts[lengths] = struct.Struct(''.join(fmt))
        if len(self._encode_layouts) > _ENCODE_LAYOUTS:
            self._encode_layouts.popitem(last=False)
        return layout

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


def _steps(field: str) -> list:
    """``'planes[1].point.x'`` -> ``['planes', 1, 'point', 'x']``."""
    steps = []
    for part in field.split('.'):
        name, _, index = part.partition('[')
        steps.append(name)
        if index:
            steps.append(int(index[:-1]))
    return steps
