"""Messages <-> the collision core: the pose's leaf fields in, CollisionState's leaf fields out.

The node reads and writes CDR bytes (``haptic_util.cdr``); these functions work on the flat
tuples of leaf fields, in the order of each message's definition (``POSE.fields``,
``STATE.fields``).
"""
import math

from haptic_contract.collision_state import STATE, STATUS_INVALID_INPUT
from haptic_contract.streams import FRAME, POSE, POSE_ORIENTATION, POSE_POSITION

__all__ = ['InvalidPose', 'POSE', 'STATE', 'invalid_state', 'state', 'tip_pose',
           'tool_state']

UNIT_QUATERNION_TOLERANCE = 1e-3  # |q| may differ from 1 by this much (float32 round trips)
_NAN3 = (math.nan, math.nan, math.nan)
_NO_CONTACTS = ((), (), ())  # the face's three sequences, empty without a tool


class InvalidPose(ValueError):
    """A pose the engine refuses; the message names the field and what is wrong.

    ``kind`` is a fixed short text of the fault, for counting.
    """

    def __init__(self, kind: str, message: str) -> None:
        super().__init__(message)
        self.kind = kind


def tip_pose(pose: list, frame_id: str) -> tuple:
    """Return the tip position (x, y, z) [m] and unit quaternion (x, y, z, w) of a pose.

    ``pose`` holds the leaf fields of a PoseStamped (``POSE.fields``), in the scene frame; the
    quaternion is normalised (its norm may be off by ``UNIT_QUATERNION_TOLERANCE``, not more).
    Raises InvalidPose for any other frame, a NaN or infinite value or a non-unit quaternion.
    """
    frame = pose[FRAME]
    px, py, pz = pose[POSE_POSITION]
    qx, qy, qz, qw = pose[POSE_ORIENTATION]
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
    return (px, py, pz), (qx / norm, qy / norm, qz / norm, qw / norm)


def state(header: tuple, result, compute_time: float, disagreements: int,
          orientation: tuple = (0.0, 0.0, 0.0, 1.0)) -> tuple:
    """Return CollisionState's leaf fields for one query result of the tip.

    ``header`` is (sec, nanosec, frame_id) of the pose answered, ``orientation`` its quaternion.
    """
    row = result.row
    return (*header, result.object or '', result.status, row[0], row[0] <= 0.0, *row[1:4],
            *row[4:7], *result.penetration.tolist(), *row[10:13], result.iterations,
            result.cross_validated, disagreements, compute_time, *orientation, *row[10:13],
            *_NO_CONTACTS)


def tool_state(header: tuple, probe, tip: tuple, orientation: tuple, compute_time: float,
               disagreements: int) -> tuple:
    """Return CollisionState's leaf fields for a mounted tool (``probe.ProbeResult``).

    The distance, witnesses and normal are the whole tool's; ``tip`` (3,) is the pose's position.
    The face's points fill the contact sequences.
    """
    row = probe.tool.row
    distance = row[0]
    penetration = ((-distance * row[4], -distance * row[5], -distance * row[6])
                   if distance <= 0.0 else (0.0, 0.0, 0.0))
    return (*header, probe.tool.object or '', probe.tool.status, distance, distance <= 0.0,
            *row[1:4], *row[4:7], *penetration, *tip, probe.tool.iterations, False,
            disagreements, compute_time, *orientation, *row[10:13],
            tuple(probe.distance.tolist()), tuple(probe.points.ravel().tolist()),
            tuple(probe.normals.ravel().tolist()))


def invalid_state(header: tuple, disagreements: int) -> tuple:
    """Return the leaf fields of a state marked invalid: the renderer then sends zero force."""
    return (*header, '', STATUS_INVALID_INPUT, math.nan, False, *_NAN3, *_NAN3,
            *_NAN3, *_NAN3, 0, False, disagreements, 0.0, *_NAN3, math.nan,
            *_NAN3, *_NO_CONTACTS)
