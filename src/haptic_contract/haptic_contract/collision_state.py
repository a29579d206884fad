"""A collision state (``haptic_msgs/CollisionState``) as the codec's flat tuple, read by name.

The collision engine writes one per pose; the force renderer reads the contact from it. The
status codes are the message's own, the one set of them (the engine's kernels return them too).
"""
import functools
from typing import NamedTuple

from haptic_contract.fields import span, vector
from haptic_msgs.msg import CollisionState

__all__ = ['STATUS_INVALID_INPUT', 'STATUS_NO_OBJECT', 'STATUS_NOT_CONVERGED',
           'STATUS_OK', 'contact_fields', 'face_fields']  # and STATE, the codec (``__getattr__``)

STATUS_OK = CollisionState.STATUS_OK  # converged, exact to the engine's tolerance
STATUS_NOT_CONVERGED = CollisionState.STATUS_NOT_CONVERGED  # the distance is an upper bound
STATUS_NO_OBJECT = CollisionState.STATUS_NO_OBJECT
STATUS_INVALID_INPUT = CollisionState.STATUS_INVALID_INPUT


class _Layout(NamedTuple):
    """Where a CollisionState's fields sit in the codec's tuple: found by name."""

    codec: object  # haptic_util.cdr.MessageCodec
    header: slice  # sec, nanosec, frame_id
    object: int
    status: int
    distance: int
    point: slice
    normal: slice
    tip: slice
    orientation: slice
    face: slice  # the face's distances, points and normals


@functools.cache
def _layout() -> _Layout:
    """Build the codec and find the fields, once, on first use.

    Not at import: the codec loads the message's nested types (geometry_msgs) into cores that
    only need the status codes.
    """
    from haptic_util.cdr import MessageCodec

    codec = MessageCodec(CollisionState)
    return _Layout(codec, span(codec, 'header.stamp.sec', 'header.frame_id'),
                   codec.index('object'), codec.index('status'), codec.index('distance'),
                   vector(codec, 'closest_point'), vector(codec, 'normal'), vector(codec, 'tip'),
                   vector(codec, 'orientation', 'w'),
                   span(codec, 'contact_distance', 'contact_normals'))


def __getattr__(name: str):
    """``STATE``, the CollisionState codec, is built on first use (see ``_layout``)."""
    if name == 'STATE':
        return _layout().codec
    raise AttributeError(f'module {__name__!r} has no attribute {name!r}')


def contact_fields(fields) -> tuple:
    """Return (header, object, status, distance, closest point, normal, tip) of a state.

    ``header`` is (sec, nanosec, frame_id); the vectors are sequences of three floats.
    """
    at = _layout()
    return (tuple(fields[at.header]), fields[at.object], fields[at.status],
            fields[at.distance], fields[at.point], fields[at.normal], fields[at.tip])


def face_fields(fields) -> tuple:
    """Return the tool's face of a state: distances, points, normals (flat) and orientation."""
    at = _layout()
    distance, points, normals = fields[at.face]
    return distance, points, normals, fields[at.orientation]
