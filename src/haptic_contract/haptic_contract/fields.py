"""Where a message's fields sit in the codec's flat tuple, found by their names.

The CDR codec (``haptic_util.cdr``) reads and writes a message as the flat tuple of its leaf
fields, in the order of its definition. Every reader of such a tuple looks its fields up here by
name once, at import, so that a field added to a message moves no literal index anywhere.
"""
from haptic_util.cdr import MessageCodec

__all__ = ['span', 'vector']


def span(codec: MessageCodec, first: str, last: str) -> slice:
    """Return the slice of the leaves from ``first`` to ``last`` (dotted names), both in."""
    return slice(codec.index(first), codec.index(last) + 1)


def vector(codec: MessageCodec, prefix: str, last: str = 'z') -> slice:
    """Return the slice of ``prefix``'s components, x to ``last`` (``z``; ``w`` a quaternion)."""
    return span(codec, f'{prefix}.x', f'{prefix}.{last}')
