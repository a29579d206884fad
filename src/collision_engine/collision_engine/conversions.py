"""Messages <-> the collision core: the pose's leaf fields in, CollisionState's leaf fields out.

The node reads and writes CDR bytes (``haptic_util.cdr``); these functions work on the flat
tuples of leaf fields, in the order of each message's definition (``POSE.fields``,
``STATE.fields``).
"""
import math

from geometry_msgs.msg import PoseStamped

from haptic_msgs.msg import CollisionState
from haptic_util.cdr import MessageCodec

__all__ = ['InvalidPose', 'POSE', 'STATE', 'tip_position', 'state', 'invalid_state']

UNIT_QUATERNION_TOLERANCE = 1e-3  # |q| may differ from 1 by this much (float32 round trips)
POSE = MessageCodec(PoseStamped)
STATE = MessageCodec(CollisionState)
_NAN3 = (math.nan, math.nan, math.nan)


class InvalidPose(ValueError):
    """A pose the engine refuses; the message names the field and what is wrong.

    ``kind`` is a fixed short text of the fault, for counting.
    """

    def __init__(self, kind: str, message: str) -> None:
        super().__init__(message)
        self.kind = kind


def tip_position(pose: list, frame_id: str) -> tuple:
    """Return the tip position (x, y, z) [m] of a pose in the scene frame, or raise InvalidPose.

    ``pose`` holds the leaf fields of a PoseStamped (``POSE.fields``).
    """
    _, _, frame, px, py, pz, qx, qy, qz, qw = pose
    if frame != frame_id:
        raise InvalidPose('pose in an unknown frame',
                          f'pose.header.frame_id is {frame!r}, not the scene frame '
                          f'{frame_id!r} (no transform is looked up)')
    for name, value in (('x', px), ('y', py), ('z', pz)):
        if not math.isfinite(value):
            raise InvalidPose('non-finite position', f'pose.position.{name} is {value}')
    for name, value in (('x', qx), ('y', qy), ('z', qz), ('w', qw)):
        if not math.isfinite(value):
            raise InvalidPose('non-finite orientation', f'pose.orientation.{name} is {value}')
    norm = math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
    if abs(norm - 1.0) > UNIT_QUATERNION_TOLERANCE:
        raise InvalidPose('non-unit quaternion',
                          f'pose.orientation is not a unit quaternion (|q| = {norm:.6g})')
    return (px, py, pz)


def state(header: tuple, result, compute_time: float, disagreements: int) -> tuple:
    """Return CollisionState's leaf fields for one query result.

    ``header`` is (sec, nanosec, frame_id) of the pose answered.
    """
    row = result.row
    return (*header, result.object or '', result.status, row[0], row[0] <= 0.0, *row[1:4],
            *row[4:7], *result.penetration.tolist(), *row[10:13], result.iterations,
            result.cross_validated, result.fcl_distance, result.fcl_discrepancy,
            disagreements, compute_time)


def invalid_state(header: tuple, disagreements: int) -> tuple:
    """Return the leaf fields of a state marked invalid: the renderer then sends zero force."""
    return (*header, '', CollisionState.STATUS_INVALID_INPUT, math.nan, False, *_NAN3, *_NAN3,
            *_NAN3, *_NAN3, 0, False, math.nan, math.nan, disagreements, 0.0)
